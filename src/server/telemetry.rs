//! The telemetry (I/O) thread: encodes and publishes each frame's ImuMsg samples (one topic per
//! IMU) and StateMsg, returns the buffer to the pool, keeps the lateness histogram, publishes StatusMsg at `status_hz` and logs a timing
//! summary every `summary_interval_s`.
//!
//! Each StateMsg and ImuMsg sample carries an 8-byte Zenoh attachment: the wall-clock time of its frame
//! boundary in ns since the Unix epoch, u64 little-endian ([`frame_stamp_ns`]). It is kept out
//! of the payload so the payload stays deterministic.

use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::transport::unix_now_ns;

use flexdyn_proto::{encode_into, CommandStatus, FrameTiming, Header, Mode, StatusMsg};
use hdrhistogram::Histogram;
use zenoh::pubsub::Publisher;
use zenoh::Wait;

use super::commands::Held;
use super::reject_log::RejectLog;
use super::settings::{mode_name, ServerSettings};
use super::shared::{Frame, Shared};
use crate::sinks::recorder::{RecordItem, RecordTx};

/// Largest lateness the histogram resolves (larger values are clamped): 1 hour in ns.
const LATENESS_MAX_NS: u64 = 3_600_000_000_000;

/// A new lateness histogram (ns, 3 significant digits).
pub fn lateness_histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, LATENESS_MAX_NS, 3).expect("constant histogram bounds are valid")
}

/// p50, p99 and max of a lateness histogram (zeros when empty).
pub fn timing_of(h: &Histogram<u64>, overruns: u64, skipped: u64) -> FrameTiming {
    let (p50, p99, max) = if h.is_empty() {
        (0, 0, 0)
    } else {
        (h.value_at_quantile(0.5), h.value_at_quantile(0.99), h.max())
    };
    FrameTiming {
        lateness_p50_ns: p50,
        lateness_p99_ns: p99,
        lateness_max_ns: max,
        overrun_count: overruns,
        frames_skipped: skipped,
    }
}

/// What the telemetry thread reports at the end.
#[derive(Debug)]
pub struct TelemetryReport {
    /// Lateness of every published real-time frame (ns).
    pub lateness: Histogram<u64>,
    /// StateMsg samples published.
    pub published: u64,
    /// Zenoh `put` failures (logged).
    pub publish_errors: u64,
}

/// Everything the telemetry thread owns.
pub struct TelemetryCtx {
    /// Publisher of `flexdyn/<sc>/tlm/state` (shared with the lockstep presence wait).
    pub state_pub: Arc<Publisher<'static>>,
    /// Publisher of `flexdyn/<sc>/status`.
    pub status_pub: Publisher<'static>,
    /// Publishers of `flexdyn/<sc>/tlm/imu/<name>`, in IMU config order.
    pub imu_pubs: Vec<Publisher<'static>>,
    /// Publishers of `flexdyn/<sc>/tlm/st/<name>` with the tracker's update period in frames,
    /// in star-tracker config order.
    pub st_pubs: Vec<(Publisher<'static>, u64)>,
    /// Filled frames from the physics thread.
    pub full_rx: Receiver<Box<Frame>>,
    /// Buffers back to the physics thread.
    pub free_tx: SyncSender<Box<Frame>>,
    /// Commands the physics thread has consumed, freed here.
    pub recycle_rx: Receiver<flexdyn_proto::CommandMsg>,
    /// Counters.
    pub shared: Arc<Shared>,
    /// Settings (mode, ids, rates).
    pub settings: ServerSettings,
    /// \[ns\] frame period.
    pub frame_ns: u64,
    /// The recorder's queue (`flexdyn run --record`): every payload published here is also
    /// queued for it.
    pub record: Option<RecordTx>,
}

/// The recorder's queue and the keys it files payloads under.
struct Recording {
    tx: RecordTx,
    state: Arc<str>,
    status: Arc<str>,
    imus: Vec<Arc<str>>,
    sts: Vec<Arc<str>>,
}

impl Recording {
    fn submit(&self, key: &Arc<str>, payload: &[u8], stamp_ns: Option<u64>) {
        self.tx.submit(RecordItem {
            key: key.clone(),
            payload: payload.to_vec(),
            publish_time_ns: stamp_ns,
        });
    }
}

struct Publishing {
    status_seq: u64,
    last_command: CommandStatus,
    published: u64,
    publish_errors: u64,
    lateness: Histogram<u64>,
}

impl TelemetryCtx {
    fn recording(&self) -> Option<Recording> {
        let key = |p: &Publisher<'static>| -> Arc<str> { p.key_expr().as_str().into() };
        self.record.as_ref().map(|tx| Recording {
            tx: tx.clone(),
            state: key(&self.state_pub),
            status: key(&self.status_pub),
            imus: self.imu_pubs.iter().map(key).collect(),
            sts: self.st_pubs.iter().map(|(p, _)| key(p)).collect(),
        })
    }

