//! `flexdyn run`: its arguments, and the process-level wrapper around [`super::run`] (settings
//! from the file and the options, the tokio runtime, the Zenoh session, SIGINT/SIGTERM).

use std::path::PathBuf;

use super::checkpoint::{self, CheckpointSettings};
use super::error::{ServerError, SettingsError};
use super::settings::{ServerSettings, Value};
use super::RunReport;
use flexdyn_proto::client::transport::{zenoh_config, Role, ZenohArgs};
use flexdyn_vehicle::checkpoint::{CheckpointHeader, Source};
use flexdyn_vehicle::config::{load_config, log_warnings, SimConfig};

/// Arguments of `flexdyn run` (plain `flexdyn` runs with all defaults). Every server option
/// overrides the same key of the configuration's `[server]` table.
#[derive(Clone, Debug, Default, PartialEq, clap::Args)]
pub struct RunArgs {
    /// Configuration file (TOML). Default: the embedded reference spacecraft
    /// (`flexdyn print-default-config`).
    #[arg(long, value_name = "FILE", conflicts_with = "fleet")]
    pub config: Option<PathBuf>,
    /// Serve every vehicle of this fleet file (`[[vehicles]]`, docs/guides/fleets.md, "Fleet in the server"),
    /// each under its own id `flexdyn/<id>/…`, on one tick and (lockstep) one barrier. The
    /// settings are the first vehicle's `[server]` table with these options on top; ids and
    /// participants come from the fleet file.
    #[arg(long, value_name = "FLEET.toml",
          conflicts_with_all = ["sc_id", "spacecraft_id", "participants"])]
    pub fleet: Option<PathBuf>,
    /// Pacing mode [default: realtime].
    #[arg(long, value_parser = ["realtime", "lockstep", "batch"])]
    pub mode: Option<String>,
    /// Lockstep participants / accepted command senders (sender ids, comma-separated)
    /// [default: 1].
    #[arg(
        long,
        value_name = "ID,...",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub participants: Option<Vec<i64>>,
    /// Lockstep: seconds to wait for each participant's answer to a tick [default: 10].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub participant_timeout_s: Option<f64>,
    /// Lockstep: seconds to wait before tick 0 for every participant [default: 30].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub presence_timeout_s: Option<f64>,
    /// String spacecraft id in the key expressions flexdyn/ID/... [default: sc1].
    #[arg(long, value_name = "ID")]
    pub sc_id: Option<String>,
    /// Numeric spacecraft id in every message header [default: 1].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub spacecraft_id: Option<i64>,
    /// Simulated duration in seconds, a whole number of frames [default: run until stopped].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration_s: Option<f64>,
    /// Real time: overrun policy [default: catch_up].
    #[arg(long, value_parser = ["catch_up", "skip", "abort"])]
    pub overrun_policy: Option<String>,
    /// Real time, abort policy: consecutive overruns tolerated [default: 10].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub overrun_limit: Option<i64>,
    /// A command older than this (simulation seconds) is stale [default: 0.1].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub stale_after_s: Option<f64>,
    /// Stale-command policy [default: hold].
    #[arg(long, value_parser = ["hold", "zero"])]
    pub stale_policy: Option<String>,
    /// StatusMsg rate in Hz [default: 10].
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub status_hz: Option<f64>,
    /// Seconds between timing summaries in the log [default: 10].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub summary_interval_s: Option<f64>,
    /// Real time: spin this many µs before each deadline instead of sleeping [default: 200].
    #[arg(long, value_name = "US", allow_negative_numbers = true)]
    pub spin_us: Option<i64>,
    /// Real time: SCHED_FIFO priority 1–99 for the physics thread, 0 = normal; needs
    /// CAP_SYS_NICE or `ulimit -r`, else the run does not start [default: 0].
    #[arg(long, value_name = "P", allow_negative_numbers = true)]
    pub realtime_priority: Option<i64>,
    /// Real time: lock the process's memory (mlockall) and pre-fault the physics thread's
    /// stack; needs CAP_IPC_LOCK or `ulimit -l` above the process size, else the run does not
    /// start [default: false].
    #[arg(long, value_name = "BOOL", num_args = 0..=1, default_missing_value = "true")]
    pub lock_memory: Option<bool>,
    /// Real time: run the physics thread alone on this CPU and every other thread on the
    /// others; -1 = no pinning [default: -1].
    #[arg(long, value_name = "CPU", allow_negative_numbers = true)]
    pub physics_cpu: Option<i64>,
    /// Real time: hold /dev/cpu_dma_latency at 0 µs while running (no deep CPU idle states);
    /// needs write access to the device, else the run does not start [default: false].
    #[arg(long, value_name = "BOOL", num_args = 0..=1, default_missing_value = "true")]
    pub cpu_dma_latency: Option<bool>,
    /// Preallocated telemetry buffers [default: 64].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub telemetry_buffers: Option<i64>,
    /// Command queue capacity [default: 1024].
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub command_queue: Option<i64>,
    /// Which thread publishes the frames: `direct` (the thread that finishes the frame),
    /// `thread` (a telemetry thread) or `auto` (direct, but thread in real time with --record)
    /// [default: auto].
    #[arg(long, value_parser = ["auto", "direct", "thread"])]
    pub handoff: Option<String>,
    /// Bind each participant's sender id to an authenticated Zenoh user name, e.g. `1=fsw`
    /// (comma-separated) [default: none].
    #[arg(long, value_name = "ID=USER,...", value_delimiter = ',')]
    pub participant_subjects: Option<Vec<String>>,
    /// Real time: simulated seconds per wall-clock second, e.g. 2 (twice as fast) or 0.5
    /// [default: 1].
    #[arg(long, value_name = "X", allow_negative_numbers = true)]
    pub speed: Option<f64>,
    /// Record the server's output (state, sensors, status, commands received) to this MCAP
    /// file. Lockstep and batch record every sample; real time drops (and counts) what the
    /// recorder cannot keep up with rather than delay the frame.
    #[arg(long, value_name = "FILE.mcap")]
    pub record: Option<PathBuf>,
    /// Also serve the live view of this run on HOST:PORT: the web page for a browser and the
    /// Foxglove protocol, as `flexdyn view` beside the server would (in this process, on its
    /// own thread and Zenoh session, connected to the server like any tool) [default without a
    /// value: 127.0.0.1:8765].
    #[arg(
        long,
        value_name = "HOST:PORT",
        num_args = 0..=1,
        default_missing_value = flexdyn_sinks::view::DEFAULT_BIND
    )]
    pub view: Option<String>,
    /// Save a checkpoint of the run at this tick (a frame boundary after the first) to
    /// `--checkpoint`; the run goes on (docs/guides/checkpoints.md).
    #[arg(
        long,
        value_name = "TICK",
        requires = "checkpoint",
        conflicts_with = "fleet"
    )]
    pub checkpoint_at_tick: Option<u64>,
    /// The file `--checkpoint-at-tick` writes.
    #[arg(long, value_name = "FILE", requires = "checkpoint_at_tick")]
    pub checkpoint: Option<PathBuf>,
    /// Where an operator's checkpoint requests (OperatorMsg `Checkpoint`) are written, as
    /// `<sc_id>-tick<k>.ckpt` (a fleet's: `fleet-tick<k>.ckpt`); without it they are refused.
    #[arg(long, value_name = "DIR")]
    pub checkpoint_dir: Option<PathBuf>,
    /// Resume from a checkpoint of `flexdyn run` (of `flexdyn run --fleet` with `--fleet`): the
    /// stream from its tick on is the uninterrupted run's, bit for bit (lockstep); with
    /// `--config` another configuration than the one it was taken with, a fork (with `--fleet`,
    /// a fleet file that differs). `--duration-s` still counts from t = 0.
    #[arg(long, value_name = "FILE")]
    pub resume: Option<PathBuf>,
    /// Zenoh endpoints and configuration file.
    #[command(flatten)]
    pub zenoh: ZenohArgs,
}

