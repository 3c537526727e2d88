//! The telemetry (I/O) thread: keeps the books of every frame (the lateness histogram, the
//! recording), publishes the frames it is handed that are not yet published
//! (`handoff = "thread"`, and batch; see [`super::publish`]), returns their buffers to the pool,
//! publishes StatusMsg at `status_hz` and logs a timing summary every `summary_interval_s`.
//!
//! In lockstep with `handoff = "direct"` no frame comes here: the Zenoh thread that steps a
//! frame publishes and records it, and this thread only publishes StatusMsg and the summaries.

use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, TryRecvError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use flexdyn_proto::client::transport::unix_now_ns;

use flexdyn_proto::{encode_into, FrameTiming, Header, Mode, StatusMsg};
use hdrhistogram::Histogram;
use zenoh::pubsub::Publisher;
use zenoh::Wait;

use super::lateness_ring::LatenessRing;
use super::publish::{FramePublisher, Recording};
use super::reject_log::RejectLog;
use super::settings::{mode_name, ServerSettings};
use super::shared::{Frame, Shared};

/// Longest park between two looks at the frame channel: how soon the end of the frames (the
/// physics side dropping its end, which wakes nobody) is noticed.
const PARK_MAX: Duration = Duration::from_millis(20);

/// Largest duration a [`ns_histogram`] resolves (larger values are clamped): 1 hour in ns.
const HISTOGRAM_MAX_NS: u64 = 3_600_000_000_000;

/// A new histogram of durations in ns (1 ns to 1 h, 3 significant digits: a value reads to
/// 0.1 %): the real-time lateness's, and a lockstep or batch run's tick periods
/// ([`super::tick_cost`]). Its bounds are fixed, so recording never allocates.
pub fn ns_histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, HISTOGRAM_MAX_NS, 3).expect("constant histogram bounds are valid")
}

/// p50, p99 and max of a [`ns_histogram`] (zeros when empty).
pub fn p50_p99_max(h: &Histogram<u64>) -> (u64, u64, u64) {
    if h.is_empty() {
        (0, 0, 0)
    } else {
        (h.value_at_quantile(0.5), h.value_at_quantile(0.99), h.max())
    }
}

/// p50, p99 and max of a lateness histogram (zeros when empty).
pub fn timing_of(h: &Histogram<u64>, overruns: u64, skipped: u64) -> FrameTiming {
    let (p50, p99, max) = p50_p99_max(h);
    FrameTiming {
        lateness_p50_ns: p50,
        lateness_p99_ns: p99,
        lateness_max_ns: max,
        overrun_count: overruns,
        frames_skipped: skipped,
    }
}

/// Records the lateness values new in `ring` into `h`; a value the ring overwrote before this
/// thread woke (4 s of 1 kHz frames late) is logged, not invented.
fn drain_lateness(ring: &LatenessRing, next: &mut u64, h: &mut Histogram<u64>) {
    let missed = ring.drain(next, |ns| h.saturating_record(ns.min(HISTOGRAM_MAX_NS)));
    if missed > 0 {
        tracing::warn!(
            missed,
            "frame lateness values overwritten before they were read"
        );
    }
}

/// What the telemetry thread reports at the end.
#[derive(Debug)]
pub struct TelemetryReport {
    /// Lateness of every published real-time frame (ns).
    pub lateness: Histogram<u64>,
}

/// Everything the telemetry thread owns.
pub struct TelemetryCtx {
    /// The frame publishers, when this thread publishes the frames (`handoff = "thread"`, or
    /// batch); `None` when the thread that finishes a frame publishes it.
    pub publisher: Option<FramePublisher>,
    /// Publisher of `flexdyn/<sc>/status`.
    pub status_pub: Publisher<'static>,
    /// Filled frames from the physics thread.
    pub full_rx: Receiver<Box<Frame>>,
    /// Buffers back to the physics thread.
    pub free_tx: SyncSender<Box<Frame>>,
    /// Commands the physics thread has consumed, freed here.
    pub recycle_rx: Receiver<flexdyn_proto::CommandMsg>,
    /// Live fault requests the physics thread has installed (their boxes), freed here.
    pub fault_recycle_rx: Receiver<flexdyn_faults::ports::Installed>,
    /// Counters.
    pub shared: Arc<Shared>,
    /// Settings (mode, ids, rates).
    pub settings: ServerSettings,
    /// \[ns\] frame period.
    pub frame_ns: u64,
    /// The recorder's queue (`flexdyn run --record`) for the frames that come here and the
    /// status.
    pub record: Option<Recording>,
    /// Fleet mode, real time: the frames' lateness, from the fleet's physics thread (the
    /// frames do not come here), with this thread's read position.
    pub lateness_ring: Option<(Arc<LatenessRing>, u64)>,
    /// The log of the vehicle's fault activations and clearances.
    pub fault_log: super::fault_log::FaultLog,
}

