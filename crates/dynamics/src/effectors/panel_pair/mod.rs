//! Dual-linked hinged rigid panels: the state effector of Allard & Schaub, Sections III.C and V.
//!
//! Geometry (docs/models/physics.md; docs/errata.md):
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

use crate::effector::{
    BackSubContributions, EffectorKind, EffectorMassProps, EnergyMomentum, HubAccel, HubKinematics,
    StateEffector,
};
pub mod kind;
mod params;
pub mod schema;

use flexdyn_kernel::validate::ParamError;
pub use params::{PanelPairInitial, PanelPairParams, PanelParams};

/// The panel pair's kind: wire tag `effector_kind::PANEL_PAIR`, CSV columns `pair<k>_…`.
pub const KIND: EffectorKind = EffectorKind {
    name: "panel_pair",
    wire_tag: flexdyn_proto::effector_kind::PANEL_PAIR,
    column_prefix: "pair",
};

/// State order: θ1 \[rad\], θ̇1 [rad/s], θ2 \[rad\], θ̇2 [rad/s].
pub const STATE_NAMES: [&str; 4] = ["theta1", "theta1_dot", "theta2", "theta2_dot"];

/// The panel frames at one state: [S1 B] = M2(θ1)[H1 B], [S2 B] = M2(φ)[S1 B], φ = θ2 + θ_H2S1.
#[derive(Debug, Clone, Copy)]
struct Frames {
    /// (sin, cos) of θ1 and of φ.
    sin1: f64,
    cos1: f64,
    sin_phi: f64,
    cos_phi: f64,
    /// Panel-1 axes ŝ11, ŝ13 and panel-2 axes ŝ21, ŝ23 in B components (ŝ12 = ŝ22 = ĥ12).
    s11: Vector3<f64>,
    s13: Vector3<f64>,
    s21: Vector3<f64>,
    s23: Vector3<f64>,
}

impl Default for Frames {
    fn default() -> Self {
        let z = Vector3::zeros();
        Self {
            sin1: 0.0,
            cos1: 1.0,
            sin_phi: 0.0,
            cos_phi: 1.0,
            s11: z,
            s13: z,
            s21: z,
            s23: z,
        }
    }
}

/// Geometry and back-substitution terms cached between the passes of one evaluation.
#[derive(Debug, Clone, Copy)]
struct Cache {
    /// Panel frames at the evaluated state.
    f: Frames,
    /// r_Sc1/B and r_Sc2/B (Eqs. 6–7).
    r_sc1b_b: Vector3<f64>,
    r_sc2b_b: Vector3<f64>,
    /// Solutions of [A_i] X = [F_i | G_i | v_i] (rows 1 and 2): θ̈_k = x_f_k·r̈ + x_g_k·ω̇ + x_v_k.
    x_f: [Vector3<f64>; 2],
    x_g: [Vector3<f64>; 2],
    x_v: [f64; 2],
}

