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
//! same allocation-free [`Stepper`] the physics thread runs; the Zenoh `put` allocates inside
//! Zenoh, as it does on the telemetry thread. The stream is bit-identical to the threaded
//! design's: the same commands are offered for the same ticks in the same order.
//!
//! The run loop in [`super::run`] keeps the no-hang rules: it wakes every 50 ms to check the
//! participant timeout (no new tick within `participant_timeout_s`) and a stop request.

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Instant;

use flexdyn_proto::{CommandMsg, RunState};
use tokio::sync::Notify;

use super::error::ServerError;
use super::physics::{Ending, PhysicsReport};
use super::publish::{FramePublisher, Recording};
use super::shared::{Frame, Shared};
use super::stepper::{count_offer, Stepper};

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

/// The lockstep state machine, driven by the Zenoh command callback.
pub struct LockstepCore {
    w: Stepper,
    frame: Box<Frame>,
    publisher: FramePublisher,
    record: Option<Recording>,
    shared: Arc<Shared>,
    k: u64,
    total_frames: Option<u64>,
    phase: Phase,
    tick_published_at: Instant,
    events: Arc<Notify>,
    /// Holding at tick `k` on an operator's request: its answers are taken, but frame
    /// `k → k + 1` waits for [`Self::release_if_due`].
    holding: bool,
}

impl LockstepCore {
    /// A core at tick 0, not yet started; `events` is notified when the run ends.
    pub fn new(
        w: Stepper,
        frame: Box<Frame>,
        publisher: FramePublisher,
        record: Option<Recording>,
        shared: Arc<Shared>,
        total_frames: Option<u64>,
        events: Arc<Notify>,
    ) -> Self {
        let mut core = Self {
            w,
            frame,
            publisher,
            record,
            shared,
            k: 0,
            total_frames,
            phase: Phase::Waiting,
            tick_published_at: Instant::now(),
            events,
            holding: false,
        };
        core.w.book.begin_tick(0);
        core
    }

    /// Publishes tick 0 and starts stepping (after every participant is present).
    pub fn start(&mut self) {
        if !matches!(self.phase, Phase::Waiting) {
            return;
        }
        self.shared.set_run_state(RunState::Running);
        self.w.fill(&mut self.frame, 0);
        self.mark_hold();
        self.publish();
        if self.total_frames == Some(0) {
            self.end(Phase::Finished);
            return;
        }
        self.phase = Phase::Running;
        self.enter_hold();
        // Answers to tick 0 that came during the presence wait.
        if self.w.book.all_answered() && !self.holding {
            self.advance();
        }
    }

    /// Before publishing tick `k`: whether the operator holds the run there (never at the
    /// run's last tick); if so its time message says `Paused`.
    fn mark_hold(&mut self) {
        self.holding = self.shared.holds_at(self.k) && self.total_frames != Some(self.k);
        if self.holding {
            self.frame.time.run_state = RunState::Paused;
        }
    }

    /// After publishing a held tick: the status says `Paused` until released.
    fn enter_hold(&mut self) {
        if self.holding {
            self.shared.held.store(true, Ordering::Release);
            self.shared.set_run_state(RunState::Paused);
            tracing::info!(tick = self.k, "held by the operator");
        }
    }

    /// After the operator moved the hold target: if the held tick is no longer held, run on
    /// (stepping at once if every participant has answered it). The participant timeout
    /// restarts from here.
    pub fn release_if_due(&mut self) {
        if !self.holding || self.shared.holds_at(self.k) || self.ended() {
            return;
        }
        self.holding = false;
        self.shared.held.store(false, Ordering::Release);
        self.shared.set_run_state(RunState::Running);
        self.tick_published_at = Instant::now();
        tracing::info!(tick = self.k, "released by the operator");
        if matches!(self.phase, Phase::Running) && self.w.book.all_answered() {
            self.advance();
        }
    }

    /// A live fault request from the fault callback, installed before frame `k → k + 1` is
    /// stepped (so at boundary `k + 1` at the earliest); `Err` with the refusal's code
    /// ([`flexdyn_faults::ports::INSTALL_REFUSALS`]).
    pub fn install_fault(&mut self, req: flexdyn_faults::ports::LiveRequest) -> Result<(), u8> {
        if self.ended() {
            return Err(flexdyn_faults::ports::REFUSED_LATE);
        }
        self.w
            .install_fault(req, self.k)
            .map(drop)
            .map_err(|(code, _)| code)
    }

    /// A validated command from the Zenoh callback: offered for the current tick; the last
    /// answer steps the frame and publishes the next state.
    pub fn offer(&mut self, cmd: &CommandMsg) {
        if !matches!(self.phase, Phase::Waiting | Phase::Running) {
            return;
        }
        let offer = self.w.book.offer_lockstep(cmd, self.k);
        count_offer(&self.shared, offer, cmd.sender_id);
        if matches!(self.phase, Phase::Running) && self.w.book.all_answered() && !self.holding {
            self.advance();
        }
    }

    fn publish(&mut self) {
        self.frame.boundary_unix_ns = flexdyn_proto::client::transport::unix_now_ns();
        self.publisher
            .publish(&self.frame, &self.shared, self.record.as_ref());
        self.shared.tick.store(self.k, Ordering::Relaxed);
        self.tick_published_at = Instant::now();
    }

    /// Steps the answered tick, publishes the next, and goes on stepping while a tick needs no
    /// answer (every participant's command link `dropped`: [`flexdyn_faults::link`]), until one
    /// does, a hold, the end, or a stop request.
    fn advance(&mut self) {
        loop {
            self.w.step(self.k);
            self.w.note_links(&self.shared);
            self.k += 1;
            self.w.fill(&mut self.frame, self.k);
            if let Err(e) = self.w.check_finite(self.k, true) {
                self.end(Phase::Failed(e));
                return;
            }
            self.mark_hold();
            self.publish();
            if self.total_frames == Some(self.k) {
                self.end(Phase::Finished);
                return;
            }
            self.w.book.begin_tick(self.k);
            self.enter_hold();
            if !self.w.book.all_answered()
                || self.holding
                || self.shared.stop.load(Ordering::Relaxed)
            {
                return;
            }
        }
    }

    fn end(&mut self, phase: Phase) {
        self.shared.set_run_state(match &phase {
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
            let e = ServerError::ParticipantTimeout {
                participant: self.w.book.first_unanswered().unwrap_or_default(),
                tick: self.k,
                timeout_s: timeout.as_secs_f64(),
            };
            self.end(Phase::Failed(e));
        }
    }

    /// The outcome once [`Self::ended`]: the last tick published and its simulation time, or
    /// the failure. The failure is taken out: a second call reports the run as stopped.
    pub fn outcome(&mut self) -> Result<PhysicsReport, ServerError> {
        let report = |ending| PhysicsReport {
            ending,
            last_tick: self.k,
            sim_time_ns: self.k.saturating_mul(self.w.sim.frame_ns()),
        };
        match std::mem::replace(&mut self.phase, Phase::Stopped) {
            Phase::Finished => Ok(report(Ending::Finished)),
            Phase::Failed(e) => Err(e),
            _ => Ok(report(Ending::Stopped)),
        }
    }
}
