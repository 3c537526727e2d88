//! A reaction wheel: a rigid axisymmetric rotor spinning about a body-fixed axis, driven by a
//! motor whose reaction acts on the hub. Fully coupled: the wheel speed Ω is an integrated state
//! and the rotor's mass and inertia are part of the spacecraft's mass properties.
//!
//! # Model and derivation
//! References: Schaub & Junkins, *Analytical Mechanics of Space Systems* (4th ed.), Section 4.5
//! (spacecraft with reaction wheels), and Alcorn, Allard & Schaub, "Fully Coupled Reaction Wheel
//! Static and Dynamic Imbalance for Spacecraft Jitter Modeling", JGCD 41(6), 2018, Section II
//! (balanced wheel, in the back-substitution form of the hub equations used here). The steps are
//! derived here in this file's notation; the numbers (W1)–(W7) are this file's own.
//!
//! The rotor W has mass `m_w` with its centre of mass fixed at r_W/B, spin axis ĝ_s (B
//! components, constant), spin inertia J_s and transverse inertia J_t about W:
//!
//! - (W1) \[I_W\] = J_s ĝ_s ĝ_sᵀ + J_t (\[I₃\] − ĝ_s ĝ_sᵀ), constant in B; ω_W/N = ω_B/N + Ω ĝ_s.
//! - (W2) Mass properties about B: m_w, first moment m_w r_W/B, inertia \[I_W\] + m_w [r̃]\[r̃\]ᵀ,
//!   r′ = 0 (the rotor's centre of mass does not move in B).
//! - (W3) Spin equation: the spin-axis component of the rotor's angular-momentum rate about W
//!   equals the motor torque u plus the bearing friction τ_f. With H_W = \[I_W\]ω + J_s Ω ĝ_s,
//!   ĝ_sᵀ(ω × H_W) = 0 for an axisymmetric rotor, so J_s (ĝ_sᵀ ω̇ + Ω̇) = u + τ_f, i.e.
//!   **Ω̇ = (u + τ_f)/J_s − ĝ_sᵀ ω̇_B/N**.
//! - (W4) The rotor's share of the system's rotational equation about B adds, beyond what its
//!   inertia in \[I_sc,B\] already carries, J_s Ω̇ ĝ_s + ω × (J_s Ω ĝ_s). Substituting (W3):
//!   **\[D_contr\] = −J_s ĝ_s ĝ_sᵀ** and **v_rot,contr = −ĝ_s (u + τ_f) − ω × (J_s Ω ĝ_s)**.
//!   The translational rows get nothing beyond the mass properties of (W2).
//! - (W5) Energy and momentum: the rotor is a rigid body at r_W/B with inertia \[I_W\] and angular
//!   velocity ω + Ω ĝ_s. The motor and the friction are internal torques, so the total angular
//!   momentum about C is conserved and the rotational energy changes at the rate (u + τ_f) Ω.
//!
//! Motor: the commanded torque (the effector's one input, `motor_torque_nm`) is clipped to
//! ±`max_torque_nm` (flag `TORQUE_LIMITED`), then set to zero if it would drive |Ω| beyond
//! `max_speed_rad_s` (flag `SPEED_LIMITED`). Both are decided once per RK4 step, from the speed at
//! the start of the step ([`StateEffector::begin_step`]), and held over the step.
//!
//! Friction: τ_f = −b Ω − τ_c · clamp(Ω/Ω_c, −1, 1): viscous coefficient b
//! (`viscous_friction_nm_s_rad`) and Coulomb torque τ_c (`coulomb_friction_nm`), the Coulomb part
//! made linear inside |Ω| < Ω_c (`coulomb_band_rad_s`) so a wheel at rest stays at rest instead of
//! chattering across zero. It is evaluated at every RK4 stage.
//!
//! # Imbalance (jitter), off by default
//! With a static imbalance U_s [kg·m] or a dynamic imbalance U_d [kg·m²], the wheel also carries
//! its angle θ (θ̇ = Ω) and applies to the hub the **simple jitter model** of Alcorn et al.,
//! Section II.A: a force and a torque rotating with the wheel,
//! - (W6) F_jitter = U_s Ω² ŵ₂(θ), applied at W, so the torque about B is r_W/B × F_jitter;
//! - (W7) L_jitter = U_d Ω² ŵ₂(θ), with ŵ₂(θ) = cos θ ĝ₂ + sin θ ĝ₃ and (ĝ_s, ĝ₂, ĝ₃) a fixed
//!   right-handed triad in B (ĝ₂ is the unit vector of ĝ_s × x̂_B, or of ĝ_s × ŷ_B when ĝ_s ∥ x̂_B).
//!
//! These enter the hub equations as an external force and torque (v_trans, v_rot). The simple
//! model is a disturbance source: it does not conserve momentum or energy (the fully coupled
//! imbalance model of that paper's Section II.B is not implemented). Use it to see jitter at the
//! wheel harmonics, not for conservation checks.
//!
//! Integrated state: `[Ω]` (balanced) or `[Ω, θ]` (imbalanced).

