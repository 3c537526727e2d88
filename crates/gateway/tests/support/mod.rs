//! What both test executables (`tests/main.rs` and `tests/no_alloc.rs`, which installs its own
//! allocator) share: the shipped device list and the catalog it is resolved against. Each
//! includes this file as `mod support;`.

use std::path::{Path, PathBuf};

use flexdyn_gateway::device::Catalog;

/// The frame period of `scenarios/wheels_star_tracker.toml` (100 Hz).
pub const FRAME_NS: u64 = 10_000_000;

/// The catalog the runtime offers for wheels_star_tracker plus a magnetometer and a GPS
/// receiver, in the vocabulary the runtime uses: its sensor groups, then the wheels' torque
/// inputs.
pub fn catalog() -> Catalog {
    let mut c = Catalog::new(FRAME_NS);
    c.add_group(
        "imu.hub",
        &[
            ("omega_p_rad_s[0]", "rad/s"),
            ("omega_p_rad_s[1]", "rad/s"),
            ("omega_p_rad_s[2]", "rad/s"),
            ("saturation_flags", "1"),
        ],
    );
    c.add_group(
        "star_tracker.st1",
        &[
            ("q_cn[0]", "1"),
            ("q_cn[1]", "1"),
            ("q_cn[2]", "1"),
            ("q_cn[3]", "1"),
            ("valid", "1"),
            ("status_flags", "1"),
        ],
    );
    c.add_group(
        "magnetometer.mag1",
        &[
            ("b_s_t[0]", "T"),
            ("b_s_t[1]", "T"),
            ("b_s_t[2]", "T"),
            ("saturation_flags", "1"),
        ],
    );
    c.add_group(
        "gps.gps1",
        &[
            ("gps_week", "1"),
            ("gps_seconds_of_week", "s"),
            ("r_be_e_m[0]", "m"),
            ("r_be_e_m[1]", "m"),
            ("r_be_e_m[2]", "m"),
            ("v_be_e_m_s[0]", "m/s"),
            ("v_be_e_m_s[1]", "m/s"),
            ("v_be_e_m_s[2]", "m/s"),
            ("valid", "1"),
            ("flags", "1"),
        ],
    );
    for w in 1..=4 {
        c.add_group(&format!("wheel.rw{w}"), &[("speed_rad_s", "rad/s")]);
    }
    for w in 1..=4 {
        c.add_input(&format!("wheel.rw{w}.torque_nm"), "N m");
    }
    c
}

/// The shipped device list.
pub fn shipped_list() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/gateway_pointing.devices.toml")
}
