//! Fleet mode: `flexdyn run --fleet FLEET.toml` serves every vehicle of a fleet file
//! ([`flexdyn_vehicle::world::fleet`]) from one process, on one tick.
//!
//! - **Keys.** Each vehicle publishes and takes commands under its own id, exactly as a
//!   single-vehicle server with `sc_id = <id>` does: `flexdyn/<id>/tlm/…`, `flexdyn/<id>/cmd/*`,
//!   `flexdyn/<id>/status`, and its `flexdyn/<id>/config` queryable describes that vehicle. A
//!   controller written for one vehicle (`flexdyn-acs-demo --sc-id <id>`) runs unchanged.
//! - **One physics thread** steps the whole world, in the frame loop a one-spacecraft server
//!   runs too ([`super::physics`] over a [`super::world::WorldStepper`]); each vehicle publishes
//!   in place from that thread ([`super::physics::Outlet::InPlace`]). The command callbacks and
//!   one telemetry (status) thread per vehicle are the I/O side.
//! - **Lockstep.** One barrier covers every participant of every vehicle: tick `k + 1` is
//!   computed when all have answered tick `k`. A participant listed for several vehicles (a
//!   formation controller) answers each of them on its key `flexdyn/<id>/cmd/<sender>` and
//!   declares its liveliness token under each. The no-hang timeout names the vehicle and the
//!   participant.
//! - **Faults** are each vehicle's own: its `[[faults]]` (fault indices from 0 in its own file),
//!   its live fault commands on `flexdyn/<id>/fault` (resolved against that vehicle, installed
//!   by the physics thread before the next frame is stepped, as in a single-vehicle server
//!   with `handoff = "queue"`), its fault events on `flexdyn/<id>/tlm/fault` and its active set
//!   in its StatusMsg.
//! - **Real time** keeps its rule: the physics thread never waits for the network (telemetry
//!   goes out with `CongestionControl::Drop`, commands are taken as they have arrived).
//! - **Settings**: the first vehicle's `[server]` table with the command-line options on top;
//!   the ids and participants are the fleet file's (`--sc-id`, `--spacecraft-id`,
//!   `--participants` are refused with `--fleet`).
//! - **Lateness** (real time): the fleet has one frame boundary, so one lateness per frame; the
//!   physics thread hands it to every vehicle's telemetry thread through a ring of atomics
//!   (`super::lateness_ring`), and each vehicle's StatusMsg and report carry its p50, p99 and
//!   maximum, as a one-vehicle server's do.
//! - **`--record`**: one MCAP file holds every vehicle (each described by its configuration),
//!   its frames, statuses and commands, and each deputy's relative states. The physics thread
//!   queues what it publishes (lockstep and batch wait for the recorder; real time drops and
//!   counts what the recorder cannot take, and never waits).
//! - **Operator**: an OperatorMsg on any vehicle's `flexdyn/<id>/operator` pauses, resumes or
//!   (lockstep) runs N ticks of the whole fleet: one hold target for the fleet, every vehicle's
//!   StatusMsg says `Paused` while held and its TimeMsg of the held tick too. A refusal counts
//!   in that vehicle's `rejected.operator_refused`.

use std::future::Future;
use std::path::Path;
use std::sync::mpsc::sync_channel;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use flexdyn_proto::{Mode, RunState, Topics};
use tokio::sync::Notify;
use zenoh::Session;

use super::cli::RunArgs;
use super::commands::Gate;
use super::error::{ServerError, SettingsError};
use super::fault_cmd::FaultSink;
use super::fault_log::FaultLog;
use super::intake::{self, CommandSink};
use super::lateness_ring::LatenessRing;
use super::lockstep::{CoreLane, LockstepCore, VehicleCore};
use super::operator;
use super::physics::{Lane, Outlet, PhysicsCtx};
use super::presence::Presence;
use super::relative::RelativePublisher;
use super::report::RunReport;
use super::settings::{mode_name, ServerSettings};
use super::setup::{self, Endpoints};
use super::shared::{Frame, Shared};
use super::telemetry::TelemetryCtx;
use super::world::WorldStepper;
use flexdyn_proto::client::transport::{zenoh_config, Role};
use flexdyn_vehicle::config::log_warnings;
use flexdyn_vehicle::world::{FleetConfig, World};

