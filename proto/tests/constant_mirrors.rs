//! The kind tags and flag bits are in `flexdyn_proto` (Rust, hand-written), and in the C header's
//! `#define`s and the Python package's constants (both generated from the wire table). This reads
//! the other two as text and checks every mirrored constant against the Rust one, so a mistake
//! in the table, or a kind or flag that reaches one codec and misses another, fails here.

use std::collections::HashMap;

use flexdyn_proto::{
    command_flags, effector_kind, fss_flags, magnetorquer_flags, saturation_flags,
    star_tracker_flags, thruster_flags, wheel_flags, OperatorAction,
};

/// An integer literal as both files write it: decimal or `0x…`, with an optional `u` suffix.
fn parse_int(s: &str) -> Option<u64> {
    let s = s.trim().trim_end_matches('u');
    match s.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => s.parse().ok(),
    }
}

/// `#define FD_NAME value` lines of the C header.
fn c_defines() -> HashMap<String, u64> {
    let text = include_str!("../c/include/flexdyn_proto.h");
    text.lines()
        .filter_map(|l| {
            let mut it = l.strip_prefix("#define ")?.split_whitespace();
            let name = it.next()?;
            let value = parse_int(it.next()?)?;
            Some((name.to_string(), value))
        })
        .collect()
}

/// `A, B = 1, 2` and `A = 1` lines of the Python package's codec.
fn python_constants() -> HashMap<String, u64> {
    let text = include_str!("../../clients/python/src/flexdyn/proto.py");
    let mut out = HashMap::new();
    for l in text.lines() {
        let Some((names, values)) = l.split_once(" = ") else {
            continue;
        };
        let names: Vec<&str> = names.split(", ").collect();
        let values: Vec<Option<u64>> = values.split(", ").map(parse_int).collect();
        if names.len() == values.len() && values.iter().all(Option::is_some) {
            for (n, v) in names.iter().zip(values) {
                out.insert(n.trim().to_string(), v.unwrap());
            }
        }
    }
    out
}

#[test]
fn c_and_python_mirror_every_kind_and_flag() {
    let mirrored: [(&str, u64); 33] = [
        ("EFFECTOR_PANEL_PAIR", effector_kind::PANEL_PAIR.into()),
        (
            "EFFECTOR_REACTION_WHEEL",
            effector_kind::REACTION_WHEEL.into(),
        ),
        ("EFFECTOR_MAGNETORQUER", effector_kind::MAGNETORQUER.into()),
        ("EFFECTOR_THRUSTER", effector_kind::THRUSTER.into()),
        ("COMMAND_FLAG_STALE", command_flags::STALE.into()),
        (
            "COMMAND_FLAG_ZEROED_BY_POLICY",
            command_flags::ZEROED_BY_POLICY.into(),
        ),
        (
            "COMMAND_FLAG_NO_COMMAND_YET",
            command_flags::NO_COMMAND_YET.into(),
        ),
        ("SATURATION_GYRO_RATE", saturation_flags::GYRO_RATE.into()),
        ("SATURATION_ACCEL", saturation_flags::ACCEL.into()),
        ("SATURATION_DTHETA", saturation_flags::DTHETA.into()),
        ("SATURATION_DV", saturation_flags::DV.into()),
        (
            "STAR_TRACKER_SUN_EXCLUSION",
            star_tracker_flags::SUN_EXCLUSION.into(),
        ),
        (
            "STAR_TRACKER_RATE_LIMIT",
            star_tracker_flags::RATE_LIMIT.into(),
        ),
        (
            "STAR_TRACKER_EARTH_EXCLUSION",
            star_tracker_flags::EARTH_EXCLUSION.into(),
        ),
        (
            "STAR_TRACKER_MOON_EXCLUSION",
            star_tracker_flags::MOON_EXCLUSION.into(),
        ),
        ("WHEEL_TORQUE_LIMITED", wheel_flags::TORQUE_LIMITED.into()),
        ("WHEEL_SPEED_LIMITED", wheel_flags::SPEED_LIMITED.into()),
        (
            "MAGNETORQUER_SATURATED",
            magnetorquer_flags::SATURATED.into(),
        ),
        ("THRUSTER_FIRING", thruster_flags::FIRING.into()),
        (
            "THRUSTER_BELOW_MIN_ON_TIME",
            thruster_flags::BELOW_MIN_ON_TIME.into(),
        ),
        (
            "THRUSTER_COMMAND_CLIPPED",
            thruster_flags::COMMAND_CLIPPED.into(),
        ),
        // The sun sensors (protocol 6).
        ("FSS_VALID", fss_flags::VALID.into()),
        ("FSS_IN_FOV", fss_flags::IN_FOV.into()),
        ("FSS_SUNLIT", fss_flags::SUNLIT.into()),
        ("MAX_CSS_DETECTORS", flexdyn_proto::MAX_CSS_DETECTORS as u64),
        ("CSS_LEN", flexdyn_proto::CSS_LEN as u64),
        ("FSS_LEN", flexdyn_proto::FSS_LEN as u64),
        ("PROTOCOL_VERSION", flexdyn_proto::PROTOCOL_VERSION.into()),
        ("OPERATOR_PAUSE", OperatorAction::Pause.tag().into()),
        ("OPERATOR_RESUME", OperatorAction::Resume.tag().into()),
        ("OPERATOR_RUN_TICKS", OperatorAction::RunTicks.tag().into()),
        ("MAX_EFFECTORS", flexdyn_proto::MAX_EFFECTORS as u64),
        (
            "MAX_EFFECTOR_VALUES",
            flexdyn_proto::MAX_EFFECTOR_VALUES as u64,
        ),
    ];
    let c = c_defines();
    let py = python_constants();
    for (name, rust) in mirrored {
        // Python names them as C does, without `FD_` (the kind tags are also aliased without
        // `EFFECTOR_`, the names from before the wire table).
        assert_eq!(c.get(&format!("FD_{name}")), Some(&rust), "C FD_{name}");
        assert_eq!(py.get(name), Some(&rust), "Python {name}");
    }
}

