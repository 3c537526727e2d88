//! Mean obliquity of the ecliptic and IAU 1976 precession, from the mean equator and equinox of
//! date to those of J2000.0.
//!
//! - Mean obliquity ε0 (Meeus eq. 22.2, Lieske et al. 1977):
//!   ε0 = 23°26′21.448″ − 46.8150″ T − 0.00059″ T² + 0.001813″ T³.
//! - Precession angles from J2000.0 to the date (Meeus eq. 21.2 with T = 0, Lieske et al.,
//!   A&A 58, 1977, Table 5):
//!   ζ = 2306.2181″ t + 0.30188″ t² + 0.017998″ t³,
//!   z = 2306.2181″ t + 1.09468″ t² + 0.018203″ t³,
//!   θ = 2004.3109″ t − 0.42665″ t² − 0.041833″ t³;
//!   the rotation is [date ← J2000] = R3(−z) R2(θ) R3(−ζ) (Meeus eq. 21.4 written as frame
//!   rotations, [`m1`]–[`m3`] of [`flexdyn_kernel::attitude`]), so [J2000 ← date] is its transpose.
//!
//! Checked against Meeus Example 21.b (θ Persei, J2000.0 → 2028 Nov 13.19 TD) in
//! `crates/environment/tests/ephemeris.rs`.

use nalgebra::Matrix3;

use flexdyn_kernel::attitude::{m1, m2, m3};

const ARCSEC_TO_RAD: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// \[rad\] mean obliquity of the ecliptic of date ε0 (Meeus eq. 22.2) at `t_tt_jc` Julian
/// centuries of TT since J2000.0.
pub fn mean_obliquity_rad(t_tt_jc: f64) -> f64 {
    let t = t_tt_jc;
    (84_381.448 + t * (-46.8150 + t * (-0.00059 + t * 0.001813))) * ARCSEC_TO_RAD
}

/// DCM [date J2000]: maps components on the mean equator and equinox of J2000.0 to those on the
/// mean equator and equinox of date (IAU 1976, Meeus eqs. 21.2–21.4).
pub fn dcm_date_j2000(t_tt_jc: f64) -> Matrix3<f64> {
    let t = t_tt_jc;
    let zeta = t * (2306.2181 + t * (0.30188 + t * 0.017998)) * ARCSEC_TO_RAD;
    let z = t * (2306.2181 + t * (1.09468 + t * 0.018203)) * ARCSEC_TO_RAD;
    let theta = t * (2004.3109 + t * (-0.42665 + t * -0.041833)) * ARCSEC_TO_RAD;
    m3(-z) * m2(theta) * m3(-zeta)
}

/// DCM [N ecliptic-of-date]: maps components on the mean ecliptic and equinox of date to N
/// (mean equator and equinox of J2000.0): first about x by −ε0 onto the mean equator of date,
/// then the precession back to J2000.0.
pub fn dcm_n_ecliptic_of_date(t_tt_jc: f64) -> Matrix3<f64> {
    dcm_date_j2000(t_tt_jc).transpose() * m1(-mean_obliquity_rad(t_tt_jc))
}
