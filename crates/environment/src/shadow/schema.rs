//! The shadow's keys of `[environment]`:
//!
//! | key | meaning | default |
//! |---|---|---|
//! | `shadow` | `"conical"`, `"cylindrical"` or `"off"` (needs `sun = true`) | `"off"` |
//! | `shadow_earth_radius_m`, `shadow_sun_radius_m` | with a shadow model: the two spheres | 6378137 m; 695700 km |

use super::{ShadowModel, EARTH_SHADOW_RADIUS_M};
use crate::ephemeris::{EphemerisSetting, SUN_RADIUS_M};
use crate::model::schema::{bounded, choice, invalid, refuse_unused};
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The keys of the shadow.
pub const KEYS: [&str; 3] = ["shadow", "shadow_earth_radius_m", "shadow_sun_radius_m"];

/// The shadow model and its two spheres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowSetting {
    /// Shadow geometry (needs the Sun), or none (full sunlight).
    pub model: Option<ShadowModel>,
    /// \[m\] the occulting Earth's radius for the shadow (default WGS-84 a); also the albedo's
    /// sphere.
    pub earth_radius_m: f64,
    /// \[m\] the Sun's radius for the shadow (default the IAU 2015 nominal radius).
    pub sun_radius_m: f64,
}

impl Default for ShadowSetting {
    fn default() -> Self {
        Self {
            model: None,
            earth_radius_m: EARTH_SHADOW_RADIUS_M,
            sun_radius_m: SUN_RADIUS_M,
        }
    }
}

/// Reads `shadow` and its radii; `ephemeris` says whether the Sun is on.
pub fn read(
    t: &TableReader<'_, '_>,
    ephemeris: &EphemerisSetting,
) -> Result<ShadowSetting, SchemaError> {
    let model = match choice(t, "shadow", &["conical", "cylindrical", "off"])? {
        "conical" => Some(ShadowModel::Conical),
        "cylindrical" => Some(ShadowModel::Cylindrical),
        _ => None,
    };
    if model.is_some() && !ephemeris.sun {
        return Err(invalid(
            t,
            "shadow",
            format!("a shadow needs the Sun: set {} = true", t.field("sun")),
        ));
    }
    let (earth_radius_m, sun_radius_m) = shadow_radii(t, model.is_some())?;
    Ok(ShadowSetting {
        model,
        earth_radius_m,
        sun_radius_m,
    })
}

/// `shadow_earth_radius_m` and `shadow_sun_radius_m` (only with a shadow model).
fn shadow_radii(t: &TableReader<'_, '_>, shadow_on: bool) -> Result<(f64, f64), SchemaError> {
    let keys = ["shadow_earth_radius_m", "shadow_sun_radius_m"];
    if !shadow_on {
        refuse_unused(t, &keys, "a shadow model")?;
    }
    let earth = bounded(
        t,
        "shadow_earth_radius_m",
        EARTH_SHADOW_RADIUS_M,
        |r| r > 0.0 && r <= 1e8,
        "a radius > 0 and <= 1e8 m (WGS-84 a is 6378137 m)",
    )?;
    let sun = bounded(
        t,
        "shadow_sun_radius_m",
        SUN_RADIUS_M,
        |r| r > 0.0 && r <= 1e10,
        "a radius > 0 and <= 1e10 m (the Sun's is 6.957e8 m)",
    )?;
    Ok((earth, sun))
}
