//! The physics thread: the frame loop of real time, batch, and lockstep with
//! `handoff = "thread"` (lockstep with `handoff = "direct"` steps in [`super::lockstep`]).
//!
//! At frame boundary `k` the loop
//! 1. (real time) waits for the deadline `t0 + k·period`, then publishes the already filled
//!    state of tick `k` (`handoff = "direct"`, real time) or hands it to the telemetry thread,
//!    stamped with the boundary's wall-clock time;
//! 2. takes the commands for tick `k` (real time/batch: whatever has arrived; lockstep: waits
//!    until every participant has answered tick `k`) and holds their sum over the frame;
//! 3. integrates the frame's RK4 steps ([`Simulation::step_frame`]);
//! 4. samples the sensors due at tick `k + 1` ([`Simulation::sample_sensors`]; an IMU closes
//!    its interval every frame) and fills the state and the sensor messages of tick `k + 1` into
//!    a free telemetry buffer.
//!
//! Steps 2–4 ([`Stepper`]) never allocate, lock or do I/O: commands arrive through a bounded
//! channel, the telemetry buffers are a fixed pool cycled through two bounded channels, and
//! counters are atomics. In real time the loop never blocks on the I/O side either: with no free
//! buffer the frame's telemetry is dropped and counted, and a direct publication uses
//! `CongestionControl::Drop`, so Zenoh drops a sample rather than make the put wait for the
//! network. The put itself (Zenoh's encoding and queueing, a few µs, see
//! `tools/benches/realtime.rs`) is the one piece of I/O-side work on this thread, at the
//! boundary, which is what takes the thread hop out of the telemetry latency.

use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, TryRecvError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use flexdyn_proto::client::transport::unix_now_ns;

use flexdyn_proto::{CommandMsg, Header, Mode, RunState, StateMsg};
use nalgebra::Vector3;

use super::clock::TimeService;
use super::commands::{CommandBook, Held, Offer};
use super::error::ServerError;
use super::pacing::{FrameEnd, Pacer};
use super::publish::FramePublisher;
use super::rt::{monotonic_ns, ThreadUsage};
use super::settings::ServerSettings;
use super::shared::{fill_state, Frame, Shared};
use flexdyn_dynamics::Wrench;
use flexdyn_sinks::table::first_non_finite;
use flexdyn_vehicle::sim::Simulation;

/// Longest single blocking wait, so a stop request is seen quickly.
const POLL: Duration = Duration::from_millis(50);

/// How often a held run looks at the operator's hold target (and the stop flag): the delay of a
/// resume.
pub(super) const HOLD_POLL: Duration = Duration::from_millis(1);

/// How the physics loop ended (errors are returned as [`ServerError`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// The configured duration was reached.
    Finished,
    /// A stop was requested (signal or shutdown future).
    Stopped,
}

/// What the physics loop reports when it ends normally.
#[derive(Clone, Copy, Debug)]
pub struct PhysicsReport {
    /// Why it ended.
    pub ending: Ending,
    /// The last tick reached (published or dropped).
    pub last_tick: u64,
    /// \[ns\] simulation time of `last_tick`.
    pub sim_time_ns: u64,
}

