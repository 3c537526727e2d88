//! The N → E rotation against the IAU SOFA validation values and Vallado's worked examples.
//!
//! The SOFA values are those of SOFA's own validation program `t_sofa_c.c` (IAU SOFA Board,
//! release 2021-05-12; identical in ERFA's `t_erfa_c.c`), each the reference output of the SOFA
//! routine named, for the arguments given. Where flexdyn's model is the same (ERA, GMST,
//! precession, IAU 2000B, the F-W matrix) the tolerance is SOFA's own; where it is truncated
//! (IAU 2000B against 2000A, the equation of the equinoxes) the tolerance is the stated bound of
//! the truncation.

use flexdyn_environment::earth_rotation::{
    dcm_n_teme, earth_rotation_angle_rad, equation_of_equinoxes_rad, fw_matrix, gmst06_rad,
    gmst82_rad, mean_obliquity06_rad, nutation_2000b, polar_motion_dcm, precession_fw06, r3,
    CelestialPole, EarthRotation, OMEGA_EARTH_RAD_S,
};
use flexdyn_environment::epoch::{
    EarthOrientationParams, EpochScale, EpochTimes, SimEpoch, NS_PER_DAY, RAD_PER_ARCSEC,
};
use nalgebra::{Matrix3, Vector3};

const MAS: f64 = RAD_PER_ARCSEC * 1e-3;

/// \[ns\] JD − 2451545.0 for a SOFA two-part date (2400000.5, mjd).
fn ns_j2000(mjd: f64) -> i64 {
    ((mjd - 51544.5) * NS_PER_DAY as f64).round() as i64
}

fn centuries(mjd: f64) -> f64 {
    (mjd - 51544.5) / 36525.0
}

/// EpochTimes with UT1 = TT = `mjd` (as the SOFA tests call the routines).
fn times_at(mjd: f64) -> EpochTimes {
    EpochTimes {
        t_sim_ns: 0,
        tt_ns_j2000: ns_j2000(mjd),
        ut1_ns_j2000: ns_j2000(mjd),
        tai_minus_utc_s: 0,
        in_leap_second: false,
        gps_week: 0,
        gps_ns_of_week: 0,
    }
}

/// The rotation angle of `a · bᵀ` \[rad\], as atan2(|axial vector|, (trace − 1)/2): precise
/// near zero, where acos of the trace bottoms out at √(2ε) ≈ 4 mas.
fn angle_between(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let d = a * b.transpose();
    let axial = Vector3::new(
        d[(2, 1)] - d[(1, 2)],
        d[(0, 2)] - d[(2, 0)],
        d[(1, 0)] - d[(0, 1)],
    );
    (0.5 * axial.norm()).atan2(0.5 * (d.trace() - 1.0))
}

fn close(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got:.19e}, SOFA {want:.19e}, |diff| {:.3e} > {tol:.1e}",
        (got - want).abs()
    );
}

#[test]
fn validate_sofa_era00_gmst06_gmst82() {
    // iauEra00(2400000.5, 54388.0)
    close(
        earth_rotation_angle_rad(ns_j2000(54388.0)),
        0.4022837240028158102,
        1e-12,
        "ERA",
    );
    // iauGmst06(2400000.5, 53736.0, 2400000.5, 53736.0)
    close(
        gmst06_rad(ns_j2000(53736.0), centuries(53736.0)),
        1.754174971870091203,
        1e-12,
        "GMST06",
    );
    // iauGmst82(2400000.5, 53736.0)
    close(
        gmst82_rad(ns_j2000(53736.0)),
        1.754174981860675096,
        1e-12,
        "GMST82",
    );
}

