//! Golden byte vectors: the wire format pinned byte by byte.
//!
//! Each table below is derived by hand from the layout in `proto/README.md`,
//! one row per primitive field: `(offset, little-endian hex, "type field = value")`.
//! Integers are written little-endian; an `f64` is its IEEE-754 binary64 bit
//! pattern (given in the comment column) with the 8 bytes reversed, e.g.
//! 1.5 = 0x3FF8000000000000 → "000000000000f83f". Values are mostly exact dyadic
//! fractions so the bits can be checked by hand (or with
//! `python3 -c 'import struct; print(struct.pack("<d", 1.5).hex())'`), distinct
//! per slot so a swapped field shows up, and include -0.0 (sign bit) and
//! multi-byte integers like 0x0102030405060708 (byte order).
//!
//! The offsets are checked too: every row must start where the previous one ended.
//!
//! **What a mismatch means**: the bytes the Rust encoder produces for these
//! messages changed, i.e. the wire format changed (field order, a type, an enum
//! tag, the bincode config or version). Flight code written against the README
//! will misread such messages. Do not "fix" the test by pasting the new output:
//! if the change is intended, bump `PROTOCOL_VERSION`, update the README tables,
//! then re-mint the affected rows by hand from the new layout (the failure
//! message lists field, offset, expected and actual bytes to help review).

use flexdyn_proto::{
    command_flags, decode, decode_header, eclipse, effector_kind, encode, environment_flags,
    fss_flags, magnetometer_flags, magnetorquer_flags, propellant_tank_flags, saturation_flags,
    star_tracker_flags, thruster_flags, time_flags, wheel_flags, AppliedWrench, CommandKind,
    CommandMsg, CommandStatus, Conserved, CssMsg, DecodeError, EffectorInput, EffectorState,
    EnvironmentMsg, FrameTiming, FssMsg, Header, ImuMsg, MagnetometerMsg, Mode, OperatorAction,
    OperatorMsg, RejectCounters, RunState, StalePolicy, StarTrackerMsg, StateMsg, StatusMsg,
    SysTime, TimeMsg, UtcTime, WireMessage, COMMAND_ACTUATORS_FIXED_LEN, COMMAND_NO_COMMAND_LEN,
    COMMAND_WRENCH_LEN, CSS_LEN, CUC_PFIELD_TAI_4_3, EFFECTOR_INPUT_FIXED_LEN,
    EFFECTOR_STATE_FIXED_LEN, ENVIRONMENT_LEN, FSS_LEN, IMU_LEN, MAGNETOMETER_LEN,
    MAX_CSS_DETECTORS, OPERATOR_LEN, STAR_TRACKER_LEN, STATE_FIXED_LEN, STATUS_LEN,
    TIME_CUC_OFFSET, TIME_LEN,
};
use flexdyn_proto::{
    FaultAction, FaultCommandMsg, FaultEventMsg, FaultSource, FaultTarget, FAULT_COMMAND_LEN,
    FAULT_EVENT_LEN, FAULT_TARGET_LEN,
};
use flexdyn_proto::{RelativeStateMsg, RELATIVE_STATE_LEN};

type Golden = &'static [(usize, &'static str, &'static str)];

