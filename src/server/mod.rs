//! The flexdyn server: propagates a spacecraft and talks to flight code over Zenoh, in real
//! time, in lockstep or in batch.
//!
//! [`run`] is the whole server as a library function with its I/O injected (a Zenoh session, the
//! settings, the simulation configuration and a shutdown future); `src/main.rs` only parses
//! arguments, initialises tracing and calls [`cli::run_from_args`], which calls [`run`].
//!
//! # Layout
//! - [`settings`]: [`ServerSettings`], the `[server]` table and `flexdyn run` options.
//! - [`crate::transport`]: [`zenoh_config`], the one builder of every Zenoh configuration (loopback
//!   defaults, multicast scouting always off).
//! - [`commands`]: per-participant command book (lockstep answers, staleness, summation).
//! - [`pacing`]: absolute-deadline real-time pacing (sleep, then spin) and overrun policies.
//! - [`physics`]: the physics thread's frame loop.
//! - [`telemetry`]: the I/O thread that publishes status (and, with `handoff = "thread"`, the
//!   frames) and keeps the books.
//! - [`shared`]: lock-free counters and the preallocated telemetry buffers.
//! - [`error`]: typed errors.
//! - [`cli`]: `flexdyn run` arguments and the process-level wrapper (runtime, signals).
//! - [`lockstep`]: lockstep stepped on the Zenoh thread that delivers a tick's last answer.
//! - [`publish`]: the frame publishers (who calls them is the `handoff` setting).
//! - [`access`]: the start-up check that the Zenoh ACL binds participants to subjects.
//!
//! # Threads
//! With `handoff = "thread"` (and in batch):
//! ```text
//!  zenoh rx (callback) --CommandMsg, bounded--> physics thread --Frame, bounded--> telemetry thread --> zenoh
//!                                               ^                                      |
//!                                               +------------ free Frame pool ---------+
//! ```
//! With `handoff = "direct"` in real time the physics thread puts each frame itself at its
//! boundary (`CongestionControl::Drop`) and the frame then goes the same way for the books; in
//! lockstep the callback steps the [`lockstep::LockstepCore`] and publishes, and the telemetry
//! thread only publishes StatusMsg. `auto` (default) is `direct` except in real time with
//! `--record`. The per-frame work ([`physics::Stepper`]) never allocates, locks or touches the
//! network; in real time the physics thread never blocks on the I/O side (a frame without a
//! free buffer loses its telemetry, counted).

pub mod access;
pub mod cli;
pub mod commands;
pub mod error;
pub mod lockstep;
pub mod pacing;
pub mod physics;
pub mod publish;
mod reject_log;
pub mod settings;
pub mod shared;
pub mod telemetry;

use std::collections::BTreeSet;
use std::fmt;
use std::future::Future;
use std::sync::mpsc::{sync_channel, SyncSender};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use flexdyn_proto::{
    decode_command, FrameTiming, Mode, RejectCounters, RunState, StalePolicy, Topics,
};
use tokio::sync::{oneshot, Notify};
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

pub use crate::transport::frame_stamp_ns;
pub use crate::transport::{zenoh_config, Role, ZenohArgs, DEFAULT_ENDPOINT};
pub use error::{ServerError, SettingsError, ZenohConfigError};
pub use settings::{mode_name, Handoff, OverrunPolicy, ServerSettings};

use crate::config::SimConfig;
use crate::sim::Simulation;
use crate::sinks::mcap_file::{flexdyn_version, git_commit, RecordingInfo, VehicleInfo};
use crate::sinks::recorder::{RecordItem, RecordReport, RecordTx, Recorder};
use lockstep::LockstepCore;
use physics::{Ending, PhysicsCtx, Stepper};
use publish::FramePublisher;
use shared::{Frame, Shared};
use telemetry::{timing_of, TelemetryCtx};

