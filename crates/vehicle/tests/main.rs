//! The vehicle layer's tests, one executable: the configuration file read into a spacecraft with
//! its effectors, sensors, faults and environment, stepped offline, alone and as a world of
//! vehicles. They check closed forms, invariants, independent references and the sensors'
//! statistics, and that stepping allocates nothing. Nothing here links an I/O stack; the tests
//! that need the server, the binary or a client stay in the root package's `tests/`.

// The allocation-free checks (actuators, environment_alloc, imu_alloc) count this thread's
// allocations.
#[global_allocator]
static GLOBAL: flexdyn_testkit::alloc_counter::Counting = flexdyn_testkit::alloc_counter::Counting;

/// The repository's root, where `scenarios/` is.
pub const REPO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// Without a counting allocator every "allocates nothing" test here would pass for nothing.
#[test]
fn the_allocation_counter_is_installed() {
    flexdyn_testkit::alloc_counter::assert_installed();
}

/// The kind of every entry of `sc`'s effector list, in order.
pub fn effector_kind_names(sc: &flexdyn_dynamics::Spacecraft) -> Vec<&'static str> {
    sc.effector_entries().map(|e| e.kind.name).collect()
}

/// Each case `(from, to, field, words)`: the configuration `text` with `from` (found exactly
/// once) replaced by `to` is refused with one error that starts with and names `field` and says
/// `words`. Returns the messages, for what a caller checks beyond that.
pub fn config_error_cases(text: &str, cases: &[(&str, &str, &str, &str)]) -> Vec<String> {
    let mut messages = Vec::new();
    for &(from, to, field, words) in cases {
        assert_eq!(text.matches(from).count(), 1, "{from}");
        let bad = text.replace(from, to);
        let err = flexdyn_vehicle::config::SimConfig::from_toml_str(&bad).unwrap_err();
        let msg = err.to_string();
        eprintln!("{msg}");
        assert!(msg.starts_with(field), "{msg}");
        assert_eq!(err.field(), Some(field), "{msg}");
        assert!(msg.contains(words), "{msg}");
        messages.push(msg);
    }
    messages
}

// Shared by the files below.
#[allow(dead_code)]
mod imu_support;
mod rigid_hub;
#[allow(dead_code)]
mod sensor_faults_support;

mod actuators;
mod dynamic_effector;
mod effector_input_schedule;
mod environment_alloc;
mod environment_constants;
mod environment_prefetch;
mod environment_world;
mod faults_actuators;
mod faults_sensor_matrix;
mod faults_sensors;
mod fleet_cw;
mod fleet_world;
mod gravity_gradient;
mod imu_alloc;
mod imu_config;
mod imu_panel_modes;
mod imu_truth;
mod panel_chain;
mod propellant_tank;
mod reaction_wheels;
mod rk4_bit_identity;
mod slosh;
mod star_tracker;
mod surface_forces;