fn unhex(s: &str) -> Vec<u8> {
    assert!(s.len().is_multiple_of(2), "odd hex length: {s}");
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex digit"))
        .collect()
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// Concatenate a table, checking that the offsets are contiguous.
fn golden_bytes(table: Golden) -> Vec<u8> {
    let mut out = Vec::new();
    for &(offset, h, what) in table {
        assert_eq!(
            offset,
            out.len(),
            "golden row `{what}` claims offset {offset}, but previous rows end at {}",
            out.len()
        );
        out.extend(unhex(h));
    }
    out
}

/// Compare `actual` against the table, reporting every differing field.
fn assert_matches_golden(name: &str, table: Golden, actual: &[u8]) {
    let expected = golden_bytes(table);
    let mut report = String::new();
    for &(offset, h, what) in table {
        let want = unhex(h);
        let got = actual.get(offset..offset + want.len()).unwrap_or(&[]);
        if got != want.as_slice() {
            report += &format!("  @{offset:>3} {what}: expected {h}, got {}\n", hex(got));
        }
    }
    if actual.len() != expected.len() {
        report += &format!(
            "  length: expected {}, got {}\n",
            expected.len(),
            actual.len()
        );
    }
    assert!(
        report.is_empty(),
        "{name} encoding differs from the golden bytes (wire format changed?):\n{report}"
    );
}

/// encode(msg) == golden, decode(golden) == msg.
fn check<M: WireMessage + PartialEq + std::fmt::Debug>(name: &str, table: Golden, msg: &M) {
    assert_matches_golden(name, table, &encode(msg));
    let bytes = golden_bytes(table);
    assert_eq!(
        &decode::<M>(&bytes).expect("golden decodes"),
        msg,
        "{name}: decoding the golden bytes"
    );
    assert_eq!(
        &decode_header(&bytes).expect("golden header decodes"),
        msg.header()
    );
}

const STATE_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (
        6,
        "0807060504030201",
        "u64 header.tick = 72623859790382856 (0x102030405060708)",
    ),
    (
        14,
        "002f685900000000",
        "u64 header.sim_time_ns = 1500000000 (0x59682F00)",
    ),
    (22, "0201000000000000", "u64 header.seq = 258 (0x102)"),
    (
        30,
        "000000000000c03f",
        "f64 sigma_bn[0] = 0.125 (bits 0x3FC0000000000000)",
    ),
    (
        38,
        "000000000000d0bf",
        "f64 sigma_bn[1] = -0.25 (bits 0xBFD0000000000000)",
    ),
    (
        46,
        "000000000000e03f",
        "f64 sigma_bn[2] = 0.5 (bits 0x3FE0000000000000)",
    ),
    (
        54,
        "000000000000ec3f",
        "f64 q_bn[0] = 0.875 (bits 0x3FEC000000000000)",
    ),
    (
        62,
        "000000000000d03f",
        "f64 q_bn[1] = 0.25 (bits 0x3FD0000000000000)",
    ),
    (
        70,
        "000000000000d8bf",
        "f64 q_bn[2] = -0.375 (bits 0xBFD8000000000000)",
    ),
    (
        78,
        "000000000000c83f",
        "f64 q_bn[3] = 0.1875 (bits 0x3FC8000000000000)",
    ),
    (
        86,
        "000000000000503f",
        "f64 omega_bn_b_rad_s[0] = 0.0009765625 (bits 0x3F50000000000000)",
    ),
    (
        94,
        "00000000000060bf",
        "f64 omega_bn_b_rad_s[1] = -0.001953125 (bits 0xBF60000000000000)",
    ),
    (
        102,
        "000000000000703f",
        "f64 omega_bn_b_rad_s[2] = 0.00390625 (bits 0x3F70000000000000)",
    ),
    (
        110,
        "000000000000f83f",
        "f64 omega_dot_bn_b_rad_s2[0] = 1.5 (bits 0x3FF8000000000000)",
    ),
    (
        118,
        "00000000000008c0",
        "f64 omega_dot_bn_b_rad_s2[1] = -3.0 (bits 0xC008000000000000)",
    ),
    (
        126,
        "0000000000001840",
        "f64 omega_dot_bn_b_rad_s2[2] = 6.0 (bits 0x4018000000000000)",
    ),
    (
        134,
        "00000000f0b35a41",
        "f64 r_bn_n_m[0] = 7000000.0 (bits 0x415AB3F000000000)",
    ),
    (
        142,
        "00000000000090c0",
        "f64 r_bn_n_m[1] = -1024.0 (bits 0xC090000000000000)",
    ),
    (
        150,
        "000000000000e03f",
        "f64 r_bn_n_m[2] = 0.5 (bits 0x3FE0000000000000)",
    ),
    (
        158,
        "000000000000d03f",
        "f64 v_bn_n_m_s[0] = 0.25 (bits 0x3FD0000000000000)",
    ),
    (
        166,
        "00000000004cbd40",
        "f64 v_bn_n_m_s[1] = 7500.0 (bits 0x40BD4C0000000000)",
    ),
    (
        174,
        "00000000000020c0",
        "f64 v_bn_n_m_s[2] = -8.0 (bits 0xC020000000000000)",
    ),
    (
        182,
        "0000000000000000",
        "f64 nongrav_accel_bn_n_m_s2[0] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        190,
        "0000000000000080",
        "f64 nongrav_accel_bn_n_m_s2[1] = -0.0 (bits 0x8000000000000000)",
    ),
    (
        198,
        "000000000000b03e",
        "f64 nongrav_accel_bn_n_m_s2[2] = 9.5367431640625e-07 (bits 0x3EB0000000000000)",
    ),
    (
        206,
        "000000e8764817c2",
        "f64 conserved.orb_energy_j = -25000000000.0 (bits 0xC2174876E8000000)",
    ),
    (
        214,
        "0000000000002940",
        "f64 conserved.rot_energy_j = 12.5 (bits 0x4029000000000000)",
    ),
    (
        222,
        "000000a2941a6d42",
        "f64 conserved.orb_ang_mom_n[0] = 1000000000000.0 (bits 0x426D1A94A2000000)",
    ),
    (
        230,
        "00000000000000c0",
        "f64 conserved.orb_ang_mom_n[1] = -2.0 (bits 0xC000000000000000)",
    ),
    (
        238,
        "0000000000001040",
        "f64 conserved.orb_ang_mom_n[2] = 4.0 (bits 0x4010000000000000)",
    ),
    (
        246,
        "0000000000005940",
        "f64 conserved.rot_ang_mom_c_n[0] = 100.0 (bits 0x4059000000000000)",
    ),
    (
        254,
        "000000000000e8bf",
        "f64 conserved.rot_ang_mom_c_n[1] = -0.75 (bits 0xBFE8000000000000)",
    ),
    (
        262,
        "000000000000f43f",
        "f64 conserved.rot_ang_mom_c_n[2] = 1.25 (bits 0x3FF4000000000000)",
    ),
    (
        270,
        "000000000000b03f",
        "f64 wrench_applied.torque_b_nm[0] = 0.0625 (bits 0x3FB0000000000000)",
    ),
    (
        278,
        "000000000000c0bf",
        "f64 wrench_applied.torque_b_nm[1] = -0.125 (bits 0xBFC0000000000000)",
    ),
    (
        286,
        "000000000000d03f",
        "f64 wrench_applied.torque_b_nm[2] = 0.25 (bits 0x3FD0000000000000)",
    ),
    (
        294,
        "000000000000f03f",
        "f64 wrench_applied.force_b_newton[0] = 1.0 (bits 0x3FF0000000000000)",
    ),
    (
        302,
        "00000000000000c0",
        "f64 wrench_applied.force_b_newton[1] = -2.0 (bits 0xC000000000000000)",
    ),
    (
        310,
        "0000000000000840",
        "f64 wrench_applied.force_b_newton[2] = 3.0 (bits 0x4008000000000000)",
    ),
    (318, "05", "u8 command_flags = 5 (STALE | NO_COMMAND_YET)"),
    (
        319,
        "0200000000000000",
        "u64 effectors count = 2 (Vec length prefix)",
    ),
    (327, "0100", "u16 effectors[0].kind = 1 (PANEL_PAIR)"),
    (329, "00000000", "u32 effectors[0].flags = 0"),
    (333, "0400000000000000", "u64 effectors[0].states count = 4"),
    (
        341,
        "000000000000e03f",
        "f64 effectors[0].states[0] theta1_rad = 0.5 (bits 0x3FE0000000000000)",
    ),
    (
        349,
        "000000000000b0bf",
        "f64 effectors[0].states[1] theta1_dot_rad_s = -0.0625 (bits 0xBFB0000000000000)",
    ),
    (
        357,
        "000000000000f43f",
        "f64 effectors[0].states[2] theta2_rad = 1.25 (bits 0x3FF4000000000000)",
    ),
    (
        365,
        "000000000000a03f",
        "f64 effectors[0].states[3] theta2_dot_rad_s = 0.03125 (bits 0x3FA0000000000000)",
    ),
    (
        373,
        "0000000000000000",
        "u64 effectors[0].outputs count = 0",
    ),
    (381, "0200", "u16 effectors[1].kind = 2 (REACTION_WHEEL)"),
    (
        383,
        "03000000",
        "u32 effectors[1].flags = 3 (TORQUE_LIMITED | SPEED_LIMITED)",
    ),
    (387, "0100000000000000", "u64 effectors[1].states count = 1"),
    (
        395,
        "0000000000d062c0",
        "f64 effectors[1].states[0] omega_rad_s = -150.5 (bits 0xC062D00000000000)",
    ),
    (
        403,
        "0200000000000000",
        "u64 effectors[1].outputs count = 2",
    ),
    (
        411,
        "000000000000d03f",
        "f64 effectors[1].outputs[0] motor_torque_nm = 0.25 (bits 0x3FD0000000000000)",
    ),
    (
        419,
        "00000000000080bf",
        "f64 effectors[1].outputs[1] friction_torque_nm = -0.0078125 (bits 0xBF80000000000000)",
    ),
];
const IMU_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "0900000000000000", "u64 header.tick = 9"),
    (
        14,
        "4054890000000000",
        "u64 header.sim_time_ns = 9000000 (0x895440)",
    ),
    (22, "0a00000000000000", "u64 header.seq = 10"),
    (
        30,
        "000000000000503f",
        "f64 omega_p_rad_s[0] = 0.0009765625 (bits 0x3F50000000000000)",
    ),
    (
        38,
        "000000000000e0bf",
        "f64 omega_p_rad_s[1] = -0.5 (bits 0xBFE0000000000000)",
    ),
    (
        46,
        "0000000000000040",
        "f64 omega_p_rad_s[2] = 2.0 (bits 0x4000000000000000)",
    ),
    (
        54,
        "0000000000000000",
        "f64 accel_p_m_s2[0] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        62,
        "0000000000802340",
        "f64 accel_p_m_s2[1] = 9.75 (bits 0x4023800000000000)",
    ),
    (
        70,
        "000000000000c0bf",
        "f64 accel_p_m_s2[2] = -0.125 (bits 0xBFC0000000000000)",
    ),
    (
        78,
        "000000000000b03e",
        "f64 dtheta_p_rad[0] = 9.5367431640625e-07 (bits 0x3EB0000000000000)",
    ),
    (
        86,
        "000000000000c0be",
        "f64 dtheta_p_rad[1] = -1.9073486328125e-06 (bits 0xBEC0000000000000)",
    ),
    (
        94,
        "000000000000d03e",
        "f64 dtheta_p_rad[2] = 3.814697265625e-06 (bits 0x3ED0000000000000)",
    ),
    (
        102,
        "fca9f1d24d62503f",
        "f64 dv_p_m_s[0] = 0.001 (bits 0x3F50624DD2F1A9FC)",
    ),
    (
        110,
        "000000000000f8bf",
        "f64 dv_p_m_s[1] = -1.5 (bits 0xBFF8000000000000)",
    ),
    (
        118,
        "0000000000000840",
        "f64 dv_p_m_s[2] = 3.0 (bits 0x4008000000000000)",
    ),
    (126, "09", "u8 saturation_flags = 9 (GYRO_RATE | DV)"),
];
const COMMAND_WRENCH_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "2a00000000000000", "u64 header.tick = 42"),
    (
        14,
        "00b1081900000000",
        "u64 header.sim_time_ns = 420000000 (0x1908B100)",
    ),
    (22, "0700000000000000", "u64 header.seq = 7"),
    (30, "efbeadde", "u32 sender_id = 3735928559 (0xDEADBEEF)"),
    (34, "00000000", "u32 kind tag = 0 (Wrench)"),
    (
        38,
        "000000000000b03f",
        "f64 kind.torque_b_nm[0] = 0.0625 (bits 0x3FB0000000000000)",
    ),
    (
        46,
        "000000000000c0bf",
        "f64 kind.torque_b_nm[1] = -0.125 (bits 0xBFC0000000000000)",
    ),
    (
        54,
        "000000000000d03f",
        "f64 kind.torque_b_nm[2] = 0.25 (bits 0x3FD0000000000000)",
    ),
    (
        62,
        "000000000000f0bf",
        "f64 kind.force_b_newton[0] = -1.0 (bits 0xBFF0000000000000)",
    ),
    (
        70,
        "0000000000000000",
        "f64 kind.force_b_newton[1] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        78,
        "000000000000e03f",
        "f64 kind.force_b_newton[2] = 0.5 (bits 0x3FE0000000000000)",
    ),
];
const COMMAND_ACTUATORS_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "2c00000000000000", "u64 header.tick = 44"),
    (
        14,
        "00de391a00000000",
        "u64 header.sim_time_ns = 440000000 (0x1A39DE00)",
    ),
    (22, "0900000000000000", "u64 header.seq = 9"),
    (30, "07000000", "u32 sender_id = 7"),
    (34, "02000000", "u32 kind tag = 2 (Actuators)"),
    (
        38,
        "000000000000e03f",
        "f64 kind.torque_b_nm[0] = 0.5 (bits 0x3FE0000000000000)",
    ),
    (
        46,
        "000000000000d0bf",
        "f64 kind.torque_b_nm[1] = -0.25 (bits 0xBFD0000000000000)",
    ),
    (
        54,
        "0000000000000000",
        "f64 kind.torque_b_nm[2] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        62,
        "0000000000000000",
        "f64 kind.force_b_newton[0] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        70,
        "0000000000000000",
        "f64 kind.force_b_newton[1] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        78,
        "0000000000000080",
        "f64 kind.force_b_newton[2] = -0.0 (bits 0x8000000000000000)",
    ),
    (86, "0200000000000000", "u64 kind.inputs count = 2"),
    (94, "02000000", "u32 kind.inputs[0].effector_index = 2"),
    (
        98,
        "0100000000000000",
        "u64 kind.inputs[0].values count = 1",
    ),
    (
        106,
        "000000000000b03f",
        "f64 kind.inputs[0].values[0] = 0.0625 (bits 0x3FB0000000000000)",
    ),
    (114, "05000000", "u32 kind.inputs[1].effector_index = 5"),
    (
        118,
        "0100000000000000",
        "u64 kind.inputs[1].values count = 1",
    ),
    (
        126,
        "000000000000a0bf",
        "f64 kind.inputs[1].values[0] = -0.03125 (bits 0xBFA0000000000000)",
    ),
];
const MAGNETOMETER_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "0d00000000000000", "u64 header.tick = 13"),
    (
        14,
        "80a4bf0700000000",
        "u64 header.sim_time_ns = 130000000 (0x7BFA480)",
    ),
    (22, "0100000000000000", "u64 header.seq = 1"),
    (
        30,
        "000000000000003f",
        "f64 b_s_t[0] = 2^-15 = 3.0517578125e-5 (bits 0x3F00000000000000)",
    ),
    (
        38,
        "000000000000f0be",
        "f64 b_s_t[1] = -2^-16 = -1.52587890625e-5 (bits 0xBEF0000000000000)",
    ),
    (
        46,
        "0000000000000080",
        "f64 b_s_t[2] = -0.0 (bits 0x8000000000000000)",
    ),
    (54, "05", "u8 saturation_flags = AXIS_1 | AXIS_3 = 0x05"),
];
const ENVIRONMENT_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "1100000000000000", "u64 header.tick = 17"),
    (
        14,
        "80fe210a00000000",
        "u64 header.sim_time_ns = 170000000 (0xA21FE80)",
    ),
    (22, "0200000000000000", "u64 header.seq = 2"),
    (
        30,
        "0807060504030201",
        "u64 tai_ns_1958 = 0x0102030405060708",
    ),
    (
        38,
        "77",
        "u8 flags = EPOCH_VALID | MAGNETIC | SUN | SHADOW | ATMOSPHERE | ALBEDO = 0x77",
    ),
    (39, "01", "u8 eclipse = PENUMBRA = 1"),
    (
        40,
        "000000000000003f",
        "f64 b_n_t[0] = 2^-15 (bits 0x3F00000000000000)",
    ),
    (
        48,
        "000000000000f0be",
        "f64 b_n_t[1] = -2^-16 (bits 0xBEF0000000000000)",
    ),
    (
        56,
        "000000000000e03e",
        "f64 b_n_t[2] = 2^-17 (bits 0x3EE0000000000000)",
    ),
    (
        64,
        "0000000000000080",
        "f64 b_b_t[0] = -0.0 (bits 0x8000000000000000)",
    ),
    (
        72,
        "000000000000103f",
        "f64 b_b_t[1] = 2^-14 (bits 0x3F10000000000000)",
    ),
    (
        80,
        "000000000000d0be",
        "f64 b_b_t[2] = -2^-18 (bits 0xBED0000000000000)",
    ),
    (
        88,
        "000000000000e03f",
        "f64 sun_n[0] = 0.5 (bits 0x3FE0000000000000)",
    ),
    (
        96,
        "000000000000e0bf",
        "f64 sun_n[1] = -0.5 (bits 0xBFE0000000000000)",
    ),
    (
        104,
        "000000000000e83f",
        "f64 sun_n[2] = 0.75 (bits 0x3FE8000000000000)",
    ),
    (
        112,
        "000000000000d03f",
        "f64 sun_b[0] = 0.25 (bits 0x3FD0000000000000)",
    ),
    (
        120,
        "000000000000f03f",
        "f64 sun_b[1] = 1.0 (bits 0x3FF0000000000000)",
    ),
    (
        128,
        "000000000000c0bf",
        "f64 sun_b[2] = -0.125 (bits 0xBFC0000000000000)",
    ),
    (
        136,
        "000000000000f0bf",
        "f64 moon_n[0] = -1.0 (bits 0xBFF0000000000000)",
    ),
    (
        144,
        "000000000000d83f",
        "f64 moon_n[1] = 0.375 (bits 0x3FD8000000000000)",
    ),
    (
        152,
        "000000000000b03f",
        "f64 moon_n[2] = 0.0625 (bits 0x3FB0000000000000)",
    ),
    (
        160,
        "000000000000e43f",
        "f64 shadow_factor = 0.625 (bits 0x3FE4000000000000)",
    ),
    (
        168,
        "000000000000703d",
        "f64 density_kg_m3 = 2^-40 (bits 0x3D70000000000000)",
    ),
    (
        176,
        "000000000000b03e",
        "f64 gravity_gradient.torque_b_nm[0] = 2^-20 (bits 0x3EB0000000000000)",
    ),
    (
        184,
        "000000000000a0be",
        "f64 gravity_gradient.torque_b_nm[1] = -2^-21 (bits 0xBEA0000000000000)",
    ),
    (
        192,
        "000000000000903e",
        "f64 gravity_gradient.torque_b_nm[2] = 2^-22 (bits 0x3E90000000000000)",
    ),
    (
        200,
        "000000000000103e",
        "f64 gravity_gradient.force_b_newton[0] = 2^-30 (bits 0x3E10000000000000)",
    ),
    (
        208,
        "0000000000000000",
        "f64 gravity_gradient.force_b_newton[1] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        216,
        "00000000000000be",
        "f64 gravity_gradient.force_b_newton[2] = -2^-31 (bits 0xBE00000000000000)",
    ),
    (
        224,
        "000000000000f83f",
        "f64 drag.torque_b_nm[0] = 1.5 (bits 0x3FF8000000000000)",
    ),
    (
        232,
        "00000000000004c0",
        "f64 drag.torque_b_nm[1] = -2.5 (bits 0xC004000000000000)",
    ),
    (
        240,
        "0000000000000c40",
        "f64 drag.torque_b_nm[2] = 3.5 (bits 0x400C000000000000)",
    ),
    (
        248,
        "0000000000001040",
        "f64 drag.force_b_newton[0] = 4.0 (bits 0x4010000000000000)",
    ),
    (
        256,
        "00000000000020c0",
        "f64 drag.force_b_newton[1] = -8.0 (bits 0xC020000000000000)",
    ),
    (
        264,
        "0000000000003040",
        "f64 drag.force_b_newton[2] = 16.0 (bits 0x4030000000000000)",
    ),
    (
        272,
        "000000000000703e",
        "f64 solar_pressure.torque_b_nm[0] = 2^-24 (bits 0x3E70000000000000)",
    ),
    (
        280,
        "000000000000603e",
        "f64 solar_pressure.torque_b_nm[1] = 2^-25 (bits 0x3E60000000000000)",
    ),
    (
        288,
        "000000000000503e",
        "f64 solar_pressure.torque_b_nm[2] = 2^-26 (bits 0x3E50000000000000)",
    ),
    (
        296,
        "00000000000070be",
        "f64 solar_pressure.force_b_newton[0] = -2^-24 (bits 0xBE70000000000000)",
    ),
    (
        304,
        "00000000000060be",
        "f64 solar_pressure.force_b_newton[1] = -2^-25 (bits 0xBE60000000000000)",
    ),
    (
        312,
        "00000000000050be",
        "f64 solar_pressure.force_b_newton[2] = -2^-26 (bits 0xBE50000000000000)",
    ),
    (
        320,
        "000000000000c03f",
        "f64 residual_dipole.torque_b_nm[0] = 0.125 (bits 0x3FC0000000000000)",
    ),
    (
        328,
        "000000000000d0bf",
        "f64 residual_dipole.torque_b_nm[1] = -0.25 (bits 0xBFD0000000000000)",
    ),
    (
        336,
        "000000000000803f",
        "f64 residual_dipole.torque_b_nm[2] = 2^-7 (bits 0x3F80000000000000)",
    ),
    (
        344,
        "0000000000000000",
        "f64 residual_dipole.force_b_newton[0] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        352,
        "0000000000000000",
        "f64 residual_dipole.force_b_newton[1] = 0.0 (bits 0x0000000000000000)",
    ),
    (
        360,
        "0000000000000000",
        "f64 residual_dipole.force_b_newton[2] = 0.0 (bits 0x0000000000000000)",
    ),
    // Protocol 11: 0.171875 = 11/64 = 1.375 × 2^-3: exponent 1023 − 3 = 0x3FC, fraction
    // .375 = .011b → 0x6 in the top nibble.
    (
        368,
        "000000000000c63f",
        "f64 albedo_nadir_w_m2 = 0.171875 (bits 0x3FC6000000000000)",
    ),
];

