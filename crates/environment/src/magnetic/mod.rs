//! The Earth's magnetic field: IGRF-14 to a chosen degree ([`igrf`]), the centred dipole of its
//! degree-1 coefficients, and the torque on a magnetic dipole ([`dipole`]).
//!
//! Fields are in Earth-fixed components (`field_ecef_t`, tesla); the local north-east-down
//! components follow from [`crate::geodetic::dcm_ned_ecef`] at the geodetic (or,
//! for the IGRF test values, geocentric) latitude. The rotation into N is the Earth-rotation
//! model's. The coefficients are a slow function of time (at most 0.004 nT per hour), so they can
//! be held for a whole run segment; the field along the orbit changes with position and is
//! evaluated at the environment sample's rate.
//!
//! Time is a decimal year in UTC ([`decimal_year`]), the IGRF convention.
//!
//! # Why not through `tobari`
//! The brief names `tobari` 0.2.0 (MIT) for IGRF-14, and it was tried first. Its synthesis
//! fails the IAGA test values by up to 29,534 nT (the same 12 cases as
//! `crates/environment/tests/magnetic.rs`, run through `tobari::magnetic::Igrf` with its own geodetic
//! input). Two defects explain it, both visible in its `magnetic/igrf/mod.rs`:
//! - the east component has the wrong sign: its degree-1 field at r = 7000 km on the x axis is
//!   (−2126.7, **+3427.3**, 22129.8) nT for 2025.0, where the dipole closed form of its own
//!   g₁⁰ = −29350.0, g₁¹ = −1410.3, h₁¹ = 4545.5 nT gives (−2126.7, −3427.3, 22129.8) nT;
//! - its sub-diagonal Legendre recursion uses the unnormalised factor (2n−1) where the Schmidt
//!   semi-normalised functions need √(2n−1), so every Pₙⁿ⁻¹ with n ≥ 2 is too large.
//!
//! It also rounds the 2005–2020 definitive models to 0.1 nT (the published file has 0.01 nT),
//! extrapolates silently before 1900 and after 2030, panics on a degree outside 1..=13, and does
//! not expose the degree-1 coefficients a dipole needs. The synthesis here is short, is checked
//! against the published test values to 0.01 nT, takes `r_ecef_m` directly, and reads the
//! official coefficient file shipped beside it. `tobari` is used for NRLMSISE-00, which passes
//! its reference tests after one documented correction (see [`crate::atmosphere`]).

pub mod dipole;
pub mod igrf;
pub mod part;
pub mod schema;

pub use dipole::{dipole_field_t, dipole_torque_b_nm, CentredDipole};
pub use igrf::{GaussCoefficients, Igrf, SphericalField, IGRF_MAX_DEGREE};
pub use part::MagneticField;
pub use schema::MagneticSetting;

/// An invalid magnetic-field model or a date it does not cover.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MagneticError {
    /// The requested degree is not one the model has.
    #[error("magnetic field degree {degree} is out of range: the model has degrees 1 to {max}")]
    DegreeOutOfRange {
        /// The degree asked for.
        degree: usize,
        /// The model's highest degree.
        max: usize,
    },
    /// The date lies outside the span the model's coefficients cover.
    #[error(
        "the date {decimal_year:.3} is outside the magnetic field model, which covers \
         {first_year:.1} to {last_year:.1}"
    )]
    DateOutsideModel {
        /// \[yr\] the date asked for.
        decimal_year: f64,
        /// \[yr\] the model's first epoch.
        first_year: f64,
        /// \[yr\] the model's last epoch.
        last_year: f64,
    },
    /// The coefficient file cannot be read.
    #[error("magnetic coefficient file, line {line}: {problem}")]
    CoefficientFile {
        /// 1-based line number (0: the file as a whole).
        line: usize,
        /// What is wrong.
        problem: String,
    },
}

/// \[yr\] the decimal year of a UTC date: `year + (day_of_year − 1 + ut_s / 86400) / days`, with
/// `days` 365 or 366 (Gregorian leap years) and `day_of_year` from 1 (the convention of the IGRF
/// programs).
pub fn decimal_year(year: i32, day_of_year: u32, ut_s: f64) -> f64 {
    let leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    let days = if leap { 366.0 } else { 365.0 };
    f64::from(year) + (f64::from(day_of_year) - 1.0 + ut_s / 86_400.0) / days
}
