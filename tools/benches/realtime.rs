//! Real-time timing at 1 kHz with the demo controller attached, and telemetry latency.
//!
//! The server runs in this process (1 kHz frames, one RK4 step each), the demo controller
//! `flexdyn-acs-demo` is a child process, and an observer session in this process (connected
//! over loopback TCP like any other subscriber) measures the telemetry latency: its receipt
//! time minus the frame-boundary stamp carried in each sample's attachment.
//!
//! Each round measures, one after the other (so a change in machine load hits every column):
//! 1. the one-way latency of a plain Zenoh hop: half the median round trip of a ping-pong of
//!    StateMsg-sized samples against `flexdyn-pingpong pong` (a child process answering in its
//!    callback), the peer of the telemetry latency;
//! 2. the server with `handoff = "direct"` (the default `auto` without `--record`: the physics
//!    thread publishes at the
//!    boundary), `--record` off;
//! 3. the server with `handoff = "thread"` (the previous design: a telemetry thread
//!    publishes), `--record` off;
//! 4. `handoff = "direct"` with `--record` on;
//! 5. `handoff = "thread"` with `--record` on.
//!
//! It prints frame lateness p50/p99/max, overruns, dropped telemetry, command freshness, the
//! telemetry latency p50/p99 and (direct) the time publishing took the physics thread, then
//! the medians side by side. Targets on an idle machine: telemetry latency p50 ≤ 1.3 × the
//! one-way hop, lateness p99 ≤ 50 µs, no overruns, and neither the direct publication nor
//! recording changing the overruns beyond round-to-round noise.
//!
//! `cargo bench -p flexdyn-tools --bench realtime`; environment: `FLEXDYN_BENCH_RT_S`
//! (default 30 s per run), `FLEXDYN_BENCH_RT_ROUNDS` (default 3, at most 8),
//! `FLEXDYN_BENCH_RT_PRIORITY` (the server's `realtime_priority`, default 0: normal
//! scheduling; e.g. 50 puts the physics thread under SCHED_FIFO, which needs CAP_SYS_NICE).
//! Every process listens on a port the OS chose (port 0) and reports it.

use flexdyn_testkit::demo_bin;
use flexdyn_testkit::median;
use flexdyn_testkit_server as support;

use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn_proto::client::transport::unix_now_ns;
use flexdyn_proto::{decode_state, Topics};
use flexdyn_server::{frame_stamp_ns, Handoff, ServerSettings};
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
    direct_publish_mean_us: f64,
    direct_publish_max_us: f64,
    direct_publish_slow: u64,
}

/// \[µs\] half the median round trip of 5000 StateMsg-sized pings (after 500 unmeasured).
fn one_way_us() -> f64 {
    let mut rtts = pingpong_rtts(500, 5000, false);
    rtts.sort_unstable();
    rtts[rtts.len() / 2].as_secs_f64() * 1e6 / 2.0
}