struct Publishing {
    status_seq: u64,
    lateness: Histogram<u64>,
}

impl TelemetryCtx {
    fn publish_status(&self, p: &mut Publishing, buf: &mut Vec<u8>, rec: Option<&Recording>) {
        let tick = self.shared.tick.load(Ordering::Relaxed);
        let (faults_active, faults_active_bits) = self.shared.faults_active();
        let msg = StatusMsg {
            header: Header::new(
                self.settings.spacecraft_id,
                tick,
                tick.saturating_mul(self.frame_ns),
                p.status_seq,
            ),
            mode: self.settings.mode,
            run_state: self.shared.run_state(),
            timing: timing_of(
                &p.lateness,
                self.shared.overruns.load(Ordering::Relaxed),
                self.shared.frames_skipped.load(Ordering::Relaxed),
            ),
            command: self.shared.last_command(self.settings.stale_policy),
            rejected: self.shared.rejected(),
            commands_dropped: self.shared.commands_dropped.load(Ordering::Relaxed),
            wall_time_unix_ns: unix_now_ns(),
            faults_active,
            faults_active_bits,
        };
        p.status_seq += 1;
        encode_into(&msg, buf);
        if let Some(r) = rec {
            r.submit(&r.status, buf, None);
        }
        if let Err(e) = self.status_pub.put(buf.as_slice()).wait() {
            self.shared.publish_errors.fetch_add(1, Ordering::Relaxed);
            tracing::warn!(error = %e, "cannot publish status");
        }
    }

    /// Warns (rate-limited) about the tick and effector-input rejections (counted by the
    /// command callback's gate and the command book) since the last call: stale ticks, naming
    /// the participant, and effector inputs that do not fit.
    fn warn_physics_rejects(
        &self,
        log: &mut RejectLog,
        seen: &mut [u64],
        bad_inputs_seen: &mut u64,
        faults_seen: &mut u64,
    ) {
        for ((id, count), last) in self.shared.stale_by_participant.iter().zip(seen) {
            let now = count.load(Ordering::Relaxed);
            if now > *last {
                log.record(
                    "stale_tick",
                    Some(*id),
                    now - *last,
                    &"a command for a tick the server is not taking (lockstep: not the tick \
                      being waited for, or a second answer; real time: a tick not yet \
                      published, or older than the sender's previous command)",
                );
                *last = now;
            }
        }
        let now = self.shared.faults_refused_physics.load(Ordering::Relaxed);
        if now > *faults_seen {
            let code = self.shared.last_fault_refusal.load(Ordering::Relaxed);
            log.record(
                "fault_refused",
                None,
                now - *faults_seen,
                &format_args!(
                    "live fault command(s) refused; the last: {}",
                    flexdyn_faults::ports::INSTALL_REFUSALS
                        .get(usize::from(code))
                        .unwrap_or(&"")
                ),
            );
            *faults_seen = now;
        }
        let now = self.shared.rejected().bad_effector_input;
        if now > *bad_inputs_seen {
            log.record(
                "bad_effector_input",
                None,
                now - *bad_inputs_seen,
                &"an Actuators command naming an effector that does not exist or takes no \
                  input, with the wrong number of values for it, or naming it twice (see the \
                  StateMsg's effector list for the indices)",
            );
            *bad_inputs_seen = now;
        }
    }

    fn log_summary(&self, p: &Publishing, frames_in_window: u64, window: Duration) {
        let last_command = self.shared.last_command(self.settings.stale_policy);
        let t = timing_of(
            &p.lateness,
            self.shared.overruns.load(Ordering::Relaxed),
            self.shared.frames_skipped.load(Ordering::Relaxed),
        );
        let rejected = self.shared.rejected();
        tracing::info!(
            mode = mode_name(self.settings.mode),
            tick = self.shared.tick.load(Ordering::Relaxed),
            frames_per_s = format!("{:.1}", frames_in_window as f64 / window.as_secs_f64()),
            lateness_p50_us = format!("{:.1}", t.lateness_p50_ns as f64 * 1e-3),
            lateness_p99_us = format!("{:.1}", t.lateness_p99_ns as f64 * 1e-3),
            lateness_max_us = format!("{:.1}", t.lateness_max_ns as f64 * 1e-3),
            overruns = t.overrun_count,
            frames_skipped = t.frames_skipped,
            telemetry_dropped = self.shared.telemetry_dropped.load(Ordering::Relaxed),
            commands_rejected = rejected.total() - rejected.fsw_refused,
            fsw_refused = rejected.fsw_refused,
            command_age_ms = if last_command.command_age_ns == flexdyn_proto::NO_COMMAND {
                "none".to_owned()
            } else {
                format!("{:.1}", last_command.command_age_ns as f64 * 1e-6)
            },
            command_stale = last_command.command_stale,
            "timing summary"
        );
    }

