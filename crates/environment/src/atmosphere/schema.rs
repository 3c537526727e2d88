//! The atmosphere's keys of `[environment]`:
//!
//! | key | meaning | default |
//! |---|---|---|
//! | `atmosphere` | `"exponential"`, `"nrlmsise00"` or `"off"` | `"off"` |
//! | `f107_sfu`, `f107a_sfu`, `ap` | `nrlmsise00` only (required there) | — |
//! | `exponential_base_altitude_m`, `exponential_base_density_kg_m3`, `exponential_scale_height_m` | `atmosphere = "exponential"`: one band | Vallado Table 8-4 |
//! | `exponential_altitude`, `exponential_radius_m` | `atmosphere = "exponential"` | `"geodetic"` |
//! | `corotating_wind` | any atmosphere | true |

use super::{
    AltitudeDefinition, AtmosphereError, ExponentialAtmosphere, ExponentialBand, SpaceWeather,
};
use crate::geodetic::WGS84_A_M;
use crate::model::schema::{choice, invalid, refuse_unused};
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::{concat_keys, SchemaError, TableReader};

/// Which atmosphere is on.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum AtmosphereSetting {
    /// Vacuum.
    #[default]
    Off,
    /// An exponential atmosphere: Vallado's bands (Table 8-4) on the geodetic height by
    /// default, or one given band over the chosen altitude.
    Exponential(ExponentialAtmosphere),
    /// NRLMSISE-00 with constant space weather.
    Nrlmsise00(SpaceWeather),
}

/// The atmosphere and its wind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AirSetting {
    /// The density model.
    pub atmosphere: AtmosphereSetting,
    /// Whether the atmosphere co-rotates with the Earth (`corotating_wind`, default true): the
    /// wind ω⊕ × r; false: still air in N.
    pub corotating_wind: bool,
}

impl Default for AirSetting {
    fn default() -> Self {
        Self {
            atmosphere: AtmosphereSetting::Off,
            corotating_wind: true,
        }
    }
}

/// The keys of the atmosphere.
pub const KEYS: [&str; 10] = concat_keys(
    concat_keys::<4, 5, 9>(
        ["atmosphere", "f107_sfu", "f107a_sfu", "ap"],
        EXPONENTIAL_KEYS,
    ),
    ["corotating_wind"],
);

/// Every `exponential_*` key.
const EXPONENTIAL_KEYS: [&str; 5] = [
    "exponential_base_altitude_m",
    "exponential_base_density_kg_m3",
    "exponential_scale_height_m",
    "exponential_altitude",
    "exponential_radius_m",
];

/// Reads the atmosphere, its space weather or band, and the wind.
pub fn read(t: &TableReader<'_, '_>) -> Result<AirSetting, SchemaError> {
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
                AtmosphereSetting::Exponential(exponential(t)?)
            } else {
                AtmosphereSetting::Off
            }
        }
    };
    if !matches!(atmosphere, AtmosphereSetting::Exponential(_)) {
        refuse_unused(t, &EXPONENTIAL_KEYS, "atmosphere = \"exponential\"")?;
    }
    let corotating_wind = corotating_wind(t, atmosphere != AtmosphereSetting::Off)?;
    Ok(AirSetting {
        atmosphere,
        corotating_wind,
    })
}

/// `atmosphere = "exponential"`: Vallado's bands or one band, over the chosen altitude.
fn exponential(t: &TableReader<'_, '_>) -> Result<ExponentialAtmosphere, SchemaError> {
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
fn corotating_wind(t: &TableReader<'_, '_>, atmosphere_on: bool) -> Result<bool, SchemaError> {
    if !atmosphere_on {
        refuse_unused(t, &["corotating_wind"], "an atmosphere")?;
        return Ok(true);
    }
    Ok(t.opt_bool("corotating_wind")?.unwrap_or(true))
}
