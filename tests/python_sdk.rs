//! The Python SDK (`clients/python`): its pytest suite, run from `cargo test` so the README's one
//! test command covers it.
//!
//! The test makes a virtual environment under the target directory (`<target>/python-venv`) the
//! first time, installs the package with its pinned dependencies (`eclipse-zenoh==1.10.2`,
//! pytest) from `clients/python/pyproject.toml`, and reinstalls when that file changes. It then
//! runs `python -m pytest clients/python` with `FLEXDYN_BIN` (this package's `flexdyn`) and
//! `FLEXDYN_VERDICTS_BIN` (`flexdyn-decode-verdicts`, built by `cargo test --workspace`).
//! Needs `python3` (3.9+) with the `venv` module, and PyPI the first time.

mod py_support;

use std::path::PathBuf;
use std::process::Command;

use py_support::{run, venv_python};

#[test]
fn python_sdk_pytest_suite() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let package = root.join("clients/python");
    // Reinstall when pyproject.toml changes (its text is the stamp).
    let pyproject = std::fs::read_to_string(package.join("pyproject.toml")).unwrap();
    let python = venv_python(
        "python-venv",
        &["-e".into(), format!("{}[test]", package.display())],
        &pyproject,
    );
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
