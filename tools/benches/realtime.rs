//! Real-time timing at 1 kHz with the demo controller attached, and telemetry latency.
//!
//! The server runs in this process (1 kHz frames, one RK4 step each), the demo controller
//! `flexdyn-acs-demo` is a child process, and an observer session in this process (connected
//! over loopback TCP like any other subscriber) measures the telemetry latency: its receipt
//! time minus the frame-boundary stamp carried in each sample's attachment.
//!
//! Prints frame lateness p50/p99/max, overruns, dropped telemetry, command freshness and the
//! telemetry latency p50/p99, for rounds with `--record` off and on alternating, then the
//! medians side by side. Targets on an idle machine: lateness p99 ≤ 50 µs, no overruns, and
//! recording changing neither beyond round-to-round noise.
//!
//! `cargo bench -p flexdyn-tools --bench realtime`; environment: `FLEXDYN_BENCH_RT_S`
//! (default 30 s per round), `FLEXDYN_BENCH_RT_ROUNDS` (default 3 of each), `FLEXDYN_BENCH_RT_PRIORITY` (the server's `realtime_priority`, default 0:
//! normal scheduling; e.g. 50 puts the physics thread under SCHED_FIFO, which needs
//! CAP_SYS_NICE). Ports 17450–17459.

#[path = "../tests/support/mod.rs"]
mod support;

use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn::server::{frame_stamp_ns, ServerSettings};
use flexdyn::transport::unix_now_ns;
use flexdyn_proto::{decode_state, Topics};
use flexdyn_tools::percentile;
use support::{connecting_session, endpoint, reference_config, ChildGuard, ServerHandle};
use zenoh::Wait;

/// What one real-time round measured.
struct Round {
    lateness_p50_us: f64,
    lateness_p99_us: f64,
    lateness_max_us: f64,
    overruns: u64,
    telemetry_dropped: u64,
    latency_p50_us: f64,
    latency_p99_us: f64,
    recorded: Option<(u64, u64)>,
}

fn round(
    port: u16,
    seconds: f64,
    realtime_priority: u8,
    record: Option<std::path::PathBuf>,
) -> Round {
    let cfg = reference_config(1000.0);
    let frames = (seconds * 1000.0).round() as u64;
    let settings = ServerSettings {
        duration_ns: Some(frames * cfg.frame_ns),
        summary_interval: Duration::from_secs(10),
        realtime_priority,
        record,
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
        "  frame lateness: p50 {:.1} us, p99 {:.1} us, max {:.1} us; overruns {}; frames skipped {}; \
         telemetry dropped {}",
        us(t.lateness_p50_ns),
        us(t.lateness_p99_ns),
        us(t.lateness_max_ns),
        t.overrun_count,
        t.frames_skipped,
        report.telemetry_dropped
    );
    println!(
        "  telemetry latency (frame boundary -> subscriber): p50 {:.1} us, p99 {:.1} us, max {:.1} us \
         over {} samples ({} frames)",
        us(percentile(&lat, 0.5).unwrap_or(0)),
        us(percentile(&lat, 0.99).unwrap_or(0)),
        us(lat.last().copied().unwrap_or(0)),
        lat.len(),
        frames + 1
    );
    println!(
        "  controller: {fresh} frames with a fresh command, {flagged} flagged (no command yet or stale)"
    );
    Round {
        lateness_p50_us: us(t.lateness_p50_ns),
        lateness_p99_us: us(t.lateness_p99_ns),
        lateness_max_us: us(t.lateness_max_ns),
        overruns: t.overrun_count,
        telemetry_dropped: report.telemetry_dropped,
        latency_p50_us: us(percentile(&lat, 0.5).unwrap_or(0)),
        latency_p99_us: us(percentile(&lat, 0.99).unwrap_or(0)),
        recorded: report.recording.map(|r| (r.stats.samples, r.dropped)),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let seconds: f64 = std::env::var("FLEXDYN_BENCH_RT_S")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(30.0);
    let rounds: usize = std::env::var("FLEXDYN_BENCH_RT_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    let realtime_priority: u8 = std::env::var("FLEXDYN_BENCH_RT_PRIORITY")
        .ok()
        .map(|v| {
            v.parse()
                .expect("FLEXDYN_BENCH_RT_PRIORITY: an integer 0..=99")
        })
        .unwrap_or(0);
    println!(
        "real-time benchmark: 1 kHz, {seconds} s per round with the demo controller, {rounds} \
         rounds each with --record off and on (alternating), 2-core machine"
    );
    println!("physics thread realtime_priority = {realtime_priority} (0: normal scheduler)");
    let dir = std::env::temp_dir().join(format!("flexdyn-bench-rt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut off = Vec::new();
    let mut on = Vec::new();
    for r in 0..rounds {
        let port = 17450 + 2 * r as u16;
        println!("round {} --record off:", r + 1);
        off.push(round(port, seconds, realtime_priority, None));
        let file = dir.join(format!("round{r}.mcap"));
        println!("round {} --record on ({}):", r + 1, file.display());
        let rec = round(port + 1, seconds, realtime_priority, Some(file.clone()));
        if let Some((samples, dropped)) = rec.recorded {
            let bytes = std::fs::metadata(&file).map_or(0, |m| m.len());
            println!("  recorded {samples} samples, {dropped} dropped, file {bytes} bytes");
        }
        on.push(rec);
    }
    let _ = std::fs::remove_dir_all(&dir);
    let col = |v: &[Round], f: fn(&Round) -> f64| median(v.iter().map(f).collect());
    println!("medians over {rounds} rounds           record off   record on   on/off");
    type Metric = fn(&Round) -> f64;
    let rows: [(&str, Metric); 7] = [
        ("frame lateness p50 (us)", |r| r.lateness_p50_us),
        ("frame lateness p99 (us)", |r| r.lateness_p99_us),
        ("frame lateness max (us)", |r| r.lateness_max_us),
        ("overruns", |r| r.overruns as f64),
        ("telemetry dropped", |r| r.telemetry_dropped as f64),
        ("telemetry latency p50 (us)", |r| r.latency_p50_us),
        ("telemetry latency p99 (us)", |r| r.latency_p99_us),
    ];
    for (name, f) in rows {
        let (a, b) = (col(&off, f), col(&on, f));
        let ratio = if a > 0.0 {
            format!("{:.2}", b / a)
        } else {
            "-".into()
        };
        println!("{name:<32} {a:>11.1} {b:>11.1} {ratio:>8}");
    }
    let dropped: u64 = on.iter().filter_map(|r| r.recorded).map(|(_, d)| d).sum();
    println!("recorder drops over all rounds: {dropped}");
}
