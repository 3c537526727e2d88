//! The shared simulation runner used by `flexdyn simulate` and by the real-time server.
//!
//! A [`Simulation`] owns the [`Spacecraft`], the configured schedules (external wrench and
//! effector inputs) and what the attitude-control software commands (a wrench and effector
//! inputs). Before every RK4 step it applies `schedule(t) + command` to both, where `t` is the
//! time at the start of the step; wrench and inputs are then held constant over the step.
//!
//! It also owns the sensors ([`flexdyn_sensors::SensorBank`]): [`Simulation::sample_sensors`]
//! samples those picked (the ones due at a frame boundary in the server; in `simulate`, the
//! interval sensors such as the IMUs at every log row and the others at their frame boundaries)
//! from one [`Truth`], and the IMUs integrate their Δv over the integrator's stages (the bank is
//! the step's [`flexdyn_dynamics::stage_hook::StageHook`]).

mod archive;
mod sensor_views;

use std::num::NonZeroU64;

use flexdyn_proto::{EffectorState, StateMsg};

use crate::config::{ConfigError, EffectorInputSegment, SimConfig};
use flexdyn_dynamics::{
    EnvironmentSource, HubOutputs, ParamError, Spacecraft, Wrench, WrenchSegment,
};
use flexdyn_environment::model::EnvironmentModel;
use flexdyn_faults::ports::FaultHost;
use flexdyn_faults::Faults;
use flexdyn_kernel::attitude::{mrp_to_dcm, mrp_to_quat};
use flexdyn_sensors::{Sensor, SensorBank, Truth};

/// A spacecraft being propagated, with its external wrench sources.
#[derive(Debug)]
pub struct Simulation {
    sc: Spacecraft,
    frame_ns: u64,
    schedule: Vec<WrenchSegment>,
    /// Number of schedule rows whose start time is ≤ the last time the wrench was applied;
    /// the active row is `cursor - 1` (none if 0).
    cursor: usize,
    /// The commanded wrench, added to the schedule's.
    command: Wrench,
    /// The commanded effector inputs, flat (laid out by
    /// [`Spacecraft::effector_input_ranges`]).
    inputs: Vec<f64>,
    /// The effector-input schedule, sorted by start time.
    input_schedule: Vec<EffectorInputSegment>,
    /// Number of input-schedule rows already applied.
    input_cursor: usize,
    /// The scheduled effector inputs in effect, flat like `inputs`.
    scheduled_inputs: Vec<f64>,
    /// Scratch for `inputs + scheduled_inputs`, sized once.
    applied_inputs: Vec<f64>,
    /// Scratch for [`Spacecraft::effector_outputs`], sized once.
    outputs_scratch: Vec<f64>,
    flags_scratch: Vec<u32>,
    /// Hub outputs at the current state with the current wrench and inputs, once evaluated:
    /// the state record and every sensor share one evaluation per frame. Cleared by anything that
    /// changes the state, the wrench or the inputs.
    frame_outputs: Option<HubOutputs>,
    /// The sensors, in registry then config order; the IMUs' Δv rides the stage hook.
    sensors: SensorBank,
    /// The environment models (`[environment]` with an `[epoch]`), updated at their rate at
    /// step boundaries and handed to the spacecraft's dynamic effectors.
    environment: Option<EnvironmentModel>,
    /// The `[epoch]` (t = 0), if the configuration has one: the time service's calendar.
    epoch: Option<flexdyn_environment::epoch::SimEpoch>,
    /// `[environment] telemetry_rate_hz` in frames (`None`: no environment record).
    environment_every_frames: Option<u64>,
    /// The faults at the sensor and actuator ports ([`flexdyn_faults`]).
    faults: Faults,
}