    fn publish_status(&self, p: &mut Publishing, buf: &mut Vec<u8>, rec: Option<&Recording>) {
        let tick = self.shared.tick.load(Ordering::Relaxed);
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
            command: p.last_command,
            rejected: self.shared.rejected(),
            commands_dropped: self.shared.commands_dropped.load(Ordering::Relaxed),
            wall_time_unix_ns: unix_now_ns(),
        };
        p.status_seq += 1;
        encode_into(&msg, buf);
        if let Some(r) = rec {
            r.submit(&r.status, buf, None);
        }
        if let Err(e) = self.status_pub.put(buf.as_slice()).wait() {
            p.publish_errors += 1;
            tracing::warn!(error = %e, "cannot publish status");
        }
    }

    /// Warns (rate-limited) about the rejections the physics thread counted since the last
    /// call: stale ticks, naming the participant, and effector inputs that do not fit.
    fn warn_physics_rejects(
        &self,
        log: &mut RejectLog,
        seen: &mut [u64],
        bad_inputs_seen: &mut u64,
    ) {
        for ((id, count), last) in self.shared.stale_by_participant.iter().zip(seen) {
            let now = count.load(Ordering::Relaxed);
            if now > *last {
                log.record(
                    "stale_tick",
                    Some(*id),
                    now - *last,
                    &"a command for a tick the server is not taking (lockstep: not the tick \
                      being waited for, or a second answer; real time: a future tick, or older \
                      than the sender's held command)",
                );
                *last = now;
            }
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
            commands_rejected = rejected.total(),
            command_age_ms = if p.last_command.command_age_ns == flexdyn_proto::NO_COMMAND {
                "none".to_owned()
            } else {
                format!("{:.1}", p.last_command.command_age_ns as f64 * 1e-6)
            },
            command_stale = p.last_command.command_stale,
            "timing summary"
        );
    }

