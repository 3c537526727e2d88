//! The run report: how a run ended and what it counted, collected once every thread is done.

use std::fmt;
use std::sync::atomic::Ordering;

use flexdyn_proto::{FrameTiming, Mode, RejectCounters};
use hdrhistogram::Histogram;

use super::physics::{Ending, PhysicsReport};
use super::rt::ThreadUsage;
use super::settings::mode_name;
use super::shared::Shared;
use super::telemetry::timing_of;
use super::tick_cost::TickSummary;
use flexdyn_sinks::recorder::RecordReport;

/// How a run ended without error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The configured duration was reached.
    Finished,
    /// The shutdown future completed (SIGINT/SIGTERM).
    Stopped,
}

/// Summary of a completed run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunReport {
    /// Pacing mode.
    pub mode: Mode,
    /// Why the run ended.
    pub outcome: Outcome,
    /// Last tick reached.
    pub last_tick: u64,
    /// \[ns\] simulation time of `last_tick`.
    pub sim_time_ns: u64,
    /// StateMsg samples published.
    pub states_published: u64,
    /// Real time: frames whose telemetry was dropped (no free buffer).
    pub telemetry_dropped: u64,
    /// The flight code's telemetry samples accepted (`flexdyn/<sc>/fsw/*`, recorded when
    /// recording); the refused ones count in `rejected.fsw_refused`.
    pub fsw_accepted: u64,
    /// Real time: lateness percentiles, overruns, skipped frames (zeros otherwise).
    pub timing: FrameTiming,
    /// Rejected commands by reason.
    pub rejected: RejectCounters,
    /// Valid commands dropped because the command queue was full.
    pub commands_dropped: u64,
    /// What the command-link faults (`links.<sender id>`) did.
    pub link_faults: flexdyn_faults::link::LinkStats,
    /// \[s\] wall time from the first frame to the end.
    pub wall_s: f64,
    /// `--record`: what the recording holds and what the recorder dropped.
    pub recording: Option<RecordReport>,
    /// Real time: what handing each frame off cost the physics thread (with
    /// `handoff = "direct"` the put; either way the channel and the telemetry thread's wake-up).
    pub handoff: Option<PublishCost>,
    /// Real time: the lateness of every published frame \[ns\] (an hdrhistogram, 3
    /// significant digits), for percentiles beyond [`Self::timing`]'s.
    pub lateness: Option<Histogram<u64>>,
    /// Real time: the physics thread's page faults and context switches from its first frame
    /// to its last (`lock_memory` makes the page faults 0).
    pub physics_thread: Option<ThreadUsage>,
    /// Real time: start and end \[ns, [`super::rt::monotonic_ns`]\] of the overrun frames (the
    /// first [`super::shared::OVERRUN_LOG_LEN`]), from the wake-up at the boundary before to the
    /// end of the frame's work; for lining overruns up with other counters (the
    /// `realtime_lateness` bench does, with the steal time and the scheduler's statistics).
    pub overrun_frames_ns: Vec<(u64, u64)>,
    /// The checkpoints this run saved (`None`: it saves none).
    pub checkpoints: Option<CheckpointSummary>,
    /// Lockstep and batch: where the ticks went (per-tick means, the tick period's
    /// distribution, the settled tick rate; [`super::tick_cost`]).
    pub ticks: Option<TickSummary>,
}

/// The checkpoints a run saved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct CheckpointSummary {
    /// Written to their files.
    pub written: u64,
    /// Not taken or not written (each logged with its reason).
    pub failed: u64,
    /// \[ns\] the longest time the stepping thread spent listing one checkpoint's state (the
    /// checksum and the file are the writer thread's).
    pub max_list_ns: u64,
}

/// The time the physics thread spent handing frames off (real time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PublishCost {
    /// Frames handed off by the physics thread.
    pub frames: u64,
    /// \[ns\] mean time per frame.
    pub mean_ns: f64,
    /// \[ns\] largest time of one frame.
    pub max_ns: u64,
    /// Frames whose publication took longer than [`super::shared::SLOW_PUBLISH_NS`] (100 µs).
    pub slow_frames: u64,
}