/// Samples the `--record` queue holds before real time drops (lockstep waits instead).
pub const RECORD_QUEUE: usize = 65_536;

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
    /// Real time: lateness percentiles, overruns, skipped frames (zeros otherwise).
    pub timing: FrameTiming,
    /// Rejected commands by reason.
    pub rejected: RejectCounters,
    /// Valid commands dropped because the command queue was full.
    pub commands_dropped: u64,
    /// \[s\] wall time from the first frame to the end.
    pub wall_s: f64,
    /// `--record`: what the recording holds and what the recorder dropped.
    pub recording: Option<RecordReport>,
    /// Real time with `handoff = "direct"`: what publishing cost the physics thread, per frame.
    pub direct_publish: Option<PublishCost>,
}

/// The time the physics thread spent publishing frames (real time, `handoff = "direct"`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PublishCost {
    /// Frames published from the physics thread.
    pub frames: u64,
    /// \[ns\] mean time per frame.
    pub mean_ns: f64,
    /// \[ns\] largest time of one frame.
    pub max_ns: u64,
    /// Frames whose publication took longer than [`shared::SLOW_PUBLISH_NS`] (100 µs).
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
        if let Some(r) = &self.recording {
            write!(
                f,
                " recorded_samples={} record_dropped={} record_missing={}",
                r.stats.samples,
                r.dropped,
                r.stats.missing_total()
            )?;
        }
        if let Some(c) = &self.direct_publish {
            write!(
                f,
                " direct_publish_us mean={:.1} max={:.1} slow_over_100us={}",
                c.mean_ns * 1e-3,
                c.max_ns as f64 * 1e-3,
                c.slow_frames
            )?;
        }
        Ok(())
    }
}

/// Participants seen through their liveliness tokens, and a wake-up for the presence wait.
#[derive(Default)]
struct Presence {
    ids: Mutex<BTreeSet<u32>>,
    changed: Notify,
}

impl Presence {
    fn missing(&self, wanted: &[u32]) -> Vec<u32> {
        let ids = self.ids.lock().unwrap_or_else(|p| p.into_inner());
        wanted
            .iter()
            .copied()
            .filter(|id| !ids.contains(id))
            .collect()
    }
}

/// Who steps the frames: the physics thread (with the frame publishers when it publishes
/// itself), or the lockstep core in the command callback.
enum FrameLoop {
    Physics(Box<Stepper>, Option<FramePublisher>),
    Core(Arc<Mutex<LockstepCore>>),
}

/// Where the command callback delivers a validated command.
enum CommandSink {
    /// The physics thread's bounded queue (never blocks: a full queue drops and counts),
    /// behind the [`commands::Gate`].
    Queue(Mutex<(SyncSender<flexdyn_proto::CommandMsg>, commands::Gate)>),
    /// Lockstep with `handoff = "direct"`: the core, stepped in this callback.
    Core(Arc<Mutex<LockstepCore>>),
}

