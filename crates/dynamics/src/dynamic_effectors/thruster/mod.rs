//! A thruster: a body-fixed force with valve timing, first-order build-up and tail-off, a
//! minimum on-time, a pulse count and the propellant it burns.
//!
//! **Command.** Flight code commands each frame's valve-open time, as seconds
//! (`command = "on_time_s"`, 0 … the frame period) or as a duty cycle (`"duty_cycle"`, 0 … 1).
//! The valve opens at the start of every frame and closes after that time; like every effector
//! input, the command is held until the next one, so a held command is pulse-width modulation
//! at the frame rate. An on-time below `min_on_time_s` does not open the valve (flag
//! `BELOW_MIN_ON_TIME`); a command outside its range is clipped (flag `COMMAND_CLIPPED`).
//!
//! **Thrust.** The thrust fraction κ (0 … 1) follows the valve u (1 open, 0 closed) as a
//! first-order lag, dκ/dt = (u − κ)/τ, with τ = `rise_time_constant_s` while open and
//! `tail_off_time_constant_s` while closed (τ = 0: κ = u at once). On an interval of constant u
//! starting at κ₀ the solution and its integral are closed forms:
//!
//! - κ(s) = u + (κ₀ − u) e^(−s/τ),
//! - ∫₀^d κ ds = u d + (κ₀ − u) τ (1 − e^(−d/τ)).
//!
//! Each integration step has at most one valve transition inside it (it closes; it opens only at
//! a frame start, which is a step boundary), so the step's thrust integral is exact. The force
//! applied over the step is its average, F̄ = F_max ∫κ/h, held over the step's stages: the
//! impulse each step delivers is then exact (a constant force is integrated exactly by every
//! Runge–Kutta method), where sampling the thrust at the stages would smear a valve closing
//! inside the step. What this neglects is the thrust's shape *within* one step (a position
//! error of order ΔF h²/m, 10⁻¹² m for 1 N, 1 ms and 100 kg).
//!
//! The force acts along `force_axis_b` (the direction the vehicle is pushed, opposite to the
//! exhaust) at the nozzle point T, so the torque about B is r_T/B × F (Sidi, *Spacecraft
//! Dynamics and Control*, §7.2). Propellant follows ṁ = F/(I_sp g₀), g₀ = 9.806 65 m/s²
//! (Sutton & Biblarz, *Rocket Propulsion Elements*, 9th ed., eq. 2-5), so the propellant used is
//! the impulse over I_sp g₀. Without `tank` the vehicle's mass and inertia are kept constant:
//! the propellant used is reported, not removed.
//!
//! **Drawing from a tank.** With `tank = "<name>"` the thruster burns the propellant of that
//! `[[propellant_tanks]]` entry ([`crate::effectors::propellant_tank`]): the spacecraft sums its
//! thrusters' step demands F̄/(I_sp g₀), and the tank's mass falls at that rate over the step
//! (linearly, exact for the step-average force), moving the vehicle's mass, centre of mass and
//! inertia. In the step the tank runs dry every thruster it feeds delivers the fraction s of its
//! force that empties the tank exactly at the step's end, and none after it (s = 0; the tank
//! flags `EMPTY`). A fed thruster also adds the mass-depletion force of its exhaust leaving the
//! rotating vehicle, −ṁ ω × r_T/B applied at T, whose moment is the jet damping
//! −ṁ [r̃_T/B]\[r̃_T/B\]ᵀ ω (the tank module's (D3)–(D4)).
//!
//! A pulse is one opening of the valve; PWM at duty 1 holds it open and counts once.
//!
//! Basilisk's `ThrusterDynamicEffector` ramps thrust linearly over fixed on/off ramp times and
//! its `ThrusterStateEffector` integrates the same first-order lag as a state; here the lag is
//! solved in closed form at the step boundaries, so it adds no integrated state and its impulse
//! carries no integration error.

pub mod kind;
pub mod schema;

use nalgebra::Vector3;

use crate::dynamic_effector::{DynamicEffector, StageState};
use crate::effector::EffectorKind;
use crate::params::Wrench;
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::validate::{
    check_at_most, check_finite, check_non_negative, check_positive, check_unit_axis, join,
    ParamError, MAX_THRUST_NEWTON,
};

/// Wire tag, configuration section and CSV prefix.
pub const KIND: EffectorKind = EffectorKind {
    name: "thruster",
    wire_tag: flexdyn_proto::effector_kind::THRUSTER,
    column_prefix: "thr",
};