use nalgebra::{Matrix3, Vector3};

use crate::effector::{
    BackSubContributions, EffectorKind, EffectorMassProps, EnergyMomentum, HubAccel, HubKinematics,
    StateEffector,
};
use flexdyn_kernel::validate::ParamError;
use flexdyn_proto::wheel_flags;

pub mod kind;
mod params;
pub mod plausibility;
pub mod schema;

pub use params::ReactionWheelParams;

/// The reaction wheel's kind: wire tag `effector_kind::REACTION_WHEEL`, CSV columns `rw<k>_…`.
pub const KIND: EffectorKind = EffectorKind {
    name: "reaction_wheel",
    wire_tag: flexdyn_proto::effector_kind::REACTION_WHEEL,
    column_prefix: "rw",
};

/// States of a balanced wheel: Ω [rad/s].
pub const BALANCED_STATE_NAMES: [&str; 1] = ["omega_rad_s"];
/// States of an imbalanced wheel: Ω [rad/s], θ \[rad\].
pub const IMBALANCED_STATE_NAMES: [&str; 2] = ["omega_rad_s", "angle_rad"];
/// The one input: the commanded motor torque [N·m] about +ĝ_s, acting on the rotor (the hub
/// receives its reaction).
pub const INPUT_NAMES: [&str; 1] = ["motor_torque_nm"];
/// Outputs: the motor torque actually applied [N·m] (after the torque and speed limits) and the
/// friction torque at the current speed [N·m].
pub const OUTPUT_NAMES: [&str; 2] = ["motor_torque_nm", "friction_torque_nm"];

const OMEGA: usize = 0;
const ANGLE: usize = 1;

/// A reaction wheel ([`StateEffector`]); see the module docs for the model.
#[derive(Debug, Clone)]
pub struct ReactionWheel {
    params: ReactionWheelParams,
    /// ĝ_s, normalised.
    g_s: Vector3<f64>,
    /// ĝ₂, ĝ₃: the fixed transverse pair of (W7).
    g_2: Vector3<f64>,
    g_3: Vector3<f64>,
    /// m_w r_W/B.
    first_moment_b: Vector3<f64>,
    /// [I_W] (W1) and [I_W] + m_w [r̃][r̃]ᵀ (W2).
    inertia_w_b: Matrix3<f64>,
    inertia_pnt_b_b: Matrix3<f64>,
    /// −J_s ĝ_s ĝ_sᵀ (W4).
    matrix_d: Matrix3<f64>,
    imbalanced: bool,
    /// [N·m] commanded motor torque (the input).
    commanded_nm: f64,
    /// [N·m] motor torque applied over the current step, and the limit flags that produced it.
    applied_nm: f64,
    flags: u32,
    /// [N·m] u + τ_f at the state of the current evaluation, from pass 2 for pass 3.
    spin_torque_nm: f64,
}

