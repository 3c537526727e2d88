//! One vehicle's per-frame work ([`Stepper`]): its simulation, its command book and the command
//! held over the frame, and the telemetry fill. The physics thread's frame loop
//! ([`super::physics`], through [`super::world::WorldStepper`]) and the direct lockstep core
//! ([`super::lockstep`]) both step frames with it. Nothing here allocates after
//! [`Stepper::new`] (checked in `tests/server_alloc.rs`).

use flexdyn_proto::{Header, RunState, StateMsg};
use nalgebra::Vector3;

use super::clock::TimeService;
use super::commands::{CommandBook, Held, Offer};
use super::error::ServerError;
use super::settings::ServerSettings;
use super::shared::{fill_state, Frame, Shared};
use flexdyn_dynamics::Wrench;
use flexdyn_sinks::table::first_non_finite;
use flexdyn_vehicle::sim::Simulation;

/// The per-frame work shared by the physics thread and the lockstep core
/// ([`super::lockstep`]): the simulation, the command book, and the buffers the frame is
/// sampled into. Nothing here allocates after [`Stepper::new`].
pub struct Stepper {
    /// The simulation.
    pub sim: Simulation,
    /// Per-participant commands.
    pub book: CommandBook,
    /// The command held over the current frame.
    pub held: Held,
    /// The state record of the last tick filled or checked.
    state: StateMsg,
    spacecraft_id: u32,
    /// The time message's per-run constants.
    pub clock: TimeService,
}

impl Stepper {
    /// A stepper at t = 0 with the sensors sampled at tick 0.
    pub fn new(mut sim: Simulation, settings: &ServerSettings) -> Self {
        let links = flexdyn_faults::link::LinkFaults::new(sim.faults().specs(), sim.frame_ns());
        let book = CommandBook::new(
            &settings.participants,
            sim.frame_ns(),
            u64::try_from(settings.stale_after.as_nanos()).unwrap_or(u64::MAX),
            settings.stale_policy,
            sim.spacecraft().effector_input_ranges(),
        )
        .with_links(links, settings.spacecraft_id);
        let state = sim.blank_state();
        // Live faults go into slots reserved here (the stepping path never allocates one).
        sim.faults_mut().reserve_live();
        // Sensors are sampled at every frame where they are due, published or not (an IMU
        // closes its interval every frame).
        sim.sample_sensors(|s| s.due(0));
        let t0 = sim.t_sim_ns();
        sim.faults_mut().note_boundary(0, t0);
        let clock = TimeService::new(
            sim.epoch().cloned(),
            settings.spacecraft_id,
            sim.frame_ns(),
            settings.mode,
            settings.speed,
        );
        Self {
            clock,
            sim,
            book,
            held: Held::initial(settings.stale_policy),
            state,
            spacecraft_id: settings.spacecraft_id,
        }
    }

    /// Fills the telemetry of tick `k` (the sensors were sampled at `k`).
    pub fn fill(&mut self, frame: &mut Frame, k: u64) {
        self.sim.state_into(&mut self.state);
        let header = Header::new(self.spacecraft_id, k, self.state.header.sim_time_ns, k);
        fill_state(&mut frame.state, &self.state, header, &self.held);
        frame.time = self.clock.message(k, RunState::Running);
        frame.command = self.held.status;
        frame.environment = None;
        if let Some(every) = self.sim.environment_every_frames() {
            if k.is_multiple_of(every) {
                let mut env = flexdyn_proto::EnvironmentMsg::default();
                self.sim.environment_into(&mut env);
                env.header = Header::new(self.spacecraft_id, k, env.header.sim_time_ns, k / every);
                frame.environment = Some(env);
            }
        }
        frame.lateness_ns = 0;
        frame.published = false;
        frame.fault_events.clear();
        let faults = self.sim.faults_mut();
        faults.take_events_into(self.spacecraft_id, &mut frame.fault_events);
        frame.faults_active = faults.active();
        frame.sensors_sampled.clear();
        let bank = self.sim.sensors();
        for &i in bank.sampled() {
            if let (Some(s), Some(buf)) = (bank.sensors().get(i), frame.sensor_payloads.get_mut(i))
            {
                s.encode(frame.state.header, buf);
                frame.sensors_sampled.push(i);
            }
        }
    }

