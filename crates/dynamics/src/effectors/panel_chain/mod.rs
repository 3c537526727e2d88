//! A chain of N ≥ 1 rigid panels hinged in series (unequal masses, inertias, lengths,
//! stiffnesses and dampings): Allard & Schaub's dual-hinged back-substitution (Sections III.C,
//! IV and V; DOI 10.2514/1.A34125; errata in `docs/errata.md`) extended from 2 links to N.
//!
//! # Geometry and kinematics
//! All hinge axes are parallel to the first hinge's axis ê = ĥ12 (the second row of `dcm_h1b`),
//! as in the pair. Indices k = 1 … N run from the hub outwards.
//!
//! - (C1) [S_k B] = M2(θ_k) M2(θ_Hk) [S_k−1 B], [S_0 B] = [H1 B] (the pair's [S2 B] of
//!   `docs/models/physics.md`, repeated). With Φ_k = Σ_{j≤k} (θ_j + θ_Hj):
//!   ŝ_k1 = cos Φ_k ĥ11 − sin Φ_k ĥ13, ŝ_k2 = ê, ŝ_k3 = sin Φ_k ĥ11 + cos Φ_k ĥ13.
//! - (C2) r_H1/B given; r_Hk+1/B = r_Hk/B − l_k ŝ_k1; r_Sck/B = r_Hk/B − d_k ŝ_k1 (Eqs. 6–7).
//! - (C3) Ω_k = Σ_{j≤k} θ̇_j, the rate of panel k relative to B about ê; ŝ_k1′ = −Ω_k ŝ_k3,
//!   ŝ_k3′ = Ω_k ŝ_k1. Hence (Eqs. 8, 10, 85–86 extended)
//!   r′_Sck = Σ_{j<k} l_j Ω_j ŝ_j3 + d_k Ω_k ŝ_k3 and
//!   r″_Sck = Σ_{m≤k} θ̈_m p_mk + κ_k, κ_k = Σ_{j<k} l_j Ω_j² ŝ_j1 + d_k Ω_k² ŝ_k1.
//! - (C4) The partial velocity of Sc_k for θ̇_i (Table 1 extended) is
//!   p_ik = ê × (r_Sck − r_Hi) = Σ_{j=i}^{k−1} l_j ŝ_j3 + d_k ŝ_k3 for i ≤ k, 0 for i > k; the
//!   partial angular velocity of panel k is ê for i ≤ k (Eqs. 87–88).
//! - (C5) ω_Sk/N = ω_B/N + Ω_k ê (Eq. 51); its inertial derivative is ω̇ + Ω̇_k ê + Ω_k ω × ê.
//!
//! # The hinge equations
//! (C6) Kane's equation for θ_i (Eqs. 91–95 and 117, one row per hinge):
//! Σ_{k≥i} [m_k p_ik · a_Sck + ê · (\[I_k\] α_k + ω_Sk × \[I_k\] ω_Sk)] = τ_i, with
//! a_Sck = r̈_B/N + ω̇ × r_Sck + ω × (ω × r_Sck) + 2 ω × r′_Sck + r″_Sck and the hinge torque
//! τ_i = −k_i θ_i − c_i θ̇_i + u_i on panel i (the inboard body takes −τ_i, so τ_i is the whole
//! generalised active force of row i). Since ê is a principal axis, ê·\[I_k\] = I_k2 êᵀ and the
//! gyroscopic term is (I_k1 − I_k3) ω_k1 ω_k3 with ω_kj = ω·ŝ_kj (as in Eq. 124). Collected:
//!
//! (C7) \[M_θ\] θ̈ = −\[A_θ\] r̈_B/N − \[B_θ\] ω̇_B/N + F_θ, an N×N system whose rows are
//! - M_im = Σ_{k≥max(i,m)} (m_k p_ik·p_mk + I_k2)  (symmetric positive-definite: the Kane block),
//! - A_θ,i = Σ_{k≥i} m_k p_ikᵀ,
//! - B_θ,i = Σ_{k≥i} (m_k (r_Sck × p_ik)ᵀ + I_k2 êᵀ),
//! - F_i = τ_i − Σ_{k≥i} [m_k p_ik·(ω × (ω × r_Sck) + 2 ω × r′_Sck + κ_k) + (I_k1 − I_k3) ω_k1 ω_k3].
//!
//! For N = 2 these are Kane's rows: row 2 is the pair's Eq. 120 (erratum E1 applied) and row 1
//! is Eq. 119 + Eq. 120 (`docs/errata.md`, Section IV), so \[M_θ\] = T \[A_i\] with
//! T = [[1, 1], [0, 1]] and the solution θ̈ is the pair's.
//!
//! (C8) With p_ik = l_i ŝ_i3 + p_i+1,k (i < k), every sum folds into one sweep from the tip,
//! k = N … 1, carrying m_>k = Σ_{j>k} m_j, c_>k = Σ_{j>k} m_j r_Scj and
//! s_>k = Σ_{j>k} m_j a_j (a_j the velocity-product part of a_Scj):
//! - A_k = (m_k d_k + m_>k l_k) ŝ_k3 + A_k+1,
//! - B_k = m_k d_k r_Sck × ŝ_k3 + l_k c_>k × ŝ_k3 + I_k2 ê + B_k+1,
//! - F_k = τ_k − G_k − E_k, G_k = m_k d_k ŝ_k3·a_k + l_k ŝ_k3·s_>k + G_k+1,
//!   E_k = (I_k1 − I_k3) ω_k1 ω_k3 + E_k+1,
//! - M_kk = I_k2 + m_k d_k² + m_>k l_k² + 2 l_k ŝ_k3·A_k+1 + M_k+1,k+1,
//! - M_im = D_im·A_m + M_mm for i < m, with D_im = Σ_{j=i}^{m−1} l_j ŝ_j3 (since
//!   p_ik = D_im + p_mk for k ≥ m).
//!
//! # Back-substitution and the hub contributions
//! (C9) With \[M_θ\] = L Lᵀ (Cholesky), X_f = −\[M_θ\]⁻¹\[A_θ\], X_g = −\[M_θ\]⁻¹\[B_θ\],
//! x_v = \[M_θ\]⁻¹ F_θ (N×3, N×3, N): θ̈ = X_f r̈_B/N + X_g ω̇_B/N + x_v (Eqs. 129–132).
//!
//! (C10) The θ̈ terms of the hub's translational and rotational equations (Eqs. 133–134) are
//! Σ_k m_k r″_Sck|θ̈ = \[A_θ\]ᵀ θ̈ and Σ_k (m_k r_Sck × r″_Sck|θ̈ + I_k2 Ω̇_k ê) = \[B_θ\]ᵀ θ̈ (the
//! same rows: Kane's symmetry). Substituting (C9) (Eqs. 139–144):
//! - \[A_contr\] = \[A_θ\]ᵀ X_f, \[B_contr\] = \[A_θ\]ᵀ X_g, \[C_contr\] = \[B_θ\]ᵀ X_f = \[B_contr\]ᵀ,
//!   \[D_contr\] = \[B_θ\]ᵀ X_g (\[A_contr\] and \[D_contr\] symmetric);
//! - v_trans,contr = −Σ_k m_k κ_k − \[A_θ\]ᵀ x_v;
//! - v_rot,contr = −Σ_k (h_k + m_k r_Sck × (2 ω × r′_Sck + κ_k)) − \[B_θ\]ᵀ x_v, with
//!   h_k = Ω_k ((I_k3 − I_k1)(ω_k3 ŝ_k1 + ω_k1 ŝ_k3) + I_k2 (ω_k1 ŝ_k3 − ω_k3 ŝ_k1)). The sum is
//!   what panel k adds beyond a body frozen in B (whose terms the hub already carries through
//!   \[I_sc,B\], c and c′): h_k = \[I_k\]α_k + ω_Sk×\[I_k\]ω_Sk − (\[I_k\]ω̇ + ω×\[I_k\]ω) − I_k2 Ω̇_k ê,
//!   and m_k r × (2ω × r′ + κ) from a_Sck. Together they equal the pair's ω × H_rel, its
//!   centripetal torques and its share of Eq. 150's −[I′]ω.
//!
//! # Cost and storage
//! One evaluation is O(N) for the sweep, O(N²) for the off-diagonal of \[M_θ\] and N³/6 for the
//! factorisation, with every array sized at construction (no allocation in the stepping path).
//! A chain holds at most [`MAX_LINKS`] panels (the static state-name table); a configured chain
//! at most [`MAX_WIRE_LINKS`], because a StateMsg effector entry carries at most
//! `flexdyn_proto::MAX_EFFECTOR_VALUES` states: 32 since protocol 11, so both limits are 16.
//!
//! Integrated state: `[θ1, θ̇1, θ2, θ̇2, …, θN, θ̇N]`, the pair's order, so the N = 2 chain's
//! state vector is the pair's.

