//! Sun and Moon ephemerides against independent references.
//!
//! Oracles (each a `validate_*` test):
//! - Meeus, *Astronomical Algorithms*, 2nd ed., worked Examples 21.b (precession), 25.a (Sun) and
//!   47.a (Moon), to their printed precision;
//! - the VSOP87 Earth series of Meeus Appendix III (`ephemeris/vsop87_earth.rs`, about
//!   1″), itself checked against Example 25.b and JPL Horizons (DE441), as the year-long reference
//!   for the Sun;
//! - JPL Horizons (DE441) astrometric positions of the Moon over 2026-01-21…28, as the reference
//!   for the Moon (how to regenerate them is beside the table).

mod vsop87_earth;

use flexdyn_environment::ephemeris::{
    julian_centuries_tt, moon_ecliptic_of_date, moon_position_n_m, precession,
    sun_ecliptic_of_date, sun_position_n_m, AU_M,
};
use nalgebra::Vector3;

const ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);
/// [s] TT − UTC for dates from 2017 on: 37 leap seconds + 32.184 s (IERS Bulletin C).
const TT_MINUS_UTC_S: f64 = 69.184;

/// Julian Date of a Gregorian calendar date and fractional hour (Meeus eq. 7.1).
fn julian_date(year: i32, month: i32, day: i32, hour: f64) -> f64 {
    let (y, m) = if month <= 2 {
        (year - 1, month + 12)
    } else {
        (year, month)
    };
    let a = (f64::from(y) / 100.0).floor();
    let b = 2.0 - a + (a / 4.0).floor();
    (365.25 * (f64::from(y) + 4716.0)).floor()
        + (30.6001 * (f64::from(m) + 1.0)).floor()
        + f64::from(day)
        + hour / 24.0
        + b
        - 1524.5
}

fn unit_from_ra_dec_deg(ra_deg: f64, dec_deg: f64) -> Vector3<f64> {
    let (sa, ca) = ra_deg.to_radians().sin_cos();
    let (sd, cd) = dec_deg.to_radians().sin_cos();
    Vector3::new(cd * ca, cd * sa, sd)
}

fn ra_dec_deg(v: &Vector3<f64>) -> (f64, f64) {
    (
        v.y.atan2(v.x).to_degrees().rem_euclid(360.0),
        (v.z / v.norm()).asin().to_degrees(),
    )
}

/// Right ascension and declination [deg] of ecliptic coordinates (Meeus eqs. 13.3, 13.4).
fn ecliptic_to_ra_dec_deg(lon_deg: f64, lat_deg: f64, obliquity_deg: f64) -> (f64, f64) {
    let (l, b, e) = (
        lon_deg.to_radians(),
        lat_deg.to_radians(),
        obliquity_deg.to_radians(),
    );
    let ra = (l.sin() * e.cos() - b.tan() * e.sin()).atan2(l.cos());
    let dec = (b.sin() * e.cos() + b.cos() * e.sin() * l.sin()).asin();
    (ra.to_degrees().rem_euclid(360.0), dec.to_degrees())
}

#[test]
fn validate_julian_date_meeus_example_7a() {
    // Meeus Example 7.a: 1957 October 4.81 = JD 2436116.31.
    assert!((julian_date(1957, 10, 4, 0.81 * 24.0) - 2_436_116.31).abs() < 1e-9);
}

#[test]
fn validate_sun_meeus_example_25a() {
    // Meeus Example 25.a: 1992 October 13.0 TD, JDE 2448908.5, T = −0.072183436.
    let t = julian_centuries_tt(2_448_908.5);
    assert!((t - -0.072_183_436).abs() < 1e-9);
    let sun = sun_ecliptic_of_date(t);
    // ☉ = 199.90988° (Meeus adds the rounded L0 = 201.80720° and C = −1.89732°, so the printed
    // value carries ±1e-5° of rounding); R = 0.99766 AU.
    let lon_deg = sun.lon_rad.to_degrees();
    assert!((lon_deg - 199.909_88).abs() < 1.5e-5, "☉ = {lon_deg}");
    assert_eq!(sun.lat_rad, 0.0);
    let r_au = sun.distance_m / AU_M;
    assert!((r_au - 0.997_66).abs() < 5e-6, "R = {r_au}");
    // The example's apparent place (nutation and aberration as the book applies them, eq. 25.8
    // and p. 165): Ω = 264.65°, λ = ☉ − 0.00569° − 0.00478° sin Ω, ε = ε0 + 0.00256° cos Ω with
    // ε0 = 23°26′24.83″; α = 13h13m31.4s (198.38083°), δ = −7°47′06″ (−7.78507°).
    let omega = (125.04 - 1934.136 * t).to_radians();
    let lambda_deg = lon_deg - 0.005_69 - 0.004_78 * omega.sin();
    let eps0_deg = precession::mean_obliquity_rad(t).to_degrees();
    assert!((eps0_deg - (23.0 + 26.0 / 60.0 + 24.83 / 3600.0)).abs() < 0.005 / 3600.0);
    let (ra, dec) = ecliptic_to_ra_dec_deg(lambda_deg, 0.0, eps0_deg + 0.002_56 * omega.cos());
    assert!((ra - 198.380_83).abs() < 1.5e-5, "α = {ra}");
    assert!((dec - -7.785_07).abs() < 1.5e-5, "δ = {dec}");
}

