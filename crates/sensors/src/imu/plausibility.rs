//! IMU values that are legal but almost surely a unit slip ([`flexdyn_kernel::schema::plausible`]).
//!
//! Gyro datasheets give °/√h, °/h, °/s and °/s/√Hz; accelerometer datasheets give µg, mg, g
//! and m/s/√h. The keys are SI, so the typical slip is a datasheet number typed as it stands.
//! Where real hardware lies (the grade tables of Groves, *Principles of GNSS, Inertial, and
//! Multisensor Integrated Navigation Systems*, 2nd ed., 2013, ch. 4, and consumer MEMS
//! datasheets), and where a warning starts:
//!
//! | key | hardware | warning above |
//! |---|---|---|
//! | `arw_rad_s_sqrt_hz` | 0.001 °/√h (navigation) to ≈ 0.01 °/s/√Hz (consumer MEMS, 1.7e-4 rad/s/√Hz) | 0.01 rad/√s (≈ 0.6 °/s/√Hz) |
//! | `bias_instability_sigma_rad_s` | 0.001 °/h to ≈ 100 °/h (4.8e-4 rad/s) | 0.01 rad/s (≈ 2000 °/h) |
//! | `bias_rad_s` | up to ±20 °/s zero-rate offset of uncalibrated consumer MEMS (0.35 rad/s) | 1 rad/s (57 °/s) |
//! | `range_rad_s` | ±75 °/s to ±4000 °/s (1.3–70 rad/s) | 100 rad/s (5700 °/s) |
//! | `lsb_rad_s` | 0.061 °/s (16 bits over ±2000 °/s, 1.1e-3 rad/s) and finer | 0.05 rad/s (2.9 °/s) |
//! | `misalignment_rad` | ≤ 2 % cross-axis sensitivity (consumer MEMS) | 0.03 rad |
//! | `vrw_m_s2_sqrt_hz` | ≈ 10 µg/√Hz (navigation) to ≈ 400 µg/√Hz (consumer MEMS, 3.9e-3 m/s²/√Hz) | 0.02 m/s²/√Hz (≈ 2 mg/√Hz) |
//! | `bias_instability_sigma_m_s2` | ≈ 10 µg to ≈ 1 mg (9.8e-3 m/s²) | 0.1 m/s² (≈ 10 mg) |
//! | `bias_m_s2` | up to ≈ ±100 mg zero-g offset of uncalibrated consumer MEMS (≈ 1 m/s²) | 2 m/s² (≈ 200 mg) |
//! | `range_m_s2` | ±1.5 g to ±100 g; no accelerometer's full scale is under 1 g | warning *below* 9.80665 m/s² (1 g) |

use super::ImuConfig;
use flexdyn_kernel::schema::plausible::{Implausible, Range, DEG, G0};

/// \[rad/s per °/h\]
const DEG_H: f64 = DEG / 3600.0;
/// \[m/s² per µg\]
const UG: f64 = G0 * 1e-6;
/// \[m/s² per mg\]
const MG: f64 = G0 * 1e-3;

/// The implausible values of `imu` (at `path`, e.g. `imus[0]`).
pub(crate) fn check(imu: &ImuConfig, path: &str, out: &mut Vec<Implausible>) {
    let (g, a) = (&imu.gyro, &imu.accel);
    const MISALIGNMENT: Range = Range {
        what: "an IMU axis misalignment",
        si: "rad",
        plausible: (1e-7, 0.03),
        units: &[("°", DEG), ("mrad", 1e-3)],
    };
    let rows = [
        (
            "gyro.arw_rad_s_sqrt_hz",
            g.arw_rad_s_sqrt_hz,
            Range {
                what: "a gyro's angle random walk",
                si: "rad/s/√Hz",
                plausible: (1e-8, 0.01),
                units: &[("°/√h", DEG / 60.0), ("°/s/√Hz", DEG)],
            },
        ),
        (
            "gyro.bias_instability_sigma_rad_s",
            g.bias_instability_sigma_rad_s,
            Range {
                what: "a gyro's bias instability",
                si: "rad/s",
                plausible: (1e-9, 0.01),
                units: &[("°/h", DEG_H), ("°/s", DEG)],
            },
        ),
        (
            "gyro.bias_rad_s",
            g.bias_rad_s.amax(),
            Range {
                what: "a gyro's bias",
                si: "rad/s",
                plausible: (1e-9, 1.0),
                units: &[("°/h", DEG_H), ("°/s", DEG)],
            },
        ),
        (
            "gyro.range_rad_s",
            g.range_rad_s,
            Range {
                what: "a gyro's full scale",
                si: "rad/s",
                plausible: (0.1, 100.0),
                units: &[("°/s", DEG)],
            },
        ),
        (
            "gyro.lsb_rad_s",
            g.lsb_rad_s,
            Range {
                what: "a gyro's output resolution",
                si: "rad/s",
                plausible: (1e-9, 0.05),
                units: &[("°/s", DEG)],
            },
        ),
        (
            "gyro.misalignment_rad",
            g.misalignment_rad.amax(),
            MISALIGNMENT,
        ),
        (
            "accel.vrw_m_s2_sqrt_hz",
            a.vrw_m_s2_sqrt_hz,
            Range {
                what: "an accelerometer's velocity random walk",
                si: "m/s²/√Hz",
                plausible: (1e-6, 0.02),
                units: &[("m/s/√h", 1.0 / 60.0), ("µg/√Hz", UG), ("mg/√Hz", MG)],
            },
        ),
        (
            "accel.bias_instability_sigma_m_s2",
            a.bias_instability_sigma_m_s2,
            Range {
                what: "an accelerometer's bias instability",
                si: "m/s²",
                plausible: (1e-8, 0.1),
                units: &[("µg", UG), ("mg", MG)],
            },
        ),
        (
            "accel.bias_m_s2",
            a.bias_m_s2.amax(),
            Range {
                what: "an accelerometer's bias",
                si: "m/s²",
                plausible: (1e-8, 2.0),
                units: &[("µg", UG), ("mg", MG)],
            },
        ),
        (
            "accel.misalignment_rad",
            a.misalignment_rad.amax(),
            MISALIGNMENT,
        ),
    ];
    for (key, value, range) in rows {
        out.extend(range.above(format!("{path}.{key}"), value));
    }
    // The one slip that makes a value too small: a full scale in g typed as m/s².
    let full_scale = Range {
        what: "an accelerometer's full scale",
        si: "m/s²",
        plausible: (G0, 2000.0),
        units: &[("g", G0)],
    };
    out.extend(full_scale.below(format!("{path}.accel.range_m_s2"), a.range_m_s2));
}