// The sun sensors' tables (protocol 6, issue 20).
const CSS_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "0d00000000000000", "u64 header.tick = 13"),
    (
        14,
        "80a4bf0700000000",
        "u64 header.sim_time_ns = 130000000 (0x7BFA480)",
    ),
    (22, "0100000000000000", "u64 header.seq = 1"),
    (30, "03", "u8 detector_count = 3"),
    (
        31,
        "000000000000e03f",
        "f64 readings[0] = 0.5 (bits 0x3FE0000000000000)",
    ),
    (
        39,
        "000000000000e83f",
        "f64 readings[1] = 0.75 (bits 0x3FE8000000000000)",
    ),
    (
        47,
        "000000000000503f",
        "f64 readings[2] = 2^-10 = 0.0009765625 (bits 0x3F50000000000000)",
    ),
    (
        55,
        "0000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "f64 readings[3..16] = 0.0 (13 unused slots, 104 zero bytes)",
    ),
];
const FSS_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "0d00000000000000", "u64 header.tick = 13"),
    (
        14,
        "80a4bf0700000000",
        "u64 header.sim_time_ns = 130000000 (0x7BFA480)",
    ),
    (22, "0100000000000000", "u64 header.seq = 1"),
    (
        30,
        "000000000000c03f",
        "f64 alpha_rad = 0.125 (bits 0x3FC0000000000000)",
    ),
    (
        38,
        "000000000000b0bf",
        "f64 beta_rad = -0.0625 (bits 0xBFB0000000000000)",
    ),
    (46, "07", "u8 flags = VALID | IN_FOV | SUNLIT = 0x07"),
];
const STAR_TRACKER_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "0b00000000000000", "u64 header.tick = 11"),
    (
        14,
        "80778e0600000000",
        "u64 header.sim_time_ns = 110000000 (0x68E7780)",
    ),
    (22, "0c00000000000000", "u64 header.seq = 12"),
    (
        30,
        "000000000000ec3f",
        "f64 q_cn[0] = 0.875 (bits 0x3FEC000000000000)",
    ),
    (
        38,
        "000000000000d03f",
        "f64 q_cn[1] = 0.25 (bits 0x3FD0000000000000)",
    ),
    (
        46,
        "000000000000d8bf",
        "f64 q_cn[2] = -0.375 (bits 0xBFD8000000000000)",
    ),
    (
        54,
        "000000000000c83f",
        "f64 q_cn[3] = 0.1875 (bits 0x3FC8000000000000)",
    ),
    (62, "00", "bool valid = false"),
    (63, "01", "u8 status_flags = 1 (SUN_EXCLUSION)"),
];
/// A time message of a run with `[epoch] utc = "2016-12-31T23:59:59.5Z"` and an 8 Hz frame at
/// `--speed 0.5`, paused at tick 6 (t = 0.75 s): 2016-12-31T23:59:60.25 UTC, inside the leap
/// second, so TAI − UTC is still 36 s and TAI reads 2017-01-01T00:00:36.25 TAI = 21,550 days
/// (1958-01-01 … 2017-01-01: 59 years, 15 leap days) + 36.25 s = 1,861,920,036.25 s since 1958.
/// GPS time = TAI − 19 s − 8,040 days (1958-01-01 … 1980-01-06) = 1,167,264,017.25 s = week
/// 1930 (1930 · 604,800 = 1,167,264,000) + 17.25 s. The last tone was at tick 4 (t = 0.5 s,
/// TAI …036.0 s). `crates/server/src/clock.rs` produces exactly this message from that epoch.
const TIME_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "0600000000000000", "u64 header.tick = 6"),
    (
        14,
        "8017b42c00000000",
        "u64 header.sim_time_ns = 750000000 (0x2CB41780)",
    ),
    (22, "0600000000000000", "u64 header.seq = 6"),
    (30, "06000000", "u32 run_state = 6 (Paused)"),
    (34, "00000000", "u32 mode = 0 (RealTime)"),
    (38, "05", "u8 flags = 5 (EPOCH_VALID | LEAP_SECOND)"),
    (
        39,
        "4059730700000000",
        "u64 frame_ns = 125000000 (0x7735940)",
    ),
    (
        47,
        "000000000000e03f",
        "f64 speed = 0.5 (bits 0x3FE0000000000000)",
    ),
    (
        55,
        "801add7868ded619",
        "u64 tai_ns_1958 = 1861920036250000000 (0x19D6DE6878DD1A80)",
    ),
    (63, "e007", "u16 utc.year = 2016 (0x07E0)"),
    (65, "0c", "u8 utc.month = 12"),
    (66, "1f", "u8 utc.day = 31"),
    (67, "17", "u8 utc.hour = 23"),
    (68, "3b", "u8 utc.minute = 59"),
    (69, "3c", "u8 utc.second = 60"),
    (
        70,
        "80b2e60e",
        "u32 utc.nanosecond = 250000000 (0x0EE6B280)",
    ),
    (74, "24000000", "i32 tai_minus_utc_s = 36"),
    (78, "8a070000", "u32 gps_week = 1930 (0x078A)"),
    (
        82,
        "801c2e0404000000",
        "u64 gps_ns_of_week = 17250000000 (0x404_2E1C80)",
    ),
    (
        90,
        "8017b42c00000000",
        "u64 met_ns = 750000000 (0x2CB41780)",
    ),
    (
        98,
        "1f6efaa524400000",
        "[u8; 8] cuc_tai: P-field 0x1F, coarse 0x6EFAA524 (1861920036 s), fine 0x400000 (0.25 s · 2^24), big-endian",
    ),
    (106, "00000000", "u32 tone_met.seconds = 0"),
    (
        110,
        "00000080",
        "u32 tone_met.subseconds = 0x80000000 (0.5 s · 2^32)",
    ),
    (
        114,
        "24a5fa6e",
        "u32 tone_tai.seconds = 1861920036 (0x6EFAA524)",
    ),
    (118, "00000000", "u32 tone_tai.subseconds = 0"),
];
const COMMAND_NO_COMMAND_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "2b00000000000000", "u64 header.tick = 43"),
    (
        14,
        "8047a11900000000",
        "u64 header.sim_time_ns = 430000000 (0x19A14780)",
    ),
    (22, "0800000000000000", "u64 header.seq = 8"),
    (30, "05000000", "u32 sender_id = 5"),
    (34, "01000000", "u32 kind tag = 1 (NoCommand)"),
];
const STATUS_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (
        6,
        "0807060504030201",
        "u64 header.tick = 72623859790382856 (0x102030405060708)",
    ),
    (
        14,
        "002f685900000000",
        "u64 header.sim_time_ns = 1500000000 (0x59682F00)",
    ),
    (22, "6300000000000000", "u64 header.seq = 99"),
    (30, "01000000", "u32 mode tag = 1 (Lockstep)"),
    (34, "01000000", "u32 run_state tag = 1 (Running)"),
    (
        38,
        "e803000000000000",
        "u64 timing.lateness_p50_ns = 1000 (0x3E8)",
    ),
    (
        46,
        "90d0030000000000",
        "u64 timing.lateness_p99_ns = 250000 (0x3D090)",
    ),
    (
        54,
        "c0c62d0000000000",
        "u64 timing.lateness_max_ns = 3000000 (0x2DC6C0)",
    ),
    (62, "0300000000000000", "u64 timing.overrun_count = 3"),
    (70, "0200000000000000", "u64 timing.frames_skipped = 2"),
    (78, "2900000000000000", "u64 command.last_command_tick = 41"),
    (
        86,
        "40420f0000000000",
        "u64 command.command_age_ns = 1000000 (0xF4240)",
    ),
    (94, "01", "bool command.command_stale = true"),
    (95, "01000000", "u32 command.stale_policy tag = 1 (Zero)"),
    (99, "0100000000000000", "u64 rejected.malformed = 1"),
    (107, "0200000000000000", "u64 rejected.bad_version = 2"),
    (115, "0300000000000000", "u64 rejected.non_finite = 3"),
    (123, "0400000000000000", "u64 rejected.wrong_spacecraft = 4"),
    (131, "0500000000000000", "u64 rejected.stale_tick = 5"),
    (139, "0600000000000000", "u64 rejected.unknown_sender = 6"),
    (
        147,
        "0800000000000000",
        "u64 rejected.bad_effector_input = 8",
    ),
    (155, "0900000000000000", "u64 rejected.wrong_identity = 9"),
    (
        163,
        "0a00000000000000",
        "u64 rejected.operator_refused = 10",
    ),
    (
        171,
        "0b00000000000000",
        "u64 rejected.fault_refused = 11 (protocol 8)",
    ),
    (
        179,
        "0c00000000000000",
        "u64 rejected.fsw_refused = 12 (protocol 10)",
    ),
    (187, "0700000000000000", "u64 commands_dropped = 7"),
    (
        195,
        "15cd853dfe9c9717",
        "u64 wall_time_unix_ns = 1700000000123456789 (0x17979CFE3D85CD15)",
    ),
    (
        203,
        "0300000000000000",
        "u64 faults_active = 3 (protocol 8)",
    ),
    (
        211,
        "0500000000000000",
        "u64 faults_active_bits[0] = 0b101: faults 0 and 2",
    ),
    (219, "0000000000000000", "u64 faults_active_bits[1] = 0"),
    (227, "0000000000000000", "u64 faults_active_bits[2] = 0"),
    (
        235,
        "0000000000000080",
        "u64 faults_active_bits[3] = 1 << 63: fault 255",
    ),
];