#[test]
fn validate_sofa_obl06_pfw06_fw2m() {
    // iauObl06(2400000.5, 54388.0)
    close(
        mean_obliquity06_rad(centuries(54388.0)),
        0.4090749229387258204,
        1e-14,
        "obl06",
    );
    // iauPfw06(2400000.5, 50123.9999)
    let fw = precession_fw06(centuries(50123.9999));
    close(fw.gamma_bar_rad, -0.2243387670997995690e-5, 1e-16, "gamb");
    close(fw.phi_bar_rad, 0.4091014602391312808, 1e-12, "phib");
    close(fw.psi_bar_rad, -0.9501954178013031895e-3, 1e-14, "psib");
    close(fw.eps_a_rad, 0.4091014316587367491, 1e-12, "epsa");
    // iauFw2m(gamb, phib, psi, eps)
    let r = fw_matrix(
        -0.2243387670997992368e-5,
        0.4091014602391312982,
        -0.9501954178013015092e-3,
        0.4091014316587367472,
    );
    let want = Matrix3::new(
        0.9999995505176007047,
        0.8695404617348192957e-3,
        0.3779735201865582571e-3,
        -0.8695404723772016038e-3,
        0.9999996219496027161,
        -0.1361752496887100026e-6,
        -0.3779734957034082790e-3,
        -0.1924880848087615651e-6,
        0.9999999285679971958,
    );
    for i in 0..3 {
        for j in 0..3 {
            close(r[(i, j)], want[(i, j)], 1e-12, &format!("fw2m[{i}][{j}]"));
        }
    }
}

#[test]
fn validate_sofa_nut00b_and_eect00() {
    // iauNut00b(2400000.5, 53736.0): the whole 77-term series, to SOFA's 1e-13 rad.
    let n = nutation_2000b(centuries(53736.0));
    close(n.dpsi_rad, -0.9632552291148362783e-5, 1e-13, "dpsi");
    close(n.deps_rad, 0.4063197106621159367e-4, 1e-13, "deps");
    // iauEect00(2400000.5, 53736.0), the complementary terms of the equation of the equinoxes.
    // flexdyn keeps the two largest terms; the 31 others have amplitudes summing to 41.7 µas,
    // plus the 0.87 µas·t term (IERS Conventions (2010) Table 5.2e).
    let t = centuries(53736.0);
    let ct = equation_of_equinoxes_rad(&n, mean_obliquity06_rad(t))
        - n.dpsi_rad * mean_obliquity06_rad(t).cos();
    close(
        ct,
        0.2046085004885125264e-8,
        (41.7 + 0.87 * t.abs()) * 1e-6 * RAD_PER_ARCSEC,
        "eect",
    );
}

#[test]
fn validate_sofa_pom00_up_to_the_neglected_tio_locator() {
    // iauPom00(xp, yp, sp) with sp = s′ = −1.367e-11 rad, which flexdyn neglects: each element
    // may differ by up to |s′|.
    let (xp, yp, sp) = (
        2.55060238e-7,
        1.860359247e-6,
        -0.1367174580728891460e-10_f64,
    );
    let w = polar_motion_dcm(xp, yp);
    let want = Matrix3::new(
        0.9999999999999674721,
        -0.1367174580728846989e-10,
        0.2550602379999972345e-6,
        0.1414624947957029801e-10,
        0.9999999999982695317,
        -0.1860359246998866389e-5,
        -0.2550602379741215021e-6,
        0.1860359247002414021e-5,
        0.9999999999982370039,
    );
    for i in 0..3 {
        for j in 0..3 {
            close(
                w[(i, j)],
                want[(i, j)],
                sp.abs() + 1e-16,
                &format!("pom00[{i}][{j}]"),
            );
        }
    }
}

