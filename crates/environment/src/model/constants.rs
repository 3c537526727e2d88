//! The `[environment]` keys that set each model's constants and definitions, so that a run can
//! be matched to a reference tool or a published case (docs/models/world-environment.md,
//! "Matching a reference"). Each is optional: without it the model is today's, to the bit.
//!
//! | key | model | default |
//! |---|---|---|
//! | `dipole_g10_nt`, `dipole_g11_nt`, `dipole_h11_nt`, `dipole_radius_m` | `magnetic = "dipole"` | g₁¹ = h₁¹ = 0; a = 6371.2 km |
//! | `dipole_moment_am2`, `dipole_axis_e` | `magnetic = "dipole"` (instead of the coefficients) | — |
//! | `exponential_base_altitude_m`, `exponential_base_density_kg_m3`, `exponential_scale_height_m` | `atmosphere = "exponential"` | Vallado Table 8-4 |
//! | `exponential_altitude`, `exponential_radius_m` | `atmosphere = "exponential"` | `"geodetic"` |
//! | `corotating_wind` | any atmosphere | true |
//! | `earth_rotation`, `earth_rotation_rate_rad_s`, `earth_rotation_angle_rad` | the Earth-fixed frame | `"iau2006"` |
//! | `sun_direction_n`, `sun_distance_m` | `sun = true` | the ephemeris; 1 au |
//! | `shadow_earth_radius_m`, `shadow_sun_radius_m` | `shadow` | 6378137 m; 695700 km |
//! | `solar_irradiance_1au_w_m2` | `solar_pressure`, `albedo` | 1361 W/m² |
//! | `albedo_coefficient` | `albedo = "lambertian"` | 0.3 |
//! | `solar_pressure_model`, `cannonball_area_m2`, `cannonball_reflectivity_coefficient`, `cannonball_r_cp_b_m` | `solar_pressure` | `"facets"` |

use nalgebra::Vector3;

use super::schema::invalid;
use crate::albedo::DEFAULT_ALBEDO_COEFFICIENT;
use crate::atmosphere::{
    AltitudeDefinition, AtmosphereError, ExponentialAtmosphere, ExponentialBand,
};
use crate::cannonball::Cannonball;
use crate::earth_rotation::{EarthOrientationModel, UniformRotation, OMEGA_EARTH_RAD_S};
use crate::ephemeris::{AU_M, SUN_RADIUS_M};
use crate::facets::SOLAR_IRRADIANCE_1AU_W_M2;
use crate::geodetic::WGS84_A_M;
use crate::magnetic::igrf::IGRF_REFERENCE_RADIUS_M;
use crate::magnetic::CentredDipole;
use crate::shadow::EARTH_SHADOW_RADIUS_M;
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::{concat_keys, SchemaError, TableReader};

/// The keys this file reads (the tail of [`super::schema::KEYS`]).
pub const KEYS: [&str; 25] = concat_keys(
    concat_keys::<6, 5, 11>(DIPOLE_KEYS, EXPONENTIAL_KEYS),
    OTHER_KEYS,
);

/// The keys of the wind, the Earth's rotation, the Sun, the shadow and solar pressure.
const OTHER_KEYS: [&str; 14] = [
    "corotating_wind",
    "earth_rotation",
    "earth_rotation_rate_rad_s",
    "earth_rotation_angle_rad",
    "sun_direction_n",
    "sun_distance_m",
    "shadow_earth_radius_m",
    "shadow_sun_radius_m",
    "solar_irradiance_1au_w_m2",
    "solar_pressure_model",
    "cannonball_area_m2",
    "cannonball_reflectivity_coefficient",
    "cannonball_r_cp_b_m",
    "albedo_coefficient",
];