// Protocol 8 (issue 21, fault injection): live fault 3 (after three configured faults, its
// first live one) activated at tick 44: `bias_step` (mode 2) of 0.25 rad/s on axes 1 and 3 of
// `imus.hub.gyro`, at 0.44 s exactly (edge = the boundary).
const FAULT_EVENT_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "2c00000000000000", "u64 header.tick = 44"),
    (
        14,
        "00de391a00000000",
        "u64 header.sim_time_ns = 440000000 (0x1A39DE00)",
    ),
    (22, "0100000000000000", "u64 header.seq = 1"),
    (30, "03000000", "u32 fault_index = 3"),
    (34, "01000000", "u32 source tag = 1 (Live)"),
    (38, "02000000", "u32 mode = 2 (bias_step)"),
    (42, "01", "bool active = true"),
    (
        43,
        "00de391a00000000",
        "u64 edge_ns = 440000000 (0x1A39DE00)",
    ),
    (51, "05000000", "u32 axes = 0b101 (axes 1 and 3)"),
    (
        55,
        "000000000000d03f",
        "f64 params[0] = 0.25 (0x3FD0000000000000)",
    ),
    (63, "0000000000000000", "f64 params[1] = 0 (unused)"),
    (
        71,
        "696d75732e6875622e6779726f",
        "u8[13] target = \"imus.hub.gyro\" (UTF-8)",
    ),
    (
        84,
        "0000000000000000000000000000000000000000000000000000000000000000\
         0000000000000000000000000000000000000000000000000000000000000000\
         0000000000000000000000000000000000000000000000000000000000000000\
         00000000000000000000000000000000000000",
        "u8[115] target padding: NUL",
    ),
];

// Protocol 8 (issue 21): a live fault command, `torque_limit` (mode 10) to a fraction of 0.5 on
// `reaction_wheels.rw2`, at tick 0x1_0000_0005 (bytes on both sides of bit 32), for 2 s, seed
// 7.
const FAULT_COMMAND_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "2c00000000000000", "u64 header.tick = 44"),
    (
        14,
        "00de391a00000000",
        "u64 header.sim_time_ns = 440000000 (0x1A39DE00)",
    ),
    (22, "0200000000000000", "u64 header.seq = 2"),
    (30, "00000000", "u32 action tag = 0 (Inject)"),
    (
        34,
        "0500000001000000",
        "u64 at_tick = 4294967301 (0x100000005)",
    ),
    (42, "00000000", "u32 fault_index = 0 (ignored for Inject)"),
    (46, "0a000000", "u32 mode = 10 (torque_limit)"),
    (
        50,
        "000000000000e03f",
        "f64 params[0] = 0.5 (0x3FE0000000000000)",
    ),
    (58, "0000000000000000", "f64 params[1] = 0 (unused)"),
    (66, "00000000", "u32 axes = 0 (every axis)"),
    (
        70,
        "0094357700000000",
        "u64 duration_ns = 2000000000 (0x77359400)",
    ),
    (78, "0700000000000000", "u64 seed = 7"),
    (
        86,
        "7265616374696f6e5f776865656c732e727732",
        "u8[19] target = \"reaction_wheels.rw2\" (UTF-8)",
    ),
    (
        105,
        "0000000000000000000000000000000000000000000000000000000000000000\
         0000000000000000000000000000000000000000000000000000000000000000\
         0000000000000000000000000000000000000000000000000000000000000000\
         00000000000000000000000000",
        "u8[109] target padding: NUL",
    ),
];

