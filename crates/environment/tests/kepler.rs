//! Kepler's equation and the element conversions, against Vallado's worked examples and the
//! two-body closed forms.

use flexdyn_environment::orbit::keplerian::{
    eccentric_anomaly_rad, mean_of_true_rad, rv_to_elements, true_of_eccentric_rad, Anomaly,
    KeplerianElements,
};
use nalgebra::Vector3;

/// Vallado's μ⊕ \[m³/s²\] (4th ed., Appendix D), used by his examples.
const MU: f64 = 3.986004418e14;
const TAU: f64 = std::f64::consts::TAU;

/// Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., Example 2-1: M = 235.4°,
/// e = 0.4 gives E = 220.512074767522° (3.848661745 rad).
#[test]
fn validate_vallado_example_2_1_kepler() {
    let e_rad = eccentric_anomaly_rad(235.4f64.to_radians(), 0.4);
    let d = (e_rad.to_degrees() - 220.512074767522).abs();
    assert!(d < 1e-11, "E = {}°, off by {d:e}°", e_rad.to_degrees());
}

/// Kepler's equation is solved to rounding for every e in [0, 1), including e → 1 near
/// perigee where Newton's method alone overshoots, and the whole turns of M are kept.
#[test]
fn kepler_residual_is_rounding_everywhere() {
    for &e in &[0.0, 1e-9, 0.1, 0.5, 0.9, 0.99, 0.999999, 1.0 - 1e-12] {
        for k in 0..=4000 {
            let m =
                -4.0 * std::f64::consts::PI + 8.0 * std::f64::consts::PI * f64::from(k) / 4000.0;
            let big_e = eccentric_anomaly_rad(m, e);
            let f = big_e - e * big_e.sin() - m;
            let scale = big_e.abs().max(1.0);
            assert!(
                f.abs() <= 8.0 * f64::EPSILON * scale,
                "e = {e}, M = {m}: residual {f:e}"
            );
            // Same turn: |E − M| ≤ e.
            assert!(
                (big_e - m).abs() <= e + 1e-12,
                "e = {e}, M = {m}: E = {big_e}"
            );
            // Inverse through the true anomaly.
            // Inverse through the true anomaly (ill-conditioned as e → 1, where √(1 − e)
            // scales the half-angle tangent: checked up to e = 0.99).
            if e <= 0.99 {
                let nu = true_of_eccentric_rad(big_e, e);
                let m_back = mean_of_true_rad(nu, e);
                let dm = (m_back - m).rem_euclid(TAU);
                let dm = dm.min(TAU - dm);
                assert!(dm < 1e-13 / (1.0 - e), "e = {e}, M = {m}: back {m_back}");
            }
        }
    }
}

fn example_2_6() -> KeplerianElements {
    let p_m = 11067.790e3;
    let e = 0.83285;
    KeplerianElements {
        semi_major_axis_m: p_m / (1.0 - e * e),
        eccentricity: e,
        inclination_rad: 87.87f64.to_radians(),
        raan_rad: 227.89f64.to_radians(),
        arg_perigee_rad: 53.38f64.to_radians(),
        anomaly: Anomaly::TrueRad(92.335f64.to_radians()),
    }
}

/// Vallado Example 2-6 (COE2RV): p = 11067.790 km, e = 0.83285, i = 87.87°, Ω = 227.89°,
/// ω = 53.38°, ν = 92.335° give r = (6525.344, 6861.535, 6449.125) km,
/// v = (4.902276, 5.533124, −1.975709) km/s. The book's inputs are printed to 0.01° (i, Ω, ω),
/// 0.001° (ν), 1 m (p) and 1e-5 (e): the tolerance is the state's change for half of each
/// last digit, summed (finite differences), plus half the printed output digit.
#[test]
fn validate_vallado_example_2_6_coe2rv() {
    let el = example_2_6();
    let (r, v) = el.to_rv_n(MU);
    let want_r = Vector3::new(6525.344, 6861.535, 6449.125) * 1e3;
    let want_v = Vector3::new(4.902276, 5.533124, -1.975709) * 1e3;
    let half = [
        0.5,
        0.5e-5,
        0.005f64.to_radians(),
        0.005f64.to_radians(),
        0.005f64.to_radians(),
        0.0005f64.to_radians(),
    ];
    let (mut r_tol, mut v_tol) = (0.5, 0.5e-3);
    for (k, h) in half.iter().enumerate() {
        let mut p = el;
        let e = el.eccentricity;
        match k {
            0 => p.semi_major_axis_m += h / (1.0 - e * e),
            1 => {
                let p_m = el.semi_major_axis_m * (1.0 - e * e);
                p.eccentricity += h;
                p.semi_major_axis_m = p_m / (1.0 - p.eccentricity * p.eccentricity);
            }
            2 => p.inclination_rad += h,
            3 => p.raan_rad += h,
            4 => p.arg_perigee_rad += h,
            _ => p.anomaly = Anomaly::TrueRad(92.335f64.to_radians() + h),
        }
        let (rp, vp) = p.to_rv_n(MU);
        r_tol += (rp - r).norm();
        v_tol += (vp - v).norm();
    }
    let (dr, dv) = ((r - want_r).norm(), (v - want_v).norm());
    println!("Vallado 2-6: |Δr| = {dr:.1} m (tol {r_tol:.1}), |Δv| = {dv:.4} m/s (tol {v_tol:.4})");
    assert!(dr <= r_tol && dv <= v_tol);
}

