//! libFuzzer, with AddressSanitizer and UndefinedBehaviorSanitizer, over every decoder of the C
//! header (`proto/c/tests/fuzz_libfuzzer.c`): no crash, no memory error, no undefined
//! behaviour, and the header's own contract on every input (an accepted message re-encodes to
//! the same bytes and passes its validator; a refusal carries a consistent reason). The corpus
//! starts from the hand-derived goldens (`proto/golden/*.bin`); the run is seeded, so it is the
//! same run every time.
//!
//! clang and its libFuzzer runtime come from Debian (`tests/deps/debian_package.sh`: `clang`,
//! `libclang-rt-<major>-dev`), installed when missing and this runs as root, as CI does.
//! `libfuzzer_finds_a_wrong_encoder` shows the harness can fail: one line of the header's IMU
//! encoder is broken in a copy, and the same run must stop on it.

use std::path::{Path, PathBuf};
use std::process::Command;

fn proto_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `tests/deps/debian_package.sh PROGRAM PACKAGE`; panics saying what to install.
fn debian_package(program: &str, package: &str) {
    let script = proto_dir().join("../tests/deps/debian_package.sh");
    let status = Command::new("sh")
        .arg(&script)
        .args([program, package])
        .status();
    assert!(
        status.as_ref().is_ok_and(|s| s.success()),
        "{program} is needed for the libFuzzer run (Debian: apt-get install {package}): {status:?}"
    );
}

/// clang with its libFuzzer runtime, installed if need be: once per process, since the tests
/// run on parallel threads and two apt-get runs at once would fight over dpkg's lock.
fn clang() -> &'static str {
    static INSTALLED: std::sync::OnceLock<()> = std::sync::OnceLock::new();
    INSTALLED.get_or_init(install_clang);
    "clang"
}

fn install_clang() {
    debian_package("clang", "clang");
    let version = Command::new("clang").arg("-dumpversion").output().unwrap();
    let version = String::from_utf8_lossy(&version.stdout).trim().to_string();
    let major = version.split('.').next().unwrap_or("").to_string();
    let dir = Command::new("clang")
        .arg("-print-resource-dir")
        .output()
        .unwrap();
    let runtime = Path::new(String::from_utf8_lossy(&dir.stdout).trim())
        .join("lib/linux/libclang_rt.fuzzer-x86_64.a");
    debian_package(
        runtime.to_str().unwrap(),
        &format!("libclang-rt-{major}-dev"),
    );
}

/// Builds the target against the header in `include` as `name`.
fn build(include: &Path, name: &str) -> PathBuf {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let result = Command::new(clang())
        .args([
            "-g",
            "-O1",
            "-fsanitize=fuzzer,address,undefined",
            "-fno-sanitize-recover=undefined",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-I",
        ])
        .arg(include)
        .arg(proto_dir().join("c/tests/fuzz_libfuzzer.c"))
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "clang failed:\n{}",
        String::from_utf8_lossy(&result.stderr)
    );
    out
}

/// A fresh corpus of the goldens under `name`.
fn corpus(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut n = 0;
    for entry in std::fs::read_dir(proto_dir().join("golden")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "bin") {
            std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
            n += 1;
        }
    }
    assert!(n >= 17, "{n} goldens");
    dir
}

/// Runs `exe` for `runs` inputs with seed 1; its exit status and stderr.
fn fuzz(exe: &Path, corpus: &Path, runs: u64) -> (bool, String) {
    // Crash inputs go beside the corpus, not into the working directory.
    let artifacts = corpus.with_extension("artifacts");
    std::fs::create_dir_all(&artifacts).unwrap();
    let out = Command::new(exe)
        .arg(format!("-runs={runs}"))
        .args(["-seed=1", "-max_len=4096"])
        .arg(format!("-artifact_prefix={}/", artifacts.display()))
        .arg(corpus)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn libfuzzer_with_sanitizers_finds_nothing() {
    let exe = build(&proto_dir().join("c/include"), "fuzz_libfuzzer");
    let (ok, log) = fuzz(&exe, &corpus("libfuzzer-corpus"), 2_000_000);
    let done = log.lines().find(|l| l.contains("DONE")).unwrap_or("");
    eprintln!("libFuzzer: {done}");
    assert!(ok, "libFuzzer stopped:\n{log}");
    assert!(done.contains("cov:"), "no final coverage line:\n{log}");
}

#[test]
fn libfuzzer_finds_a_wrong_encoder() {
    let header = std::fs::read_to_string(proto_dir().join("c/include/flexdyn_proto.h")).unwrap();
    let line = "    buf[126] = m->saturation_flags;";
    assert_eq!(
        header.matches(line).count(),
        1,
        "the IMU encoder's flags line"
    );
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("libfuzzer-broken-header");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("flexdyn_proto.h"),
        header.replacen(line, "    buf[126] = 0;", 1),
    )
    .unwrap();
    let exe = build(&dir, "fuzz_libfuzzer_broken");
    let (ok, log) = fuzz(&exe, &corpus("libfuzzer-corpus-broken"), 2_000_000);
    assert!(!ok, "the broken encoder went unnoticed");
    assert!(log.contains("deadly signal"), "{log}");
}
