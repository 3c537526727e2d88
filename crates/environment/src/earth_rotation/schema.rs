//! The Earth's orientation's keys of `[environment]`:
//!
//! | key | meaning | default |
//! |---|---|---|
//! | `earth_rotation` | `"iau2006"` or `"uniform"` | `"iau2006"` |
//! | `earth_rotation_rate_rad_s`, `earth_rotation_angle_rad` | `earth_rotation = "uniform"` | ω⊕; 0 |
//!
//! The Earth's orientation is not a model of the sample's: it is an input of those that work
//! in the Earth-fixed frame ([`crate::model::part::Needs::frame`]), evaluated by the update
//! itself ([`crate::model`]).

use super::{EarthOrientationModel, UniformRotation, OMEGA_EARTH_RAD_S};
use crate::model::schema::{bounded, invalid, refuse_unused};
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The keys of the Earth's orientation.
pub const KEYS: [&str; 3] = [
    "earth_rotation",
    "earth_rotation_rate_rad_s",
    "earth_rotation_angle_rad",
];

/// `earth_rotation`: `"iau2006"` (default) or `"uniform"` with its rate and angle.
pub fn read(t: &TableReader<'_, '_>) -> Result<EarthOrientationModel, SchemaError> {
    let uniform_keys = ["earth_rotation_rate_rad_s", "earth_rotation_angle_rad"];
    let name = match t.get("earth_rotation") {
        None => "iau2006".to_string(),
        Some(_) => t.string("earth_rotation")?,
    };
    match name.as_str() {
        "iau2006" => {
            refuse_unused(t, &uniform_keys, "earth_rotation = \"uniform\"")?;
            Ok(EarthOrientationModel::Iau2006)
        }
        "uniform" => Ok(EarthOrientationModel::Uniform(UniformRotation {
            rate_rad_s: bounded(
                t,
                "earth_rotation_rate_rad_s",
                OMEGA_EARTH_RAD_S,
                |w| w.abs() <= 1.0,
                "a rate within ±1 rad/s (the Earth's is 7.292115e-5)",
            )?,
            angle_at_t0_rad: bounded(
                t,
                "earth_rotation_angle_rad",
                0.0,
                |a| a.abs() <= 1e3,
                "an angle within ±1000 rad",
            )?,
        })),
        other => Err(invalid(
            t,
            "earth_rotation",
            format!("unknown model \"{other}\" (expected \"iau2006\" or \"uniform\")"),
        )),
    }
}
