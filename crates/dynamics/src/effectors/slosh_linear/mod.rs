//! Fuel slosh as a linear spring-mass-damper: a particle of mass m that moves along a body-fixed
//! unit axis p̂ through its rest point P, held by a spring k and a damper c. It is the lumped-mass
//! slosh model of Allard, Diaz Ramos & Schaub, "Spacecraft Dynamics Integrating Hinged Solar
//! Panels and Lumped-Mass Fuel Slosh Model", AIAA/AAS Astrodynamics Specialist Conference, Long
//! Beach CA, 2016, in the back-substitution form of Basilisk's `linearSpringMassDamper` module
//! (its technical note `Basilisk-LINEARSPRINGMASSDAMPER-20180102`, Section "Model Description",
//! Eqs. `sloshaccel3`–`sloshaccel5` for the particle and `Final5`/`Final6` for the hub; the
//! equation labels are the note's LaTeX labels, which its PDF numbers consecutively).
//!
//! # Model and derivation
//! The steps are derived here in this file's notation; the numbers (L1)–(L7) are this file's own
//! and are cited beside the code.
//!
//! - (L1) Position of the particle Pc: r_Pc/B = r_P/B + ρ p̂, so r′_Pc/B = ρ̇ p̂ and
//!   r″_Pc/B = ρ̈ p̂ (p̂ and r_P/B are fixed in B).
//! - (L2) Newton's law for the particle (note, Eq. `sloshaccel3`), projected on p̂ where the
//!   constraint force has no component (Eq. `sloshaccel4`):
//!   m (p̂ᵀ r̈_B/N + ρ̈ + p̂ᵀ(ω̇ × r) + 2 p̂ᵀ(ω × r′) + p̂ᵀ(ω × (ω × r))) = −k ρ − c ρ̇,
//!   with r = r_Pc/B and ω = ω_B/N. Gravity is a uniform field (it acts at the system's centre of
//!   mass, `docs/models/physics.md`) and drops out when r̈_B/N is the non-gravitational
//!   acceleration [`HubAccel::nongrav_accel_bn_b`]. The Coriolis term vanishes: r′ ∥ p̂, so
//!   p̂ᵀ(ω × r′) = 0 (Basilisk evaluates it; it is zero up to round-off).
//! - (L3) Hence ρ̈ = a_ρᵀ r̈_B/N + b_ρᵀ ω̇ + c_ρ (Eq. `sloshaccel5` solved for ρ̈), with
//!   **a_ρ = −p̂**, **b_ρ = p̂ × r** (from p̂ᵀ(ω̇ × r) = −(p̂ × r)ᵀ ω̇) and
//!   **c_ρ = −(k ρ + c ρ̇)/m − p̂ᵀ(ω × (ω × r))**.
//! - (L4) The particle's mass m r″ = m ρ̈ p̂ enters the hub's translational equation through
//!   m_sc c″ (note, Eq. `Final5`). Substituting (L3):
//!   **\[A_contr\] = m p̂ a_ρᵀ = −m p̂p̂ᵀ**, **\[B_contr\] = m p̂ b_ρᵀ**, **v_trans,contr = −m c_ρ p̂**.
//! - (L5) Its m r × r″ = −m ρ̈ b_ρ enters the rotational equation about B (Eq. `Final6`), which also
//!   carries −ω × (m r × r′) and the particle's share of −\[I′_sc,B\]ω:
//!   **\[C_contr\] = −m b_ρ a_ρᵀ = \[B_contr\]ᵀ**, **\[D_contr\] = −m b_ρ b_ρᵀ**,
//!   **v_rot,contr = m c_ρ b_ρ − ω × (m r × r′) − \[I′\]ω**, where \[I\] = m(|r|²\[1\] − r rᵀ) gives
//!   \[I′\]ω = m(2 (r·r′) ω − r′ (r·ω) − r (r′·ω)).
//! - (L6) Mass properties about B: m, m r, m r′ = m ρ̇ p̂, \[I\] = m \[r̃\]\[r̃\]ᵀ (a point mass).
//! - (L7) Energy and momentum: a point mass at r moving at r′ in B, plus the spring's ½ k ρ². The
//!   spring and the damper are internal forces: the angular momentum about the system's centre of
//!   mass is conserved, and with c = 0 so is the energy.
//!
//! # Parameters from a tank's fill level
//! The sloshing mass, its stiffness and its rest point come from the tank and how full it is:
//! [`crate::slosh_tank`] maps a fill level to them (first lateral mode of an upright cylindrical
//! tank), and [`SloshLinearEntry::resolve`] builds a particle from that mapping (a `tank` table in
//! the configuration).
//!
//! Integrated state: `[ρ, ρ̇]`.

