//! The cost of a checkpoint (issue 40 §2): saving the complete state of a run, its file size,
//! and reading it back into a freshly built run, for the reference spacecraft and the full ACS
//! scenario (`scenarios/acs_full.toml`), each after 10 s of flight.
//!
//! Each figure is the median of the rounds, printed beside the same run's frame, so the ratio
//! says how many frames a save would hold the stepping thread (save / frame period) and how it
//! compares with stepping one frame (save / frame cost).
//!
//! `cargo bench --bench checkpoint`; environment `FLEXDYN_BENCH_ROUNDS` (default 200).

use flexdyn_testkit::median;
use std::hint::black_box;
use std::time::Instant;

use flexdyn_vehicle::checkpoint::{self, Checkpoint, CheckpointHeader};
use flexdyn_vehicle::config::{SimConfig, DEFAULT_CONFIG_TOML};
use flexdyn_vehicle::sim::Simulation;
use flexdyn_vehicle::world::World;

const ACS_FULL: &str = include_str!("../scenarios/acs_full.toml");

fn world(text: &str) -> (World, SimConfig) {
    let cfg = SimConfig::from_toml_str(text).expect("the scenario parses");
    let sim = Simulation::new(&cfg).expect("the scenario builds");
    (World::of_one("sc1".into(), 1, sim), cfg)
}

fn main() {
    let rounds: usize = std::env::var("FLEXDYN_BENCH_ROUNDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    println!("checkpoint: {rounds} rounds per figure, each case after 10 s of flight");
    println!(
        "{:<10} {:>9} {:>10} {:>12} {:>10} {:>11} {:>12} {:>12}",
        "case",
        "bytes",
        "save µs",
        "restore µs",
        "frame µs",
        "period µs",
        "save/period",
        "save/frame"
    );
    for (label, text) in [("reference", DEFAULT_CONFIG_TOML), ("acs_full", ACS_FULL)] {
        let (mut w, cfg) = world(text);
        let steps_per_frame = w.steps_per_frame();
        w.step_n(10_000_000_000 / cfg.step_ns);
        let header = CheckpointHeader {
            front_end: "simulate".into(),
            source_text: text.into(),
            source_sha256: CheckpointHeader::digest(text),
            step_ns: cfg.step_ns,
            frame_ns: cfg.frame_ns,
            ..CheckpointHeader::default()
        };
        let mut save_us = Vec::with_capacity(rounds);
        let mut frame_us = Vec::with_capacity(rounds);
        let mut bytes = Vec::new();
        for _ in 0..rounds {
            let t = Instant::now();
            bytes = black_box(checkpoint::save(&header, &mut w).expect("saves"));
            save_us.push(t.elapsed().as_secs_f64() * 1e6);
            let t = Instant::now();
            w.step_n(steps_per_frame);
            frame_us.push(t.elapsed().as_secs_f64() * 1e6);
        }
        let (mut fresh, _) = world(text);
        let mut restore_us = Vec::with_capacity(rounds);
        for _ in 0..rounds {
            let t = Instant::now();
            let c = Checkpoint::parse(&bytes).expect("parses");
            c.restore(&mut fresh).expect("restores");
            restore_us.push(t.elapsed().as_secs_f64() * 1e6);
        }
        let (save, restore, frame) = (median(save_us), median(restore_us), median(frame_us));
        let period_us = cfg.frame_ns as f64 / 1e3;
        println!(
            "{label:<10} {:>9} {save:>10.1} {restore:>12.1} {frame:>10.1} {period_us:>11.0} {:>12.4} {:>12.2}",
            bytes.len(),
            save / period_us,
            save / frame
        );
    }
}
