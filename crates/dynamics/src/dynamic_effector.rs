//! The dynamic-effector contract: external forces and torques on the vehicle, evaluated at every
//! RK4 stage.
//!
//! A [`StateEffector`](super::StateEffector) is a body with its own integrated states, solved by
//! back-substitution. A [`DynamicEffector`] has no states: it is a force and a torque acting on
//! the whole vehicle (Basilisk's `dynamicEffector` idea, typed): gravity gradient, drag, solar
//! radiation pressure, a magnetic dipole in the planet's field, a thruster, a scheduled wrench.
//! Per derivative evaluation the [`Spacecraft`](super::Spacecraft):
//!
//! 1. sums the state effectors' mass properties (Eqs. 3, 4, 19), which gives the vehicle's mass,
//!    centre of mass and inertia *at this stage*, panels flexed as they are;
//! 2. hands each dynamic effector that [`StageState`] and the held [`EnvironmentSample`], and
//!    lets it add its force and torque into one sum;
//! 3. puts the sum into v_trans and v_rot of Eqs. 149–150, where the flight code's commanded
//!    wrench already stands.
//!
//! **Where the forces act.** The sum is a force applied at the hub point B and a torque about B,
//! both in B components, exactly like the commanded wrench. An effector whose force F acts at a
//! point P adds F and r_P/B × F. The vehicle is treated as one body for external forces: a force
//! on a panel is a force on the system applied at the panel's point. What this neglects is the
//! *distribution*: an external force on a panel also drives its hinge directly (a generalized
//! force Q_θ = ∂r_P/∂θ · F in Kane's method), which this seam does not pass to the hinge
//! equations. For the environment's forces on a spacecraft (drag, solar pressure: 10⁻⁶–10⁻³ N)
//! the hinge torques they would add are orders below the hinges' own stiffness terms.
//!
//! **Gravity** stays beside this seam: a uniform field accelerates every body alike, so it is
//! applied at the system centre of mass as an acceleration of the whole vehicle
//! ([`super::gravity_accel_n`]), and it drops out of every hinge equation. Its *gradient* across
//! the vehicle is a dynamic effector.
//!
//! Like the state effectors, implementations never allocate, lock, do I/O or fail inside
//! [`DynamicEffector::add_force_torque`]: it runs four times per RK4 step.

use nalgebra::{Matrix3, Vector3};

use super::effector::EffectorKind;
use super::params::Wrench;
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::archive::Archive;

/// The vehicle at one RK4 stage, as a dynamic effector sees it.
#[derive(Debug, Clone, Copy)]
pub struct StageState {
    /// \[ns\] simulation time at the start of the RK4 step this stage belongs to.
    pub t_step_ns: u64,
    /// \[s\] how far into the step the stage is (0, h/2, h/2 or h for RK4).
    pub dt_stage_s: f64,
    /// \[m\] r_B/N, N components.
    pub r_bn_n_m: Vector3<f64>,
    /// \[m/s\] v_B/N, N components.
    pub v_bn_n_m_s: Vector3<f64>,
    /// MRP σ_B/N.
    pub sigma_bn: Vector3<f64>,
    /// \[BN\]: maps N components to B components.
    pub dcm_bn: Matrix3<f64>,
    /// \[rad/s\] ω_B/N, B components.
    pub omega_bn_b_rad_s: Vector3<f64>,
    /// \[kg\] total mass of the vehicle.
    pub mass_kg: f64,
    /// \[m\] system centre of mass C relative to B, B components, at this stage.
    pub r_cb_b_m: Vector3<f64>,
    /// \[m\] r_C/N, N components.
    pub r_cn_n_m: Vector3<f64>,
    /// \[kg·m²\] inertia of the whole vehicle about B, B components, at this stage.
    pub inertia_pnt_b_b_kg_m2: Matrix3<f64>,
}

impl StageState {
    /// \[s\] simulation time of the stage.
    #[inline]
    pub fn t_s(&self) -> f64 {
        self.t_step_ns as f64 * 1e-9 + self.dt_stage_s
    }

    /// \[kg·m²\] inertia of the whole vehicle about its centre of mass C, B components, by the
    /// parallel-axis theorem: \[I_C\] = \[I_B\] − m [c̃]\[c̃\]ᵀ = \[I_B\] − m (|c|² 𝟙 − c cᵀ).
    #[inline]
    pub fn inertia_pnt_c_b_kg_m2(&self) -> Matrix3<f64> {
        let c = &self.r_cb_b_m;
        self.inertia_pnt_b_b_kg_m2
            - (Matrix3::from_diagonal_element(c.norm_squared()) - c * c.transpose()) * self.mass_kg
    }
}

/// The environment's sources of force and torque, as the environment message reports them
/// (`EnvironmentMsg`, `simulate`'s environment columns): one slot each, in this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EnvironmentSource {
    /// Gravity-gradient torque (and the gradient's small net force).
    GravityGradient = 0,
    /// Aerodynamic drag on the facets.
    Drag = 1,
    /// Solar radiation pressure on the facets.
    SolarPressure = 2,
    /// A residual magnetic dipole in the planet's field.
    ResidualDipole = 3,
}

