//! The fleet's physics thread: one frame loop for every vehicle.
//!
//! At frame boundary `k` the loop
//! 1. (real time) waits for the deadline `t0 + k·period`, then publishes the already filled
//!    telemetry of tick `k` of every vehicle, in fleet order (real time with
//!    `CongestionControl::Drop`: the put never waits for the network);
//! 2. takes the commands for tick `k`: lockstep waits until every participant of every vehicle
//!    has answered (one barrier for the whole fleet; a participant listed for several vehicles
//!    answers each of them on its own key); real time and batch take whatever has arrived;
//! 3. installs each vehicle's live faults that have arrived (from its own fault queue), steps
//!    every vehicle's frame and fills its telemetry of tick `k + 1` ([`FleetStepper`],
//!    allocation-free).
//!
//! The commands arrive through one bounded channel tagged with the vehicle's index; a consumed
//! command goes back to that vehicle's telemetry thread to be freed there.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender};
use std::sync::Arc;
use std::time::{Duration, Instant};

use flexdyn_proto::{CommandMsg, Mode, RunState};

use super::super::error::ServerError;
use super::super::lateness_ring::LatenessRing;
use super::super::pacing::{FrameEnd, Pacer};
use super::super::physics::{count_offer, Ending, PhysicsReport, HOLD_POLL};
use super::super::publish::FramePublisher;
use super::super::publish::Recording;
use super::super::settings::ServerSettings;
use super::super::shared::{Frame, Shared};
use super::relative::RelativePublisher;
use super::stepper::FleetStepper;
use flexdyn_faults::ports::{Installed, LiveRequest};
use flexdyn_proto::client::transport::unix_now_ns;

/// Longest single blocking wait, so a stop request is seen quickly.
const POLL: Duration = Duration::from_millis(50);

/// Everything the fleet's physics thread owns besides the [`FleetStepper`] it runs.
pub(super) struct FleetPhysics {
    /// The fleet's settings (mode, timeouts, pacing).
    pub settings: ServerSettings,
    /// Frames to run (`None`: until stopped).
    pub total_frames: Option<u64>,
    /// Validated commands, tagged with their vehicle's index.
    pub cmd_rx: Receiver<(usize, CommandMsg)>,
    /// Per vehicle: consumed commands, back to its telemetry thread to be freed (never blocks).
    pub recycle: Vec<SyncSender<CommandMsg>>,
    /// Per vehicle: its frame publishers.
    pub publishers: Vec<FramePublisher>,
    /// Per vehicle: its live fault requests (resolved by its fault callback), and the channel
    /// their boxes go back on, to its telemetry thread (never blocks).
    pub faults: Vec<(Receiver<LiveRequest>, SyncSender<Installed>)>,
    /// Per (chief, deputy) pair of the stepper ([`FleetStepper::pairs`], same order): its
    /// relative-state publisher.
    pub relative: Vec<RelativePublisher>,
    /// Per vehicle: the recorder's view of its keys (`--record`).
    pub recordings: Vec<Option<Recording>>,
    /// The fleet's operator hold target (and the tick published, which the operator decides
    /// against): set by any vehicle's operator callback.
    pub hold: Arc<Shared>,
    /// Real time: every frame boundary's lateness, for the vehicles' telemetry threads.
    pub lateness: Arc<LatenessRing>,
    /// Per vehicle: its counters (its StatusMsg reads them).
    pub shared: Vec<Arc<Shared>>,
    /// Set to stop at the next frame boundary.
    pub stop: Arc<AtomicBool>,
    /// Per vehicle: the channel its telemetry thread ends on when this is dropped.
    pub _telemetry_alive: Vec<SyncSender<Box<Frame>>>,
}

/// How the fleet's frames ended, and what the physics cost.
#[derive(Clone, Copy, Debug)]
pub struct FleetPhysicsReport {
    /// The ending, the last tick, its simulation time.
    pub physics: PhysicsReport,
    /// Frames stepped.
    pub frames: u64,
    /// \[ns\] wall time spent stepping and filling the frames (every vehicle), without the
    /// waits and the publications.
    pub physics_ns: u64,
    /// \[ns\] wall time spent publishing the frames (every vehicle's puts).
    pub publish_ns: u64,
    /// \[ns\] wall time spent waiting for the commands (lockstep: the barrier).
    pub wait_ns: u64,
}

/// Where the physics thread's time went: frames, physics, publications, waits (ns).
#[derive(Default)]
struct Spent {
    frames: u64,
    physics_ns: u64,
    publish_ns: u64,
    wait_ns: u64,
}

