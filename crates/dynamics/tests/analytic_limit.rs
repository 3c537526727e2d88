//! Analytic limit: with a hub so massive it is effectively fixed, a pair is a 2-DOF chain whose
//! small-angle frequencies solve the linearised eigenproblem det(K − ω² M) = 0.
//!
//! Derivation (hub fixed, ω_B/N = 0, θ small, φ0 = θ_H2S1):
//! - panel 1: CoM velocity d1 θ̇1 ŝ13, angular velocity θ̇1 ŝ12;
//! - panel 2: CoM velocity l1 θ̇1 ŝ13 + d2 (θ̇1 + θ̇2) ŝ23, angular velocity (θ̇1 + θ̇2) ŝ12;
//! - T = ½ (I1₂ + m1 d1²) θ̇1² + ½ I2₂ (θ̇1 + θ̇2)² + ½ m2 |l1 θ̇1 ŝ13 + d2 (θ̇1 + θ̇2) ŝ23|²,
//!   with ŝ13·ŝ23 = cos(θ2 + φ0) → cos φ0 at θ = 0;
//! - V = ½ k1 θ1² + ½ k2 θ2².
//!
//! So M = [[I1₂ + m1 d1² + I2₂ + m2 (l1² + d2² + 2 l1 d2 cos φ0), I2₂ + m2 (d2² + l1 d2 cos φ0)],
//!         [I2₂ + m2 (d2² + l1 d2 cos φ0),                         I2₂ + m2 d2²]],  K = diag(k1, k2).
//!
//! The simulation starts in one pure mode (θ(0) ∝ its eigenvector, θ̇(0) = 0, amplitude 1e-5 rad so
//! the nonlinear frequency shift is ~1e-10) and the frequency is measured from the zero crossings
//! of θ1 over many periods.

use crate::common;

use common::*;
use flexdyn_dynamics::{
    GravityModel, HubInitial, HubParams, InitialTranslation, PanelPairInitial, PanelPairParams,
};
use nalgebra::{Matrix3, Vector3};

/// (ω_low, ω_high) [rad/s] and their eigenvectors, from det(K − λM) = 0:
/// det(M) λ² − (k1 M22 + k2 M11) λ + k1 k2 = 0; eigenvector (λ M12, k1 − λ M11).
fn linearised_modes(p: &PanelPairParams) -> [(f64, [f64; 2]); 2] {
    let (m1, m2) = (p.panel1.mass_kg, p.panel2.mass_kg);
    let (d1, d2, l1) = (p.panel1.d_m, p.panel2.d_m, p.l1_m);
    let (i1, i2) = (p.panel1.inertia_s_kg_m2.y, p.panel2.inertia_s_kg_m2.y);
    let (k1, k2) = (p.panel1.k_nm_rad, p.panel2.k_nm_rad);
    let cphi = p.theta_h2s1_rad.cos();
    let m11 = i1 + m1 * d1 * d1 + i2 + m2 * (l1 * l1 + d2 * d2 + 2.0 * l1 * d2 * cphi);
    let m12 = i2 + m2 * (d2 * d2 + l1 * d2 * cphi);
    let m22 = i2 + m2 * d2 * d2;
    let det = m11 * m22 - m12 * m12;
    let b = k1 * m22 + k2 * m11;
    let disc = (b * b - 4.0 * det * k1 * k2).sqrt();
    let mode = |lambda: f64| (lambda.sqrt(), [lambda * m12, k1 - lambda * m11]);
    [
        mode((b - disc) / (2.0 * det)),
        mode((b + disc) / (2.0 * det)),
    ]
}

/// Frequency [rad/s] of θ1 measured from its zero crossings (linear interpolation between steps).
fn measured_frequency(pair: PanelPairParams, mode: [f64; 2], duration_s: f64) -> f64 {
    let scale = 1e-5 / mode[0].abs().max(mode[1].abs());
    let init = PanelPairInitial {
        theta1_rad: mode[0] * scale,
        theta1_dot_rad_s: 0.0,
        theta2_rad: mode[1] * scale,
        theta2_dot_rad_s: 0.0,
    };
    let hub = HubParams {
        mass_kg: 1e13,
        inertia_bc_b_kg_m2: Matrix3::from_diagonal_element(1e13),
        r_bcb_b_m: Vector3::zeros(),
    };
    let initial = HubInitial {
        translation: InitialTranslation::PointB {
            r_bn_n_m: Vector3::zeros(),
            v_bn_n_m_s: Vector3::zeros(),
        },
        sigma_bn: Vector3::zeros(),
        omega_bn_b_rad_s: Vector3::zeros(),
    };
    let step_s = 1e-3;
    let mut sc = build(
        hub,
        GravityModel::None,
        vec![(pair, init)],
        initial,
        1_000_000,
    );
    let mut crossings = Vec::new();
    let mut prev = sc.state().effectors[0];
    let n = (duration_s / step_s) as usize;
    for k in 1..=n {
        sc.step();
        let th = sc.state().effectors[0];
        if (prev < 0.0) != (th < 0.0) {
            crossings.push((k as f64 - 1.0 + prev / (prev - th)) * step_s);
        }
        prev = th;
    }
    assert!(
        crossings.len() >= 6,
        "only {} zero crossings",
        crossings.len()
    );
    std::f64::consts::PI * (crossings.len() - 1) as f64 / (crossings.last().unwrap() - crossings[0])
}

fn check_pair(pair: PanelPairParams, label: &str) {
    for (i, (omega, mode)) in linearised_modes(&pair).into_iter().enumerate() {
        let periods = 12.0;
        let measured = measured_frequency(
            pair.clone(),
            mode,
            periods * 2.0 * std::f64::consts::PI / omega,
        );
        let rel = (measured - omega).abs() / omega;
        eprintln!("{label} mode {i}: analytic {omega:.9} rad/s, simulated {measured:.9} rad/s, rel err {rel:.2e}");
        assert!(
            rel <= 1e-4,
            "{label} mode {i}: analytic {omega} vs simulated {measured} (rel {rel:e})"
        );
    }
}

#[test]
fn validate_fixed_hub_frequencies_reference_pair() {
    check_pair(reference_pairs(0.0).remove(0).0, "reference pair");
}

#[test]
fn validate_fixed_hub_frequencies_folded_unequal_pair() {
    // Folded outer panel (θ_H2S1 = 0.7 rad), unequal panels and springs, a rotated hinge frame.
    let mut p = reference_pairs(0.0).remove(1).0;
    p.theta_h2s1_rad = 0.7;
    p.l1_m = 2.0;
    p.panel1.d_m = 1.1;
    p.panel1.k_nm_rad = 300.0;
    p.panel2.mass_kg = 20.0;
    p.panel2.inertia_s_kg_m2 = Vector3::new(12.0, 7.0, 6.0);
    p.panel2.d_m = 0.4;
    p.panel2.k_nm_rad = 40.0;
    let a = 0.4f64;
    p.dcm_h1b = Matrix3::new(a.cos(), 0.0, -a.sin(), 0.0, 1.0, 0.0, a.sin(), 0.0, a.cos())
        * Matrix3::new(0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    check_pair(p, "folded pair");
}