// Protocol 6 (issue 23, operator control): a `RunTicks` operator command. The tick count
// 4294967301 = 0x1_0000_0005 has bytes on both sides of bit 32, so a u32 `ticks` would show.
const OPERATOR_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "2c00000000000000", "u64 header.tick = 44"),
    (
        14,
        "00de391a00000000",
        "u64 header.sim_time_ns = 440000000 (0x1A39DE00)",
    ),
    (22, "0300000000000000", "u64 header.seq = 3"),
    (30, "02000000", "u32 action tag = 2 (RunTicks)"),
    (
        34,
        "0500000001000000",
        "u64 ticks = 4294967301 (0x100000005)",
    ),
];

// Protocol 12 (issue 40 §2, operator checkpoints): a `Checkpoint` operator command naming
// frame boundary 1000 = 0x3E8 (LE e8 03 then six zero bytes), sent by an operator who last saw
// tick 44 (t = 0.44 s), its 4th command. The header is the RunTicks golden's but for seq 4; the
// action tag is the new one, 3; `ticks` is the tick to save at.
const OPERATOR_CHECKPOINT_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "2c00000000000000", "u64 header.tick = 44"),
    (
        14,
        "00de391a00000000",
        "u64 header.sim_time_ns = 440000000 (0x1A39DE00)",
    ),
    (22, "0400000000000000", "u64 header.seq = 4"),
    (30, "03000000", "u32 action tag = 3 (Checkpoint)"),
    (34, "e803000000000000", "u64 ticks = 1000 (0x3E8)"),
];

const SC: u32 = 0x1122_3344;

fn state_msg() -> StateMsg {
    StateMsg {
        header: Header::new(SC, 0x0102_0304_0506_0708, 1_500_000_000, 0x102),
        sigma_bn: [0.125, -0.25, 0.5],
        q_bn: [0.875, 0.25, -0.375, 0.1875],
        omega_bn_b_rad_s: [1.0 / 1024.0, -2.0 / 1024.0, 4.0 / 1024.0],
        omega_dot_bn_b_rad_s2: [1.5, -3.0, 6.0],
        r_bn_n_m: [7_000_000.0, -1024.0, 0.5],
        v_bn_n_m_s: [0.25, 7500.0, -8.0],
        nongrav_accel_bn_n_m_s2: [0.0, -0.0, 1.0 / 1_048_576.0],
        conserved: Conserved {
            orb_energy_j: -2.5e10,
            rot_energy_j: 12.5,
            orb_ang_mom_n: [1.0e12, -2.0, 4.0],
            rot_ang_mom_c_n: [100.0, -0.75, 1.25],
        },
        wrench_applied: AppliedWrench {
            torque_b_nm: [0.0625, -0.125, 0.25],
            force_b_newton: [1.0, -2.0, 3.0],
        },
        command_flags: command_flags::STALE | command_flags::NO_COMMAND_YET,
        effectors: vec![
            EffectorState {
                kind: effector_kind::PANEL_PAIR,
                flags: 0,
                states: vec![0.5, -0.0625, 1.25, 0.03125],
                outputs: vec![],
            },
            EffectorState {
                kind: effector_kind::REACTION_WHEEL,
                flags: wheel_flags::TORQUE_LIMITED | wheel_flags::SPEED_LIMITED,
                states: vec![-150.5],
                outputs: vec![0.25, -0.0078125],
            },
        ],
    }
}

#[test]
fn state_golden() {
    let msg = state_msg();
    check("StateMsg", STATE_GOLDEN, &msg);
    // Fixed part, then per effector 22 bytes + 8 per value (4 + 0 and 1 + 2 values).
    assert_eq!(
        encode(&msg).len(),
        STATE_FIXED_LEN + 2 * EFFECTOR_STATE_FIXED_LEN + 8 * (4 + 3)
    );
    // The -0.0 survives the round trip with its sign bit.
    let back: StateMsg = decode(&golden_bytes(STATE_GOLDEN)).unwrap();
    assert!(back.nongrav_accel_bn_n_m_s2[1].is_sign_negative());
}

#[test]
fn state_without_effectors_is_the_fixed_part() {
    let mut msg = state_msg();
    msg.effectors.clear();
    let bytes = encode(&msg);
    assert_eq!(bytes.len(), STATE_FIXED_LEN);
    let golden = golden_bytes(STATE_GOLDEN);
    // Same bytes up to the count, which is now 0.
    assert_eq!(bytes[..319], golden[..319]);
    assert_eq!(bytes[319..], [0u8; 8]);
}

#[test]
fn imu_golden() {
    let msg = ImuMsg {
        header: Header::new(SC, 9, 9_000_000, 10),
        omega_p_rad_s: [1.0 / 1024.0, -0.5, 2.0],
        accel_p_m_s2: [0.0, 9.75, -0.125],
        dtheta_p_rad: [1.0 / 1_048_576.0, -2.0 / 1_048_576.0, 4.0 / 1_048_576.0],
        dv_p_m_s: [0.001, -1.5, 3.0],
        saturation_flags: saturation_flags::GYRO_RATE | saturation_flags::DV,
    };
    check("ImuMsg", IMU_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), IMU_LEN);
}

#[test]
fn command_wrench_golden() {
    let msg = CommandMsg::wrench(
        Header::new(SC, 42, 420_000_000, 7),
        0xDEAD_BEEF,
        [0.0625, -0.125, 0.25],
        [-1.0, 0.0, 0.5],
    );
    check("CommandMsg::Wrench", COMMAND_WRENCH_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), COMMAND_WRENCH_LEN);
}

#[test]
fn command_actuators_golden() {
    let msg = CommandMsg::actuators(
        Header::new(SC, 44, 440_000_000, 9),
        7,
        [0.5, -0.25, 0.0],
        [0.0, 0.0, -0.0],
        vec![
            EffectorInput {
                effector_index: 2,
                values: vec![0.0625],
            },
            EffectorInput {
                effector_index: 5,
                values: vec![-0.03125],
            },
        ],
    );
    check("CommandMsg::Actuators", COMMAND_ACTUATORS_GOLDEN, &msg);
    assert_eq!(
        encode(&msg).len(),
        COMMAND_ACTUATORS_FIXED_LEN + 2 * (EFFECTOR_INPUT_FIXED_LEN + 8)
    );
}

#[test]
fn star_tracker_golden() {
    let msg = StarTrackerMsg {
        header: Header::new(SC, 11, 110_000_000, 12),
        q_cn: [0.875, 0.25, -0.375, 0.1875],
        valid: false,
        status_flags: star_tracker_flags::SUN_EXCLUSION,
    };
    check("StarTrackerMsg", STAR_TRACKER_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), STAR_TRACKER_LEN);
}

/// The message [`TIME_GOLDEN`] describes.
pub fn time_golden_msg() -> TimeMsg {
    TimeMsg {
        header: Header::new(SC, 6, 750_000_000, 6),
        run_state: RunState::Paused,
        mode: Mode::RealTime,
        flags: time_flags::EPOCH_VALID | time_flags::LEAP_SECOND,
        frame_ns: 125_000_000,
        speed: 0.5,
        tai_ns_1958: 1_861_920_036_250_000_000,
        utc: UtcTime {
            year: 2016,
            month: 12,
            day: 31,
            hour: 23,
            minute: 59,
            second: 60,
            nanosecond: 250_000_000,
        },
        tai_minus_utc_s: 36,
        gps_week: 1930,
        gps_ns_of_week: 17_250_000_000,
        met_ns: 750_000_000,
        cuc_tai: [CUC_PFIELD_TAI_4_3, 0x6E, 0xFA, 0xA5, 0x24, 0x40, 0x00, 0x00],
        tone_met: SysTime {
            seconds: 0,
            subseconds: 0x8000_0000,
        },
        tone_tai: SysTime {
            seconds: 1_861_920_036,
            subseconds: 0,
        },
    }
}

#[test]
fn time_golden() {
    let msg = time_golden_msg();
    check("TimeMsg", TIME_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), TIME_LEN);
    assert_eq!(
        &encode(&msg)[TIME_CUC_OFFSET..TIME_CUC_OFFSET + 8],
        &msg.cuc_tai
    );
}

#[test]
fn magnetometer_golden() {
    let msg = MagnetometerMsg {
        header: Header::new(SC, 13, 130_000_000, 1),
        b_s_t: [0.000_030_517_578_125, -0.000_015_258_789_062_5, -0.0],
        saturation_flags: magnetometer_flags::AXIS_1 | magnetometer_flags::AXIS_3,
    };
    check("MagnetometerMsg", MAGNETOMETER_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), MAGNETOMETER_LEN);
}

#[test]
fn css_golden() {
    let mut readings = [0.0; MAX_CSS_DETECTORS];
    readings[..3].copy_from_slice(&[0.5, 0.75, 0.000_976_562_5]);
    let msg = CssMsg {
        header: Header::new(SC, 13, 130_000_000, 1),
        detector_count: 3,
        readings,
    };
    check("CssMsg", CSS_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), CSS_LEN);
    // A detector count above the maximum is malformed, at the maximum it decodes.
    let mut b = golden_bytes(CSS_GOLDEN);
    b[30] = MAX_CSS_DETECTORS as u8;
    assert!(decode::<CssMsg>(&b).is_ok());
    b[30] = MAX_CSS_DETECTORS as u8 + 1;
    assert!(
        matches!(decode::<CssMsg>(&b), Err(DecodeError::Malformed(ref m)) if m.contains("detector_count 17")),
        "{:?}",
        decode::<CssMsg>(&b)
    );
}