/// Everything the physics thread owns besides the [`Stepper`] it runs.
pub struct PhysicsCtx {
    /// Server settings.
    pub settings: ServerSettings,
    /// Frames to run (`None`: until stopped).
    pub total_frames: Option<u64>,
    /// Validated commands from the I/O side.
    pub cmd_rx: Receiver<CommandMsg>,
    /// Consumed commands, handed back to be freed off this thread (when the channel is full the
    /// command is freed here instead; never blocks).
    pub recycle_tx: SyncSender<CommandMsg>,
    /// Live fault requests, resolved by the fault callback ([`super::fault_cmd`]).
    pub fault_rx: Receiver<flexdyn_faults::ports::LiveRequest>,
    /// Installed requests' boxes, handed back to be freed off this thread.
    pub fault_recycle_tx: SyncSender<flexdyn_faults::ports::Installed>,
    /// Free telemetry buffers returned by the I/O thread.
    pub free_rx: Receiver<Box<Frame>>,
    /// Filled telemetry buffers to publish.
    pub full_tx: SyncSender<Box<Frame>>,
    /// Counters and the stop flag.
    pub shared: Arc<Shared>,
    /// Real time with `handoff = "direct"`: publish each frame from this thread at its boundary
    /// (`CongestionControl::Drop`: never waits for the network), then hand it to the telemetry
    /// thread for the books. `None`: the telemetry thread publishes.
    pub direct: Option<FramePublisher>,
    /// The telemetry thread, woken after each frame handed to it (`None` until it starts).
    pub wake: Option<std::thread::Thread>,
}

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

enum Wait {
    Done,
    Stopped,
}

impl PhysicsCtx {
    /// Runs the loop over `w` to its end; sets the shared run state accordingly. In real time,
    /// also this thread's page faults and context switches from the end of the first frame
    /// (which warms what is lazily set up on first use, such as Zenoh's per-thread state) to
    /// the end.
    pub fn run(mut self, w: Stepper) -> (Result<PhysicsReport, ServerError>, Option<ThreadUsage>) {
        let mut warm = None;
        let result = self.frame_loop(w, &mut warm);
        self.shared.set_run_state(match &result {
            Ok(r) if r.ending == Ending::Finished => RunState::Finished,
            Ok(_) => RunState::Stopped,
            Err(_) => RunState::Failed,
        });
        let usage = warm.map(|w: ThreadUsage| ThreadUsage::this_thread().since(&w));
        (result, usage)
    }

    /// A free telemetry buffer: real time never waits (`None` = drop this frame's telemetry);
    /// lockstep and batch wait for the I/O thread (`Err` = stop requested or I/O gone).
    fn acquire(&self, realtime: bool) -> Result<Option<Box<Frame>>, Wait> {
        if realtime {
            return match self.free_rx.try_recv() {
                Ok(f) => Ok(Some(f)),
                Err(TryRecvError::Empty) => {
                    self.shared
                        .telemetry_dropped
                        .fetch_add(1, Ordering::Relaxed);
                    Ok(None)
                }
                Err(TryRecvError::Disconnected) => Err(Wait::Stopped),
            };
        }
        loop {
            match self.free_rx.recv_timeout(POLL) {
                Ok(f) => return Ok(Some(f)),
                Err(RecvTimeoutError::Timeout) => {
                    if self.shared.stop.load(Ordering::Relaxed) {
                        return Err(Wait::Stopped);
                    }
                }
                Err(RecvTimeoutError::Disconnected) => return Err(Wait::Stopped),
            }
        }
    }

    /// Real time / batch: take every command that has arrived.
    fn drain_commands(&self, book: &mut CommandBook, k: u64) {
        while let Ok(cmd) = self.cmd_rx.try_recv() {
            count_offer(&self.shared, book.offer_latest(&cmd, k), cmd.sender_id);
            let _ = self.recycle_tx.try_send(cmd);
        }
    }

    /// Installs the live faults that have arrived, before frame `k → k + 1` is stepped; counts
    /// the refused ones. Allocation- and lock-free (the boxes go back to the telemetry thread).
    fn drain_faults(&self, w: &mut Stepper, k: u64) {
        while let Ok(req) = self.fault_rx.try_recv() {
            let installed = match w.install_fault(req, k) {
                Ok(i) => i,
                Err((code, i)) => {
                    self.shared.reject_fault_physics(code);
                    i
                }
            };
            let _ = self.fault_recycle_tx.try_send(installed);
        }
    }