use nalgebra::{Matrix3, Vector3};

use crate::effector::{
    BackSubContributions, EffectorKind, EffectorMassProps, EnergyMomentum, HubAccel, HubKinematics,
    StateEffector,
};
use flexdyn_kernel::validate::ParamError;

pub mod kind;
mod params;
pub mod plausibility;
pub mod schema;
#[cfg(test)]
mod tests;

pub use params::{ChainPanelParams, PanelChainParams};

/// The chain's kind: wire tag `effector_kind::PANEL_CHAIN`, CSV columns `chain<k>_…`.
pub const KIND: EffectorKind = EffectorKind {
    name: "panel_chain",
    wire_tag: flexdyn_proto::effector_kind::PANEL_CHAIN,
    column_prefix: "chain",
};

/// The most panels one chain may have (the length of the static name tables).
pub const MAX_LINKS: usize = 16;

/// The most panels of a configured chain: a StateMsg effector entry carries at most
/// `MAX_EFFECTOR_VALUES` states, two per panel.
pub const MAX_WIRE_LINKS: usize = flexdyn_proto::MAX_EFFECTOR_VALUES / 2;

/// State names, `[θ_k rad, θ̇_k rad/s]` per panel; a chain of N panels uses the first 2N.
pub static STATE_NAMES: [&str; 2 * MAX_LINKS] = [
    "theta_1",
    "theta_dot_1",
    "theta_2",
    "theta_dot_2",
    "theta_3",
    "theta_dot_3",
    "theta_4",
    "theta_dot_4",
    "theta_5",
    "theta_dot_5",
    "theta_6",
    "theta_dot_6",
    "theta_7",
    "theta_dot_7",
    "theta_8",
    "theta_dot_8",
    "theta_9",
    "theta_dot_9",
    "theta_10",
    "theta_dot_10",
    "theta_11",
    "theta_dot_11",
    "theta_12",
    "theta_dot_12",
    "theta_13",
    "theta_dot_13",
    "theta_14",
    "theta_dot_14",
    "theta_15",
    "theta_dot_15",
    "theta_16",
    "theta_dot_16",
];