// ---- GpsMsg (protocol 7, issue 20): a self-contained block. ----
/// GpsMsg, hand-derived from proto/README.md (147 bytes).
const GPS_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "0d00000000000000", "u64 header.tick = 13"),
    (
        14,
        "80a4bf0700000000",
        "u64 header.sim_time_ns = 130000000 (0x7BFA480)",
    ),
    (22, "0100000000000000", "u64 header.seq = 1"),
    (
        30,
        "80c3c90100000000",
        "u64 valid_sim_time_ns = 30000000 (0x1C9C380)",
    ),
    (38, "5a090000", "u32 gps_week = 2394 (0x095A)"),
    (
        42,
        "000000000818f540",
        "f64 gps_seconds_of_week = 86400.5 (0x40F5180800000000)",
    ),
    (50, "000000000000f83f", "f64 r_be_e_m[0] = 1.5"),
    (58, "00000000000000c0", "f64 r_be_e_m[1] = -2.0"),
    (66, "000000000000d03f", "f64 r_be_e_m[2] = 0.25"),
    (74, "000000000000e03f", "f64 v_be_e_m_s[0] = 0.5"),
    (
        82,
        "0000000000000080",
        "f64 v_be_e_m_s[1] = -0.0 (sign bit)",
    ),
    (90, "0000000000001040", "f64 v_be_e_m_s[2] = 4.0"),
    (98, "0000000000002040", "f64 r_bn_n_m[0] = 8.0"),
    (106, "000000000000c03f", "f64 r_bn_n_m[1] = 0.125"),
    (114, "000000000000f0bf", "f64 r_bn_n_m[2] = -1.0"),
    (122, "0000000000000840", "f64 v_bn_n_m_s[0] = 3.0"),
    (130, "000000000000e0bf", "f64 v_bn_n_m_s[1] = -0.5"),
    (
        138,
        "0000000000009040",
        "f64 v_bn_n_m_s[2] = 1024.0 (0x4090000000000000)",
    ),
    (146, "07", "u8 flags = FIX | ECEF | INERTIAL"),
];

#[test]
fn gps_golden() {
    use flexdyn_proto::{gps_flags, GpsMsg, GPS_LEN};
    let msg = GpsMsg {
        header: Header::new(SC, 13, 130_000_000, 1),
        valid_sim_time_ns: 30_000_000,
        gps_week: 2394,
        gps_seconds_of_week: 86_400.5,
        r_be_e_m: [1.5, -2.0, 0.25],
        v_be_e_m_s: [0.5, -0.0, 4.0],
        r_bn_n_m: [8.0, 0.125, -1.0],
        v_bn_n_m_s: [3.0, -0.5, 1024.0],
        flags: gps_flags::FIX | gps_flags::ECEF | gps_flags::INERTIAL,
    };
    check("GpsMsg", GPS_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), GPS_LEN);
    assert_eq!(
        (gps_flags::FIX, gps_flags::ECEF, gps_flags::INERTIAL),
        (0b001, 0b010, 0b100)
    );
    assert_eq!(gps_flags::RESERVED_MASK, 0b1111_1000);
}
// ---- end GpsMsg ----

#[test]
fn fss_golden() {
    let msg = FssMsg {
        header: Header::new(SC, 13, 130_000_000, 1),
        alpha_rad: 0.125,
        beta_rad: -0.0625,
        flags: fss_flags::VALID | fss_flags::IN_FOV | fss_flags::SUNLIT,
    };
    check("FssMsg", FSS_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), FSS_LEN);
}

#[test]
fn command_no_command_golden() {
    let msg = CommandMsg::no_command(Header::new(SC, 43, 430_000_000, 8), 5);
    assert_eq!(msg.kind, CommandKind::NoCommand);
    check("CommandMsg::NoCommand", COMMAND_NO_COMMAND_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), COMMAND_NO_COMMAND_LEN);
}

#[test]
fn status_golden() {
    let msg = StatusMsg {
        header: Header::new(SC, 0x0102_0304_0506_0708, 1_500_000_000, 99),
        mode: Mode::Lockstep,
        run_state: RunState::Running,
        timing: FrameTiming {
            lateness_p50_ns: 1000,
            lateness_p99_ns: 250_000,
            lateness_max_ns: 3_000_000,
            overrun_count: 3,
            frames_skipped: 2,
        },
        command: CommandStatus {
            last_command_tick: 41,
            command_age_ns: 1_000_000,
            command_stale: true,
            stale_policy: StalePolicy::Zero,
        },
        rejected: RejectCounters {
            malformed: 1,
            bad_version: 2,
            non_finite: 3,
            wrong_spacecraft: 4,
            stale_tick: 5,
            unknown_sender: 6,
            bad_effector_input: 8,
            wrong_identity: 9,
            operator_refused: 10,
            fault_refused: 11,
            fsw_refused: 12,
        },
        commands_dropped: 7,
        wall_time_unix_ns: 1_700_000_000_123_456_789,
        faults_active: 3,
        faults_active_bits: [0b101, 0, 0, 1 << 63],
    };
    check("StatusMsg", STATUS_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), STATUS_LEN);
}

/// Every enum tag, pinned: the u32 at the tag's offset for each variant.
#[test]
fn operator_golden() {
    let msg = OperatorMsg::new(
        Header::new(SC, 44, 440_000_000, 3),
        OperatorAction::RunTicks,
        0x1_0000_0005,
    );
    check("OperatorMsg", OPERATOR_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), OPERATOR_LEN);
    for (action, tag) in [
        (OperatorAction::Pause, 0u32),
        (OperatorAction::Resume, 1),
        (OperatorAction::RunTicks, 2),
        (OperatorAction::Checkpoint, 3),
    ] {
        let bytes = encode(&OperatorMsg::new(Header::default(), action, 0));
        assert_eq!(
            u32::from_le_bytes(bytes[30..34].try_into().unwrap()),
            tag,
            "{action:?}"
        );
        assert_eq!(action.tag(), tag);
    }
}

/// Protocol 12: a `Checkpoint` operator command (issue 40 §2).
#[test]
fn operator_checkpoint_golden() {
    let msg = OperatorMsg::new(
        Header::new(SC, 44, 440_000_000, 4),
        OperatorAction::Checkpoint,
        1000,
    );
    check("OperatorMsg", OPERATOR_CHECKPOINT_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), OPERATOR_LEN);
}

/// Protocol 8: a fault event; every [`FaultSource`] tag pinned.
#[test]
fn fault_event_golden() {
    let msg = FaultEventMsg {
        header: Header::new(SC, 44, 440_000_000, 1),
        fault_index: 3,
        source: FaultSource::Live,
        mode: 2,
        active: true,
        edge_ns: 440_000_000,
        axes: 0b101,
        params: [0.25, 0.0],
        target: FaultTarget::new("imus.hub.gyro").unwrap(),
    };
    check("FaultEventMsg", FAULT_EVENT_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), FAULT_EVENT_LEN);
    for (source, tag) in [
        (FaultSource::Config, 0u32),
        (FaultSource::Live, 1),
        (FaultSource::Random, 2),
    ] {
        let bytes = encode(&FaultEventMsg { source, ..msg });
        assert_eq!(u32::from_le_bytes(bytes[34..38].try_into().unwrap()), tag);
        assert_eq!(source.tag(), tag);
    }
    assert_eq!(msg.target.as_str(), Some("imus.hub.gyro"));
}

/// Protocol 8: a live fault command; both [`FaultAction`] tags pinned, and a non-finite
/// parameter is rejected like a command's.
#[test]
fn fault_command_golden() {
    let msg = FaultCommandMsg {
        header: Header::new(SC, 44, 440_000_000, 2),
        action: FaultAction::Inject,
        at_tick: 0x1_0000_0005,
        fault_index: 0,
        mode: 10,
        params: [0.5, 0.0],
        axes: 0,
        duration_ns: 2_000_000_000,
        seed: 7,
        target: FaultTarget::new("reaction_wheels.rw2").unwrap(),
    };
    check("FaultCommandMsg", FAULT_COMMAND_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), FAULT_COMMAND_LEN);
    for (action, tag) in [(FaultAction::Inject, 0u32), (FaultAction::Clear, 1)] {
        let bytes = encode(&FaultCommandMsg { action, ..msg });
        assert_eq!(u32::from_le_bytes(bytes[30..34].try_into().unwrap()), tag);
        assert_eq!(action.tag(), tag);
    }
    let mut bad = encode(&msg);
    bad[58..66].copy_from_slice(&f64::NAN.to_le_bytes());
    assert!(matches!(
        decode::<FaultCommandMsg>(&bad),
        Err(flexdyn_proto::DecodeError::NonFinite { field: "params[1]" })
    ));
    // A target longer than the field, or holding a NUL, is refused when built.
    assert!(FaultTarget::new(&"x".repeat(FAULT_TARGET_LEN + 1)).is_none());
    assert!(FaultTarget::new("a\0b").is_none());
    assert_eq!(
        FaultTarget::truncated(&"é".repeat(100))
            .as_str()
            .unwrap()
            .len(),
        128
    );
}