impl Default for Cache {
    fn default() -> Self {
        let z = Vector3::zeros();
        Self {
            f: Frames::default(),
            r_sc1b_b: z,
            r_sc2b_b: z,
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
    /// [m²] r_H1/B × ĥ11 and r_H1/B × ĥ13: every r_H1 × ŝ is a rotation of these two.
    rho1: Vector3<f64>,
    rho3: Vector3<f64>,
    /// [m] ĥ11 · r_H1/B and ĥ13 · r_H1/B.
    h11_rh: f64,
    h13_rh: f64,
    /// [kg·m] μ1 = m1 d1 + m2 l1 and μ2 = m2 d2: the first moments about H1 of the two panels'
    /// rotation about hinge 1, and of panel 2 about H2. [F_i] = −[μ1 ŝ13ᵀ; μ2 ŝ23ᵀ] (Eq. 122).
    mu1: f64,
    mu2: f64,
    /// [kg·m²] θ-independent parts of Eq. 121: a11 = a11_0 + κ cos φ, a12 = κ cos φ,
    /// a21 = a22 + κ cos φ, a22, with κ = m2 l1 d2 and ŝ13·ŝ23 = cos φ.
    a11_0: f64,
    a22: f64,
    kappa: f64,
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
        let r_h = params.r_h1b_b_m;
        let (h11, h13): (Vector3<f64>, Vector3<f64>) = (h.row(0).transpose(), h.row(2).transpose());
        let (m1, m2) = (params.panel1.mass_kg, params.panel2.mass_kg);
        let (d1, d2, l1) = (params.panel1.d_m, params.panel2.d_m, params.l1_m);
        Ok(Self {
            inertia_const_b,
            rho1: r_h.cross(&h11),
            rho3: r_h.cross(&h13),
            h11_rh: h11.dot(&r_h),
            h13_rh: h13.dot(&r_h),
            mu1: m1 * d1 + m2 * l1,
            mu2: m2 * d2,
            a11_0: i1.y + m1 * d1 * d1 + m2 * l1 * l1,
            a22: i2.y + m2 * d2 * d2,
            kappa: m2 * l1 * d2,
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
        let f = self.frames(x);
        [[f.s11, self.h12, f.s13], [f.s21, self.h12, f.s23]]
    }

    /// The panel frames at state `x`; M2(θ2) M2(θ_H2S1) = M2(θ2 + θ_H2S1) is expanded with the
    /// angle-sum identities, so only θ1 and θ2 need a `sin_cos`.
    #[inline(always)]
    fn frames(&self, x: &[f64]) -> Frames {
        let (sin1, cos1) = x[THETA1].sin_cos();
        let (sn2, cs2) = x[THETA2].sin_cos();
        let sin_phi = sn2 * self.cos_h2s1 + cs2 * self.sin_h2s1;
        let cos_phi = cs2 * self.cos_h2s1 - sn2 * self.sin_h2s1;
        let s11 = self.h11 * cos1 - self.h13 * sin1;
        let s13 = self.h11 * sin1 + self.h13 * cos1;
        let s21 = s11 * cos_phi - s13 * sin_phi;
        let s23 = s11 * sin_phi + s13 * cos_phi;
        Frames {
            sin1,
            cos1,
            sin_phi,
            cos_phi,
            s11,
            s13,
            s21,
            s23,
        }
    }

    /// Eqs. 6–7: r_Sc1/B = r_H1/B − d1 ŝ11 and r_Sc2/B = r_H1/B − l1 ŝ11 − d2 ŝ21.
    #[inline(always)]
    fn com_positions(
        &self,
        s11: &Vector3<f64>,
        s21: &Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let p = &self.params;
        (
            p.r_h1b_b_m - s11 * p.panel1.d_m,
            p.r_h1b_b_m - s11 * p.l1_m - s21 * p.panel2.d_m,
        )
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

/// `m += diag(d) + Σ α v vᵀ` for symmetric rank-one terms, computing each product once.
#[inline(always)]
fn add_symmetric_rank_ones(m: &mut Matrix3<f64>, d: f64, terms: &[(f64, &Vector3<f64>); 4]) {
    let (mut xx, mut yy, mut zz, mut xy, mut xz, mut yz) = (d, d, d, 0.0, 0.0, 0.0);
    for (alpha, v) in terms {
        let (ax, ay, az) = (alpha * v.x, alpha * v.y, alpha * v.z);
        xx += ax * v.x;
        yy += ay * v.y;
        zz += az * v.z;
        xy += ax * v.y;
        xz += ax * v.z;
        yz += ay * v.z;
    }
    m[(0, 0)] += xx;
    m[(1, 1)] += yy;
    m[(2, 2)] += zz;
    m[(0, 1)] += xy;
    m[(1, 0)] += xy;
    m[(0, 2)] += xz;
    m[(2, 0)] += xz;
    m[(1, 2)] += yz;
    m[(2, 1)] += yz;
}

/// `m += a1 b1ᵀ + a2 b2ᵀ` for a sum known to be symmetric: computes the upper triangle once and
/// mirrors it, so the result is exactly symmetric.
#[inline(always)]
fn add_symmetric_rank_two(
    m: &mut Matrix3<f64>,
    a1: &Vector3<f64>,
    b1: &Vector3<f64>,
    a2: &Vector3<f64>,
    b2: &Vector3<f64>,
) {
    for i in 0..3 {
        m[(i, i)] += a1[i] * b1[i] + a2[i] * b2[i];
        for j in (i + 1)..3 {
            let v = a1[i] * b1[j] + a2[i] * b2[j];
            m[(i, j)] += v;
            m[(j, i)] += v;
        }
    }
}

impl StateEffector for PanelPair {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn kind(&self) -> EffectorKind {
        KIND
    }

    fn state_len(&self) -> usize {
        4
    }

    fn state_names(&self) -> &'static [&'static str] {
        &STATE_NAMES
    }

    fn parameters(&self, x0: &[f64], out: &mut Vec<(String, f64)>) {
        let p = &self.params;
        let mut put = |k: String, v: f64| out.push((k, v));
        for i in 0..3 {
            put(format!("r_h1b_b_m[{i}]"), p.r_h1b_b_m[i]);
            for j in 0..3 {
                put(format!("dcm_h1b[{i}][{j}]"), p.dcm_h1b[(i, j)]);
            }
        }
        put("theta_h2s1_rad".into(), p.theta_h2s1_rad);
        put("motor_torque_nm[0]".into(), p.motor_torque_nm[0]);
        put("motor_torque_nm[1]".into(), p.motor_torque_nm[1]);
        put("panel1.l_m".into(), p.l1_m);
        let states = [(THETA1, THETA1_DOT), (THETA2, THETA2_DOT)];
        for (name, panel, (th, th_dot)) in [
            ("panel1", &p.panel1, states[0]),
            ("panel2", &p.panel2, states[1]),
        ] {
            put(format!("{name}.mass_kg"), panel.mass_kg);
            for i in 0..3 {
                put(
                    format!("{name}.inertia_s_kg_m2[{i}]"),
                    panel.inertia_s_kg_m2[i],
                );
            }
            put(format!("{name}.d_m"), panel.d_m);
            put(format!("{name}.k_nm_rad"), panel.k_nm_rad);
            put(format!("{name}.c_nm_s_rad"), panel.c_nm_s_rad);
            put(format!("{name}.theta_rad"), x0[th]);
            put(format!("{name}.theta_dot_rad_s"), x0[th_dot]);
        }
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
        let (i1, i2) = (&p.panel1.inertia_s_kg_m2, &p.panel2.inertia_s_kg_m2);
        let (th1_dot, th12_dot) = (x[THETA1_DOT], x[THETA1_DOT] + x[THETA2_DOT]);
        let f = self.frames(x);
        let (r1, r2) = self.com_positions(&f.s11, &f.s21);
        let c = &mut self.cache;
        c.f = f;
        c.r_sc1b_b = r1;
        c.r_sc2b_b = r2;

        sum.mass_kg += m1 + m2;
        sum.first_moment_b_kg_m += r1 * m1 + r2 * m2;
        // Eqs. 8 and 10: m1 r′_Sc1 + m2 r′_Sc2 = μ1 θ̇1 ŝ13 + μ2 (θ̇1 + θ̇2) ŝ23.
        sum.first_moment_prime_b_kg_m_s +=
            f.s13 * (self.mu1 * th1_dot) + f.s23 * (self.mu2 * th12_dot);
        // [I_Sc1] + [I_Sc2] + m1[r̃1][r̃1]ᵀ + m2[r̃2][r̃2]ᵀ, with [r̃][r̃]ᵀ = |r|² I − r rᵀ: the constant
        // part plus four symmetric rank-one terms.
        let i_b = &mut sum.inertia_pnt_b_b_kg_m2;
        *i_b += self.inertia_const_b;
        add_symmetric_rank_ones(
            i_b,
            m1 * r1.norm_squared() + m2 * r2.norm_squared(),
            &[
                (i1.z - i1.x, &f.s13),
                (i2.z - i2.x, &f.s23),
                (-m1, &r1),
                (-m2, &r2),
            ],
        );
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
        let (mu1, mu2) = (self.mu1, self.mu2);
        let e = &self.h12; // ŝ12 = ŝ22 = ĥ12
        let f = &c.f;
        let (s11, s13, s21, s23) = (&f.s11, &f.s13, &f.s21, &f.s23);
        let (r1, r2) = (&c.r_sc1b_b, &c.r_sc2b_b);
        let (sn, cs) = (f.sin_phi, f.cos_phi);

        // Frame identities used below, for the right-handed triads (ŝ11, ê, ŝ13) and (ŝ21, ê, ŝ23)
        // with ŝ21 = cos φ ŝ11 − sin φ ŝ13 and ŝ23 = sin φ ŝ11 + cos φ ŝ13:
        //   ŝ11 × ŝ13 = −ê, ŝ21 × ŝ23 = −ê, ŝ13 × ŝ21 = cos φ ê, ŝ13 × ŝ23 = sin φ ê,
        //   ŝ11 × ŝ21 = sin φ ê, ŝ11 × ŝ23 = −cos φ ê; ŝ13·ŝ21 = −sin φ, ŝ13·ŝ23 = cos φ,
        //   ŝ11·ŝ23 = sin φ. With R_jk = r_H1/B × ŝ_jk this gives, from Eqs. 6–7:
        //   r1 × ŝ13 = R13 + d1 ê,  r2 × ŝ13 = R13 + (l1 + d2 cos φ) ê,
        //   r2 × ŝ23 = R23 + (d2 + l1 cos φ) ê,  r1 × ŝ11 = R11,
        //   r2 × ŝ11 = R11 + d2 sin φ ê,  r2 × ŝ21 = R21 − l1 sin φ ê.
        let r11 = self.rho1 * f.cos1 - self.rho3 * f.sin1;
        let r13 = self.rho1 * f.sin1 + self.rho3 * f.cos1;
        let r21 = r11 * cs - r13 * sn;
        let r23 = r11 * sn + r13 * cs;
        let s13_rh = self.h11_rh * f.sin1 + self.h13_rh * f.cos1;
        let s11_rh = self.h11_rh * f.cos1 - self.h13_rh * f.sin1;
        let s23_rh = s11_rh * sn + s13_rh * cs;

        // Eq. 121: [A_i], with ŝ13·ŝ23 = cos φ.
        let a12 = self.kappa * cs;
        let a11 = self.a11_0 + a12;
        let a22 = self.a22;
        let a21 = a22 + a12;
        // Eq. 122: rows of [F_i] are −μ1 ŝ13 and −μ2 ŝ23.
        // Eq. 123a, and 123b with erratum E1: with the identities above, the rows of [G_i] are
        //   g1 = −[I12 ê + m1 d1 r1 × ŝ13 + m2 l1 r2 × ŝ13] = −(μ1 R13 + a11 ê),
        //   g2 = −[I22 ê + m2 d2 r2 × ŝ23] = −(μ2 R23 + a21 ê).

        // ω_B/N components (Eq. 53) and the dot products of the Coriolis/centripetal terms.
        let (w11, w13, w21, w23, we) = (w.dot(s11), w.dot(s13), w.dot(s21), w.dot(s23), w.dot(e));
        let w_sq = w.norm_squared();
        let w_rh = w.dot(&p.r_h1b_b_m);
        let w_r1 = w_rh - d1 * w11;
        let w_r2 = w_rh - l1 * w11 - d2 * w21;
        // ŝ13·(2ω × r′1 + ω × (ω × r1)) (r′1 ∥ ŝ13 drops out; ŝ13·r1 = ŝ13·r_H1):
        let s13_acc1 = w13 * w_r1 - w_sq * s13_rh;
        // ŝ13·(2ω × r′2 + ω × (ω × r2) + l1 θ̇1² ŝ11 + d2 θ̇12² ŝ21):
        let s13_acc2 = -2.0 * d2 * th12_dot * sn * we + w13 * w_r2
            - w_sq * (s13_rh + d2 * sn)
            - d2 * th12_dot * th12_dot * sn;
        // ŝ23·(2ω × r′2 + ω × (ω × r2) + l1 θ̇1² ŝ11):
        let s23_acc2 = 2.0 * l1 * th1_dot * sn * we + w23 * w_r2 - w_sq * (s23_rh - l1 * sn)
            + l1 * th1_dot * th1_dot * sn;
        let [u1, u2] = p.motor_torque_nm;
        let (k1, k2) = (p.panel1.k_nm_rad, p.panel2.k_nm_rad);
        let (c1, c2) = (p.panel1.c_nm_s_rad, p.panel2.c_nm_s_rad);
        // Eq. 124, plus the hinge motor torques: u1 acts on panel 1 (reaction on the hub), u2 on
        // panel 2 (reaction −u2 on panel 1).
        let v1 =
            -(i1.x - i1.z) * w13 * w11 - k1 * th1 - c1 * th1_dot + k2 * th2 + c2 * th2_dot + u1
                - u2
                - m1 * d1 * s13_acc1
                - m2 * l1 * s13_acc2;
        // Eq. 125 (with E1's sign carried through from Eq. 80).
        let v2 = -(i2.x - i2.z) * w23 * w21 - k2 * th2 - c2 * th2_dot + u2 - m2 * d2 * s23_acc2;

        // Eqs. 129–132: [A_i] X = [F_i | G_i | v_i] by Cramer's rule (2×2, det > 0 because [A_i]
        // is a row operation away from the positive-definite Kane mass matrix). Written out,
        //   x_f1 = −α11 ŝ13 + α12 ŝ23,       x_f2 = α21 ŝ13 − α22 ŝ23,
        //   x_g1 = −α11 R13 + α12 R23 − ê,   x_g2 = α21 R13 − α22 R23,
        // with α11 = a22 μ1/det, α12 = a12 μ2/det, α21 = a21 μ1/det, α22 = a11 μ2/det.
        let inv_det = 1.0 / (a11 * a22 - a12 * a21);
        let (al11, al12) = (a22 * mu1 * inv_det, a12 * mu2 * inv_det);
        let (al21, al22) = (a21 * mu1 * inv_det, a11 * mu2 * inv_det);
        let xf1 = s23 * al12 - s13 * al11;
        let xf2 = s13 * al21 - s23 * al22;
        let xg1 = r23 * al12 - r13 * al11 - e;
        let xg2 = r13 * al21 - r23 * al22;
        let xv1 = (v1 * a22 - v2 * a12) * inv_det;
        let xv2 = (v2 * a11 - v1 * a21) * inv_det;
        c.x_f = [xf1, xf2];
        c.x_g = [xg1, xg2];
        c.x_v = [xv1, xv2];

        // Coefficients of θ̈1 and θ̈2 in the hub equations 133 (translation) and 134 (rotation):
        // p1 = −(f1 + f2) = μ1 ŝ13 + μ2 ŝ23, p2 = −f2 = μ2 ŝ23,
        // q1 = −(g1 + g2) = μ1 R13 + μ2 R23 + (a11 + a21) ê, q2 = −g2 = μ2 R23 + a21 ê.
        let p2 = s23 * mu2;
        let p1 = s13 * mu1 + p2;
        let q2 = r23 * mu2 + e * a21;
        let q1 = r13 * mu1 + q2 + e * a11;

        // Eqs. 139, 140, 142, 143 as rank-one updates of the hub sums. [A_i] = T⁻¹ M_θθ with
        // T = [[1, 1], [0, 1]] (Kane's θ1 row is Eq. 119 + Eq. 120, docs/errata.md) and M_θθ the
        // symmetric Kane block, so [A_contr] = −(T F)ᵀ M_θθ⁻¹ (T F) and [D_contr] are symmetric
        // and [C_contr] = [B_contr]ᵀ: the same symmetry that erratum E2 restores in the hub's
        // [C] = m_sc[c̃] + [C_contr] = [B]ᵀ. Only their independent entries are computed.
        add_symmetric_rank_two(&mut sum.matrix_a, &p1, &xf1, &p2, &xf2);
        add_symmetric_rank_two(&mut sum.matrix_d, &q1, &xg1, &q2, &xg2);
        let b_contr = p1 * xg1.transpose() + p2 * xg2.transpose();
        sum.matrix_b += b_contr;
        sum.matrix_c += b_contr.transpose();

        // Eq. 141: m1 d1 θ̇1² ŝ11 + m2 (l1 θ̇1² ŝ11 + d2 θ̇12² ŝ21) = μ1 θ̇1² ŝ11 + μ2 θ̇12² ŝ21.
        let (th1_dot_sq, th12_dot_sq) = (th1_dot * th1_dot, th12_dot * th12_dot);
        sum.vec_trans -= s11 * (mu1 * th1_dot_sq) + s21 * (mu2 * th12_dot_sq) + p1 * xv1 + p2 * xv2;
        // Eq. 144. The bodies' relative angular momentum about B,
        // θ̇1 I12 ê + θ̇12 I22 ê + m1 r1 × r′1 + m2 r2 × r′2, equals q1 θ̇1 + q2 θ̇2 by the identities
        // above; the centripetal torques m1 r1 × (d1 θ̇1² ŝ11) + m2 r2 × (l1 θ̇1² ŝ11 + d2 θ̇12² ŝ21)
        // equal μ1 θ̇1² R11 + μ2 θ̇12² R21 + κ sin φ (θ̇1² − θ̇12²) ê.
        let v_rot_144 = w.cross(&(q1 * th1_dot + q2 * th2_dot))
            + r11 * (mu1 * th1_dot_sq)
            + r21 * (mu2 * th12_dot_sq)
            + e * (self.kappa * sn * (th1_dot_sq - th12_dot_sq))
            + q1 * xv1
            + q2 * xv2;
        // This pair's share of Eq. 150's −[I′_sc,B]ω. With ŝ3′ = θ̇ ŝ1, the moving inertia term
        // (I_3 − I_1) ŝ3ŝ3ᵀ has derivative θ̇ (I_3 − I_1)(ŝ1ŝ3ᵀ + ŝ3ŝ1ᵀ); the parallel-axis term
        // m(|r|² I − r rᵀ) has derivative m(2 r·r′ I − r′rᵀ − r r′ᵀ), with r′1 = d1 θ̇1 ŝ13 and
        // r′2 = l1 θ̇1 ŝ13 + d2 θ̇12 ŝ23 (Eqs. 8, 10).
        let r2_r2p = l1 * th1_dot * (s13_rh + d2 * sn) + d2 * th12_dot * (s23_rh - l1 * sn);
        let r2p = s13 * (l1 * th1_dot) + s23 * (d2 * th12_dot);
        let i_prime_omega = (s11 * w13 + s13 * w11) * (th1_dot * (i1.z - i1.x))
            + (s21 * w23 + s23 * w21) * (th12_dot * (i2.z - i2.x))
            + (w * (2.0 * s13_rh) - s13 * w_r1 - r1 * w13) * (m1 * d1 * th1_dot)
            + (w * (2.0 * r2_r2p) - r2p * w_r2 - r2 * r2p.dot(w)) * m2;
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
        let (r1, r2) = self.com_positions(&s11, &s21);
        let r1p = s13 * (d1 * th1_dot);
        let r2p = s13 * (l1 * th1_dot) + s23 * (d2 * (th1_dot + th2_dot));
        let i1 = Self::inertia_b(&p.panel1.inertia_s_kg_m2, &s11, &s12, &s13);
        let i2 = Self::inertia_b(&p.panel2.inertia_s_kg_m2, &s21, &s12, &s23);
        // Panel angular velocities (Eq. 51): ω_S1/N = ω_B/N + θ̇1 ŝ12, ω_S2/N = ω_B/N + (θ̇1 + θ̇2) ŝ22.
        let w1 = omega_bn_b + s12 * th1_dot;
        let w2 = omega_bn_b + s12 * (th1_dot + th2_dot);
        let mut em = EnergyMomentum::rigid_body(p.panel1.mass_kg, &r1, &r1p, &i1, &w1, omega_bn_b);
        em += EnergyMomentum::rigid_body(p.panel2.mass_kg, &r2, &r2p, &i2, &w2, omega_bn_b);
        em.potential_j = 0.5 * p.panel1.k_nm_rad * x[THETA1] * x[THETA1]
            + 0.5 * p.panel2.k_nm_rad * x[THETA2] * x[THETA2];
        em
    }

    /// Nothing beyond the integrated states: the cached geometry is recomputed from `x`.
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
}
