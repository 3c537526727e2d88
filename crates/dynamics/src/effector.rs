//! The state-effector contract: how an appended body plugs into the hub's back-substitution solve.
//!
//! Every appended body (a dual-hinged panel pair today; a single hinged panel, a reaction wheel or
//! an N-panel chain tomorrow) implements [`StateEffector`]. Per derivative evaluation the
//! [`Spacecraft`](super::Spacecraft) calls, in order (steps 1 and 2 back to back for each effector:
//! contributions depend on ω, never on the other effectors' mass properties):
//!
//! 1. [`StateEffector::update_mass_props`] — the effector's mass, first moment and inertia about B
//!    (their sums give m_sc, c, c′ and \[I_sc,B\] of Eqs. 3, 4 and 19);
//! 2. [`StateEffector::update_contributions`] — its \[A\], \[B\], \[C\], \[D\], v_trans and v_rot
//!    contributions to the hub system (Eqs. 139–144 for a panel pair). The body's share of
//!    Eq. 150's −[I′_sc,B]ω is part of its v_rot contribution, because only the product with ω is
//!    ever needed and it is far cheaper than a 3×3 [I′] per body;
//! 3. the hub solves Eqs. 151–153 for r̈_B/N and ω̇_B/N;
//! 4. [`StateEffector::compute_derivatives`] — back-substitution of its own second derivatives
//!    (Eqs. 131–132 for a panel pair).
//!
//! The hub code only ever sees the summed [`EffectorMassProps`] and [`BackSubContributions`], so a
//! new kind of body plugs in without touching it. Effectors add into the sums in place (as
//! Basilisk's `updateContributions` does) instead of returning them: a returned
//! [`BackSubContributions`] is 336 bytes, copied and added per effector per RK4 stage.

use std::ops::AddAssign;

use flexdyn_kernel::archive::Archive;
use nalgebra::{Matrix3, Vector3};

/// Hub kinematics an effector needs for its contributions.
#[derive(Debug, Clone, Copy)]
pub struct HubKinematics {
    /// [rad/s] ω_B/N in B components.
    pub omega_bn_b: Vector3<f64>,
}

/// The hub's solved accelerations, handed to each effector for back-substitution.
#[derive(Debug, Clone, Copy, Default)]
pub struct HubAccel {
    /// [m/s²] non-gravitational acceleration of point B relative to N, in B components
    /// (r̈_B/N minus the uniform gravity field g(r_C/N)). Effector equations use this one: a
    /// uniform gravity field accelerates every body alike and drops out of the hinge equations.
    pub nongrav_accel_bn_b: Vector3<f64>,
    /// [rad/s²] ω̇_B/N in B components.
    pub omega_dot_bn_b: Vector3<f64>,
}

/// Mass properties of an effector about point B, B components (summed into Eqs. 3, 4 and 19).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffectorMassProps {
    /// \[kg\] mass.
    pub mass_kg: f64,
    /// [kg·m] first moment Σ m r_Sc/B.
    pub first_moment_b_kg_m: Vector3<f64>,
    /// [kg·m/s] body-frame derivative of the first moment, Σ m r′_Sc/B.
    pub first_moment_prime_b_kg_m_s: Vector3<f64>,
    /// [kg·m²] inertia about point B.
    pub inertia_pnt_b_b_kg_m2: Matrix3<f64>,
}

impl Default for EffectorMassProps {
    fn default() -> Self {
        Self {
            mass_kg: 0.0,
            first_moment_b_kg_m: Vector3::zeros(),
            first_moment_prime_b_kg_m_s: Vector3::zeros(),
            inertia_pnt_b_b_kg_m2: Matrix3::zeros(),
        }
    }
}

impl AddAssign for EffectorMassProps {
    fn add_assign(&mut self, o: Self) {
        self.mass_kg += o.mass_kg;
        self.first_moment_b_kg_m += o.first_moment_b_kg_m;
        self.first_moment_prime_b_kg_m_s += o.first_moment_prime_b_kg_m_s;
        self.inertia_pnt_b_b_kg_m2 += o.inertia_pnt_b_b_kg_m2;
    }
}