/// The zenoh callback for `flexdyn/<sc>/cmd/*`: decode and check (spacecraft, the key's
/// sender, the participants), count rejections, and deliver valid commands to `sink`.
fn command_callback(
    sink: CommandSink,
    shared: Arc<Shared>,
    topics: Topics,
    spacecraft_id: u32,
    participants: Vec<u32>,
    record: Option<RecordTx>,
) -> impl Fn(zenoh::sample::Sample) + Send + Sync + 'static {
    let log = Mutex::new(reject_log::RejectLog::default());
    let warn = move |reason: &'static str, sender: Option<u32>, detail: &dyn std::fmt::Display| {
        log.lock()
            .unwrap_or_else(|p| p.into_inner())
            .record(reason, sender, 1, detail);
    };
    move |sample| {
        let bytes = sample.payload().to_bytes();
        let key = sample.key_expr().as_str();
        // Every command that arrives is recorded, accepted or not: the file shows what was sent.
        if let Some(rec) = &record {
            rec.submit(RecordItem {
                key: Arc::from(key),
                payload: bytes.to_vec(),
                publish_time_ns: crate::transport::frame_stamp_ns(&sample),
            });
        }
        let cmd = match decode_command(&bytes) {
            Ok(cmd) => cmd,
            Err(e) => {
                let reason = match e {
                    flexdyn_proto::DecodeError::UnknownVersion { .. } => "bad_version",
                    flexdyn_proto::DecodeError::NonFinite { .. } => "non_finite",
                    _ => "malformed",
                };
                // The sender id sits at bytes 30..34 once the header is there.
                let sender = bytes
                    .get(30..34)
                    .and_then(|b| b.try_into().ok())
                    .map(u32::from_le_bytes)
                    .filter(|_| reason == "non_finite");
                warn(reason, sender, &e);
                shared.reject_decode(&e);
                return;
            }
        };
        if cmd.header.spacecraft_id != spacecraft_id {
            warn(
                "wrong_spacecraft",
                Some(cmd.sender_id),
                &format_args!(
                    "header.spacecraft_id {} is not this server's {spacecraft_id}",
                    cmd.header.spacecraft_id
                ),
            );
            shared.reject_wrong_spacecraft();
            return;
        }
        if topics.cmd_sender(key) != Some(cmd.sender_id) {
            warn(
                "wrong_identity",
                Some(cmd.sender_id),
                &format_args!(
                    "sender_id {} arrived on `{key}`; participant {} publishes on `{}` only",
                    cmd.sender_id,
                    cmd.sender_id,
                    topics.cmd(cmd.sender_id)
                ),
            );
            shared.reject_wrong_identity();
            return;
        }
        if participants.binary_search(&cmd.sender_id).is_err() {
            warn(
                "unknown_sender",
                Some(cmd.sender_id),
                &format_args!(
                    "sender_id {} is not in server.participants {participants:?}",
                    cmd.sender_id
                ),
            );
            shared.reject_unknown_sender();
            return;
        }
        match &sink {
            CommandSink::Queue(queue) => {
                let mut queue = queue.lock().unwrap_or_else(|p| p.into_inner());
                let (tx, gate) = &mut *queue;
                let published = shared.tick.load(std::sync::atomic::Ordering::Acquire);
                let offer = gate.check(&cmd, published);
                if offer != commands::Offer::Accepted {
                    physics::count_offer(&shared, offer, cmd.sender_id);
                    return;
                }
                let (sender, tick) = (cmd.sender_id, cmd.header.tick);
                match tx.try_send(cmd) {
                    Ok(()) => gate.queued(sender, tick),
                    Err(_) => {
                        shared
                            .commands_dropped
                            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    }
                }
            }
            CommandSink::Core(core) => core.lock().unwrap_or_else(|p| p.into_inner()).offer(&cmd),
        }
    }
}

/// Lockstep: waits until every participant's liveliness token is present and the state
/// publisher has a subscriber. `Ok(true)` to start, `Ok(false)` if `shutdown` completed first.
async fn await_presence(
    state_pub: &zenoh::pubsub::Publisher<'static>,
    presence: &Arc<Presence>,
    settings: &ServerSettings,
    topics: &Topics,
    mut shutdown: std::pin::Pin<&mut impl Future<Output = ()>>,
) -> Result<bool, ServerError> {
    let waited_from = Instant::now();
    let give_up = tokio::time::Instant::now() + settings.presence_timeout;
    let p = presence.clone();
    let _matching = state_pub
        .matching_listener()
        .callback(move |_| p.changed.notify_one())
        .await
        .map_err(|e| ServerError::zenoh("declare a matching listener", e))?;
    tracing::info!(
        participants = ?settings.participants,
        key = topics.participant_wildcard(),
        "waiting for the lockstep participants"
    );
    loop {
        let missing = presence.missing(&settings.participants);
        let matching = state_pub
            .matching_status()
            .await
            .map_err(|e| ServerError::zenoh("query the state publisher's matching status", e))?
            .matching();
        if missing.is_empty() && matching {
            tracing::info!("every lockstep participant is present; starting at tick 0");
            return Ok(true);
        }
        tokio::select! {
            () = shutdown.as_mut() => {
                tracing::info!("shutdown requested before tick 0");
                return Ok(false);
            }
            r = tokio::time::timeout_at(give_up, presence.changed.notified()) => {
                if r.is_err() {
                    return Err(ServerError::ParticipantsAbsent {
                        missing: if missing.is_empty() {
                            settings.participants.clone()
                        } else {
                            missing
                        },
                        sc_id: settings.sc_id.clone(),
                        waited_s: waited_from.elapsed().as_secs_f64(),
                    });
                }
            }
        }
    }
}