/// The one input, as configured by [`ThrusterCommand`].
pub const ON_TIME_INPUT: [&str; 1] = ["on_time_s"];
/// The one input of a duty-cycle thruster.
pub const DUTY_CYCLE_INPUT: [&str; 1] = ["duty_cycle"];
/// The outputs: the thrust now, the pulses so far, the propellant and the impulse so far.
pub const OUTPUT_NAMES: [&str; 4] = [
    "thrust_newton",
    "pulse_count",
    "propellant_used_kg",
    "impulse_n_s",
];

/// Flag bit 0: the valve is open at this instant.
pub const FIRING: u32 = flexdyn_proto::thruster_flags::FIRING;
/// Flag bit 1: the commanded on-time is below `min_on_time_s`; the valve stays shut.
pub const BELOW_MIN_ON_TIME: u32 = flexdyn_proto::thruster_flags::BELOW_MIN_ON_TIME;
/// Flag bit 2: the command was outside its range and was clipped.
pub const COMMAND_CLIPPED: u32 = flexdyn_proto::thruster_flags::COMMAND_CLIPPED;

/// \[m/s²\] standard gravity, the g₀ of I_sp (CGPM 1901; Sutton & Biblarz eq. 2-5).
pub const G0_M_S2: f64 = 9.806_65;

/// What the one input means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ThrusterCommand {
    /// \[s\] the valve-open time in each frame, 0 … the frame period.
    OnTime,
    /// \[-\] the fraction of each frame the valve is open, 0 … 1.
    DutyCycle,
}

impl ThrusterCommand {
    /// The configuration spellings, in the order of the enum.
    pub const NAMES: [&'static str; 2] = ["on_time_s", "duty_cycle"];

    /// Parses a configuration spelling.
    pub fn from_name(s: &str) -> Option<Self> {
        match s {
            "on_time_s" => Some(Self::OnTime),
            "duty_cycle" => Some(Self::DutyCycle),
            _ => None,
        }
    }
}

/// One thruster (`[[thrusters]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct ThrusterParams {
    /// Name used in logs, messages and telemetry.
    pub name: String,
    /// \[m\] the nozzle point T relative to B, B components (where the force acts).
    pub r_tb_b_m: Vector3<f64>,
    /// The direction the thrust pushes the vehicle, B components (a unit vector within
    /// [`flexdyn_kernel::validate::UNIT_AXIS_TOL`]).
    pub force_axis_b: Vector3<f64>,
    /// \[N\] steady-state thrust with the valve open.
    pub max_thrust_newton: f64,
    /// \[s\] specific impulse.
    pub isp_s: f64,
    /// \[s\] the shortest on-time the valve executes (0: any).
    pub min_on_time_s: f64,
    /// \[s\] time constant of the thrust build-up (0: instant).
    pub rise_time_constant_s: f64,
    /// \[s\] time constant of the tail-off (0: instant).
    pub tail_off_time_constant_s: f64,
    /// What the input means.
    pub command: ThrusterCommand,
    /// The `[[propellant_tanks]]` entry it draws from, by name; `None`: it burns nothing the
    /// vehicle carries (its mass properties stay constant).
    pub tank: Option<String>,
}

impl ThrusterParams {
    /// Validates the thruster (`path` is e.g. `thrusters[0]`) for frames of `frame_ns`.
    pub fn validate(&self, path: &str, frame_ns: u64) -> Result<(), ParamError> {
        check_finite(path, "r_tb_b_m", self.r_tb_b_m.as_slice())?;
        check_unit_axis(path, "force_axis_b", &self.force_axis_b)?;
        check_positive(path, "max_thrust_newton", self.max_thrust_newton)?;
        check_at_most(
            path,
            "max_thrust_newton",
            self.max_thrust_newton,
            MAX_THRUST_NEWTON,
            "the largest thrust flexdyn accepts, in N; the F-1 engine made 6.8e6",
        )?;
        check_positive(path, "isp_s", self.isp_s)?;
        check_non_negative(path, "min_on_time_s", self.min_on_time_s)?;
        let frame_s = frame_ns as f64 * 1e-9;
        if self.min_on_time_s > frame_s {
            return Err(ParamError::Invalid {
                field: join(path, "min_on_time_s"),
                problem: format!(
                    "{} s is longer than the frame period ({frame_s} s): the valve could never open",
                    self.min_on_time_s
                ),
            });
        }
        check_non_negative(path, "rise_time_constant_s", self.rise_time_constant_s)?;
        check_non_negative(
            path,
            "tail_off_time_constant_s",
            self.tail_off_time_constant_s,
        )?;
        if self.tank.as_deref() == Some("") {
            return Err(ParamError::Invalid {
                field: join(path, "tank"),
                problem: "must name a [[propellant_tanks]] entry, not be empty".into(),
            });
        }
        Ok(())
    }
}

