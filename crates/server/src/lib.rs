//! The flexdyn server: propagates a spacecraft and talks to flight code over Zenoh, in real
//! time, in lockstep or in batch.
//!
//! [`run`] is the whole server as a library function with its I/O injected (a Zenoh session, the
//! settings, the simulation configuration and a shutdown future); the `flexdyn` binary only parses
//! arguments, initialises tracing and calls [`cli::run_from_args`], which calls [`run`].
//!
//! # Layout
//! [`run`] goes through the phases of a run, each in its own module:
//! - `setup`: the telemetry publishers, the `flexdyn/<sc>/config` queryable, the `--record`
//!   recorder; then the threads' channels (`Wiring`, in this file).
//! - `intake`: the command callback (Zenoh rx): decoding, the checks, the rejection counters,
//!   and delivery to the physics thread's queue or the lockstep core.
//! - `presence`: lockstep participants' liveliness tokens and the wait before tick 0.
//! - [`operator`]: the operator's pause, resume and "run N ticks" (`flexdyn/<sc>/operator`).
//! - [`telemetry`], [`physics`], [`lockstep`]: the threads that run the frames (below).
//!   [`physics`] is the one frame loop, over a world of one spacecraft or of a fleet
//!   ([`world::WorldStepper`]; [`fleet`] only sets a fleet up); each vehicle's per-frame work is
//!   a [`stepper::Stepper`], which the direct lockstep core steps as well.
//! - `report`: the [`RunReport`], collected when every thread is done.
//!
//! And what they use:
//! - [`settings`]: [`ServerSettings`], the `[server]` table and `flexdyn run` options.
//! - [`flexdyn_proto::client::transport`]: [`zenoh_config`], the one builder of every Zenoh configuration (loopback
//!   defaults, multicast scouting always off).
//! - [`commands`]: per-participant command book (lockstep answers, staleness, summation) and
//!   the callback's gate.
//! - [`pacing`]: absolute-deadline real-time pacing (sleep, then spin) and overrun policies.
//! - [`shared`]: lock-free counters and the preallocated telemetry buffers.
//! - [`error`]: typed errors.
//! - [`cli`]: `flexdyn run` arguments and the process-level wrapper (runtime, signals).
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
//! `--record` or under SCHED_FIFO. The per-frame work ([`stepper::Stepper`]) never allocates, locks or
//! touches the network; in real time the physics thread never blocks on the I/O side (a frame without a
//! free buffer loses its telemetry, counted).
//!
//! # Place in the workspace
//! A crate of its own (`flexdyn-server`): it depends on the wire (`flexdyn-proto` with its client
//! transport), the model crates, `flexdyn-vehicle` (the configuration, one vehicle, the world of
//! vehicles) and `flexdyn-sinks` (the `--record` recorder, the shutdown signals), and on Zenoh and
//! tokio. It must never depend on the campaigns or the command line, which use it; `.ci/layers`
//! checks the order.

#![warn(missing_docs)]

pub mod access;
pub mod checkpoint;
pub mod cli;
pub mod clock;
pub mod commands;
pub mod error;
pub mod fault_cmd;
pub mod fault_log;
pub mod fleet;
pub mod fsw;
mod intake;
mod lateness_ring;
pub mod lockstep;
pub mod operator;
pub mod pacing;
pub mod physics;
mod presence;
pub mod publish;
mod reject_log;
mod relative;
mod report;
pub mod rt;
pub mod settings;
mod setup;
pub mod shared;
pub mod stepper;
pub mod telemetry;
pub mod tick_cost;
pub mod world;

use std::future::Future;
use std::sync::mpsc::{sync_channel, SyncSender};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use flexdyn_proto::{Mode, RunState, StalePolicy, Topics};
use tokio::sync::{oneshot, Notify};
use zenoh::Session;

pub use error::{ServerError, SettingsError, ZenohConfigError};
pub use flexdyn_proto::client::transport::frame_stamp_ns;
pub use flexdyn_proto::client::transport::{zenoh_config, Role, ZenohArgs, DEFAULT_ENDPOINT};
pub use report::{CheckpointSummary, Outcome, PublishCost, RunReport};
pub use settings::{mode_name, Handoff, OverrunPolicy, ServerSettings};
pub use setup::RECORD_QUEUE;