/// Runs the server until the configured duration is reached, `shutdown` completes, or an error
/// stops it.
///
/// `settings` are usually [`ServerSettings::from_table`] of `cfg.server` with command-line
/// overrides applied. The session is used as given (see [`zenoh_config`] for the loopback
/// defaults) and is not closed: close it after `run` returns to flush the last samples.
pub async fn run(
    session: Session,
    settings: ServerSettings,
    cfg: SimConfig,
    shutdown: impl Future<Output = ()>,
) -> Result<RunReport, ServerError> {
    let mut shutdown = std::pin::pin!(shutdown);
    settings.validate()?;
    let total_frames = settings.duration_frames(cfg.frame_ns)?;
    let topics = Topics::new(&settings.sc_id).map_err(|e| SettingsError::Invalid {
        name: "server.sc_id".into(),
        problem: e.to_string(),
    })?;
    let sim = Simulation::new(&cfg).map_err(|source| ServerError::Config { file: None, source })?;
    let mode = settings.mode;
    tracing::info!(
        mode = mode_name(mode),
        zid = %session.zid(),
        state = topics.state(),
        commands = topics.cmd_wildcard(),
        status = topics.status(),
        imus = ?sim.imu_names(),
        "flexdyn server starting: {}",
        cfg.summary()
    );
    tracing::info!("server settings: {}", settings.summary());
    if mode == Mode::RealTime && settings.stale_policy == StalePolicy::Hold {
        tracing::debug!("stale commands are held (stale_policy = hold)");
    }

    // Real time drops telemetry under congestion rather than delaying the frame; lockstep and
    // batch block, so no sample of the deterministic stream is lost. Delivery is reliable
    // (Zenoh's default `Reliability::Reliable`, over TCP); its setter is unstable in Zenoh 1.10.
    let congestion = if mode == Mode::RealTime {
        CongestionControl::Drop
    } else {
        CongestionControl::Block
    };
    let express = mode != Mode::Batch;
    // The state and every sensor topic are declared alike.
    let telemetry_pub = |key: String, what: &'static str| {
        let declared = session
            .declare_publisher(key)
            .congestion_control(congestion)
            .express(express);
        async move { declared.await.map_err(|e| ServerError::zenoh(what, e)) }
    };
    let state_pub = telemetry_pub(topics.state().to_owned(), "declare the state publisher").await?;
    let status_pub = session
        .declare_publisher(topics.status().to_owned())
        .congestion_control(congestion)
        .await
        .map_err(|e| ServerError::zenoh("declare the status publisher", e))?;

    let mut imu_pubs = Vec::with_capacity(sim.n_imus());
    for (i, name) in sim.imu_names().iter().enumerate() {
        let key = topics.imu(name).map_err(|e| SettingsError::Invalid {
            name: format!("imus[{i}].name"),
            problem: e.to_string(),
        })?;
        imu_pubs.push(telemetry_pub(key, "declare an IMU publisher").await?);
    }

    let mut st_pubs = Vec::with_capacity(sim.star_trackers().len());
    for (i, st) in sim.star_trackers().iter().enumerate() {
        let key = topics
            .star_tracker(st.name())
            .map_err(|e| SettingsError::Invalid {
                name: format!("star_trackers[{i}].name"),
                problem: e.to_string(),
            })?;
        st_pubs.push((
            telemetry_pub(key, "declare a star-tracker publisher").await?,
            st.config().every_frames,
        ));
    }
    let state_pub = Arc::new(state_pub);
    let publisher = FramePublisher::new(state_pub.clone(), imu_pubs, st_pubs);

    // What this server runs, for recordings and for the `flexdyn/<sc>/config` queryable.
    let vehicle = VehicleInfo {
        sc_id: settings.sc_id.clone(),
        spacecraft_id: settings.spacecraft_id,
        config_toml: cfg.source_toml.clone(),
        server_settings: settings.summary(),
        flexdyn_version: flexdyn_version().to_owned(),
        git_commit: git_commit().map(str::to_owned),
    };
    let vehicle_json = serde_json::to_string(&vehicle)
        .map_err(|e| ServerError::Internal(format!("vehicle description: {e}")))?;
    let _config_queryable = session
        .declare_queryable(topics.config())
        .callback(move |query| {
            let key = query.key_expr().clone();
            if let Err(e) = query.reply(key, vehicle_json.clone()).wait() {
                tracing::debug!(error = %e, "cannot answer a configuration query");
            }
        })
        .await
        .map_err(|e| ServerError::zenoh("declare the configuration queryable", e))?;

    // `--record`: the recorder thread, fed by whoever publishes the frames, the telemetry
    // thread (status) and the command callback. Real time drops (and counts) what it cannot
    // keep up with; lockstep and batch wait for it.
    let recorder = match &settings.record {
        Some(path) => {
            let info = RecordingInfo {
                recorder: "flexdyn run --record".into(),
                command_line: std::env::args().collect::<Vec<_>>().join(" "),
            };
            let (recorder, tx) =
                Recorder::start(path, &info, RECORD_QUEUE, mode != Mode::RealTime)?;
            tx.describe_vehicle(vehicle.clone());
            tracing::info!(file = %path.display(), "recording to MCAP");
            Some((recorder, tx))
        }
        None => None,
    };
    let record_tx = recorder.as_ref().map(|(_, tx)| tx.clone());
    // The recorder's view of the keys, for the telemetry thread and (lockstep, direct) the core.
    let recording = record_tx
        .clone()
        .map(|tx| publisher.recording(tx, &status_pub));

    // Who publishes the frames (see `publish`): batch always the telemetry thread.
    let direct = settings.handoff.is_direct(mode, settings.record.is_some());
    tracing::info!(
        handoff = if direct { "direct" } else { "thread" },
        "frames are published by {}",
        match (direct, mode) {
            (true, Mode::Lockstep) => "the Zenoh thread that delivers each tick's last answer",
            (true, _) => "the physics thread at each frame boundary",
            (false, _) => "the telemetry thread",
        }
    );

    let shared = Arc::new(Shared::new(&settings.participants));
    shared.set_run_state(RunState::Starting);
    let (cmd_tx, cmd_rx) = sync_channel(settings.command_queue);
    // Consumed commands go back to the telemetry thread to be freed there: an `Actuators`
    // command owns heap vectors, and the physics thread frees nothing.
    let (recycle_tx, recycle_rx) = sync_channel(settings.command_queue);
    let n_buffers = settings.telemetry_buffers;
    let (free_tx, free_rx) = sync_channel::<Box<Frame>>(n_buffers);
    let (full_tx, full_rx) = sync_channel::<Box<Frame>>(n_buffers);
    let shape = crate::sim::Snapshot::for_simulation(&sim);
    let (n_imus, n_sts) = (sim.n_imus(), sim.star_trackers().len());
    let new_frame = || Box::new(Frame::for_snapshot(&shape, n_imus, n_sts));
    let frame_ns = cfg.frame_ns;
    let input_ranges = sim.spacecraft().effector_input_ranges().to_vec();
    let stepper = Stepper::new(sim, &settings);

    // Who steps the frames, and where the frame publishers go: the physics thread (real time,
    // direct), the lockstep core (lockstep, direct) or the telemetry thread (otherwise).
    let events = Arc::new(Notify::new());
    let (frame_loop, telemetry_publisher) = match (direct, mode) {
        (true, Mode::Lockstep) => {
            let core = LockstepCore::new(
                stepper,
                new_frame(),
                publisher,
                recording.clone(),
                shared.clone(),
                total_frames,
                events.clone(),
            );
            (FrameLoop::Core(Arc::new(Mutex::new(core))), None)
        }
        (true, _) => (FrameLoop::Physics(Box::new(stepper), Some(publisher)), None),
        (false, _) => (FrameLoop::Physics(Box::new(stepper), None), Some(publisher)),
    };
    let sink = match &frame_loop {
        FrameLoop::Core(core) => CommandSink::Core(core.clone()),
        FrameLoop::Physics(..) => {
            // The telemetry pool, which only the physics thread's frames go through.
            for _ in 0..n_buffers {
                free_tx
                    .send(new_frame())
                    .map_err(|_| ServerError::Internal("telemetry pool".into()))?;
            }
            let gate = commands::Gate::new(
                &settings.participants,
                &input_ranges,
                mode == Mode::Lockstep,
            );
            CommandSink::Queue(Mutex::new((cmd_tx, gate)))
        }
    };

    let _cmd_sub = session
        .declare_subscriber(topics.cmd_wildcard().to_owned())
        .callback(command_callback(
            sink,
            shared.clone(),
            topics.clone(),
            settings.spacecraft_id,
            settings.participants.clone(),
            record_tx.clone(),
        ))
        .await
        .map_err(|e| ServerError::zenoh("declare the command subscriber", e))?;

    // Lockstep participants announce themselves with a liveliness token.
    let presence = Arc::new(Presence::default());
    let _presence_sub = if mode == Mode::Lockstep {
        let p = presence.clone();
        let t = topics.clone();
        let shared_p = shared.clone();
        Some(
            session
                .liveliness()
                .declare_subscriber(topics.participant_wildcard())
                .history(true)
                .callback(move |sample| {
                    let Some(id) = t.participant_id(sample.key_expr().as_str()) else {
                        return;
                    };
                    let mut ids = p.ids.lock().unwrap_or_else(|e| e.into_inner());
                    match sample.kind() {
                        SampleKind::Put => {
                            if ids.insert(id) {
                                tracing::info!(participant = id, "lockstep participant present");
                            }
                        }
                        SampleKind::Delete => {
                            if ids.remove(&id) {
                                tracing::warn!(
                                    participant = id,
                                    tick = shared_p.tick.load(std::sync::atomic::Ordering::Relaxed),
                                    "lockstep participant left (liveliness token dropped)"
                                );
                            }
                        }
                    }
                    drop(ids);
                    p.changed.notify_one();
                })
                .await
                .map_err(|e| {
                    ServerError::zenoh("declare the participant liveliness subscriber", e)
                })?,
        )
    } else {
        None
    };

    // The telemetry thread starts first, so StatusMsg (run_state = Starting) goes out while a
    // lockstep server waits for its participants.
    let telemetry = TelemetryCtx {
        publisher: telemetry_publisher,
        status_pub,
        full_rx,
        free_tx,
        recycle_rx,
        shared: shared.clone(),
        settings: settings.clone(),
        frame_ns,
        record: recording,
    };
    let (tlm_done_tx, tlm_done_rx) = oneshot::channel();
    std::thread::Builder::new()
        .name("flexdyn-telemetry".into())
        .spawn(move || {
            let _ = tlm_done_tx.send(telemetry.run());
        })
        .map_err(|e| ServerError::Internal(format!("cannot start the telemetry thread: {e}")))?;

    if mode == Mode::Lockstep {
        let ready =
            await_presence(&state_pub, &presence, &settings, &topics, shutdown.as_mut()).await;
        if !matches!(ready, Ok(true)) {
            // Not starting: end the telemetry thread (it publishes a final status) first.
            shared.set_run_state(if ready.is_ok() {
                RunState::Stopped
            } else {
                RunState::Failed
            });
            drop(full_tx);
            let _ = tlm_done_rx.await;
            drop(_cmd_sub);
            if let Some((recorder, tx)) = recorder {
                recorder.finish(&tx)?;
            }
            ready?;
            return Ok(RunReport {
                mode,
                outcome: Outcome::Stopped,
                last_tick: 0,
                sim_time_ns: 0,
                states_published: 0,
                telemetry_dropped: 0,
                timing: FrameTiming::default(),
                rejected: shared.rejected(),
                commands_dropped: 0,
                wall_s: 0.0,
                recording: None,
                direct_publish: None,
            });
        }
    }

    let started = Instant::now();
    let physics_result = match frame_loop {
        FrameLoop::Physics(stepper, direct) => {
            let physics = PhysicsCtx {
                settings: settings.clone(),
                total_frames,
                cmd_rx,
                recycle_tx,
                free_rx,
                full_tx,
                shared: shared.clone(),
                direct,
            };
            run_physics_thread(physics, *stepper, &settings, &shared, shutdown.as_mut()).await?
        }
        FrameLoop::Core(core) => {
            drop((cmd_rx, recycle_tx, free_rx));
            let r = run_lockstep_core(&core, &events, &settings, &shared, shutdown.as_mut()).await;
            // No frame goes through the channel; closing it ends the telemetry thread.
            drop(full_tx);
            r
        }
    };
    let wall_s = started.elapsed().as_secs_f64();
    let tlm = tlm_done_rx
        .await
        .map_err(|_| ServerError::Internal("the telemetry thread panicked".into()))?;

    // Commands stop arriving, then the recorder writes what it holds and closes the file.
    drop(_cmd_sub);
    let recording = match recorder {
        Some((recorder, tx)) => Some(recorder.finish(&tx)?),
        None => None,
    };
    let phys = physics_result?;
    let report = RunReport {
        mode,
        outcome: match phys.ending {
            Ending::Finished => Outcome::Finished,
            Ending::Stopped => Outcome::Stopped,
        },
        last_tick: phys.last_tick,
        sim_time_ns: phys.sim_time_ns,
        states_published: shared.published.load(std::sync::atomic::Ordering::Relaxed),
        telemetry_dropped: shared
            .telemetry_dropped
            .load(std::sync::atomic::Ordering::Relaxed),
        timing: timing_of(
            &tlm.lateness,
            shared.overruns.load(std::sync::atomic::Ordering::Relaxed),
            shared
                .frames_skipped
                .load(std::sync::atomic::Ordering::Relaxed),
        ),
        rejected: shared.rejected(),
        commands_dropped: shared
            .commands_dropped
            .load(std::sync::atomic::Ordering::Relaxed),
        wall_s,
        recording,
        direct_publish: {
            let n = shared
                .direct_publishes
                .load(std::sync::atomic::Ordering::Relaxed);
            (n > 0).then(|| PublishCost {
                frames: n,
                mean_ns: shared
                    .direct_publish_ns_total
                    .load(std::sync::atomic::Ordering::Relaxed) as f64
                    / n as f64,
                max_ns: shared
                    .direct_publish_ns_max
                    .load(std::sync::atomic::Ordering::Relaxed),
                slow_frames: shared
                    .direct_publishes_slow
                    .load(std::sync::atomic::Ordering::Relaxed),
            })
        },
    };
    tracing::info!("{report}");
    Ok(report)
}

