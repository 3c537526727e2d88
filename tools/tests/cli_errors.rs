//! Every tool follows `flexdyn`'s error rules: one `error:` line, exit 2 for bad input, no
//! backtrace, no Rust or registry paths. Negative numbers are accepted in value lists.
//! No test here reaches a server: each command fails on its input before connecting.

use std::process::Command;

fn run(bin: &str, args: &[&str]) -> (Option<i32>, String) {
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

#[track_caller]
fn assert_one_error_line(code: Option<i32>, err: &str, want: &str) {
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

#[test]
fn the_demo_rejects_bad_options_in_one_line() {
    let demo = env!("CARGO_BIN_EXE_flexdyn-acs-demo");
    let (c, e) = run(demo, &["--bogus"]);
    assert_one_error_line(c, &e, "unexpected argument '--bogus'");
    // A negative first element in a list parses; the bad timeout is what is reported.
    let (c, e) = run(
        demo,
        &["--sigma-rn", "-0.1,0.2,0.1", "--imu-timeout-s", "-1"],
    );
    assert_one_error_line(c, &e, "--imu-timeout-s must be a positive number");
    let (c, e) = run(demo, &["--sigma-rn", "0.1,0.2"]);
    assert_one_error_line(c, &e, "--sigma-rn takes three");
    let (c, e) = run(demo, &["--imu-dcm-pb", "-1,0,0,0,-1,0,0,0,2"]);
    assert_one_error_line(c, &e, "--imu-dcm-pb is not orthonormal");
    let (c, e) = run(demo, &["--listen", "garbage"]);
    assert_one_error_line(c, &e, "--listen: `garbage`: not an endpoint");
    let (c, e) = run(demo, &["--sc-id", "a/b"]);
    assert_one_error_line(c, &e, "--sc-id");
}

#[test]
fn the_monitor_and_pingpong_reject_bad_options_in_one_line() {
    let monitor = env!("CARGO_BIN_EXE_flexdyn-monitor");
    let (c, e) = run(monitor, &["--interval-s", "0"]);
    assert_one_error_line(c, &e, "--interval-s must be > 0");
    let (c, e) = run(monitor, &["--connect", "udp/127.0.0.1:7447"]);
    assert_one_error_line(c, &e, "protocol `udp` is not built into flexdyn");
    let pingpong = env!("CARGO_BIN_EXE_flexdyn-pingpong");
    let (c, e) = run(pingpong, &["fly"]);
    assert_one_error_line(c, &e, "unrecognized subcommand");
}