impl RunArgs {
    /// The command-line overrides as `(key, value)` pairs, in [`super::settings::KEYS`] order.
    fn overrides(&self) -> Vec<(&'static str, Value)> {
        let mut out = Vec::new();
        let s = |v: &Option<String>| v.clone().map(Value::Str);
        let f = |v: &Option<f64>| v.map(Value::Float);
        let i = |v: &Option<i64>| v.map(Value::Int);
        let subjects = self.participant_subjects.as_ref().map(|v| {
            Value::Strings(
                v.iter()
                    .map(|p| match p.split_once('=') {
                        Some((id, user)) => (id.to_owned(), user.to_owned()),
                        None => (p.clone(), String::new()),
                    })
                    .collect(),
            )
        });
        let b = |v: &Option<bool>| v.map(Value::Bool);
        let pairs: [(&'static str, Option<Value>); 23] = [
            ("mode", s(&self.mode)),
            ("sc_id", s(&self.sc_id)),
            ("spacecraft_id", i(&self.spacecraft_id)),
            ("participants", self.participants.clone().map(Value::Ints)),
            ("participant_timeout_s", f(&self.participant_timeout_s)),
            ("presence_timeout_s", f(&self.presence_timeout_s)),
            ("duration_s", f(&self.duration_s)),
            ("overrun_policy", s(&self.overrun_policy)),
            ("overrun_limit", i(&self.overrun_limit)),
            ("stale_after_s", f(&self.stale_after_s)),
            ("stale_policy", s(&self.stale_policy)),
            ("status_hz", f(&self.status_hz)),
            ("summary_interval_s", f(&self.summary_interval_s)),
            ("spin_us", i(&self.spin_us)),
            ("realtime_priority", i(&self.realtime_priority)),
            ("lock_memory", b(&self.lock_memory)),
            ("physics_cpu", i(&self.physics_cpu)),
            ("cpu_dma_latency", b(&self.cpu_dma_latency)),
            ("telemetry_buffers", i(&self.telemetry_buffers)),
            ("command_queue", i(&self.command_queue)),
            ("handoff", s(&self.handoff)),
            ("participant_subjects", subjects),
            ("speed", f(&self.speed)),
        ];
        for (k, v) in pairs {
            if let Some(v) = v {
                out.push((k, v));
            }
        }
        out
    }

    /// The settings of `cfg`'s `[server]` table with these options applied on top
    /// ([`ServerSettings::resolve`]).
    pub fn settings(&self, cfg: &SimConfig) -> Result<ServerSettings, SettingsError> {
        let mut settings = ServerSettings::resolve(cfg, self.config.as_deref(), &self.overrides())?;
        settings.record.clone_from(&self.record);
        Ok(settings)
    }
}

/// [`flexdyn_sinks::signals::shutdown_signal`], its failure as a [`ServerError::Signal`].
async fn shutdown_signal() -> Result<impl std::future::Future<Output = ()>, ServerError> {
    flexdyn_sinks::signals::shutdown_signal()
        .await
        .map_err(|(signal, source)| ServerError::Signal { signal, source })
}

/// `flexdyn run`: builds the settings and the Zenoh configuration, starts a tokio runtime, opens
/// the session, runs the server until the duration, a signal or an error, and closes the
/// session (which flushes the last samples).
pub fn run_from_args(args: &RunArgs) -> Result<RunReport, ServerError> {
    let file = args.config.as_deref();
    let (cfg, checkpoints) = checkpoint_settings(args)?;
    log_warnings(&cfg, file);
    let mut settings = args.settings(&cfg)?;
    settings.checkpoints = checkpoints;
    let zcfg = zenoh_config(&args.zenoh, Role::Server)?;
    super::access::check(&zcfg, &settings)?;
    // Every thread started from here on (tokio's, Zenoh's, the server's) inherits this thread's
    // CPU mask: off the physics thread's CPU.
    if let (flexdyn_proto::Mode::RealTime, Some(cpu)) = (settings.mode, settings.physics_cpu) {
        super::rt::keep_off_cpu(cpu).map_err(|problem| ServerError::Realtime {
            setting: "server.physics_cpu",
            problem,
        })?;
    }
    check_view(args)?;
    let view = args.view.clone();
    serve(zcfg, move |session, shutdown| {
        if let Some(bind) = &view {
            start_view(bind, &session);
        }
        super::run(session, settings, cfg, shutdown)
    })
}

/// The configuration to run and the checkpoint settings: a resumed run's configuration is the
/// one its checkpoint records, unless `--config` names another (a fork).
fn checkpoint_settings(args: &RunArgs) -> Result<(SimConfig, CheckpointSettings), ServerError> {
    let file = args.config.as_deref();
    let config_error = |file: Option<PathBuf>| {
        move |source| ServerError::Config {
            file: file.clone(),
            source,
        }
    };
    let resumed = resumed(args, checkpoint::FRONT_END)?;
    let source = match (&resumed, file) {
        (Some((_, header)), None) => Source::recorded(header),
        (Some(_), Some(_)) => Source::of(file).map_err(config_error(args.config.clone()))?,
        (None, _) if saves(args) => Source::of(file).map_err(config_error(args.config.clone()))?,
        (None, _) => Source::default(),
    };
    let cfg = match (&resumed, file) {
        (Some(_), None) => source.config().map_err(config_error(source.file()))?,
        _ => load_config(file).map_err(config_error(args.config.clone()))?,
    };
    Ok((cfg, with_source(args, resumed, source)))
}

/// The checkpoint settings of a fleet server (`--fleet FILE`): its checkpoints record the fleet
/// file; a fleet file that differs from the one a resumed checkpoint recorded is a fork.
pub(super) fn fleet_checkpoint_settings(
    args: &RunArgs,
    fleet_file: &std::path::Path,
) -> Result<CheckpointSettings, ServerError> {
    let resumed = resumed(args, checkpoint::FRONT_END_FLEET)?;
    let source = if resumed.is_some() || saves(args) {
        Source::of(Some(fleet_file)).map_err(|source| ServerError::Config {
            file: Some(fleet_file.to_path_buf()),
            source,
        })?
    } else {
        Source::default()
    };
    Ok(with_source(args, resumed, source))
}

/// `--resume`'s checkpoint, read and checked for `front_end`, with its header.
fn resumed(
    args: &RunArgs,
    front_end: &str,
) -> Result<Option<(checkpoint::Resumed, CheckpointHeader)>, ServerError> {
    args.resume
        .as_deref()
        .map(|f| checkpoint::read(f, front_end))
        .transpose()
}

/// Whether the run may save a checkpoint (`--checkpoint-at-tick` or `--checkpoint-dir`).
fn saves(args: &RunArgs) -> bool {
    args.checkpoint_at_tick.is_some() || args.checkpoint_dir.is_some()
}

/// The checkpoint settings of `args` for a run of configuration `source`; a resume whose
/// configuration differs from the checkpoint's is logged as a fork.
fn with_source(
    args: &RunArgs,
    resumed: Option<(checkpoint::Resumed, CheckpointHeader)>,
    source: Source,
) -> CheckpointSettings {
    if let Some((r, header)) = &resumed {
        if CheckpointHeader::digest(&source.text) != header.source_sha256 {
            tracing::warn!(
                checkpoint = %r.file.display(),
                "resuming with a configuration that differs from the one it was taken with: a fork"
            );
        }
    }
    CheckpointSettings {
        save_at: args.checkpoint_at_tick.zip(args.checkpoint.clone()),
        dir: args.checkpoint_dir.clone(),
        source,
        resume: resumed.map(|(r, _)| r),
    }
}

/// `--view` connects to the server as a tool with the default configuration: with a Zenoh
/// configuration file (a lab network's credentials and access rules) it could not, so it is
/// refused rather than left unable to see anything.
pub(super) fn check_view(args: &RunArgs) -> Result<(), ServerError> {
    if let (Some(_), Some(file)) = (&args.view, &args.zenoh.zenoh_config) {
        return Err(SettingsError::Invalid {
            name: "--view".into(),
            problem: format!(
                "the in-process view connects without a Zenoh configuration file, and this \
                 server uses {}: run `flexdyn view --zenoh-config <a tool's file>` beside it \
                 instead",
                file.display()
            ),
        }
        .into());
    }
    Ok(())
}

/// Starts `--view`'s viewer ([`flexdyn_sinks::view::view`]) on its own thread with its own
/// Zenoh session, connected to the endpoints `session` listens on: the server's threads publish
/// to it over loopback as to any subscriber, so viewing costs the physics thread nothing. It
/// runs until the process ends or a signal; an error (the port is taken) is logged, and the run
/// goes on.
pub(super) fn start_view(bind: &str, session: &zenoh::Session) {
    let args = flexdyn_sinks::view::ViewArgs {
        bind: bind.to_owned(),
        sc_id: Vec::new(),
        file: None,
        backlog: 4096,
        duration_s: None,
        zenoh: ZenohArgs {
            connect: flexdyn_proto::client::transport::listening_on(session),
            ..ZenohArgs::default()
        },
    };
    let spawned = std::thread::Builder::new()
        .name("flexdyn-view".into())
        .spawn(move || {
            if let Err(e) = flexdyn_sinks::view::view(&args) {
                tracing::error!("--view: {e}");
            }
        });
    if let Err(e) = spawned {
        tracing::error!("--view: cannot start its thread: {e}");
    }
}

/// Starts the server's tokio runtime, opens the Zenoh session, runs `run(session, shutdown on
/// SIGINT/SIGTERM)` and closes the session (which flushes the last samples).
pub(super) fn serve<R, F, Fut>(zcfg: zenoh::Config, run: F) -> Result<R, ServerError>
where
    F: FnOnce(
        zenoh::Session,
        std::pin::Pin<Box<dyn std::future::Future<Output = ()> + Send>>,
    ) -> Fut,
    Fut: std::future::Future<Output = Result<R, ServerError>>,
{
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .thread_name("flexdyn-io")
        .build()
        .map_err(|e| ServerError::Internal(format!("cannot start the tokio runtime: {e}")))?;
    runtime.block_on(async move {
        let shutdown = Box::pin(shutdown_signal().await?);
        let session = zenoh::open(zcfg)
            .await
            .map_err(|e| ServerError::zenoh("open the session", e))?;
        let result = run(session.clone(), shutdown).await;
        if let Err(e) = session.close().await {
            tracing::warn!(error = %e, "closing the Zenoh session failed");
        }
        result
    })
}