/// Runs the physics thread to its end (or a stop request); `Err` only if it panicked.
async fn run_physics_thread(
    physics: PhysicsCtx,
    stepper: Stepper,
    settings: &ServerSettings,
    shared: &Arc<Shared>,
    mut shutdown: std::pin::Pin<&mut impl Future<Output = ()>>,
) -> Result<Result<physics::PhysicsReport, ServerError>, ServerError> {
    let (phys_done_tx, mut phys_done_rx) = oneshot::channel();
    let realtime_priority = (settings.mode == Mode::RealTime).then_some(settings.realtime_priority);
    std::thread::Builder::new()
        .name("flexdyn-physics".into())
        .spawn(move || {
            if let Some(p) = realtime_priority.filter(|p| *p > 0) {
                match set_fifo_priority(p) {
                    Ok(()) => tracing::info!(priority = p, "physics thread runs under SCHED_FIFO"),
                    Err(e) => tracing::warn!(
                        priority = p,
                        error = %e,
                        "cannot put the physics thread under SCHED_FIFO (needs CAP_SYS_NICE); \
                         running at normal priority"
                    ),
                }
            }
            let _ = phys_done_tx.send(physics.run(stepper));
        })
        .map_err(|e| ServerError::Internal(format!("cannot start the physics thread: {e}")))?;

    tokio::select! {
        r = &mut phys_done_rx => r,
        () = &mut shutdown => {
            tracing::info!("shutdown requested; stopping at the next frame boundary");
            shared.set_run_state(RunState::Stopping);
            shared.stop.store(true, std::sync::atomic::Ordering::Relaxed);
            phys_done_rx.await
        }
    }
    .map_err(|_| ServerError::Internal("the physics thread panicked".into()))
}