impl fmt::Display for RunReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "run {}: mode={} last_tick={} sim_time_s={} states_published={} telemetry_dropped={} \
             wall_s={:.3} lateness_us p50={:.1} p99={:.1} max={:.1} overruns={} frames_skipped={} \
             rejected={} commands_dropped={}",
            match self.outcome {
                Outcome::Finished => "finished",
                Outcome::Stopped => "stopped",
            },
            mode_name(self.mode),
            self.last_tick,
            self.sim_time_ns as f64 / 1e9,
            self.states_published,
            self.telemetry_dropped,
            self.wall_s,
            self.timing.lateness_p50_ns as f64 * 1e-3,
            self.timing.lateness_p99_ns as f64 * 1e-3,
            self.timing.lateness_max_ns as f64 * 1e-3,
            self.timing.overrun_count,
            self.timing.frames_skipped,
            self.rejected.total(),
            self.commands_dropped,
        )?;
        if self.fsw_accepted > 0 {
            write!(f, " fsw_accepted={}", self.fsw_accepted)?;
        }
        let l = &self.link_faults;
        if !l.is_zero() {
            write!(
                f,
                " link_faults dropped={} empty_answers={} delayed_frames={} corrupted={} \
                 corrupted_rejected={}",
                l.commands_dropped,
                l.empty_answers,
                l.delayed_frames,
                l.commands_corrupted,
                l.corrupted_rejected
            )?;
        }
        if let Some(r) = &self.recording {
            write!(
                f,
                " recorded_samples={} record_dropped={} record_missing={}",
                r.stats.samples,
                r.dropped,
                r.stats.missing_total()
            )?;
        }
        if let Some(c) = &self.handoff {
            write!(
                f,
                " handoff_us mean={:.1} max={:.1} slow_over_100us={}",
                c.mean_ns * 1e-3,
                c.max_ns as f64 * 1e-3,
                c.slow_frames
            )?;
        }
        if let Some(u) = &self.physics_thread {
            write!(
                f,
                " physics_thread page_faults={} voluntary_switches={} involuntary_switches={}",
                u.page_faults(),
                u.voluntary_switches,
                u.involuntary_switches
            )?;
        }
        if let Some(t) = &self.ticks {
            write!(f, "{t}")?;
        }
        if let Some(c) = &self.checkpoints {
            write!(
                f,
                " checkpoints written={} failed={} max_list_us={:.1}",
                c.written,
                c.failed,
                c.max_list_ns as f64 * 1e-3
            )?;
        }
        Ok(())
    }
}

impl RunReport {
    /// The report of a run that ended: the physics thread's (or lockstep core's) ending, the
    /// counters in `shared`, the telemetry thread's lateness histogram, the wall time from the
    /// first frame and what the recorder wrote.
    pub(super) fn collect(
        mode: Mode,
        phys: PhysicsReport,
        shared: &Shared,
        lateness: &Histogram<u64>,
        wall_s: f64,
        recording: Option<RecordReport>,
    ) -> Self {
        let load = |c: &std::sync::atomic::AtomicU64| c.load(Ordering::Relaxed);
        Self {
            mode,
            outcome: match phys.ending {
                Ending::Finished => Outcome::Finished,
                Ending::Stopped => Outcome::Stopped,
            },
            last_tick: phys.last_tick,
            sim_time_ns: phys.sim_time_ns,
            states_published: load(&shared.published),
            telemetry_dropped: load(&shared.telemetry_dropped),
            fsw_accepted: load(&shared.fsw_recorded),
            timing: timing_of(
                lateness,
                load(&shared.overruns),
                load(&shared.frames_skipped),
            ),
            rejected: shared.rejected(),
            commands_dropped: load(&shared.commands_dropped),
            link_faults: shared.link_stats(),
            wall_s,
            recording,
            handoff: {
                let n = load(&shared.handoffs);
                (n > 0).then(|| PublishCost {
                    frames: n,
                    mean_ns: load(&shared.handoff_ns_total) as f64 / n as f64,
                    max_ns: load(&shared.handoff_ns_max),
                    slow_frames: load(&shared.handoffs_slow),
                })
            },
            physics_thread: None,
            overrun_frames_ns: shared.overrun_log.frames(),
            lateness: (mode == Mode::RealTime).then(|| lateness.clone()),
            checkpoints: None,
            ticks: None,
        }
    }

    /// The report of a lockstep run stopped before tick 0 (nothing stepped or published).
    pub(super) fn before_tick_0(mode: Mode, rejected: RejectCounters) -> Self {
        Self {
            mode,
            outcome: Outcome::Stopped,
            last_tick: 0,
            sim_time_ns: 0,
            states_published: 0,
            telemetry_dropped: 0,
            fsw_accepted: 0,
            timing: FrameTiming::default(),
            rejected,
            commands_dropped: 0,
            link_faults: Default::default(),
            wall_s: 0.0,
            recording: None,
            handoff: None,
            physics_thread: None,
            overrun_frames_ns: Vec::new(),
            lateness: None,
            checkpoints: None,
            ticks: None,
        }
    }
}