use flexdyn_sinks::recorder::{RecordReport, RecordTx, Recorder};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use intake::CommandSink;
use lockstep::LockstepCore;
use physics::{Lane, Outlet, PhysicsCtx, PhysicsOutcome};
use presence::Presence;
use setup::Endpoints;
use shared::{Frame, Shared};
use stepper::Stepper;
use telemetry::{TelemetryCtx, TelemetryReport};
use world::WorldStepper;

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
    let mode = settings.mode;

    // Setup: the simulation, its telemetry publishers and configuration queryable, the
    // recorder, and the threads' channels (who steps the frames and who publishes them).
    let (topics, sim, total_frames) = prepare(&session, &settings, &cfg)?;
    let endpoints = Endpoints::declare(&session, &settings, &cfg, &topics, &sim).await?;
    let _config = setup::serve_config(&session, &topics, &endpoints.vehicle).await?;
    let recorder = setup::start_recorder(&settings, &endpoints.vehicle)?;
    let record_tx = recorder.as_ref().map(|(_, tx)| tx.clone());
    let shared = Arc::new(Shared::new(&settings.participants));
    shared.set_run_state(RunState::Starting);
    let state_pub = endpoints.state_pub.clone();
    // Checkpoints: the writer thread, and the stepping side that takes them.
    let (writer, checkpointer) = start_checkpoints(
        &settings,
        (checkpoint::FRONT_END, &settings.sc_id),
        (sim.step_ns(), sim.frame_ns()),
        total_frames,
    )?;
    let wiring = Wiring::new(
        endpoints,
        sim,
        &settings,
        total_frames,
        &shared,
        record_tx.clone(),
        checkpointer,
    )?;
    // Hard real time: after the buffers exist (mlockall faults them in), before the physics
    // thread starts; undone when the run ends.
    let _realtime = RealtimeHold::acquire(&settings)?;

    // zenoh rx: the operator's pause / resume / run N ticks (moves the shared hold target).
    let core = match &wiring.frames {
        Frames::Core { core, .. } => Some(core.clone()),
        Frames::Physics(..) => None,
    };
    let _operator = operator::declare(
        &session,
        &topics,
        shared.clone(),
        mode,
        settings.spacecraft_id,
        core,
        record_tx.clone(),
        shared.clone(),
        writer
            .as_ref()
            .and_then(|w| w.operator_requests(&settings.checkpoints)),
    )
    .await?;

    // zenoh rx: live faults (resolved there, installed by whoever steps the frames).
    let resolver = cfg
        .live_fault_resolver()
        .map_err(|source| ServerError::Config { file: None, source })?;
    let _faults = fault_cmd::declare(
        &session,
        &topics,
        resolver,
        wiring.fault_sink,
        shared.clone(),
        settings.spacecraft_id,
        record_tx.clone(),
    )
    .await?;

    // zenoh rx: the flight code's own telemetry, checked against `[[fsw_streams]]` and recorded.
    let _fsw = fsw::declare(
        &session,
        &topics,
        fsw::FswIntake::new(
            &topics,
            cfg.fsw_streams.clone(),
            settings.spacecraft_id,
            cfg.frame_ns,
            total_frames.filter(|_| mode == Mode::Lockstep),
        )?,
        shared.clone(),
        record_tx.clone(),
    )
    .await?;

    // zenoh rx: the command callback, into the physics thread's queue or the lockstep core.
    let commands = intake::declare(
        &session,
        &topics,
        wiring.sink,
        shared.clone(),
        &settings,
        record_tx,
    )
    .await?;

    // Presence: lockstep participants announce themselves with a liveliness token.
    let presence = match mode {
        Mode::Lockstep => Some(Presence::declare(&session, &topics, shared.clone()).await?),
        _ => None,
    };

    // The telemetry thread starts first, so StatusMsg (run_state = Starting) goes out while a
    // lockstep server waits for its participants.
    let (telemetry, telemetry_thread) = spawn_telemetry(wiring.telemetry)?;
    let mut wiring_frames = wiring.frames;
    if let Frames::Physics(physics, _) = &mut wiring_frames {
        physics.set_wake(telemetry_thread);
    }
    if let Some(presence) = &presence {
        let ready = presence
            .wait(&state_pub, &settings, &topics, shutdown.as_mut())
            .await;
        if !matches!(ready, Ok(true)) {
            // Not starting: end the telemetry thread (it publishes a final status) first.
            shared.set_run_state(if ready.is_ok() {
                RunState::Stopped
            } else {
                RunState::Failed
            });
            drop(wiring_frames);
            let _ = telemetry.await;
            drop(commands);
            finish_recording(recorder)?;
            ready?;
            return Ok(RunReport::before_tick_0(mode, shared.rejected()));
        }
    }

    // The physics thread (or the lockstep core) to the end, then the telemetry thread's.
    let started = Instant::now();
    let physics = run_frames(wiring_frames, &settings, &shared, shutdown.as_mut()).await?;
    let wall_s = started.elapsed().as_secs_f64();
    if let Some(w) = &writer {
        w.flush();
    }
    let tlm = telemetry
        .await
        .map_err(|_| ServerError::Internal("the telemetry thread panicked".into()))?;

    // The report: commands stop arriving, the recorder writes what it holds and closes the file.
    drop(commands);
    let recording = finish_recording(recorder)?;
    let mut report = RunReport::collect(
        mode,
        physics.result?,
        &shared,
        &tlm.lateness,
        wall_s,
        recording,
    );
    report.physics_thread = physics.usage;
    report.ticks = physics.ticks.summary();
    report.checkpoints = writer.map(|w| w.stats.summary());
    tracing::info!("{report}");
    Ok(report)
}