use nalgebra::Vector3;

use crate::effector::{
    point_mass_i_prime_omega, BackSubContributions, EffectorKind, EffectorMassProps,
    EnergyMomentum, HubAccel, HubKinematics, StateEffector,
};
use flexdyn_kernel::validate::ParamError;

pub mod kind;
mod params;
pub mod schema;
#[cfg(test)]
mod tests;

pub use params::{SloshLinearEntry, SloshLinearParams, SloshLinearSource};

/// The linear slosh kind: wire tag `effector_kind::SLOSH_LINEAR`, CSV columns `slosh<k>_…`.
pub const KIND: EffectorKind = EffectorKind {
    name: "slosh_linear",
    wire_tag: flexdyn_proto::effector_kind::SLOSH_LINEAR,
    column_prefix: "slosh",
};

/// State order: ρ \[m\], ρ̇ \[m/s\].
pub const STATE_NAMES: [&str; 2] = ["rho_m", "rho_dot_m_s"];

/// Index of ρ in the particle's state slice.
pub const RHO: usize = 0;
/// Index of ρ̇.
pub const RHO_DOT: usize = 1;

/// Geometry and back-substitution terms cached between the passes of one evaluation.
#[derive(Debug, Clone, Copy)]
struct Cache {
    /// \[m\] r_Pc/B (L1).
    r_pcb_b: Vector3<f64>,
    /// \[m\] b_ρ = p̂ × r_Pc/B (L3).
    b_rho: Vector3<f64>,
    /// \[m/s²\] c_ρ (L3).
    c_rho: f64,
}

/// A linear spring-mass-damper slosh particle ([`StateEffector`]); see the module docs.
#[derive(Debug, Clone)]
pub struct SloshLinear {
    params: SloshLinearParams,
    /// −m p̂p̂ᵀ (L4), constant.
    matrix_a: nalgebra::Matrix3<f64>,
    cache: Cache,
}

