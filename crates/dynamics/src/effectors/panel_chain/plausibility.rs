//! Panel-chain values that are legal but almost surely a mistake
//! ([`flexdyn_kernel::schema::plausible`]): warnings, never errors. Two kinds:
//!
//! - **Angles in degrees.** `theta_h_rad` and `theta_rad` are radians; a hinge angle of more
//!   than a turn (|θ| > 2π) is legal (it wraps) but is what 90° or 180° typed as radians gives
//!   (`theta_h_rad = 180` for a panel folded back over the one before it, which the book writes
//!   as π). The warning names the value in degrees.
//! - **A hinge mode the step cannot follow.** The fixed-step integrator samples the chain's
//!   fastest hinge mode, of angular frequency ω_max, every h = `step_s`. Classical RK4 on
//!   ẍ = −ω² x multiplies each step by R(iωh), R(z) = 1 + z + z²/2 + z³/6 + z⁴/24, so with
//!   x = ωh, |R|² = 1 − x⁶/72 + x⁸/576: the mode is damped by the integrator alone, and it grows
//!   (|R| > 1) once x⁸/576 > x⁶/72, i.e. x > 2√2 ≈ 2.83 — below the Nyquist limit x = π of the
//!   sampling itself. At x = 1 (2π ≈ 6.3 steps a period) |R| = √(1 − 1/72 + 1/576) = 0.99390,
//!   and over the 2π/x steps of a period the amplitude falls to 0.99390^(2π) = 0.962: the
//!   integrator removes 3.8 % of the mode a period, more than a typical structural damping
//!   ratio of 0.5 % (a free decay of e^(−2πζ) = 3.1 % a period) puts in. So a chain warns when
//!   **ω_max h > 1**, and says whether RK4 diverges (ω_max h > 2√2). The higher-order methods
//!   are more accurate below the limit but need the same resolution to mean anything.
//!
//! # The fastest hinge mode
//! The hinge modes are those of the chain on a free hub, linearised at the configured initial
//! angles: the generalised speeds u = (ṙ_B, ω, θ̇_1 … θ̇_N), the mass matrix
//! \[M\] = Σ_bodies (m J_vᵀ J_v + J_ωᵀ \[I_c\] J_ω) of the hub and the panels, with the rows of
//! each body's centre-of-mass velocity and angular velocity (panel_chain/mod.rs, (C1)–(C5)):
//! - hub: v = ṙ_B − [r̃_BcB] ω, ω_hub = ω;
//! - panel k: v = ṙ_B − [r̃_Sck] ω + Σ_{i≤k} p_ik θ̇_i, p_ik = ê × (r_Sck − r_Hi);
//!   ω_k = ω + Σ_{i≤k} θ̇_i ê, and \[I_c\] = Σ_j I_kj ŝ_kj ŝ_kjᵀ in B.
//!
//! The hub's six speeds carry no stiffness, so they are eliminated (a free hub takes whatever
//! motion keeps the momenta zero): \[M_eff\] = \[M_θθ\] − \[M_hθ\]ᵀ \[M_hh\]⁻¹ \[M_hθ\], and the hinge
//! modes are \[K\] v = ω² \[M_eff\] v with \[K\] = diag(k_i). With \[M_eff\] = L Lᵀ, ω_max² is the
//! largest eigenvalue of L⁻¹ \[K\] L⁻ᵀ. A light hub raises ω_max (the hub recoils, so less inertia
//! resists the hinge): this is where the ratio of panel to hub mass enters. The other bodies
//! of the vehicle are left out: held rigid they only add inertia to the hub, so ω_max here is
//! at or above the vehicle's.
//! The warning names the hinge that stores most of the mode's elastic energy (k_i v_i²).

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::PanelChainParams;
use crate::params::HubParams;
use flexdyn_kernel::numfmt::{Num, Rounded};
use flexdyn_kernel::schema::plausible::{Implausible, DEG};

/// \[-\] ω_max h above which a hinge mode is warned about (module docs: 3.8 % a period).
pub const MAX_OMEGA_STEP: f64 = 1.0;