#[test]
fn enum_tags() {
    let tag_at = |b: &[u8], at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    let status = |mode, run_state, stale_policy| {
        let mut s = StatusMsg {
            mode,
            run_state,
            ..Default::default()
        };
        s.command.stale_policy = stale_policy;
        encode(&s)
    };
    for (m, t) in [(Mode::RealTime, 0), (Mode::Lockstep, 1), (Mode::Batch, 2)] {
        assert_eq!(
            tag_at(&status(m, RunState::Starting, StalePolicy::Hold), 30),
            t,
            "{m:?}"
        );
        assert_eq!(m.tag(), t, "{m:?}.tag()");
    }
    for (r, t) in [
        (RunState::Starting, 0),
        (RunState::Running, 1),
        (RunState::Stopping, 2),
        (RunState::Finished, 3),
        (RunState::Failed, 4),
        (RunState::Stopped, 5),
        (RunState::Paused, 6),
    ] {
        assert_eq!(
            tag_at(&status(Mode::RealTime, r, StalePolicy::Hold), 34),
            t,
            "{r:?}"
        );
        assert_eq!((r.tag(), RunState::from_tag(t)), (t, Some(r)), "{r:?} tag");
    }
    assert_eq!(RunState::from_tag(7), None);
    let time = |run_state, mode| {
        encode(&TimeMsg {
            run_state,
            mode,
            ..Default::default()
        })
    };
    assert_eq!(tag_at(&time(RunState::Paused, Mode::Batch), 30), 6);
    assert_eq!(tag_at(&time(RunState::Paused, Mode::Batch), 34), 2);
    for (p, t) in [(StalePolicy::Hold, 0), (StalePolicy::Zero, 1)] {
        assert_eq!(
            tag_at(&status(Mode::RealTime, RunState::Starting, p), 95),
            t,
            "{p:?}"
        );
        assert_eq!(p.tag(), t, "{p:?}.tag()");
    }
}

#[test]
fn flag_bits() {
    assert_eq!(command_flags::STALE, 0b001);
    assert_eq!(command_flags::ZEROED_BY_POLICY, 0b010);
    assert_eq!(command_flags::NO_COMMAND_YET, 0b100);
    assert_eq!(command_flags::RESERVED_MASK, 0b1111_1000);
    assert_eq!(saturation_flags::GYRO_RATE, 0b0001);
    assert_eq!(saturation_flags::ACCEL, 0b0010);
    assert_eq!(saturation_flags::DTHETA, 0b0100);
    assert_eq!(saturation_flags::DV, 0b1000);
    assert_eq!(saturation_flags::RESERVED_MASK, 0b1111_0000);
    assert_eq!(star_tracker_flags::SUN_EXCLUSION, 0b01);
    assert_eq!(star_tracker_flags::RATE_LIMIT, 0b10);
    assert_eq!(star_tracker_flags::RESERVED_MASK, 0b1111_0000);
    assert_eq!(magnetometer_flags::AXIS_1, 0b001);
    assert_eq!(magnetometer_flags::AXIS_2, 0b010);
    assert_eq!(magnetometer_flags::AXIS_3, 0b100);
    assert_eq!(magnetometer_flags::RESERVED_MASK, 0b1111_1000);
    assert_eq!(fss_flags::VALID, 0b001);
    assert_eq!(fss_flags::IN_FOV, 0b010);
    assert_eq!(fss_flags::SUNLIT, 0b100);
    assert_eq!(fss_flags::RESERVED_MASK, 0b1111_1000);
    assert_eq!(time_flags::EPOCH_VALID, 0b001);
    assert_eq!(time_flags::TONE, 0b010);
    assert_eq!(time_flags::LEAP_SECOND, 0b100);
    assert_eq!(time_flags::RESERVED_MASK, 0b1111_1000);
    // 0 001 11 11: no extension, TAI 1958 (Level 1), 4 coarse octets, 3 fine octets.
    assert_eq!(CUC_PFIELD_TAI_4_3, 0b0001_1111);
    assert_eq!(wheel_flags::TORQUE_LIMITED, 0b01);
    assert_eq!(wheel_flags::SPEED_LIMITED, 0b10);
    assert_eq!(effector_kind::PANEL_PAIR, 1);
    assert_eq!(effector_kind::REACTION_WHEEL, 2);
    assert_eq!(effector_kind::MAGNETORQUER, 3);
    assert_eq!(effector_kind::THRUSTER, 4);
    assert_eq!(effector_kind::SLOSH_LINEAR, 6);
    assert_eq!(effector_kind::SLOSH_PENDULUM, 7);
    assert_eq!(effector_kind::PROPELLANT_TANK, 8);
    assert_eq!(propellant_tank_flags::EMPTY, 0b001);
    assert_eq!(magnetorquer_flags::SATURATED, 0b001);
    assert_eq!(thruster_flags::FIRING, 0b001);
    assert_eq!(thruster_flags::BELOW_MIN_ON_TIME, 0b010);
    assert_eq!(thruster_flags::COMMAND_CLIPPED, 0b100);
}

#[test]
fn environment_golden() {
    let msg = EnvironmentMsg {
        header: Header::new(SC, 17, 170_000_000, 2),
        tai_ns_1958: 0x0102_0304_0506_0708,
        flags: environment_flags::EPOCH_VALID
            | environment_flags::MAGNETIC
            | environment_flags::SUN
            | environment_flags::SHADOW
            | environment_flags::ATMOSPHERE
            | environment_flags::ALBEDO,
        eclipse: eclipse::PENUMBRA,
        b_n_t: [2f64.powi(-15), -(2f64.powi(-16)), 2f64.powi(-17)],
        b_b_t: [-0.0, 2f64.powi(-14), -(2f64.powi(-18))],
        sun_n: [0.5, -0.5, 0.75],
        sun_b: [0.25, 1.0, -0.125],
        moon_n: [-1.0, 0.375, 0.0625],
        shadow_factor: 0.625,
        density_kg_m3: 2f64.powi(-40),
        gravity_gradient: AppliedWrench {
            torque_b_nm: [2f64.powi(-20), -(2f64.powi(-21)), 2f64.powi(-22)],
            force_b_newton: [2f64.powi(-30), 0.0, -(2f64.powi(-31))],
        },
        drag: AppliedWrench {
            torque_b_nm: [1.5, -2.5, 3.5],
            force_b_newton: [4.0, -8.0, 16.0],
        },
        solar_pressure: AppliedWrench {
            torque_b_nm: [2f64.powi(-24), 2f64.powi(-25), 2f64.powi(-26)],
            force_b_newton: [-(2f64.powi(-24)), -(2f64.powi(-25)), -(2f64.powi(-26))],
        },
        residual_dipole: AppliedWrench {
            torque_b_nm: [0.125, -0.25, 2f64.powi(-7)],
            force_b_newton: [0.0; 3],
        },
        albedo_nadir_w_m2: 0.171875,
    };
    check("EnvironmentMsg", ENVIRONMENT_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), ENVIRONMENT_LEN);
    assert_eq!(eclipse::of_shadow_factor(1.0), eclipse::SUNLIT);
    assert_eq!(eclipse::of_shadow_factor(0.5), eclipse::PENUMBRA);
    assert_eq!(eclipse::of_shadow_factor(0.0), eclipse::UMBRA);
}

/// The golden vectors exported for the C and Python codecs (`proto/golden/*.bin`, listed in
/// `proto/golden/MANIFEST.tsv`) are byte for byte the tables above, and the manifest names
/// every table once with its message type and length.
#[test]
fn exported_golden_files_match_the_tables() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("golden");
    let tables: [(&str, &str, Golden, &str); 19] = [
        ("state", "StateMsg", STATE_GOLDEN, "STATE_GOLDEN"),
        ("imu", "ImuMsg", IMU_GOLDEN, "IMU_GOLDEN"),
        (
            "command_wrench",
            "CommandMsg",
            COMMAND_WRENCH_GOLDEN,
            "COMMAND_WRENCH_GOLDEN",
        ),
        (
            "command_actuators",
            "CommandMsg",
            COMMAND_ACTUATORS_GOLDEN,
            "COMMAND_ACTUATORS_GOLDEN",
        ),
        (
            "star_tracker",
            "StarTrackerMsg",
            STAR_TRACKER_GOLDEN,
            "STAR_TRACKER_GOLDEN",
        ),
        (
            "command_no_command",
            "CommandMsg",
            COMMAND_NO_COMMAND_GOLDEN,
            "COMMAND_NO_COMMAND_GOLDEN",
        ),
        ("status", "StatusMsg", STATUS_GOLDEN, "STATUS_GOLDEN"),
        (
            "magnetometer",
            "MagnetometerMsg",
            MAGNETOMETER_GOLDEN,
            "MAGNETOMETER_GOLDEN",
        ),
        ("time", "TimeMsg", TIME_GOLDEN, "TIME_GOLDEN"),
        // Protocol 6, the sun sensors.
        ("css", "CssMsg", CSS_GOLDEN, "CSS_GOLDEN"),
        (
            "environment",
            "EnvironmentMsg",
            ENVIRONMENT_GOLDEN,
            "ENVIRONMENT_GOLDEN",
        ),
        ("fss", "FssMsg", FSS_GOLDEN, "FSS_GOLDEN"),
        // Protocol 7, the GPS receiver.
        ("gps", "GpsMsg", GPS_GOLDEN, "GPS_GOLDEN"),
        (
            "operator",
            "OperatorMsg",
            OPERATOR_GOLDEN,
            "OPERATOR_GOLDEN",
        ),
        // Protocol 8, fault injection.
        (
            "fault_event",
            "FaultEventMsg",
            FAULT_EVENT_GOLDEN,
            "FAULT_EVENT_GOLDEN",
        ),
        (
            "fault_command",
            "FaultCommandMsg",
            FAULT_COMMAND_GOLDEN,
            "FAULT_COMMAND_GOLDEN",
        ),
        // Protocol 9, a fleet deputy's relative state.
        (
            "relative_state",
            "RelativeStateMsg",
            RELATIVE_STATE_GOLDEN,
            "RELATIVE_STATE_GOLDEN",
        ),
        // Protocol 10, the flight code's own telemetry.
        ("fsw", "FswMsg", FSW_GOLDEN, "FSW_GOLDEN"),
        // Protocol 12, the operator's checkpoint action.
        (
            "operator_checkpoint",
            "OperatorMsg",
            OPERATOR_CHECKPOINT_GOLDEN,
            "OPERATOR_CHECKPOINT_GOLDEN",
        ),
    ];
    let manifest = std::fs::read_to_string(dir.join("MANIFEST.tsv")).expect("MANIFEST.tsv");
    let rows: Vec<Vec<&str>> = manifest
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split('\t').collect())
        .collect();
    assert_eq!(rows.len(), tables.len(), "manifest rows");
    for (name, message, table, source) in tables {
        let bytes = golden_bytes(table);
        let file = std::fs::read(dir.join(format!("{name}.bin")))
            .unwrap_or_else(|e| panic!("proto/golden/{name}.bin: {e}"));
        assert!(
            file == bytes,
            "proto/golden/{name}.bin differs from {source}: re-export it from the table"
        );
        let row = rows
            .iter()
            .find(|r| r[0] == name)
            .unwrap_or_else(|| panic!("{name} missing from MANIFEST.tsv"));
        assert_eq!(
            row.as_slice(),
            [name, message, bytes.len().to_string().as_str(), source]
        );
    }
}

