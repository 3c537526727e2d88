//! Independent cross-check of the N-link panel chain against a dense Kane formulation.
//!
//! The library's `PanelChain` folds Kane's hinge rows into a tip-to-hub sweep and an N×N
//! Cholesky solve, then substitutes θ̈ into the hub system (its module doc, C1–C10). This file
//! builds instead the *full* (6 + N)×(6 + N) mass matrix and forcing vector of the hub and the
//! chain body by body, from each body's partial velocities, and solves it with a dense LU —
//! the approach of [`super::validate_dense_kane`] for pairs, written here for a chain from first
//! principles. Only the parameter types and `Spacecraft::derivatives` come from the library; the
//! helpers (DCMs, the body assembler, the error measures) are the pair oracle's.
//!
//! # Kinematics (B components, positions relative to point B)
//! - [S_k B] = M2(θ_k + θ_Hk) [S_k−1 B], [S_0 B] = [H1 B], formed as matrix products (the
//!   library sums the angles instead); ê = ŝ_k2 is the same for every k.
//! - r_H1 given, r_Hk+1 = r_Hk − l_k ŝ_k1, r_k = r_Sck = r_Hk − d_k ŝ_k1.
//! - A hinge rate θ̇_i turns everything outboard of hinge i about the axis through H_i: the
//!   velocity of a point P outboard of H_i, relative to B, is Σ_{i: H_i inboard of P} θ̇_i ê × (r_P − r_Hi).
//!   So the partial velocity of Sc_k for θ̇_i is ê × (r_k − r_Hi) (i ≤ k), its partial angular
//!   velocity ê; r′_k = Σ_{i≤k} θ̇_i ê × (r_k − r_Hi), r′_Hi = Σ_{j<i} θ̇_j ê × (r_Hi − r_Hj),
//!   and with θ̈ = 0, r″_k = Σ_{i≤k} θ̇_i ê × (r′_k − r′_Hi) (ê is fixed in B).
//!   `validate_dense_kane_chain_kinematics_fd` checks all three by finite differences of the
//!   positions alone.
//! - ω_Sk = ω + Ω_k ê with Ω_k = Σ_{i≤k} θ̇_i; the velocity-product part of its angular
//!   acceleration is ω × Ω_k ê.
//!
//! # Forces
//! Hinge k puts τ_k ê on panel k and −τ_k ê on the body inboard (panel k − 1, or the hub), with
//! τ_k = −k_k θ_k − c_k θ̇_k + u_k; gravity acts as a uniform field at the system CoM; the
//! external force acts at B, the external torque on the hub. The generalized forces come out of
//! the projection by the partial velocities, not written in by hand.

use super::validate_dense_kane::{
    add_hub, axis, backward_error, dcm_bn_from_mrp, dense_solve, inf_norm, median, random_config,
    random_panel, rel_err, rot2, set_block, set_col, skeel_cond, skew, spacecraft_of, Assembler,
    Body, Config, Dense, Ranges, Rng, M3, ROUNDOFF_FACTOR, V3,
};
use flexdyn_dynamics::effectors::panel_chain::{ChainPanelParams, PanelChain, PanelChainParams};
use flexdyn_dynamics::{Spacecraft, State};
use nalgebra::{DMatrix, DVector};

/// A hub (with its force, torque and gravity from the pair oracle's generator) and one chain.
struct ChainCase {
    base: Config,
    chain: PanelChainParams,
    /// \[N·m\] the commanded hinge motor torques.
    u: Vec<f64>,
}

fn random_chain_case(rng: &mut Rng, n: usize, gravity: bool) -> ChainCase {
    let base = random_config(rng, 0, gravity, Ranges::Plausible);
    let panels = (0..n)
        .map(|_| {
            let l = rng.range(0.3, 3.0);
            let p = random_panel(rng, l, Ranges::Plausible);
            ChainPanelParams {
                mass_kg: p.mass_kg,
                inertia_s_kg_m2: p.inertia_s_kg_m2,
                d_m: l * rng.range(0.05, 1.0),
                l_m: l,
                k_nm_rad: p.k_nm_rad,
                c_nm_s_rad: p.c_nm_s_rad,
                theta_h_rad: if rng.unit() < 0.5 {
                    0.0
                } else {
                    rng.range(-std::f64::consts::PI, std::f64::consts::PI)
                },
                motor_torque_nm: 0.0,
                theta_rad: 0.0,
                theta_dot_rad_s: 0.0,
            }
        })
        .collect();
    ChainCase {
        base,
        chain: PanelChainParams {
            name: "chain".into(),
            r_h1b_b_m: rng.vec(2.5),
            dcm_h1b: rng.rotation(),
            panels,
        },
        u: (0..n).map(|_| rng.range(-20.0, 20.0)).collect(),
    }
}