/// \[-\] ω h above which classical RK4 grows an undamped mode: 2√2.
pub const RK4_UNSTABLE_OMEGA_STEP: f64 = 2.0 * std::f64::consts::SQRT_2;

/// The implausible values of `chain` (at `path`, e.g. `panel_chains[0]`) on `hub`, integrated
/// with a step of `step_s`.
pub fn check(
    chain: &PanelChainParams,
    path: &str,
    hub: &HubParams,
    step_s: f64,
    out: &mut Vec<Implausible>,
) {
    for (k, p) in chain.panels.iter().enumerate() {
        for (key, value) in [("theta_h_rad", p.theta_h_rad), ("theta_rad", p.theta_rad)] {
            if value.abs() > std::f64::consts::TAU {
                out.push(Implausible {
                    field: format!("{path}.panels[{k}].{key}"),
                    message: format!(
                        "{} rad is more than a turn of a hinge; is it in deg? {} deg = {} rad",
                        Num(value),
                        Num(value),
                        Rounded(value * DEG, 5)
                    ),
                });
            }
        }
    }
    let Some((omega, hinge)) = fastest_mode(chain, hub) else {
        return;
    };
    let x = omega * step_s;
    if x > MAX_OMEGA_STEP {
        let fate = if x > RK4_UNSTABLE_OMEGA_STEP {
            "RK4 diverges on it (beyond ω·h = 2√2)"
        } else {
            "RK4 damps it artificially (3.8 % a period at ω·h = 1, diverging beyond 2√2)"
        };
        out.push(Implausible {
            field: format!("{path}.panels[{hinge}].k_nm_rad"),
            message: format!(
                "the chain's fastest hinge mode, {} rad/s (free hub, initial angles; mostly this \
                 hinge), has ω·h = {} at step_s = {} s: fewer than 2π steps a period, and {fate}; \
                 a step below {} s, or a softer hinge, resolves it",
                Rounded(omega, 5),
                Rounded(x, 4),
                Num(step_s),
                Rounded(MAX_OMEGA_STEP / omega, 3),
            ),
        });
    }
}

