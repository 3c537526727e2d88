//! Invariants of the free (undamped, unforced) spacecraft: energy and angular momentum.
//!
//! Oracle: physics, not the code's own output. With k ≠ 0 and c = 0 and no external wrench, the
//! rotational kinetic energy about the CoM plus spring energy, and the angular momentum about the
//! CoM, are exact invariants; under point-mass gravity applied at the CoM the orbital energy and
//! orbital angular momentum of the CoM are too. RK4 at 1 ms over 10 s keeps them to ~1e-14, so the
//! 1e-12 bound leaves margin for round-off only: erratum E1 alone drifts the rotational energy by
//! 4.5e-2 and E2 drifts the momentum by 4.0e-1 (ERRATA.md, evidence table).

mod common;

use common::*;
use flexdyn::dynamics::GravityModel;

const TEN_SECONDS_AT_1_MS: usize = 10_000;

#[test]
fn validate_conservation_free_space() {
    let mut sc = reference(GravityModel::None, 0.0);
    let d = run_drift(&mut sc, TEN_SECONDS_AT_1_MS);
    eprintln!("free space, 10 s @ 1 ms: {d:?}");
    d.assert_rotational(1e-12);
    // The panels really move (otherwise the test would prove nothing about the hinge equations).
    let theta = &sc.state().effectors;
    assert!(
        (theta[0] - 5f64.to_radians()).abs() > 1e-3,
        "panel 1 of wing_px did not move"
    );
}

#[test]
fn validate_conservation_point_mass_orbit() {
    let mut sc = reference(GravityModel::PointMass { mu_m3_s2: MU_EARTH }, 0.0);
    let d = run_drift(&mut sc, TEN_SECONDS_AT_1_MS);
    eprintln!("point-mass orbit, 10 s @ 1 ms: {d:?}");
    d.assert_all(1e-12);
}

#[test]
fn validate_conservation_j2_orbit() {
    // J2 applied at the CoM is a conservative field with no torque about C: the orbital energy
    // (with the J2 potential) and the polar component of the orbital angular momentum are
    // conserved; the rotational quantities are untouched.
    let gravity = GravityModel::J2 {
        mu_m3_s2: MU_EARTH,
        j2: 1.08262668e-3,
        r_eq_m: 6_378_136.3,
    };
    let mut sc = reference(gravity, 0.0);
    let h0 = sc.conserved().orb_ang_mom_n;
    let d = run_drift(&mut sc, TEN_SECONDS_AT_1_MS);
    let h1 = sc.conserved().orb_ang_mom_n;
    eprintln!("J2 orbit, 10 s @ 1 ms: {d:?}");
    d.assert_rotational(1e-12);
    assert!(
        d.orb_energy <= 1e-12,
        "orbital energy drift {:e}",
        d.orb_energy
    );
    assert!(
        ((h1.z - h0.z) / h0.norm()).abs() <= 1e-12,
        "polar orbital momentum drift"
    );
    // J2 does torque the orbit about the other axes: the full vector must move.
    assert!(
        (h1 - h0).norm() / h0.norm() > 1e-9,
        "J2 had no effect on the orbit plane"
    );
}

#[test]
fn validate_conservation_eight_pairs_folded_full_inertia() {
    // Eight pairs, folded second panels (θ_H2S1 ≠ 0) and a non-diagonal hub inertia.
    let mut pairs = ring_pairs(8, 0.0);
    for (k, (p, _)) in pairs.iter_mut().enumerate() {
        p.theta_h2s1_rad = 0.3 + 0.2 * k as f64;
    }
    let mut hub = reference_hub();
    hub.inertia_bc_b_kg_m2 =
        nalgebra::Matrix3::new(900.0, 40.0, -25.0, 40.0, 800.0, 15.0, -25.0, 15.0, 600.0);
    let mut sc = build(
        hub,
        GravityModel::PointMass { mu_m3_s2: MU_EARTH },
        pairs,
        reference_initial(),
        1_000_000,
    );
    let d = run_drift(&mut sc, TEN_SECONDS_AT_1_MS);
    eprintln!("8 folded pairs, full hub inertia, 10 s @ 1 ms: {d:?}");
    d.assert_all(1e-12);
}