impl Simulation {
    /// Builds the spacecraft of `cfg` at t = 0 with a zero commanded wrench.
    pub fn new(cfg: &SimConfig) -> Result<Self, ConfigError> {
        let sc = cfg.build_spacecraft()?;
        let frame_s = cfg.frame_ns as f64 * 1e-9;
        let sensors = SensorBank::new(&cfg.sensor_build(frame_s, sc.t_sim_ns(), sc.state()))?;
        let environment = cfg.environment_model()?;
        let host = FaultHost {
            sc: &sc,
            frame_ns: cfg.frame_ns,
            reaction_wheels: &cfg.reaction_wheels,
        };
        let faults = Faults::new(&cfg.faults, &host)?;
        let mut sim = Self {
            faults,
            environment,
            epoch: cfg.epoch.clone(),
            environment_every_frames: cfg
                .environment
                .as_ref()
                .and_then(|e| e.telemetry_every_frames),
            inputs: vec![0.0; sc.effector_input_len()],
            input_schedule: cfg.effector_input_schedule.clone(),
            input_cursor: 0,
            scheduled_inputs: vec![0.0; sc.effector_input_len()],
            applied_inputs: vec![0.0; sc.effector_input_len()],
            outputs_scratch: vec![0.0; sc.effector_output_len()],
            flags_scratch: vec![0; sc.effector_count()],
            frame_outputs: None,
            sc,
            frame_ns: cfg.frame_ns,
            schedule: cfg.wrench_schedule.clone(),
            cursor: 0,
            command: Wrench::ZERO,
            sensors,
        };
        sim.apply_schedules();
        // The world exists at t = 0: sensors sampled at tick 0 read it (the first step's update
        // then finds the sample current, so the dynamics are unchanged).
        sim.update_environment();
        Ok(sim)
    }

    /// The spacecraft.
    pub fn spacecraft(&self) -> &Spacecraft {
        &self.sc
    }

    /// The spacecraft, mutably (e.g. to restore a state). Its wrench is overwritten before each
    /// step; use [`Self::set_command_wrench`] to apply one.
    pub fn spacecraft_mut(&mut self) -> &mut Spacecraft {
        self.frame_outputs = None;
        &mut self.sc
    }

    /// \[ns\] simulation time.
    pub fn t_sim_ns(&self) -> u64 {
        self.sc.t_sim_ns()
    }

    /// \[ns\] RK4 step.
    pub fn step_ns(&self) -> u64 {
        self.sc.step_ns()
    }

    /// \[ns\] frame period.
    pub fn frame_ns(&self) -> u64 {
        self.frame_ns
    }

    /// RK4 steps per frame.
    pub fn steps_per_frame(&self) -> u64 {
        self.frame_ns / self.sc.step_ns()
    }

    /// Number of effector entries (panel pairs, reaction wheels, then the actuators).
    pub fn n_effectors(&self) -> usize {
        self.sc.effector_count()
    }

    /// Commanded wrench (from the ACS controller), added to the scheduled disturbance wrench;
    /// held until the next call.
    pub fn set_command_wrench(&mut self, w: Wrench) {
        if w != self.command {
            self.frame_outputs = None;
        }
        self.command = w;
    }

    /// Sets every effector's commanded inputs from one flat vector laid out by
    /// [`Spacecraft::effector_input_ranges`] (e.g. every wheel's motor torque), held until the
    /// next call. They are added to the scheduled inputs (`[[effector_input_schedule]]`), as the
    /// commanded wrench is to the wrench schedule. Fails, changing nothing, on a wrong length or
    /// a non-finite value.
    pub fn set_effector_inputs(&mut self, u: &[f64]) -> Result<(), ParamError> {
        self.sc.check_effector_inputs(u)?;
        if self.inputs != u {
            self.frame_outputs = None;
            self.inputs.copy_from_slice(u);
            self.push_inputs();
        }
        Ok(())
    }

    /// The commanded effector inputs, flat.
    pub fn effector_inputs(&self) -> &[f64] {
        &self.inputs
    }

    /// The scheduled effector inputs in effect, flat (zero without `[[effector_input_schedule]]`).
    pub fn scheduled_effector_inputs(&self) -> &[f64] {
        &self.scheduled_inputs
    }