/// The checkpoint writer and the stepping side of a run that saves checkpoints (`None` for
/// one that saves none), for the front end and file stem `(front_end, stem)` and the step and
/// frame `(step_ns, frame_ns)`; checks that a resumed run starts before its end.
pub(crate) fn start_checkpoints(
    settings: &ServerSettings,
    (front_end, stem): (&str, &str),
    (step_ns, frame_ns): (u64, u64),
    total_frames: Option<u64>,
) -> Result<(Option<checkpoint::Writer>, Option<checkpoint::Checkpointer>), ServerError> {
    let c = &settings.checkpoints;
    let start = c.start_tick();
    if let (Some(r), Some(total)) = (&c.resume, total_frames) {
        if start >= total {
            return Err(SettingsError::Invalid {
                name: "--duration-s".into(),
                problem: format!(
                    "the checkpoint `{}` is at tick {start}, at or after the end of the run \
                     (tick {total}; the duration counts from t = 0)",
                    r.file.display()
                ),
            }
            .into());
        }
    }
    if let Some((tick, _)) = &c.save_at {
        let problem = if *tick <= start {
            Some("must be after the tick the run starts at".to_string())
        } else if total_frames.is_some_and(|t| *tick > t) {
            Some("is after the end of the run".to_string())
        } else {
            None
        };
        if let Some(problem) = problem {
            return Err(SettingsError::Invalid {
                name: "--checkpoint-at-tick".into(),
                problem: format!("{tick} {problem}"),
            }
            .into());
        }
    }
    if let Some((_, file)) = &c.save_at {
        let parent = file
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."));
        if !parent.is_dir() {
            return Err(SettingsError::Invalid {
                name: "--checkpoint".into(),
                problem: format!(
                    "`{}`: its directory `{}` does not exist",
                    file.display(),
                    parent.display()
                ),
            }
            .into());
        }
    }
    if let Some(dir) = c.dir.as_ref().filter(|d| !d.is_dir()) {
        return Err(SettingsError::Invalid {
            name: "--checkpoint-dir".into(),
            problem: format!("`{}` is not a directory", dir.display()),
        }
        .into());
    }
    if !c.saves() {
        return Ok((None, None));
    }
    let sync = settings.mode != Mode::RealTime;
    let (w, cp) = checkpoint::Writer::start(c, (front_end, stem), (step_ns, frame_ns), sync)?;
    Ok((Some(w), Some(cp)))
}

