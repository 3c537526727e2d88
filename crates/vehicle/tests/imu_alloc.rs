//! Closing an IMU interval (truth, error models, RNG) allocates nothing once the output buffer
//! exists. A counting global allocator, per thread, checks it.

use flexdyn_testkit::alloc_counter::allocations;

use std::path::Path;

use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

#[test]
fn stepping_and_sampling_imus_does_not_allocate() {
    let cfg =
        SimConfig::from_file(&Path::new(crate::REPO).join("scenarios/imu_tactical.toml")).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut out = Vec::with_capacity(sim.n_imus());
    sim.imu_samples_into(&mut out);
    let before = allocations();
    for _ in 0..200 {
        sim.step_frame();
        sim.imu_samples_into(&mut out);
    }
    let after = allocations();
    assert_eq!(out.len(), 2);
    assert_eq!(after - before, 0, "allocations while stepping and sampling");
}