    /// Hands `command + schedule` to the effectors, through the actuator faults' port. Without
    /// a schedule or an actuator fault the command goes through untouched (bit for bit, −0.0
    /// included). A sum beyond ±f64::MAX is held at it: the effector clips it to its own limit
    /// anyway.
    fn push_inputs(&mut self) {
        let u: &[f64] = if self.input_schedule.is_empty() && !self.faults.has_actuator_faults() {
            &self.inputs
        } else {
            for ((a, c), s) in self
                .applied_inputs
                .iter_mut()
                .zip(&self.inputs)
                .zip(&self.scheduled_inputs)
            {
                *a = (c + s).clamp(-f64::MAX, f64::MAX);
            }
            self.faults.at_input_port(
                self.sc.t_sim_ns(),
                self.sc.state(),
                &mut self.applied_inputs,
            );
            &self.applied_inputs
        };
        // Cannot fail: the length is the spacecraft's and every value is finite.
        let _ = self.sc.set_effector_inputs(u);
    }

    /// The commanded wrench.
    pub fn command_wrench(&self) -> Wrench {
        self.command
    }

    /// Applies both schedules at the current time t: the wrench schedule(t) + command, and the
    /// effector-input rows that start at or before t (then command + schedule).
    #[inline]
    fn apply_schedules(&mut self) {
        let t = self.sc.t_sim_ns();
        let mut inputs_changed = false;
        while let Some(row) = self
            .input_schedule
            .get(self.input_cursor)
            .filter(|r| r.t_start_ns <= t)
        {
            let r = self.sc.effector_input_ranges()[row.effector_index].clone();
            self.scheduled_inputs[r].copy_from_slice(&row.inputs);
            self.input_cursor += 1;
            inputs_changed = true;
        }
        if inputs_changed {
            self.push_inputs();
        }
        while self.cursor < self.schedule.len() && self.schedule[self.cursor].t_start_ns <= t {
            self.cursor += 1;
        }
        let mut w = self.command;
        if let Some(seg) = self.cursor.checked_sub(1).map(|i| &self.schedule[i]) {
            w = w + seg.wrench();
        }
        self.sc.set_wrench(w);
    }

    /// Refills the environment sample when its update is due (at the start of a step), and hands
    /// it to the spacecraft; held otherwise. Allocates nothing.
    #[inline]
    fn update_environment(&mut self) {
        if let Some(env) = self.environment.as_mut() {
            let x = self.sc.state();
            if let Some(sample) = env.update_if_due(self.sc.t_sim_ns(), &x.r_bn_n, &x.v_bn_n) {
                self.sc.set_environment(sample);
            }
        }
    }

    /// Moves the environment models' updates to a worker thread
    /// ([`EnvironmentModel::offload`]): the physics thread then only picks up each sample. The
    /// run's output is bit-identical either way. Without `[environment]`, nothing to do.
    pub fn offload_environment(&mut self) -> std::io::Result<()> {
        match self.environment.as_mut() {
            Some(env) => env.offload(),
            None => Ok(()),
        }
    }

    /// The environment models, if configured.
    pub fn environment(&self) -> Option<&EnvironmentModel> {
        self.environment.as_ref()
    }

    /// One RK4 step: total wrench = schedule(t at step start) + command, then
    /// [`Spacecraft::step`]. Allocates nothing.
    #[inline]
    pub fn step(&mut self) {
        self.frame_outputs = None;
        self.apply_schedules();
        if self.faults.has_actuator_faults() {
            // The actuator faults see the time and state of every step's start.
            self.push_inputs();
        }
        self.update_environment();
        self.sc.step_with(&mut self.sensors);
    }

    /// [`Self::steps_per_frame`] steps.
    pub fn step_frame(&mut self) {
        for _ in 0..self.steps_per_frame() {
            self.step();
        }
    }

    /// `n` steps.
    pub fn step_n(&mut self, n: u64) {
        for _ in 0..n {
            self.step();
        }
    }

    /// The current state as a new record ([`Self::state_into`] into [`Self::blank_state`]).
    pub fn state_msg(&mut self) -> StateMsg {
        let mut out = self.blank_state();
        self.state_into(&mut out);
        out
    }