    /// Runs until the physics thread drops its end of the channel, then publishes a final
    /// status.
    pub fn run(self) -> TelemetryReport {
        let rec = self.recording();
        let realtime = self.settings.mode == Mode::RealTime;
        let status_period = self.settings.status_period();
        let summary_period = self.settings.summary_interval;
        let mut p = Publishing {
            status_seq: 0,
            last_command: Held::initial(self.settings.stale_policy).status,
            published: 0,
            publish_errors: 0,
            lateness: lateness_histogram(),
        };
        let mut state_buf = Vec::with_capacity(1024);
        let mut status_buf = Vec::with_capacity(256);
        let mut imu_buf = Vec::with_capacity(256);
        let mut next_status = Instant::now();
        let mut next_summary = Instant::now() + summary_period;
        let mut window_start = Instant::now();
        let mut window_frames = 0u64;
        let mut rejects = RejectLog::default();
        let mut stale_seen = vec![0u64; self.shared.stale_by_participant.len()];
        let mut bad_inputs_seen = 0u64;
        loop {
            let now = Instant::now();
            if now >= next_status {
                self.warn_physics_rejects(&mut rejects, &mut stale_seen, &mut bad_inputs_seen);
                self.publish_status(&mut p, &mut status_buf, rec.as_ref());
                next_status += status_period;
                if next_status < now {
                    next_status = now + status_period;
                }
            }
            if now >= next_summary {
                self.log_summary(&p, window_frames, now - window_start);
                window_start = now;
                window_frames = 0;
                next_summary = now + summary_period;
            }
            let wait = next_status
                .min(next_summary)
                .saturating_duration_since(Instant::now());
            // Free the commands the physics thread is done with.
            while self.recycle_rx.try_recv().is_ok() {}
            match self.full_rx.recv_timeout(wait) {
                Ok(frame) => {
                    if realtime {
                        p.lateness
                            .saturating_record(frame.lateness_ns.min(LATENESS_MAX_NS));
                    }
                    p.last_command = frame.command;
                    encode_into(&frame.state, &mut state_buf);
                    let stamp = frame.boundary_unix_ns.to_le_bytes();
                    let header = frame.state.header;
                    for (i, (sample, publisher)) in frame.imu.iter().zip(&self.imu_pubs).enumerate()
                    {
                        encode_into(&sample.to_msg(header), &mut imu_buf);
                        if let Some(r) = &rec {
                            r.submit(&r.imus[i], &imu_buf, Some(frame.boundary_unix_ns));
                        }
                        if let Err(e) = publisher.put(imu_buf.as_slice()).attachment(stamp).wait() {
                            p.publish_errors += 1;
                            if p.publish_errors.is_power_of_two() {
                                tracing::warn!(error = %e, errors = p.publish_errors, "cannot publish an IMU sample");
                            }
                        }
                    }
                    for (i, sample) in &frame.star_trackers {
                        let Some((publisher, every)) = self.st_pubs.get(*i) else {
                            continue;
                        };
                        // seq counts this tracker's messages: +1 per update.
                        let h = flexdyn_proto::Header {
                            seq: header.tick / every,
                            ..header
                        };
                        encode_into(&sample.to_msg(h), &mut imu_buf);
                        if let Some(r) = &rec {
                            r.submit(&r.sts[*i], &imu_buf, Some(frame.boundary_unix_ns));
                        }
                        if let Err(e) = publisher.put(imu_buf.as_slice()).attachment(stamp).wait() {
                            p.publish_errors += 1;
                            if p.publish_errors.is_power_of_two() {
                                tracing::warn!(error = %e, errors = p.publish_errors, "cannot publish a star-tracker sample");
                            }
                        }
                    }
                    let boundary_unix_ns = frame.boundary_unix_ns;
                    // Return the buffer before the state goes out, so the physics thread has it.
                    let _ = self.free_tx.send(frame);
                    match self
                        .state_pub
                        .put(state_buf.as_slice())
                        .attachment(stamp)
                        .wait()
                    {
                        Ok(()) => p.published += 1,
                        Err(e) => {
                            p.publish_errors += 1;
                            if p.publish_errors.is_power_of_two() {
                                tracing::warn!(error = %e, errors = p.publish_errors, "cannot publish state");
                            }
                        }
                    }
                    // Queued for the recorder after the state is out: the subscriber first.
                    if let Some(r) = &rec {
                        r.submit(&r.state, &state_buf, Some(boundary_unix_ns));
                    }
                    window_frames += 1;
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        self.warn_physics_rejects(&mut rejects, &mut stale_seen, &mut bad_inputs_seen);
        self.publish_status(&mut p, &mut status_buf, rec.as_ref());
        TelemetryReport {
            lateness: p.lateness,
            published: p.published,
            publish_errors: p.publish_errors,
        }
    }
}
