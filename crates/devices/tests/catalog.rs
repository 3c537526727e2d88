//! The shipped device lists resolve against the catalogs of the scenarios they are written
//! for, and a list is refused, naming the file, the key and the channel, against a scenario
//! that lacks one of its sensors.

use std::path::{Path, PathBuf};

use flexdyn_devices::catalog::VehicleCatalog;
use flexdyn_gateway::device::DeviceSet;
use flexdyn_proto::client::vehicle::VehicleConfig;

fn scenarios() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios")
}

fn catalog_of(scenario: &str) -> VehicleCatalog {
    let text = std::fs::read_to_string(scenarios().join(scenario)).unwrap();
    VehicleCatalog::from_config(&VehicleConfig::from_toml(&text).unwrap())
}

#[test]
fn shipped_lists_resolve_against_their_scenarios() {
    for (scenario, list, names) in [
        (
            "wheels_star_tracker.toml",
            "wheels_star_tracker.devices.toml",
            &["st1", "imu", "rw1", "rw2", "rw3", "rw4"][..],
        ),
        (
            "gateway_pointing.toml",
            "gateway_pointing.devices.toml",
            &["st1", "imu", "rw1", "rw2", "rw3", "rw4", "mag1", "gps1"][..],
        ),
    ] {
        let cat = catalog_of(scenario);
        let set = DeviceSet::load(&scenarios().join(list), cat.catalog())
            .unwrap_or_else(|e| panic!("{list} against {scenario}: {e}"));
        let got: Vec<&str> = set.devices.iter().map(|d| d.name()).collect();
        assert_eq!(got, names, "{list}");
    }
}

#[test]
fn a_list_needing_a_sensor_the_scenario_lacks_is_refused_by_name() {
    let cat = catalog_of("wheels_star_tracker.toml");
    let e = DeviceSet::load(
        &scenarios().join("gateway_pointing.devices.toml"),
        cat.catalog(),
    )
    .unwrap_err()
    .to_string();
    // wheels_star_tracker.toml has no magnetometer: mag1's description names its channels.
    assert!(e.contains("magnetometer.toml"), "{e}");
    assert!(e.contains("magnetometer.mag1"), "{e}");
}

#[test]
fn the_catalog_offers_every_sensor_field_and_actuator_input_with_its_unit() {
    let cat = catalog_of("gateway_pointing.toml");
    let c = cat.catalog();
    // 1 IMU (13), 1 tracker (6), 1 magnetometer (4), 1 GPS (16), 4 wheels (2 each).
    assert_eq!(c.channel_count(), 13 + 6 + 4 + 16 + 4 * 2);
    assert_eq!(c.group_count(), 1 + 1 + 1 + 1 + 4);
    // Four wheel torques; the scenario has no magnetorquer.
    assert_eq!(c.input_count(), 4);
    for name in [
        "imu.hub.omega_p_rad_s[2]",
        "star_tracker.st1.q_cn[3]",
        "magnetometer.mag1.b_s_t[0]",
        "gps.gps1.r_be_e_m[1]",
        "gps.gps1.valid",
        "wheel.rw4.speed_rad_s",
    ] {
        assert!(c.channel_index(name).is_some(), "{name}");
    }
    assert_eq!(c.input_index("wheel.rw3.torque_nm"), Some(2));
    // Effector inputs go to the wheels' effector indices: after the two panel pairs.
    let inputs = cat.effector_inputs(&[0.1, 0.2, 0.3, 0.4]);
    let idx: Vec<u32> = inputs.iter().map(|i| i.effector_index).collect();
    assert_eq!(idx, [2, 3, 4, 5]);
    assert_eq!(inputs[3].values, [0.4]);
}