/// Input names, the hinge motor torques \[N·m\]; a chain of N panels uses the first N.
pub static INPUT_NAMES: [&str; MAX_LINKS] = [
    "motor_torque_1_nm",
    "motor_torque_2_nm",
    "motor_torque_3_nm",
    "motor_torque_4_nm",
    "motor_torque_5_nm",
    "motor_torque_6_nm",
    "motor_torque_7_nm",
    "motor_torque_8_nm",
    "motor_torque_9_nm",
    "motor_torque_10_nm",
    "motor_torque_11_nm",
    "motor_torque_12_nm",
    "motor_torque_13_nm",
    "motor_torque_14_nm",
    "motor_torque_15_nm",
    "motor_torque_16_nm",
];

/// Per-panel constants, read once at construction.
#[derive(Debug, Clone, Copy, Default)]
struct Link {
    /// \[kg\] m_k.
    m: f64,
    /// \[m\] d_k and l_k.
    d: f64,
    l: f64,
    /// \[kg·m\] m_k d_k.
    md: f64,
    /// \[kg·m²\] principal moments I_k1, I_k2, I_k3.
    i1: f64,
    i2: f64,
    i3: f64,
    /// \[N·m/rad\], \[N·m·s/rad\] hinge stiffness and damping.
    k: f64,
    c: f64,
    /// \[rad\] θ_Hk.
    theta_h: f64,
}

