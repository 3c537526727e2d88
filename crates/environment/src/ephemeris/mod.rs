//! Geocentric positions of the Sun and the Moon in the inertial frame N, from analytic series.
//!
//! - Sun: Meeus, *Astronomical Algorithms*, 2nd ed. (1998), ch. 25, "low accuracy" (eqs. 25.2–25.5):
//!   the geometric longitude and distance referred to the mean equinox of date.
//! - Moon: Meeus ch. 47 (eqs. 47.1–47.7, Tables 47.A and 47.B), a truncation of ELP-2000/82: the
//!   geometric longitude, latitude and distance referred to the mean equinox of date.
//! - Both are turned into N (mean equator and equinox of J2000.0, see [`crate`]) by
//!   the mean obliquity of date (Meeus eq. 22.2) and the IAU 1976 precession (Lieske et al. 1977,
//!   as Meeus eqs. 21.2–21.4); see [`precession`].
//!
//! Time is `t_tt_jc`: Julian centuries of Terrestrial Time since J2000.0 (JD 2451545.0 TT),
//! `(JD_TT − 2451545.0) / 36525` (Meeus eq. 22.1, with TD = TT). The positions are geometric (no
//! light time, no aberration), which is what a dynamics model wants.
//!
//! # Accuracy (measured in `crates/environment/tests/ephemeris.rs`)
//! - Sun: the worked Example 25.a to its printed precision; over the whole of 2024 (every 6 h)
//!   the direction is within 21″ and the distance within 6 800 km (4.5e-5 relative) of the
//!   VSOP87 series of Meeus Appendix III (accurate to about 1″), itself checked against Meeus
//!   Example 25.b and a JPL Horizons DE441 value. Meeus states 0.01° for this method.
//! - Moon: the worked Example 47.a to its printed precision; over 2026-01-21…28 (every 6 h) within
//!   25″ in direction and 45 km in distance of JPL Horizons DE441. Meeus states about 10″ in
//!   longitude and 4″ in latitude against the full ELP-2000/82.
//!
//! The cost is one short series per call (see `benches/environment.rs`); both are slow fields,
//! meant to be evaluated at a low rate and held or interpolated between updates.

pub mod moon;
mod moon_terms;
pub mod part;
pub mod precession;
pub mod schema;
pub mod sun;

use nalgebra::Vector3;

pub use moon::{moon_ecliptic_of_date, moon_position_n_m};
pub use part::Ephemeris;
pub use schema::EphemerisSetting;
pub use sun::{sun_ecliptic_of_date, sun_position_n_m};

/// \[d\] Julian Date of the epoch J2000.0 (2000-01-01 12:00 TT).
pub const J2000_JD: f64 = 2_451_545.0;
/// \[d\] days per Julian century.
pub const DAYS_PER_JULIAN_CENTURY: f64 = 36_525.0;
/// \[m\] the astronomical unit (IAU 2012 Resolution B2, exact).
pub const AU_M: f64 = 149_597_870_700.0;
/// \[m\] nominal solar radius (IAU 2015 Resolution B3).
pub const SUN_RADIUS_M: f64 = 695_700_000.0;

/// Julian centuries of TT since J2000.0 from a Julian Date in TT (Meeus eq. 22.1).
pub fn julian_centuries_tt(jd_tt: f64) -> f64 {
    (jd_tt - J2000_JD) / DAYS_PER_JULIAN_CENTURY
}

/// A geocentric position in spherical coordinates on the mean ecliptic and equinox of date.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EclipticOfDate {
    /// \[rad\] ecliptic longitude λ, in [0, 2π).
    pub lon_rad: f64,
    /// \[rad\] ecliptic latitude β.
    pub lat_rad: f64,
    /// \[m\] distance from the Earth's centre.
    pub distance_m: f64,
}

impl EclipticOfDate {
    /// The position in N (EME2000 ≈ GCRF) at `t_tt_jc`, through the obliquity of date and the
    /// precession from date to J2000.0.
    pub fn to_n_m(&self, t_tt_jc: f64) -> Vector3<f64> {
        let (sl, cl) = self.lon_rad.sin_cos();
        let (sb, cb) = self.lat_rad.sin_cos();
        let r_ecl_m = self.distance_m * Vector3::new(cb * cl, cb * sl, sb);
        precession::dcm_n_ecliptic_of_date(t_tt_jc) * r_ecl_m
    }
}

/// `deg` reduced to [0, 360) and turned into radians, so the series keep their precision far
/// from J2000.0.
pub(crate) fn reduced_rad(deg: f64) -> f64 {
    deg.rem_euclid(360.0).to_radians()
}
