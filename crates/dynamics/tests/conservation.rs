//! Invariants of the free (undamped, unforced) spacecraft: energy and angular momentum.
//!
//! Oracle: physics, not the code's own output. With k ≠ 0 and c = 0 and no external wrench, the
//! rotational kinetic energy about the CoM plus spring energy, and the angular momentum about the
//! CoM, are exact invariants; under point-mass gravity applied at the CoM the orbital energy and
//! orbital angular momentum of the CoM are too. RK4 at 1 ms over 10 s keeps them to ~1e-14, so the
//! 1e-12 bound leaves margin for round-off only: erratum E1 alone drifts the rotational energy by
//! 4.5e-2 and E2 drifts the momentum by 4.0e-1 (ERRATA.md, evidence table).

use crate::common;

use common::*;
use flexdyn_dynamics::GravityModel;

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
    sc.set_wrench(flexdyn_dynamics::Wrench {
        force_b_newton: nalgebra::Vector3::zeros(),
        torque_b_nm: torque_b,
    });
    let h0 = sc.conserved().rot_ang_mom_c_n;
    let dcm_nb = |sc: &flexdyn_dynamics::Spacecraft| {
        flexdyn_kernel::attitude::mrp_to_dcm(&sc.state().sigma_bn).transpose()
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

/// Every integrator keeps the invariants of the free, undamped reference spacecraft in orbit,
/// and its drift over 200 s shrinks at (at least) the method's order when the step is halved: a
/// drift that did not shrink would be a modelling error, not truncation. The steps are each
/// method's asymptotic range on this spacecraft (panel modes up to ~3 rad/s) above the round-off
/// floor (~1e-14). Measured: RK4 0.05 → 0.025 s divides the rotational energy drift by 32 and the
/// momentum drift by 32; RK8 0.2 → 0.1 s by 450 and 446.
#[test]
fn validate_conservation_every_integrator() {
    use flexdyn_dynamics::integrator::METHODS;
    const SPAN_S: f64 = 200.0;
    for m in METHODS {
        let (h, min_order) = match m.name {
            "rk4" => (50_000_000u64, 3.8),
            "rk8" => (200_000_000u64, 7.0),
            other => panic!("no conservation steps for integrator {other}: add them"),
        };
        let drift = |step_ns: u64| {
            let mut sc = build(
                reference_hub(),
                GravityModel::PointMass { mu_m3_s2: MU_EARTH },
                reference_pairs(0.0),
                reference_initial(),
                step_ns,
            );
            sc.set_integrator(m);
            let d = run_drift(&mut sc, (SPAN_S * 1e9 / step_ns as f64) as usize);
            eprintln!(
                "{} h = {} s over {SPAN_S} s: {d:?}",
                m.name,
                step_ns as f64 * 1e-9
            );
            d
        };
        let (d1, d2) = (drift(h), drift(h / 2));
        let p_energy = (d1.rot_energy / d2.rot_energy).log2();
        let p_momentum = (d1.rot_ang_mom / d2.rot_ang_mom).log2();
        assert!(
            p_energy >= min_order && p_momentum >= min_order,
            "{}: invariant drift order {p_energy:.2} (energy), {p_momentum:.2} (momentum) < \
             {min_order}",
            m.name
        );
        // The orbit (period ~ 100 min) is integrated far more accurately than the panels.
        assert!(
            d2.orb_energy <= 1e-12 && d2.orb_ang_mom <= 1e-12,
            "{}: orbital drift {d2:?}",
            m.name
        );
        if m.order >= 8 {
            // RK8 at 0.1 s (100 default steps) holds the rotational invariants where RK4 at
            // the same step drifts by 8e-4 (energy).
            d2.assert_rotational(1e-10);
        }
    }
}

/// N-link chains of unequal panels (`reference::unequal_chain`: every mass, inertia, length,
/// hinge offset and stiffness differs along the chain), undamped, on the reference hub, for
/// N = 1, 3 and 5, in free space and in orbit: the same invariants to the same 1e-12 bound as
/// the pairs. Measured: rotational + spring energy within 2.2e-14 (N = 5), momentum about C
/// within 1.3e-14, orbital quantities within 1.4e-14. A wrong term in the chain's hinge rows or
/// hub contributions drifts the energy or the momentum (the N = 2 chain equals the pair to
/// round-off, `panel_chain::tests`).
#[test]
fn validate_conservation_unequal_chains() {
    for n in [1, 3, 5] {
        for gravity in [
            GravityModel::None,
            GravityModel::PointMass { mu_m3_s2: MU_EARTH },
        ] {
            let mut sc = reference_with_chain(gravity, n, 0.0);
            let d = run_drift(&mut sc, TEN_SECONDS_AT_1_MS);
            eprintln!("{n}-link chain, {gravity:?}, 10 s @ 1 ms: {d:?}");
            d.assert_all(1e-12);
            // The tip panel really moved.
            let x = &sc.state().effectors;
            let x0 = unequal_chain(n, 0.0).panels[n - 1].theta_rad;
            assert!(
                (x[2 * n - 2] - x0).abs() > 1e-3,
                "{n}-link chain did not move"
            );
        }
    }
}

/// With hinge damping the chain's energy decreases by the dampers' work ∫ Σ c θ̇_k² dt while
/// the angular momentum about C, which internal torques cannot change, is conserved.
#[test]
fn validate_chain_damping_dissipates_energy_and_conserves_momentum() {
    let (n, c) = (5, 4.0);
    let mut sc = reference_with_chain(GravityModel::None, n, c);
    let c0 = sc.conserved();
    let damper_power = |x: &[f64]| c * x.iter().skip(1).step_by(2).map(|v| v * v).sum::<f64>();
    let mut p_prev = damper_power(&sc.state().effectors);
    let (mut dissipated, mut h_drift) = (0.0, 0.0f64);
    for _ in 0..TEN_SECONDS_AT_1_MS {
        sc.step();
        let p = damper_power(&sc.state().effectors);
        dissipated += 0.5e-3 * (p + p_prev);
        p_prev = p;
        let cq = sc.conserved();
        h_drift = h_drift
            .max((cq.rot_ang_mom_c_n - c0.rot_ang_mom_c_n).norm() / c0.rot_ang_mom_c_n.norm());
    }
    let lost = c0.rot_energy_j - sc.conserved().rot_energy_j;
    eprintln!(
        "damped 5-link chain: lost {lost:e} J, damper work {dissipated:e} J, H drift {h_drift:e}"
    );
    assert!(lost > 1e-3 * c0.rot_energy_j, "{lost:e}");
    assert!(
        ((lost - dissipated) / lost).abs() < 1e-5,
        "{lost:e} vs {dissipated:e}"
    );
    assert!(h_drift <= 1e-12, "{h_drift:e}");
}