    /// Holds at boundary `k` (already published) until the operator's hold target moves past it
    /// or is cleared; `false` if a stop was requested meanwhile. The status says `Paused`
    /// meanwhile. Nothing is stepped or published here.
    fn hold(&self, k: u64) -> bool {
        self.shared.held.store(true, Ordering::Release);
        self.shared.set_run_state(RunState::Paused);
        let mut stopped = false;
        while self.shared.holds_at(k) {
            if self.shared.stop.load(Ordering::Relaxed) {
                stopped = true;
                break;
            }
            std::thread::sleep(HOLD_POLL);
        }
        self.shared.held.store(false, Ordering::Release);
        if !stopped {
            self.shared.set_run_state(RunState::Running);
        }
        !stopped
    }

    /// Lockstep: wait until every participant has answered tick `k`.
    fn await_answers(&self, book: &mut CommandBook, k: u64) -> Result<Wait, ServerError> {
        book.begin_tick(k);
        let timeout = self.settings.participant_timeout;
        let give_up = Instant::now() + timeout;
        while !book.all_answered() {
            let now = Instant::now();
            if now >= give_up {
                return Err(ServerError::ParticipantTimeout {
                    participant: book.first_unanswered().unwrap_or_default(),
                    tick: k,
                    timeout_s: timeout.as_secs_f64(),
                });
            }
            match self.cmd_rx.recv_timeout((give_up - now).min(POLL)) {
                Ok(cmd) => {
                    count_offer(&self.shared, book.offer_lockstep(&cmd, k), cmd.sender_id);
                    let _ = self.recycle_tx.try_send(cmd);
                }
                Err(RecvTimeoutError::Timeout) => {
                    if self.shared.stop.load(Ordering::Relaxed) {
                        return Ok(Wait::Stopped);
                    }
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(ServerError::Internal("command channel closed".into()))
                }
            }
        }
        Ok(Wait::Done)
    }