/// Validates the settings against `cfg`, builds the simulation and logs what is starting:
/// the spacecraft's topics, the simulation and the frames to run (`None`: until stopped).
fn prepare(
    session: &Session,
    settings: &ServerSettings,
    cfg: &SimConfig,
) -> Result<(Topics, Simulation, Option<u64>), ServerError> {
    settings.validate()?;
    settings.check_link_faults(cfg)?;
    let total_frames = settings.duration_frames(cfg.frame_ns)?;
    let topics = Topics::new(&settings.sc_id).map_err(|e| SettingsError::Invalid {
        name: "server.sc_id".into(),
        problem: e.to_string(),
    })?;
    let mut sim =
        Simulation::new(cfg).map_err(|source| ServerError::Config { file: None, source })?;
    // The environment models run on their own thread, never on the physics thread; the
    // samples are the same bits either way, so a failed spawn only costs time.
    if let Err(e) = sim.offload_environment() {
        tracing::warn!(error = %e, "environment updates stay on the physics thread");
    }
    tracing::info!(
        mode = mode_name(settings.mode),
        zid = %session.zid(),
        state = topics.state(),
        commands = topics.cmd_wildcard(),
        status = topics.status(),
        sensors = ?sim
            .sensors()
            .sensors()
            .iter()
            .map(|s| format!("{}/{}", s.kind().key_prefix, s.name()))
            .collect::<Vec<_>>(),
        "flexdyn server starting: {}",
        cfg.summary()
    );
    tracing::info!("server settings: {}", settings.summary());
    fault_log::log_configured(sim.faults().specs(), None);
    flexdyn_proto::client::transport::log_listening(session);
    if settings.mode == Mode::RealTime && settings.stale_policy == StalePolicy::Hold {
        tracing::debug!("stale commands are held (stale_policy = hold)");
    }
    Ok((topics, sim, total_frames))
}

/// What steps the frames, with the channel ends it needs.
enum Frames {
    /// The physics thread (with the frame publishers when it publishes them itself).
    Physics(Box<PhysicsCtx>, Box<WorldStepper>),
    /// Lockstep with `handoff = "direct"`: the core, stepped in the command callback. No frame
    /// goes through the channel to the telemetry thread; closing `full_tx` ends that thread.
    Core {
        core: Arc<Mutex<LockstepCore>>,
        events: Arc<Notify>,
        full_tx: SyncSender<Box<Frame>>,
    },
}

/// The threads of a run, wired as in the diagram of the module docs: who steps the frames,
/// where the command callback delivers, and the telemetry thread's side.
struct Wiring {
    frames: Frames,
    sink: CommandSink,
    fault_sink: fault_cmd::FaultSink,
    telemetry: TelemetryCtx,
}