/// κ at the end of `d_s` seconds of constant valve state `u` (0 or 1) from κ₀, and ∫κ over them
/// (the closed forms of the module documentation).
#[inline]
fn lag_segment(kappa0: f64, u: f64, d_s: f64, tau_s: f64) -> (f64, f64) {
    if d_s <= 0.0 {
        return (kappa0, 0.0);
    }
    // τ = 0: the valve state at once. κ₀ = u (a shut valve at rest, or a valve open long
    // enough for κ to reach 1 exactly): κ stays u. The general expressions below give the same
    // bits then, since (κ₀ − u) = +0 makes both second terms +0 and x + (+0) = x for the
    // non-negative u·d; this only skips their e^(−d/τ) (an idle thruster's whole cost).
    if tau_s == 0.0 || kappa0 == u {
        return (u, u * d_s);
    }
    // 1 − e^(−d/τ), accurate for d ≪ τ.
    let one_minus_e = -(-d_s / tau_s).exp_m1();
    (
        u + (kappa0 - u) * (1.0 - one_minus_e),
        u * d_s + (kappa0 - u) * tau_s * one_minus_e,
    )
}

/// One step of thrust, solved at its start for the step that follows.
#[derive(Debug, Clone, Copy, Default)]
struct StepThrust {
    /// \[ns\] the step's end.
    t_end_ns: u64,
    /// κ at the end.
    kappa_end: f64,
    /// \[s\] ∫κ dt over the step.
    kappa_integral_s: f64,
    /// Whether the valve opens at the step's start (it was shut before).
    opens: bool,
    /// Whether the valve is open at the step's start and through its end.
    open_at_end: bool,
    /// Whether the valve is open at the step's start.
    open_at_start: bool,
}

/// A built thruster: parameters, command, the thrust lag's state and the totals.
#[derive(Debug, Clone)]
pub struct Thruster {
    params: ThrusterParams,
    path: String,
    frame_ns: u64,
    step_ns: u64,
    min_on_ns: u64,
    /// \[ns\] valve-open time per frame, after clipping and the minimum on-time.
    on_ns: u64,
    command_flags: u32,
    /// κ at `t_anchor_ns`.
    kappa: f64,
    t_anchor_ns: u64,
    /// Whether the valve was open at the end of the last step.
    valve_open: bool,
    /// The step being integrated (solved by the last [`DynamicEffector::begin_step`]).
    step: StepThrust,
    /// \[N\] the step's average force magnitude, F_max ∫κ / h.
    force_avg_newton: f64,
    pulse_count: u64,
    impulse_n_s: f64,
    /// The fraction of the step's force its tank can feed (1 without a tank, or while the tank
    /// has enough; [`DynamicEffector::set_propellant_supply`]).
    supply: f64,
}

impl Thruster {
    /// Builds a thruster after validating it; `path` (`thrusters[0]`) names its fields in errors
    /// and in [`DynamicEffector::parameters`]. The valve opens at every multiple of `frame_ns`
    /// (a whole number of steps of `step_ns`).
    pub fn new(
        params: ThrusterParams,
        path: &str,
        frame_ns: u64,
        step_ns: u64,
    ) -> Result<Self, ParamError> {
        params.validate(path, frame_ns)?;
        let min_on_ns = (params.min_on_time_s * 1e9).round() as u64;
        let mut t = Self {
            params,
            path: path.to_string(),
            frame_ns,
            step_ns,
            min_on_ns,
            on_ns: 0,
            command_flags: 0,
            kappa: 0.0,
            t_anchor_ns: 0,
            valve_open: false,
            step: StepThrust::default(),
            force_avg_newton: 0.0,
            pulse_count: 0,
            impulse_n_s: 0.0,
            supply: 1.0,
        };
        t.solve_step(0);
        Ok(t)
    }

    /// The parameters.
    pub fn params(&self) -> &ThrusterParams {
        &self.params
    }

