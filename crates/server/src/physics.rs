//! The physics thread: the one frame loop of real time, batch, and lockstep with
//! `handoff = "thread"`, over a world of one spacecraft or of a fleet ([`WorldStepper`]).
//! (Lockstep with `handoff = "direct"` steps one spacecraft's frames in [`super::lockstep`]
//! instead, on the thread that delivers each tick's last answer.)
//!
//! At frame boundary `k` the loop
//! 1. (real time) waits for the deadline `t0 + k·period`, then hands out the already filled
//!    telemetry of tick `k` of every vehicle, in world order, stamped with the boundary's
//!    wall-clock time, each through its [`Outlet`]: to its telemetry thread (which publishes it,
//!    or only keeps its books when this thread already put it, `handoff = "direct"`), or
//!    published in place (a fleet's vehicles, each followed by its relative states);
//! 2. takes the commands for tick `k`: lockstep waits until every participant of every vehicle
//!    has answered (one barrier for the whole world; a participant listed for several vehicles
//!    answers each of them on its own key); real time and batch take whatever has arrived. The
//!    commands are held over the frame;
//! 3. installs each vehicle's live faults that have arrived (from its own fault queue) and
//!    integrates every vehicle's frame ([`WorldStepper::step`]);
//! 4. samples the sensors due at tick `k + 1` and fills every vehicle's state and sensor
//!    messages of tick `k + 1` ([`WorldStepper::fill`]) into a telemetry buffer.
//!
//! Steps 2–4 never allocate, lock or do I/O: commands arrive through a bounded channel tagged
//! with the vehicle's index, the telemetry buffers are a fixed pool cycled through two bounded
//! channels (or one buffer per vehicle, published in place), and counters are atomics. A
//! consumed command goes back to its vehicle's telemetry thread to be freed there. In real time
//! the loop never blocks on the I/O side either: with no free buffer the frame's telemetry is
//! dropped and counted, and a publication from this thread uses `CongestionControl::Drop`, so
//! Zenoh drops a sample rather than make the put wait for the network. The put itself (Zenoh's
//! encoding and queueing, a few µs, see `tools/benches/realtime.rs`) is the one piece of
//! I/O-side work on this thread, at the boundary.

use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, TryRecvError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use flexdyn_proto::client::transport::unix_now_ns;
use flexdyn_proto::{CommandMsg, Mode, RunState};

use super::checkpoint::Checkpointer;
use super::error::ServerError;
use super::lateness_ring::LatenessRing;
use super::pacing::{FrameEnd, Pacer};
use super::publish::{FramePublisher, Recording};
use super::relative::{publish_deputy, RelativePublisher};
use super::rt::{monotonic_ns, ThreadUsage};
use super::settings::ServerSettings;
use super::shared::{Frame, Shared};
use super::stepper::count_offer;
use super::tick_cost::{ns_between, TickCost};
use super::world::WorldStepper;
use flexdyn_faults::ports::{Installed, LiveRequest};

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

/// How the physics thread ended, what it did, and (real time) its counters from the end of
/// the first frame to the end.
pub struct PhysicsOutcome {
    /// The ending, or the error that stopped the run.
    pub result: Result<PhysicsReport, ServerError>,
    /// Where the thread's time went, and when the ticks went out.
    pub ticks: TickCost,
    /// Real time: the thread's page faults and context switches over the measured frames.
    pub usage: Option<ThreadUsage>,
}

/// How one vehicle's telemetry leaves the physics thread.
pub enum Outlet {
    /// Buffers cycled through a telemetry thread (one spacecraft's server): a free buffer is
    /// taken before each fill and handed back full at the boundary.
    Pool {
        /// Free telemetry buffers returned by the telemetry thread.
        free_rx: Receiver<Box<Frame>>,
        /// Filled telemetry buffers to publish (or, with `direct`, to keep the books of).
        full_tx: SyncSender<Box<Frame>>,
        /// Real time with `handoff = "direct"`: publish each frame from this thread at its
        /// boundary (`CongestionControl::Drop`), then hand it over for the books. `None`: the
        /// telemetry thread publishes.
        direct: Option<FramePublisher>,
        /// The telemetry thread, woken after each frame handed to it (`None` until it starts).
        wake: Option<std::thread::Thread>,
    },
    /// This thread publishes the vehicle's one buffer itself at each boundary (a fleet's
    /// vehicles), then the vehicle's relative states.
    InPlace {
        /// The vehicle's frame publishers.
        publisher: FramePublisher,
        /// The recorder's view of its keys (`--record`).
        recording: Option<Recording>,
        /// The channel its telemetry (status) thread ends on when this is dropped.
        telemetry_alive: SyncSender<Box<Frame>>,
    },
}

