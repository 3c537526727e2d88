//! The Python SDK (`clients/python`): its pytest suite, run from `cargo test` so the README's one
//! test command covers it.
//!
//! The test makes a virtual environment under the target directory (`<target>/python-venv`) the
//! first time, installs the package with its pinned dependencies (`eclipse-zenoh==1.10.2`,
//! pytest) from `clients/python/pyproject.toml`, and reinstalls when that file changes. It then
//! runs `python -m pytest clients/python` with `FLEXDYN_BIN` (this package's `flexdyn`) and
//! `FLEXDYN_VERDICTS_BIN` (`flexdyn-decode-verdicts`, built by `cargo test --workspace`).
//! Needs `python3` (3.9+) with the `venv` module, and PyPI the first time.
//!
//! `pip_install_leaves_the_checkout_clean` installs the package the other way the README
//! mentions, `pip install clients/python` (a wheel built in the source tree), into a temporary
//! directory, and checks that `git status` of `clients/python` has nothing new afterwards.

use crate::py_support;

use std::path::{Path, PathBuf};
use std::process::Command;

use py_support::{run, venv_python};

/// The checkout, the SDK's folder and the Python of the venv that has the SDK installed
/// (editable, with its test extras; reinstalled when `pyproject.toml` or the checkout's path
/// changes, the two being the stamp: an editable install points into one checkout, and a
/// target directory reused by another checkout or worktree must not import the old one).
fn sdk_venv() -> (PathBuf, PathBuf, PathBuf) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let package = root.join("clients/python");
    let pyproject = std::fs::read_to_string(package.join("pyproject.toml")).unwrap();
    let python = venv_python(
        "python-venv",
        &["-e".into(), format!("{}[test]", package.display())],
        &format!("{}\n{pyproject}", package.display()),
    );
    (root, package, python)
}

#[test]
fn python_sdk_pytest_suite() {
    let (_, package, python) = sdk_venv();
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

/// `git status --porcelain` of `clients/python`, untracked files listed one by one.
fn git_status(root: &Path) -> String {
    run(
        Command::new("git")
            .args([
                "status",
                "--porcelain",
                "--untracked-files=all",
                "--",
                "clients/python",
            ])
            .current_dir(root),
        "git status",
    )
}

/// `pip install clients/python` builds a wheel in the source tree (`clients/python/build/`);
/// that must not show up as an untracked directory in the checkout.
#[test]
fn pip_install_leaves_the_checkout_clean() {
    let (root, package, python) = sdk_venv();
    let build_dir = package.join("build");
    let had_build_dir = build_dir.exists();
    let before = git_status(&root);
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("pip-install-target");
    let _ = std::fs::remove_dir_all(&target);
    let out = run(
        Command::new(&python)
            .args([
                "-m",
                "pip",
                "install",
                "--no-deps",
                "--disable-pip-version-check",
            ])
            .arg("--target")
            .arg(&target)
            .arg(&package)
            .env("PYTHONDONTWRITEBYTECODE", "1"),
        "pip install clients/python",
    );
    assert!(
        target.join("flexdyn/client.py").is_file(),
        "pip installed nothing: {out}"
    );
    assert!(
        build_dir.is_dir(),
        "pip no longer builds in the tree: {out}"
    );
    let after = git_status(&root);
    if !had_build_dir {
        let _ = std::fs::remove_dir_all(&build_dir);
    }
    let new: Vec<&str> = after
        .lines()
        .filter(|l| !before.contains(l) || l.contains("clients/python/build/"))
        .collect();
    assert!(new.is_empty(), "pip install left untracked files: {new:?}");
}
