//! A `cargo build` run from inside a test or a benchmark, for what Cargo gives a test no path
//! to (another package's binary or static library), and the libraries a C program links with
//! the static C client library.

use std::path::Path;
use std::process::{Command, Stdio};

/// The libraries `rustc --print native-static-libs` names for the static library on Linux
/// (docs/guides/flight-code.md).
pub const NATIVE_LIBS: &[&str] = &[
    "-ldl",
    "-lgcc_s",
    "-lutil",
    "-lrt",
    "-lpthread",
    "-lm",
    "-ldl",
    "-lc",
];

/// Runs `cargo build --message-format=json-render-diagnostics ARGS` in the workspace `root`
/// (`--release` unless this test is a debug build) and returns its standard output, one JSON
/// message per line. A no-op when everything is fresh, as in `cargo test --workspace`. Cargo
/// runs with the variables it set for this test removed: build scripts such as ring's rerun
/// when `CARGO_PKG_NAME` & co. differ, and would rebuild dependencies on every run. Panics if
/// the build fails.
pub fn cargo_build(root: &Path, args: &[&str]) -> String {
    let mut cmd = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    cmd.current_dir(root)
        .arg("build")
        .args(args)
        .arg("--message-format=json-render-diagnostics");
    for (key, _) in std::env::vars_os() {
        let k = key.to_string_lossy();
        let set_for_tests = k.starts_with("CARGO_PKG_")
            || k.starts_with("CARGO_MANIFEST_")
            || k.starts_with("CARGO_CRATE_")
            || k.starts_with("CARGO_BIN_")
            || k == "CARGO_PRIMARY_PACKAGE"
            || k == "CARGO_TARGET_TMPDIR"
            || k == "CARGO_RUSTC_CURRENT_DIR"
            || k == "OUT_DIR";
        if set_for_tests {
            cmd.env_remove(&key);
        }
    }
    if !cfg!(debug_assertions) {
        cmd.arg("--release");
    }
    let out = cmd.stderr(Stdio::inherit()).output().expect("run cargo");
    assert!(out.status.success(), "cargo build {args:?} failed");
    String::from_utf8_lossy(&out.stdout).into_owned()
}
