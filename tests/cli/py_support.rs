//! Python for the tests that check flexdyn against independent Python readers
//! ([`flexdyn_testkit::python`]), with this executable's target directory.

use std::path::{Path, PathBuf};

pub use flexdyn_testkit::python::run;

/// [`flexdyn_testkit::python::venv_python`] beside this test executable's temporary directory.
pub fn venv_python(name: &str, pip_args: &[String], stamp: &str) -> PathBuf {
    flexdyn_testkit::python::venv_python(
        Path::new(env!("CARGO_TARGET_TMPDIR")),
        name,
        pip_args,
        stamp,
    )
}