/// Lockstep with `handoff = "direct"`: starts the core (publishes tick 0) and waits for it to
/// end, checking the participant timeout every 50 ms; a stop request ends it at once.
async fn run_lockstep_core(
    core: &Arc<Mutex<LockstepCore>>,
    events: &Notify,
    settings: &ServerSettings,
    shared: &Arc<Shared>,
    mut shutdown: std::pin::Pin<&mut impl Future<Output = ()>>,
) -> Result<physics::PhysicsReport, ServerError> {
    let lock = || core.lock().unwrap_or_else(|p| p.into_inner());
    lock().start();
    loop {
        if lock().ended() {
            break;
        }
        tokio::select! {
            () = events.notified() => {}
            () = tokio::time::sleep(std::time::Duration::from_millis(50)) => {
                lock().check_timeout(settings.participant_timeout);
            }
            () = &mut shutdown => {
                tracing::info!("shutdown requested; stopping at the current tick");
                shared.set_run_state(RunState::Stopping);
                shared.stop.store(true, std::sync::atomic::Ordering::Relaxed);
                lock().stop();
            }
        }
    }
    lock().outcome()
}

/// Puts the calling thread under SCHED_FIFO at `priority` (1–99); the error says why the OS
/// refused (typically: no CAP_SYS_NICE).
#[cfg(unix)]
fn set_fifo_priority(priority: u8) -> Result<(), String> {
    use thread_priority::{
        set_thread_priority_and_policy, thread_native_id, RealtimeThreadSchedulePolicy,
        ThreadPriority, ThreadPriorityValue, ThreadSchedulePolicy,
    };
    let value = ThreadPriorityValue::try_from(priority).map_err(|e| format!("{e:?}"))?;
    set_thread_priority_and_policy(
        thread_native_id(),
        ThreadPriority::Crossplatform(value),
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
    )
    .map_err(|e| format!("{e:?}"))
}

/// SCHED_FIFO is a POSIX policy: elsewhere the setting is refused.
#[cfg(not(unix))]
fn set_fifo_priority(_priority: u8) -> Result<(), String> {
    Err("realtime_priority needs a POSIX system".into())
}

#[cfg(all(test, unix))]
mod tests {
    use super::set_fifo_priority;
    use thread_priority::{
        thread_native_id, thread_schedule_policy, RealtimeThreadSchedulePolicy,
        ThreadSchedulePolicy,
    };

    #[test]
    fn fifo_priority_applies_to_the_calling_thread_or_reports_why_not() {
        std::thread::spawn(|| match set_fifo_priority(10) {
            Ok(()) => {
                assert_eq!(
                    thread_schedule_policy().unwrap(),
                    ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo)
                );
                let params =
                    thread_priority::unix::thread_schedule_policy_param(thread_native_id())
                        .unwrap()
                        .1;
                assert_eq!(params.sched_priority, 10);
            }
            Err(e) => assert!(!e.is_empty(), "a refusal must say why"),
        })
        .join()
        .unwrap();
        assert!(
            set_fifo_priority(0).is_err(),
            "0 is not a SCHED_FIFO priority"
        );
    }
}