    /// A state record shaped for this spacecraft: one [`EffectorState`] per effector (its
    /// kind, zero states and outputs of its lengths), everything else zero, the identity
    /// attitude. Filling
    /// it with [`Self::state_into`] allocates nothing.
    pub fn blank_state(&self) -> StateMsg {
        StateMsg {
            effectors: self
                .sc
                .effector_entries()
                .map(|e| EffectorState {
                    kind: e.kind.wire_tag,
                    flags: 0,
                    states: vec![0.0; e.state_names.len()],
                    outputs: vec![0.0; e.output_names.len()],
                })
                .collect(),
            ..StateMsg::default()
        }
    }

    /// The hub outputs at the current state with the wrench and inputs that apply from now on:
    /// one derivative evaluation, shared by the state record and every sensor until the state, the
    /// wrench or the inputs change.
    fn frame_outputs(&mut self) -> HubOutputs {
        if let Some(o) = self.frame_outputs {
            return o;
        }
        self.apply_schedules();
        let o = self.sc.hub_outputs();
        self.frame_outputs = Some(o);
        o
    }

    /// Writes the current state into `out`, the one state record of flexdyn: the wire
    /// `StateMsg` that the server publishes and that `simulate` writes as a CSV row. One
    /// derivative evaluation, with the wrench and inputs that apply from now on (schedules +
    /// command), gives ω̇ and the non-gravitational acceleration. Sets `header.sim_time_ns`
    /// and every physical field; the rest of the header, `wrench_applied` and `command_flags`
    /// are the caller's (the server's command bookkeeping). Allocates nothing once `out` has
    /// this spacecraft's shape ([`Self::blank_state`], or a first call).
    pub fn state_into(&mut self, out: &mut StateMsg) {
        let hub = self.frame_outputs();
        self.sc
            .effector_outputs(&mut self.outputs_scratch, &mut self.flags_scratch);
        let state = self.sc.state();
        let dcm_nb = mrp_to_dcm(&state.sigma_bn).transpose();
        out.header.sim_time_ns = self.sc.t_sim_ns();
        out.sigma_bn = state.sigma_bn.into();
        out.q_bn = mrp_to_quat(&state.sigma_bn).into();
        out.omega_bn_b_rad_s = state.omega_bn_b.into();
        out.omega_dot_bn_b_rad_s2 = hub.omega_dot_bn_b.into();
        out.r_bn_n_m = state.r_bn_n.into();
        out.v_bn_n_m_s = state.v_bn_n.into();
        out.nongrav_accel_bn_n_m_s2 = (dcm_nb * hub.nongrav_accel_bn_b).into();
        out.effectors
            .resize_with(self.sc.effector_count(), EffectorState::default);
        let ranges = self
            .sc
            .effector_output_ranges()
            .iter()
            .zip(&self.flags_scratch);
        for ((o, e), (or, flags)) in out
            .effectors
            .iter_mut()
            .zip(self.sc.effector_entries())
            .zip(ranges)
        {
            o.kind = e.kind.wire_tag;
            o.flags = *flags;
            o.states.clear();
            o.states.extend_from_slice(&state.effectors[e.state_range]);
            o.outputs.clear();
            o.outputs
                .extend_from_slice(&self.outputs_scratch[or.clone()]);
        }
        let c = self.sc.conserved();
        out.conserved = flexdyn_proto::Conserved {
            orb_energy_j: c.orb_energy_j,
            rot_energy_j: c.rot_energy_j,
            orb_ang_mom_n: c.orb_ang_mom_n.into(),
            rot_ang_mom_c_n: c.rot_ang_mom_c_n.into(),
        };
    }

    /// `[environment] telemetry_rate_hz` as a whole number of frames: the environment record is
    /// due at the ticks that are multiples of it. `None` without that setting.
    pub fn environment_every_frames(&self) -> Option<u64> {
        self.environment_every_frames
    }