/// What a fleet run did: each vehicle's report, and what the physics cost.
#[derive(Clone, Debug)]
pub struct FleetReport {
    /// Per vehicle, in fleet order: its id and its report (its own counters; the ending, the
    /// last tick and the wall time are the fleet's).
    pub vehicles: Vec<(String, RunReport)>,
    /// Frames stepped (every vehicle).
    pub frames: u64,
    /// \[ns\] wall time the physics thread spent stepping and filling the frames of every
    /// vehicle (not the waits, not the publications).
    pub physics_ns: u64,
    /// \[ns\] wall time the physics thread spent publishing every vehicle's frames.
    pub publish_ns: u64,
    /// \[ns\] wall time the physics thread spent waiting for commands (lockstep: the barrier,
    /// which holds the participants' own time and the network's).
    pub wait_ns: u64,
    /// `--record`: what the file holds.
    pub recording: Option<flexdyn_sinks::recorder::RecordReport>,
    /// Lockstep and batch: where the world's ticks went (every vehicle's frames per tick;
    /// [`super::tick_cost`]). On the fleet's line only: the vehicles' lines would repeat it.
    pub ticks: Option<super::tick_cost::TickSummary>,
}

impl FleetReport {
    /// \[ns\] physics time per vehicle and frame.
    pub fn physics_ns_per_vehicle_frame(&self) -> f64 {
        let n = (self.frames as f64) * (self.vehicles.len().max(1) as f64);
        if n == 0.0 {
            0.0
        } else {
            self.physics_ns as f64 / n
        }
    }
}

impl std::fmt::Display for FleetReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "fleet of {}: frames={} physics_us_per_vehicle_frame={:.2}",
            self.vehicles.len(),
            self.frames,
            self.physics_ns_per_vehicle_frame() * 1e-3
        )?;
        if let Some(t) = &self.ticks {
            write!(f, "{t}")?;
        }
        for (id, r) in &self.vehicles {
            write!(f, "\n  {id}: {r}")?;
        }
        Ok(())
    }
}

/// Vehicle `v`'s settings: the fleet's, with its ids and participants.
fn vehicle_settings(
    base: &ServerSettings,
    v: &flexdyn_vehicle::world::VehicleConfig,
) -> ServerSettings {
    let mut participants = v.participants.clone();
    participants.sort_unstable();
    ServerSettings {
        sc_id: v.id.clone(),
        spacecraft_id: v.spacecraft_id,
        participants,
        ..base.clone()
    }
}

/// The fleet's settings, checked: every participant of every vehicle (for the
/// `participant_subjects` check), and no option fleet mode does not have.
fn check_settings(base: &ServerSettings, fleet: &FleetConfig) -> Result<(), ServerError> {
    let mut all: Vec<u32> = fleet
        .vehicles
        .iter()
        .flat_map(|v| v.participants.iter().copied())
        .collect();
    all.sort_unstable();
    all.dedup();
    if base.mode == Mode::Lockstep && all.is_empty() {
        return Err(SettingsError::Invalid {
            name: "vehicles[].participants".into(),
            problem: "lockstep needs at least one participant in the fleet file".into(),
        }
        .into());
    }
    let union = ServerSettings {
        participants: all,
        ..base.clone()
    };
    union.validate()?;
    Ok(())
}

