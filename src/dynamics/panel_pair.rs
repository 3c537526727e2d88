//! Dual-linked hinged rigid panels: the state effector of Allard & Schaub, Sections III.C and V.
//!
//! Geometry (ERRATA.md, "Conventions"):
//! - [S1 B] = M2(θ1) [H1 B];  [S2 B] = M2(θ2) M2(θ_H2S1) [S1 B]  (θ2 is relative to panel 1);
//! - the hinge axes coincide: ŝ12 = ŝ22 = ĥ12;
//! - r_Sc1/B = r_H1/B − d1 ŝ11 (Eq. 6);  r_Sc2/B = r_H1/B − l1 ŝ11 − d2 ŝ21 (Eq. 7).
//!
//! Integrated state per pair: `[θ1, θ̇1, θ2, θ̇2]`.
//!
//! Each evaluation computes the pair's rows of the hinge equations (Eqs. 119–120, i.e. 72 and 81,
//! with erratum E1 applied to the panel-2 row), written as Eq. 128:
//! `[A_i] θ̈ = [F_i] r̈_B/N + [G_i] ω̇_B/N + v_i`, and folds them into the hub system
//! (Eqs. 139–144). After the hub solve, θ̈ follows from Eqs. 131–132.

use nalgebra::{Matrix3, Vector3};

use super::effector::{
    BackSubContributions, EffectorMassProps, EnergyMomentum, HubAccel, HubKinematics, StateEffector,
};
use super::params::{PanelPairInitial, PanelPairParams};
use super::ParamError;

/// Geometry and back-substitution terms cached between the passes of one evaluation.
#[derive(Debug, Clone, Copy)]
struct Cache {
    /// Panel-1 frame axes in B components (rows of [S1 B]).
    s11: Vector3<f64>,
    s13: Vector3<f64>,
    /// Panel-2 frame axes in B components (rows of [S2 B]); ŝ22 = ŝ12.
    s21: Vector3<f64>,
    s23: Vector3<f64>,
    /// r_Sc1/B, r_Sc2/B and their body-frame derivatives (Eqs. 6–8, 10).
    r_sc1b_b: Vector3<f64>,
    r_sc2b_b: Vector3<f64>,
    r_prime_sc1b_b: Vector3<f64>,
    r_prime_sc2b_b: Vector3<f64>,
    /// Solutions of [A_i] X = [F_i | G_i | v_i] (rows 1 and 2): θ̈_k = x_f_k·r̈ + x_g_k·ω̇ + x_v_k.
    x_f: [Vector3<f64>; 2],
    x_g: [Vector3<f64>; 2],
    x_v: [f64; 2],
}

impl Default for Cache {
    fn default() -> Self {
        let z = Vector3::zeros();
        Self {
            s11: z,
            s13: z,
            s21: z,
            s23: z,
            r_sc1b_b: z,
            r_sc2b_b: z,
            r_prime_sc1b_b: z,
            r_prime_sc2b_b: z,
            x_f: [z; 2],
            x_g: [z; 2],
            x_v: [0.0; 2],
        }
    }
}

/// A dual-hinged panel pair (two rigid panels in a chain) appended to the hub.
#[derive(Debug, Clone)]
pub struct PanelPair {
    params: PanelPairParams,
    initial: PanelPairInitial,
    /// Rows of [H1 B]: ĥ11, ĥ12, ĥ13 in B components.
    h11: Vector3<f64>,
    h12: Vector3<f64>,
    h13: Vector3<f64>,
    /// (sin, cos) of θ_H2S1.
    sin_h2s1: f64,
    cos_h2s1: f64,
    /// [kg·m²] the θ-independent part of both panels' inertias about their centres of mass, in B:
    /// with ŝ1ŝ1ᵀ + ŝ2ŝ2ᵀ + ŝ3ŝ3ᵀ = I, each panel's Σ I_k ŝ_kŝ_kᵀ is
    /// I_1 [1] + (I_2 − I_1) ĥ2ĥ2ᵀ + (I_3 − I_1) ŝ3ŝ3ᵀ, and only the last term moves.
    inertia_const_b: Matrix3<f64>,
    cache: Cache,
}