/// (Vallado's Example 2-5, the inverse, is not used: its printed elements do not follow from
/// its printed r and v — they give i = 87.8691°, p = 11067.798 km, not 87.870° and 11067.790
/// km — by more than the rounding of r and v explains; `rv_to_elements` is checked here by
/// the closed forms and round trips instead.)
///
/// The two-body closed forms the state must satisfy whatever the elements: |h| = √(μ p),
/// energy = −μ / 2a, the eccentricity vector points to perigee, `[N PQW]`'s W is ĥ and its
/// P the perigee; and elements → r/v → elements → r/v reproduces the state (also at the
/// singular circular and equatorial orbits, where the angles follow the documented convention).
#[test]
fn closed_forms_and_round_trips() {
    let mut n = 0;
    for &e in &[0.0, 1e-6, 0.01, 0.3, 0.7, 0.95] {
        for &i_deg in &[0.0, 1e-3, 28.5, 63.4, 97.8, 179.9, 180.0] {
            for k in 0..6 {
                let kf = f64::from(k);
                let el = KeplerianElements {
                    semi_major_axis_m: 7.0e6 + 3.0e6 * kf,
                    eccentricity: e,
                    inclination_rad: f64::to_radians(i_deg),
                    raan_rad: 0.7 + 1.1 * kf,
                    arg_perigee_rad: 2.9 - 0.8 * kf,
                    anomaly: if k % 2 == 0 {
                        Anomaly::TrueRad(-3.0 + 1.3 * kf)
                    } else {
                        Anomaly::MeanRad(5.0 - 2.1 * kf)
                    },
                };
                el.validate("orbit", ["a", "e", "i", "raan", "argp", "anomaly"])
                    .unwrap();
                let (r, v) = el.to_rv_n(MU);
                let a = el.semi_major_axis_m;
                let p = a * (1.0 - e * e);
                let h = r.cross(&v);
                assert!((h.norm() / (MU * p).sqrt() - 1.0).abs() < 1e-13);
                let energy = 0.5 * v.norm_squared() - MU / r.norm();
                assert!((energy / (-MU / (2.0 * a)) - 1.0).abs() < 1e-12);
                let dcm = el.dcm_n_pqw();
                assert!((dcm.column(2) - h / h.norm()).norm() < 1e-13);
                if e > 1e-3 {
                    let e_vec = ((v.norm_squared() - MU / r.norm()) * r - r.dot(&v) * v) / MU;
                    assert!((e_vec - dcm.column(0) * e).norm() < 1e-12 * (1.0 + e));
                }
                let back = rv_to_elements(&r, &v, MU);
                let (r2, v2) = back.to_rv_n(MU);
                assert!(
                    (r2 - r).norm() < 1e-6 * r.norm() * 1e-3,
                    "e {e} i {i_deg} k {k}"
                );
                assert!((v2 - v).norm() < 1e-9 * v.norm());
                assert!((back.semi_major_axis_m / a - 1.0).abs() < 1e-11);
                assert!((back.eccentricity - e).abs() < 1e-11);
                assert!((back.inclination_rad - el.inclination_rad).abs() < 1e-7);
                n += 1;
            }
        }
    }
    assert_eq!(n, 6 * 7 * 6);
}

#[test]
fn bad_elements_name_the_field() {
    let names = [
        "semi_major_axis_m",
        "eccentricity",
        "inclination_deg",
        "raan_deg",
        "arg_perigee_deg",
        "true_anomaly_deg",
    ];
    let mut el = example_2_6();
    el.eccentricity = 1.0;
    let err = el.validate("orbit", names).unwrap_err().to_string();
    assert!(err.starts_with("orbit.eccentricity: "), "{err}");
    let mut el = example_2_6();
    el.semi_major_axis_m = -7e6;
    let err = el.validate("orbit", names).unwrap_err().to_string();
    assert!(err.starts_with("orbit.semi_major_axis_m: "), "{err}");
    let mut el = example_2_6();
    el.inclination_rad = 3.5;
    let err = el.validate("orbit", names).unwrap_err().to_string();
    assert!(err.starts_with("orbit.inclination_deg: "), "{err}");
    let mut el = example_2_6();
    el.raan_rad = f64::NAN;
    let err = el.validate("orbit", names).unwrap_err().to_string();
    assert!(err.starts_with("orbit.raan_deg: "), "{err}");
}
