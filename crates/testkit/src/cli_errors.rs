//! The error rules every flexdyn binary follows, as test helpers for the packages' command-line
//! tests (`tools/tests/cli_errors.rs`, `clients/rust/acs-demo/tests/cli.rs`): one `error:`
//! line, exit 2 for bad input, no backtrace, no Rust or registry paths.

use std::process::Command;

/// Runs `bin` with `args` (and `RUST_BACKTRACE=1`, which must change nothing); its exit code
/// and stderr.
pub fn run(bin: &str, args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(bin)
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("runs the tool");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

/// Exit 2 and one `error:` line that says `want` and leaks nothing.
#[track_caller]
pub fn assert_one_error_line(code: Option<i32>, err: &str, want: &str) {
    assert_eq!(code, Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "not one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains(want), "does not say `{want}`: {err}");
    for leak in [
        ".rs:",
        "Json5Err",
        "stack backtrace",
        "registry/src",
        "Error:",
    ] {
        assert!(!err.contains(leak), "leaks `{leak}`: {err}");
    }
}