/// The IAU 2000B model against SOFA's IAU 2006/2000A results: the bias-precession-nutation
/// matrix (iauPnm06a), GAST (iauGst06a) and the whole celestial-to-terrestrial matrix with polar
/// motion (iauC2t06a, CIO based). Bound: IAU 2000B vs 2000A ≤ 1.001 mas (McCarthy & Luzum
/// 2003), + 0.042 mas for the truncated equation of the equinoxes, + 0.06 mas for the IAU 2006
/// nutation adjustments and s′ = 1.1 mas.
#[test]
fn validate_against_sofa_iau2006_2000a_within_the_2000b_bound() {
    let bound = 1.1 * MAS;
    // iauPnm06a(2400000.5, 50123.9999)
    let pole = CelestialPole::at(centuries(50123.9999));
    let pnm06a = Matrix3::new(
        0.9999995832794205484,
        0.8372382772630962111e-3,
        0.3639684771140623099e-3,
        -0.8372533744743683605e-3,
        0.9999996486492861646,
        0.4132905944611019498e-4,
        -0.3639337469629464969e-3,
        -0.4163377605910663999e-4,
        0.9999999329094260057,
    );
    let a = angle_between(&pole.dcm_tod_n, &pnm06a);
    assert!(a <= bound, "[TOD N] vs iauPnm06a: {:.3} mas", a / MAS);

    // iauGst06a(2400000.5, 53736.0, 2400000.5, 53736.0)
    let times = times_at(53736.0);
    let pole = CelestialPole::at(times.tt_centuries_j2000());
    let d = pole.gast_rad(&times) - 1.754166137675019159;
    assert!(d.abs() <= bound, "GAST vs iauGst06a: {:.3} mas", d / MAS);

    // iauC2t06a(2400000.5, 53736.0, 2400000.5, 53736.0, xp, yp)
    let (xp, yp) = (2.55060238e-7, 1.860359247e-6);
    let rot = EarthRotation::new(&EarthOrientationParams {
        ut1_minus_utc_s: 0.0,
        polar_motion_x_rad: xp,
        polar_motion_y_rad: yp,
    });
    let c2t06a = Matrix3::new(
        -0.1810332128305897282,
        0.9834769806938592296,
        0.6555550962998436505e-4,
        -0.9834768134136214897,
        -0.1810332203649130832,
        0.5749800844905594110e-3,
        0.5773474024748545878e-3,
        0.3961816829632690581e-4,
        0.9999998325501747785,
    );
    let frame = rot.at(&times);
    let a = angle_between(&frame.dcm_en, &c2t06a);
    assert!(a <= bound, "[E N] vs iauC2t06a: {:.3} mas", a / MAS);
}

/// Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., Examples 3-14 and 3-15
/// and Table 3-6 (also Vallado et al. 2006, AIAA 2006-6753, Appendix C): on
/// 2004-04-06T07:51:28.386009 UTC, with UT1 − UTC = −0.4399619 s, x_p = −0.140682″,
/// y_p = 0.333309″, the ITRF state r = (−1033.4793830, 7901.2952754, 6380.3565958) km,
/// v = (−3.225636520, −2.872451450, 5.531924446) km/s is, in the GCRF,
/// r = (5102.50895790, 6123.01140070, 6378.13692820) km,
/// v = (−4.7432201570, 0.7905364970, 5.5337557270) km/s (Example 3-15's reduction with the EOP
/// nutation corrections; Example 3-14's IAU 2006/2000 CIO reduction prints the same r to 1 mm).
fn vallado_epoch(eop: EarthOrientationParams) -> SimEpoch {
    SimEpoch::parse(
        "2004-04-06T07:51:28.386009Z",
        EpochScale::Utc,
        eop,
        "epoch.utc",
    )
    .unwrap()
}

const VALLADO_EOP: EarthOrientationParams = EarthOrientationParams {
    ut1_minus_utc_s: -0.4399619,
    polar_motion_x_rad: -0.140682 * RAD_PER_ARCSEC,
    polar_motion_y_rad: 0.333309 * RAD_PER_ARCSEC,
};
const R_ITRF_KM: [f64; 3] = [-1033.4793830, 7901.2952754, 6380.3565958];
const V_ITRF_KM_S: [f64; 3] = [-3.225636520, -2.872451450, 5.531924446];
const R_GCRF_KM: [f64; 3] = [5102.50895790, 6123.01140070, 6378.13692820];
const V_GCRF_KM_S: [f64; 3] = [-4.7432201570, 0.7905364970, 5.5337557270];

fn itrf_to_gcrf(eop: EarthOrientationParams) -> (Vector3<f64>, Vector3<f64>) {
    let e = vallado_epoch(eop);
    let frame = EarthRotation::new(e.earth_orientation()).at(&e.times(0));
    let r_e = Vector3::from(R_ITRF_KM) * 1e3;
    let v_e = Vector3::from(V_ITRF_KM_S) * 1e3;
    (frame.r_n(&r_e), frame.v_n(&r_e, &v_e))
}

#[test]
fn validate_vallado_itrf_to_gcrf_with_eop() {
    // Bound: the model with EOP given, 1.7 mas (see the module docs), plus half the last
    // printed digit (0.05 mm for r, 5e-11 km/s for v).
    let (r_n, v_n) = itrf_to_gcrf(VALLADO_EOP);
    let dr = (r_n - Vector3::from(R_GCRF_KM) * 1e3).norm();
    let dv = (v_n - Vector3::from(V_GCRF_KM_S) * 1e3).norm();
    let r_tol = 1.7 * MAS * r_n.norm() + 0.05e-3;
    let v_tol = 1.7 * MAS * v_n.norm() + 0.05e-6;
    println!(
        "Vallado 3-14, EOP given: |Δr| = {:.4} m (bound {:.4}), |Δv| = {:.2e} m/s (bound {:.2e})",
        dr, r_tol, dv, v_tol
    );
    assert!(dr <= r_tol, "|Δr| = {dr} m > {r_tol} m");
    assert!(dv <= v_tol, "|Δv| = {dv} m/s > {v_tol} m/s");
}