/// One panel's kinematics at a state (C1–C3).
#[derive(Debug, Clone, Copy)]
struct LinkGeom {
    /// ŝ_k1, ŝ_k3 in B components.
    s1: Vector3<f64>,
    s3: Vector3<f64>,
    /// \[m\] r_Sck/B.
    r: Vector3<f64>,
    /// \[m/s\] r′_Sck/B.
    r_prime: Vector3<f64>,
    /// \[m/s²\] κ_k, the velocity part of r″_Sck/B.
    kappa: Vector3<f64>,
    /// \[rad/s\] Ω_k.
    rate: f64,
}

impl Default for LinkGeom {
    fn default() -> Self {
        let z = Vector3::zeros();
        Self {
            s1: z,
            s3: z,
            r: z,
            r_prime: z,
            kappa: z,
            rate: 0.0,
        }
    }
}

/// One panel's rows of (C7) and its back-substitution coefficients (C9), cached between the
/// passes of one evaluation.
#[derive(Debug, Clone, Copy)]
struct LinkWork {
    g: LinkGeom,
    /// A_θ,k and B_θ,k (C7, C8).
    a_row: Vector3<f64>,
    b_row: Vector3<f64>,
    /// Right-hand sides [−A_θ,k | −B_θ,k | F_k], solved in place into [X_f,k | X_g,k | x_v,k].
    rhs: [f64; 7],
}

impl Default for LinkWork {
    fn default() -> Self {
        let z = Vector3::zeros();
        Self {
            g: LinkGeom::default(),
            a_row: z,
            b_row: z,
            rhs: [0.0; 7],
        }
    }
}

/// A chain of N hinged rigid panels appended to the hub.
#[derive(Debug, Clone)]
pub struct PanelChain {
    params: PanelChainParams,
    /// Number of panels N.
    n: usize,
    /// ĥ11, ê = ĥ12, ĥ13 in B components.
    h1: Vector3<f64>,
    e: Vector3<f64>,
    h3: Vector3<f64>,
    links: Vec<Link>,
    /// \[N·m\] commanded hinge motor torques u_k.
    motor_torque_nm: Vec<f64>,
    /// Workspace sized at construction: per-panel rows, and [M_θ] row-major (its lower
    /// triangle holds the Cholesky factor after pass 2).
    work: Vec<LinkWork>,
    m_theta: Vec<f64>,
}

impl PanelChain {
    /// Builds a chain after validating its parameters (`path` prefixes field names in errors).
    pub fn new(params: PanelChainParams, path: &str) -> Result<Self, ParamError> {
        params.validate(path)?;
        let n = params.panels.len();
        let h = &params.dcm_h1b;
        let links = params
            .panels
            .iter()
            .map(|p| Link {
                m: p.mass_kg,
                d: p.d_m,
                l: p.l_m,
                md: p.mass_kg * p.d_m,
                i1: p.inertia_s_kg_m2.x,
                i2: p.inertia_s_kg_m2.y,
                i3: p.inertia_s_kg_m2.z,
                k: p.k_nm_rad,
                c: p.c_nm_s_rad,
                theta_h: p.theta_h_rad,
            })
            .collect();
        Ok(Self {
            n,
            h1: h.row(0).transpose(),
            e: h.row(1).transpose(),
            h3: h.row(2).transpose(),
            links,
            motor_torque_nm: params.panels.iter().map(|p| p.motor_torque_nm).collect(),
            work: vec![LinkWork::default(); n],
            m_theta: vec![0.0; n * n],
            params,
        })
    }

    /// The chain's parameters.
    pub fn params(&self) -> &PanelChainParams {
        &self.params
    }

    /// Number of panels N.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false: a chain has at least one panel.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Panel k's axes (ŝ_k1, ŝ_k2 = ê, ŝ_k3) in B components at state `x`, k = 0 … N − 1.
    pub fn panel_axes_b(&self, x: &[f64], k: usize) -> [Vector3<f64>; 3] {
        let mut axes = [Vector3::zeros(); 3];
        self.for_each_link(x, |j, g| {
            if j == k {
                axes = [g.s1, self.e, g.s3];
            }
        });
        axes
    }