    /// Writes the environment at the current instant into `out`, the environment record of
    /// flexdyn: the wire `EnvironmentMsg` the server publishes and whose fields `simulate`
    /// writes as CSV columns. Sets `header.sim_time_ns` and every field; the rest of the header
    /// is the caller's.
    ///
    /// The instant is the current state's (the end of the last step): the environment sample is
    /// the one in force from now on ([`EnvironmentModel::sample_from`]: the sample the next
    /// step's stages read, refreshed now if its update is due now), and each source's force and
    /// torque is its own dynamic effector's evaluation at this state with that sample
    /// ([`Spacecraft::environment_wrenches`]), i.e. what it adds at the first stage of the next
    /// step. Gravity itself is not a source here: it is the uniform field acting at the centre
    /// of mass (no torque about C), in every state record already. Allocates nothing; not on
    /// the stepping path.
    pub fn environment_into(&mut self, out: &mut flexdyn_proto::EnvironmentMsg) {
        use flexdyn_proto::{eclipse, environment_flags as f, AppliedWrench};
        let t = self.sc.t_sim_ns();
        let x = self.sc.state();
        let (env, on) = match &mut self.environment {
            Some(m) => (m.sample_from(t, &x.r_bn_n, &x.v_bn_n), m.models_on()),
            None => (*self.sc.environment(), Default::default()),
        };
        let dcm_bn = mrp_to_dcm(&x.sigma_bn);
        let unit = |v: &nalgebra::Vector3<f64>| {
            let n = v.norm();
            if n > 0.0 {
                v / n
            } else {
                *v
            }
        };
        let sun_n = unit(&env.r_sun_b_n_m);
        let mut flags = 0;
        for (bit, is_on) in [
            (f::EPOCH_VALID, self.epoch.is_some()),
            (f::MAGNETIC, on.is_on("magnetic")),
            (f::SUN, on.is_on("sun")),
            (f::MOON, on.is_on("moon")),
            (f::SHADOW, on.is_on("shadow")),
            (f::ATMOSPHERE, on.is_on("atmosphere")),
            (f::ALBEDO, on.is_on("albedo")),
        ] {
            if is_on {
                flags |= bit;
            }
        }
        out.header.sim_time_ns = t;
        out.tai_ns_1958 = self.epoch.as_ref().map_or(0, |e| e.tai_ns_1958(t));
        out.flags = flags;
        out.eclipse = eclipse::of_shadow_factor(env.shadow_factor);
        out.b_n_t = env.b_field_n_t.into();
        out.b_b_t = (dcm_bn * env.b_field_n_t).into();
        out.sun_n = sun_n.into();
        out.sun_b = (dcm_bn * sun_n).into();
        out.moon_n = unit(&env.r_moon_b_n_m).into();
        out.shadow_factor = env.shadow_factor;
        out.density_kg_m3 = env.density_kg_m3;
        let w = self.sc.environment_wrenches(&env);
        let wire = |w: &Wrench| AppliedWrench {
            torque_b_nm: w.torque_b_nm.into(),
            force_b_newton: w.force_b_newton.into(),
        };
        out.gravity_gradient = wire(&w[EnvironmentSource::GravityGradient as usize]);
        out.drag = wire(&w[EnvironmentSource::Drag as usize]);
        out.solar_pressure = wire(&w[EnvironmentSource::SolarPressure as usize]);
        out.residual_dipole = wire(&w[EnvironmentSource::ResidualDipole as usize]);
        out.albedo_nadir_w_m2 = env
            .albedo
            .as_ref()
            .map_or(0.0, |cap| cap.nadir_irradiance_w_m2());
    }

    /// The `[epoch]` (the instant of t = 0), if configured.
    pub fn epoch(&self) -> Option<&flexdyn_environment::epoch::SimEpoch> {
        self.epoch.as_ref()
    }

    /// The faults at the ports.
    pub fn faults(&self) -> &Faults {
        &self.faults
    }

    /// The faults at the ports, mutably: live faults are installed here, and the server notes
    /// each frame boundary ([`Faults::note_boundary`]).
    pub fn faults_mut(&mut self) -> &mut Faults {
        &mut self.faults
    }

    /// The sensors, in publication order.
    pub fn sensors(&self) -> &SensorBank {
        &self.sensors
    }

