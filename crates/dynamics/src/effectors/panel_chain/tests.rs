//! The chain's own checks: the N = 2 chain against today's [`PanelPair`] (derivatives at random
//! states and a propagated trajectory), the name tables, and the validation paths. The
//! conservation laws and the dense Kane oracle are in `crates/dynamics/tests/`.

use nalgebra::Vector3;

use super::*;
use crate::effectors::panel_pair::{PanelPair, PanelPairInitial, PanelPairParams};
use crate::reference::{reference_hub, reference_initial, reference_pairs, unequal_chain};
use crate::{GravityModel, Spacecraft, State};

/// The reference wings, made unequal and folded, with motor torques: every pair parameter the
/// chain must reproduce is exercised.
fn unequal_pairs() -> Vec<(PanelPairParams, PanelPairInitial)> {
    let mut pairs = reference_pairs(0.0);
    for (i, (p, init)) in pairs.iter_mut().enumerate() {
        let s = 1.0 + 0.3 * i as f64;
        p.panel1.mass_kg = 45.0 * s;
        p.panel2.mass_kg = 28.0 / s;
        p.panel1.inertia_s_kg_m2 = Vector3::new(40.0, 22.0, 19.0) * s;
        p.panel2.inertia_s_kg_m2 = Vector3::new(21.0, 9.0, 13.0) / s;
        p.panel1.d_m = 0.7;
        p.panel2.d_m = 0.55 * s;
        p.l1_m = 1.6;
        p.panel1.k_nm_rad = 140.0;
        p.panel2.k_nm_rad = 60.0 * s;
        p.panel1.c_nm_s_rad = 3.0;
        p.panel2.c_nm_s_rad = 1.5 * s;
        p.theta_h2s1_rad = 0.4 - 0.9 * i as f64;
        p.motor_torque_nm = [0.7 * s, -0.3];
        init.theta1_dot_rad_s = 0.03 * s;
        init.theta2_dot_rad_s = -0.05;
    }
    pairs
}

/// The same spacecraft twice: with the pairs, and with each pair as a two-panel chain.
fn pair_and_chain(gravity: GravityModel) -> (Spacecraft, Spacecraft) {
    let pairs = unequal_pairs();
    let mut with_pairs: Vec<Box<dyn StateEffector>> = Vec::new();
    let mut with_chains: Vec<Box<dyn StateEffector>> = Vec::new();
    for (i, (p, init)) in pairs.iter().enumerate() {
        let path = format!("[{i}]");
        with_pairs.push(Box::new(PanelPair::new(p.clone(), *init, &path).unwrap()));
        let chain = PanelChainParams::from_pair(p, init);
        with_chains.push(Box::new(PanelChain::new(chain, &path).unwrap()));
    }
    let build = |effectors| {
        Spacecraft::new(
            reference_hub(),
            gravity,
            effectors,
            reference_initial(),
            1_000_000,
        )
        .unwrap()
    };
    (build(with_pairs), build(with_chains))
}

/// Largest |a − b| / max(|b|, floor) over the state derivative's components.
fn max_rel_diff(a: &State, b: &State) -> f64 {
    let va: Vec<f64> = flatten(a);
    let vb: Vec<f64> = flatten(b);
    let scale = vb.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    va.iter()
        .zip(&vb)
        .map(|(x, y)| (x - y).abs() / scale)
        .fold(0.0, f64::max)
}

fn flatten(s: &State) -> Vec<f64> {
    let mut v: Vec<f64> = s
        .r_bn_n
        .iter()
        .chain(s.v_bn_n.iter())
        .chain(s.sigma_bn.iter())
        .chain(s.omega_bn_b.iter())
        .copied()
        .collect();
    v.extend_from_slice(&s.effectors);
    v
}

