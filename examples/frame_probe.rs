//! The server's frame loop on `scenarios/leo_environment.toml` (everything on at 10 Hz), for
//! `perf`: `cargo build --release --example frame_probe && perf record target/release/examples/frame_probe 20000`.
fn main() {
    let frames: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    let text = include_str!("../scenarios/leo_environment.toml");
    let start = text.find("[[magnetometers]]").unwrap();
    let cfg = flexdyn_vehicle::config::SimConfig::from_toml_str(&text[..start]).unwrap();
    let mut sim = flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap();
    let t0 = std::time::Instant::now();
    for _ in 0..frames {
        sim.step_frame();
        let tick = sim.t_sim_ns() / sim.frame_ns();
        sim.sample_sensors(|s| s.due(tick));
    }
    let ns = t0.elapsed().as_nanos() as f64 / (frames * sim.steps_per_frame()) as f64;
    println!("{ns:.1} ns/step; t = {} ns", sim.t_sim_ns());
}