impl EnvironmentSource {
    /// Number of sources (slots of an [`EnvironmentWrenches`]).
    pub const COUNT: usize = 4;
    /// Every source, in slot order.
    pub const ALL: [EnvironmentSource; Self::COUNT] = [
        Self::GravityGradient,
        Self::Drag,
        Self::SolarPressure,
        Self::ResidualDipole,
    ];

    /// Its name in CSV columns, plots and messages (`gravity_gradient`, `drag`, …).
    pub fn name(self) -> &'static str {
        match self {
            Self::GravityGradient => "gravity_gradient",
            Self::Drag => "drag",
            Self::SolarPressure => "solar_pressure",
            Self::ResidualDipole => "residual_dipole",
        }
    }
}

/// Per [`EnvironmentSource`] slot, its force (at B) and torque (about B), B components.
pub type EnvironmentWrenches = [Wrench; EnvironmentSource::COUNT];

/// An external force and torque on the vehicle, evaluated at every RK4 stage.
pub trait DynamicEffector: Send + std::fmt::Debug {
    /// Name from the configuration (or the model's own), for logs, messages and telemetry.
    fn name(&self) -> &str;
    /// Called once per RK4 step before its first stage, with the time at the start of the step:
    /// the place for inputs held over a whole step (a commanded on-time, a schedule row).
    fn begin_step(&mut self, _t_step_ns: u64) {}
    /// Whether [`Self::begin_step`] does anything (the spacecraft calls it only on those that do).
    fn uses_begin_step(&self) -> bool {
        false
    }
    /// Adds this effector's force (applied at B) and torque (about B), both in B components, at
    /// the stage `stage` in the environment `env`, into `sum`.
    fn add_force_torque(&mut self, stage: &StageState, env: &EnvironmentSample, sum: &mut Wrench);
    /// Every numeric parameter of the built model, keyed by its full configuration path
    /// (`environment.facets[0].area_m2`). A campaign reads dispersed values back from here, not
    /// from the file. Not on the stepping path.
    fn parameters(&self, _out: &mut Vec<(String, f64)>) {}

    /// A magnetic dipole this effector carries, as (its position relative to B \[m\], its moment
    /// \[A·m²\]), both B components, as it applies from now on (after the last inputs): what a
    /// magnetometer on the vehicle sees of it. `None` (the default) for an effector with none.
    /// Not on the stepping path.
    fn magnetic_dipole_b(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        None
    }

    /// An actuator (a magnetorquer, a thruster) is listed beside the appended bodies: it has an
    /// entry in the state record's effector list under this kind, after the state effectors, and
    /// takes its inputs from `CommandKind::Actuators` by that index. `None` (the default) for a
    /// force nobody commands (gravity gradient, drag, solar pressure, a residual dipole).
    fn listed_kind(&self) -> Option<EffectorKind> {
        None
    }
    /// Which environment source this effector is, for the environment message's per-source
    /// force and torque (`None`, the default: not an environment source, e.g. an actuator).
    fn environment_source(&self) -> Option<EnvironmentSource> {
        None
    }
    /// Names of the inputs flight code may command (with units); empty if none.
    fn input_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// Sets the commanded inputs, held until the next call. `u` has `input_names().len()`
    /// values, each finite (the caller checks both). Allocates nothing and cannot fail:
    /// out-of-range values are clipped and flagged by the effector.
    fn set_inputs(&mut self, _u: &[f64]) {}
    /// Names of the outputs reported by [`Self::outputs`] (with units).
    fn output_names(&self) -> &'static [&'static str] {
        &[]
    }
    /// Writes the outputs at the current instant into `out` (length `output_names().len()`)
    /// and returns the kind's status flags. Call after [`Self::begin_step`] at that instant.
    fn outputs(&self, _out: &mut [f64]) -> u32 {
        0
    }
    /// Lists the effector's mutable state (held inputs, a valve's timing, counters) for a
    /// checkpoint ([`flexdyn_kernel::archive`]). A value memoised from its inputs (a held Sun
    /// direction) is not state: it is the same bits when recomputed. Required, so a new kind
    /// says what it holds. Not on the stepping path.
    fn archive(&mut self, a: &mut Archive<'_>);

    /// The name of the propellant tank (a state effector whose
    /// [`StateEffector::propellant_kg`](super::StateEffector::propellant_kg) is `Some`) this
    /// effector draws from, if any (a thruster with `tank = "…"`). `None` (the default): it
    /// burns nothing the vehicle carries. Construction time only.
    fn propellant_tank(&self) -> Option<&str> {
        None
    }
    /// \[kg/s\] the propellant it would burn over the step solved by the last
    /// [`Self::begin_step`] with a full supply (a thruster: its step-average thrust over
    /// I_sp g₀). Called once per step, after [`Self::begin_step`].
    fn propellant_demand_kg_s(&self) -> f64 {
        0.0
    }
    /// The fraction (0 … 1) of [`Self::propellant_demand_kg_s`] its tank can deliver over the
    /// coming step: 1 while there is enough, less in the step the tank runs dry, 0 once it is
    /// empty. The effector scales its force (and its mass flow) by it. Called once per step,
    /// after [`Self::begin_step`], only on effectors that name a tank.
    fn set_propellant_supply(&mut self, _fraction: f64) {}
}