/// Index of θ1 in the pair's state slice.
pub const THETA1: usize = 0;
/// Index of θ̇1.
pub const THETA1_DOT: usize = 1;
/// Index of θ2.
pub const THETA2: usize = 2;
/// Index of θ̇2.
pub const THETA2_DOT: usize = 3;

impl PanelPair {
    /// Builds a pair after validating its parameters (`path` prefixes field names in errors).
    pub fn new(
        params: PanelPairParams,
        initial: PanelPairInitial,
        path: &str,
    ) -> Result<Self, ParamError> {
        params.validate(path)?;
        initial.validate(path)?;
        let h = params.dcm_h1b;
        let (sin_h2s1, cos_h2s1) = params.theta_h2s1_rad.sin_cos();
        let h12: Vector3<f64> = h.row(1).transpose();
        let (i1, i2) = (
            &params.panel1.inertia_s_kg_m2,
            &params.panel2.inertia_s_kg_m2,
        );
        let inertia_const_b = Matrix3::from_diagonal_element(i1.x + i2.x)
            + h12 * h12.transpose() * (i1.y - i1.x + i2.y - i2.x);
        Ok(Self {
            inertia_const_b,
            h11: h.row(0).transpose(),
            h12: h.row(1).transpose(),
            h13: h.row(2).transpose(),
            sin_h2s1,
            cos_h2s1,
            params,
            initial,
            cache: Cache::default(),
        })
    }

    /// The pair's parameters.
    pub fn params(&self) -> &PanelPairParams {
        &self.params
    }

    /// Panel frame axes (ŝ_k1, ŝ_k2, ŝ_k3 for panels k = 1, 2) in B components at state `x`.
    ///
    /// [S1 B] = M2(θ1)[H1 B] gives ŝ11 = cos θ1 ĥ11 − sin θ1 ĥ13, ŝ12 = ĥ12,
    /// ŝ13 = sin θ1 ĥ11 + cos θ1 ĥ13; panel 2 repeats this about ŝ12 with θ2 + θ_H2S1.
    #[inline(always)]
    pub fn panel_axes_b(&self, x: &[f64]) -> [[Vector3<f64>; 3]; 2] {
        let (sn1, cs1) = x[THETA1].sin_cos();
        let s11 = self.h11 * cs1 - self.h13 * sn1;
        let s13 = self.h11 * sn1 + self.h13 * cs1;
        // M2(θ2) M2(θ_H2S1) = M2(θ2 + θ_H2S1), expanded with the angle-sum identities.
        let (sn2, cs2) = x[THETA2].sin_cos();
        let sn = sn2 * self.cos_h2s1 + cs2 * self.sin_h2s1;
        let cs = cs2 * self.cos_h2s1 - sn2 * self.sin_h2s1;
        let s21 = s11 * cs - s13 * sn;
        let s23 = s11 * sn + s13 * cs;
        [[s11, self.h12, s13], [s21, self.h12, s23]]
    }

    /// Inertia about a panel's centre of mass in B components: Σ_k I_k ŝ_k ŝ_kᵀ.
    #[inline(always)]
    fn inertia_b(
        i_s: &Vector3<f64>,
        s1: &Vector3<f64>,
        s2: &Vector3<f64>,
        s3: &Vector3<f64>,
    ) -> Matrix3<f64> {
        s1 * s1.transpose() * i_s.x + s2 * s2.transpose() * i_s.y + s3 * s3.transpose() * i_s.z
    }
}

impl StateEffector for PanelPair {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn state_len(&self) -> usize {
        4
    }