/// A 64-bit LCG in [−1, 1): enough spread for random states, no dependency.
fn uniform(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// The N = 2 chain equals the pair to round-off, not bit for bit: the chain forms Kane's
/// symmetric rows and solves them by Cholesky, the pair the paper's Newtonian rows by Cramer's
/// rule, so the same sums are rounded in a different order. Over 1000 random states (hinge
/// angles ±1.5 rad, rates ±1 rad/s, ω ±0.5 rad/s, point-mass gravity) the measured largest
/// difference, relative to the largest derivative component of the wings' rates and the hub's
/// accelerations, is below 1e-14; the bound asserted is 1e-13.
#[test]
fn two_link_chain_matches_the_pair_at_random_states() {
    let (mut sc_pair, mut sc_chain) = pair_and_chain(GravityModel::PointMass {
        mu_m3_s2: crate::reference::MU_EARTH,
    });
    let mut seed = 0x5eed_u64;
    let mut worst = 0.0_f64;
    let mut bit_equal = 0;
    for _ in 0..1000 {
        let mut x = sc_pair.state().clone();
        for v in x.effectors.iter_mut().step_by(2) {
            *v = 1.5 * uniform(&mut seed);
        }
        for v in x.effectors.iter_mut().skip(1).step_by(2) {
            *v = uniform(&mut seed);
        }
        x.omega_bn_b =
            Vector3::new(uniform(&mut seed), uniform(&mut seed), uniform(&mut seed)) * 0.5;
        let (mut dx_pair, mut dx_chain) = (x.clone(), x.clone());
        sc_pair.derivatives(&x, &mut dx_pair);
        sc_chain.derivatives(&x, &mut dx_chain);
        // Only the accelerations: the rest (ṙ, σ̇, θ̇) are copies of the state.
        let rel = max_rel_diff(
            &State {
                r_bn_n: Vector3::zeros(),
                sigma_bn: Vector3::zeros(),
                ..dx_chain.clone()
            },
            &State {
                r_bn_n: Vector3::zeros(),
                sigma_bn: Vector3::zeros(),
                ..dx_pair.clone()
            },
        );
        bit_equal += usize::from(flatten(&dx_pair) == flatten(&dx_chain));
        worst = worst.max(rel);
    }
    eprintln!("N = 2 chain vs pair: max relative derivative difference {worst:e}, bit-equal in {bit_equal} of 1000");
    assert!(worst < 1e-13, "{worst:e}");
}

/// The same over a propagated trajectory: 20 s at 1 ms under point-mass gravity, with damping
/// and motor torques. The measured largest hinge-angle difference is ~1e-15 rad of angles of
/// order 0.1 rad and the hub's ω agrees to ~1e-16 rad/s; the bounds asserted are 1e-12.
#[test]
fn two_link_chain_matches_the_pair_over_a_trajectory() {
    let (mut sc_pair, mut sc_chain) = pair_and_chain(GravityModel::PointMass {
        mu_m3_s2: crate::reference::MU_EARTH,
    });
    let (mut d_theta, mut d_omega, mut d_r) = (0.0_f64, 0.0_f64, 0.0_f64);
    for _ in 0..20_000 {
        sc_pair.step();
        sc_chain.step();
        let (a, b) = (sc_pair.state(), sc_chain.state());
        for (x, y) in a.effectors.iter().zip(&b.effectors) {
            d_theta = d_theta.max((x - y).abs());
        }
        d_omega = d_omega.max((a.omega_bn_b - b.omega_bn_b).norm());
        d_r = d_r.max((a.r_bn_n - b.r_bn_n).norm());
    }
    let theta = sc_pair.state().effectors[0];
    eprintln!(
        "N = 2 chain vs pair over 20 s: |Δθ| ≤ {d_theta:e} (θ1 ends at {theta:.4} rad), \
         |Δω| ≤ {d_omega:e} rad/s, |Δr| ≤ {d_r:e} m"
    );
    assert!(d_theta < 1e-12, "{d_theta:e}");
    assert!(d_omega < 1e-12, "{d_omega:e}");
    assert!(d_r < 1e-6, "{d_r:e}");
}

#[test]
fn names_are_sliced_by_panel_count() {
    for n in 1..=MAX_LINKS {
        let mut p = unequal_chain(1, 0.0);
        p.panels = (0..n).map(|_| p.panels[0].clone()).collect();
        for q in &mut p.panels {
            q.l_m = 1.5;
        }
        let c = PanelChain::new(p, "c").unwrap();
        assert_eq!(c.state_len(), 2 * n);
        assert_eq!(c.state_names().len(), 2 * n);
        assert_eq!(c.input_names().len(), n);
        assert_eq!(c.state_names()[2 * n - 2], format!("theta_{n}"));
        assert_eq!(c.state_names()[2 * n - 1], format!("theta_dot_{n}"));
        assert_eq!(c.input_names()[n - 1], format!("motor_torque_{n}_nm"));
    }
    let names = kind::COMPONENT.wire_names;
    assert_eq!(names(6, 0).unwrap().0, &STATE_NAMES[..6]);
    assert!(names(5, 0).is_none());
    assert!(names(0, 0).is_none());
    assert!(names(4, 1).is_none());
}

#[test]
fn validation_names_the_panel_and_field() {
    let mut p = unequal_chain(3, 0.0);
    p.panels[2].mass_kg = -1.0;
    let e = PanelChain::new(p, "panel_chains[0]")
        .unwrap_err()
        .to_string();
    assert!(e.contains("panel_chains[0].panels[2].mass_kg"), "{e}");

    let mut p = unequal_chain(3, 0.0);
    p.panels[1].d_m = 2.0;
    let e = PanelChain::new(p, "panel_chains[0]")
        .unwrap_err()
        .to_string();
    assert!(e.contains("panel_chains[0].panels[1].d_m"), "{e}");

    let mut p = unequal_chain(3, 0.0);
    p.panels.clear();
    let e = PanelChain::new(p, "panel_chains[1]")
        .unwrap_err()
        .to_string();
    assert!(e.contains("panel_chains[1].panels"), "{e}");

    // The last panel needs no length; the others do.
    let mut p = unequal_chain(3, 0.0);
    p.panels[2].l_m = 0.0;
    assert!(PanelChain::new(p.clone(), "c").is_ok());
    p.panels[1].l_m = 0.0;
    let e = PanelChain::new(p, "c").unwrap_err().to_string();
    assert!(e.contains("c.panels[1].l_m"), "{e}");
}

/// Motor torques are inputs, and a motor torque u_N on the last hinge alone moves the chain's
/// equilibrium to θ_N = u_N / k_N (the others at 0): there every acceleration vanishes, and
/// without the torque the last panel accelerates back.
#[test]
fn motor_inputs_are_commanded_torques() {
    let p = unequal_chain(3, 5.0);
    let k3 = p.panels[2].k_nm_rad;
    let chain = PanelChain::new(p, "c").unwrap();
    let mut initial = reference_initial();
    initial.omega_bn_b_rad_s = Vector3::zeros();
    let mut sc = Spacecraft::new(
        reference_hub(),
        GravityModel::None,
        vec![Box::new(chain)],
        initial,
        1_000_000,
    )
    .unwrap();
    let mut x = sc.state().clone();
    x.effectors = vec![0.0, 0.0, 0.0, 0.0, 2.0 / k3, 0.0];
    let mut dx = x.clone();
    sc.set_effector_inputs(&[0.0, 0.0, 2.0]).unwrap();
    sc.derivatives(&x, &mut dx);
    let worst = dx.effectors.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(worst < 1e-15, "{:?}", dx.effectors);
    assert!(dx.omega_bn_b.norm() < 1e-15, "{:?}", dx.omega_bn_b);
    sc.set_effector_inputs(&[0.0, 0.0, 0.0]).unwrap();
    sc.derivatives(&x, &mut dx);
    assert!(dx.effectors[5] < -1e-3, "{:?}", dx.effectors);
}