impl SloshLinear {
    /// A particle from validated parameters; `path` prefixes error fields (`slosh_linear[0]`).
    pub fn new(params: SloshLinearParams, path: &str) -> Result<Self, ParamError> {
        params.validate(path)?;
        let p = params.p_hat_b;
        Ok(Self {
            matrix_a: -(p * p.transpose()) * params.mass_kg,
            cache: Cache {
                r_pcb_b: params.r_pb_b_m,
                b_rho: Vector3::zeros(),
                c_rho: 0.0,
            },
            params,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &SloshLinearParams {
        &self.params
    }

    /// (L1): r_Pc/B at displacement `rho_m`.
    #[inline(always)]
    pub fn r_pcb_b_m(&self, rho_m: f64) -> Vector3<f64> {
        self.params.r_pb_b_m + self.params.p_hat_b * rho_m
    }
}

impl StateEffector for SloshLinear {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn kind(&self) -> EffectorKind {
        KIND
    }

    fn state_names(&self) -> &'static [&'static str] {
        &STATE_NAMES
    }

    fn parameters(&self, x0: &[f64], out: &mut Vec<(String, f64)>) {
        let p = &self.params;
        let mut put = |k: String, v: f64| out.push((k, v));
        for i in 0..3 {
            put(format!("r_pb_b_m[{i}]"), p.r_pb_b_m[i]);
            put(format!("p_hat_b[{i}]"), p.p_hat_b[i]);
        }
        put("mass_kg".into(), p.mass_kg);
        put("k_n_m".into(), p.k_n_m);
        put("c_n_s_m".into(), p.c_n_s_m);
        put("rho_m".into(), x0[RHO]);
        put("rho_dot_m_s".into(), x0[RHO_DOT]);
    }

    fn initial_state(&self, x: &mut [f64]) {
        x[RHO] = self.params.rho_m;
        x[RHO_DOT] = self.params.rho_dot_m_s;
    }

    fn update_mass_props(&mut self, x: &[f64], sum: &mut EffectorMassProps) {
        // (L6)
        let r = self.r_pcb_b_m(x[RHO]);
        self.cache.r_pcb_b = r;
        sum.add_point_mass(self.params.mass_kg, &r, &(self.params.p_hat_b * x[RHO_DOT]));
    }

    fn update_contributions(
        &mut self,
        x: &[f64],
        hub: &HubKinematics,
        sum: &mut BackSubContributions,
    ) {
        let p = &self.params;
        let (m, p_hat) = (p.mass_kg, &p.p_hat_b);
        let w = &hub.omega_bn_b;
        let (rho, rho_dot) = (x[RHO], x[RHO_DOT]);
        let r = self.cache.r_pcb_b;
        let r_prime = p_hat * rho_dot;
        // (L3)
        let b_rho = p_hat.cross(&r);
        let c_rho = -(p.k_n_m * rho + p.c_n_s_m * rho_dot) / m - p_hat.dot(&w.cross(&w.cross(&r)));
        self.cache.b_rho = b_rho;
        self.cache.c_rho = c_rho;
        // (L4): [A_contr] = −m p̂p̂ᵀ, [B_contr] = m p̂ b_ρᵀ, v_trans,contr = −m c_ρ p̂.
        let b_contr = p_hat * b_rho.transpose() * m;
        sum.matrix_a += self.matrix_a;
        sum.matrix_b += b_contr;
        sum.vec_trans -= p_hat * (m * c_rho);
        // (L5): [C_contr] = [B_contr]ᵀ, [D_contr] = −m b_ρ b_ρᵀ,
        // v_rot,contr = m c_ρ b_ρ − ω × (m r × r′) − [I′]ω.
        sum.matrix_c += b_contr.transpose();
        sum.matrix_d -= b_rho * b_rho.transpose() * m;
        sum.vec_rot += b_rho * (m * c_rho)
            - w.cross(&(r.cross(&r_prime) * m))
            - point_mass_i_prime_omega(m, &r, &r_prime, w);
    }

    fn compute_derivatives(&mut self, x: &[f64], hub_accel: &HubAccel, dx: &mut [f64]) {
        // (L3): ρ̈ = −p̂ᵀ r̈_B/N + b_ρᵀ ω̇ + c_ρ.
        let c = &self.cache;
        dx[RHO] = x[RHO_DOT];
        dx[RHO_DOT] = -self.params.p_hat_b.dot(&hub_accel.nongrav_accel_bn_b)
            + c.b_rho.dot(&hub_accel.omega_dot_bn_b)
            + c.c_rho;
    }

    fn energy_momentum(&self, x: &[f64], omega_bn_b: &Vector3<f64>) -> EnergyMomentum {
        // (L7)
        let p = &self.params;
        let r = self.r_pcb_b_m(x[RHO]);
        let mut em =
            EnergyMomentum::point_mass(p.mass_kg, &r, &(p.p_hat_b * x[RHO_DOT]), omega_bn_b);
        em.potential_j = 0.5 * p.k_n_m * x[RHO] * x[RHO];
        em
    }

    /// Nothing beyond the integrated states: the cached geometry is recomputed from `x`.
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
}