    /// The spacecraft id its messages carry.
    pub fn spacecraft_id(&self) -> u32 {
        self.spacecraft_id
    }

    /// \[ns\] simulation time of the last tick filled (or checked).
    pub fn filled_sim_time_ns(&self) -> u64 {
        self.state.header.sim_time_ns
    }

    /// Frame `k` → `k + 1`: holds the book's commands for tick `k`, integrates the frame's RK4
    /// steps and samples the sensors at `k + 1`.
    pub fn step(&mut self, k: u64) {
        self.held = self.book.held(k);
        self.sim.set_command_wrench(Wrench {
            force_b_newton: Vector3::from(self.held.force_b_newton),
            torque_b_nm: Vector3::from(self.held.torque_b_nm),
        });
        // Cannot fail: the book's inputs have the spacecraft's layout and were checked
        // finite by the decoder.
        let _ = self.sim.set_effector_inputs(self.book.held_inputs());
        self.sim.step_frame();
        self.sim.sample_sensors(|s| s.due(k + 1));
        let t = self.sim.t_sim_ns();
        self.sim.faults_mut().note_boundary(k + 1, t);
    }

    /// Installs a live fault request before frame `k → k + 1` is stepped (it takes effect at
    /// boundary `k + 1` at the earliest). Allocation- and lock-free; the request's box comes
    /// back to be freed off the stepping path, refused or not.
    pub fn install_fault(
        &mut self,
        req: flexdyn_faults::ports::LiveRequest,
        k: u64,
    ) -> Result<flexdyn_faults::ports::Installed, (u8, flexdyn_faults::ports::Installed)> {
        // A clear of a command-link fault also reaches the command book, where it acts.
        let clears = req.clears();
        let at_ns = req.applies_at(k + 1).saturating_mul(self.sim.frame_ns());
        let installed = self.sim.faults_mut().install(req, k + 1)?;
        if let Some(i) = clears {
            self.book.clear_link_fault(i, at_ns);
        }
        Ok(installed)
    }

    /// Copies what the command-link faults did into `shared` (a few atomic stores; nothing
    /// without link faults).
    pub fn note_links(&self, shared: &Shared) {
        if !self.book.links().is_empty() {
            shared.note_link_stats(&self.book.link_stats());
        }
    }

    /// Once per frame, outside the RK4 loop: never publish a non-finite state. `filled` says
    /// whether [`Self::fill`] already took this tick's state.
    pub fn check_finite(&mut self, k: u64, filled: bool) -> Result<(), ServerError> {
        if !filled {
            self.sim.state_into(&mut self.state);
        }
        let sensor_bad = self
            .sim
            .sensors()
            .first_non_finite()
            .map(|(s, q)| format!("{}'s {q} output", s.kind().a_noun));
        match first_non_finite(&self.state).or(sensor_bad) {
            Some(quantity) => Err(ServerError::NonFinite {
                tick: k,
                t_s: self.state.header.sim_time_ns as f64 * 1e-9,
                quantity,
            }),
            None => Ok(()),
        }
    }
}

/// Counts a command the book rejected under its reason.
pub fn count_offer(shared: &Shared, offer: Offer, sender_id: u32) {
    match offer {
        Offer::Accepted => {}
        Offer::StaleTick => shared.reject_stale_tick_from(sender_id),
        Offer::UnknownSender => shared.reject_unknown_sender(),
        Offer::BadEffectorInput => shared.reject_bad_effector_input(),
        // Counted in the book's link statistics.
        Offer::LinkDropped => {}
        Offer::LinkCorrupted(why) => shared.reject_damaged(why, sender_id),
    }
}
