//! The Python SDK (`clients/python`): its pytest suite, run from `cargo test` so the README's one
//! test command covers it.
//!
//! The test makes a virtual environment under the target directory (`<target>/python-venv`) the
//! first time, installs the package with its pinned dependencies (`eclipse-zenoh==1.10.2`,
//! pytest) from `clients/python/pyproject.toml`, and reinstalls when that file changes. It then
//! runs `python -m pytest clients/python` with `FLEXDYN_BIN` (this package's `flexdyn`) and
//! `FLEXDYN_VERDICTS_BIN` (`flexdyn-decode-verdicts`, built by `cargo test --workspace`).
//! Needs `python3` (3.9+) with the `venv` module, and PyPI the first time.

use std::path::{Path, PathBuf};
use std::process::Command;

fn run(cmd: &mut Command, what: &str) -> String {
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

#[test]
fn python_sdk_pytest_suite() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let package = root.join("clients/python");
    let target = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .expect("target dir")
        .to_path_buf();
    let venv = target.join("python-venv");
    let python = venv.join("bin/python");
    if !python.is_file() {
        let status = Command::new("python3")
            .args(["-m", "venv"])
            .arg(&venv)
            .status()
            .unwrap_or_else(|e| {
                panic!(
                    "no python3 ({e}): the Python SDK tests need Python 3.9+ with venv \
                     (Debian: apt install python3-venv)"
                )
            });
        assert!(
            status.success(),
            "python3 -m venv {} failed",
            venv.display()
        );
    }
    // Reinstall when pyproject.toml changes (its text is the stamp).
    let pyproject = std::fs::read_to_string(package.join("pyproject.toml")).unwrap();
    let stamp = venv.join("flexdyn-installed.stamp");
    if std::fs::read_to_string(&stamp).ok().as_deref() != Some(pyproject.as_str()) {
        run(
            Command::new(&python)
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "--disable-pip-version-check",
                    "-e",
                ])
                .arg(format!("{}[test]", package.display())),
            "pip install -e clients/python[test]",
        );
        std::fs::write(&stamp, &pyproject).unwrap();
    }
    let flexdyn = PathBuf::from(env!("CARGO_BIN_EXE_flexdyn"));
    let verdicts = flexdyn.with_file_name("flexdyn-decode-verdicts");
    let out = run(
        Command::new(&python)
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
            .arg(&package)
            .current_dir(&package)
            .env("FLEXDYN_BIN", &flexdyn)
            .env("FLEXDYN_VERDICTS_BIN", &verdicts)
            .env("PYTHONDONTWRITEBYTECODE", "1"),
        "pytest clients/python",
    );
    eprintln!("{out}");
    assert!(out.contains(" passed"), "{out}");
}