/// Runs the fleet server until the configured duration is reached, `shutdown` completes, or an
/// error stops it (an error about one vehicle names it: [`ServerError::Vehicle`]).
///
/// `settings` are the fleet's (mode, timeouts, pacing); each vehicle's ids and participants
/// come from `fleet`. The session is used as given and not closed.
pub async fn run(
    session: Session,
    settings: ServerSettings,
    fleet: FleetConfig,
    shutdown: impl Future<Output = ()>,
) -> Result<FleetReport, ServerError> {
    let mut shutdown = std::pin::pin!(shutdown);
    let mode = settings.mode;
    check_settings(&settings, &fleet)?;
    let vsettings: Vec<ServerSettings> = fleet
        .vehicles
        .iter()
        .map(|v| vehicle_settings(&settings, v))
        .collect();
    let mut world = World::new(&fleet)?;
    // The environment models run on their own threads, never on the physics thread.
    world.offload_environments();
    let pairs = world.relative_pairs().to_vec();
    let frame_ns = world.vehicles().first().map_or(1, |v| v.sim.frame_ns());
    let total_frames = settings.duration_frames(frame_ns)?;
    let vehicles = world.into_vehicles();
    tracing::info!(
        mode = mode_name(mode),
        zid = %session.zid(),
        vehicles = ?vehicles.iter().map(|v| v.id.as_str()).collect::<Vec<_>>(),
        "flexdyn fleet server starting"
    );
    tracing::info!("server settings: {}", settings.summary());
    flexdyn_proto::client::transport::log_listening(&session);

    // Who steps the frames: the physics thread, or (lockstep with `handoff = "direct"`, what
    // `auto` gives in lockstep) the lockstep core, in the command callback that delivers the
    // last answer of a tick, as for one spacecraft.
    let direct = mode == Mode::Lockstep && settings.direct_handoff();
    tracing::info!(
        handoff = if direct { "direct" } else { "thread" },
        "the fleet's frames are stepped and published by {}",
        if direct {
            "the Zenoh thread that delivers each tick's last answer"
        } else {
            "the physics thread"
        }
    );

    // Per vehicle: its publishers, configuration queryable, counters, status thread and
    // (lockstep) presence. Its command, fault and operator callbacks come once the world is
    // built, since the lockstep core is what they deliver to.
    let (cmd_tx, cmd_rx) = sync_channel(settings.command_queue);
    let mut parts = Vec::with_capacity(vehicles.len());
    // Per vehicle: its frame publishers, recorder view and telemetry thread's channel (the
    // outlet of whichever steps the frames), and its physics-thread channels.
    let mut outlets = Vec::with_capacity(vehicles.len());
    let mut thread_side = Vec::with_capacity(vehicles.len());
    let mut shared = Vec::with_capacity(vehicles.len());
    let mut telemetry = Vec::with_capacity(vehicles.len());
    let mut presences = Vec::new();
    // `--record`: one file for the fleet; each vehicle is described as it is declared.
    let recorder = setup::open_recorder(&settings)?;
    let record_tx = recorder.as_ref().map(|(_, tx)| tx.clone());
    // The operator's hold target and the stop flag, one for the fleet.
    let hold = Arc::new(Shared::default());
    // Real time: each frame boundary's lateness, for every vehicle's StatusMsg.
    let lateness = Arc::new(LatenessRing::default());
    for (i, (v, vs)) in vehicles.iter().zip(&vsettings).enumerate() {
        let named = |e: ServerError| named(&v.id, e);
        let topics = Topics::new(&v.id).map_err(|e| {
            named(
                SettingsError::Invalid {
                    name: "id".into(),
                    problem: e.to_string(),
                }
                .into(),
            )
        })?;
        let cfg = &fleet.vehicles[i].cfg;
        log_warnings(cfg, None);
        super::fault_log::log_configured(v.sim.faults().specs(), Some(&v.id));
        vs.check_link_faults(cfg).map_err(|e| named(e.into()))?;
        let endpoints = Endpoints::declare(&session, vs, cfg, &topics, &v.sim)
            .await
            .map_err(named)?;
        let config = setup::serve_config(&session, &topics, &endpoints.vehicle)
            .await
            .map_err(named)?;
        let recording = record_tx.as_ref().map(|tx| {
            tx.describe_vehicle(endpoints.vehicle.clone());
            endpoints
                .frames
                .recording(tx.clone(), &endpoints.status_pub)
        });
        let sh = Arc::new(Shared::new(&vs.participants));
        sh.set_run_state(RunState::Starting);
        let gate = Gate::new(
            &vs.participants,
            v.sim.spacecraft().effector_input_ranges(),
            mode == Mode::Lockstep,
        );
        let resolver = cfg
            .live_fault_resolver()
            .map_err(|source| named(ServerError::Config { file: None, source }))?;
        // The vehicle's flight-code telemetry, checked against its `[[fsw_streams]]`, recorded.
        let fsw = super::fsw::declare(
            &session,
            &topics,
            super::fsw::FswIntake::new(
                &topics,
                cfg.fsw_streams.clone(),
                vs.spacecraft_id,
                frame_ns,
                total_frames.filter(|_| mode == Mode::Lockstep),
            )
            .map_err(named)?,
            sh.clone(),
            record_tx.clone(),
        )
        .await
        .map_err(named)?;
        if mode == Mode::Lockstep {
            let presence = Presence::declare(&session, &topics, sh.clone())
                .await
                .map_err(named)?;
            presences.push((presence, endpoints.state_pub.clone(), topics.clone()));
        }
        // Live faults (physics thread): resolved on the Zenoh thread against this vehicle,
        // installed before the next frame; their boxes freed by its telemetry thread.
        let (fault_tx, fault_rx) = sync_channel(flexdyn_faults::MAX_LIVE_FAULTS);
        let (fault_recycle_tx, fault_recycle_rx) =
            sync_channel(2 * flexdyn_faults::MAX_LIVE_FAULTS);
        let (recycle_tx, recycle_rx) = sync_channel(settings.command_queue);
        let (full_tx, full_rx) = sync_channel::<Box<Frame>>(1);
        let (free_tx, _free_rx) = sync_channel::<Box<Frame>>(1);
        let ctx = TelemetryCtx {
            publisher: None,
            status_pub: endpoints.status_pub,
            full_rx,
            free_tx,
            recycle_rx,
            fault_recycle_rx,
            shared: sh.clone(),
            settings: vs.clone(),
            frame_ns,
            record: recording.clone(),
            lateness_ring: Some((lateness.clone(), 0)),
            fault_log: FaultLog::new(v.sim.faults().specs()).for_vehicle(&v.id),
        };
        telemetry.push(super::spawn_telemetry(ctx).map_err(named)?.0);
        parts.push(VehicleParts {
            topics,
            gate,
            resolver,
            fault_tx,
            config,
            fsw,
        });
        outlets.push((endpoints.frames, recording, full_tx));
        thread_side.push((recycle_tx, fault_rx, fault_recycle_tx));
        shared.push(sh);
    }
    // Each deputy's relative state, on its own key (`flexdyn/<deputy>/tlm/rel/<chief>`).
    let mut relative = Vec::with_capacity(pairs.len());
    for &(c, d) in &pairs {
        let deputy = &vehicles[d].id;
        let topics = Topics::new(deputy)
            .map_err(|e| ServerError::Internal(format!("vehicle id {deputy:?}: {e}")))?;
        let rp = RelativePublisher::declare(&session, mode, &topics, &vehicles[c].id)
            .await
            .map_err(|e| named(deputy, e))?;
        relative.push(rp);
    }

    // The world, and what steps it.
    let ids: Vec<String> = vehicles.iter().map(|v| v.id.clone()).collect();
    let mut world = WorldStepper::new(vehicles, &vsettings).with_relative_pairs(&pairs);
    let step_ns = world
        .vehicles
        .first()
        .map_or(1, |v| v.stepper.sim.step_ns());
    let (writer, mut checkpointer) = super::start_checkpoints(
        &settings,
        (super::checkpoint::FRONT_END_FLEET, "fleet"),
        (step_ns, frame_ns),
        total_frames,
    )?;
    let start_tick = settings.checkpoints.start_tick();
    let mut keep = Vec::with_capacity(parts.len());
    let mut alive = Vec::new();
    let mut lanes = Vec::new();
    if let (false, Some(r)) = (direct, &settings.checkpoints.resume) {
        super::checkpoint::restore(r, &mut world)?;
    }
    let mut engine = if direct {
        let mut core_lanes = Vec::with_capacity(outlets.len());
        for ((publisher, record, telemetry_alive), sh) in outlets.into_iter().zip(&shared) {
            core_lanes.push(CoreLane {
                publisher,
                record,
                shared: sh.clone(),
            });
            alive.push(telemetry_alive);
        }
        let events = Arc::new(Notify::new());
        let mut core = LockstepCore::new(
            world,
            core_lanes,
            relative,
            hold.clone(),
            true,
            total_frames,
            events.clone(),
        )
        .with_checkpoints(checkpointer.take());
        // Restored after the core began tick 0 on the fresh world (see `super::Wiring`).
        if let Some(r) = &settings.checkpoints.resume {
            super::checkpoint::restore(r, core.world_mut())?;
            core.resumed_at(start_tick);
        }
        Engine::Core {
            core: Arc::new(Mutex::new(core)),
            events,
        }
    } else {
        for (
            ((publisher, recording, telemetry_alive), (recycle_tx, fault_rx, fault_recycle_tx)),
            sh,
        ) in outlets.into_iter().zip(thread_side).zip(&shared)
        {
            lanes.push(Lane {
                shared: sh.clone(),
                recycle_tx,
                fault_rx,
                fault_recycle_tx,
                outlet: Outlet::InPlace {
                    publisher,
                    recording,
                    telemetry_alive,
                },
            });
        }
        Engine::Thread {
            world: Box::new(world),
            relative,
        }
    };
    let core = match &engine {
        Engine::Core { core, .. } => Some(core.clone()),
        Engine::Thread { .. } => None,
    };
    // Per vehicle: its command, fault and operator callbacks, into the physics thread's queues
    // or the core.
    let mut operators = Vec::with_capacity(parts.len());
    for (i, (p, vs)) in parts.into_iter().zip(&vsettings).enumerate() {
        let named = |e: ServerError| named(&ids[i], e);
        let sh = shared[i].clone();
        let (sink, fault_sink) = match &core {
            Some(core) => {
                let seat = VehicleCore {
                    vehicle: i,
                    core: core.clone(),
                };
                (CommandSink::Core(seat.clone()), FaultSink::Core(seat))
            }
            None => (
                CommandSink::Queue {
                    vehicle: i,
                    queue: Mutex::new((cmd_tx.clone(), p.gate)),
                },
                FaultSink::Queue(p.fault_tx),
            ),
        };
        let commands =
            intake::declare(&session, &p.topics, sink, sh.clone(), vs, record_tx.clone())
                .await
                .map_err(named)?;
        let fault_commands = super::fault_cmd::declare(
            &session,
            &p.topics,
            p.resolver,
            fault_sink,
            sh.clone(),
            vs.spacecraft_id,
            None,
        )
        .await
        .map_err(named)?;
        operators.push(
            operator::declare(
                &session,
                &p.topics,
                sh.clone(),
                mode,
                vs.spacecraft_id,
                core.clone(),
                record_tx.clone(),
                hold.clone(),
                writer
                    .as_ref()
                    .and_then(|w| w.operator_requests(&settings.checkpoints)),
            )
            .await
            .map_err(named)?,
        );
        keep.push((p.config, commands, fault_commands, p.fsw));
    }
    drop(cmd_tx);
    let _realtime = super::RealtimeHold::acquire(&settings)?;

    // Lockstep: tick 0 waits for every participant of every vehicle.
    for ((presence, state_pub, topics), (vs, id)) in
        presences.iter().zip(vsettings.iter().zip(&ids))
    {
        let ready = presence
            .wait(state_pub, vs, topics, shutdown.as_mut())
            .await
            .map_err(|e| named(id, e));
        if !matches!(ready, Ok(true)) {
            for sh in &shared {
                sh.set_run_state(if ready.is_ok() {
                    RunState::Stopped
                } else {
                    RunState::Failed
                });
            }
            drop(lanes);
            drop(alive);
            drop(engine);
            for t in telemetry {
                let _ = t.await;
            }
            drop(keep);
            drop(operators);
            drop(core);
            let recording = super::finish_recording(recorder)?;
            ready?;
            return Ok(FleetReport {
                vehicles: ids
                    .iter()
                    .zip(&shared)
                    .map(|(id, sh)| (id.clone(), RunReport::before_tick_0(mode, sh.rejected())))
                    .collect(),
                frames: 0,
                physics_ns: 0,
                publish_ns: 0,
                wait_ns: 0,
                recording,
                ticks: None,
            });
        }
    }

    let started = Instant::now();
    let outcome = match &mut engine {
        Engine::Core { core, events } => Ok(super::run_lockstep_core(
            core,
            events,
            &settings,
            &shared,
            &hold,
            shutdown.as_mut(),
        )
        .await),
        Engine::Thread { world, relative } => {
            let world = std::mem::replace(
                world.as_mut(),
                WorldStepper {
                    vehicles: Vec::new(),
                    pairs: Vec::new(),
                },
            );
            let physics = PhysicsCtx {
                settings: settings.clone(),
                total_frames,
                cmd_rx,
                lanes: std::mem::take(&mut lanes),
                control: hold.clone(),
                lateness: Some(lateness),
                relative: std::mem::take(relative),
                name_vehicles: true,
                start_tick,
                checkpoints: checkpointer.take(),
            };
            super::run_physics_thread(physics, world, &settings, &shared, shutdown.as_mut()).await
        }
    };
    let wall_s = started.elapsed().as_secs_f64();
    if let Some(w) = &writer {
        w.flush();
    }
    // The core's telemetry threads end when their channels close; the physics thread's when
    // it drops its lanes.
    drop(alive);
    drop(lanes);
    let mut lateness = Vec::with_capacity(telemetry.len());
    for t in telemetry {
        let tlm = t
            .await
            .map_err(|_| ServerError::Internal("a telemetry thread panicked".into()))?;
        lateness.push(tlm.lateness);
    }
    // Commands stop arriving; the recorder writes what it holds and closes the file.
    drop(keep);
    drop(operators);
    drop(core);
    drop(engine);
    let recording = super::finish_recording(recorder)?;
    let outcome = outcome?;
    let (physics, spent) = (outcome.result?, outcome.ticks);
    let ticks = spent.summary();
    let vehicles = ids
        .into_iter()
        .zip(&shared)
        .zip(&lateness)
        .map(|((id, sh), h)| {
            let mut r = RunReport::collect(mode, physics, sh, h, wall_s, None);
            r.checkpoints = writer.as_ref().map(|w| w.stats.summary());
            (id, r)
        })
        .collect();
    let report = FleetReport {
        vehicles,
        frames: spent.frames,
        physics_ns: spent.physics_ns,
        publish_ns: spent.publish_ns,
        wait_ns: spent.wait_ns,
        recording,
        ticks,
    };
    tracing::info!("{report}");
    Ok(report)
}