impl Wiring {
    fn new(
        endpoints: Endpoints,
        sim: Simulation,
        settings: &ServerSettings,
        total_frames: Option<u64>,
        shared: &Arc<Shared>,
        record: Option<RecordTx>,
        checkpoints: Option<checkpoint::Checkpointer>,
    ) -> Result<Self, ServerError> {
        let mode = settings.mode;
        let resume = settings.checkpoints.resume.as_ref();
        let start_tick = settings.checkpoints.start_tick();
        // Who publishes the frames (see `publish`): batch always the telemetry thread.
        let direct = settings.direct_handoff();
        tracing::info!(
            handoff = if direct { "direct" } else { "thread" },
            "frames are published by {}",
            match (direct, mode) {
                (true, Mode::Lockstep) => "the Zenoh thread that delivers each tick's last answer",
                (true, _) => "the physics thread at each frame boundary",
                (false, _) => "the telemetry thread",
            }
        );
        let Endpoints {
            status_pub,
            frames: publisher,
            ..
        } = endpoints;
        // The recorder's view of the keys, for the telemetry thread and (lockstep, direct) the
        // core.
        let recording = record.map(|tx| publisher.recording(tx, &status_pub));

        let (cmd_tx, cmd_rx) = sync_channel(settings.command_queue);
        // Consumed commands go back to the telemetry thread to be freed there: an `Actuators`
        // command owns heap vectors, and the physics thread frees nothing.
        let (recycle_tx, recycle_rx) = sync_channel(settings.command_queue);
        let n_buffers = settings.telemetry_buffers;
        let (free_tx, free_rx) = sync_channel::<Box<Frame>>(n_buffers);
        let (full_tx, full_rx) = sync_channel::<Box<Frame>>(n_buffers);
        // Live faults: resolved requests in (one queue slot per live-fault slot), their boxes
        // back to be freed by the telemetry thread.
        let (fault_tx, fault_rx) = sync_channel(flexdyn_faults::MAX_LIVE_FAULTS);
        let (fault_recycle_tx, fault_recycle_rx) =
            sync_channel(2 * flexdyn_faults::MAX_LIVE_FAULTS);
        let shape = sim.blank_state();
        let n_sensors = sim.sensors().len();
        let n_events = sim.faults().event_capacity();
        let new_frame =
            || Box::new(Frame::for_state(&shape, n_sensors).with_fault_events(n_events));
        let frame_ns = sim.frame_ns();
        let input_ranges = sim.spacecraft().effector_input_ranges().to_vec();
        let fault_log = fault_log::FaultLog::new(sim.faults().specs());
        let stepper = Stepper::new(sim, settings);

        // Who steps the frames, and where the frame publishers go: the physics thread (real
        // time, direct), the lockstep core (lockstep, direct) or the telemetry thread
        // (otherwise).
        let (frames, sink, fault_sink, telemetry_publisher) = if direct && mode == Mode::Lockstep {
            let events = Arc::new(Notify::new());
            let mut world = WorldStepper::one(settings.sc_id.clone(), stepper);
            for v in &mut world.vehicles {
                v.frame = Some(new_frame());
            }
            let lane = lockstep::CoreLane {
                publisher,
                record: recording.clone(),
                shared: shared.clone(),
            };
            let mut core = LockstepCore::new(
                world,
                vec![lane],
                Vec::new(),
                shared.clone(),
                false,
                total_frames,
                events.clone(),
            )
            .with_checkpoints(checkpoints);
            // Restored after the core began tick 0 on the fresh world, so nothing of that
            // beginning stays in the restored books.
            if let Some(r) = resume {
                checkpoint::restore(r, core.world_mut())?;
                core.resumed_at(start_tick);
            }
            let core = Arc::new(Mutex::new(core));
            let seat = lockstep::VehicleCore {
                vehicle: 0,
                core: core.clone(),
            };
            let sink = CommandSink::Core(seat.clone());
            let fault_sink = fault_cmd::FaultSink::Core(seat);
            let frames = Frames::Core {
                core,
                events,
                full_tx,
            };
            (frames, sink, fault_sink, None)
        } else {
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
            let (direct, telemetry) = if direct {
                (Some(publisher), None)
            } else {
                (None, Some(publisher))
            };
            let lane = Lane {
                shared: shared.clone(),
                recycle_tx,
                fault_rx,
                fault_recycle_tx,
                outlet: Outlet::Pool {
                    free_rx,
                    full_tx,
                    direct,
                    wake: None,
                },
            };
            let physics = PhysicsCtx {
                settings: settings.clone(),
                total_frames,
                cmd_rx,
                lanes: vec![lane],
                control: shared.clone(),
                lateness: None,
                relative: Vec::new(),
                name_vehicles: false,
                start_tick,
                checkpoints,
            };
            let mut world = WorldStepper::one(settings.sc_id.clone(), stepper);
            if let Some(r) = resume {
                checkpoint::restore(r, &mut world)?;
            }
            let frames = Frames::Physics(Box::new(physics), Box::new(world));
            (
                frames,
                CommandSink::Queue {
                    vehicle: 0,
                    queue: Mutex::new((cmd_tx, gate)),
                },
                fault_cmd::FaultSink::Queue(fault_tx),
                telemetry,
            )
        };
        let telemetry = TelemetryCtx {
            publisher: telemetry_publisher,
            status_pub,
            full_rx,
            free_tx,
            recycle_rx,
            fault_recycle_rx,
            shared: shared.clone(),
            settings: settings.clone(),
            frame_ns,
            record: recording,
            lateness_ring: None,
            fault_log,
        };
        Ok(Self {
            frames,
            sink,
            fault_sink,
            telemetry,
        })
    }
}

