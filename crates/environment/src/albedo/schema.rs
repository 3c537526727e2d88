//! The albedo's keys of `[environment]`:
//!
//! | key | meaning | default |
//! |---|---|---|
//! | `albedo` | `"lambertian"` or `"off"` (needs `sun = true`) | `"off"` |
//! | `albedo_coefficient` | `albedo = "lambertian"`: the coefficient a, 0..=1 | 0.3 |
//!
//! The sphere is the shadow's (`shadow_earth_radius_m`) and the irradiance
//! `solar_irradiance_1au_w_m2`.

use super::DEFAULT_ALBEDO_COEFFICIENT;
use crate::ephemeris::EphemerisSetting;
use crate::model::schema::{bounded, choice, invalid, refuse_unused};
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The keys of the albedo.
pub const KEYS: [&str; 2] = ["albedo", "albedo_coefficient"];

/// Reads `albedo` and `albedo_coefficient`: the coefficient a when albedo is on, `None` when
/// off. `ephemeris` says whether the Sun is on.
pub fn read(
    t: &TableReader<'_, '_>,
    ephemeris: &EphemerisSetting,
) -> Result<Option<f64>, SchemaError> {
    let albedo_on = match choice(t, "albedo", &["lambertian", "off"])? {
        "lambertian" => {
            if !ephemeris.sun {
                return Err(invalid(
                    t,
                    "albedo",
                    format!(
                        "albedo is sunlight reflected by the Earth: set {} = true",
                        t.field("sun")
                    ),
                ));
            }
            true
        }
        _ => false,
    };
    albedo_coefficient(t, albedo_on)
}

/// `albedo_coefficient` (only with `albedo = "lambertian"`, default
/// [`DEFAULT_ALBEDO_COEFFICIENT`]): `Some(a)` when albedo is on.
fn albedo_coefficient(
    t: &TableReader<'_, '_>,
    albedo_on: bool,
) -> Result<Option<f64>, SchemaError> {
    if !albedo_on {
        refuse_unused(t, &["albedo_coefficient"], "albedo = \"lambertian\"")?;
        return Ok(None);
    }
    bounded(
        t,
        "albedo_coefficient",
        DEFAULT_ALBEDO_COEFFICIENT,
        |a| (0.0..=1.0).contains(&a),
        "an albedo coefficient from 0 to 1 (the Earth's mean is about 0.3)",
    )
    .map(Some)
}