impl EffectorMassProps {
    /// Adds a point mass `mass_kg` at `r_b` moving at `r_prime_b` relative to B (B components):
    /// m, m r, m r′ and the inertia about B m \[r̃\]\[r̃\]ᵀ = m (|r|² \[1\] − r rᵀ).
    #[inline(always)]
    pub fn add_point_mass(&mut self, mass_kg: f64, r_b: &Vector3<f64>, r_prime_b: &Vector3<f64>) {
        self.mass_kg += mass_kg;
        self.first_moment_b_kg_m += r_b * mass_kg;
        self.first_moment_prime_b_kg_m_s += r_prime_b * mass_kg;
        self.inertia_pnt_b_b_kg_m2 +=
            (Matrix3::from_diagonal_element(r_b.norm_squared()) - r_b * r_b.transpose()) * mass_kg;
    }
}

/// \[N·m\] \[I′\]ω of a point mass `mass_kg` at `r_b` moving at `r_prime_b` relative to B, when B
/// rotates at `omega_bn_b`: the body-frame derivative of m (|r|² \[1\] − r rᵀ) applied to ω,
/// m (2 (r·r′) ω − r′ (r·ω) − r (r′·ω)). Its negative is the mass's share of Eq. 150's
/// −\[I′_sc,B\]ω, which an effector adds to its v_rot contribution.
#[inline(always)]
pub fn point_mass_i_prime_omega(
    mass_kg: f64,
    r_b: &Vector3<f64>,
    r_prime_b: &Vector3<f64>,
    omega_bn_b: &Vector3<f64>,
) -> Vector3<f64> {
    (omega_bn_b * (2.0 * r_b.dot(r_prime_b))
        - r_prime_b * r_b.dot(omega_bn_b)
        - r_b * r_prime_b.dot(omega_bn_b))
        * mass_kg
}

/// An effector's contributions to the hub system of Eq. 151:
/// `[[A, B], [C, D]] [r̈_B/N; ω̇_B/N] = [v_trans; v_rot]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BackSubContributions {
    /// \[kg\] \[A_contr\], Eq. 139.
    pub matrix_a: Matrix3<f64>,
    /// [kg·m] \[B_contr\], Eq. 140.
    pub matrix_b: Matrix3<f64>,
    /// [kg·m] \[C_contr\], Eq. 142.
    pub matrix_c: Matrix3<f64>,
    /// [kg·m²] \[D_contr\], Eq. 143.
    pub matrix_d: Matrix3<f64>,
    /// \[N\] v_trans,contr, Eq. 141.
    pub vec_trans: Vector3<f64>,
    /// [N·m] v_rot,contr, Eq. 144, plus the body's −[I′]ω share of Eq. 150.
    pub vec_rot: Vector3<f64>,
}

impl Default for BackSubContributions {
    fn default() -> Self {
        Self {
            matrix_a: Matrix3::zeros(),
            matrix_b: Matrix3::zeros(),
            matrix_c: Matrix3::zeros(),
            matrix_d: Matrix3::zeros(),
            vec_trans: Vector3::zeros(),
            vec_rot: Vector3::zeros(),
        }
    }
}

impl AddAssign for BackSubContributions {
    fn add_assign(&mut self, o: Self) {
        self.matrix_a += o.matrix_a;
        self.matrix_b += o.matrix_b;
        self.matrix_c += o.matrix_c;
        self.matrix_d += o.matrix_d;
        self.vec_trans += o.vec_trans;
        self.vec_rot += o.vec_rot;
    }
}

/// An effector's share of the system's energy and momentum, taken about point B for motion
/// relative to B's translation, in B components. All fields are additive across bodies; the
/// [`Spacecraft`](super::Spacecraft) shifts the sums to the system centre of mass C.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyMomentum {
    /// \[kg\] mass.
    pub mass_kg: f64,
    /// [kg·m] first moment Σ m r_i/B.
    pub first_moment_b_kg_m: Vector3<f64>,
    /// [kg·m/s] linear momentum relative to B's translation, Σ m ṙ_i/B (ṙ = r′ + ω × r).
    pub lin_mom_rel_b_kg_m_s: Vector3<f64>,
    /// [kg·m²/s] angular momentum about B, Σ (\[I_i\] ω_i + m r_i/B × ṙ_i/B).
    pub ang_mom_pnt_b_b_kg_m2_s: Vector3<f64>,
    /// \[J\] kinetic energy relative to B's translation, ½ Σ (ω_iᵀ\[I_i\]ω_i + m |ṙ_i/B|²).
    pub kinetic_rel_b_j: f64,
    /// \[J\] stored potential energy (springs).
    pub potential_j: f64,
}