/// Starts the telemetry thread; the receiver yields its report when it ends (an error if it
/// panicked).
fn spawn_telemetry(
    telemetry: TelemetryCtx,
) -> Result<(oneshot::Receiver<TelemetryReport>, std::thread::Thread), ServerError> {
    let (done_tx, done_rx) = oneshot::channel();
    let off_cpu = match telemetry.settings.mode {
        Mode::RealTime => telemetry.settings.physics_cpu,
        _ => None,
    };
    let handle = std::thread::Builder::new()
        .name("flexdyn-telemetry".into())
        .spawn(move || {
            // Off the physics thread's CPU (checked before it starts), whatever thread
            // started this one.
            if let Some(cpu) = off_cpu {
                if let Err(e) = rt::keep_off_cpu(cpu) {
                    tracing::warn!(error = %e, "telemetry thread: cannot leave CPU {cpu}");
                }
            }
            let _ = done_tx.send(telemetry.run());
        })
        .map_err(|e| ServerError::Internal(format!("cannot start the telemetry thread: {e}")))?;
    Ok((done_rx, handle.thread().clone()))
}

/// Steps the frames to the end (or a stop request): on the physics thread, or through the
/// lockstep core. The outer `Err` only if the physics thread panicked.
async fn run_frames(
    frames: Frames,
    settings: &ServerSettings,
    shared: &Arc<Shared>,
    shutdown: std::pin::Pin<&mut impl Future<Output = ()>>,
) -> Result<PhysicsOutcome, ServerError> {
    match frames {
        Frames::Physics(physics, world) => {
            run_physics_thread(
                *physics,
                *world,
                settings,
                std::slice::from_ref(shared),
                shutdown,
            )
            .await
        }
        Frames::Core {
            core,
            events,
            full_tx,
        } => {
            let outcome = run_lockstep_core(
                &core,
                &events,
                settings,
                std::slice::from_ref(shared),
                shared,
                shutdown,
            )
            .await;
            drop(full_tx);
            Ok(outcome)
        }
    }
}

/// Closes the `--record` file once everything queued is written; what it holds.
pub(crate) fn finish_recording(
    recorder: Option<(Recorder, RecordTx)>,
) -> Result<Option<RecordReport>, ServerError> {
    recorder
        .map(|(recorder, tx)| recorder.finish(&tx))
        .transpose()
        .map_err(ServerError::from)
}

/// The process-wide real-time requests of a real-time run ([`rt`]), held until the run ends.
struct RealtimeHold {
    locked: bool,
    _dma: Option<rt::DmaLatency>,
}

impl RealtimeHold {
    /// Checks `physics_cpu`, locks the memory and holds `/dev/cpu_dma_latency` as the settings
    /// ask (real time only); an error names the setting the OS refused.
    fn acquire(settings: &ServerSettings) -> Result<Self, ServerError> {
        let mut hold = Self {
            locked: false,
            _dma: None,
        };
        if settings.mode != Mode::RealTime {
            return Ok(hold);
        }
        let refused = |setting: &'static str| {
            move |problem: String| ServerError::Realtime { setting, problem }
        };
        if let Some(cpu) = settings.physics_cpu {
            rt::check_physics_cpu(cpu).map_err(refused("server.physics_cpu"))?;
        }
        if settings.cpu_dma_latency {
            hold._dma = Some(rt::DmaLatency::hold().map_err(refused("server.cpu_dma_latency"))?);
            tracing::info!("holding {} at 0 µs", rt::CPU_DMA_LATENCY);
        }
        if settings.lock_memory {
            rt::lock_memory().map_err(refused("server.lock_memory"))?;
            hold.locked = true;
            tracing::info!("memory locked (mlockall MCL_CURRENT | MCL_FUTURE)");
        }
        Ok(hold)
    }
}

