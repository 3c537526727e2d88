//! The `[environment]` keys of the dynamic effectors' constants, and the readers' helpers.
//!
//! Each environment model reads its own keys, constants included, in its folder
//! (`magnetic/schema.rs`, `atmosphere/schema.rs`, `ephemeris/schema.rs`, `shadow/schema.rs`,
//! `albedo/schema.rs`, `earth_rotation/schema.rs`), so that a run can be matched to a reference
//! tool or a published case (docs/models/world-environment.md, "Matching a reference"); each key
//! is optional, and without it the model is today's, to the bit. The keys read here belong to
//! the dynamic effectors the table switches on:
//!
//! | key | used by | default |
//! |---|---|---|
//! | `solar_irradiance_1au_w_m2` | `solar_pressure`, and the models that read it (`albedo`) | 1361 W/m² |
//! | `solar_pressure_model`, `cannonball_area_m2`, `cannonball_reflectivity_coefficient`, `cannonball_r_cp_b_m` | `solar_pressure` | `"facets"` |

use nalgebra::Vector3;

use super::schema::invalid;
use crate::cannonball::Cannonball;
use crate::facets::SOLAR_IRRADIANCE_1AU_W_M2;
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::{SchemaError, TableReader};

/// The keys this file reads.
pub const KEYS: [&str; 5] = [
    "solar_irradiance_1au_w_m2",
    "solar_pressure_model",
    "cannonball_area_m2",
    "cannonball_reflectivity_coefficient",
    "cannonball_r_cp_b_m",
];

/// How far from 1 a configured unit vector's length may be.
const UNIT_TOLERANCE: f64 = 1e-6;

/// The error if any of `keys` is given although `what` is not on.
pub(crate) fn refuse_unused(
    t: &TableReader<'_, '_>,
    keys: &[&str],
    used_by: &str,
) -> Result<(), SchemaError> {
    match keys.iter().find(|k| t.get(k).is_some()) {
        Some(k) => Err(invalid(
            t,
            k,
            format!("only used by {used_by}; remove it or switch that model on"),
        )),
        None => Ok(()),
    }
}

/// A unit vector at `key` (its length within [`UNIT_TOLERANCE`] of 1).
pub(crate) fn unit_vector(t: &TableReader<'_, '_>, key: &str) -> Result<Vector3<f64>, SchemaError> {
    let v = Vector3::from(t.floats::<3>(key)?);
    if (v.norm() - 1.0).abs() > UNIT_TOLERANCE {
        return Err(invalid(
            t,
            key,
            format!(
                "|v| = {}: expected a unit vector (length 1 within {UNIT_TOLERANCE})",
                Num(v.norm())
            ),
        ));
    }
    Ok(v)
}

/// A number at `key` (default `default`) that must satisfy `ok`, else `expected` is the message.
pub(crate) fn bounded(
    t: &TableReader<'_, '_>,
    key: &str,
    default: f64,
    ok: impl Fn(f64) -> bool,
    expected: &str,
) -> Result<f64, SchemaError> {
    let v = t.opt_f64(key)?.unwrap_or(default);
    if !ok(v) {
        return Err(invalid(t, key, format!("{}: expected {expected}", Num(v))));
    }
    Ok(v)
}

/// `solar_irradiance_1au_w_m2` (only with solar pressure or a model that reads it: `users`
/// are the switches of those, for the error when it is given unused).
pub(super) fn irradiance(
    t: &TableReader<'_, '_>,
    used: bool,
    users: &[&str],
) -> Result<f64, SchemaError> {
    if !used {
        let users: Vec<&str> = std::iter::once("solar_pressure = true")
            .chain(users.iter().copied())
            .collect();
        refuse_unused(t, &["solar_irradiance_1au_w_m2"], &users.join(" or "))?;
    }
    bounded(
        t,
        "solar_irradiance_1au_w_m2",
        SOLAR_IRRADIANCE_1AU_W_M2,
        |w| w > 0.0 && w <= 1e5,
        "an irradiance > 0 and <= 1e5 W/m² (the Sun's at 1 au is about 1361)",
    )
}

/// `solar_pressure_model`: `"facets"` (default, `None`) or `"cannonball"` with its keys.
pub(super) fn cannonball(
    t: &TableReader<'_, '_>,
    solar_pressure: bool,
) -> Result<Option<Cannonball>, SchemaError> {
    let keys = [
        "cannonball_area_m2",
        "cannonball_reflectivity_coefficient",
        "cannonball_r_cp_b_m",
    ];
    if !solar_pressure {
        refuse_unused(t, &["solar_pressure_model"], "solar_pressure = true")?;
    }
    let name = match t.get("solar_pressure_model") {
        None => "facets".to_string(),
        Some(_) => t.string("solar_pressure_model")?,
    };
    match name.as_str() {
        "facets" => {
            refuse_unused(t, &keys, "solar_pressure_model = \"cannonball\"")?;
            Ok(None)
        }
        "cannonball" => {
            let ball = Cannonball {
                area_m2: t.f64("cannonball_area_m2")?,
                reflectivity_coefficient: t.f64("cannonball_reflectivity_coefficient")?,
                r_cp_b_m: t
                    .opt_floats::<3>("cannonball_r_cp_b_m")?
                    .map_or(Vector3::zeros(), Vector3::from),
            };
            ball.validate()
                .map_err(|(key, message)| invalid(t, key, message))?;
            Ok(Some(ball))
        }
        other => Err(invalid(
            t,
            "solar_pressure_model",
            format!("unknown model \"{other}\" (expected \"facets\" or \"cannonball\")"),
        )),
    }
}