    fn state_names(&self) -> Vec<String> {
        ["theta1", "theta1_dot", "theta2", "theta2_dot"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    }

    fn initial_state(&self, x: &mut [f64]) {
        x[THETA1] = self.initial.theta1_rad;
        x[THETA1_DOT] = self.initial.theta1_dot_rad_s;
        x[THETA2] = self.initial.theta2_rad;
        x[THETA2_DOT] = self.initial.theta2_dot_rad_s;
    }

    fn update_mass_props(&mut self, x: &[f64], sum: &mut EffectorMassProps) {
        let p = &self.params;
        let (m1, m2) = (p.panel1.mass_kg, p.panel2.mass_kg);
        let (d1, d2, l1) = (p.panel1.d_m, p.panel2.d_m, p.l1_m);
        let (i1, i2) = (&p.panel1.inertia_s_kg_m2, &p.panel2.inertia_s_kg_m2);
        let (th1_dot, th2_dot) = (x[THETA1_DOT], x[THETA2_DOT]);
        let [[s11, _, s13], [s21, _, s23]] = self.panel_axes_b(x);
        let c = &mut self.cache;
        c.s11 = s11;
        c.s13 = s13;
        c.s21 = s21;
        c.s23 = s23;
        // Eqs. 6–7: centre-of-mass positions; Eqs. 8 and 10: their body-frame rates.
        let r1 = p.r_h1b_b_m - s11 * d1;
        let r2 = p.r_h1b_b_m - s11 * l1 - s21 * d2;
        c.r_sc1b_b = r1;
        c.r_sc2b_b = r2;
        c.r_prime_sc1b_b = s13 * (d1 * th1_dot);
        c.r_prime_sc2b_b = s13 * (l1 * th1_dot) + s23 * (d2 * (th1_dot + th2_dot));

        sum.mass_kg += m1 + m2;
        sum.first_moment_b_kg_m += r1 * m1 + r2 * m2;
        sum.first_moment_prime_b_kg_m_s += c.r_prime_sc1b_b * m1 + c.r_prime_sc2b_b * m2;
        // [I_Sc1] + [I_Sc2] + m1[r̃1][r̃1]ᵀ + m2[r̃2][r̃2]ᵀ, with [r̃][r̃]ᵀ = |r|² I − r rᵀ.
        let i_b = &mut sum.inertia_pnt_b_b_kg_m2;
        *i_b += self.inertia_const_b;
        for k in 0..3 {
            i_b[(k, k)] += m1 * r1.norm_squared() + m2 * r2.norm_squared();
        }
        i_b.ger(i1.z - i1.x, &s13, &s13, 1.0);
        i_b.ger(i2.z - i2.x, &s23, &s23, 1.0);
        i_b.ger(-m1, &r1, &r1, 1.0);
        i_b.ger(-m2, &r2, &r2, 1.0);
    }

    fn update_contributions(
        &mut self,
        x: &[f64],
        hub: &HubKinematics,
        sum: &mut BackSubContributions,
    ) {
        let p = &self.params;
        let c = &mut self.cache;
        let w = &hub.omega_bn_b;
        let (m1, m2) = (p.panel1.mass_kg, p.panel2.mass_kg);
        let (d1, d2, l1) = (p.panel1.d_m, p.panel2.d_m, p.l1_m);
        let (i1, i2) = (&p.panel1.inertia_s_kg_m2, &p.panel2.inertia_s_kg_m2);
        let (th1, th1_dot, th2, th2_dot) = (x[THETA1], x[THETA1_DOT], x[THETA2], x[THETA2_DOT]);
        let th12_dot = th1_dot + th2_dot;
        let s12 = &self.h12;
        let (s11, s13, s21, s23) = (&c.s11, &c.s13, &c.s21, &c.s23);
        let (r1, r2) = (&c.r_sc1b_b, &c.r_sc2b_b);
        let (r1p, r2p) = (&c.r_prime_sc1b_b, &c.r_prime_sc2b_b);

        // Eq. 121: [A_i].
        let s13_s23 = s13.dot(s23);
        let a11 = i1.y + m1 * d1 * d1 + m2 * l1 * l1 + m2 * l1 * d2 * s13_s23;
        let a12 = m2 * l1 * d2 * s13_s23;
        let a21 = i2.y + m2 * d2 * d2 + m2 * l1 * d2 * s13_s23;
        let a22 = i2.y + m2 * d2 * d2;

        // Eq. 122: rows of [F_i].
        let f1 = s13 * (-(m2 * l1 + m1 * d1));
        let f2 = s23 * (-m2 * d2);
        // Eq. 123a, and 123b with erratum E1 (the m2 d2 term's sign): rows of [G_i], written as
        // vectors using ŝᵀ[r̃] = −(r × ŝ)ᵀ.
        let g1 = -(s12 * i1.y + r1.cross(s13) * (m1 * d1) + r2.cross(s13) * (m2 * l1));
        let g2 = -(s12 * i2.y + r2.cross(s23) * (m2 * d2));

        // Coriolis and centripetal accelerations of the panel centres of mass,
        // 2[ω̃]r′ + [ω̃][ω̃]r (the bracketed terms of Eqs. 124–125).
        let acc1 = w.cross(r1p) * 2.0 + w.cross(&w.cross(r1));
        let acc2 = w.cross(r2p) * 2.0 + w.cross(&w.cross(r2));
        // Centripetal terms of r″ (Eqs. 9 and 11).
        let cent1 = s11 * (d1 * th1_dot * th1_dot);
        let cent2 = s11 * (l1 * th1_dot * th1_dot) + s21 * (d2 * th12_dot * th12_dot);
        // ω_B/N components along the panel axes (Eq. 53).
        let (w_s11, w_s13, w_s21, w_s23) = (w.dot(s11), w.dot(s13), w.dot(s21), w.dot(s23));
        let [u1, u2] = p.motor_torque_nm;
        let (k1, k2) = (p.panel1.k_n_m_rad, p.panel2.k_n_m_rad);
        let (c1, c2) = (p.panel1.c_n_m_s_rad, p.panel2.c_n_m_s_rad);
        // Eq. 124, plus the hinge motor torques: u1 acts on panel 1 (reaction on the hub), u2 on
        // panel 2 (reaction −u2 on panel 1).
        let v1 =
            -(i1.x - i1.z) * w_s13 * w_s11 - k1 * th1 - c1 * th1_dot + k2 * th2 + c2 * th2_dot + u1
                - u2
                - m1 * d1 * s13.dot(&acc1)
                - m2 * l1 * s13.dot(&(acc2 + cent2));
        // Eq. 125 (with E1's sign carried through from Eq. 80).
        let v2 = -(i2.x - i2.z) * w_s23 * w_s21 - k2 * th2 - c2 * th2_dot + u2
            - m2 * d2 * s23.dot(&(acc2 + s11 * (l1 * th1_dot * th1_dot)));

        // Eqs. 129–132: solve [A_i] X = [F_i | G_i | v_i] by Cramer's rule (2×2, det > 0 because
        // [A_i] is a row operation away from the positive-definite Kane mass matrix).
        let inv_det = 1.0 / (a11 * a22 - a12 * a21);
        let xf1 = (f1 * a22 - f2 * a12) * inv_det;
        let xf2 = (f2 * a11 - f1 * a21) * inv_det;
        let xg1 = (g1 * a22 - g2 * a12) * inv_det;
        let xg2 = (g2 * a11 - g1 * a21) * inv_det;
        let xv1 = (v1 * a22 - v2 * a12) * inv_det;
        let xv2 = (v2 * a11 - v1 * a21) * inv_det;
        c.x_f = [xf1, xf2];
        c.x_g = [xg1, xg2];
        c.x_v = [xv1, xv2];

        // Coefficients of θ̈1 and θ̈2 in the hub equations 133 (translation) and 134 (rotation):
        // p_1 = (m1 d1 + m2 l1) ŝ13 + m2 d2 ŝ23 = −(f1 + f2), p_2 = m2 d2 ŝ23 = −f2,
        // q_1 = I12 ŝ12 + m1 d1 r̃1 ŝ13 + I22 ŝ22 + m2 l1 r̃2 ŝ13 + m2 d2 r̃2 ŝ23 = −(g1 + g2),
        // q_2 = I22 ŝ22 + m2 d2 r̃2 ŝ23 = −g2.
        let p1 = -(f1 + f2);
        let p2 = -f2;
        let q1 = -(g1 + g2);
        let q2 = -g2;

        // Eqs. 139, 140, 142, 143 as rank-one updates of the hub sums.
        sum.matrix_a.ger(1.0, &p1, &xf1, 1.0);
        sum.matrix_a.ger(1.0, &p2, &xf2, 1.0);
        sum.matrix_b.ger(1.0, &p1, &xg1, 1.0);
        sum.matrix_b.ger(1.0, &p2, &xg2, 1.0);
        sum.matrix_c.ger(1.0, &q1, &xf1, 1.0);
        sum.matrix_c.ger(1.0, &q2, &xf2, 1.0);
        sum.matrix_d.ger(1.0, &q1, &xg1, 1.0);
        sum.matrix_d.ger(1.0, &q2, &xg2, 1.0);

        // Eq. 141: the remaining (non-second-order) terms of Eq. 133.
        sum.vec_trans -= cent1 * m1 + cent2 * m2 + p1 * xv1 + p2 * xv2;
        // Eq. 144: the remaining terms of Eq. 134.
        let v_rot_144 = w.cross(
            &(s12 * (th1_dot * i1.y + th12_dot * i2.y) + r1.cross(r1p) * m1 + r2.cross(r2p) * m2),
        ) + r1.cross(&cent1) * m1
            + r2.cross(&cent2) * m2
            + q1 * xv1
            + q2 * xv2;
        // This pair's share of Eq. 150's −[I′_sc,B]ω. With ŝ3′ = θ̇ ŝ1, the moving inertia term
        // (I_3 − I_1) ŝ3ŝ3ᵀ has derivative θ̇ (I_3 − I_1)(ŝ1ŝ3ᵀ + ŝ3ŝ1ᵀ); the parallel-axis term
        // m(|r|² I − r rᵀ) has derivative m(2 r·r′ I − r′rᵀ − r r′ᵀ).
        let i_prime_omega = (s11 * w_s13 + s13 * w_s11) * (th1_dot * (i1.z - i1.x))
            + (s21 * w_s23 + s23 * w_s21) * (th12_dot * (i2.z - i2.x))
            + (w * (2.0 * r1.dot(r1p)) - r1p * r1.dot(w) - r1 * r1p.dot(w)) * m1
            + (w * (2.0 * r2.dot(r2p)) - r2p * r2.dot(w) - r2 * r2p.dot(w)) * m2;
        sum.vec_rot -= v_rot_144 + i_prime_omega;
    }

    fn compute_derivatives(&mut self, x: &[f64], hub_accel: &HubAccel, dx: &mut [f64]) {
        let c = &self.cache;
        let (a, w_dot) = (&hub_accel.nongrav_accel_bn_b, &hub_accel.omega_dot_bn_b);
        dx[THETA1] = x[THETA1_DOT];
        dx[THETA2] = x[THETA2_DOT];
        // Eqs. 131–132.
        dx[THETA1_DOT] = c.x_f[0].dot(a) + c.x_g[0].dot(w_dot) + c.x_v[0];
        dx[THETA2_DOT] = c.x_f[1].dot(a) + c.x_g[1].dot(w_dot) + c.x_v[1];
    }

    fn energy_momentum(&self, x: &[f64], omega_bn_b: &Vector3<f64>) -> EnergyMomentum {
        let p = &self.params;
        let (d1, d2, l1) = (p.panel1.d_m, p.panel2.d_m, p.l1_m);
        let (th1_dot, th2_dot) = (x[THETA1_DOT], x[THETA2_DOT]);
        let [[s11, s12, s13], [s21, _, s23]] = self.panel_axes_b(x);
        let r1 = p.r_h1b_b_m - s11 * d1;
        let r2 = p.r_h1b_b_m - s11 * l1 - s21 * d2;
        let r1p = s13 * (d1 * th1_dot);
        let r2p = s13 * (l1 * th1_dot) + s23 * (d2 * (th1_dot + th2_dot));
        let i1 = Self::inertia_b(&p.panel1.inertia_s_kg_m2, &s11, &s12, &s13);
        let i2 = Self::inertia_b(&p.panel2.inertia_s_kg_m2, &s21, &s12, &s23);
        // Panel angular velocities (Eq. 51): ω_S1/N = ω_B/N + θ̇1 ŝ12, ω_S2/N = ω_B/N + (θ̇1 + θ̇2) ŝ22.
        let w1 = omega_bn_b + s12 * th1_dot;
        let w2 = omega_bn_b + s12 * (th1_dot + th2_dot);
        let mut em = EnergyMomentum::rigid_body(p.panel1.mass_kg, &r1, &r1p, &i1, &w1, omega_bn_b);
        em += EnergyMomentum::rigid_body(p.panel2.mass_kg, &r2, &r2p, &i2, &w2, omega_bn_b);
        em.potential_j = 0.5 * p.panel1.k_n_m_rad * x[THETA1] * x[THETA1]
            + 0.5 * p.panel2.k_n_m_rad * x[THETA2] * x[THETA2];
        em
    }
}
