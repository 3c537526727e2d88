//! Lockstep with `server.handoff = "direct"` (what the default `auto` gives in lockstep): the
//! frame is stepped on the thread that delivers its last answer.
//!
//! A lockstep tick is a round trip: the server publishes the state of tick `k`, every
//! participant answers it, and only then is frame `k → k + 1` computed. With a separate physics
//! thread (`handoff = "thread"`) each tick pays two thread wake-ups on the server on top of
//! the network round trip: the Zenoh callback wakes the physics thread, which wakes the
//! telemetry thread to publish. Here the Zenoh callback that delivers the last answer offers it
//! to the [`LockstepCore`] and, the tick being complete, steps the frame (1.8 µs for one RK4
//! step of the reference spacecraft), fills and publishes the state of `k + 1` itself. Nothing
//! waits for another thread, so a tick costs what a plain Zenoh ping-pong costs plus the
//! physics (see `tools/benches/lockstep.rs`).
//!
//! What it trades: the core sits behind a mutex taken once per command. With one participant
//! it is never contended; with several, their callbacks take turns, which is what lockstep
//! needs anyway. The per-frame work itself (command book, RK4, sensors, telemetry fill) is the
//! same allocation-free `Stepper` the physics thread runs; the Zenoh `put` allocates inside
//! Zenoh, as it does on the telemetry thread. The stream is bit-identical to the threaded
//! design's: the same commands are offered for the same ticks in the same order.
//!
//! The run loop in [`super::run`] keeps the no-hang rules: it wakes every 50 ms to check the
//! participant timeout (no new tick within `participant_timeout_s`) and a stop request.
//!
//! The core steps a world ([`WorldStepper`]), as the physics thread's loop does: one spacecraft
//! is a world of one, and a fleet's core takes every vehicle's answers (each vehicle's command
//! callback offers to it with the vehicle's index), steps every vehicle once all have answered,
//! and publishes every vehicle's frame in fleet order, each deputy's relative states after its
//! frame. Each vehicle's stream is the one the physics thread would publish, bit for bit.

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Instant;

use flexdyn_proto::{CommandMsg, RunState};
use tokio::sync::Notify;

use super::checkpoint::Checkpointer;
use super::error::ServerError;
use super::physics::{Ending, PhysicsReport};
use super::publish::{FramePublisher, Recording};
use super::relative::{publish_deputy, RelativePublisher};
use super::shared::Shared;
use super::stepper::count_offer;
use super::tick_cost::{ns_between, TickCost};
use super::world::WorldStepper;

/// Where a direct lockstep run is.
#[derive(Debug)]
pub enum Phase {
    /// Before tick 0 (the presence wait): answers are taken for tick 0, nothing is stepped.
    Waiting,
    /// Tick `k` is published; waiting for its answers.
    Running,
    /// The configured duration was reached.
    Finished,
    /// Stopped on request.
    Stopped,
    /// Failed (non-finite state, or a participant timed out).
    Failed(ServerError),
}

/// One vehicle's outlet in the core: its publishers, its recorder view and its counters.
pub struct CoreLane {
    /// Its frame publishers.
    pub publisher: FramePublisher,
    /// The recorder's view of its keys (`--record`).
    pub record: Option<Recording>,
    /// Its counters (its StatusMsg reads them).
    pub shared: Arc<Shared>,
}

/// One vehicle's way into the world's core: what its command and fault callbacks hold in
/// lockstep with `handoff = "direct"`. Each call takes the core's lock and passes the vehicle's
/// index along.
#[derive(Clone)]
pub struct VehicleCore {
    /// The vehicle's index in the world (0 for one spacecraft).
    pub vehicle: usize,
    /// The world's core.
    pub core: Arc<std::sync::Mutex<LockstepCore>>,
}

impl VehicleCore {
    fn lock(&self) -> std::sync::MutexGuard<'_, LockstepCore> {
        self.core.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// [`LockstepCore::offer`] for this vehicle.
    pub fn offer(&self, cmd: &CommandMsg) {
        self.lock().offer(self.vehicle, cmd);
    }

