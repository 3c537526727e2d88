//! Checkpoints of a real-time server: does writing them stall the physics thread?
//!
//! Issue 40 §2 asks that "the physics thread does not stall longer than one frame while a
//! checkpoint is written in real time". The server lists the state on the physics thread at the
//! checkpoint's boundary and leaves the checksum and the file to its writer thread
//! (`crates/server/src/checkpoint.rs`); this measures what that costs the frames.
//!
//! Each round runs `scenarios/acs_full.toml` at a 50 Hz frame (two 10 ms RK4 steps per frame,
//! the fastest its thrusters' 20 ms minimum on-time allows;
//! every sensor and environment model on) in real time in this process, twice, one after the
//! other: without checkpoints, then with an operator asking for a checkpoint every 0.5 s
//! (OperatorMsg `Checkpoint`, written into a temporary `--checkpoint-dir`). It prints each
//! run's frame lateness p50/p99/max and overruns, and for the second the checkpoints written and
//! the longest time the physics thread spent listing one, beside the frame period (the target:
//! well under 1), and the runs' max lateness with and without checkpoints (on a shared VM the
//! max lateness alone varies by milliseconds from run to run; compare the medians).
//!
//! `cargo bench -p flexdyn-tools --bench checkpoint_realtime`; environment:
//! `FLEXDYN_BENCH_CKPT_S` (simulated seconds per run, default 10), `FLEXDYN_BENCH_CKPT_ROUNDS`
//! (default 2). Every session listens on a port the OS chose.

use flexdyn_testkit::median;
use flexdyn_testkit_server as support;

use std::path::Path;
use std::time::{Duration, Instant};

use flexdyn_proto::{encode, Header, OperatorAction, OperatorMsg, Topics};
use flexdyn_server::checkpoint::CheckpointSettings;
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::checkpoint::Source;
use flexdyn_vehicle::config::SimConfig;
use support::{connecting_session, ServerHandle};
use zenoh::Wait;

/// The frame the bench runs at \[Hz\].
const FRAME_HZ: f64 = 50.0;

struct Run {
    lateness_p50_us: f64,
    lateness_p99_us: f64,
    lateness_max_us: f64,
    overruns: u64,
    written: u64,
    failed: u64,
    max_list_us: f64,
}

fn acs_full_50hz() -> (SimConfig, Source) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/acs_full.toml");
    let mut source = Source::of(Some(&path)).expect("scenarios/acs_full.toml");
    source.text =
        source
            .text
            .replacen("frame_hz = 10.0 ", &format!("frame_hz = {FRAME_HZ:.1} "), 1);
    let cfg = source.config().expect("acs_full at 50 Hz");
    assert_eq!(cfg.frame_ns, 20_000_000, "the frame is 50 Hz");
    (cfg, source)
}

fn run(seconds: f64, checkpoint_every_s: Option<f64>) -> Run {
    let (cfg, source) = acs_full_50hz();
    let frames = (seconds * FRAME_HZ).round() as u64;
    let dir = std::env::temp_dir().join(format!("flexdyn-bench-ckpt-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a temporary directory");
    let settings = ServerSettings {
        duration_ns: Some(frames * cfg.frame_ns),
        summary_interval: Duration::from_secs(60),
        checkpoints: CheckpointSettings {
            dir: checkpoint_every_s.map(|_| dir.clone()),
            source,
            ..CheckpointSettings::default()
        },
        ..ServerSettings::default()
    };
    let server = ServerHandle::start(settings, cfg);
    let topics = Topics::new("sc1").expect("sc1");
    if let Some(every) = checkpoint_every_s {
        let op = connecting_session(server.port);
        let started = Instant::now();
        let mut seq = 0;
        while started.elapsed().as_secs_f64() < seconds - every {
            std::thread::sleep(Duration::from_secs_f64(every));
            let msg = OperatorMsg::new(Header::new(1, 0, 0, seq), OperatorAction::Checkpoint, 0);
            seq += 1;
            let _ = op.put(topics.operator(), encode(&msg)).wait();
        }
    }
    let report = server
        .join(Duration::from_secs_f64(seconds + 60.0))
        .expect("real-time run");
    let _ = std::fs::remove_dir_all(&dir);
    let t = report.timing;
    let us = |ns: u64| ns as f64 * 1e-3;
    let c = report.checkpoints.unwrap_or_default();
    Run {
        lateness_p50_us: us(t.lateness_p50_ns),
        lateness_p99_us: us(t.lateness_p99_ns),
        lateness_max_us: us(t.lateness_max_ns),
        overruns: t.overrun_count,
        written: c.written,
        failed: c.failed,
        max_list_us: us(c.max_list_ns),
    }
}

fn env_f64(name: &str, default: f64) -> f64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let seconds = env_f64("FLEXDYN_BENCH_CKPT_S", 10.0).max(2.0);
    let rounds = env_f64("FLEXDYN_BENCH_CKPT_ROUNDS", 2.0).clamp(1.0, 8.0) as usize;
    let period_us = 1e6 / FRAME_HZ;
    println!(
        "checkpoints of a real-time server: acs_full at {FRAME_HZ} Hz (frame {period_us:.0} us), \
         {seconds} s per run, {rounds} rounds; a checkpoint every 0.5 s in the second run"
    );
    let (mut max_with, mut max_without, mut lists) = (Vec::new(), Vec::new(), Vec::new());
    for r in 1..=rounds {
        let without = run(seconds, None);
        let with = run(seconds, Some(0.5));
        for (name, x) in [("without", &without), ("with", &with)] {
            println!(
                "  round {r} {name:>7}: lateness p50 {:.1} us, p99 {:.1} us, max {:.1} us; \
                 overruns {}; checkpoints written {}, failed {}, longest listing {:.1} us",
                x.lateness_p50_us,
                x.lateness_p99_us,
                x.lateness_max_us,
                x.overruns,
                x.written,
                x.failed,
                x.max_list_us
            );
        }
        max_with.push(with.lateness_max_us);
        max_without.push(without.lateness_max_us);
        lists.push(with.max_list_us);
    }
    let worst = max_with.iter().copied().fold(0.0, f64::max);
    let (list, with, without) = (median(lists), median(max_with), median(max_without));
    println!(
        "median longest listing on the physics thread: {list:.1} us = {:.4} of the frame; \
         median max lateness with checkpoints {with:.1} us, without {without:.1} us (ratio \
         {:.2}); worst lateness with checkpoints {worst:.1} us = {:.4} of the frame (a stall \
         of a frame or more would be >= 1)",
        list / period_us,
        with / without.max(0.1),
        worst / period_us
    );
}