/// One vehicle's side of the physics thread: its counters, its channels and its outlet.
pub struct Lane {
    /// The vehicle's counters (its StatusMsg reads them).
    pub shared: Arc<Shared>,
    /// Consumed commands, handed back to be freed off this thread (freed here only when the
    /// channel is full; never blocks).
    pub recycle_tx: SyncSender<CommandMsg>,
    /// Live fault requests, resolved by the vehicle's fault callback ([`super::fault_cmd`]).
    pub fault_rx: Receiver<LiveRequest>,
    /// Installed requests' boxes, handed back to be freed off this thread.
    pub fault_recycle_tx: SyncSender<Installed>,
    /// How its telemetry leaves.
    pub outlet: Outlet,
}

/// Everything the physics thread owns besides the [`WorldStepper`] it runs.
pub struct PhysicsCtx {
    /// The server's settings (mode, timeouts, pacing).
    pub settings: ServerSettings,
    /// Frames to run (`None`: until stopped).
    pub total_frames: Option<u64>,
    /// Validated commands, tagged with their vehicle's index.
    pub cmd_rx: Receiver<(usize, CommandMsg)>,
    /// Per vehicle, in world order.
    pub lanes: Vec<Lane>,
    /// The world's stop flag, operator hold target and published tick (one spacecraft: its own
    /// counters; a fleet: one block that every vehicle's operator callback moves).
    pub control: Arc<Shared>,
    /// Real time: every frame boundary's lateness, for the vehicles' telemetry threads (a
    /// fleet's; one spacecraft's frames carry their own).
    pub lateness: Option<Arc<LatenessRing>>,
    /// Per (chief, deputy) pair of the stepper ([`WorldStepper::pairs`], same order): its
    /// relative-state publisher.
    pub relative: Vec<RelativePublisher>,
    /// Whether an error about one vehicle names it ([`ServerError::Vehicle`]: a fleet's).
    pub name_vehicles: bool,
    /// The first tick (a resumed checkpoint's; else 0).
    pub start_tick: u64,
    /// Takes the checkpoints due at each boundary (`None`: this run saves none).
    pub checkpoints: Option<Checkpointer>,
}

enum Wait {
    Done,
    Stopped,
}

fn ns_since(t: Instant) -> u64 {
    ns_between(t, Instant::now())
}

/// A free telemetry buffer: real time never waits (`None` = drop this frame's telemetry, counted
/// in `shared`); lockstep and batch wait for the telemetry thread (`Err` = stop requested or
/// that thread gone).
fn acquire(
    free_rx: &Receiver<Box<Frame>>,
    realtime: bool,
    shared: &Shared,
    stop: &Shared,
) -> Result<Option<Box<Frame>>, Wait> {
    if realtime {
        return match free_rx.try_recv() {
            Ok(f) => Ok(Some(f)),
            Err(TryRecvError::Empty) => {
                shared.telemetry_dropped.fetch_add(1, Ordering::Relaxed);
                Ok(None)
            }
            Err(TryRecvError::Disconnected) => Err(Wait::Stopped),
        };
    }
    loop {
        match free_rx.recv_timeout(POLL) {
            Ok(f) => return Ok(Some(f)),
            Err(RecvTimeoutError::Timeout) => {
                if stop.stop.load(Ordering::Relaxed) {
                    return Err(Wait::Stopped);
                }
            }
            Err(RecvTimeoutError::Disconnected) => return Err(Wait::Stopped),
        }
    }
}

impl PhysicsCtx {
    /// Runs the loop over `world` to its end; sets every vehicle's run state accordingly.
    pub fn run(mut self, mut world: WorldStepper) -> PhysicsOutcome {
        let mut warm = None;
        let mut ticks = TickCost::default();
        let result = self.frame_loop(&mut world, &mut warm, &mut ticks);
        self.set_run_state(match &result {
            Ok(r) if r.ending == Ending::Finished => RunState::Finished,
            Ok(_) => RunState::Stopped,
            Err(_) => RunState::Failed,
        });
        let usage = warm.map(|w: ThreadUsage| ThreadUsage::this_thread().since(&w));
        PhysicsOutcome {
            result,
            ticks,
            usage,
        }
    }