    /// [`LockstepCore::install_fault`] for this vehicle.
    pub fn install_fault(&self, req: flexdyn_faults::ports::LiveRequest) -> Result<(), u8> {
        self.lock().install_fault(self.vehicle, req)
    }
}

/// The lockstep state machine, driven by the Zenoh command callbacks.
pub struct LockstepCore {
    world: WorldStepper,
    lanes: Vec<CoreLane>,
    /// Per (chief, deputy) pair of the world, same order: its relative-state publisher.
    relative: Vec<RelativePublisher>,
    /// The world's stop flag, operator hold target and published tick (one spacecraft: its own
    /// counters).
    control: Arc<Shared>,
    /// Whether an error about one vehicle names it (a fleet's).
    name_vehicles: bool,
    k: u64,
    total_frames: Option<u64>,
    phase: Phase,
    tick_published_at: Instant,
    events: Arc<Notify>,
    /// Holding at tick `k` on an operator's request: its answers are taken, but frame
    /// `k → k + 1` waits for [`Self::release_if_due`].
    holding: bool,
    ticks: TickCost,
    /// Takes the checkpoints due at each boundary (`None`: this run saves none).
    checkpoints: Option<Checkpointer>,
}

impl LockstepCore {
    /// A core at tick 0, not yet started; every vehicle of `world` has its own telemetry buffer
    /// and `lanes[i]` is vehicle `i`'s; `events` is notified when the run ends. A resumed run
    /// starts at its checkpoint's tick ([`Self::resumed_at`]).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        world: WorldStepper,
        lanes: Vec<CoreLane>,
        relative: Vec<RelativePublisher>,
        control: Arc<Shared>,
        name_vehicles: bool,
        total_frames: Option<u64>,
        events: Arc<Notify>,
    ) -> Self {
        let mut core = Self {
            world,
            lanes,
            relative,
            control,
            name_vehicles,
            k: 0,
            total_frames,
            phase: Phase::Waiting,
            tick_published_at: Instant::now(),
            events,
            holding: false,
            ticks: TickCost::default(),
            checkpoints: None,
        };
        core.world.begin_tick(0);
        core
    }

    /// Takes the checkpoints `c` says are due.
    pub fn with_checkpoints(mut self, c: Option<Checkpointer>) -> Self {
        self.checkpoints = c;
        self
    }

    /// The world, before the run starts (to restore a checkpoint into).
    pub fn world_mut(&mut self) -> &mut WorldStepper {
        &mut self.world
    }

    /// Starts at tick `k` (a checkpoint restored into the world was taken there).
    pub fn resumed_at(&mut self, k: u64) {
        self.k = k;
        self.world.begin_tick(k);
    }

    fn set_run_state(&self, s: RunState) {
        for lane in &self.lanes {
            lane.shared.set_run_state(s);
        }
    }

    /// `e`, naming vehicle `v` in a fleet.
    fn named(&self, v: usize, e: ServerError) -> ServerError {
        if !self.name_vehicles {
            return e;
        }
        ServerError::Vehicle {
            vehicle: self
                .world
                .vehicles
                .get(v)
                .map(|v| v.id.clone())
                .unwrap_or_default(),
            source: Box::new(e),
        }
    }

    /// Publishes tick 0 and starts stepping (after every participant is present).
    pub fn start(&mut self) {
        if !matches!(self.phase, Phase::Waiting) {
            return;
        }
        self.set_run_state(RunState::Running);
        if let Err((v, e)) = self.world.fill(self.k) {
            let e = self.named(v, e);
            self.end(Phase::Failed(e));
            return;
        }
        self.mark_hold();
        self.publish();
        if self.total_frames == Some(self.k) {
            self.end(Phase::Finished);
            return;
        }
        self.phase = Phase::Running;
        self.enter_hold();
        // Answers to tick 0 that came during the presence wait.
        if self.world.all_answered() && !self.holding {
            self.advance();
        }
    }

    /// Before publishing tick `k`: whether the operator holds the run there (never at the
    /// run's last tick); if so every time message says `Paused`.
    fn mark_hold(&mut self) {
        self.holding = self.control.holds_at(self.k) && self.total_frames != Some(self.k);
        if self.holding {
            for f in self
                .world
                .vehicles
                .iter_mut()
                .filter_map(|v| v.frame.as_mut())
            {
                f.time.run_state = RunState::Paused;
            }
        }
    }

    /// After publishing a held tick: every status says `Paused` until released.
    fn enter_hold(&mut self) {
        if self.holding {
            for lane in &self.lanes {
                lane.shared.held.store(true, Ordering::Release);
            }
            self.set_run_state(RunState::Paused);
            tracing::info!(tick = self.k, "held by the operator");
        }
    }

    /// After the operator moved the hold target: if the held tick is no longer held, run on
    /// (stepping at once if every participant has answered it). The participant timeout
    /// restarts from here.
    pub fn release_if_due(&mut self) {
        if !self.holding || self.control.holds_at(self.k) || self.ended() {
            return;
        }
        self.holding = false;
        for lane in &self.lanes {
            lane.shared.held.store(false, Ordering::Release);
        }
        self.set_run_state(RunState::Running);
        self.tick_published_at = Instant::now();
        self.ticks.released(self.tick_published_at);
        tracing::info!(tick = self.k, "released by the operator");
        if matches!(self.phase, Phase::Running) && self.world.all_answered() {
            self.advance();
        }
    }

    /// A live fault request for vehicle `vehicle` from its fault callback, installed before
    /// frame `k → k + 1` is stepped (so at boundary `k + 1` at the earliest); `Err` with the
    /// refusal's code ([`flexdyn_faults::ports::INSTALL_REFUSALS`]).
    pub fn install_fault(
        &mut self,
        vehicle: usize,
        req: flexdyn_faults::ports::LiveRequest,
    ) -> Result<(), u8> {
        if self.ended() {
            return Err(flexdyn_faults::ports::REFUSED_LATE);
        }
        let k = self.k;
        match self.world.vehicles.get_mut(vehicle) {
            Some(v) => v
                .stepper
                .install_fault(req, k)
                .map(drop)
                .map_err(|(code, _)| code),
            None => Err(flexdyn_faults::ports::REFUSED_LATE),
        }
    }

    /// A validated command for vehicle `vehicle` from its command callback: offered for the
    /// current tick; the last answer of the world steps the frame and publishes the next state.
    pub fn offer(&mut self, vehicle: usize, cmd: &CommandMsg) {
        if !matches!(self.phase, Phase::Waiting | Phase::Running) {
            return;
        }
        let offer = self.world.offer_lockstep(vehicle, cmd, self.k);
        if let Some(lane) = self.lanes.get(vehicle) {
            count_offer(&lane.shared, offer, cmd.sender_id);
        }
        if matches!(self.phase, Phase::Running) && self.world.all_answered() && !self.holding {
            self.advance();
        }
    }

    /// Notes tick `k` reached, then publishes every vehicle's frame of it, in world order, each
    /// deputy's relative states after its frame.
    fn publish(&mut self) {
        let started = Instant::now();
        self.ticks.published(self.k, started);
        let stamp = flexdyn_proto::client::transport::unix_now_ns();
        // Noted before the states go out (as the physics thread does, and as `Shared::tick`
        // says), so a participant's flight-code telemetry for tick k, sent as soon as it has
        // the state of k, finds k reached.
        for lane in &self.lanes {
            lane.shared.tick.store(self.k, Ordering::Release);
        }
        self.control.tick.store(self.k, Ordering::Release);
        for (i, (v, lane)) in self
            .world
            .vehicles
            .iter_mut()
            .zip(&mut self.lanes)
            .enumerate()
        {
            if let Some(f) = v.frame.as_mut() {
                f.boundary_unix_ns = stamp;
                lane.publisher
                    .publish(f, &lane.shared, lane.record.as_ref());
            }
            publish_deputy(
                i,
                &self.world.pairs,
                &mut self.relative,
                stamp,
                &lane.shared,
                lane.record.as_ref(),
            );
        }
        self.tick_published_at = Instant::now();
        self.ticks.publish_ns += ns_between(started, self.tick_published_at);
    }

    /// Steps the answered tick, publishes the next, and goes on stepping while a tick needs no
    /// answer (every participant's command link `dropped`: [`flexdyn_faults::link`]), until one
    /// does, a hold, the end, or a stop request.
    fn advance(&mut self) {
        loop {
            let started = Instant::now();
            self.ticks.wait_ns += ns_between(self.tick_published_at, started);
            self.world.step(self.k);
            for (v, lane) in self.world.vehicles.iter().zip(&self.lanes) {
                v.stepper.note_links(&lane.shared);
            }
            self.k += 1;
            // A checkpoint due at this boundary: its state before its telemetry is filled.
            if let Some(c) = self.checkpoints.as_mut() {
                c.at_boundary(&mut self.world, self.k);
            }
            let filled = self.world.fill(self.k);
            self.ticks.frames += 1;
            self.ticks.physics_ns += ns_between(started, Instant::now());
            if let Err((v, e)) = filled {
                let e = self.named(v, e);
                self.end(Phase::Failed(e));
                return;
            }
            self.mark_hold();
            self.publish();
            if self.total_frames == Some(self.k) {
                self.end(Phase::Finished);
                return;
            }
            self.world.begin_tick(self.k);
            self.enter_hold();
            if !self.world.all_answered()
                || self.holding
                || self.control.stop.load(Ordering::Relaxed)
            {
                return;
            }
        }
    }

    fn end(&mut self, phase: Phase) {
        self.set_run_state(match &phase {
            Phase::Finished => RunState::Finished,
            Phase::Stopped => RunState::Stopped,
            _ => RunState::Failed,
        });
        self.phase = phase;
        self.events.notify_one();
    }

    /// Whether the run has ended (finished, stopped or failed).
    pub fn ended(&self) -> bool {
        !matches!(self.phase, Phase::Waiting | Phase::Running)
    }

    /// Stops taking answers (a stop request); nothing is stepped after this returns.
    pub fn stop(&mut self) {
        if !self.ended() {
            self.end(Phase::Stopped);
        }
    }

    /// Fails the run if the current tick has waited longer than `timeout` for its answers.
    pub fn check_timeout(&mut self, timeout: std::time::Duration) {
        if matches!(self.phase, Phase::Running)
            && !self.holding
            && self.tick_published_at.elapsed() >= timeout
        {
            let (v, participant) = self.world.first_unanswered().unwrap_or_default();
            let e = ServerError::ParticipantTimeout {
                participant,
                tick: self.k,
                timeout_s: timeout.as_secs_f64(),
            };
            let e = self.named(v, e);
            self.end(Phase::Failed(e));
        }
    }

    /// Where the core's time went: stepping and filling, publishing, and waiting for answers;
    /// and when the ticks went out (taken: the core keeps an empty record).
    pub fn take_ticks(&mut self) -> TickCost {
        std::mem::take(&mut self.ticks)
    }

    /// The outcome once [`Self::ended`]: the last tick published and its simulation time, or
    /// the failure. The failure is taken out: a second call reports the run as stopped.
    pub fn outcome(&mut self) -> Result<PhysicsReport, ServerError> {
        let report = |ending| PhysicsReport {
            ending,
            last_tick: self.k,
            sim_time_ns: self.k.saturating_mul(self.world.frame_ns()),
        };
        match std::mem::replace(&mut self.phase, Phase::Stopped) {
            Phase::Finished => Ok(report(Ending::Finished)),
            Phase::Failed(e) => Err(e),
            _ => Ok(report(Ending::Stopped)),
        }
    }
}
