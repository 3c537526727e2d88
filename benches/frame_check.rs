//! The cost of the once-per-frame non-finite check against the frame it guards.
//!
//! The server and `simulate` check every frame's state record (and IMU samples) for NaN or
//! infinity before publishing or writing it, outside the RK4 loop. This bench times, on the
//! reference spacecraft (10 RK4 steps per 100 Hz frame), the frame's integration
//! (`step_frame`), the state record the frame publishes anyway (`state_into`), and the check
//! alone (`first_non_finite` on a finite record), as medians over 31 batches of 2,000 frames,
//! and prints the check's share of a frame.

use std::hint::black_box;
use std::time::Instant;

use flexdyn_sinks::table::first_non_finite;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

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
    let mut state = sim.blank_state();
    let frame = median_ns_per_frame(|| {
        sim.step_frame();
        black_box(sim.t_sim_ns());
    });
    let state_fill = median_ns_per_frame(|| {
        sim.state_into(&mut state);
        black_box(&state);
    });
    sim.state_into(&mut state);
    let check = median_ns_per_frame(|| {
        black_box(first_non_finite(black_box(&state)));
    });
    println!("frame_check (reference spacecraft, {} steps per frame; medians of {BATCHES} x {FRAMES} frames)", cfg.steps_per_frame());
    println!("  step_frame        {frame:>10.1} ns");
    println!("  state_into        {state_fill:>10.1} ns");
    println!(
        "  first_non_finite  {check:>10.1} ns  ({:.2} % of step_frame + state_into)",
        100.0 * check / (frame + state_fill)
    );
}