/// `e`, naming vehicle `id`.
fn named(id: &str, e: ServerError) -> ServerError {
    ServerError::Vehicle {
        vehicle: id.to_owned(),
        source: Box::new(e),
    }
}

/// What steps a fleet's frames.
enum Engine {
    /// The physics thread's frame loop ([`super::physics`]), over this world, publishing the
    /// relative states with these publishers.
    Thread {
        world: Box<WorldStepper>,
        relative: Vec<RelativePublisher>,
    },
    /// Lockstep with `handoff = "direct"`: the core, stepped in the command callbacks.
    Core {
        core: Arc<Mutex<LockstepCore>>,
        events: Arc<Notify>,
    },
}

/// One vehicle's pieces between its declaration and its callbacks'.
struct VehicleParts {
    topics: Topics,
    /// The command gate (physics thread's queue).
    gate: Gate,
    resolver: flexdyn_faults::live::LiveResolver,
    /// Live faults into the physics thread's queue.
    fault_tx: std::sync::mpsc::SyncSender<flexdyn_faults::ports::LiveRequest>,
    /// Its `flexdyn/<id>/config` queryable, kept for the run.
    config: zenoh::query::Queryable<()>,
    /// Its flight-code telemetry subscriber (`flexdyn/<id>/fsw/*`), kept for the run.
    fsw: zenoh::pubsub::Subscriber<()>,
}