    /// Samples every sensor `pick` selects at the current instant, from one truth: the state, the
    /// frame's hub outputs (with the wrench and inputs that apply from now on, as in
    /// [`Self::state_into`]; evaluated only if some sensor is picked, and shared with the state
    /// record) and the environment sample. [`SensorBank::sampled`] then lists them. After the
    /// first call this allocates nothing.
    pub fn sample_sensors(&mut self, pick: impl Fn(&dyn Sensor) -> bool) {
        if !self.sensors.any(&pick) {
            self.sensors.clear_sampled();
            return;
        }
        let hub = self.frame_outputs();
        let truth = Truth {
            t_sim_ns: self.sc.t_sim_ns(),
            state: self.sc.state(),
            hub: &hub,
            env: self.environment.as_ref().map(|_| self.sc.environment()),
            dynamic_effectors: self.sc.dynamic_effectors(),
        };
        self.sensors.sample(&truth, pick);
        self.faults
            .at_sensor_port(self.sc.t_sim_ns(), &mut self.sensors);
    }

    /// Sets every sensor's nominal sample interval (default: the frame period); `simulate`
    /// sets it to the log interval. It does not change where intervals end: that is when the
    /// sensor is sampled.
    pub fn set_sensor_sample_interval_ns(&mut self, interval_ns: NonZeroU64) {
        // A positive whole number of ns is finite and > 0.
        self.sensors
            .set_sample_interval_s(interval_ns.get() as f64 * 1e-9);
    }

    /// Starts a new interval of every sensor at the current state without sampling (an IMU
    /// discards the Δv accumulated so far). Call it after replacing the spacecraft state (e.g.
    /// a snapshot restore) so the next Δθ/Δv do not span the jump.
    pub fn restart_sensors(&mut self) {
        self.sensors.restart(self.sc.t_sim_ns(), self.sc.state());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector3, Vector4};

    #[test]
    fn schedule_plus_command() {
        let text = format!(
            "{}\n[[wrench_schedule]]\nt_s = 0.002\nforce_b_newton = [1.0, 0.0, 0.0]\ntorque_b_nm = [0.0, 0.0, 2.0]\n\n\
             [[wrench_schedule]]\nt_s = 0.004\nforce_b_newton = [0.0, 0.0, 0.0]\ntorque_b_nm = [0.0, 0.0, 0.0]\n",
            crate::config::DEFAULT_CONFIG_TOML
        );
        let cfg = SimConfig::from_toml_str(&text).unwrap();
        let mut sim = Simulation::new(&cfg).unwrap();
        sim.set_command_wrench(Wrench {
            force_b_newton: Vector3::new(0.0, 3.0, 0.0),
            torque_b_nm: Vector3::zeros(),
        });
        // The wrench that applies from each instant on, as the state record sees it.
        let applied = |sim: &mut Simulation| {
            let s = sim.state_msg();
            (s.header.sim_time_ns, sim.spacecraft().wrench())
        };
        let (_, w) = applied(&mut sim);
        assert_eq!(w.force_b_newton, Vector3::new(0.0, 3.0, 0.0));
        sim.step_n(2);
        let (t, w) = applied(&mut sim);
        assert_eq!(t, 2_000_000);
        assert_eq!(w.force_b_newton, Vector3::new(1.0, 3.0, 0.0));
        assert_eq!(w.torque_b_nm, Vector3::new(0.0, 0.0, 2.0));
        sim.step_n(2);
        let (_, w) = applied(&mut sim);
        assert_eq!(w.force_b_newton, Vector3::new(0.0, 3.0, 0.0));
        assert_eq!(sim.state_msg().effectors.len(), 2);
    }

    #[test]
    fn frame_stepping() {
        let mut sim = Simulation::new(&SimConfig::reference()).unwrap();
        assert_eq!(sim.steps_per_frame(), 10);
        sim.step_frame();
        assert_eq!(sim.t_sim_ns(), sim.frame_ns());
        let mut state = sim.blank_state();
        sim.state_into(&mut state);
        assert_eq!(state.header.sim_time_ns, 10_000_000);
        let q = Vector4::from(state.q_bn);
        assert!((q.norm() - 1.0).abs() < 1e-12);
    }
}