#[test]
fn validate_moon_meeus_example_47a() {
    // Meeus Example 47.a: 1992 April 12, 0h TD, JDE 2448724.5.
    let t = julian_centuries_tt(2_448_724.5);
    assert!((t - -0.077_221_081_451).abs() < 1e-12);
    let moon = moon_ecliptic_of_date(t);
    // λ = 133.162655°, β = −3.229126°, Δ = 368409.7 km (printed to 1e-6° and 0.1 km: the sums
    // Σl = −1127527, Σb = −3229126 are printed to one unit of 1e-6°).
    let lon_deg = moon.lon_rad.to_degrees();
    let lat_deg = moon.lat_rad.to_degrees();
    assert!((lon_deg - 133.162_655).abs() < 1e-6, "λ = {lon_deg}");
    assert!((lat_deg - -3.229_126).abs() < 1e-6, "β = {lat_deg}");
    assert!(
        (moon.distance_m - 368_409.7e3).abs() < 50.0,
        "Δ = {}",
        moon.distance_m
    );
    // Apparent place with the example's Δψ = +0.004610° and ε = 23.440636°:
    // α = 134.688470°, δ = +13.768368°.
    let (ra, dec) = ecliptic_to_ra_dec_deg(lon_deg + 0.004_610, lat_deg, 23.440_636);
    assert!((ra - 134.688_470).abs() < 2e-6, "α = {ra}");
    assert!((dec - 13.768_368).abs() < 2e-6, "δ = {dec}");
}

#[test]
fn validate_precession_meeus_example_21b() {
    // Meeus Example 21.b: θ Persei, J2000.0 place corrected for proper motion α0 = 41.054063°,
    // δ0 = +49.227750°, precessed to 2028 Nov 13.19 TD (JD 2462088.69): α = 41.547214°,
    // δ = +49.348483°.
    let t = julian_centuries_tt(2_462_088.69);
    let u_date = precession::dcm_date_j2000(t) * unit_from_ra_dec_deg(41.054_063, 49.227_750);
    let (ra, dec) = ra_dec_deg(&u_date);
    assert!((ra - 41.547_214).abs() < 1e-6, "α = {ra}");
    assert!((dec - 49.348_483).abs() < 1e-6, "δ = {dec}");
}

/// Σ_i τ^i Σ_rows A cos(B + C τ), in the table's units (1e-8 rad or 1e-8 AU).
fn vsop_sum(series: &[&[[f64; 3]]], tau: f64) -> f64 {
    series
        .iter()
        .enumerate()
        .map(|(i, rows)| {
            let s: f64 = rows.iter().map(|[a, b, c]| a * (b + c * tau).cos()).sum();
            s * tau.powi(i as i32)
        })
        .sum::<f64>()
        * 1e-8
}

/// Heliocentric L [rad], B [rad], R [AU] of the Earth from the truncated VSOP87 (Meeus ch. 32).
fn vsop87_earth_lbr(t_tt_jc: f64) -> (f64, f64, f64) {
    use vsop87_earth::*;
    let tau = t_tt_jc / 10.0;
    (
        vsop_sum(&[&L0, &L1, &L2, &L3, &L4, &L5], tau),
        vsop_sum(&[&B0, &B1], tau),
        vsop_sum(&[&R0, &R1, &R2, &R3, &R4], tau),
    )
}

/// [m] the Sun's geometric geocentric position in N from VSOP87: ☉ = L + 180°, β = −B, the
/// conversion to the FK5 system (Meeus eq. 32.3), then the same obliquity and precession as the
/// model under test (checked on their own by Example 21.b above).
fn sun_vsop87_n_m(t_tt_jc: f64) -> Vector3<f64> {
    let (l, b, r_au) = vsop87_earth_lbr(t_tt_jc);
    let mut lon = l + std::f64::consts::PI;
    let mut lat = -b;
    let lon_prime = lon - (1.397 * t_tt_jc + 0.000_31 * t_tt_jc * t_tt_jc).to_radians();
    lon += -0.090_33 * ARCSEC;
    lat += 0.039_16 * ARCSEC * (lon_prime.cos() - lon_prime.sin());
    let r_ecl = r_au * AU_M * Vector3::new(lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin());
    precession::dcm_n_ecliptic_of_date(t_tt_jc) * r_ecl
}