    /// Solves the step starting at `t_ns` from κ at `t_ns` and the current command.
    #[inline]
    fn solve_step(&mut self, t_ns: u64) {
        let h_ns = self.step_ns;
        if self.on_ns == 0 && self.kappa == 0.0 {
            // Shut all step, at rest: the general path below then opens for 0 ns, so its first
            // segment is (κ₀, +0); the shut segment starts at κ₀ = ±0 = u and gives (+0, 0·h = +0);
            // the integral is +0 + +0 = +0 and the force F_max·(+0)/h = +0 (F_max > 0). The same
            // bits without the remainder and conversions: the cost of an idle thruster.
            self.step = StepThrust {
                t_end_ns: t_ns + h_ns,
                kappa_end: 0.0,
                kappa_integral_s: 0.0,
                opens: false,
                open_at_end: false,
                open_at_start: false,
            };
            self.force_avg_newton = 0.0;
            return;
        }
        let phase_ns = t_ns % self.frame_ns;
        let open_ns = self.on_ns.saturating_sub(phase_ns).min(h_ns);
        let (k1, i1) = lag_segment(
            self.kappa,
            1.0,
            open_ns as f64 * 1e-9,
            self.params.rise_time_constant_s,
        );
        let (k2, i2) = lag_segment(
            k1,
            0.0,
            (h_ns - open_ns) as f64 * 1e-9,
            self.params.tail_off_time_constant_s,
        );
        self.step = StepThrust {
            t_end_ns: t_ns + h_ns,
            kappa_end: k2,
            kappa_integral_s: i1 + i2,
            opens: open_ns > 0 && !self.valve_open,
            open_at_end: open_ns == h_ns,
            open_at_start: open_ns > 0,
        };
        self.force_avg_newton =
            self.params.max_thrust_newton * self.step.kappa_integral_s / (h_ns as f64 * 1e-9);
    }

    /// \[kg\] propellant burnt so far: the impulse over I_sp g₀.
    pub fn propellant_used_kg(&self) -> f64 {
        self.impulse_n_s / (self.params.isp_s * G0_M_S2)
    }

    /// \[kg/s\] the mass flow over the step being integrated, after its tank's supply:
    /// s F̄ / (I_sp g₀).
    #[inline]
    pub fn mass_flow_kg_s(&self) -> f64 {
        self.supply * self.force_avg_newton / (self.params.isp_s * G0_M_S2)
    }
}

impl DynamicEffector for Thruster {
    fn name(&self) -> &str {
        &self.params.name
    }

    fn uses_begin_step(&self) -> bool {
        true
    }

    /// Closes the step that ends at `t_step_ns` (its pulse, impulse and κ become the totals),
    /// then solves the step that starts there with the current command. Called again at the same
    /// instant (after a new command), it re-solves without counting twice. A jump in time (a
    /// restored state) keeps κ and the totals and starts over from there.
    fn begin_step(&mut self, t_step_ns: u64) {
        if t_step_ns != self.t_anchor_ns && self.step.t_end_ns == t_step_ns {
            let s = self.step;
            self.kappa = s.kappa_end;
            if self.params.tank.is_some() {
                self.impulse_n_s +=
                    self.params.max_thrust_newton * s.kappa_integral_s * self.supply;
            } else {
                self.impulse_n_s += self.params.max_thrust_newton * s.kappa_integral_s;
            }
            self.pulse_count += u64::from(s.opens);
            self.valve_open = s.open_at_end;
        }
        self.t_anchor_ns = t_step_ns;
        self.solve_step(t_step_ns);
        // Full supply until the spacecraft says what the tank can feed over this step.
        self.supply = 1.0;
    }

    fn add_force_torque(&mut self, stage: &StageState, _env: &EnvironmentSample, sum: &mut Wrench) {
        if self.force_avg_newton == 0.0 {
            // A shut, spent thruster adds ±0 to each component: nothing (a sum that is exactly
            // −0 would become +0, which no later operation tells apart from −0 but a sign).
            return;
        }
        if self.params.tank.is_none() {
            let f_b = self.params.force_axis_b * self.force_avg_newton;
            sum.force_b_newton += f_b;
            sum.torque_b_nm += self.params.r_tb_b_m.cross(&f_b);
            return;
        }
        // Fed by a tank: the thrust the supply allows, plus the exhaust's mass-depletion force
        // −ṁ ω × r_T/B at T (tank module, (D3)); its moment r_T/B × (−ṁ ω × r_T/B) is the
        // jet damping −ṁ [r̃][r̃]ᵀ ω (D4).
        let r = &self.params.r_tb_b_m;
        let f_b = self.params.force_axis_b * (self.force_avg_newton * self.supply)
            - stage.omega_bn_b_rad_s.cross(r) * self.mass_flow_kg_s();
        sum.force_b_newton += f_b;
        sum.torque_b_nm += r.cross(&f_b);
    }