/// The environment message's length, flag bits and eclipse values (protocol 6), in their own
/// list so other messages' mirrors merge beside it.
#[test]
fn c_and_python_mirror_the_environment_message() {
    use flexdyn_proto::{eclipse, environment_flags};
    let mirrored = [
        ("ENVIRONMENT_LEN", flexdyn_proto::ENVIRONMENT_LEN as u64),
        (
            "ENVIRONMENT_EPOCH_VALID",
            environment_flags::EPOCH_VALID.into(),
        ),
        ("ENVIRONMENT_MAGNETIC", environment_flags::MAGNETIC.into()),
        ("ENVIRONMENT_SUN", environment_flags::SUN.into()),
        ("ENVIRONMENT_MOON", environment_flags::MOON.into()),
        ("ENVIRONMENT_SHADOW", environment_flags::SHADOW.into()),
        (
            "ENVIRONMENT_ATMOSPHERE",
            environment_flags::ATMOSPHERE.into(),
        ),
        ("ECLIPSE_SUNLIT", eclipse::SUNLIT.into()),
        ("ECLIPSE_PENUMBRA", eclipse::PENUMBRA.into()),
        ("ECLIPSE_UMBRA", eclipse::UMBRA.into()),
    ];
    let c = c_defines();
    let py = python_constants();
    for (name, rust) in mirrored {
        assert_eq!(c.get(&format!("FD_{name}")), Some(&rust), "C FD_{name}");
        assert_eq!(py.get(name), Some(&rust), "Python {name}");
    }
}

/// The GPS message's length and flag bits (protocol 7), in their own list so other messages'
/// mirrors merge beside it.
#[test]
fn c_and_python_mirror_the_gps_message() {
    use flexdyn_proto::gps_flags;
    let mirrored = [
        ("GPS_LEN", flexdyn_proto::GPS_LEN as u64),
        ("GPS_FIX", gps_flags::FIX.into()),
        ("GPS_ECEF", gps_flags::ECEF.into()),
        ("GPS_INERTIAL", gps_flags::INERTIAL.into()),
    ];
    let c = c_defines();
    let py = python_constants();
    for (name, rust) in mirrored {
        assert_eq!(c.get(&format!("FD_{name}")), Some(&rust), "C FD_{name}");
        assert_eq!(py.get(name), Some(&rust), "Python {name}");
    }
}

/// A fleet deputy's relative-state message length (protocol 9), in its own list so other
/// messages' mirrors merge beside it.
#[test]
fn c_and_python_mirror_the_relative_state_message() {
    let c = c_defines();
    let py = python_constants();
    let rust = flexdyn_proto::RELATIVE_STATE_LEN as u64;
    assert_eq!(
        c.get("FD_RELATIVE_STATE_LEN"),
        Some(&rust),
        "C FD_RELATIVE_STATE_LEN"
    );
    assert_eq!(
        py.get("RELATIVE_STATE_LEN"),
        Some(&rust),
        "Python RELATIVE_STATE_LEN"
    );
}
