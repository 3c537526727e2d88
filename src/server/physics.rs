//! The physics thread: the frame loop of every mode.
//!
//! At frame boundary `k` the loop
//! 1. (real time) waits for the deadline `t0 + k·period`, then hands the already filled state of
//!    tick `k` to the I/O thread, stamped with the boundary's wall-clock time;
//! 2. takes the commands for tick `k` (real time/batch: whatever has arrived; lockstep: waits
//!    until every participant has answered tick `k`) and holds their sum over the frame;
//! 3. integrates the frame's RK4 steps ([`Simulation::step_frame`]);
//! 4. samples the IMUs ([`Simulation::imu_samples_into`], closing their interval every frame)
//!    and the star trackers that are due ([`Simulation::star_tracker_samples_into`])
//!    and fills the state and IMU samples of tick `k + 1` into a free telemetry buffer.
//!
//! The loop never allocates, locks or does I/O: commands arrive through a bounded channel, the
//! telemetry buffers are a fixed pool cycled through two bounded channels, and counters are
//! atomics. In real time it never blocks on the I/O side either: with no free buffer the frame's
//! telemetry is dropped and counted.

use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, TryRecvError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::transport::unix_now_ns;

use flexdyn_proto::{CommandMsg, Header, Mode, RunState};
use nalgebra::Vector3;

use super::commands::{CommandBook, Held, Offer};
use super::error::ServerError;
use super::pacing::{FrameEnd, Pacer};
use super::settings::ServerSettings;
use super::shared::{fill_state, Frame, Shared};
use crate::dynamics::Wrench;
use crate::sensors::imu::ImuSample;
use crate::sensors::star_tracker::StarTrackerSample;
use crate::sim::{Simulation, Snapshot};

/// Longest single blocking wait, so a stop request is seen quickly.
const POLL: Duration = Duration::from_millis(50);

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

/// Everything the physics thread owns.
pub struct PhysicsCtx {
    /// The simulation, at t = 0.
    pub sim: Simulation,
    /// Server settings.
    pub settings: ServerSettings,
    /// Frames to run (`None`: until stopped).
    pub total_frames: Option<u64>,
    /// Validated commands from the I/O side.
    pub cmd_rx: Receiver<CommandMsg>,
    /// Consumed commands, handed back to be freed off this thread (when the channel is full the
    /// command is freed here instead; never blocks).
    pub recycle_tx: SyncSender<CommandMsg>,
    /// Free telemetry buffers returned by the I/O thread.
    pub free_rx: Receiver<Box<Frame>>,
    /// Filled telemetry buffers to publish.
    pub full_tx: SyncSender<Box<Frame>>,
    /// Counters and the stop flag.
    pub shared: Arc<Shared>,
}

enum Wait {
    Done,
    Stopped,
}