    /// Runs until the physics side drops its end of the frame channel, then publishes a final
    /// status.
    pub fn run(mut self) -> TelemetryReport {
        let realtime = self.settings.mode == Mode::RealTime;
        let status_period = self.settings.status_period();
        let summary_period = self.settings.summary_interval;
        let mut p = Publishing {
            status_seq: 0,
            lateness: ns_histogram(),
        };
        let rec = self.record.take();
        let mut publisher = self.publisher.take();
        let mut status_buf = Vec::with_capacity(256);
        let mut record_buf = Vec::with_capacity(4096);
        let mut next_status = Instant::now();
        let mut next_summary = Instant::now() + summary_period;
        let mut window_start = Instant::now();
        let mut window_published = self.shared.published.load(Ordering::Relaxed);
        let mut rejects = RejectLog::default();
        let mut stale_seen = vec![0u64; self.shared.stale_by_participant.len()];
        let mut bad_inputs_seen = 0u64;
        let mut faults_seen = 0u64;
        loop {
            self.fault_log.catch_up(&self.shared.fault_edges);
            let now = Instant::now();
            if now >= next_status {
                self.warn_physics_rejects(
                    &mut rejects,
                    &mut stale_seen,
                    &mut bad_inputs_seen,
                    &mut faults_seen,
                );
                self.publish_status(&mut p, &mut status_buf, rec.as_ref());
                next_status += status_period;
                if next_status < now {
                    next_status = now + status_period;
                }
            }
            if now >= next_summary {
                let published = self.shared.published.load(Ordering::Relaxed);
                self.log_summary(&p, published - window_published, now - window_start);
                window_start = now;
                window_published = published;
                next_summary = now + summary_period;
            }
            let wait = next_status
                .min(next_summary)
                .saturating_duration_since(Instant::now());
            if let Some((ring, next)) = &mut self.lateness_ring {
                drain_lateness(ring, next, &mut p.lateness);
            }
            // Free the commands and fault requests the physics thread is done with.
            while self.recycle_rx.try_recv().is_ok() {}
            while self.fault_recycle_rx.try_recv().is_ok() {}
            // Never waits inside the channel: parks, and the physics thread unparks it after
            // each frame. A receiver waiting in the channel would make the physics thread's
            // send take the channel's waker lock, which this thread (normal priority) holds
            // while it registers; parked, it holds nothing the physics thread needs.
            let next = match self.full_rx.try_recv() {
                Ok(frame) => Ok(frame),
                Err(TryRecvError::Empty) => {
                    std::thread::park_timeout(wait.min(PARK_MAX));
                    Err(RecvTimeoutError::Timeout)
                }
                Err(TryRecvError::Disconnected) => Err(RecvTimeoutError::Disconnected),
            };
            match next {
                Ok(frame) => {
                    if realtime {
                        p.lateness
                            .saturating_record(frame.lateness_ns.min(HISTOGRAM_MAX_NS));
                    }
                    match (&mut publisher, frame.published) {
                        (Some(publisher), false) => {
                            publisher.publish(&frame, &self.shared, rec.as_ref());
                        }
                        _ => {
                            if let Some(r) = &rec {
                                r.record_frame(&frame, &mut record_buf);
                            }
                        }
                    }
                    let _ = self.free_tx.send(frame);
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        if let Some((ring, next)) = &mut self.lateness_ring {
            drain_lateness(ring, next, &mut p.lateness);
        }
        self.fault_log.catch_up(&self.shared.fault_edges);
        self.warn_physics_rejects(
            &mut rejects,
            &mut stale_seen,
            &mut bad_inputs_seen,
            &mut faults_seen,
        );
        self.publish_status(&mut p, &mut status_buf, rec.as_ref());
        TelemetryReport {
            lateness: p.lateness,
        }
    }
}