/// The Gauss-coefficient keys of `magnetic = "dipole"`.
const DIPOLE_COEFFICIENT_KEYS: [&str; 4] = [
    "dipole_g10_nt",
    "dipole_g11_nt",
    "dipole_h11_nt",
    "dipole_radius_m",
];
/// The moment keys of `magnetic = "dipole"`.
const DIPOLE_MOMENT_KEYS: [&str; 2] = ["dipole_moment_am2", "dipole_axis_e"];
/// Every `dipole_*` key.
pub(super) const DIPOLE_KEYS: [&str; 6] = concat_keys(DIPOLE_COEFFICIENT_KEYS, DIPOLE_MOMENT_KEYS);
/// Every `exponential_*` key.
pub(super) const EXPONENTIAL_KEYS: [&str; 5] = [
    "exponential_base_altitude_m",
    "exponential_base_density_kg_m3",
    "exponential_scale_height_m",
    "exponential_altitude",
    "exponential_radius_m",
];
/// \[nT\] the largest |g₁| accepted (the Earth's is about 30 000 nT; Jupiter's 420 000 nT).
const MAX_DIPOLE_COEFFICIENT_NT: f64 = 1e7;
/// \[A·m²\] the largest planetary dipole moment accepted (the Earth's is 7.7e22; Jupiter's
/// 1.6e27).
const MAX_PLANET_DIPOLE_AM2: f64 = 1e30;
/// How far from 1 a configured unit vector's length may be.
const UNIT_TOLERANCE: f64 = 1e-6;

