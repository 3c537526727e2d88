//! Real-time timing at 1 kHz with the demo controller attached, and telemetry latency.
//!
//! The server runs in this process (1 kHz frames, one RK4 step each), the demo controller
//! `flexdyn-acs-demo` is a child process, and an observer session in this process (connected
//! over loopback TCP like any other subscriber) measures the telemetry latency: its receipt
//! time minus the frame-boundary stamp carried in each sample's attachment.
//!
//! Prints frame lateness p50/p99/max, overruns, dropped telemetry, command freshness and the
//! telemetry latency p50/p99. Targets on an idle machine: lateness p99 ≤ 50 µs, no overruns.
//!
//! `cargo bench -p flexdyn-tools --bench realtime`; environment: `FLEXDYN_BENCH_RT_S`
//! (default 60 s), `FLEXDYN_BENCH_RT_PRIORITY` (the server's `realtime_priority`, default 0:
//! normal scheduling; e.g. 50 puts the physics thread under SCHED_FIFO, which needs
//! CAP_SYS_NICE). Ports 17450–17459.

#[path = "../tests/support/mod.rs"]
mod support;

use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use flexdyn::server::{frame_stamp_ns, ServerSettings};
use flexdyn_proto::{decode_state, Topics};
use flexdyn_tools::percentile;
use support::{connecting_session, endpoint, reference_config, ChildGuard, ServerHandle};
use zenoh::Wait;

fn unix_now_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

fn main() {
    let seconds: f64 = std::env::var("FLEXDYN_BENCH_RT_S")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(60.0);
    let port = 17450;
    let cfg = reference_config(1000.0);
    let frames = (seconds * 1000.0).round() as u64;
    println!("real-time benchmark: 1 kHz for {seconds} s with the demo controller, 2-core machine");
    let realtime_priority: u8 = std::env::var("FLEXDYN_BENCH_RT_PRIORITY")
        .ok()
        .map(|v| {
            v.parse()
                .expect("FLEXDYN_BENCH_RT_PRIORITY: an integer 0..=99")
        })
        .unwrap_or(0);
    println!("physics thread realtime_priority = {realtime_priority} (0: normal scheduler)");
    let settings = ServerSettings {
        duration_ns: Some(frames * cfg.frame_ns),
        summary_interval: Duration::from_secs(10),
        realtime_priority,
        ..ServerSettings::default()
    };
    let server = ServerHandle::start(port, settings, cfg);
    let topics = Topics::new("sc1").unwrap();

    // Observer: latency of every state sample, and whether its command was fresh.
    let latencies: Arc<Mutex<Vec<u64>>> =
        Arc::new(Mutex::new(Vec::with_capacity(frames as usize + 1)));
    let flags: Arc<Mutex<[u64; 2]>> = Arc::default();
    let session = connecting_session(port);
    let (lat, fl) = (latencies.clone(), flags.clone());
    let _sub = session
        .declare_subscriber(topics.state())
        .callback(move |sample| {
            let now = unix_now_ns();
            if let Some(stamp) = frame_stamp_ns(&sample) {
                lat.lock().unwrap().push(now.saturating_sub(stamp));
            }
            if let Ok(s) = decode_state(&sample.payload().to_bytes()) {
                fl.lock().unwrap()[usize::from(s.command_flags == 0)] += 1;
            }
        })
        .wait()
        .unwrap();
    let _ctrl = ChildGuard::spawn(Command::new(env!("CARGO_BIN_EXE_flexdyn-acs-demo")).args([
        "--connect",
        &endpoint(port),
        "--log-every-s",
        "0",
    ]));
    let report = server
        .join(Duration::from_secs_f64(seconds + 60.0))
        .expect("real-time run");
    std::thread::sleep(Duration::from_millis(200));
    let mut lat = latencies.lock().unwrap().clone();
    lat.sort_unstable();
    let [flagged, fresh] = *flags.lock().unwrap();
    let us = |ns: u64| ns as f64 * 1e-3;
    let t = report.timing;
    println!("{report}");
    println!(
        "frame lateness: p50 {:.1} us, p99 {:.1} us, max {:.1} us; overruns {}; frames skipped {}; \
         telemetry dropped {}",
        us(t.lateness_p50_ns),
        us(t.lateness_p99_ns),
        us(t.lateness_max_ns),
        t.overrun_count,
        t.frames_skipped,
        report.telemetry_dropped
    );
    println!(
        "telemetry latency (frame boundary -> subscriber): p50 {:.1} us, p99 {:.1} us, max {:.1} us \
         over {} samples ({} of {} frames)",
        us(percentile(&lat, 0.5).unwrap_or(0)),
        us(percentile(&lat, 0.99).unwrap_or(0)),
        us(lat.last().copied().unwrap_or(0)),
        lat.len(),
        lat.len(),
        frames + 1
    );
    println!(
        "controller: {fresh} frames with a fresh command, {flagged} flagged (no command yet or stale)"
    );
}
