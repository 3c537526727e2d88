//! Units of a field against the SI unit of its catalog channel, input or time source: a
//! field may name any unit of the same dimension, and its values are converted.
//!
//! Each unit is its factor to the SI unit of its dimension (value_SI = value · factor), from the
//! SI Brochure (BIPM, 9th ed., 2019, Table 8: degree = π/180 rad, second of arc = π/648 000 rad;
//! gauss = 10⁻⁴ T, from the CGS–SI correspondence in its §4 note), the revolution per minute
//! = 2π/60 rad/s and the standard acceleration of gravity g₀ = 9.806 65 m/s² (3rd CGPM, 1901).
//! Spellings are compared after removing spaces, `·` and `*`, with `µ` read as `u` and `²`
//! as `^2`, so `"N m"`, `"N·m"` and `"Nm"` are one unit.

use std::f64::consts::PI;

/// A physical dimension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimension {
    /// Dimensionless.
    One,
    /// Plane angle.
    Angle,
    /// Angular rate.
    AngularRate,
    /// Magnetic flux density.
    MagneticField,
    /// Length.
    Length,
    /// Speed.
    Speed,
    /// Acceleration.
    Acceleration,
    /// Torque.
    Torque,
    /// Magnetic dipole moment.
    Dipole,
    /// Time.
    Time,
}

/// Every unit known: its spelling (normalised), dimension and factor to SI.
const UNITS: [(&str, Dimension, f64); 38] = [
    ("1", Dimension::One, 1.0),
    ("rad", Dimension::Angle, 1.0),
    ("mrad", Dimension::Angle, 1e-3),
    ("urad", Dimension::Angle, 1e-6),
    ("deg", Dimension::Angle, PI / 180.0),
    ("arcsec", Dimension::Angle, PI / 648_000.0),
    ("rad/s", Dimension::AngularRate, 1.0),
    ("mrad/s", Dimension::AngularRate, 1e-3),
    ("urad/s", Dimension::AngularRate, 1e-6),
    ("deg/s", Dimension::AngularRate, PI / 180.0),
    ("arcsec/s", Dimension::AngularRate, PI / 648_000.0),
    ("rpm", Dimension::AngularRate, 2.0 * PI / 60.0),
    ("T", Dimension::MagneticField, 1.0),
    ("mT", Dimension::MagneticField, 1e-3),
    ("uT", Dimension::MagneticField, 1e-6),
    ("nT", Dimension::MagneticField, 1e-9),
    ("gauss", Dimension::MagneticField, 1e-4),
    ("mgauss", Dimension::MagneticField, 1e-7),
    ("m", Dimension::Length, 1.0),
    ("km", Dimension::Length, 1e3),
    ("cm", Dimension::Length, 1e-2),
    ("mm", Dimension::Length, 1e-3),
    ("m/s", Dimension::Speed, 1.0),
    ("km/s", Dimension::Speed, 1e3),
    ("cm/s", Dimension::Speed, 1e-2),
    ("mm/s", Dimension::Speed, 1e-3),
    ("m/s^2", Dimension::Acceleration, 1.0),
    ("mm/s^2", Dimension::Acceleration, 1e-3),
    ("g0", Dimension::Acceleration, 9.806_65),
    ("Nm", Dimension::Torque, 1.0),
    ("mNm", Dimension::Torque, 1e-3),
    ("uNm", Dimension::Torque, 1e-6),
    ("Am^2", Dimension::Dipole, 1.0),
    ("mAm^2", Dimension::Dipole, 1e-3),
    ("s", Dimension::Time, 1.0),
    ("ms", Dimension::Time, 1e-3),
    ("us", Dimension::Time, 1e-6),
    ("ns", Dimension::Time, 1e-9),
];

/// The spelling compared: no spaces, `·` or `*`; `µ`/`μ` as `u`; `²` as `^2`.
fn normalise(unit: &str) -> String {
    unit.chars()
        .filter(|c| !matches!(c, ' ' | '·' | '*'))
        .map(|c| match c {
            'µ' | 'μ' => "u".to_owned(),
            '²' => "^2".to_owned(),
            c => c.to_string(),
        })
        .collect()
}

/// The dimension and factor to SI of a unit, if known.
pub fn lookup(unit: &str) -> Option<(Dimension, f64)> {
    let unit = normalise(unit);
    UNITS
        .iter()
        .find(|(name, _, _)| *name == unit)
        .map(|&(_, d, f)| (d, f))
}

/// Every unit's spelling, for error messages.
pub fn known_units() -> impl Iterator<Item = &'static str> {
    UNITS.iter().map(|(name, _, _)| *name)
}

/// A unit that cannot stand for the other.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum UnitMismatch {
    /// The field's unit is not in the table.
    Unknown,
    /// Both are known, of different dimensions (or the SI unit is unknown and differs).
    Incompatible,
}

/// The factor from the SI unit `si` (a catalog channel's, an input's or a time source's) to
/// the field's `unit`: value_field = value_SI · factor. An SI unit outside the table is only
/// compatible with itself (factor 1).
pub fn factor_from_si(si: &str, unit: &str) -> Result<f64, UnitMismatch> {
    if normalise(si) == normalise(unit) {
        return Ok(1.0);
    }
    let Some((field_dim, field_to_si)) = lookup(unit) else {
        return Err(UnitMismatch::Unknown);
    };
    match lookup(si) {
        Some((si_dim, si_to_si)) if si_dim == field_dim => Ok(si_to_si / field_to_si),
        _ => Err(UnitMismatch::Incompatible),
    }
}
