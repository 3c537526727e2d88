//! A run that ends for everyone (issue 36; issue 37 §4): when a lockstep server finishes, the
//! demo flight code and the monitor stop on the server's last status (`finished`), without
//! `--idle-exit-s` or `--duration-s`, which would otherwise keep them waiting forever. Before
//! this, both ran until a signal: this test's 10 s bound then failed.
//!
//! The time from the server's return (its last status is out) to each client's exit is printed:
//! a figure, not a pass/fail bound (speed targets belong in benchmarks); the bound here is only
//! "long before forever".

use flexdyn_testkit::demo_bin;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::support::{endpoint, reference_config, ChildGuard, ServerHandle};
use flexdyn_proto::Mode;
use flexdyn_server::ServerSettings;

/// Far above any delivery time, far below "never".
const EXIT_BOUND: Duration = Duration::from_secs(10);

#[test]
fn the_demo_and_the_monitor_stop_when_the_server_finishes() {
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        participants: vec![1],
        duration_ns: Some(3_000_000_000),
        ..ServerSettings::default()
    };
    let server = ServerHandle::start(settings, reference_config(100.0));
    let connect = endpoint(server.port);
    let mut monitor = ChildGuard(
        Command::new(env!("CARGO_BIN_EXE_flexdyn-monitor"))
            .args(["--connect", &connect, "--plain", "--interval-s", "0.5"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    // The monitor prints its first line once its subscribers are declared: only then may the
    // run start (the demo is the participant the lockstep server waits for). A monitor that
    // subscribes after the run ended cannot hear its end; on a loaded CI machine it once did.
    let (tx, lines) = std::sync::mpsc::channel::<String>();
    let stdout = monitor.0.stdout.take().unwrap();
    std::thread::spawn(move || {
        for line in std::io::BufRead::lines(std::io::BufReader::new(stdout)) {
            let Ok(line) = line else { break };
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let first = lines
        .recv_timeout(Duration::from_secs(30))
        .expect("the monitor printed nothing within 30 s");
    let mut out = vec![first];
    let mut demo = ChildGuard::spawn(
        Command::new(demo_bin::acs_demo())
            .args(["--connect", &connect, "--sender-id", "1"])
            .args(["--rate-source", "truth", "--log-every-s", "0"]),
    );
    let report = server.join(Duration::from_secs(120)).expect("the run");
    let server_done = Instant::now();
    assert_eq!(report.last_tick, 300);

    let status = demo
        .wait_timeout(EXIT_BOUND)
        .expect("the demo did not stop after the server finished");
    let demo_ms = server_done.elapsed().as_secs_f64() * 1e3;
    assert!(status.success(), "the demo: {status}");
    let status = monitor
        .wait_timeout(EXIT_BOUND)
        .expect("the monitor did not stop after the server finished");
    let monitor_ms = server_done.elapsed().as_secs_f64() * 1e3;
    assert!(status.success(), "the monitor: {status}");
    // Its stdout closed with its exit: every line is in the channel.
    out.extend(lines.try_iter());
    let last = out.last().map(String::as_str).unwrap_or_default();
    assert_eq!(last, "run ended: finished at tick 300", "{out:?}");
    eprintln!(
        "from the server's return: the demo exited after {demo_ms:.1} ms, the monitor (checked \
         second) after {monitor_ms:.1} ms"
    );
}