/// A random state: hub attitude, rate and orbit, hinge angles within ±1.5 rad and rates within
/// ±1 rad/s.
fn random_state(rng: &mut Rng, n: usize) -> State {
    let dir = rng.vec(1.0).normalize();
    State {
        r_bn_n: dir * rng.range(6.8e6, 4.2e7),
        v_bn_n: rng.vec(7.5e3),
        sigma_bn: rng.vec(0.5),
        omega_bn_b: rng.vec(0.5),
        effectors: (0..n)
            .flat_map(|_| [rng.range(-1.5, 1.5), rng.range(-1.0, 1.0)])
            .collect(),
    }
}

/// The chain's geometry at hinge angles θ: per panel its DCM [S_k B] and CoM, and the hinge
/// points H_1 … H_N.
struct ChainGeom {
    dcm_sb: Vec<M3>,
    r_sc: Vec<V3>,
    r_h: Vec<V3>,
}

fn chain_geom(p: &PanelChainParams, theta: &[f64]) -> ChainGeom {
    let mut g = ChainGeom {
        dcm_sb: Vec::new(),
        r_sc: Vec::new(),
        r_h: Vec::new(),
    };
    let mut dcm_prev = p.dcm_h1b;
    let mut r_h = p.r_h1b_b_m;
    for (panel, th) in p.panels.iter().zip(theta) {
        let dcm = rot2(th + panel.theta_h_rad) * dcm_prev;
        let s1 = axis(&dcm, 0);
        g.dcm_sb.push(dcm);
        g.r_sc.push(r_h - s1 * panel.d_m);
        g.r_h.push(r_h);
        r_h -= s1 * panel.l_m;
        dcm_prev = dcm;
    }
    g
}

/// r′_k, r′_Hk and r″_k (θ̈ = 0) from the hinge-axis rule of the module docs.
fn chain_rates(g: &ChainGeom, e: &V3, theta_dot: &[f64]) -> (Vec<V3>, Vec<V3>, Vec<V3>) {
    let n = theta_dot.len();
    let r_h_prime: Vec<V3> = (0..n)
        .map(|i| {
            (0..i)
                .map(|j| e.cross(&(g.r_h[i] - g.r_h[j])) * theta_dot[j])
                .sum()
        })
        .collect();
    let r_prime: Vec<V3> = (0..n)
        .map(|k| {
            (0..=k)
                .map(|i| e.cross(&(g.r_sc[k] - g.r_h[i])) * theta_dot[i])
                .sum()
        })
        .collect();
    let r_pp: Vec<V3> = (0..n)
        .map(|k| {
            (0..=k)
                .map(|i| e.cross(&(r_prime[k] - r_h_prime[i])) * theta_dot[i])
                .sum()
        })
        .collect();
    (r_prime, r_h_prime, r_pp)
}

