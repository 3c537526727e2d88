//! The `[environment]` schema: which models and dynamic effectors are on, and their parameters.
//!
//! ```toml
//! [environment]
//! update_hz = 10.0            # sample rate; held between updates (default 10 Hz)
//! telemetry_rate_hz = 10.0    # the environment message (tlm/env) and CSV columns; default off
//! magnetic = "igrf14"         # "igrf14", "dipole_tilted", "dipole_axial", "dipole" or "off"
//! magnetic_degree = 13        # igrf14 only, 1..=13 (default 13)
//! atmosphere = "nrlmsise00"   # "exponential", "nrlmsise00" or "off" (default)
//! f107_sfu = 150.0            # nrlmsise00 only (required there)
//! f107a_sfu = 150.0
//! ap = 15.0
//! sun = true                  # default false
//! moon = true                 # default false
//! shadow = "conical"          # "conical", "cylindrical" or "off" (default; needs sun)
//! albedo = "lambertian"       # Earth albedo on the sun sensors: "lambertian" or "off" (default;
//! albedo_coefficient = 0.3    #   needs sun); its coefficient, 0..=1 (default 0.3)
//! gravity_gradient = true     # dynamic effectors, default false
//! drag = true                 # needs an atmosphere and facets
//! solar_pressure = true       # needs the Sun and facets
//! residual_dipole_m_b_am2 = [0.0, 0.0, 0.1]   # needs a magnetic field
//!
//! [[environment.facets]]
//! area_m2 = 1.0
//! normal_b = [1.0, 0.0, 0.0]
//! r_cp_b_m = [0.5, 0.0, 0.0]
//! drag_coefficient = 2.2
//! absorbed = 0.6
//! specular = 0.3
//! diffuse = 0.1
//! ```
//!
//! Each environment model reads its own keys, in its folder (`magnetic/schema.rs`, …), and
//! lists them in its [`EnvironmentPart::KEYS`](super::part::EnvironmentPart::KEYS): this file
//! reads the update's rates, asks every registered model (`crate::ModelSettings::read`) and
//! the Earth's orientation ([`crate::earth_rotation::schema`]) for theirs, and reads the dynamic
//! effectors' switches, the facets and their constants ([`super::constants`]).
//!
//! The reader checks keys, types, names and each facet; the cross-checks that need the rest of
//! the configuration (an epoch, a gravity model, the step) are the configuration's.

use nalgebra::Vector3;

use super::constants;
use super::EnvironmentSettings;
use crate::atmosphere::AtmosphereSetting;
use crate::facets::{Facet, FacetError};
use crate::magnetic::MagneticSetting;
use crate::{earth_rotation, ModelSettings, MODEL_KEYS};
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::{At, SchemaError, TableReader};
use flexdyn_kernel::validate::MAX_DIPOLE_AM2;

pub(crate) use constants::{bounded, refuse_unused, unit_vector};

/// The update's keys.
const RATE_KEYS: [&str; 2] = ["update_hz", "telemetry_rate_hz"];

/// The keys of the dynamic effectors the table switches on, and of the facets.
const EFFECTOR_KEYS: [&str; 5] = [
    "gravity_gradient",
    "drag",
    "solar_pressure",
    "residual_dipole_m_b_am2",
    "facets",
];

/// The groups of keys of `[environment]`, in the order an unknown key's message lists them:
/// the rates, every registered model's, the effectors', the Earth's orientation's and the
/// effectors' constants.
const KEY_GROUPS: [&[&[&str]]; 3] = [
    &[&RATE_KEYS],
    MODEL_KEYS,
    &[
        &EFFECTOR_KEYS,
        &earth_rotation::schema::KEYS,
        &constants::KEYS,
    ],
];

/// How many keys `groups` hold.
const fn key_count(groups: &[&[&[&str]]]) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < groups.len() {
        let mut j = 0;
        while j < groups[i].len() {
            n += groups[i][j].len();
            j += 1;
        }
        i += 1;
    }
    n
}

