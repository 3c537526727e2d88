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
//! The keys that set each model's constants (a given dipole, the exponential atmosphere's band
//! and altitude, the wind, the Earth's rotation, a fixed Sun, the shadow's radii, the
//! irradiance, a cannonball) are read by [`super::constants`], which lists them with their
//! defaults.
//!
//! The reader checks keys, types, names and each facet; the cross-checks that need the rest of
//! the configuration (an epoch, a gravity model, the step) are the configuration's.

use nalgebra::Vector3;

use super::constants;
use super::{AtmosphereSetting, EnvironmentSettings, MagneticSetting};
use crate::atmosphere::SpaceWeather;
use crate::facets::{Facet, FacetError};
use crate::magnetic::IGRF_MAX_DEGREE;
use crate::shadow::ShadowModel;
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::{concat_keys, At, SchemaError, TableReader};
use flexdyn_kernel::validate::MAX_DIPOLE_AM2;

/// The keys of `[environment]` that switch the models on and give their parameters.
const SWITCH_KEYS: [&str; 17] = [
    "update_hz",
    "telemetry_rate_hz",
    "magnetic",
    "magnetic_degree",
    "atmosphere",
    "f107_sfu",
    "f107a_sfu",
    "ap",
    "sun",
    "moon",
    "shadow",
    "albedo",
    "gravity_gradient",
    "drag",
    "solar_pressure",
    "residual_dipole_m_b_am2",
    "facets",
];

/// The keys of `[environment]`: the switches, then the models' constants
/// ([`constants::KEYS`]).
pub const KEYS: [&str; 42] = concat_keys(SWITCH_KEYS, constants::KEYS);

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

pub(super) fn invalid(t: &TableReader<'_, '_>, key: &str, message: String) -> SchemaError {
    SchemaError::InvalidValue {
        field: t.field(key),
        message,
        at: At(None),
    }
}

fn choice<'c>(
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
    let magnetic = match choice(
        t,
        "magnetic",
        &["igrf14", "dipole_tilted", "dipole_axial", "dipole", "off"],
    )? {
        "igrf14" => MagneticSetting::Igrf14 {
            degree: match t.get("magnetic_degree") {
                Some(_) => t.int_in("magnetic_degree", 1, IGRF_MAX_DEGREE as i64)? as usize,
                None => IGRF_MAX_DEGREE,
            },
        },
        other => {
            if t.get("magnetic_degree").is_some() {
                return Err(invalid(
                    t,
                    "magnetic_degree",
                    format!(
                        "only used by magnetic = \"igrf14\" (magnetic is \"{other}\"); remove it"
                    ),
                ));
            }
            match other {
                "dipole" => MagneticSetting::GivenDipole(constants::given_dipole(t)?),
                "dipole_tilted" => MagneticSetting::Dipole { tilted: true },
                "dipole_axial" => MagneticSetting::Dipole { tilted: false },
                _ => MagneticSetting::Off,
            }
        }
    };
    let weather_keys = ["f107_sfu", "f107a_sfu", "ap"];
    let atmosphere = match choice(t, "atmosphere", &["exponential", "nrlmsise00", "off"])? {
        "nrlmsise00" => {
            let w = SpaceWeather {
                f107_sfu: t.f64("f107_sfu")?,
                f107a_sfu: t.f64("f107a_sfu")?,
                ap: t.f64("ap")?,
            };
            let w = w.validated().map_err(|e| {
                let msg = e.to_string();
                let key = weather_keys
                    .iter()
                    .copied()
                    .find(|k| msg.contains(k))
                    .unwrap_or("f107_sfu");
                invalid(t, key, msg)
            })?;
            AtmosphereSetting::Nrlmsise00(w)
        }
        other => {
            if let Some(k) = weather_keys.iter().find(|k| t.get(k).is_some()) {
                return Err(invalid(
                    t,
                    k,
                    format!(
                        "only used by atmosphere = \"nrlmsise00\" (atmosphere is \"{other}\"); \
                         remove it"
                    ),
                ));
            }
            if other == "exponential" {
                AtmosphereSetting::Exponential(constants::exponential(t)?)
            } else {
                AtmosphereSetting::Off
            }
        }
    };
    if !matches!(magnetic, MagneticSetting::GivenDipole(_)) {
        constants::refuse_unused(t, &constants::DIPOLE_KEYS, "magnetic = \"dipole\"")?;
    }
    if !matches!(atmosphere, AtmosphereSetting::Exponential(_)) {
        constants::refuse_unused(
            t,
            &constants::EXPONENTIAL_KEYS,
            "atmosphere = \"exponential\"",
        )?;
    }
    let sun = t.opt_bool("sun")?.unwrap_or(false);
    let moon = t.opt_bool("moon")?.unwrap_or(false);
    let shadow = match choice(t, "shadow", &["conical", "cylindrical", "off"])? {
        "conical" => Some(ShadowModel::Conical),
        "cylindrical" => Some(ShadowModel::Cylindrical),
        _ => None,
    };
    if shadow.is_some() && !sun {
        return Err(invalid(
            t,
            "shadow",
            format!("a shadow needs the Sun: set {} = true", t.field("sun")),
        ));
    }
    let albedo_on = match choice(t, "albedo", &["lambertian", "off"])? {
        "lambertian" => {
            if !sun {
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
    let albedo_coefficient = constants::albedo_coefficient(t, albedo_on)?;
    let corotating_wind = constants::corotating_wind(t, atmosphere != AtmosphereSetting::Off)?;
    let earth_rotation = constants::earth_rotation(t)?;
    let sun_fixed_n_m = constants::sun_fixed(t, sun)?;
    let (shadow_earth_radius_m, shadow_sun_radius_m) =
        constants::shadow_radii(t, shadow.is_some())?;
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
    let solar_irradiance_1au_w_m2 = constants::irradiance(t, solar_pressure || albedo_on)?;
    let cannonball = constants::cannonball(t, solar_pressure)?;
    let residual_dipole_m_b_am2 = t
        .opt_floats::<3>("residual_dipole_m_b_am2")?
        .map(Vector3::from);
    if drag && atmosphere == AtmosphereSetting::Off {
        return Err(invalid(
            t,
            "drag",
            format!("drag needs an atmosphere: set {}", t.field("atmosphere")),
        ));
    }
    if solar_pressure && !sun {
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
    if residual_dipole_m_b_am2.is_some() && magnetic == MagneticSetting::Off {
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
        magnetic,
        atmosphere,
        sun,
        sun_fixed_n_m,
        earth_rotation,
        corotating_wind,
        moon,
        shadow,
        shadow_earth_radius_m,
        shadow_sun_radius_m,
        facets,
        gravity_gradient,
        drag,
        solar_pressure,
        cannonball,
        solar_irradiance_1au_w_m2,
        residual_dipole_m_b_am2,
        albedo_coefficient,
    })
}