    /// The telemetry thread of a one-spacecraft world, woken after each frame handed to it.
    pub fn set_wake(&mut self, thread: std::thread::Thread) {
        if let Some(Lane {
            outlet: Outlet::Pool { wake, .. },
            ..
        }) = self.lanes.first_mut()
        {
            *wake = Some(thread);
        }
    }

    fn set_run_state(&self, s: RunState) {
        for lane in &self.lanes {
            lane.shared.set_run_state(s);
        }
    }

    /// `e`, naming vehicle `v` in a fleet.
    fn named(&self, world: &WorldStepper, v: usize, e: ServerError) -> ServerError {
        if !self.name_vehicles {
            return e;
        }
        ServerError::Vehicle {
            vehicle: world
                .vehicles
                .get(v)
                .map(|v| v.id.clone())
                .unwrap_or_default(),
            source: Box::new(e),
        }
    }

    /// Counts `offer` under vehicle `v` and hands the consumed command back to be freed off this
    /// thread (freed here only if that vehicle's channel is full; never blocks).
    fn consumed(&self, v: usize, offer: super::commands::Offer, cmd: CommandMsg) {
        if let Some(lane) = self.lanes.get(v) {
            count_offer(&lane.shared, offer, cmd.sender_id);
            let _ = lane.recycle_tx.try_send(cmd);
        }
    }

    /// Real time / batch: takes every command that has arrived.
    fn drain_commands(&self, world: &mut WorldStepper, k: u64) {
        while let Ok((v, cmd)) = self.cmd_rx.try_recv() {
            let offer = world.offer_latest(v, &cmd, k);
            self.consumed(v, offer, cmd);
        }
    }