#[test]
fn validate_damping_dissipates_energy_and_conserves_momentum() {
    // With hinge damping c > 0: energy never increases (beyond round-off), the energy lost equals
    // the work of the dampers ∫ Σ c θ̇² dt (trapezoid rule, O(h²)), and the angular momentum about
    // C, which internal torques cannot change, is still conserved.
    let c = 5.0;
    let mut sc = reference(GravityModel::PointMass { mu_m3_s2: MU_EARTH }, c);
    let c0 = sc.conserved();
    let damper_power = |x: &[f64]| c * (x[1] * x[1] + x[3] * x[3] + x[5] * x[5] + x[7] * x[7]);
    let h_s = 1e-3;
    let mut e_prev = c0.rot_energy_j;
    let mut p_prev = damper_power(&sc.state().effectors);
    let mut dissipated = 0.0;
    let mut max_rise = 0.0f64;
    let mut h_drift = 0.0f64;
    for _ in 0..TEN_SECONDS_AT_1_MS {
        sc.step();
        let cq = sc.conserved();
        max_rise = max_rise.max(cq.rot_energy_j - e_prev);
        e_prev = cq.rot_energy_j;
        let p = damper_power(&sc.state().effectors);
        dissipated += 0.5 * h_s * (p + p_prev);
        p_prev = p;
        h_drift = h_drift
            .max((cq.rot_ang_mom_c_n - c0.rot_ang_mom_c_n).norm() / c0.rot_ang_mom_c_n.norm());
    }
    let lost = c0.rot_energy_j - e_prev;
    eprintln!(
        "damped: E0 = {:.6} J, lost {lost:.6e} J, damper work {dissipated:.6e} J, max step rise {max_rise:e} J, H drift {h_drift:e}",
        c0.rot_energy_j
    );
    assert!(
        max_rise <= 1e-12 * c0.rot_energy_j,
        "energy rose by {max_rise:e} J in one step"
    );
    assert!(
        lost > 1e-3 * c0.rot_energy_j,
        "damping removed almost no energy ({lost:e} J)"
    );
    assert!(
        ((lost - dissipated) / lost).abs() < 1e-5,
        "energy lost {lost:e} J != damper work {dissipated:e} J"
    );
    assert!(
        h_drift <= 1e-12,
        "angular momentum about C drift {h_drift:e} with damping"
    );
}

#[test]
fn validate_external_torque_changes_momentum_at_the_applied_rate() {
    // A constant body torque with the hub otherwise free: dH_C/dt = L (about C, since the force is
    // zero), so H_C(T) − H_C(0) = ∫ [NB] L dt. Integrated alongside with the trapezoid rule.
    let mut sc = reference(GravityModel::None, 0.0);
    let torque_b = nalgebra::Vector3::new(0.3, -0.2, 0.1);
    sc.set_wrench(flexdyn::dynamics::Wrench {
        force_b_newton: nalgebra::Vector3::zeros(),
        torque_b_nm: torque_b,
    });
    let h0 = sc.conserved().rot_ang_mom_c_n;
    let dcm_nb = |sc: &flexdyn::dynamics::Spacecraft| {
        flexdyn::attitude::mrp_to_dcm(&sc.state().sigma_bn).transpose()
    };
    let mut l_prev = dcm_nb(&sc) * torque_b;
    let mut impulse = nalgebra::Vector3::zeros();
    for _ in 0..2000 {
        sc.step();
        let l = dcm_nb(&sc) * torque_b;
        impulse += (l + l_prev) * 0.5e-3;
        l_prev = l;
    }
    let dh = sc.conserved().rot_ang_mom_c_n - h0;
    eprintln!("torque impulse {impulse:?}, ΔH {dh:?}");
    assert!((dh - impulse).norm() / impulse.norm() < 1e-6);
}
