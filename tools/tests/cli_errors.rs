//! Every tool follows `flexdyn`'s error rules: one `error:` line, exit 2 for bad input, no
//! backtrace, no Rust or registry paths. Negative numbers are accepted in value lists.
//! No test here reaches a server: each command fails on its input before connecting.

#[path = "../../tests/ports/mod.rs"]
mod ports;

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

/// With nobody to talk to, the tools say so and fail, instead of a false pass.
#[test]
fn no_server_is_a_failure_not_a_pass() {
    let demo = env!("CARGO_BIN_EXE_flexdyn-acs-demo");
    let (nobody, _held) = ports::closed_endpoint();
    let (c, e) = run(demo, &["--connect", &nobody, "--idle-exit-s", "1"]);
    assert_eq!(c, Some(1), "{e}");
    let last = e.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("error: no state received on flexdyn/sc1/tlm/state within 1 s"),
        "{e}"
    );
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

/// A non-interactive shell starts background jobs with SIGINT ignored; the demo still stops
/// on SIGINT (and SIGTERM), closes its session and exits 0.
#[test]
fn the_demo_stops_on_sigint_even_when_started_with_it_ignored() {
    let demo = env!("CARGO_BIN_EXE_flexdyn-acs-demo");
    for sig in ["-INT", "-TERM"] {
        let (nobody, _held) = ports::closed_endpoint();
        let mut child = Command::new("sh")
            .args([
                "-c",
                &format!("trap '' INT; exec {demo} --connect {nobody}"),
            ])
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(700));
        assert!(child.try_wait().unwrap().is_none(), "the demo exited early");
        let ok = Command::new("kill")
            .args([sig, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(ok.success());
        let give_up = std::time::Instant::now() + std::time::Duration::from_secs(10);
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            if std::time::Instant::now() > give_up {
                let _ = child.kill();
                panic!("the demo ignored {sig}");
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        };
        assert_eq!(status.code(), Some(0), "{sig}: {status:?}");
    }
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
