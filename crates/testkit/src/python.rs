//! Python for the tests that check flexdyn against independent Python readers (`mcap`, pandas,
//! `pynmea2`, `spacepackets`): a virtual environment under the target directory, made the
//! first time and reinstalled when what it should hold changes. Needs `python3` (3.9+) with the
//! `venv` module, and PyPI the first time.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `cmd`, panics with its output unless it succeeds, and returns stdout + stderr.
pub fn run(cmd: &mut Command, what: &str) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run {cmd:?}: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{text}",
        out.status
    );
    text
}

/// The Python of the virtual environment `<target>/<name>`, with `pip install <pip_args>`
/// done whenever `stamp` (the text that decides what is installed) differs from last time.
/// `target_tmpdir` is the calling test's `CARGO_TARGET_TMPDIR` (the venv goes beside it).
pub fn venv_python(target_tmpdir: &Path, name: &str, pip_args: &[String], stamp: &str) -> PathBuf {
    // The tests of one binary run as threads: one of them makes the venv, the others wait.
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let target = target_tmpdir.parent().expect("target dir").to_path_buf();
    let venv = target.join(name);
    let python = venv.join("bin/python");
    if !python.is_file() {
        let status = Command::new("python3")
            .args(["-m", "venv"])
            .arg(&venv)
            .status()
            .unwrap_or_else(|e| {
                panic!(
                    "no python3 ({e}): these tests need Python 3.9+ with venv \
                     (Debian: apt install python3-venv)"
                )
            });
        assert!(
            status.success(),
            "python3 -m venv {} failed",
            venv.display()
        );
    }
    let stamp_file = venv.join("flexdyn-installed.stamp");
    if std::fs::read_to_string(&stamp_file).ok().as_deref() != Some(stamp) {
        run(
            Command::new(&python)
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "--disable-pip-version-check",
                ])
                .args(pip_args),
            &format!("pip install {}", pip_args.join(" ")),
        );
        std::fs::write(&stamp_file, stamp).unwrap();
    }
    python
}
