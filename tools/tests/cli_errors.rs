//! Every tool follows `flexdyn`'s error rules (the demo flight code's are checked in
//! `clients/rust/acs-demo/tests/cli.rs`): one `error:` line, exit 2 for bad input, no
//! backtrace, no Rust or registry paths. Negative numbers are accepted in value lists.
//! No test here reaches a server: each command fails on its input before connecting.

use flexdyn_testkit::ports;

use std::process::Command;

use cli_errors::{assert_one_error_line, run};
use flexdyn_testkit::cli_errors;

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

/// With nobody to talk to, the monitor says so and fails, instead of a false pass.
#[test]
fn no_server_is_a_failure_not_a_pass() {
    let (nobody, _held) = ports::closed_endpoint();
    let monitor = env!("CARGO_BIN_EXE_flexdyn-monitor");
    let out = Command::new(monitor)
        .args(["--connect", &nobody, "--duration-s", "1.5"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stdout
            .lines()
            .next()
            .is_some_and(|l| l.starts_with("no data: no StateMsg")),
        "the monitor must not print zeros that look like data: {stdout}"
    );
    assert!(
        stderr
            .lines()
            .last()
            .unwrap_or_default()
            .starts_with("error: no data"),
        "{stderr}"
    );
}

/// Zenoh's "Scouting delay elapsed before start conditions are met" warning is filtered at the
/// default level (it reports nothing actionable with multicast scouting off); naming its module
/// in RUST_LOG brings it back, which shows the check can fail.
#[test]
fn the_scouting_delay_warning_is_quiet_by_default() {
    let monitor = env!("CARGO_BIN_EXE_flexdyn-monitor");
    let (nobody, _held) = ports::closed_endpoint();
    let stderr_with = |rust_log: &str| {
        let out = Command::new(monitor)
            .args(["--connect", &nobody, "--duration-s", "1"])
            .env("RUST_LOG", rust_log)
            .output()
            .unwrap();
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    let quiet = stderr_with("info");
    assert!(!quiet.contains("Scouting delay"), "{quiet}");
    let loud = stderr_with("info,zenoh::net::runtime::orchestrator=warn");
    assert!(loud.contains("Scouting delay"), "{loud}");
}
