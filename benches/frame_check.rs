//! The cost of the once-per-frame non-finite check against the frame it guards.
//!
//! The server and `simulate` check every frame's snapshot (and IMU samples) for NaN or infinity
//! before publishing or writing it, outside the RK4 loop. This bench times, on the reference
//! spacecraft (10 RK4 steps per 100 Hz frame), the frame's integration (`step_frame`), the
//! snapshot the frame publishes anyway (`snapshot_into`), and the check alone
//! (`first_non_finite` on a finite snapshot), as medians over 31 batches of 2,000 frames, and
//! prints the check's share of a frame.

use std::hint::black_box;
use std::time::Instant;

use flexdyn::config::SimConfig;
use flexdyn::sim::{Simulation, Snapshot};

const BATCHES: usize = 31;
const FRAMES: usize = 2_000;

fn median_ns_per_frame(mut f: impl FnMut()) -> f64 {
    let mut per = Vec::with_capacity(BATCHES);
    for _ in 0..BATCHES {
        let t0 = Instant::now();
        for _ in 0..FRAMES {
            f();
        }
        per.push(t0.elapsed().as_nanos() as f64 / FRAMES as f64);
    }
    per.sort_by(|a, b| a.total_cmp(b));
    per[BATCHES / 2]
}

fn main() {
    let cfg = SimConfig::reference();
    let mut sim = Simulation::new(&cfg).expect("reference builds");
    let mut snap = Snapshot::for_simulation(&sim);
    let frame = median_ns_per_frame(|| {
        sim.step_frame();
        black_box(sim.t_sim_ns());
    });
    let snapshot = median_ns_per_frame(|| {
        sim.snapshot_into(&mut snap);
        black_box(&snap);
    });
    sim.snapshot_into(&mut snap);
    let check = median_ns_per_frame(|| {
        black_box(black_box(&snap).first_non_finite());
    });
    println!("frame_check (reference spacecraft, {} steps per frame; medians of {BATCHES} x {FRAMES} frames)", cfg.steps_per_frame());
    println!("  step_frame        {frame:>10.1} ns");
    println!("  snapshot_into     {snapshot:>10.1} ns");
    println!(
        "  first_non_finite  {check:>10.1} ns  ({:.2} % of step_frame + snapshot_into)",
        100.0 * check / (frame + snapshot)
    );
}
