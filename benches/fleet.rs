//! Physics scaling of a fleet (issue 22): frames per second of [`World::step_frame`] with 1, 2,
//! 4, 8 and 16 vehicles, each the LEO scenario (`scenarios/leo_environment.toml`: the reference
//! spacecraft with two panel pairs, 1 ms steps, 100 Hz frames, every environment model on at
//! 10 Hz), the deputies 50 m apart along-track behind the chief.
//!
//! This is the physics alone, on one thread: no server, no Zenoh, no controllers (the
//! lockstep benchmark with one controller process per vehicle needs the server's fleet mode,
//! which is not built yet). It prints, per fleet size, the median over `ROUNDS` runs of
//! `FRAMES` frames: frames/s, the ratio to the 1-vehicle rate and the physics time per vehicle
//! per frame. With the physics linear in the vehicle count the ratio is 1/N; the
//! issue's lockstep target (≥ 0.5 × at 8 vehicles) holds only if the frame is mostly waiting
//! for the controllers, not stepping.
//!
//! `cargo bench --bench fleet`.

use std::time::Instant;

use flexdyn_vehicle::world::{FleetConfig, World};

const SIZES: [usize; 5] = [1, 2, 4, 8, 16];
const FRAMES: u32 = 1000;
const ROUNDS: usize = 5;

fn fleet(n: usize) -> FleetConfig {
    let mut text =
        String::from("[[vehicles]]\nid = \"v0\"\nspacecraft_file = \"leo_environment.toml\"\n");
    for i in 1..n {
        text += &format!(
            "\n[[vehicles]]\nid = \"v{i}\"\nspacecraft_file = \"leo_environment.toml\"\n\
             [vehicles.relative]\nchief = \"v0\"\nhill_position_m = [0.0, {}, 0.0]\n",
            -50.0 * i as f64
        );
    }
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
    FleetConfig::from_toml_str_in(&text, std::path::Path::new(dir)).expect("valid fleet")
}

fn main() {
    // `cargo bench` passes `--bench` (and maybe a filter); this bench has one measurement.
    let mut base_frames_per_s = None;
    println!("vehicles  frames/s  ratio_to_1  physics_us_per_vehicle_frame");
    for n in SIZES {
        let cfg = fleet(n);
        let mut rates = Vec::with_capacity(ROUNDS);
        for _ in 0..ROUNDS {
            let mut world = World::new(&cfg).expect("world");
            world.step_frame(); // warm the caches
            let start = Instant::now();
            for _ in 0..FRAMES {
                world.step_frame();
            }
            let s = start.elapsed().as_secs_f64();
            rates.push(f64::from(FRAMES) / s);
        }
        rates.sort_by(f64::total_cmp);
        let frames_per_s = rates[ROUNDS / 2];
        let base = *base_frames_per_s.get_or_insert(frames_per_s);
        println!(
            "{n:8}  {frames_per_s:8.1}  {:10.3}  {:28.1}",
            frames_per_s / base,
            1e6 / (frames_per_s * n as f64)
        );
    }
}
