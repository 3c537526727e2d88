//! The Earth's shadow: the fraction ν of the solar disc visible from the spacecraft (1 in full
//! Sun, 0 in the umbra), which scales the solar radiation pressure and the power of the arrays.
//!
//! - [`ShadowModel::Conical`]: Montenbruck & Gill, *Satellite Orbits* (2000), §3.4.2 ("Conical
//!   shadow model"): the Sun and the Earth seen from the spacecraft as discs of apparent radii
//!   a and b at apparent separation c; the occulted area of the solar disc is the overlap of the
//!   two circles, and ν = 1 − A/(π a²). It has a penumbra (a ring about 0.5° wide seen from the
//!   Earth) and the annular case. The discs are treated as plane circles on the sky; against the
//!   exact spherical geometry (the limb of the Earth is a small circle of angular radius b), the
//!   error in ν is below 1e-3 in low orbit (measured in `crates/environment/tests/shadow.rs`).
//! - [`ShadowModel::Cylindrical`]: Montenbruck & Gill §3.4.2 ("Cylindrical shadow model"): the
//!   umbra is a cylinder of radius R⊕ behind the Earth, ν ∈ {0, 1}.
//!
//! The Earth is a sphere of its equatorial radius (WGS-84 a, 6378137 m) and the Sun one of
//! the IAU 2015 nominal radius (695 700 km), unless `shadow_earth_radius_m` and
//! `shadow_sun_radius_m` set others ([`ShadowGeometry`]); its flattening moves the shadow
//! boundary by at most 21 km of height, about 3 s of a low orbit's eclipse entry. Eclipses by the
//! Moon are not modelled.

pub mod part;
pub mod schema;

pub use schema::ShadowSetting;

use nalgebra::Vector3;

use super::ephemeris::SUN_RADIUS_M;
use super::geodetic::WGS84_A_M;

/// \[m\] radius of the occulting Earth (WGS-84 equatorial radius).
pub const EARTH_SHADOW_RADIUS_M: f64 = WGS84_A_M;

/// Which shadow geometry to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShadowModel {
    /// Conical umbra and penumbra, ν continuous in [0, 1] (Montenbruck & Gill §3.4.2).
    Conical,
    /// Cylindrical umbra without penumbra, ν ∈ {0, 1}.
    Cylindrical,
}

/// [-] the fraction ν ∈ [0, 1] of the solar disc visible from the spacecraft at `r_sat_n_m`
/// (geocentric, N), with the Sun at `r_sun_n_m` (geocentric, N). Allocation-free and
/// panic-free; a non-finite input gives a non-finite ν.
pub fn shadow_factor(
    model: ShadowModel,
    r_sat_n_m: &Vector3<f64>,
    r_sun_n_m: &Vector3<f64>,
) -> f64 {
    ShadowGeometry::new(model).factor(r_sat_n_m, r_sun_n_m)
}

/// A shadow model with the radii of its two bodies (`environment.shadow_earth_radius_m`,
/// `environment.shadow_sun_radius_m`; by default [`EARTH_SHADOW_RADIUS_M`] and
/// [`SUN_RADIUS_M`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowGeometry {
    /// Conical or cylindrical.
    pub model: ShadowModel,
    /// \[m\] the occulting Earth's radius R⊕ (a sphere).
    pub earth_radius_m: f64,
    /// \[m\] the Sun's radius (the conical model's apparent solar disc).
    pub sun_radius_m: f64,
}

impl ShadowGeometry {
    /// `model` with the default radii.
    pub const fn new(model: ShadowModel) -> Self {
        Self {
            model,
            earth_radius_m: EARTH_SHADOW_RADIUS_M,
            sun_radius_m: SUN_RADIUS_M,
        }
    }

    /// [-] ν ∈ [0, 1] for the spacecraft at `r_sat_n_m` and the Sun at `r_sun_n_m` (both
    /// geocentric, N), as [`shadow_factor`]. Allocation-free and panic-free.
    pub fn factor(&self, r_sat_n_m: &Vector3<f64>, r_sun_n_m: &Vector3<f64>) -> f64 {
        match self.model {
            ShadowModel::Conical => {
                conical(r_sat_n_m, r_sun_n_m, self.earth_radius_m, self.sun_radius_m)
            }
            ShadowModel::Cylindrical => cylindrical(r_sat_n_m, r_sun_n_m, self.earth_radius_m),
        }
    }
}

/// Montenbruck & Gill §3.4.2, conical model.
fn conical(
    r_sat_n_m: &Vector3<f64>,
    r_sun_n_m: &Vector3<f64>,
    earth_radius_m: f64,
    sun_radius_m: f64,
) -> f64 {
    let s_sat_sun = r_sun_n_m - r_sat_n_m;
    let d_sun = s_sat_sun.norm();
    let d_earth = r_sat_n_m.norm();
    if d_earth <= earth_radius_m {
        // Inside the Earth: no sunlight (keeps asin's argument in range).
        return 0.0;
    }
    // Apparent radii of the Sun (a) and of the Earth (b), and their apparent separation (c).
    let a = (sun_radius_m / d_sun).min(1.0).asin();
    let b = (earth_radius_m / d_earth).asin();
    let cos_c = (-r_sat_n_m.dot(&s_sat_sun) / (d_earth * d_sun)).clamp(-1.0, 1.0);
    let c = cos_c.acos();
    if c >= a + b {
        1.0
    } else if c <= b - a {
        // The Earth covers the whole solar disc.
        0.0
    } else if c <= a - b {
        // Annular: the Earth's disc lies inside the Sun's (only far beyond GEO).
        1.0 - (b * b) / (a * a)
    } else {
        // Partial overlap (M&G §3.4.2): x is the distance from the Sun's centre to the chord
        // through the two intersection points, y half the chord.
        let x = (c * c + a * a - b * b) / (2.0 * c);
        let y = (a * a - x * x).max(0.0).sqrt();
        let area = a * a * (x / a).clamp(-1.0, 1.0).acos()
            + b * b * ((c - x) / b).clamp(-1.0, 1.0).acos()
            - c * y;
        (1.0 - area / (std::f64::consts::PI * a * a)).clamp(0.0, 1.0)
    }
}

/// Cylindrical umbra: in shadow when behind the Earth's terminator plane and within R⊕ of the
/// Earth–Sun line.
fn cylindrical(r_sat_n_m: &Vector3<f64>, r_sun_n_m: &Vector3<f64>, earth_radius_m: f64) -> f64 {
    let sun_dir = r_sun_n_m.normalize();
    let along = r_sat_n_m.dot(&sun_dir);
    let across = (r_sat_n_m - along * sun_dir).norm();
    if along < 0.0 && across < earth_radius_m {
        0.0
    } else {
        1.0
    }
}