    /// Lockstep: waits until every participant of every vehicle has answered tick `k`.
    fn await_answers(&self, world: &mut WorldStepper, k: u64) -> Result<Wait, ServerError> {
        world.begin_tick(k);
        let timeout = self.settings.participant_timeout;
        let give_up = Instant::now() + timeout;
        while !world.all_answered() {
            let now = Instant::now();
            if now >= give_up {
                let (v, participant) = world.first_unanswered().unwrap_or_default();
                let e = ServerError::ParticipantTimeout {
                    participant,
                    tick: k,
                    timeout_s: timeout.as_secs_f64(),
                };
                return Err(self.named(world, v, e));
            }
            match self.cmd_rx.recv_timeout((give_up - now).min(POLL)) {
                Ok((v, cmd)) => {
                    let offer = world.offer_lockstep(v, &cmd, k);
                    self.consumed(v, offer, cmd);
                }
                Err(RecvTimeoutError::Timeout) => {
                    if self.control.stop.load(Ordering::Relaxed) {
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

    /// Installs each vehicle's live faults that have arrived, before frame `k → k + 1` is
    /// stepped; counts the refused ones under the vehicle. Allocation- and lock-free (the boxes
    /// go back to the vehicle's telemetry thread).
    fn drain_faults(&self, world: &mut WorldStepper, k: u64) {
        for (v, lane) in world.vehicles.iter_mut().zip(&self.lanes) {
            while let Ok(req) = lane.fault_rx.try_recv() {
                let installed = match v.stepper.install_fault(req, k) {
                    Ok(i) => i,
                    Err((code, i)) => {
                        lane.shared.reject_fault_physics(code);
                        i
                    }
                };
                let _ = lane.fault_recycle_tx.try_send(installed);
            }
        }
    }

    /// Holds the world at boundary `k` (already published) until the operator's hold target
    /// moves past it or is cleared; `false` if a stop was requested meanwhile. Every vehicle's
    /// status says `Paused` meanwhile; nothing is stepped or published here.
    fn hold(&self, k: u64) -> bool {
        for lane in &self.lanes {
            lane.shared.held.store(true, Ordering::Release);
        }
        self.set_run_state(RunState::Paused);
        let mut stopped = false;
        while self.control.holds_at(k) {
            if self.control.stop.load(Ordering::Relaxed) {
                stopped = true;
                break;
            }
            std::thread::sleep(HOLD_POLL);
        }
        for lane in &self.lanes {
            lane.shared.held.store(false, Ordering::Release);
        }
        if !stopped {
            self.set_run_state(RunState::Running);
        }
        !stopped
    }

    /// Takes a free buffer for every pooled vehicle, then fills every vehicle's tick `k`;
    /// `Ok(false)` if a stop was requested (or a telemetry thread is gone) meanwhile.
    fn fill(&self, world: &mut WorldStepper, k: u64, realtime: bool) -> Result<bool, ServerError> {
        for (v, lane) in world.vehicles.iter_mut().zip(&self.lanes) {
            if let Outlet::Pool { free_rx, .. } = &lane.outlet {
                match acquire(free_rx, realtime, &lane.shared, &self.control) {
                    Ok(f) => v.frame = f,
                    Err(Wait::Stopped | Wait::Done) => return Ok(false),
                }
            }
        }
        match world.fill(k) {
            Ok(()) => Ok(true),
            Err((v, e)) => Err(self.named(world, v, e)),
        }
    }

    /// Frame boundary `k`: hands out every vehicle's telemetry of tick `k`, in world order.
    fn hand_out(
        &mut self,
        world: &mut WorldStepper,
        lateness_ns: u64,
        realtime: bool,
    ) -> Result<(), ServerError> {
        let stamp = unix_now_ns();
        for (i, (v, lane)) in world.vehicles.iter_mut().zip(&mut self.lanes).enumerate() {
            match &mut lane.outlet {
                Outlet::Pool {
                    full_tx,
                    direct,
                    wake,
                    ..
                } => {
                    let Some(mut f) = v.frame.take() else {
                        continue;
                    };
                    f.boundary_unix_ns = stamp;
                    f.lateness_ns = lateness_ns;
                    // The handoff, timed (real time): the put itself with `direct`, and the
                    // channel and the telemetry thread's wake-up either way.
                    let t = Instant::now();
                    if let Some(p) = direct.as_mut() {
                        p.publish(&f, &lane.shared, None);
                        f.published = true;
                    }
                    // The full channel holds the whole pool, so this never blocks; and since
                    // the telemetry thread never waits inside the channel (it parks instead,
                    // see `telemetry`), sending takes no lock: a compare-and-swap, then
                    // `unpark` (an atomic swap, and a FUTEX_WAKE only if that thread sleeps).
                    // Nothing here waits for a thread of lower priority.
                    if full_tx.try_send(f).is_err() {
                        return Err(ServerError::Internal("telemetry thread ended".into()));
                    }
                    if let Some(t) = wake {
                        t.unpark();
                    }
                    if realtime {
                        lane.shared.note_handoff(ns_since(t));
                    }
                }
                Outlet::InPlace {
                    publisher,
                    recording,
                    ..
                } => {
                    if let Some(f) = v.frame.as_mut() {
                        f.boundary_unix_ns = stamp;
                        f.lateness_ns = lateness_ns;
                        publisher.publish(f, &lane.shared, recording.as_ref());
                    }
                    // Its relative states, after its frame.
                    publish_deputy(
                        i,
                        &world.pairs,
                        &mut self.relative,
                        stamp,
                        &lane.shared,
                        recording.as_ref(),
                    );
                }
            }
        }
        Ok(())
    }

    fn frame_loop(
        &mut self,
        world: &mut WorldStepper,
        warm: &mut Option<ThreadUsage>,
        ticks: &mut TickCost,
    ) -> Result<PhysicsReport, ServerError> {
        let mode = self.settings.mode;
        let realtime = mode == Mode::RealTime;
        let frame_ns = world.frame_ns();
        // A stop reports the last boundary reached (the tick the last StateMsg and StatusMsg
        // carry), not a tick that was stepped to but never published.
        let stopped = |control: &Shared| {
            let k = control.tick.load(Ordering::Relaxed);
            PhysicsReport {
                ending: Ending::Stopped,
                last_tick: k,
                sim_time_ns: k.saturating_mul(frame_ns),
            }
        };

        let mut k: u64 = self.start_tick;
        if !self.fill(world, k, realtime)? {
            return Ok(stopped(&self.control));
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
        )
        .first_tick(k);
        self.set_run_state(RunState::Running);
        // The overrun log's clock starts before the first frame.
        monotonic_ns();

        loop {
            // 1. Frame boundary k: hand out every vehicle's tick k.
            let lateness_ns = if realtime {
                match pacer.wait_boundary(k, &self.control.stop) {
                    Some(l) => {
                        if let Some(ring) = &self.lateness {
                            ring.push(l);
                        }
                        l
                    }
                    None => return Ok(stopped(&self.control)),
                }
            } else {
                if self.control.stop.load(Ordering::Relaxed) {
                    return Ok(stopped(&self.control));
                }
                0
            };
            // When this frame's work starts (for the overrun log).
            let frame_start_ns = if realtime { monotonic_ns() } else { 0 };
            // Noted before the states go out, so a participant answering one finds its tick
            // published (the command callback refuses ticks not yet published).
            for lane in &self.lanes {
                lane.shared.tick.store(k, Ordering::Release);
            }
            self.control.tick.store(k, Ordering::Release);
            // The operator's hold (one atomic load): this tick's time messages say `Paused`,
            // and nothing follows until the hold is released. Never at the last tick.
            let holding = self.control.holds_at(k) && self.total_frames != Some(k);
            if holding {
                for f in world.vehicles.iter_mut().filter_map(|v| v.frame.as_mut()) {
                    f.time.run_state = RunState::Paused;
                }
            }
            let t = Instant::now();
            // Real time paces the ticks itself (its lateness is the record there): no tick note
            // on its latency-sensitive path.
            if !realtime {
                ticks.published(k, t);
            }
            self.hand_out(world, lateness_ns, realtime)?;
            ticks.publish_ns += ns_since(t);
            if self.total_frames == Some(k) {
                return Ok(PhysicsReport {
                    ending: Ending::Finished,
                    last_tick: k,
                    sim_time_ns: world.sim_time_ns(),
                });
            }
            if holding {
                if !self.hold(k) {
                    return Ok(stopped(&self.control));
                }
                ticks.released(Instant::now());
                // Real time: boundary k + 1 is due one period after the release, not at its
                // old deadline (no burst of catch-up frames).
                if realtime {
                    pacer.resume_after(k);
                }
            }

            // 2. Commands for tick k, held over the frame.
            let t = Instant::now();
            match mode {
                Mode::Lockstep => {
                    if let Wait::Stopped = self.await_answers(world, k)? {
                        return Ok(stopped(&self.control));
                    }
                }
                Mode::RealTime | Mode::Batch => self.drain_commands(world, k),
            }
            ticks.wait_ns += ns_since(t);

            // Live faults for boundary k + 1 on, then 3. integrate every vehicle's frame and
            // 4. fill its telemetry of tick k + 1.
            let t = Instant::now();
            self.drain_faults(world, k);
            world.step(k);
            for (v, lane) in world.vehicles.iter().zip(&self.lanes) {
                v.stepper.note_links(&lane.shared);
            }
            k += 1;
            // A checkpoint due at this boundary: its state before its telemetry is filled.
            if let Some(c) = self.checkpoints.as_mut() {
                c.at_boundary(world, k);
            }
            if !self.fill(world, k, realtime)? {
                return Ok(stopped(&self.control));
            }
            ticks.frames += 1;
            ticks.physics_ns += ns_since(t);
            if realtime && k == self.start_tick + 1 {
                // Once, off the measured frames: the counters' baseline (reads /proc twice,
                // the first read warms the reading itself).
                ThreadUsage::this_thread();
                *warm = Some(ThreadUsage::this_thread());
            }
            if realtime {
                match pacer.end_frame(k) {
                    FrameEnd::OnTime => {}
                    FrameEnd::Overrun => {
                        let end_ns = monotonic_ns();
                        for lane in &self.lanes {
                            lane.shared
                                .overruns
                                .store(pacer.overruns, Ordering::Relaxed);
                            lane.shared.overrun_log.note(frame_start_ns, end_ns);
                        }
                    }
                    FrameEnd::Abort { consecutive } => {
                        for lane in &self.lanes {
                            lane.shared
                                .overruns
                                .store(pacer.overruns, Ordering::Relaxed);
                        }
                        return Err(ServerError::OverrunLimit {
                            tick: k,
                            consecutive,
                            limit: self.settings.overrun_limit,
                        });
                    }
                }
                for lane in &self.lanes {
                    lane.shared
                        .frames_skipped
                        .store(pacer.skipped, Ordering::Relaxed);
                }
            }
        }
    }
}
