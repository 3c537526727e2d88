//! WGS-84 geodetic coordinates: Earth-fixed Cartesian ↔ geodetic latitude, longitude and
//! height above the ellipsoid, and the local north-east-down (NED) frame.
//!
//! The ellipsoid is WGS-84 (NIMA TR8350.2, 3rd ed., Table 3.1: a = 6 378 137 m,
//! 1/f = 298.257223563). The forward map is the closed form (TR8350.2 eq. 4-14). The inverse is
//! Bowring's method (Bowring, "Transformation from spatial to geographical coordinates", Survey
//! Review 23(181), 1976, eqs. 2–5), iterated a fixed four times from the parametric latitude,
//! which converges to below 1e-12 rad from the Earth's centre region out past GEO; the height is
//! then `h = p cos φ + z sin φ − a √(1 − e² sin² φ)`, which has no singularity at the poles.

use nalgebra::{Matrix3, Vector3};

/// \[m\] WGS-84 semi-major axis a.
pub const WGS84_A_M: f64 = 6_378_137.0;
/// [-] WGS-84 flattening f.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// [-] WGS-84 first eccentricity squared e² = f (2 − f).
pub const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);

/// A point as geodetic latitude, longitude and height above the WGS-84 ellipsoid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geodetic {
    /// \[rad\] geodetic latitude φ, in [−π/2, π/2].
    pub lat_rad: f64,
    /// \[rad\] east longitude λ, in (−π, π].
    pub lon_rad: f64,
    /// \[m\] height above the ellipsoid along its normal.
    pub height_m: f64,
}

/// The Earth-fixed position of a geodetic point (TR8350.2 eq. 4-14, exact).
pub fn ecef_from_geodetic(p: &Geodetic) -> Vector3<f64> {
    let (sin_lat, cos_lat) = p.lat_rad.sin_cos();
    let (sin_lon, cos_lon) = p.lon_rad.sin_cos();
    // Prime-vertical radius of curvature N(φ).
    let n_m = WGS84_A_M / (1.0 - WGS84_E2 * sin_lat * sin_lat).sqrt();
    Vector3::new(
        (n_m + p.height_m) * cos_lat * cos_lon,
        (n_m + p.height_m) * cos_lat * sin_lon,
        (n_m * (1.0 - WGS84_E2) + p.height_m) * sin_lat,
    )
}

/// The geodetic coordinates of an Earth-fixed position `r_ecef_m` \[m\] (Bowring 1976, four fixed
/// iterations). Allocation-free and panic-free for every finite input; the Earth's centre maps
/// to latitude 0, height −a.
pub fn geodetic_from_ecef(r_ecef_m: &Vector3<f64>) -> Geodetic {
    let (x, y, z) = (r_ecef_m.x, r_ecef_m.y, r_ecef_m.z);
    let b_m = WGS84_A_M * (1.0 - WGS84_F);
    // Second eccentricity squared e'² = e² / (1 − e²).
    let ep2 = WGS84_E2 / (1.0 - WGS84_E2);
    let p = x.hypot(y);
    // Parametric (reduced) latitude β, first guess (Bowring eq. 3 with φ from the sphere).
    let mut beta = z.atan2(p * (1.0 - WGS84_F));
    let mut lat = 0.0;
    for _ in 0..4 {
        let (sb, cb) = beta.sin_cos();
        // Bowring eq. 2: tan φ = (z + e'² b sin³β) / (p − e² a cos³β).
        lat = (z + ep2 * b_m * sb * sb * sb).atan2(p - WGS84_E2 * WGS84_A_M * cb * cb * cb);
        // Bowring eq. 4: tan β = (1 − f) tan φ.
        let (sl, cl) = lat.sin_cos();
        beta = ((1.0 - WGS84_F) * sl).atan2(cl);
    }
    let (sin_lat, cos_lat) = lat.sin_cos();
    let height_m =
        p * cos_lat + z * sin_lat - WGS84_A_M * (1.0 - WGS84_E2 * sin_lat * sin_lat).sqrt();
    Geodetic {
        lat_rad: lat,
        lon_rad: y.atan2(x),
        height_m,
    }
}

/// DCM [NED ECEF]: maps Earth-fixed components to the local north-east-down components at
/// geodetic latitude `lat_rad` and longitude `lon_rad` (`v_ned = dcm_ned_ecef * v_ecef`). With a
/// geocentric latitude it gives the geocentric NED frame instead.
pub fn dcm_ned_ecef(lat_rad: f64, lon_rad: f64) -> Matrix3<f64> {
    let (sl, cl) = lat_rad.sin_cos();
    let (so, co) = lon_rad.sin_cos();
    // Rows: north, east and down unit vectors in ECEF components.
    Matrix3::new(
        -sl * co,
        -sl * so,
        cl, //
        -so,
        co,
        0.0, //
        -cl * co,
        -cl * so,
        -sl,
    )
}