impl Default for EnergyMomentum {
    fn default() -> Self {
        Self {
            mass_kg: 0.0,
            first_moment_b_kg_m: Vector3::zeros(),
            lin_mom_rel_b_kg_m_s: Vector3::zeros(),
            ang_mom_pnt_b_b_kg_m2_s: Vector3::zeros(),
            kinetic_rel_b_j: 0.0,
            potential_j: 0.0,
        }
    }
}

impl AddAssign for EnergyMomentum {
    fn add_assign(&mut self, o: Self) {
        self.mass_kg += o.mass_kg;
        self.first_moment_b_kg_m += o.first_moment_b_kg_m;
        self.lin_mom_rel_b_kg_m_s += o.lin_mom_rel_b_kg_m_s;
        self.ang_mom_pnt_b_b_kg_m2_s += o.ang_mom_pnt_b_b_kg_m2_s;
        self.kinetic_rel_b_j += o.kinetic_rel_b_j;
        self.potential_j += o.potential_j;
    }
}

impl EnergyMomentum {
    /// The contribution of one rigid body of mass `mass_kg` whose centre of mass is at `r_b`
    /// (relative to B, B components) moving at `r_prime_b` relative to the B frame, with inertia
    /// `inertia_c_b` about its own centre of mass (B components) and inertial angular velocity
    /// `omega_body_b`, when the B frame rotates at `omega_bn_b`.
    #[inline]
    pub fn rigid_body(
        mass_kg: f64,
        r_b: &Vector3<f64>,
        r_prime_b: &Vector3<f64>,
        inertia_c_b: &Matrix3<f64>,
        omega_body_b: &Vector3<f64>,
        omega_bn_b: &Vector3<f64>,
    ) -> Self {
        let r_dot_b = r_prime_b + omega_bn_b.cross(r_b);
        let i_omega = inertia_c_b * omega_body_b;
        Self {
            mass_kg,
            first_moment_b_kg_m: r_b * mass_kg,
            lin_mom_rel_b_kg_m_s: r_dot_b * mass_kg,
            ang_mom_pnt_b_b_kg_m2_s: i_omega + r_b.cross(&r_dot_b) * mass_kg,
            kinetic_rel_b_j: 0.5 * (omega_body_b.dot(&i_omega) + mass_kg * r_dot_b.norm_squared()),
            potential_j: 0.0,
        }
    }
}

impl EnergyMomentum {
    /// The contribution of a point mass `mass_kg` at `r_b` moving at `r_prime_b` relative to the
    /// B frame, when B rotates at `omega_bn_b` ([`Self::rigid_body`] without inertia).
    #[inline]
    pub fn point_mass(
        mass_kg: f64,
        r_b: &Vector3<f64>,
        r_prime_b: &Vector3<f64>,
        omega_bn_b: &Vector3<f64>,
    ) -> Self {
        Self::rigid_body(
            mass_kg,
            r_b,
            r_prime_b,
            &Matrix3::zeros(),
            omega_bn_b,
            omega_bn_b,
        )
    }
}

/// What kind of body an effector is: its wire tag (`flexdyn_proto::effector_kind`) and the
/// prefix of its CSV columns (`pair1_theta1`, `rw2_omega_rad_s`). Each kind defines one `const`
/// in its own folder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EffectorKind {
    /// Human-readable kind name (`panel_pair`, `reaction_wheel`), also the config section's
    /// singular.
    pub name: &'static str,
    /// [`flexdyn_proto::EffectorState::kind`] on the wire.
    pub wire_tag: u16,
    /// CSV column prefix; the 1-based index among effectors of this kind follows it.
    pub column_prefix: &'static str,
}