fn ns_since(t: Instant) -> u64 {
    u64::try_from(t.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

enum Wait {
    Done,
    Stopped,
}

impl FleetPhysics {
    fn set_run_state(&self, s: RunState) {
        for sh in &self.shared {
            sh.set_run_state(s);
        }
    }

    /// Runs the loop to its end; sets every vehicle's run state accordingly.
    pub fn run(self, mut f: FleetStepper) -> Result<FleetPhysicsReport, ServerError> {
        let mut this = self;
        let mut acc = Spent::default();
        let result = this.frame_loop(&mut f, &mut acc);
        this.set_run_state(match &result {
            Ok(r) if r.ending == Ending::Finished => RunState::Finished,
            Ok(_) => RunState::Stopped,
            Err(_) => RunState::Failed,
        });
        result.map(|physics| FleetPhysicsReport {
            physics,
            frames: acc.frames,
            physics_ns: acc.physics_ns,
            publish_ns: acc.publish_ns,
            wait_ns: acc.wait_ns,
        })
    }

    /// Holds the fleet at boundary `k` (already published) until the operator's hold target
    /// moves past it or is cleared; `false` if a stop was requested meanwhile. Every vehicle's
    /// status says `Paused` meanwhile; nothing is stepped or published here.
    fn hold_fleet(&self, k: u64) -> bool {
        for sh in &self.shared {
            sh.held.store(true, Ordering::Release);
        }
        self.set_run_state(RunState::Paused);
        let mut stopped = false;
        while self.hold.holds_at(k) {
            if self.stop.load(Ordering::Relaxed) {
                stopped = true;
                break;
            }
            std::thread::sleep(HOLD_POLL);
        }
        for sh in &self.shared {
            sh.held.store(false, Ordering::Release);
        }
        if !stopped {
            self.set_run_state(RunState::Running);
        }
        !stopped
    }

    /// Lockstep: waits until every participant of every vehicle has answered tick `k`.
    fn await_answers(&self, f: &mut FleetStepper, k: u64) -> Result<Wait, ServerError> {
        f.begin_tick(k);
        let timeout = self.settings.participant_timeout;
        let give_up = Instant::now() + timeout;
        while !f.all_answered() {
            let now = Instant::now();
            if now >= give_up {
                let (v, participant) = f.first_unanswered().unwrap_or_default();
                return Err(ServerError::Vehicle {
                    vehicle: f.vehicles.get(v).map(|v| v.id.clone()).unwrap_or_default(),
                    source: Box::new(ServerError::ParticipantTimeout {
                        participant,
                        tick: k,
                        timeout_s: timeout.as_secs_f64(),
                    }),
                });
            }
            match self.cmd_rx.recv_timeout((give_up - now).min(POLL)) {
                Ok((v, cmd)) => {
                    if let Some(sh) = self.shared.get(v) {
                        count_offer(sh, f.offer_lockstep(v, &cmd, k), cmd.sender_id);
                    }
                    self.recycle_command(v, cmd);
                }
                Err(RecvTimeoutError::Timeout) => {
                    if self.stop.load(Ordering::Relaxed) {
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

    /// Real time / batch: takes every command that has arrived.
    fn drain_commands(&self, f: &mut FleetStepper, k: u64) {
        while let Ok((v, cmd)) = self.cmd_rx.try_recv() {
            if let Some(sh) = self.shared.get(v) {
                count_offer(sh, f.offer_latest(v, &cmd, k), cmd.sender_id);
            }
            self.recycle_command(v, cmd);
        }
    }

    /// Installs each vehicle's live faults that have arrived, before frame `k → k + 1` is
    /// stepped; counts the refused ones under the vehicle. Allocation- and lock-free.
    fn drain_faults(&self, f: &mut FleetStepper, k: u64) {
        for ((v, (rx, recycle)), sh) in f.vehicles.iter_mut().zip(&self.faults).zip(&self.shared) {
            while let Ok(req) = rx.try_recv() {
                let installed = match v.stepper.install_fault(req, k) {
                    Ok(i) => i,
                    Err((code, i)) => {
                        sh.reject_fault_physics(code);
                        i
                    }
                };
                let _ = recycle.try_send(installed);
            }
        }
    }

    /// Hands a consumed command back to be freed off this thread (freed here only if that
    /// vehicle's channel is full; never blocks).
    fn recycle_command(&self, v: usize, cmd: CommandMsg) {
        if let Some(tx) = self.recycle.get(v) {
            let _ = tx.try_send(cmd);
        }
    }

    fn frame_loop(
        &mut self,
        f: &mut FleetStepper,
        acc: &mut Spent,
    ) -> Result<PhysicsReport, ServerError> {
        let mode = self.settings.mode;
        let realtime = mode == Mode::RealTime;
        let frame_ns = f.frame_ns();
        let stopped = |k: u64| PhysicsReport {
            ending: Ending::Stopped,
            last_tick: k,
            sim_time_ns: k.saturating_mul(frame_ns),
        };
        let mut k: u64 = 0;
        f.fill(0)?;
        let wall_period_ns = ((frame_ns as f64 / self.settings.speed).round() as u64).max(1);
        let mut pacer = Pacer::new(
            Instant::now() + Duration::from_nanos(wall_period_ns),
            wall_period_ns,
            self.settings.spin,
            self.settings.overrun_policy,
            self.settings.overrun_limit,
        );
        self.set_run_state(RunState::Running);
        loop {
            // 1. Frame boundary k: publish every vehicle's tick k.
            let lateness_ns = if realtime {
                match pacer.wait_boundary(k, &self.stop) {
                    Some(l) => {
                        self.lateness.push(l);
                        l
                    }
                    None => return Ok(stopped(k.saturating_sub(1))),
                }
            } else {
                if self.stop.load(Ordering::Relaxed) {
                    return Ok(stopped(k));
                }
                0
            };
            // Noted before the states go out, so an answer finds its tick published.
            for sh in &self.shared {
                sh.tick.store(k, Ordering::Release);
            }
            self.hold.tick.store(k, Ordering::Release);
            // The operator's hold (one atomic load): this tick's time messages say `Paused`,
            // and nothing follows until the hold is released. Never at the last tick.
            let holding = self.hold.holds_at(k) && self.total_frames != Some(k);
            if holding {
                for v in &mut f.vehicles {
                    v.frame.time.run_state = RunState::Paused;
                }
            }
            let stamp = unix_now_ns();
            let t = Instant::now();
            for (i, ((v, p), sh)) in f
                .vehicles
                .iter_mut()
                .zip(&mut self.publishers)
                .zip(&self.shared)
                .enumerate()
            {
                v.frame.boundary_unix_ns = stamp;
                v.frame.lateness_ns = lateness_ns;
                let rec = self.recordings.get(i).and_then(Option::as_ref);
                p.publish(&v.frame, sh, rec);
                // Its relative states, after its frame.
                for (pair, rp) in f.pairs.iter().zip(&mut self.relative) {
                    if pair.deputy == i {
                        rp.publish(pair, stamp, sh, rec);
                    }
                }
            }
            acc.publish_ns += ns_since(t);
            if self.total_frames == Some(k) {
                return Ok(PhysicsReport {
                    ending: Ending::Finished,
                    last_tick: k,
                    sim_time_ns: k.saturating_mul(frame_ns),
                });
            }
            if holding {
                if !self.hold_fleet(k) {
                    return Ok(stopped(k));
                }
                // Real time: boundary k + 1 is due one period after the release.
                if realtime {
                    pacer.resume_after(k);
                }
            }

            // 2. Commands for tick k.
            let t = Instant::now();
            match mode {
                Mode::Lockstep => {
                    if let Wait::Stopped = self.await_answers(f, k)? {
                        return Ok(stopped(k));
                    }
                }
                Mode::RealTime | Mode::Batch => self.drain_commands(f, k),
            }
            acc.wait_ns += ns_since(t);

            // 3. Live faults for boundary k + 1 on, every vehicle's frame, and its telemetry of
            //    tick k + 1.
            let t = Instant::now();
            self.drain_faults(f, k);
            f.step(k);
            k += 1;
            f.fill(k)?;
            acc.frames += 1;
            acc.physics_ns += ns_since(t);
            if realtime {
                match pacer.end_frame(k) {
                    FrameEnd::OnTime => {}
                    FrameEnd::Overrun => {
                        for sh in &self.shared {
                            sh.overruns.store(pacer.overruns, Ordering::Relaxed);
                        }
                    }
                    FrameEnd::Abort { consecutive } => {
                        return Err(ServerError::OverrunLimit {
                            tick: k,
                            consecutive,
                            limit: self.settings.overrun_limit,
                        });
                    }
                }
                for sh in &self.shared {
                    sh.frames_skipped.store(pacer.skipped, Ordering::Relaxed);
                }
            }
        }
    }
}
