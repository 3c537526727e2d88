//! Reaction-wheel values that are legal but almost surely a unit slip
//! ([`flexdyn_kernel::schema::plausible`]).
//!
//! Wheel datasheets give speeds in rpm and, for small wheels, torques in mN·m; the keys are
//! rad/s and N·m. Where catalogue wheels lie, and where a warning starts:
//! - speed: reaction and momentum wheels spin at up to about 6000–10 000 rpm (630–1050 rad/s).
//!   Above 1500 rad/s (≈ 14 300 rpm) is a warning: 6000 rpm typed as rad/s is 6000 rad/s.
//! - motor torque: from about 1 mN·m (CubeSat wheels) to a few tenths of a N·m (the wheels of
//!   large spacecraft). Above 1 N·m is a warning: 5 mN·m typed as N·m is 5 N·m.
//! - Coulomb (bearing) friction: micro-N·m to a few mN·m, always well under the motor torque.
//!   Above 0.1 N·m is a warning.

use super::ReactionWheelParams;
use flexdyn_kernel::schema::plausible::{Implausible, Range};

/// \[rad/s per rpm\]
const RPM: f64 = std::f64::consts::TAU / 60.0;

/// The implausible values of `w` (at `path`, e.g. `reaction_wheels[0]`).
pub fn check(w: &ReactionWheelParams, path: &str, out: &mut Vec<Implausible>) {
    let speed = || Range {
        what: "a reaction wheel's speed",
        si: "rad/s",
        plausible: (1.0, 1500.0),
        units: &[("rpm", RPM)],
    };
    let torque = |what| Range {
        what,
        si: "N·m",
        plausible: (1e-7, 1.0),
        units: &[("mN·m", 1e-3)],
    };
    let rows = [
        ("max_speed_rad_s", w.max_speed_rad_s, speed()),
        ("omega_rad_s", w.omega_rad_s, speed()),
        (
            "max_torque_nm",
            w.max_torque_nm,
            torque("a reaction wheel's motor torque"),
        ),
        (
            "coulomb_friction_nm",
            w.coulomb_friction_nm,
            Range {
                plausible: (1e-7, 0.1),
                ..torque("a reaction wheel's bearing friction")
            },
        ),
    ];
    for (key, value, range) in rows {
        out.extend(range.above(format!("{path}.{key}"), value));
    }
}