/// A body appended to the hub, with its own integrated states, solved by back-substitution.
///
/// Implementations validate their parameters at construction. None of these methods may allocate,
/// lock, do I/O or fail: they run inside every RK4 stage (or once per step or output). They
/// receive the effector's own slice of the integrated state (`x`, length
/// [`StateEffector::state_len`]) and may cache geometry in `self` between the calls of one
/// evaluation.
///
/// Beyond the dynamics, an effector describes itself to every layer above it: its states'
/// names (CSV headers, wire order), its inputs (commanded by flight code through
/// `CommandKind::Actuators`) and its outputs and flags (telemetry). Adding a kind therefore
/// touches only its own folder (with its [`super::component::ComponentKind`]) plus the one line
/// that lists it in [`super::kinds::KINDS`] (and its `mod` line).
pub trait StateEffector: Send + std::fmt::Debug {
    /// Name from the configuration, for logs and messages.
    fn name(&self) -> &str;
    /// The kind of body (wire tag, CSV prefix).
    fn kind(&self) -> EffectorKind;
    /// Number of integrated states this effector owns.
    fn state_len(&self) -> usize {
        self.state_names().len()
    }
    /// Names of the integrated states with their units where they have one (e.g. `theta1`,
    /// `omega_rad_s`), in state order: CSV headers and the wire's `states` order.
    fn state_names(&self) -> &'static [&'static str];
    /// Names of the inputs flight code may command (e.g. `motor_torque_nm`); empty if none.
    fn input_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// Number of inputs.
    fn input_len(&self) -> usize {
        self.input_names().len()
    }
    /// Sets the commanded inputs, held until the next call. `u` has [`Self::input_len`]
    /// values, each finite (the caller checks both).
    fn set_inputs(&mut self, _u: &[f64]) {}
    /// Names of the outputs reported by [`Self::outputs`] (e.g. `friction_torque_nm`).
    fn output_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// Writes the outputs at state `x` into `out` (length `output_names().len()`) and returns
    /// the kind's status flags. Call after [`Self::begin_step`] on the same `x`.
    fn outputs(&self, _x: &[f64], _out: &mut [f64]) -> u32 {
        0
    }
    /// Called once per RK4 step before its first stage (and before outputs are taken), with the
    /// state at the start of the step: the place for logic that must hold over a whole step,
    /// such as clipping a commanded torque against a speed limit.
    fn begin_step(&mut self, _x: &[f64]) {}
    /// Whether [`Self::begin_step`] does anything: the spacecraft calls it only on effectors
    /// that say so, keeping the per-step loop empty for bodies without step logic.
    fn uses_begin_step(&self) -> bool {
        false
    }
    /// Writes the effector's initial state into `x`.
    fn initial_state(&self, x: &mut [f64]);
    /// Every numeric parameter of the built body, keyed by its configuration path relative to
    /// the effector's table (`panel1.k_nm_rad`, `r_h1b_b_m[0]`, `dcm_h1b[2][2]`); initial
    /// values are read from `x0`, the body's slice of the initial state. A campaign reads the
    /// dispersed values back from here, not from the file. Not on the stepping path.
    fn parameters(&self, _x0: &[f64], _out: &mut Vec<(String, f64)>) {}
    /// Pass 1: adds the mass properties about B at state `x` into `sum`.
    fn update_mass_props(&mut self, x: &[f64], sum: &mut EffectorMassProps);
    /// Pass 2: adds the contributions to the hub system at state `x` into `sum` (after pass 1 on
    /// the same `x`).
    fn update_contributions(
        &mut self,
        x: &[f64],
        hub: &HubKinematics,
        sum: &mut BackSubContributions,
    );
    /// Pass 3: the effector's state derivative `dx` once the hub accelerations are known
    /// (after pass 2 on the same `x`).
    fn compute_derivatives(&mut self, x: &[f64], hub_accel: &HubAccel, dx: &mut [f64]);
    /// Energy and momentum contributions at state `x` when the hub rotates at `omega_bn_b`.
    fn energy_momentum(&self, x: &[f64], omega_bn_b: &Vector3<f64>) -> EnergyMomentum;
    /// Lists the body's mutable state outside the integrated states (held inputs, clipping
    /// flags) for a checkpoint ([`flexdyn_kernel::archive`]). Geometry cached between the calls
    /// of one evaluation is not state: every evaluation recomputes it from `x`. Required, so a
    /// new kind says what it holds. Not on the stepping path.
    fn archive(&mut self, a: &mut Archive<'_>);
    /// \[kg\] the propellant a tank holds at state `x` (never negative); `None` (the default)
    /// for a body that is not a propellant tank. Dynamic effectors that name this body
    /// ([`super::DynamicEffector::propellant_tank`]) draw from it.
    fn propellant_kg(&self, _x: &[f64]) -> Option<f64> {
        None
    }
    /// \[kg/s\] the mass flow (≥ 0) its thrusters draw over the coming step, constant over the
    /// step: the spacecraft sets it once per step after the thrusters have solved theirs.
    /// Only called on bodies whose [`Self::propellant_kg`] is `Some`.
    fn set_propellant_outflow(&mut self, _outflow_kg_s: f64) {}
}