impl ReactionWheel {
    /// A wheel from validated parameters; `path` prefixes error fields (`reaction_wheels[0]`).
    pub fn new(params: ReactionWheelParams, path: &str) -> Result<Self, ParamError> {
        params.validate(path)?;
        let g_s = params.spin_axis_b / params.spin_axis_b.norm();
        let x = Vector3::x();
        let helper = if g_s.cross(&x).norm() > 0.5 {
            x
        } else {
            Vector3::y()
        };
        let g_2 = g_s.cross(&helper).normalize();
        let g_3 = g_s.cross(&g_2);
        let ggt = g_s * g_s.transpose();
        let inertia_w_b = ggt * params.j_s_kg_m2 + (Matrix3::identity() - ggt) * params.j_t_kg_m2;
        let r = params.r_wb_b_m;
        let inertia_pnt_b_b = inertia_w_b
            + (Matrix3::from_diagonal_element(r.norm_squared()) - r * r.transpose())
                * params.mass_kg;
        Ok(Self {
            g_s,
            g_2,
            g_3,
            first_moment_b: r * params.mass_kg,
            inertia_w_b,
            inertia_pnt_b_b,
            matrix_d: -ggt * params.j_s_kg_m2,
            imbalanced: params.imbalanced(),
            commanded_nm: 0.0,
            applied_nm: 0.0,
            spin_torque_nm: 0.0,
            flags: 0,
            params,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &ReactionWheelParams {
        &self.params
    }

    /// ĝ_s, the unit spin axis in B.
    pub fn spin_axis_b(&self) -> Vector3<f64> {
        self.g_s
    }

    /// [N·m] friction torque τ_f at wheel speed `omega_rad_s`.
    #[inline(always)]
    pub fn friction_nm(&self, omega_rad_s: f64) -> f64 {
        let p = &self.params;
        let coulomb = if p.coulomb_friction_nm > 0.0 {
            p.coulomb_friction_nm * (omega_rad_s / p.coulomb_band_rad_s).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        -p.viscous_friction_nm_s_rad * omega_rad_s - coulomb
    }

    /// [N·m] the motor torque that applies over a step starting at speed `omega_rad_s`, and its
    /// limit flags.
    fn limit(&self, omega_rad_s: f64) -> (f64, u32) {
        let p = &self.params;
        let mut flags = 0;
        let mut u = self.commanded_nm;
        if u.abs() > p.max_torque_nm {
            u = u.clamp(-p.max_torque_nm, p.max_torque_nm);
            flags |= wheel_flags::TORQUE_LIMITED;
        }
        if (omega_rad_s >= p.max_speed_rad_s && u > 0.0)
            || (omega_rad_s <= -p.max_speed_rad_s && u < 0.0)
        {
            u = 0.0;
            flags |= wheel_flags::SPEED_LIMITED;
        }
        (u, flags)
    }

    /// ŵ₂(θ) of (W7).
    #[inline(always)]
    fn w2(&self, angle_rad: f64) -> Vector3<f64> {
        let (s, c) = angle_rad.sin_cos();
        self.g_2 * c + self.g_3 * s
    }

    /// The jitter force (W6) and torque about B (W6 + W7) at state `x`, zero when balanced.
    #[inline(always)]
    pub fn jitter_b(&self, x: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        if !self.imbalanced {
            return (Vector3::zeros(), Vector3::zeros());
        }
        let omega2 = x[OMEGA] * x[OMEGA];
        let w2 = self.w2(x[ANGLE]);
        let force = w2 * (self.params.static_imbalance_kg_m * omega2);
        let torque = self.params.r_wb_b_m.cross(&force)
            + w2 * (self.params.dynamic_imbalance_kg_m2 * omega2);
        (force, torque)
    }
}

impl StateEffector for ReactionWheel {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn kind(&self) -> EffectorKind {
        KIND
    }

    fn state_len(&self) -> usize {
        if self.imbalanced {
            2
        } else {
            1
        }
    }

    fn state_names(&self) -> &'static [&'static str] {
        if self.imbalanced {
            &IMBALANCED_STATE_NAMES
        } else {
            &BALANCED_STATE_NAMES
        }
    }

    fn input_names(&self) -> &'static [&'static str] {
        &INPUT_NAMES
    }

    fn set_inputs(&mut self, u: &[f64]) {
        if let Some(&v) = u.first() {
            self.commanded_nm = v;
        }
    }

    fn output_names(&self) -> &'static [&'static str] {
        &OUTPUT_NAMES
    }

    fn outputs(&self, x: &[f64], out: &mut [f64]) -> u32 {
        out[0] = self.applied_nm;
        out[1] = self.friction_nm(x[OMEGA]);
        self.flags
    }

    fn uses_begin_step(&self) -> bool {
        true
    }

    fn begin_step(&mut self, x: &[f64]) {
        (self.applied_nm, self.flags) = self.limit(x[OMEGA]);
    }

    fn parameters(&self, x0: &[f64], out: &mut Vec<(String, f64)>) {
        let p = &self.params;
        let mut put = |k: &str, v: f64| out.push((k.to_owned(), v));
        for i in 0..3 {
            put(&format!("spin_axis_b[{i}]"), p.spin_axis_b[i]);
            put(&format!("r_wb_b_m[{i}]"), p.r_wb_b_m[i]);
        }
        put("mass_kg", p.mass_kg);
        put("j_s_kg_m2", p.j_s_kg_m2);
        put("j_t_kg_m2", p.j_t_kg_m2);
        put("max_torque_nm", p.max_torque_nm);
        put("max_speed_rad_s", p.max_speed_rad_s);
        put("omega_rad_s", x0[0]);
        put("viscous_friction_nm_s_rad", p.viscous_friction_nm_s_rad);
        put("coulomb_friction_nm", p.coulomb_friction_nm);
        put("coulomb_band_rad_s", p.coulomb_band_rad_s);
        put("static_imbalance_kg_m", p.static_imbalance_kg_m);
        put("dynamic_imbalance_kg_m2", p.dynamic_imbalance_kg_m2);
    }

    fn initial_state(&self, x: &mut [f64]) {
        x[OMEGA] = self.params.omega_rad_s;
        if self.imbalanced {
            x[ANGLE] = 0.0;
        }
    }

    fn update_mass_props(&mut self, _x: &[f64], sum: &mut EffectorMassProps) {
        // (W2): constant in B.
        sum.mass_kg += self.params.mass_kg;
        sum.first_moment_b_kg_m += self.first_moment_b;
        sum.inertia_pnt_b_b_kg_m2 += self.inertia_pnt_b_b;
    }

    fn update_contributions(
        &mut self,
        x: &[f64],
        hub: &HubKinematics,
        sum: &mut BackSubContributions,
    ) {
        // (W4)
        let omega = x[OMEGA];
        let spin_torque = self.applied_nm + self.friction_nm(omega);
        self.spin_torque_nm = spin_torque;
        sum.matrix_d += self.matrix_d;
        sum.vec_rot -= self.g_s * spin_torque
            + hub
                .omega_bn_b
                .cross(&(self.g_s * (self.params.j_s_kg_m2 * omega)));
        if self.imbalanced {
            // (W6), (W7): external to the hub equations.
            let (force, torque) = self.jitter_b(x);
            sum.vec_trans += force;
            sum.vec_rot += torque;
        }
    }

    fn compute_derivatives(&mut self, x: &[f64], hub_accel: &HubAccel, dx: &mut [f64]) {
        // (W3)
        // u + τ_f as pass 2 computed it at this same x.
        dx[OMEGA] =
            self.spin_torque_nm / self.params.j_s_kg_m2 - self.g_s.dot(&hub_accel.omega_dot_bn_b);
        if self.imbalanced {
            dx[ANGLE] = x[OMEGA];
        }
    }

    fn energy_momentum(&self, x: &[f64], omega_bn_b: &Vector3<f64>) -> EnergyMomentum {
        // (W5)
        let omega_w = omega_bn_b + self.g_s * x[OMEGA];
        EnergyMomentum::rigid_body(
            self.params.mass_kg,
            &self.params.r_wb_b_m,
            &Vector3::zeros(),
            &self.inertia_w_b,
            &omega_w,
            omega_bn_b,
        )
    }

    /// The held command, the torque applied after clipping this step, its flags and the spin
    /// torque.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        // Named field by field: a new field does not compile until it is listed here or marked
        // as configuration (`_`).
        let Self {
            params: _,
            g_s: _,
            g_2: _,
            g_3: _,
            first_moment_b: _,
            inertia_w_b: _,
            inertia_pnt_b_b: _,
            matrix_d: _,
            imbalanced: _,
            commanded_nm,
            applied_nm,
            flags,
            spin_torque_nm,
        } = self;
        a.put(commanded_nm);
        a.put(applied_nm);
        a.put(flags);
        a.put(spin_torque_nm);
    }
}