    fn frame_loop(
        &mut self,
        mut w: Stepper,
        warm: &mut Option<ThreadUsage>,
    ) -> Result<PhysicsReport, ServerError> {
        let mode = self.settings.mode;
        let realtime = mode == Mode::RealTime;
        let frame_ns = w.sim.frame_ns();
        // A stop reports the last boundary reached (the tick the last StateMsg and StatusMsg
        // carry), not a tick that was stepped to but never published.
        let stopped = |shared: &Shared| {
            let k = shared.tick.load(Ordering::Relaxed);
            PhysicsReport {
                ending: Ending::Stopped,
                last_tick: k,
                sim_time_ns: k.saturating_mul(frame_ns),
            }
        };

        let mut k: u64 = 0;
        let mut pending = match self.acquire(realtime) {
            Ok(f) => f,
            Err(_) => return Ok(stopped(&self.shared)),
        };
        if let Some(f) = pending.as_mut() {
            w.fill(f, 0);
        }
        // Real time: boundary 0 is due one frame from now, so the I/O side is settled.
        // `--speed`: the wall-clock period of a frame (≥ 1 ns; `speed` is bounded by
        // `SPEED_RANGE`).
        let wall_period_ns = ((frame_ns as f64 / self.settings.speed).round() as u64).max(1);
        let mut pacer = Pacer::new(
            Instant::now() + Duration::from_nanos(wall_period_ns),
            wall_period_ns,
            self.settings.spin,
            self.settings.overrun_policy,
            self.settings.overrun_limit,
        );
        self.shared.set_run_state(RunState::Running);
        // The overrun log's clock starts before the first frame.
        monotonic_ns();

        loop {
            // 1. Frame boundary k: publish the state of tick k.
            let lateness_ns = if realtime {
                match pacer.wait_boundary(k, &self.shared.stop) {
                    Some(l) => l,
                    None => return Ok(stopped(&self.shared)),
                }
            } else {
                if self.shared.stop.load(Ordering::Relaxed) {
                    return Ok(stopped(&self.shared));
                }
                0
            };
            // When this frame's work starts (for the overrun log).
            let frame_start_ns = if realtime { monotonic_ns() } else { 0 };
            // Noted before the state goes out, so a participant answering it finds its tick
            // published (the command callback refuses ticks not yet published).
            self.shared.tick.store(k, Ordering::Release);
            // The operator's hold (one atomic load): this tick's time message says `Paused`,
            // and nothing follows until the hold is released. Never at the last tick.
            let hold = self.shared.holds_at(k) && self.total_frames != Some(k);
            if let (true, Some(f)) = (hold, pending.as_mut()) {
                f.time.run_state = RunState::Paused;
            }
            let stamp = unix_now_ns();
            if let Some(mut f) = pending.take() {
                f.boundary_unix_ns = stamp;
                f.lateness_ns = lateness_ns;
                // The handoff, timed (real time): the put itself with `direct`, and the
                // channel and the telemetry thread's wake-up either way.
                let t = Instant::now();
                if let Some(p) = self.direct.as_mut() {
                    p.publish(&f, &self.shared, None);
                    f.published = true;
                }
                // The full channel holds the whole pool, so this never blocks; and since the
                // telemetry thread never waits inside the channel (it parks instead, see
                // `telemetry`), sending takes no lock: a compare-and-swap, then `unpark`
                // (an atomic swap, and a FUTEX_WAKE only if that thread sleeps). Nothing here
                // waits for a thread of lower priority.
                if self.full_tx.try_send(f).is_err() {
                    return Err(ServerError::Internal("telemetry thread ended".into()));
                }
                if let Some(t) = &self.wake {
                    t.unpark();
                }
                if realtime {
                    self.shared
                        .note_handoff(u64::try_from(t.elapsed().as_nanos()).unwrap_or(u64::MAX));
                }
            }
            if self.total_frames == Some(k) {
                return Ok(PhysicsReport {
                    ending: Ending::Finished,
                    last_tick: k,
                    sim_time_ns: w.sim.t_sim_ns(),
                });
            }
            if hold {
                if !self.hold(k) {
                    return Ok(stopped(&self.shared));
                }
                // Real time: boundary k + 1 is due one period after the release, not at its
                // old deadline (no burst of catch-up frames).
                if realtime {
                    pacer.resume_after(k);
                }
            }

            // 2. Commands for tick k, held over the frame.
            match mode {
                Mode::Lockstep => {
                    if let Wait::Stopped = self.await_answers(&mut w.book, k)? {
                        return Ok(stopped(&self.shared));
                    }
                }
                Mode::RealTime | Mode::Batch => self.drain_commands(&mut w.book, k),
            }

            // Live faults for boundary k + 1 on, then 3. integrate the frame.
            self.drain_faults(&mut w, k);
            w.step(k);
            w.note_links(&self.shared);
            k += 1;

            // 4. Fill the state of tick k.
            pending = match self.acquire(realtime) {
                Ok(f) => f,
                Err(_) => return Ok(stopped(&self.shared)),
            };
            if let Some(f) = pending.as_mut() {
                w.fill(f, k);
            }
            w.check_finite(k, pending.is_some())?;
            if realtime && k == 1 {
                // Once, off the measured frames: the counters' baseline (reads /proc twice,
                // the first read warms the reading itself).
                ThreadUsage::this_thread();
                *warm = Some(ThreadUsage::this_thread());
            }
            if realtime {
                match pacer.end_frame(k) {
                    FrameEnd::OnTime => {}
                    FrameEnd::Overrun => {
                        self.shared
                            .overruns
                            .store(pacer.overruns, Ordering::Relaxed);
                        self.shared.overrun_log.note(frame_start_ns, monotonic_ns());
                    }
                    FrameEnd::Abort { consecutive } => {
                        self.shared
                            .overruns
                            .store(pacer.overruns, Ordering::Relaxed);
                        return Err(ServerError::OverrunLimit {
                            tick: k,
                            consecutive,
                            limit: self.settings.overrun_limit,
                        });
                    }
                }
                self.shared
                    .frames_skipped
                    .store(pacer.skipped, Ordering::Relaxed);
            }
        }
    }
}
