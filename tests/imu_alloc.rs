//! Closing an IMU interval (truth, error models, RNG) allocates nothing once the output buffer
//! exists. A counting global allocator, per thread, checks it.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

use flexdyn::config::SimConfig;
use flexdyn::sim::Simulation;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn stepping_and_sampling_imus_does_not_allocate() {
    let cfg = SimConfig::from_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/imu_tactical.toml"),
    )
    .unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut out = Vec::with_capacity(sim.n_imus());
    sim.imu_samples_into(&mut out);
    let before = ALLOCATIONS.with(Cell::get);
    for _ in 0..200 {
        sim.step_frame();
        sim.imu_samples_into(&mut out);
    }
    let after = ALLOCATIONS.with(Cell::get);
    assert_eq!(out.len(), 2);
    assert_eq!(after - before, 0, "allocations while stepping and sampling");
}