impl Drop for RealtimeHold {
    fn drop(&mut self) {
        if self.locked {
            rt::unlock_memory();
        }
    }
}

/// What the physics thread does before its first frame in real time: pre-fault its stack, pin
/// itself to its CPU, go under SCHED_FIFO, as the settings ask. An error names the setting the
/// OS refused.
fn prepare_physics_thread(settings: &ServerSettings) -> Result<(), ServerError> {
    if settings.mode != Mode::RealTime {
        return Ok(());
    }
    if settings.lock_memory {
        rt::prefault_stack();
    }
    if let Some(cpu) = settings.physics_cpu {
        rt::pin_to_cpu(cpu).map_err(|problem| ServerError::Realtime {
            setting: "server.physics_cpu",
            problem,
        })?;
        tracing::info!(cpu, "physics thread pinned");
    }
    let p = settings.realtime_priority;
    if p > 0 {
        set_fifo_priority(p).map_err(|e| ServerError::Realtime {
            setting: "server.realtime_priority",
            problem: format!(
                "cannot put the physics thread under SCHED_FIFO at priority {p}: {e} (needs \
                 CAP_SYS_NICE, or an RLIMIT_RTPRIO (`ulimit -r`) of at least {p})"
            ),
        })?;
        tracing::info!(priority = p, "physics thread runs under SCHED_FIFO");
    }
    Ok(())
}

/// Runs the physics thread over `world` to its end (or a stop request: `shared` are every
/// vehicle's counters, which say `Stopping` meanwhile; the stop flag is `physics.control`'s).
/// `Err` only if the thread panicked.
async fn run_physics_thread(
    physics: PhysicsCtx,
    world: WorldStepper,
    settings: &ServerSettings,
    shared: &[Arc<Shared>],
    mut shutdown: std::pin::Pin<&mut impl Future<Output = ()>>,
) -> Result<PhysicsOutcome, ServerError> {
    let (done_tx, mut done_rx) = oneshot::channel();
    let control = physics.control.clone();
    let thread_settings = settings.clone();
    std::thread::Builder::new()
        .name("flexdyn-physics".into())
        .stack_size(rt::PHYSICS_STACK_BYTES)
        .spawn(move || {
            if let Err(e) = prepare_physics_thread(&thread_settings) {
                let _ = done_tx.send(PhysicsOutcome {
                    result: Err(e),
                    ticks: tick_cost::TickCost::default(),
                    usage: None,
                });
                return;
            }
            let _ = done_tx.send(physics.run(world));
        })
        .map_err(|e| ServerError::Internal(format!("cannot start the physics thread: {e}")))?;

    tokio::select! {
        r = &mut done_rx => r,
        () = &mut shutdown => {
            tracing::info!("shutdown requested; stopping at the next frame boundary");
            for sh in shared {
                sh.set_run_state(RunState::Stopping);
            }
            control.stop.store(true, std::sync::atomic::Ordering::Relaxed);
            done_rx.await
        }
    }
    .map_err(|_| ServerError::Internal("the physics thread panicked".into()))
}

/// Lockstep with `handoff = "direct"`: starts the core (publishes tick 0) and waits for it to
/// end, checking the participant timeout every 50 ms; a stop request ends it at once (`shared`
/// are every vehicle's counters, which say `Stopping` meanwhile; the stop flag is `control`'s).
async fn run_lockstep_core(
    core: &Arc<Mutex<LockstepCore>>,
    events: &Notify,
    settings: &ServerSettings,
    shared: &[Arc<Shared>],
    control: &Shared,
    mut shutdown: std::pin::Pin<&mut impl Future<Output = ()>>,
) -> PhysicsOutcome {
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
                for sh in shared {
                    sh.set_run_state(RunState::Stopping);
                }
                control.stop.store(true, std::sync::atomic::Ordering::Relaxed);
                lock().stop();
            }
        }
    }
    let mut core = lock();
    PhysicsOutcome {
        result: core.outcome(),
        ticks: core.take_ticks(),
        usage: None,
    }
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
