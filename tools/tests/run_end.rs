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

/// `flexdyn-monitor --plain` on `connect`, its output lines, and its first line. It prints its
/// first line once its subscribers are declared: only then may the run start (the demo is the
/// participant the lockstep server waits for). A monitor that subscribes after the run ended
/// cannot hear its end; on a loaded CI machine it once did.
fn start_monitor(connect: &str) -> (ChildGuard, std::sync::mpsc::Receiver<String>, String) {
    let mut monitor = ChildGuard(
        Command::new(env!("CARGO_BIN_EXE_flexdyn-monitor"))
            .args(["--connect", connect, "--plain", "--interval-s", "0.5"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
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
    (monitor, lines, first)
}

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
    let (mut monitor, lines, first) = start_monitor(&connect);
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

/// Issue 37 §2: the monitor shows the flight code's current mode and its last event. The FDIR
/// demo flies `scenarios/fdir.toml` (imu_a's gyro sticks at 3 s, rw2 seizes at 60 s) for 65 s
/// with the server recording; the monitor, a separate peer, hears the telemetry the server
/// passes on. Its last line must name the mode of the last recorded sample and the last event
/// recorded, with its severity and time, read back from the recording.
#[test]
fn the_monitor_shows_the_flight_codes_mode_and_last_event() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/fdir.toml");
    let cfg = flexdyn_vehicle::config::SimConfig::from_file(&path).expect("fdir.toml");
    let decl = cfg
        .fsw_stream("acs")
        .expect("fdir.toml declares acs")
        .clone();
    let record = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("monitor_fsw.mcap");
    let _ = std::fs::remove_file(&record);
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        participants: vec![1],
        duration_ns: Some(65_000_000_000),
        participant_timeout: Duration::from_secs(30),
        record: Some(record.clone()),
        ..ServerSettings::default()
    };
    let server = ServerHandle::start(settings, cfg);
    let connect = endpoint(server.port);
    let (mut monitor, lines, first) = start_monitor(&connect);
    let mut out = vec![first];
    let mut demo = ChildGuard::spawn(crate::support::on_sensors(
        Command::new(demo_bin::acs_demo())
            .args(["--connect", &connect, "--sender-id", "1", "--fdir"])
            .args(["--log-every-s", "0"]),
        "imu_a",
    ));
    let report = server.join(Duration::from_secs(120)).expect("the run");
    assert_eq!(report.last_tick, 650);
    assert!(demo.wait_timeout(EXIT_BOUND).is_some_and(|s| s.success()));
    assert!(monitor
        .wait_timeout(EXIT_BOUND)
        .is_some_and(|s| s.success()));
    out.extend(lines.try_iter());

    // The recording's last sample and its last event.
    let rec = flexdyn_sinks::reader::read_recording(&record).unwrap();
    let key = flexdyn_proto::fsw_key("sc1", "acs").unwrap();
    let samples: Vec<flexdyn_proto::FswMsg> = rec
        .samples
        .iter()
        .filter(|s| s.key == key)
        .map(|s| flexdyn_proto::decode_fsw(&s.payload).unwrap())
        .collect();
    assert_eq!(
        samples.len(),
        650,
        "ticks 0..650, the last one not recorded"
    );
    let mode = &decl.modes[samples.last().unwrap().mode as usize];
    let (event, t_ns) = samples
        .iter()
        .rev()
        .find_map(|m| m.event_indices().last().map(|e| (*e, m.header.sim_time_ns)))
        .expect("the FDIR raised events");
    let e = &decl.events[usize::from(event)];
    let want = format!(
        "fsw acs: mode={mode} last_event={} ({}) at t={:.3}s",
        e.name,
        e.severity.name(),
        t_ns as f64 / 1e9
    );
    // The last line is `run ended: …`; the one before is the final summary.
    assert_eq!(
        out.last().map(String::as_str),
        Some("run ended: finished at tick 650")
    );
    let summary = &out[out.len() - 2];
    assert!(
        summary.ends_with(&want),
        "{want}\nnot at the end of\n{summary}"
    );
}