// ---- RelativeStateMsg (protocol 9, issue 22): a self-contained block. ----
/// RelativeStateMsg, hand-derived from proto/README.md (102 bytes): deputy 0x11223344 at
/// tick 1000 (t = 10 s) relative to chief 1.
const RELATIVE_STATE_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344), the deputy",
    ),
    (6, "e803000000000000", "u64 header.tick = 1000 (0x3E8)"),
    (
        14,
        "00e40b5402000000",
        "u64 header.sim_time_ns = 10000000000 (0x2540BE400)",
    ),
    (22, "e803000000000000", "u64 header.seq = 1000"),
    (30, "01000000", "u32 chief_spacecraft_id = 1"),
    (
        34,
        "44332211",
        "u32 deputy_spacecraft_id = 287454020 (0x11223344)",
    ),
    (
        38,
        "000000000000e03f",
        "f64 r_dc_h_m[0] = 0.5 (0x3FE0000000000000)",
    ),
    (
        46,
        "00000000000059c0",
        "f64 r_dc_h_m[1] = -100.0 (-1.5625 · 2^6: 0xC059000000000000)",
    ),
    (
        54,
        "0000000000000240",
        "f64 r_dc_h_m[2] = 2.25 (0x4002000000000000)",
    ),
    (
        62,
        "000000000000c03f",
        "f64 v_dc_h_m_s[0] = 0.125 (0x3FC0000000000000)",
    ),
    (
        70,
        "0000000000000080",
        "f64 v_dc_h_m_s[1] = -0.0 (sign bit)",
    ),
    (
        78,
        "0000000000000cc0",
        "f64 v_dc_h_m_s[2] = -3.5 (-1.75 · 2^1: 0xC00C000000000000)",
    ),
    (
        86,
        "0000000000025940",
        "f64 range_m = 100.03125 = (1 + 0x9020000000000 / 2^52) · 2^6 (0x4059020000000000)",
    ),
    (
        94,
        "000000000000d0bf",
        "f64 range_rate_m_s = -0.25 (0xBFD0000000000000)",
    ),
];

#[test]
fn relative_state_golden() {
    let msg = RelativeStateMsg {
        header: Header::new(SC, 1000, 10_000_000_000, 1000),
        chief_spacecraft_id: 1,
        deputy_spacecraft_id: SC,
        r_dc_h_m: [0.5, -100.0, 2.25],
        v_dc_h_m_s: [0.125, -0.0, -3.5],
        range_m: 100.031_25,
        range_rate_m_s: -0.25,
    };
    check("RelativeStateMsg", RELATIVE_STATE_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), RELATIVE_STATE_LEN);
    assert_eq!(RELATIVE_STATE_LEN, 102);
    let back = flexdyn_proto::decode_relative_state(&golden_bytes(RELATIVE_STATE_GOLDEN)).unwrap();
    assert!(back.v_dc_h_m_s[1].is_sign_negative(), "-0.0 keeps its sign");
}
// ---- end RelativeStateMsg ----

// ---- FswMsg (protocol 10, issue 37): a self-contained block. ----
/// FswMsg, hand-derived from proto/README.md (148 + 3 · 8 = 172 bytes): stream sample of
/// vehicle 0x11223344 answering tick 1000 (t = 10 s), its 7th, with every optional field set,
/// two events and three value words (an f64, an i64 and a bool, in that declared order).
const FSW_GOLDEN: &[(usize, &str, &str)] = &[
    (0, "0c00", "u16 header.protocol_version = 12"),
    (
        2,
        "44332211",
        "u32 header.spacecraft_id = 287454020 (0x11223344)",
    ),
    (6, "e803000000000000", "u64 header.tick = 1000 (0x3E8)"),
    (
        14,
        "00e40b5402000000",
        "u64 header.sim_time_ns = 10000000000 (0x2540BE400)",
    ),
    (22, "0700000000000000", "u64 header.seq = 7"),
    (
        30,
        "0f",
        "u8 flags = MODE | ESTIMATE | TARGET | COVARIANCE (bits 0–3)",
    ),
    (31, "02000000", "u32 mode = 2"),
    (
        35,
        "000000000000e03f",
        "f64 q_est_bn[0] = 0.5 (0x3FE0000000000000)",
    ),
    (
        43,
        "000000000000e0bf",
        "f64 q_est_bn[1] = -0.5 (0xBFE0000000000000)",
    ),
    (51, "000000000000e03f", "f64 q_est_bn[2] = 0.5"),
    (59, "000000000000e0bf", "f64 q_est_bn[3] = -0.5"),
    (
        67,
        "000000000000f03f",
        "f64 q_target_rn[0] = 1.0 (0x3FF0000000000000)",
    ),
    (75, "0000000000000000", "f64 q_target_rn[1] = 0.0"),
    (
        83,
        "0000000000000080",
        "f64 q_target_rn[2] = -0.0 (sign bit)",
    ),
    (91, "0000000000000000", "f64 q_target_rn[3] = 0.0"),
    (
        99,
        "000000000000d03f",
        "f64 att_var_b_rad2[0] = 0.25 (0x3FD0000000000000)",
    ),
    (
        107,
        "000000000000c03f",
        "f64 att_var_b_rad2[1] = 0.125 (0x3FC0000000000000)",
    ),
    (
        115,
        "000000000000b03e",
        "f64 att_var_b_rad2[2] = 2^-20 (exponent 1023 - 20 = 0x3EB: 0x3EB0000000000000)",
    ),
    (123, "02", "u8 event_count = 2"),
    (124, "0300", "u16 events[0] = 3"),
    (126, "0201", "u16 events[1] = 0x0102 (byte order)"),
    (128, "000000000000000000000000", "u16 events[2..8] = 0"),
    (140, "0300000000000000", "u64 values count = 3"),
    (
        148,
        "000000000000f8bf",
        "u64 values[0] = bits of f64 -1.5 (0xBFF8000000000000)",
    ),
    (
        156,
        "feffffffffffffff",
        "u64 values[1] = i64 -2 in two's complement (0xFFFFFFFFFFFFFFFE)",
    ),
    (164, "0100000000000000", "u64 values[2] = bool true"),
];

fn fsw_golden_msg() -> flexdyn_proto::FswMsg {
    use flexdyn_proto::fsw_flags;
    flexdyn_proto::FswMsg {
        header: Header::new(SC, 1000, 10_000_000_000, 7),
        flags: fsw_flags::MODE | fsw_flags::ESTIMATE | fsw_flags::TARGET | fsw_flags::COVARIANCE,
        mode: 2,
        q_est_bn: [0.5, -0.5, 0.5, -0.5],
        q_target_rn: [1.0, 0.0, -0.0, 0.0],
        att_var_b_rad2: [0.25, 0.125, 1.0 / 1_048_576.0],
        event_count: 2,
        events: [3, 0x0102, 0, 0, 0, 0, 0, 0],
        values: vec![(-1.5f64).to_bits(), (-2i64) as u64, 1],
    }
}

#[test]
fn fsw_golden() {
    let msg = fsw_golden_msg();
    check("FswMsg", FSW_GOLDEN, &msg);
    assert_eq!(encode(&msg).len(), flexdyn_proto::FSW_FIXED_LEN + 3 * 8);
    assert_eq!(flexdyn_proto::FSW_FIXED_LEN, 148);
    let back = flexdyn_proto::decode_fsw(&golden_bytes(FSW_GOLDEN)).unwrap();
    assert_eq!(back, msg);
    assert_eq!(back.event_indices(), &[3, 0x0102]);
    assert!(
        back.q_target_rn[2].is_sign_negative(),
        "-0.0 keeps its sign"
    );
    // Nine events, or a NaN in the estimate, are refused by every decoder.
    let mut bytes = golden_bytes(FSW_GOLDEN);
    bytes[123] = 9;
    assert!(matches!(
        flexdyn_proto::decode_fsw(&bytes),
        Err(DecodeError::Malformed(_))
    ));
    let mut bytes = golden_bytes(FSW_GOLDEN);
    bytes[35..43].copy_from_slice(&f64::NAN.to_le_bytes());
    assert!(matches!(
        flexdyn_proto::decode_fsw(&bytes),
        Err(DecodeError::NonFinite {
            field: "q_est_bn[0]"
        })
    ));
}
// ---- end FswMsg ----