/// The dense Kane system M q̈ = f, q̈ = [a_B (B); ω̇; θ̈_1 … θ̈_N].
fn dense_kane_chain(case: &ChainCase, x: &State) -> Dense {
    let (cfg, p) = (&case.base, &case.chain);
    let nl = p.panels.len();
    let n = 6 + nl;
    let w = x.omega_bn_b;
    let hub = &cfg.hub;
    let theta: Vec<f64> = x.effectors.iter().step_by(2).copied().collect();
    let theta_dot: Vec<f64> = x.effectors.iter().skip(1).step_by(2).copied().collect();
    let g = chain_geom(p, &theta);
    let e = axis(&p.dcm_h1b, 1);
    let (r_prime, _, r_pp) = chain_rates(&g, &e, &theta_dot);

    let mut m_sc = hub.mass_kg;
    let mut first = hub.r_bcb_b_m * hub.mass_kg;
    for (panel, r) in p.panels.iter().zip(&g.r_sc) {
        m_sc += panel.mass_kg;
        first += r * panel.mass_kg;
    }
    let dcm_bn = dcm_bn_from_mrp(&x.sigma_bn);
    let g_b = match cfg.mu {
        None => V3::zeros(),
        Some(mu) => {
            let r_cn_n = x.r_bn_n + dcm_bn.transpose() * (first / m_sc);
            dcm_bn * (-r_cn_n * (mu / r_cn_n.norm().powi(3)))
        }
    };
    let tau: Vec<f64> = p
        .panels
        .iter()
        .enumerate()
        .map(|(k, q)| -q.k_nm_rad * theta[k] - q.c_nm_s_rad * theta_dot[k] + case.u[k])
        .collect();

    let mut asm = Assembler {
        m: DMatrix::zeros(n, n),
        f: DVector::zeros(n),
    };
    for k in 0..3 {
        asm.f[k] += cfg.force_b[k];
    }
    add_hub(&mut asm, hub, &w, &g_b, &(cfg.torque_b - e * tau[0]));
    // Panels.
    let mut rate = 0.0;
    for k in 0..nl {
        let q = &p.panels[k];
        rate += theta_dot[k];
        let dcm = &g.dcm_sb[k];
        let i_c = dcm.transpose() * M3::from_diagonal(&q.inertia_s_kg_m2) * dcm;
        let mut v = DMatrix::zeros(3, n);
        let mut wm = DMatrix::zeros(3, n);
        set_block(&mut v, 0, &M3::identity());
        set_block(&mut v, 3, &(-skew(&g.r_sc[k])));
        set_block(&mut wm, 3, &M3::identity());
        for i in 0..=k {
            set_col(&mut v, 6 + i, &e.cross(&(g.r_sc[k] - g.r_h[i])));
            set_col(&mut wm, 6 + i, &e);
        }
        let tau_out = if k + 1 < nl { tau[k + 1] } else { 0.0 };
        asm.add(&Body {
            mass: q.mass_kg,
            i_c,
            v: &v,
            w: &wm,
            a_vp: w.cross(&w.cross(&g.r_sc[k])) + w.cross(&r_prime[k]) * 2.0 + r_pp[k],
            omega: w + e * rate,
            alpha_vp: w.cross(&(e * rate)),
            force: g_b * q.mass_kg,
            torque: e * (tau[k] - tau_out),
            gyroscopic: None,
        });
    }
    Dense {
        m: asm.m,
        f: asm.f,
        g_b,
    }
}

fn build_library(case: &ChainCase) -> Spacecraft {
    let chain = PanelChain::new(case.chain.clone(), "panel_chains[0]").expect("valid chain");
    let mut sc = spacecraft_of(&case.base, vec![Box::new(chain)], 1_000_000);
    sc.set_effector_inputs(&case.u)
        .expect("one input per hinge");
    sc
}

/// The library's [a_B (B); ω̇; θ̈…] at `x`.
fn library_accel(sc: &mut Spacecraft, x: &State) -> DVector<f64> {
    let mut dx = x.clone();
    sc.derivatives(x, &mut dx);
    let nl = x.effectors.len() / 2;
    let mut q = DVector::zeros(6 + nl);
    q.fixed_rows_mut::<3>(0)
        .copy_from(&(dcm_bn_from_mrp(&x.sigma_bn) * dx.v_bn_n));
    q.fixed_rows_mut::<3>(3).copy_from(&dx.omega_bn_b);
    for k in 0..nl {
        assert_eq!(
            dx.effectors[2 * k],
            x.effectors[2 * k + 1],
            "θ̇ is the state"
        );
        q[6 + k] = dx.effectors[2 * k + 1];
    }
    q
}

/// The oracle's kinematics (partial velocities, r′ and r″ of every CoM, by the hinge-axis
/// rule) checked by central finite differences of the positions along θ(t) = θ + θ̇ t.
#[test]
fn validate_dense_kane_chain_kinematics_fd() {
    let mut rng = Rng::new(0xC4A1_F1D0);
    let mut worst = 0.0_f64;
    for _ in 0..100 {
        let n = 1 + (rng.unit() * 6.0) as usize;
        let case = random_chain_case(&mut rng, n, false);
        let p = &case.chain;
        let e = axis(&p.dcm_h1b, 1);
        let theta: Vec<f64> = (0..n).map(|_| rng.range(-1.5, 1.5)).collect();
        let theta_dot: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
        let at = |t: f64| {
            let th: Vec<f64> = theta
                .iter()
                .zip(&theta_dot)
                .map(|(a, b)| a + b * t)
                .collect();
            chain_geom(p, &th)
        };
        let g0 = at(0.0);
        let (r_prime, _, r_pp) = chain_rates(&g0, &e, &theta_dot);
        let scale: f64 = p.panels.iter().map(|q| q.l_m).sum();
        let h = 1e-3;
        let (gp, gm) = (at(h), at(-h));
        for k in 0..n {
            let fd1 = (gp.r_sc[k] - gm.r_sc[k]) / (2.0 * h);
            let fd2 = (gp.r_sc[k] - g0.r_sc[k] * 2.0 + gm.r_sc[k]) / (h * h);
            worst = worst.max((fd1 - r_prime[k]).norm() / scale);
            worst = worst.max((fd2 - r_pp[k]).norm() / scale);
            // Each partial velocity alone: θ_i moved, the others held.
            for i in 0..=k {
                let mut tp = theta.clone();
                let mut tm = theta.clone();
                tp[i] += h;
                tm[i] -= h;
                let fd = (chain_geom(p, &tp).r_sc[k] - chain_geom(p, &tm).r_sc[k]) / (2.0 * h);
                let pv = e.cross(&(g0.r_sc[k] - g0.r_h[i]));
                worst = worst.max((fd - pv).norm() / scale);
            }
            // ê is every panel's second axis.
            assert!((axis(&g0.dcm_sb[k], 1) - e).norm() < 1e-14);
        }
    }
    eprintln!(
        "chain kinematics vs finite differences: worst {worst:e} (relative to the chain length)"
    );
    assert!(worst < 1e-5, "{worst:e}");
}