    /// Walks the chain from the hub outwards at state `x`, handing each panel's kinematics
    /// (C1–C3) to `f`: one `sin_cos` per panel, the hinge point, velocity and centripetal
    /// acceleration carried from one panel to the next.
    #[inline(always)]
    fn for_each_link(&self, x: &[f64], mut f: impl FnMut(usize, &LinkGeom)) {
        let mut phi = 0.0;
        let mut rate = 0.0;
        let mut r_h = self.params.r_h1b_b_m;
        let mut v_h = Vector3::zeros();
        let mut kappa_h = Vector3::zeros();
        for (k, link) in self.links.iter().enumerate() {
            phi += x[2 * k] + link.theta_h;
            rate += x[2 * k + 1];
            let (sn, cs) = phi.sin_cos();
            // (C1)
            let s1 = self.h1 * cs - self.h3 * sn;
            let s3 = self.h1 * sn + self.h3 * cs;
            let rate_sq = rate * rate;
            // (C2), (C3)
            let g = LinkGeom {
                s1,
                s3,
                r: r_h - s1 * link.d,
                r_prime: v_h + s3 * (link.d * rate),
                kappa: kappa_h + s1 * (link.d * rate_sq),
                rate,
            };
            f(k, &g);
            r_h -= s1 * link.l;
            v_h += s3 * (link.l * rate);
            kappa_h += s1 * (link.l * rate_sq);
        }
    }

    /// Inertia of panel k about its centre of mass in B components: Σ_j I_kj ŝ_kj ŝ_kjᵀ.
    #[inline(always)]
    fn inertia_b(&self, link: &Link, g: &LinkGeom) -> Matrix3<f64> {
        g.s1 * g.s1.transpose() * link.i1
            + self.e * self.e.transpose() * link.i2
            + g.s3 * g.s3.transpose() * link.i3
    }

    /// (C9): factors [M_θ] = L Lᵀ in place (lower triangle) and solves the seven right-hand
    /// sides of every row in place.
    #[inline(always)]
    fn cholesky_solve(&mut self) {
        let n = self.n;
        let m = &mut self.m_theta;
        for j in 0..n {
            let mut d = m[j * n + j];
            for p in 0..j {
                d -= m[j * n + p] * m[j * n + p];
            }
            let ljj = d.sqrt();
            m[j * n + j] = ljj;
            let inv = 1.0 / ljj;
            for i in (j + 1)..n {
                let mut v = m[i * n + j];
                for p in 0..j {
                    v -= m[i * n + p] * m[j * n + p];
                }
                m[i * n + j] = v * inv;
            }
        }
        let w = &mut self.work;
        // L y = b, then Lᵀ x = y.
        for k in 0..n {
            let mut b = w[k].rhs;
            for (p, wp) in w.iter().enumerate().take(k) {
                let lkp = m[k * n + p];
                for (bc, yc) in b.iter_mut().zip(&wp.rhs) {
                    *bc -= lkp * yc;
                }
            }
            let inv = 1.0 / m[k * n + k];
            w[k].rhs = b.map(|v| v * inv);
        }
        for k in (0..n).rev() {
            let mut b = w[k].rhs;
            for (p, wp) in w.iter().enumerate().skip(k + 1) {
                let lpk = m[p * n + k];
                for (bc, xc) in b.iter_mut().zip(&wp.rhs) {
                    *bc -= lpk * xc;
                }
            }
            let inv = 1.0 / m[k * n + k];
            w[k].rhs = b.map(|v| v * inv);
        }
    }
}