/// \[rad/s\] the chain's fastest hinge mode on a free `hub` (module docs) and the index of the
/// hinge that stores most of its elastic energy; `None` when every hinge is free (k = 0) or
/// the matrices are not positive-definite (the configuration's validation refuses those).
pub fn fastest_mode(chain: &PanelChainParams, hub: &HubParams) -> Option<(f64, usize)> {
    let n = chain.panels.len();
    let dim = 6 + n;
    let mut m = DMatrix::<f64>::zeros(dim, dim);
    // Adds a body of mass `mass`, inertia `inertia` (about its centre of mass, B components)
    // whose velocity rows are `jv` and angular velocity rows `jw`.
    let mut add_body = |mass: f64, inertia: &Matrix3<f64>, jv: &DMatrix<f64>, jw: &DMatrix<f64>| {
        m += jv.transpose() * jv * mass + jw.transpose() * inertia * jw;
    };
    let rows = |r_cb: &Vector3<f64>| {
        // v = ṙ_B + ω × r = ṙ_B − [r̃] ω; ω_body = ω.
        let mut jv = DMatrix::<f64>::zeros(3, dim);
        let mut jw = DMatrix::<f64>::zeros(3, dim);
        jv.view_mut((0, 0), (3, 3)).copy_from(&Matrix3::identity());
        jv.view_mut((0, 3), (3, 3)).copy_from(&-r_cb.cross_matrix());
        jw.view_mut((0, 3), (3, 3)).copy_from(&Matrix3::identity());
        (jv, jw)
    };
    let (jv, jw) = rows(&hub.r_bcb_b_m);
    add_body(hub.mass_kg, &hub.inertia_bc_b_kg_m2, &jv, &jw);
    let h = chain.dcm_h1b;
    let (h1, e, h3) = (
        h.row(0).transpose(),
        h.row(1).transpose(),
        h.row(2).transpose(),
    );
    let mut hinges: Vec<Vector3<f64>> = Vec::with_capacity(n);
    let mut hinge = chain.r_h1b_b_m;
    let mut phi = 0.0;
    for p in &chain.panels {
        // (C1)–(C2) at the initial angles.
        phi += p.theta_rad + p.theta_h_rad;
        let s1 = h1 * phi.cos() - h3 * phi.sin();
        let s3 = h1 * phi.sin() + h3 * phi.cos();
        hinges.push(hinge);
        let r_sc = hinge - p.d_m * s1;
        let (mut jv, mut jw) = rows(&r_sc);
        for (i, r_hi) in hinges.iter().enumerate() {
            jv.view_mut((0, 6 + i), (3, 1))
                .copy_from(&e.cross(&(r_sc - r_hi)));
            jw.view_mut((0, 6 + i), (3, 1)).copy_from(&e);
        }
        let i = p.inertia_s_kg_m2;
        let inertia =
            s1 * s1.transpose() * i.x + e * e.transpose() * i.y + s3 * s3.transpose() * i.z;
        add_body(p.mass_kg, &inertia, &jv, &jw);
        hinge -= p.l_m * s1;
    }
    let m_hh = m.view((0, 0), (6, 6)).into_owned();
    let m_ht = m.view((0, 6), (6, n)).into_owned();
    let m_tt = m.view((6, 6), (n, n)).into_owned();
    let m_eff = m_tt - m_ht.transpose() * m_hh.cholesky()?.solve(&m_ht);
    let l = m_eff.cholesky()?.l();
    let l_inv = l.clone().try_inverse()?;
    let k = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        n,
        chain.panels.iter().map(|p| p.k_nm_rad),
    ));
    let a = &l_inv * &k * l_inv.transpose();
    let eig = nalgebra::SymmetricEigen::new((&a + a.transpose()) * 0.5);
    let (top, lambda) = eig
        .eigenvalues
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    if lambda.is_nan() || lambda <= 0.0 {
        return None;
    }
    // The mode in hinge angles: v = L⁻ᵀ y; the hinge with the largest k_i v_i².
    let v = l_inv.transpose() * eig.eigenvectors.column(top);
    let hinge = (0..n)
        .max_by(|&a, &b| {
            let energy = |i: usize| chain.panels[i].k_nm_rad * v[i] * v[i];
            energy(a).total_cmp(&energy(b))
        })
        .unwrap_or(0);
    Some((lambda.sqrt(), hinge))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effectors::panel_chain::ChainPanelParams;

    fn panel(mass_kg: f64, inertia: [f64; 3], d_m: f64, l_m: f64, k: f64) -> ChainPanelParams {
        ChainPanelParams {
            mass_kg,
            inertia_s_kg_m2: Vector3::from(inertia),
            d_m,
            l_m,
            k_nm_rad: k,
            c_nm_s_rad: 0.0,
            theta_h_rad: 0.0,
            motor_torque_nm: 0.0,
            theta_rad: 0.0,
            theta_dot_rad_s: 0.0,
        }
    }

    fn hub(mass_kg: f64, j: [f64; 3]) -> HubParams {
        HubParams {
            mass_kg,
            inertia_bc_b_kg_m2: Matrix3::from_diagonal(&Vector3::from(j)),
            r_bcb_b_m: Vector3::new(0.0, 0.0, 0.3),
        }
    }

    /// One panel hinged at the hub's centre of mass, ê a principal axis of both: a planar
    /// two-body problem in closed form. With the momenta zero the hinge H moves opposite the
    /// panel's centre of mass (reduced mass μ = mM/(M + m)), so the panel's absolute rate ψ̇
    /// meets I_e = I_2 + μ d²; the hub turns at φ̇ = −(I_e/J) ψ̇, the hinge rate is
    /// θ̇ = ψ̇ (1 + I_e/J), and T = ½ I_e (1 + I_e/J) ψ̇² = ½ [I_e J/(J + I_e)] θ̇². With
    /// V = ½ k θ²: ω² = k (J + I_e)/(J I_e). A heavy hub (M, J → ∞) leaves ω² = k/(I_2 + m d²).
    #[test]
    fn one_panel_on_a_free_hub_has_the_two_body_frequency() {
        let (m_hub, j) = (500.0, 300.0);
        let (m, i2, d, k) = (20.0, 8.0, 0.5, 100.0);
        let chain = PanelChainParams {
            name: "c".into(),
            r_h1b_b_m: Vector3::new(0.0, 0.0, 0.3),
            dcm_h1b: Matrix3::identity(),
            panels: vec![panel(m, [6.0, i2, 2.0], d, 0.0, k)],
        };
        // ê = ĥ12 = y: J is the hub's moment about y.
        let (omega, hinge) = fastest_mode(&chain, &hub(m_hub, [400.0, j, 350.0])).unwrap();
        let mu = m * m_hub / (m + m_hub);
        let i_e = i2 + mu * d * d;
        let expect = (k * (j + i_e) / (j * i_e)).sqrt();
        assert!((omega / expect - 1.0).abs() < 1e-12, "{omega} vs {expect}");
        assert_eq!(hinge, 0);
        let (heavy, _) = fastest_mode(&chain, &hub(1e12, [1e12; 3])).unwrap();
        let cantilever = (k / (i2 + m * d * d)).sqrt();
        assert!(
            (heavy / cantilever - 1.0).abs() < 1e-9,
            "{heavy} vs {cantilever}"
        );
        // Free hinges have no mode.
        let mut free = chain.clone();
        free.panels[0].k_nm_rad = 0.0;
        assert!(fastest_mode(&free, &hub(m_hub, [400.0, j, 350.0])).is_none());
    }

    /// The warnings fire on the bad value and only there: a stiff tip hinge at h = 1 ms, then an
    /// angle in degrees.
    #[test]
    fn a_stiff_hinge_and_an_angle_in_degrees_are_warned_about() {
        let h = hub(750.0, [900.0, 800.0, 600.0]);
        let mut chain = PanelChainParams {
            name: "c".into(),
            r_h1b_b_m: Vector3::new(0.5, 0.0, 1.0),
            dcm_h1b: Matrix3::identity(),
            panels: vec![
                panel(40.0, [30.0, 15.0, 16.0], 0.7, 1.5, 150.0),
                panel(18.0, [12.0, 6.0, 7.0], 0.55, 0.0, 60.0),
            ],
        };
        let warnings = |c: &PanelChainParams, step_s: f64| {
            let mut out = Vec::new();
            check(c, "panel_chains[0]", &h, step_s, &mut out);
            out
        };
        assert!(warnings(&chain, 1e-3).is_empty());
        // The tip alone on a fixed base: I_2 + m d² = 6 + 18·0.55² = 11.445 kg·m²; k = 1e8
        // gives ω ≈ √(1e8/11.445) = 2956 rad/s, ω·h ≈ 2.96 > 2√2 at 1 ms (the free hub and
        // the inboard panel only raise it).
        chain.panels[1].k_nm_rad = 1e8;
        let w = warnings(&chain, 1e-3);
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!(w[0].field, "panel_chains[0].panels[1].k_nm_rad");
        assert!(w[0].message.contains("RK4 diverges"), "{}", w[0].message);
        let (omega, _) = fastest_mode(&chain, &h).unwrap();
        assert!(omega > (1e8f64 / 11.445).sqrt(), "{omega}");
        // Between 1 and 2√2: damped, not divergent (h = 0.5 ms: ω·h ≈ 1.5).
        let w = warnings(&chain, 0.5e-3);
        assert!(w[0].message.contains("damps it"), "{}", w[0].message);
        // Just below ω·h = 1: quiet.
        assert!(warnings(&chain, 0.99 / omega).is_empty());
        // 180 typed for π: the degrees it meant.
        chain.panels[1].k_nm_rad = 60.0;
        chain.panels[1].theta_h_rad = 180.0;
        let w = warnings(&chain, 1e-3);
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!(w[0].field, "panel_chains[0].panels[1].theta_h_rad");
        assert!(
            w[0].message.ends_with("is it in deg? 180 deg = 3.1416 rad"),
            "{}",
            w[0].message
        );
        // A full turn is still radians.
        chain.panels[1].theta_h_rad = -std::f64::consts::TAU;
        assert!(warnings(&chain, 1e-3).is_empty());
    }
}