/// The library's chain against the dense Kane oracle for N = 3 and N = 5 unequal panels, at
/// random states, with external force and torque, motor inputs, damping and (in half the
/// cases) point-mass gravity: 1000 states each. Asserted: relative error ≤ 1e-12 or within the
/// pair oracle's round-off envelope 32 κ_S eps, and backward error ≤ 1e-14. Measured: N = 3 max
/// 1.7e-13 (median 1.3e-15), N = 5 max 1.0e-11 (median 6.5e-15) at most 2.6 κ_S eps; backward
/// error ≤ 3.1e-16 for both.
#[test]
fn validate_dense_kane_chain_matches_library() {
    let mut rng = Rng::new(0xC4A1_0005);
    for n in [3, 5] {
        let (mut errs, mut worst_bw, mut worst_ratio, mut count) =
            (Vec::new(), 0.0_f64, 0.0_f64, 0);
        for case_i in 0..40 {
            let case = random_chain_case(&mut rng, n, case_i % 2 == 1);
            let mut sc = build_library(&case);
            for _ in 0..25 {
                let x = random_state(&mut rng, n);
                let d = dense_kane_chain(&case, &x);
                let q_dense = dense_solve(&d);
                let q_lib = library_accel(&mut sc, &x);
                let err = rel_err(&q_lib, &q_dense);
                let kappa_s = skeel_cond(&d, &q_dense);
                let bw = backward_error(&d, &q_lib);
                assert!(
                    err <= 1e-12_f64.max(ROUNDOFF_FACTOR * kappa_s * f64::EPSILON),
                    "N = {n}: rel err {err:e} (κ_S {kappa_s:e})"
                );
                assert!(bw <= 1e-14, "N = {n}: backward error {bw:e}");
                worst_bw = worst_bw.max(bw);
                worst_ratio = worst_ratio.max(err / (kappa_s * f64::EPSILON));
                assert!(inf_norm(&q_dense) > 0.0);
                errs.push(err);
                count += 1;
            }
        }
        let max = errs.iter().fold(0.0_f64, |a, b| a.max(*b));
        eprintln!(
            "dense Kane vs library, {n}-link chains, {count} states: max rel err {max:.3e}, \
             median {:.3e}, max err/(κ_S eps) {worst_ratio:.2}, max backward error {worst_bw:.2e}",
            median(&mut errs)
        );
    }
}

/// The comparison fails when the oracle is wrong: the last panel's mass perturbed by 1e-6 in
/// the oracle moves the answer far beyond the tolerance, so the tolerance is meaningful.
#[test]
fn validate_dense_kane_chain_negative_control() {
    let mut rng = Rng::new(0xBAD_C4A1);
    let case = random_chain_case(&mut rng, 3, false);
    let mut sc = build_library(&case);
    let mut wrong = ChainCase {
        base: case.base.clone(),
        chain: case.chain.clone(),
        u: case.u.clone(),
    };
    wrong.chain.panels[2].mass_kg *= 1.0 + 1e-6;
    let x = random_state(&mut rng, 3);
    let q_lib = library_accel(&mut sc, &x);
    let d = dense_kane_chain(&wrong, &x);
    let err = rel_err(&q_lib, &dense_solve(&d));
    eprintln!("negative control (m3 × (1 + 1e-6)): rel err {err:e}");
    assert!(err > 1e-9, "{err:e}");
}