/// The first three entries of `a` as a vector.
#[inline(always)]
fn v3(a: &[f64]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

impl StateEffector for PanelChain {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn kind(&self) -> EffectorKind {
        KIND
    }

    fn state_len(&self) -> usize {
        2 * self.n
    }

    fn state_names(&self) -> &'static [&'static str] {
        &STATE_NAMES[..2 * self.n]
    }

    fn input_names(&self) -> &'static [&'static str] {
        &INPUT_NAMES[..self.n]
    }

    fn set_inputs(&mut self, u: &[f64]) {
        self.motor_torque_nm.copy_from_slice(u);
    }

    fn parameters(&self, x0: &[f64], out: &mut Vec<(String, f64)>) {
        let p = &self.params;
        for i in 0..3 {
            out.push((format!("r_h1b_b_m[{i}]"), p.r_h1b_b_m[i]));
            for j in 0..3 {
                out.push((format!("dcm_h1b[{i}][{j}]"), p.dcm_h1b[(i, j)]));
            }
        }
        for (k, panel) in p.panels.iter().enumerate() {
            let mut put = |key: &str, v: f64| out.push((format!("panels[{k}].{key}"), v));
            put("mass_kg", panel.mass_kg);
            for i in 0..3 {
                put(&format!("inertia_s_kg_m2[{i}]"), panel.inertia_s_kg_m2[i]);
            }
            put("d_m", panel.d_m);
            put("l_m", panel.l_m);
            put("k_nm_rad", panel.k_nm_rad);
            put("c_nm_s_rad", panel.c_nm_s_rad);
            put("theta_h_rad", panel.theta_h_rad);
            put("motor_torque_nm", panel.motor_torque_nm);
            put("theta_rad", x0[2 * k]);
            put("theta_dot_rad_s", x0[2 * k + 1]);
        }
    }

    fn initial_state(&self, x: &mut [f64]) {
        for (k, p) in self.params.panels.iter().enumerate() {
            x[2 * k] = p.theta_rad;
            x[2 * k + 1] = p.theta_dot_rad_s;
        }
    }

    fn update_mass_props(&mut self, x: &[f64], sum: &mut EffectorMassProps) {
        // The workspace is moved out while the walk borrows `self` (an empty Vec does not
        // allocate) and put back after.
        let mut work = std::mem::take(&mut self.work);
        self.for_each_link(x, |k, g| {
            let link = &self.links[k];
            sum.mass_kg += link.m;
            sum.first_moment_b_kg_m += g.r * link.m;
            sum.first_moment_prime_b_kg_m_s += g.r_prime * link.m;
            // [I_Sck] + m_k [r̃][r̃]ᵀ, with [r̃][r̃]ᵀ = |r|² I − r rᵀ.
            sum.inertia_pnt_b_b_kg_m2 += self.inertia_b(link, g)
                + (Matrix3::from_diagonal_element(g.r.norm_squared()) - g.r * g.r.transpose())
                    * link.m;
            work[k].g = *g;
        });
        self.work = work;
    }

    fn update_contributions(
        &mut self,
        x: &[f64],
        hub: &HubKinematics,
        sum: &mut BackSubContributions,
    ) {
        let n = self.n;
        let w = hub.omega_bn_b;
        let e = self.e;
        // The tip-to-hub sweep (C8).
        let (mut mass_out, mut first_out, mut accel_out) =
            (0.0, Vector3::zeros(), Vector3::zeros());
        let (mut a_next, mut b_next) = (Vector3::zeros(), Vector3::zeros());
        let (mut g_next, mut e_next, mut m_next) = (0.0, 0.0, 0.0);
        let mut extra_trans = Vector3::zeros();
        let mut extra_rot = Vector3::zeros();
        for k in (0..n).rev() {
            let link = self.links[k];
            let lw = &mut self.work[k];
            let g = lw.g;
            let (w1, w3) = (w.dot(&g.s1), w.dot(&g.s3));
            // a_k: the velocity-product part of a_Sck (C6).
            let coriolis = w.cross(&g.r_prime) * 2.0;
            let a_k = w.cross(&w.cross(&g.r)) + coriolis + g.kappa;
            let s3_a_next = g.s3.dot(&a_next);
            let a_row = g.s3 * (link.md + mass_out * link.l) + a_next;
            let b_row = (g.r.cross(&g.s3) * link.md)
                + first_out.cross(&g.s3) * link.l
                + e * link.i2
                + b_next;
            let g_k = link.md * g.s3.dot(&a_k) + link.l * g.s3.dot(&accel_out) + g_next;
            let e_k = (link.i1 - link.i3) * w1 * w3 + e_next;
            let th = x[2 * k];
            let th_dot = x[2 * k + 1];
            let tau = -link.k * th - link.c * th_dot + self.motor_torque_nm[k];
            let m_kk = link.i2
                + link.md * link.d
                + mass_out * link.l * link.l
                + 2.0 * link.l * s3_a_next
                + m_next;
            self.m_theta[k * n + k] = m_kk;
            lw.a_row = a_row;
            lw.b_row = b_row;
            lw.rhs = [
                -a_row.x,
                -a_row.y,
                -a_row.z,
                -b_row.x,
                -b_row.y,
                -b_row.z,
                tau - g_k - e_k,
            ];
            // (C10): what the panel adds beyond a body frozen in B.
            extra_trans += g.kappa * link.m;
            extra_rot += (g.s1 * w3 + g.s3 * w1) * (g.rate * (link.i3 - link.i1))
                + (g.s3 * w1 - g.s1 * w3) * (g.rate * link.i2)
                + g.r.cross(&(coriolis + g.kappa)) * link.m;
            mass_out += link.m;
            first_out += g.r * link.m;
            accel_out += a_k * link.m;
            (a_next, b_next, g_next, e_next, m_next) = (a_row, b_row, g_k, e_k, m_kk);
        }
        // (C8): M_im = D_im·A_m + M_mm below the diagonal (row m > column i).
        for mi in 1..n {
            let a_m = self.work[mi].a_row;
            let m_mm = self.m_theta[mi * n + mi];
            let mut d_im = Vector3::zeros();
            for i in (0..mi).rev() {
                d_im += self.work[i].g.s3 * self.links[i].l;
                self.m_theta[mi * n + i] = d_im.dot(&a_m) + m_mm;
            }
        }
        self.cholesky_solve();

        // (C10): [A_contr] = A_θᵀX_f, [B_contr] = A_θᵀX_g, [C_contr] = [B_contr]ᵀ,
        // [D_contr] = B_θᵀX_g; the symmetric two from their upper triangles.
        let (mut ma, mut mb, mut md) = (Matrix3::zeros(), Matrix3::zeros(), Matrix3::zeros());
        let (mut vt, mut vr) = (-extra_trans, -extra_rot);
        for lw in &self.work[..n] {
            let (x_f, x_g, x_v) = (v3(&lw.rhs[0..3]), v3(&lw.rhs[3..6]), lw.rhs[6]);
            ma += lw.a_row * x_f.transpose();
            mb += lw.a_row * x_g.transpose();
            md += lw.b_row * x_g.transpose();
            vt -= lw.a_row * x_v;
            vr -= lw.b_row * x_v;
        }
        for i in 0..3 {
            for j in 0..i {
                ma[(i, j)] = ma[(j, i)];
                md[(i, j)] = md[(j, i)];
            }
        }
        sum.matrix_a += ma;
        sum.matrix_b += mb;
        sum.matrix_c += mb.transpose();
        sum.matrix_d += md;
        sum.vec_trans += vt;
        sum.vec_rot += vr;
    }

    fn compute_derivatives(&mut self, x: &[f64], hub_accel: &HubAccel, dx: &mut [f64]) {
        let (a, w_dot) = (&hub_accel.nongrav_accel_bn_b, &hub_accel.omega_dot_bn_b);
        for (k, lw) in self.work.iter().enumerate() {
            dx[2 * k] = x[2 * k + 1];
            // (C9)
            dx[2 * k + 1] = v3(&lw.rhs[0..3]).dot(a) + v3(&lw.rhs[3..6]).dot(w_dot) + lw.rhs[6];
        }
    }

    fn energy_momentum(&self, x: &[f64], omega_bn_b: &Vector3<f64>) -> EnergyMomentum {
        let mut em = EnergyMomentum::default();
        self.for_each_link(x, |k, g| {
            let link = &self.links[k];
            let inertia = self.inertia_b(link, g);
            // (C5)
            let w_k = omega_bn_b + self.e * g.rate;
            em += EnergyMomentum::rigid_body(link.m, &g.r, &g.r_prime, &inertia, &w_k, omega_bn_b);
            em.potential_j += 0.5 * link.k * x[2 * k] * x[2 * k];
        });
        em
    }

    /// The held hinge-motor torques; the per-link work arrays are recomputed from `x`.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        a.put(&mut self.motor_torque_nm[..]);
    }
}
