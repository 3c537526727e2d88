//! The magnetic field's keys of `[environment]`:
//!
//! | key | meaning | default |
//! |---|---|---|
//! | `magnetic` | `"igrf14"`, `"dipole_tilted"`, `"dipole_axial"`, `"dipole"` or `"off"` | `"off"` |
//! | `magnetic_degree` | `igrf14` only, 1..=13 | 13 |
//! | `dipole_g10_nt`, `dipole_g11_nt`, `dipole_h11_nt`, `dipole_radius_m` | `magnetic = "dipole"` | g₁¹ = h₁¹ = 0; a = 6371.2 km |
//! | `dipole_moment_am2`, `dipole_axis_e` | `magnetic = "dipole"` (instead of the coefficients) | — |

use nalgebra::Vector3;

use super::igrf::IGRF_REFERENCE_RADIUS_M;
use super::{CentredDipole, IGRF_MAX_DEGREE};
use crate::model::schema::{bounded, choice, invalid, refuse_unused, unit_vector};
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::{concat_keys, SchemaError, TableReader};

/// Which magnetic-field model is on.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum MagneticSetting {
    /// No field.
    #[default]
    Off,
    /// IGRF-14 to `degree` (1..=13).
    Igrf14 {
        /// Highest degree n.
        degree: usize,
    },
    /// The centred dipole of IGRF-14's degree-1 coefficients at the epoch: tilted (g₁⁰, g₁¹,
    /// h₁¹) or axial (g₁⁰ only).
    Dipole {
        /// Tilted (true) or axial (false).
        tilted: bool,
    },
    /// A centred dipole given outright (`magnetic = "dipole"`: Gauss coefficients and a
    /// reference radius, or a moment and an axis): the date does not enter.
    GivenDipole(CentredDipole),
}

/// The keys of the magnetic field.
pub const KEYS: [&str; 8] = concat_keys(["magnetic", "magnetic_degree"], DIPOLE_KEYS);

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
const DIPOLE_KEYS: [&str; 6] = concat_keys(DIPOLE_COEFFICIENT_KEYS, DIPOLE_MOMENT_KEYS);
/// \[nT\] the largest |g₁| accepted (the Earth's is about 30 000 nT; Jupiter's 420 000 nT).
const MAX_DIPOLE_COEFFICIENT_NT: f64 = 1e7;
/// \[A·m²\] the largest planetary dipole moment accepted (the Earth's is 7.7e22; Jupiter's
/// 1.6e27).
const MAX_PLANET_DIPOLE_AM2: f64 = 1e30;

/// Reads `magnetic`, `magnetic_degree` and the `dipole_*` keys.
pub fn read(t: &TableReader<'_, '_>) -> Result<MagneticSetting, SchemaError> {
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
                "dipole" => MagneticSetting::GivenDipole(given_dipole(t)?),
                "dipole_tilted" => MagneticSetting::Dipole { tilted: true },
                "dipole_axial" => MagneticSetting::Dipole { tilted: false },
                _ => MagneticSetting::Off,
            }
        }
    };
    if !matches!(magnetic, MagneticSetting::GivenDipole(_)) {
        refuse_unused(t, &DIPOLE_KEYS, "magnetic = \"dipole\"")?;
    }
    Ok(magnetic)
}

/// `magnetic = "dipole"`: the dipole of the given Gauss coefficients (g₁⁰ required, g₁¹ and
/// h₁¹ default 0, at `dipole_radius_m`, default IGRF's 6371.2 km) or of a moment along an
/// Earth-fixed axis.
fn given_dipole(t: &TableReader<'_, '_>) -> Result<CentredDipole, SchemaError> {
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
