//! The Moon's geocentric position: Meeus, *Astronomical Algorithms*, 2nd ed., ch. 47
//! (eqs. 47.1–47.7, Tables 47.A/47.B, and the additive terms of p. 338), a truncation of
//! ELP-2000/82 stated to about 10″ in longitude and 4″ in latitude.

use nalgebra::Vector3;

use super::moon_terms::{LAT, LON_DIST};
use super::{reduced_rad, EclipticOfDate};

/// The Moon's geometric position on the mean ecliptic and equinox of date at `t_tt_jc` Julian
/// centuries of TT since J2000.0 (Meeus ch. 47).
pub fn moon_ecliptic_of_date(t_tt_jc: f64) -> EclipticOfDate {
    let t = t_tt_jc;
    // Eqs. 47.1–47.5 [deg]: mean longitude L′, mean elongation D, the Sun's mean anomaly M, the
    // Moon's mean anomaly M′, and the argument of latitude F.
    let lp_deg = 218.316_447_7
        + t * (481_267.881_234_21 + t * (-0.001_578_6 + t * (1.0 / 538_841.0 - t / 65_194_000.0)));
    let d = reduced_rad(
        297.850_192_1
            + t * (445_267.111_403_4
                + t * (-0.001_881_9 + t * (1.0 / 545_868.0 - t / 113_065_000.0))),
    );
    let m =
        reduced_rad(357.529_109_2 + t * (35_999.050_290_9 + t * (-0.000_153_6 + t / 24_490_000.0)));
    let mp = reduced_rad(
        134.963_396_4
            + t * (477_198.867_505_5 + t * (0.008_741_4 + t * (1.0 / 69_699.0 - t / 14_712_000.0))),
    );
    let f = reduced_rad(
        93.272_095_0
            + t * (483_202.017_523_3
                + t * (-0.003_653_9 + t * (-1.0 / 3_526_000.0 + t / 863_310_000.0))),
    );
    let lp = reduced_rad(lp_deg);
    // Further arguments [deg] (p. 338): A1 (Venus), A2 (Jupiter), A3.
    let a1 = reduced_rad(119.75 + 131.849 * t);
    let a2 = reduced_rad(53.09 + 479_264.290 * t);
    let a3 = reduced_rad(313.45 + 481_266.484 * t);
    // Eq. 47.6: the decrease of the Earth's orbital eccentricity; terms in M carry E^|m|.
    let e = 1.0 - t * (0.002_516 + t * 0.000_007_4);
    let e_pow = [1.0, e, e * e];

    let argument = |row: &[i32]| {
        f64::from(row[0]) * d
            + f64::from(row[1]) * m
            + f64::from(row[2]) * mp
            + f64::from(row[3]) * f
    };
    // Σl [1e-6 deg] and Σr [1e-3 km], Table 47.A.
    let (mut sum_l, mut sum_r) = (0.0, 0.0);
    for row in &LON_DIST {
        let (s, c) = argument(row).sin_cos();
        let scale = e_pow[row[1].unsigned_abs() as usize];
        sum_l += f64::from(row[4]) * scale * s;
        sum_r += f64::from(row[5]) * scale * c;
    }
    // Σb [1e-6 deg], Table 47.B.
    let mut sum_b = 0.0;
    for row in &LAT {
        sum_b += f64::from(row[4]) * e_pow[row[1].unsigned_abs() as usize] * argument(row).sin();
    }
    // Additive terms (p. 338): Venus, Jupiter and the flattening of the Earth.
    sum_l += 3958.0 * a1.sin() + 1962.0 * (lp - f).sin() + 318.0 * a2.sin();
    sum_b += -2235.0 * lp.sin()
        + 382.0 * a3.sin()
        + 175.0 * (a1 - f).sin()
        + 175.0 * (a1 + f).sin()
        + 127.0 * (lp - mp).sin()
        - 115.0 * (lp + mp).sin();

    // Eq. 47.7 and p. 342: λ = L′ + Σl, β = Σb, Δ = 385 000.56 km + Σr.
    EclipticOfDate {
        lon_rad: reduced_rad(lp_deg + sum_l * 1e-6),
        lat_rad: (sum_b * 1e-6).to_radians(),
        distance_m: (385_000.56 + sum_r * 1e-3) * 1e3,
    }
}

/// \[m\] the Moon's geocentric position in N (mean equator and equinox of J2000.0 ≈ GCRF) at
/// `t_tt_jc` Julian centuries of TT since J2000.0.
pub fn moon_position_n_m(t_tt_jc: f64) -> Vector3<f64> {
    moon_ecliptic_of_date(t_tt_jc).to_n_m(t_tt_jc)
}