#[test]
fn validate_vallado_itrf_to_gcrf_without_eop_within_the_default_bound() {
    // UT1 − UTC and polar motion left at 0, as a configuration without them: the error must
    // stay within |UT1 − UTC| ≤ 0.9 s of Earth rotation + 0.6″ of polar motion + 1.7 mas.
    let (r_n, v_n) = itrf_to_gcrf(EarthOrientationParams::default());
    let angle = 0.9 * OMEGA_EARTH_RAD_S + 0.6 * RAD_PER_ARCSEC + 1.7 * MAS;
    let dr = (r_n - Vector3::from(R_GCRF_KM) * 1e3).norm();
    let dv = (v_n - Vector3::from(V_GCRF_KM_S) * 1e3).norm();
    println!(
        "Vallado 3-14, no EOP: |Δr| = {dr:.1} m (bound {:.1} m)",
        angle * r_n.norm()
    );
    assert!(dr <= angle * r_n.norm() + 0.05e-3);
    assert!(dv <= angle * v_n.norm() + 0.05e-6);
    // And the error is the UT1 term: 0.44 s of rotation about the pole, ~0.2 km here.
    let with = itrf_to_gcrf(VALLADO_EOP).0;
    assert!((r_n - with).norm() > 100.0);
}

/// Vallado et al. 2006 (AIAA 2006-6753, Appendix C) / Vallado 4th ed. Table 3-6: the same
/// satellite in TEME, r = (5094.18016210, 6127.64465950, 6380.34453270) km,
/// v = (−4.746131487, 0.785818041, 5.531931288) km/s; in the pseudo-Earth-fixed frame (TIRS)
/// r = (−1033.4750312, 7901.3055856, 6380.3445328) km; in the GCRF (the IAU-76/FK5 reduction
/// with its EOP corrections) r = (5102.50895790, 6123.01140070, 6378.13692820) km,
/// v = (−4.7432201570, 0.7905364970, 5.5337557270) km/s.
#[test]
fn validate_vallado_teme() {
    let r_teme = Vector3::new(5094.18016210, 6127.64465950, 6380.34453270) * 1e3;
    let v_teme = Vector3::new(-4.746131487, 0.785818041, 5.531931288) * 1e3;
    let e = vallado_epoch(VALLADO_EOP);
    let times = e.times(0);

    // TEME → TIRS is R3(GMST82(UT1)): this checks the IAU 1982 GMST and UT1 alone. Vallado's
    // code holds JD_UT1 in one f64, whose quantum near JD 2.45e6 is 2⁻³¹ day = 40 µs: half of
    // it is 1.47 nrad of Earth rotation, 12 mm at this 7,968 km distance from the pole; plus
    // the printed 0.1 mm.
    let r_tirs = r3(gmst82_rad(times.ut1_ns_j2000)) * r_teme;
    let want = Vector3::new(-1033.4750312, 7901.3055856, 6380.3445328) * 1e3;
    let d = (r_tirs - want).norm();
    let jd_quantum_rad = 0.5 * 2f64.powi(-31) * 86400.0 * OMEGA_EARTH_RAD_S;
    let tol = jd_quantum_rad * r_teme.xy().norm() + 0.1e-3;
    println!(
        "Vallado TEME → TIRS: |Δr| = {:.2} mm (bound {:.2} mm)",
        d * 1e3,
        tol * 1e3
    );
    assert!(d <= tol, "TEME → TIRS: |Δr| = {d} m");

    // TEME → GCRF. Bound: the model (1.7 mas) + the ambiguity of TEME's equation of the
    // equinoxes (2.7 mas) = 4.4 mas, + half the printed digit.
    let pole = CelestialPole::at(times.tt_centuries_j2000());
    let dcm = dcm_n_teme(&pole, &times);
    let r_n = dcm * r_teme;
    let v_n = dcm * v_teme;
    let dr = (r_n - Vector3::new(5102.50895790, 6123.01140070, 6378.13692820) * 1e3).norm();
    let dv = (v_n - Vector3::new(-4.7432201570, 0.7905364970, 5.5337557270) * 1e3).norm();
    println!("Vallado TEME → GCRF: |Δr| = {dr:.4} m, |Δv| = {dv:.2e} m/s");
    assert!(dr <= 4.4 * MAS * r_n.norm() + 0.05e-3, "|Δr| = {dr} m");
    assert!(dv <= 4.4 * MAS * v_n.norm() + 0.05e-6, "|Δv| = {dv} m/s");
    // UT1 − UTC cancels in [N TEME]: 0.9 s moves it by ≪ 1 µas.
    let e0 = vallado_epoch(EarthOrientationParams::default());
    let t0 = e0.times(0);
    let dcm0 = dcm_n_teme(&CelestialPole::at(t0.tt_centuries_j2000()), &t0);
    assert!(angle_between(&dcm, &dcm0) < 1e-3 * MAS);
}