#[test]
fn validate_vsop87_reference_meeus_example_25b_and_horizons() {
    // Meeus Example 25.b (1992 Oct 13.0 TD): L = −43.63484796 rad, B = −0.00000312 rad,
    // R = 0.99760775 AU.
    let (l, b, r) = vsop87_earth_lbr(julian_centuries_tt(2_448_908.5));
    assert!((l - -43.634_847_96).abs() < 1e-8, "L = {l}");
    assert!((b - -0.000_003_12).abs() < 1e-8, "B = {b}");
    assert!((r - 0.997_607_75).abs() < 1e-8, "R = {r}");
    // JPL Horizons, Sun (10) from the geocentre, DE441, 2023-Jun-21 12:00 UT, astrometric ICRF:
    // RA 89.52285°, Dec 23.43572° (request: COMMAND=10 CENTER=500@399 EPHEM_TYPE=OBSERVER
    // QUANTITIES=1 ANG_FORMAT=DEG). The Sun's barycentric motion during the 499 s light time
    // moves it by 0.01″, so astrometric and geometric agree far inside the tolerance.
    let jd_tt = julian_date(2023, 6, 21, 12.0) + TT_MINUS_UTC_S / 86_400.0;
    let u = sun_vsop87_n_m(julian_centuries_tt(jd_tt)).normalize();
    let err = u.angle(&unit_from_ra_dec_deg(89.522_85, 23.435_72)) / ARCSEC;
    assert!(err < 0.5, "VSOP87 reference vs DE441: {err}″");
}

#[test]
fn validate_sun_against_vsop87_over_2024() {
    // Every 6 h through 2024 (1464 samples): the direction within 21″ of VSOP87 (Meeus states
    // 0.01° = 36″ for the low-accuracy method), the distance within 6 800 km (4.5e-5 relative,
    // so 9e-5 on a 1/r² solar flux).
    let (mut worst_angle, mut worst_range_m) = (0.0_f64, 0.0_f64);
    for i in 0..4 * 366 {
        let jd_tt = julian_date(2024, 1, 1, 0.0) + f64::from(i) * 0.25;
        let t = julian_centuries_tt(jd_tt);
        let model = sun_position_n_m(t);
        let reference = sun_vsop87_n_m(t);
        worst_angle = worst_angle.max(model.angle(&reference) / ARCSEC);
        worst_range_m = worst_range_m.max((model.norm() - reference.norm()).abs());
    }
    println!(
        "Sun over 2024: {worst_angle:.2}″, {:.0} km",
        worst_range_m / 1e3
    );
    assert!(worst_angle < 21.5, "worst direction error {worst_angle}″");
    assert!(
        worst_range_m < 6.8e6,
        "worst distance error {worst_range_m} m"
    );
}