fn round(
    seconds: f64,
    realtime_priority: u8,
    handoff: Handoff,
    record: Option<std::path::PathBuf>,
) -> Round {
    let cfg = reference_config(1000.0);
    let frames = (seconds * 1000.0).round() as u64;
    let settings = ServerSettings {
        duration_ns: Some(frames * cfg.frame_ns),
        summary_interval: Duration::from_secs(10),
        realtime_priority,
        handoff,
        record,
        ..ServerSettings::default()
    };
    let server = ServerHandle::start(settings, cfg);
    let port = server.port;
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
    let _ctrl = ChildGuard::spawn(Command::new(demo_bin::acs_demo()).args([
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
    let (direct_mean, direct_max, direct_slow) = report.handoff.map_or((0.0, 0.0, 0), |c| {
        (c.mean_ns * 1e-3, c.max_ns as f64 * 1e-3, c.slow_frames)
    });
    if report.handoff.is_some() {
        println!(
            "  publishing on the physics thread: mean {direct_mean:.1} us, max {direct_max:.1} us \
             per frame; {direct_slow} frames over 100 us"
        );
    }
    Round {
        lateness_p50_us: us(t.lateness_p50_ns),
        lateness_p99_us: us(t.lateness_p99_ns),
        lateness_max_us: us(t.lateness_max_ns),
        overruns: t.overrun_count,
        telemetry_dropped: report.telemetry_dropped,
        latency_p50_us: us(percentile(&lat, 0.5).unwrap_or(0)),
        latency_p99_us: us(percentile(&lat, 0.99).unwrap_or(0)),
        recorded: report.recording.map(|r| (r.stats.samples, r.dropped)),
        direct_publish_mean_us: direct_mean,
        direct_publish_max_us: direct_max,
        direct_publish_slow: direct_slow,
    }
}

fn main() {
    let seconds: f64 = std::env::var("FLEXDYN_BENCH_RT_S")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(30.0);
    let rounds: usize = std::env::var("FLEXDYN_BENCH_RT_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3)
        .clamp(1, 8);
    let realtime_priority: u8 = std::env::var("FLEXDYN_BENCH_RT_PRIORITY")
        .ok()
        .map(|v| {
            v.parse()
                .expect("FLEXDYN_BENCH_RT_PRIORITY: an integer 0..=99")
        })
        .unwrap_or(0);
    println!(
        "real-time benchmark: 1 kHz, {seconds} s per run with the demo controller, {rounds} \
         rounds of [ping-pong, handoff direct, handoff thread, each again with --record], 2-core \
         machine"
    );
    println!("physics thread realtime_priority = {realtime_priority} (0: normal scheduler)");
    let dir = std::env::temp_dir().join(format!("flexdyn-bench-rt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (mut one_way, mut direct, mut thread) = (Vec::new(), Vec::new(), Vec::new());
    let (mut on, mut thread_on) = (Vec::new(), Vec::new());
    for r in 0..rounds {
        let ow = one_way_us();
        println!(
            "round {}: one-way Zenoh hop (half the median ping-pong rtt): {ow:.1} us",
            r + 1
        );
        one_way.push(ow);
        println!("round {} handoff direct, --record off:", r + 1);
        direct.push(round(seconds, realtime_priority, Handoff::Direct, None));
        println!("round {} handoff thread, --record off:", r + 1);
        thread.push(round(seconds, realtime_priority, Handoff::Thread, None));
        for (handoff, name, out) in [
            (Handoff::Direct, "direct", &mut on),
            (Handoff::Thread, "thread", &mut thread_on),
        ] {
            let file = dir.join(format!("round{r}-{name}.mcap"));
            println!(
                "round {} handoff {name}, --record on ({}):",
                r + 1,
                file.display()
            );
            let rec = round(seconds, realtime_priority, handoff, Some(file.clone()));
            if let Some((samples, dropped)) = rec.recorded {
                let bytes = std::fs::metadata(&file).map_or(0, |m| m.len());
                println!("  recorded {samples} samples, {dropped} dropped, file {bytes} bytes");
            }
            out.push(rec);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    let col = |v: &[Round], f: fn(&Round) -> f64| median(v.iter().map(f).collect());
    let ow = median(one_way.clone());
    println!("median one-way Zenoh hop over {rounds} rounds: {ow:.1} us");
    println!(
        "medians over {rounds} rounds               direct      thread  direct+rec  thread+rec  \
         direct/thread"
    );
    type Metric = fn(&Round) -> f64;
    let rows: [(&str, Metric); 10] = [
        ("frame lateness p50 (us)", |r| r.lateness_p50_us),
        ("frame lateness p99 (us)", |r| r.lateness_p99_us),
        ("frame lateness max (us)", |r| r.lateness_max_us),
        ("overruns", |r| r.overruns as f64),
        ("telemetry dropped", |r| r.telemetry_dropped as f64),
        ("telemetry latency p50 (us)", |r| r.latency_p50_us),
        ("telemetry latency p99 (us)", |r| r.latency_p99_us),
        ("publish on physics thread mean (us)", |r| {
            r.direct_publish_mean_us
        }),
        ("publish on physics thread max (us)", |r| {
            r.direct_publish_max_us
        }),
        ("publishes over 100 us", |r| r.direct_publish_slow as f64),
    ];
    for (name, f) in rows {
        let (a, b, c, d) = (
            col(&direct, f),
            col(&thread, f),
            col(&on, f),
            col(&thread_on, f),
        );
        let ratio = if b > 0.0 {
            format!("{:.2}", a / b)
        } else {
            "-".into()
        };
        println!("{name:<36} {a:>11.1} {b:>11.1} {c:>11.1} {d:>11.1} {ratio:>14}");
    }
    let lat: Vec<f64> = direct
        .iter()
        .zip(&one_way)
        .map(|(r, ow)| r.latency_p50_us / ow)
        .collect();
    let lat_t: Vec<f64> = thread
        .iter()
        .zip(&one_way)
        .map(|(r, ow)| r.latency_p50_us / ow)
        .collect();
    println!(
        "telemetry latency p50 / one-way hop, median of the per-round ratios: direct {:.2} \
         (target <= 1.3), thread {:.2}",
        median(lat),
        median(lat_t)
    );
    let dropped: u64 = on
        .iter()
        .chain(&thread_on)
        .filter_map(|r| r.recorded)
        .map(|(_, d)| d)
        .sum();
    println!("recorder drops over all rounds: {dropped}");
}

/// Round-trip times of `count` StateMsg-sized pings after `warmup` ones, against a
/// `flexdyn-pingpong pong` child ([`flexdyn_tools::pingpong::round_trips`]).
fn pingpong_rtts(warmup: usize, count: usize, recv_loop: bool) -> Vec<Duration> {
    let pong = std::path::Path::new(env!("CARGO_BIN_EXE_flexdyn-pingpong"));
    flexdyn_tools::pingpong::round_trips(pong, warmup, count, recv_loop).expect("ping-pong")
}