impl PhysicsCtx {
    /// Runs the loop to its end; sets the shared run state accordingly.
    pub fn run(mut self) -> Result<PhysicsReport, ServerError> {
        let result = self.frame_loop();
        self.shared.set_run_state(match &result {
            Ok(r) if r.ending == Ending::Finished => RunState::Finished,
            Ok(_) => RunState::Stopped,
            Err(_) => RunState::Failed,
        });
        result
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

    fn count(&self, offer: Offer, sender_id: u32) {
        match offer {
            Offer::Accepted => {}
            Offer::StaleTick => self.shared.reject_stale_tick_from(sender_id),
            Offer::UnknownSender => self.shared.reject_unknown_sender(),
            Offer::BadEffectorInput => self.shared.reject_bad_effector_input(),
        }
    }

    /// Real time / batch: take every command that has arrived.
    fn drain_commands(&self, book: &mut CommandBook, k: u64) {
        while let Ok(cmd) = self.cmd_rx.try_recv() {
            self.count(book.offer_latest(&cmd, k), cmd.sender_id);
            let _ = self.recycle_tx.try_send(cmd);
        }
    }

    /// Lockstep: wait until every participant has answered tick `k`.
    fn await_answers(&self, book: &mut CommandBook, k: u64) -> Result<Wait, ServerError> {
        book.begin_tick();
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
                    self.count(book.offer_lockstep(&cmd, k), cmd.sender_id);
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

    /// Fills the telemetry of tick `k` (the IMU samples were taken into `imu` just before).
    fn fill(
        &mut self,
        frame: &mut Frame,
        snap: &mut Snapshot,
        imu: &[ImuSample],
        st: &[(usize, StarTrackerSample)],
        k: u64,
        held: &Held,
    ) {
        self.sim.snapshot_into(snap);
        let header = Header::new(self.settings.spacecraft_id, k, snap.t_sim_ns, k);
        fill_state(&mut frame.state, snap, header, held);
        frame.command = held.status;
        frame.lateness_ns = 0;
        frame.imu.clear();
        frame.imu.extend_from_slice(imu);
        frame.star_trackers.clear();
        frame.star_trackers.extend_from_slice(st);
    }

    fn frame_loop(&mut self) -> Result<PhysicsReport, ServerError> {
        let mode = self.settings.mode;
        let realtime = mode == Mode::RealTime;
        let frame_ns = self.sim.frame_ns();
        let mut book = CommandBook::new(
            &self.settings.participants,
            frame_ns,
            u64::try_from(self.settings.stale_after.as_nanos()).unwrap_or(u64::MAX),
            self.settings.stale_policy,
            self.sim.spacecraft().effector_input_ranges(),
        );
        let mut snap = Snapshot::for_simulation(&self.sim);
        // IMU samples close their interval every frame, published or not.
        let mut imu = Vec::with_capacity(self.sim.n_imus());
        let mut st = Vec::with_capacity(self.sim.star_trackers().len());
        let mut held = Held::initial(self.settings.stale_policy);
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
        self.sim.imu_samples_into(&mut imu);
        self.sim.star_tracker_samples_into(0, &mut st);
        if let Some(mut f) = pending.take() {
            self.fill(&mut f, &mut snap, &imu, &st, 0, &held);
            pending = Some(f);
        }
        // Real time: boundary 0 is due one frame from now, so the I/O side is settled.
        let mut pacer = Pacer::new(
            Instant::now() + Duration::from_nanos(frame_ns),
            frame_ns,
            self.settings.spin,
            self.settings.overrun_policy,
            self.settings.overrun_limit,
        );
        self.shared.set_run_state(RunState::Running);

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
            let stamp = unix_now_ns();
            if let Some(mut f) = pending.take() {
                f.boundary_unix_ns = stamp;
                f.lateness_ns = lateness_ns;
                // The full channel holds the whole pool, so this never blocks.
                if self.full_tx.send(f).is_err() {
                    return Err(ServerError::Internal("telemetry thread ended".into()));
                }
            }
            self.shared.tick.store(k, Ordering::Relaxed);
            if self.total_frames == Some(k) {
                return Ok(PhysicsReport {
                    ending: Ending::Finished,
                    last_tick: k,
                    sim_time_ns: self.sim.t_sim_ns(),
                });
            }

            // 2. Commands for tick k, held over the frame.
            match mode {
                Mode::Lockstep => {
                    if let Wait::Stopped = self.await_answers(&mut book, k)? {
                        return Ok(stopped(&self.shared));
                    }
                }
                Mode::RealTime | Mode::Batch => self.drain_commands(&mut book, k),
            }
            held = book.held(k);
            self.sim.set_command_wrench(Wrench {
                force_b_newton: Vector3::from(held.force_b_newton),
                torque_b_nm: Vector3::from(held.torque_b_nm),
            });
            // Cannot fail: the book's inputs have the spacecraft's layout and were checked
            // finite by the decoder.
            let _ = self.sim.set_effector_inputs(book.held_inputs());

            // 3. Integrate the frame.
            self.sim.step_frame();
            k += 1;

            // 4. Fill the state of tick k.
            pending = match self.acquire(realtime) {
                Ok(f) => f,
                Err(_) => return Ok(stopped(&self.shared)),
            };
            self.sim.imu_samples_into(&mut imu);
            self.sim.star_tracker_samples_into(k, &mut st);
            if let Some(mut f) = pending.take() {
                self.fill(&mut f, &mut snap, &imu, &st, k, &held);
                pending = Some(f);
            } else {
                // No buffer for this frame's telemetry: still check what was propagated.
                self.sim.snapshot_into(&mut snap);
            }
            // Once per frame, outside the RK4 loop: never publish a non-finite state.
            let imu_bad = imu.iter().find_map(|s| s.first_non_finite());
            let imu_bad = imu_bad.map(|q| format!("an IMU's {q} output"));
            let st_bad = st
                .iter()
                .find_map(|(_, s)| s.first_non_finite())
                .map(|q| format!("a star tracker's {q} output"));
            let imu_bad = imu_bad.or(st_bad);
            if let Some(quantity) = snap.first_non_finite().or(imu_bad) {
                return Err(ServerError::NonFinite {
                    tick: k,
                    t_s: snap.t_s(),
                    quantity,
                });
            }
            if realtime {
                match pacer.end_frame(k) {
                    FrameEnd::OnTime => {}
                    FrameEnd::Overrun => {
                        self.shared
                            .overruns
                            .store(pacer.overruns, Ordering::Relaxed);
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