/// The keys of `groups`, one after the other.
const fn flatten<const N: usize>(groups: &[&[&[&'static str]]]) -> [&'static str; N] {
    let mut out = [""; N];
    let mut n = 0;
    let mut i = 0;
    while i < groups.len() {
        let mut j = 0;
        while j < groups[i].len() {
            let mut k = 0;
            while k < groups[i][j].len() {
                out[n] = groups[i][j][k];
                n += 1;
                k += 1;
            }
            j += 1;
        }
        i += 1;
    }
    assert!(n == N, "flatten: N must be the number of keys");
    out
}

/// The keys of `[environment]`.
pub const KEYS: [&str; key_count(&KEY_GROUPS)] = flatten(&KEY_GROUPS);

/// The keys of each `[[environment.facets]]`.
pub(crate) const FACET_KEYS: [&str; 7] = [
    "area_m2",
    "normal_b",
    "r_cp_b_m",
    "drag_coefficient",
    "absorbed",
    "specular",
    "diffuse",
];

/// \[Hz\] default `update_hz`.
pub const DEFAULT_UPDATE_HZ: f64 = 10.0;

pub(crate) fn invalid(t: &TableReader<'_, '_>, key: &str, message: String) -> SchemaError {
    SchemaError::InvalidValue {
        field: t.field(key),
        message,
        at: At(None),
    }
}

pub(crate) fn choice<'c>(
    t: &TableReader<'_, '_>,
    key: &str,
    choices: &[&'c str],
) -> Result<&'c str, SchemaError> {
    let Some(_) = t.get(key) else {
        return Ok("off");
    };
    let s = t.string(key)?;
    choices.iter().copied().find(|c| *c == s).ok_or_else(|| {
        let list: Vec<String> = choices.iter().map(|c| format!("\"{c}\"")).collect();
        invalid(
            t,
            key,
            format!(
                "unknown model \"{s}\" (expected one of {})",
                list.join(", ")
            ),
        )
    })
}

/// Reads `[environment]` (opened with [`KEYS`]) into validated settings.
pub fn read(t: &TableReader<'_, '_>) -> Result<EnvironmentSettings, SchemaError> {
    let update_hz = t.opt_f64("update_hz")?.unwrap_or(DEFAULT_UPDATE_HZ);
    if !(update_hz.is_finite() && update_hz > 0.0 && update_hz <= 1e9) {
        return Err(invalid(
            t,
            "update_hz",
            format!("{update_hz} Hz: expected a rate > 0 and ≤ 1e9 Hz"),
        ));
    }
    let update_ns = (1e9 / update_hz).round() as u64;
    // Checked against the frame rate (a whole number of frames) by the configuration.
    let telemetry_rate_hz = t.opt_f64("telemetry_rate_hz")?;
    let models = ModelSettings::read(t)?;
    let earth_rotation = earth_rotation::schema::read(t)?;
    let facets = t
        .tables("facets", &FACET_KEYS)?
        .unwrap_or_default()
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let facet = Facet {
                area_m2: f.f64("area_m2")?,
                normal_b: Vector3::from(f.floats::<3>("normal_b")?),
                r_cp_b_m: Vector3::from(f.floats::<3>("r_cp_b_m")?),
                drag_coefficient: f.f64("drag_coefficient")?,
                absorbed: f.f64("absorbed")?,
                specular: f.f64("specular")?,
                diffuse: f.f64("diffuse")?,
            };
            facet.validate(i).map_err(|e| match e {
                FacetError::Invalid {
                    field,
                    value,
                    expected,
                    ..
                } => SchemaError::InvalidValue {
                    field: f.field(field),
                    message: format!("{value}: expected {expected}"),
                    at: At(None),
                },
            })?;
            Ok(facet)
        })
        .collect::<Result<Vec<_>, SchemaError>>()?;
    let gravity_gradient = t.opt_bool("gravity_gradient")?.unwrap_or(false);
    let drag = t.opt_bool("drag")?.unwrap_or(false);
    let solar_pressure = t.opt_bool("solar_pressure")?.unwrap_or(false);
    let (irradiance_read, users) = models.irradiance_users();
    let solar_irradiance_1au_w_m2 =
        constants::irradiance(t, solar_pressure || irradiance_read, &users)?;
    let cannonball = constants::cannonball(t, solar_pressure)?;
    let residual_dipole_m_b_am2 = t
        .opt_floats::<3>("residual_dipole_m_b_am2")?
        .map(Vector3::from);
    if drag && models.atmosphere.atmosphere == AtmosphereSetting::Off {
        return Err(invalid(
            t,
            "drag",
            format!("drag needs an atmosphere: set {}", t.field("atmosphere")),
        ));
    }
    if solar_pressure && !models.ephemeris.sun {
        return Err(invalid(
            t,
            "solar_pressure",
            format!(
                "solar pressure needs the Sun: set {} = true",
                t.field("sun")
            ),
        ));
    }
    for (on, key) in [
        (drag, "drag"),
        (solar_pressure && cannonball.is_none(), "solar_pressure"),
    ] {
        if on && facets.is_empty() {
            return Err(invalid(
                t,
                key,
                format!(
                    "{key} acts on the vehicle's surfaces: give at least one [[{}]]",
                    t.field("facets")
                ),
            ));
        }
    }
    if let Some(m) = residual_dipole_m_b_am2.filter(|m| m.norm() > MAX_DIPOLE_AM2) {
        return Err(invalid(
            t,
            "residual_dipole_m_b_am2",
            format!(
                "|m| = {} A·m² is beyond the largest dipole flexdyn accepts ({} A·m²; a \
                 spacecraft's residual is typically below 1): check the units",
                Num(m.norm()),
                Num(MAX_DIPOLE_AM2)
            ),
        ));
    }
    if residual_dipole_m_b_am2.is_some() && models.magnetic == MagneticSetting::Off {
        return Err(invalid(
            t,
            "residual_dipole_m_b_am2",
            format!(
                "a residual dipole needs a magnetic field: set {}",
                t.field("magnetic")
            ),
        ));
    }
    Ok(EnvironmentSettings {
        update_ns,
        update_hz,
        telemetry_rate_hz,
        telemetry_every_frames: None,
        models,
        earth_rotation,
        facets,
        gravity_gradient,
        drag,
        solar_pressure,
        cannonball,
        solar_irradiance_1au_w_m2,
        residual_dipole_m_b_am2,
    })
}

#[cfg(test)]
mod tests {
    use super::KEYS;

    #[test]
    fn every_key_is_read_by_one_reader() {
        for (i, k) in KEYS.iter().enumerate() {
            assert!(!KEYS[..i].contains(k), "{k} twice");
        }
        // The rates' keys first, then the first model's.
        assert_eq!(KEYS[..3], ["update_hz", "telemetry_rate_hz", "magnetic"]);
    }
}
