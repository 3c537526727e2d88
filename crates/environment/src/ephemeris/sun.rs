//! The Sun's geocentric position: Meeus, *Astronomical Algorithms*, 2nd ed., ch. 25 ("low
//! accuracy", stated 0.01°), eqs. 25.2–25.5.

use nalgebra::Vector3;

use super::{reduced_rad, EclipticOfDate, AU_M};

/// The Sun's geometric position on the mean ecliptic and equinox of date at `t_tt_jc` Julian
/// centuries of TT since J2000.0 (Meeus ch. 25). The ecliptic latitude is set to zero: the
/// Sun's never exceeds 1.2″ (Meeus ch. 25).
pub fn sun_ecliptic_of_date(t_tt_jc: f64) -> EclipticOfDate {
    let t = t_tt_jc;
    // Eq. 25.2: geometric mean longitude L0 [deg], mean equinox of date.
    let l0_deg = 280.46646 + t * (36_000.769_83 + t * 0.000_303_2);
    // Eq. 25.3: mean anomaly M [deg].
    let m = reduced_rad(357.52911 + t * (35_999.050_29 - t * 0.000_153_7));
    // Eq. 25.4: eccentricity of the Earth's orbit e.
    let e = 0.016_708_634 - t * (0.000_042_037 + t * 0.000_000_126_7);
    // Equation of the centre C [deg] (Meeus p. 164).
    let c_deg = (1.914_602 - t * (0.004_817 + t * 0.000_014)) * m.sin()
        + (0.019_993 - t * 0.000_101) * (2.0 * m).sin()
        + 0.000_289 * (3.0 * m).sin();
    // True longitude ☉ = L0 + C and true anomaly ν = M + C.
    let nu = m + c_deg.to_radians();
    // Eq. 25.5: radius vector R [AU].
    let r_au = 1.000_001_018 * (1.0 - e * e) / (1.0 + e * nu.cos());
    EclipticOfDate {
        lon_rad: reduced_rad(l0_deg + c_deg),
        lat_rad: 0.0,
        distance_m: r_au * AU_M,
    }
}

/// \[m\] the Sun's geocentric position in N (mean equator and equinox of J2000.0 ≈ GCRF) at
/// `t_tt_jc` Julian centuries of TT since J2000.0.
pub fn sun_position_n_m(t_tt_jc: f64) -> Vector3<f64> {
    sun_ecliptic_of_date(t_tt_jc).to_n_m(t_tt_jc)
}
