//! The Sun's and the Moon's keys of `[environment]`:
//!
//! | key | meaning | default |
//! |---|---|---|
//! | `sun` | the Sun's position (the ephemeris, or a fixed Sun) | false |
//! | `moon` | the Moon's position (the ephemeris) | false |
//! | `sun_direction_n`, `sun_distance_m` | `sun = true`: a fixed geocentric Sun in N instead of the ephemeris | the ephemeris; 1 au |

use nalgebra::Vector3;

use super::AU_M;
use crate::model::schema::{bounded, refuse_unused, unit_vector};
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The keys of the Sun and the Moon.
pub const KEYS: [&str; 4] = ["sun", "moon", "sun_direction_n", "sun_distance_m"];

/// Which of the Sun and the Moon are on.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EphemerisSetting {
    /// The Sun (from the ephemeris unless [`Self::sun_fixed_n_m`] is set).
    pub sun: bool,
    /// \[m\] a fixed geocentric Sun position in N (`sun_direction_n` × `sun_distance_m`)
    /// instead of the ephemeris.
    pub sun_fixed_n_m: Option<Vector3<f64>>,
    /// The Moon ephemeris.
    pub moon: bool,
}

/// Reads `sun`, `moon` and a fixed Sun.
pub fn read(t: &TableReader<'_, '_>) -> Result<EphemerisSetting, SchemaError> {
    let sun = t.opt_bool("sun")?.unwrap_or(false);
    let moon = t.opt_bool("moon")?.unwrap_or(false);
    let sun_fixed_n_m = sun_fixed(t, sun)?;
    Ok(EphemerisSetting {
        sun,
        sun_fixed_n_m,
        moon,
    })
}

/// `sun_direction_n` and `sun_distance_m`: a fixed geocentric Sun (only with `sun = true`).
fn sun_fixed(t: &TableReader<'_, '_>, sun: bool) -> Result<Option<Vector3<f64>>, SchemaError> {
    if !sun {
        refuse_unused(t, &["sun_direction_n", "sun_distance_m"], "sun = true")?;
        return Ok(None);
    }
    if t.get("sun_direction_n").is_none() {
        refuse_unused(t, &["sun_distance_m"], "a fixed Sun (sun_direction_n)")?;
        return Ok(None);
    }
    let direction_n = unit_vector(t, "sun_direction_n")?;
    let distance_m = bounded(
        t,
        "sun_distance_m",
        AU_M,
        |d| (1e6..=1e14).contains(&d),
        "a distance from 1e6 m to 1e14 m (1 au is 1.495978707e11 m)",
    )?;
    Ok(Some(direction_n * distance_m))
}