/// `flexdyn run --fleet FILE`: the fleet file, the settings (the first vehicle's `[server]`
/// table and the options), a tokio runtime, the Zenoh session, SIGINT/SIGTERM.
pub fn run_from_args(args: &RunArgs, fleet_file: &Path) -> Result<FleetReport, ServerError> {
    let fleet = FleetConfig::from_file(fleet_file)?;
    let mut settings = args.settings(&fleet.vehicles[0].cfg)?;
    settings.checkpoints = super::cli::fleet_checkpoint_settings(args, fleet_file)?;
    let zcfg = zenoh_config(&args.zenoh, Role::Server)?;
    super::access::check(
        &zcfg,
        &ServerSettings {
            participants: fleet
                .vehicles
                .iter()
                .flat_map(|v| v.participants.iter().copied())
                .collect(),
            ..settings.clone()
        },
    )?;
    if let (Mode::RealTime, Some(cpu)) = (settings.mode, settings.physics_cpu) {
        super::rt::keep_off_cpu(cpu).map_err(|problem| ServerError::Realtime {
            setting: "server.physics_cpu",
            problem,
        })?;
    }
    super::cli::check_view(args)?;
    let view = args.view.clone();
    super::cli::serve(zcfg, move |session, shutdown| {
        if let Some(bind) = &view {
            super::cli::start_view(bind, &session);
        }
        run(session, settings, fleet, shutdown)
    })
}