/// The error if any of `keys` is given although `what` is not on.
pub(super) fn refuse_unused(
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
fn unit_vector(t: &TableReader<'_, '_>, key: &str) -> Result<Vector3<f64>, SchemaError> {
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
fn bounded(
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

/// `magnetic = "dipole"`: the dipole of the given Gauss coefficients (g₁⁰ required, g₁¹ and
/// h₁¹ default 0, at `dipole_radius_m`, default IGRF's 6371.2 km) or of a moment along an
/// Earth-fixed axis.
pub(super) fn given_dipole(t: &TableReader<'_, '_>) -> Result<CentredDipole, SchemaError> {
    let has = |keys: &[&str]| keys.iter().any(|k| t.get(k).is_some());
    match (has(&DIPOLE_COEFFICIENT_KEYS), has(&DIPOLE_MOMENT_KEYS)) {
        (true, true) => Err(invalid(
            t,
            "dipole_moment_am2",
            "give the dipole either as Gauss coefficients (dipole_g10_nt, …) or as a moment \
             (dipole_moment_am2 and dipole_axis_e), not both"
                .into(),
        )),
        (false, false) => Err(invalid(
            t,
            "magnetic",
            "magnetic = \"dipole\" needs its dipole: dipole_g10_nt (and optionally \
             dipole_g11_nt, dipole_h11_nt, dipole_radius_m), or dipole_moment_am2 and \
             dipole_axis_e"
                .into(),
        )),
        (true, false) => {
            let coefficient = |key: &str, required: bool| -> Result<f64, SchemaError> {
                let v = if required {
                    t.f64(key)?
                } else {
                    t.opt_f64(key)?.unwrap_or(0.0)
                };
                if v.abs() > MAX_DIPOLE_COEFFICIENT_NT {
                    return Err(invalid(
                        t,
                        key,
                        format!(
                            "{} nT: expected |g| <= {} nT (the Earth's g₁⁰ is about -29 350 \
                             nT): check the units",
                            Num(v),
                            Num(MAX_DIPOLE_COEFFICIENT_NT)
                        ),
                    ));
                }
                Ok(v)
            };
            let g10 = coefficient("dipole_g10_nt", true)?;
            let g11 = coefficient("dipole_g11_nt", false)?;
            let h11 = coefficient("dipole_h11_nt", false)?;
            let radius_m = bounded(
                t,
                "dipole_radius_m",
                IGRF_REFERENCE_RADIUS_M,
                |r| r > 0.0 && r <= 1e9,
                "a reference radius > 0 and <= 1e9 m (IGRF's is 6371200 m)",
            )?;
            Ok(CentredDipole::from_coefficients_nt(
                Vector3::new(g11, h11, g10),
                radius_m,
            ))
        }
        (false, true) => {
            let moment_am2 = t.f64("dipole_moment_am2")?;
            if !(0.0..=MAX_PLANET_DIPOLE_AM2).contains(&moment_am2) {
                return Err(invalid(
                    t,
                    "dipole_moment_am2",
                    format!(
                        "{} A·m²: expected a moment >= 0 and <= {} A·m² (the Earth's is about \
                         7.7e22; give its direction in dipole_axis_e)",
                        Num(moment_am2),
                        Num(MAX_PLANET_DIPOLE_AM2)
                    ),
                ));
            }
            let axis_e = unit_vector(t, "dipole_axis_e")?;
            Ok(CentredDipole::from_moment(moment_am2, axis_e))
        }
    }
}

/// `atmosphere = "exponential"`: Vallado's bands or one band, over the chosen altitude.
pub(super) fn exponential(t: &TableReader<'_, '_>) -> Result<ExponentialAtmosphere, SchemaError> {
    let given = [
        "exponential_base_density_kg_m3",
        "exponential_scale_height_m",
    ];
    let band = if given.iter().any(|k| t.get(k).is_some()) {
        // Either key asks for a given band: both are then required (the error names the one
        // missing).
        Some(ExponentialBand {
            base_altitude_m: t.opt_f64("exponential_base_altitude_m")?.unwrap_or(0.0),
            density_kg_m3: t.f64("exponential_base_density_kg_m3")?,
            scale_height_m: t.f64("exponential_scale_height_m")?,
        })
    } else {
        refuse_unused(
            t,
            &["exponential_base_altitude_m"],
            "a given band (with exponential_base_density_kg_m3 and \
             exponential_scale_height_m)",
        )?;
        None
    };
    let altitude = match t.get("exponential_altitude") {
        None => AltitudeDefinition::Geodetic,
        Some(_) => match t.string("exponential_altitude")?.as_str() {
            "geodetic" => AltitudeDefinition::Geodetic,
            "spherical" => AltitudeDefinition::Spherical {
                radius_m: t.opt_f64("exponential_radius_m")?.unwrap_or(WGS84_A_M),
            },
            other => {
                return Err(invalid(
                    t,
                    "exponential_altitude",
                    format!(
                        "unknown altitude \"{other}\" (expected \"geodetic\" or \"spherical\")"
                    ),
                ))
            }
        },
    };
    if altitude == AltitudeDefinition::Geodetic {
        refuse_unused(
            t,
            &["exponential_radius_m"],
            "exponential_altitude = \"spherical\"",
        )?;
    }
    let model = ExponentialAtmosphere { band, altitude };
    model.validate().map_err(|e| match e {
        AtmosphereError::Invalid {
            field,
            value,
            expected,
        } => invalid(t, field, format!("{}: expected {expected}", Num(value))),
    })?;
    Ok(model)
}

/// `corotating_wind` (default true; only with an atmosphere).
pub(super) fn corotating_wind(
    t: &TableReader<'_, '_>,
    atmosphere_on: bool,
) -> Result<bool, SchemaError> {
    if !atmosphere_on {
        refuse_unused(t, &["corotating_wind"], "an atmosphere")?;
        return Ok(true);
    }
    Ok(t.opt_bool("corotating_wind")?.unwrap_or(true))
}

/// `earth_rotation`: `"iau2006"` (default) or `"uniform"` with its rate and angle.
pub(super) fn earth_rotation(
    t: &TableReader<'_, '_>,
) -> Result<EarthOrientationModel, SchemaError> {
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

/// `sun_direction_n` and `sun_distance_m`: a fixed geocentric Sun (only with `sun = true`).
pub(super) fn sun_fixed(
    t: &TableReader<'_, '_>,
    sun: bool,
) -> Result<Option<Vector3<f64>>, SchemaError> {
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

/// `shadow_earth_radius_m` and `shadow_sun_radius_m` (only with a shadow model).
pub(super) fn shadow_radii(
    t: &TableReader<'_, '_>,
    shadow_on: bool,
) -> Result<(f64, f64), SchemaError> {
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

/// `solar_irradiance_1au_w_m2` (only with solar pressure or albedo).
pub(super) fn irradiance(t: &TableReader<'_, '_>, used: bool) -> Result<f64, SchemaError> {
    if !used {
        refuse_unused(
            t,
            &["solar_irradiance_1au_w_m2"],
            "solar_pressure = true or albedo = \"lambertian\"",
        )?;
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

/// `albedo_coefficient` (only with `albedo = "lambertian"`, default
/// [`DEFAULT_ALBEDO_COEFFICIENT`]): `Some(a)` when albedo is on.
pub(super) fn albedo_coefficient(
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