/// JPL Horizons, Moon (301) from the geocentre (500@399), DE441, observer table, 6-hourly from
/// 2026-Jan-21 18:00 UT: astrometric RA (h m s) and Dec (° ′ ″) in the ICRF, and the range delta
/// [AU]. Generated by Horizons on 2026-01-21 09:02:08 with COMMAND='301' CENTER='500@399'
/// EPHEM_TYPE='OBSERVER' START_TIME='2026-01-21 17:00' STOP_TIME='2026-01-28 17:00'
/// STEP_SIZE='1h' QUANTITIES='1,20,23,24,29' CSV_FORMAT='YES' (every sixth row kept here); to
/// regenerate, send the same request to https://ssd.jpl.nasa.gov/api/horizons.api. A mismatch
/// beyond the tolerance means the lunar series or the precession changed.
const HORIZONS_MOON_2026: [(i32, f64, &str, &str, f64); 28] = [
    (21, 18.0, "22 30 24.41", "-09 42 01.1", 0.002_578_454_479_09),
    (22, 0.0, "22 42 14.97", "-08 12 39.8", 0.002_572_937_612_81),
    (22, 6.0, "22 54 02.85", "-06 41 39.9", 0.002_567_443_987_13),
    (22, 12.0, "23 05 48.95", "-05 09 15.8", 0.002_561_975_466_44),
    (22, 18.0, "23 17 34.26", "-03 35 41.6", 0.002_556_533_717_70),
    (23, 0.0, "23 29 19.77", "-02 01 12.0", 0.002_551_120_389_91),
    (23, 6.0, "23 41 06.54", "-00 26 01.5", 0.002_545_737_297_86),
    (23, 12.0, "23 52 55.65", "+01 09 34.8", 0.002_540_386_607_63),
    (23, 18.0, "00 04 48.21", "+02 45 21.7", 0.002_535_071_020_70),
    (24, 0.0, "00 16 45.36", "+04 21 03.7", 0.002_529_793_953_62),
    (24, 6.0, "00 28 48.24", "+05 56 24.6", 0.002_524_559_710_51),
    (24, 12.0, "00 40 58.02", "+07 31 07.9", 0.002_519_373_644_67),
    (24, 18.0, "00 53 15.87", "+09 04 56.5", 0.002_514_242_306_85),
    (25, 0.0, "01 05 42.95", "+10 37 32.6", 0.002_509_173_576_60),
    (25, 6.0, "01 18 20.39", "+12 08 37.8", 0.002_504_176_774_02),
    (25, 12.0, "01 31 09.32", "+13 37 52.7", 0.002_499_262_748_98),
    (25, 18.0, "01 44 10.79", "+15 04 57.4", 0.002_494_443_945_21),
    (26, 0.0, "01 57 25.79", "+16 29 31.1", 0.002_489_734_436_71),
    (26, 6.0, "02 10 55.25", "+17 51 12.2", 0.002_485_149_934_26),
    (26, 12.0, "02 24 39.93", "+19 09 38.3", 0.002_480_707_760_60),
    (26, 18.0, "02 38 40.49", "+20 24 26.4", 0.002_476_426_792_26),
    (27, 0.0, "02 52 57.40", "+21 35 12.9", 0.002_472_327_367_46),
    (27, 6.0, "03 07 30.89", "+22 41 34.0", 0.002_468_431_159_46),
    (27, 12.0, "03 22 21.00", "+23 43 05.7", 0.002_464_761_015_44),
    (27, 18.0, "03 37 27.44", "+24 39 24.1", 0.002_461_340_761_66),
    (28, 0.0, "03 52 49.67", "+25 30 06.2", 0.002_458_194_976_21),
    (28, 6.0, "04 08 26.78", "+26 14 49.6", 0.002_455_348_731_57),
    (28, 12.0, "04 24 17.55", "+26 53 13.6", 0.002_452_827_309_64),
];

/// "h m s" or "±d m s" to degrees (`hours` multiplies by 15).
fn sexagesimal_deg(text: &str, hours: bool) -> f64 {
    let negative = text.trim_start().starts_with('-');
    let parts: Vec<f64> = text
        .split_whitespace()
        .map(|p| p.trim_start_matches(['+', '-']).parse().unwrap())
        .collect();
    let v = parts[0] + parts[1] / 60.0 + parts[2] / 3600.0;
    let v = if hours { 15.0 * v } else { v };
    if negative {
        -v
    } else {
        v
    }
}

#[test]
fn validate_moon_against_horizons_de441() {
    // Astrometric places carry the 1.3 s light time (≈ 1 km, 0.7″ of lunar motion), well inside
    // the tolerance; times are UTC, so TT = UTC + 69.184 s (the Moon moves 38″ in that time).
    let (mut worst_angle, mut worst_range_m) = (0.0_f64, 0.0_f64);
    for (day, hour, ra, dec, delta_au) in HORIZONS_MOON_2026 {
        let jd_tt = julian_date(2026, 1, day, hour) + TT_MINUS_UTC_S / 86_400.0;
        let model = moon_position_n_m(julian_centuries_tt(jd_tt));
        let reference =
            unit_from_ra_dec_deg(sexagesimal_deg(ra, true), sexagesimal_deg(dec, false));
        worst_angle = worst_angle.max(model.angle(&reference) / ARCSEC);
        worst_range_m = worst_range_m.max((model.norm() - delta_au * AU_M).abs());
    }
    println!(
        "Moon over 2026-01-21..28: {worst_angle:.2}″, {:.1} km",
        worst_range_m / 1e3
    );
    assert!(worst_angle < 25.0, "worst direction error {worst_angle}″");
    assert!(
        worst_range_m < 45e3,
        "worst distance error {worst_range_m} m"
    );
}

#[test]
fn positions_are_finite_and_plausible_over_two_centuries() {
    // 1900–2100 monthly: the Sun within 0.983–1.017 AU (perihelion/aphelion), the Moon within
    // 356 000–407 000 km (the extremes of the lunar distance), both finite.
    for month in 0..12 * 200 {
        let t = julian_centuries_tt(julian_date(1900, 1, 1, 0.0) + f64::from(month) * 30.4375);
        let sun_au = sun_position_n_m(t).norm() / AU_M;
        let moon_km = moon_position_n_m(t).norm() / 1e3;
        assert!(
            (0.983..1.017).contains(&sun_au),
            "Sun {sun_au} AU at T = {t}"
        );
        assert!(
            (356_000.0..407_000.0).contains(&moon_km),
            "Moon {moon_km} km at T = {t}"
        );
    }
}