    fn propellant_tank(&self) -> Option<&str> {
        self.params.tank.as_deref()
    }

    fn propellant_demand_kg_s(&self) -> f64 {
        self.force_avg_newton / (self.params.isp_s * G0_M_S2)
    }

    fn set_propellant_supply(&mut self, fraction: f64) {
        self.supply = fraction;
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        let p = &self.params;
        for i in 0..3 {
            out.push((format!("{}.r_tb_b_m[{i}]", self.path), p.r_tb_b_m[i]));
        }
        for i in 0..3 {
            out.push((
                format!("{}.force_axis_b[{i}]", self.path),
                p.force_axis_b[i],
            ));
        }
        for (key, v) in [
            ("max_thrust_newton", p.max_thrust_newton),
            ("isp_s", p.isp_s),
            ("min_on_time_s", p.min_on_time_s),
            ("rise_time_constant_s", p.rise_time_constant_s),
            ("tail_off_time_constant_s", p.tail_off_time_constant_s),
        ] {
            out.push((format!("{}.{key}", self.path), v));
        }
    }

    fn listed_kind(&self) -> Option<EffectorKind> {
        Some(KIND)
    }

    fn input_names(&self) -> &'static [&'static str] {
        match self.params.command {
            ThrusterCommand::OnTime => &ON_TIME_INPUT,
            ThrusterCommand::DutyCycle => &DUTY_CYCLE_INPUT,
        }
    }

    fn set_inputs(&mut self, u: &[f64]) {
        let frame_s = self.frame_ns as f64 * 1e-9;
        let (lo, hi) = match self.params.command {
            ThrusterCommand::OnTime => (0.0, frame_s),
            ThrusterCommand::DutyCycle => (0.0, 1.0),
        };
        let v = u[0].clamp(lo, hi);
        let on_s = match self.params.command {
            ThrusterCommand::OnTime => v,
            ThrusterCommand::DutyCycle => v * frame_s,
        };
        let mut flags = if v != u[0] { COMMAND_CLIPPED } else { 0 };
        let mut on_ns = ((on_s * 1e9).round() as u64).min(self.frame_ns);
        if on_ns > 0 && on_ns < self.min_on_ns {
            on_ns = 0;
            flags |= BELOW_MIN_ON_TIME;
        }
        self.on_ns = on_ns;
        self.command_flags = flags;
    }

    fn output_names(&self) -> &'static [&'static str] {
        &OUTPUT_NAMES
    }

    fn outputs(&self, out: &mut [f64]) -> u32 {
        out[0] = self.params.max_thrust_newton * self.kappa * self.supply;
        out[1] = self.pulse_count as f64;
        out[2] = self.propellant_used_kg();
        out[3] = self.impulse_n_s;
        self.command_flags | if self.step.open_at_start { FIRING } else { 0 }
    }

    /// The held on-time and its flags, the valve and the thrust lag's state, the step's thrust
    /// and the counters.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        // Named field by field: a new field does not compile until it is listed here or marked
        // as configuration (`_`).
        let Self {
            params: _,
            path: _,
            frame_ns: _,
            step_ns: _,
            min_on_ns: _,
            on_ns,
            command_flags,
            kappa,
            t_anchor_ns,
            valve_open,
            step:
                StepThrust {
                    t_end_ns,
                    kappa_end,
                    kappa_integral_s,
                    opens,
                    open_at_end,
                    open_at_start,
                },
            force_avg_newton,
            pulse_count,
            impulse_n_s,
            supply,
        } = self;
        a.put(on_ns);
        a.put(command_flags);
        a.put(kappa);
        a.put(t_anchor_ns);
        a.put(valve_open);
        a.put(t_end_ns);
        a.put(kappa_end);
        a.put(kappa_integral_s);
        a.put(opens);
        a.put(open_at_end);
        a.put(open_at_start);
        a.put(force_avg_newton);
        a.put(pulse_count);
        a.put(impulse_n_s);
        a.put(supply);
    }
}

#[cfg(test)]
mod tests;