/// The DCM is a rotation, and its rate is the Earth's angular velocity:
/// d[E N]/dt = −[ω_E/N in E ×] [E N], checked by central differences over ±1 ms; a point fixed
/// in E moves at ω × r in N.
#[test]
fn angular_velocity_matches_the_dcm_rate() {
    let e = vallado_epoch(VALLADO_EOP);
    let rot = EarthRotation::new(e.earth_orientation());
    let t = 3_600_000_000_000u64;
    let h = 1_000_000u64;
    let f = rot.at(&e.times(t));
    let (fp, fm) = (rot.at(&e.times(t + h)), rot.at(&e.times(t - h)));
    let c_dot = (fp.dcm_en - fm.dcm_en) / (2.0 * h as f64 * 1e-9);
    let w_e = f.dcm_en * f.omega_en_n_rad_s;
    let expected = -w_e.cross_matrix() * f.dcm_en;
    let err = (c_dot - expected).norm();
    // Central-difference truncation ω³h²/6 ≈ 6e-20 and rounding ~1e-16/2e-3: the residual is
    // the precession-nutation rate the ω of the model leaves out (< 1e-11 rad/s).
    assert!(err < 2e-11, "|dC/dt + [ω×]C| = {err:e}");
    assert!(((f.dcm_en * f.dcm_en.transpose()) - Matrix3::identity()).norm() < 1e-15);
    assert!((f.omega_en_n_rad_s.norm() / OMEGA_EARTH_RAD_S - 1.0).abs() < 1e-15);
    let r_e = Vector3::new(6378137.0, 0.0, 0.0);
    let r_n = f.r_n(&r_e);
    assert!((f.v_n(&r_e, &Vector3::zeros()) - f.omega_en_n_rad_s.cross(&r_n)).norm() < 1e-9);
    assert!(f.v_e(&r_n, &f.omega_en_n_rad_s.cross(&r_n)).norm() < 1e-9);
}

/// Holding the pole (precession-nutation) while the sidereal angle advances: the error after
/// a hold of `dt` is the pole's motion, which the bench's update-rate choice rests on.
#[test]
fn holding_the_pole_for_a_minute_costs_under_a_milliarcsecond() {
    let e = vallado_epoch(VALLADO_EOP);
    let rot = EarthRotation::new(e.earth_orientation());
    let held = CelestialPole::at(e.times(0).tt_centuries_j2000());
    let mut worst = 0.0f64;
    for k in 0..=60u64 {
        let t = e.times(k * 1_000_000_000);
        worst = worst.max(angle_between(
            &rot.at_with_pole(&held, &t).dcm_en,
            &rot.at(&t).dcm_en,
        ));
    }
    println!("pole held 60 s: worst {:.4} mas", worst / MAS);
    // The precession rate (50″/yr) and the fastest nutation terms move the pole by < 10 µas/s.
    assert!(worst < 0.6 * MAS, "{} mas", worst / MAS);
}

#[test]
fn dcm_does_not_allocate() {
    let e = vallado_epoch(VALLADO_EOP);
    let rot = EarthRotation::new(e.earth_orientation());
    let n = crate::allocations_in(|| {
        for k in 0..1_000u64 {
            std::hint::black_box(rot.at(&e.times(k * 1_000_000)));
        }
    });
    assert_eq!(n, 0);
}
