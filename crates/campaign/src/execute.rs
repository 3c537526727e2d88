//! `flexdyn campaign run`: each run is a lockstep server on its own loopback port, an observer
//! participant in this process (sender id [`OBSERVER_ID`], answering `NoCommand`, so it sees
//! every tick from 0), and the flight code as a child process (sender id 1), when the campaign
//! has a `controller`. Open-loop runs have the observer only. In a campaign with `start_from`
//! ([`super::fork`]) the server resumes the checkpoint, and everything below (the hash, the
//! states, the criteria) starts at its tick.
//!
//! A run writes `run-NNNN/result.json`: the parameters read back from its built model, its
//! seeds, the SHA-256 over its StateMsg payloads in tick order, the criteria, each fault's first
//! activation as the server published it (the observer subscribes to the fault events too), the
//! exit status of the server and the controller, and the wall time; with `--record`,
//! `run-NNNN/recording.mcap`.
//! A controller that exits before the end stops the run at once, which fails with its status.
//!
//! Each run comes to an [`Outcome`]: `passed`, `failed` (it ran and the flight code did not meet
//! the campaign: a criterion, an early controller exit, a participant timeout, a non-finite
//! state) or `not_run` (no valid draw, the controller could not be started or never joined, the
//! server or the observer could not start): the campaign's exit code counts them
//! ([`super::verdict`]).
//!
//! Over a fleet (`fleet` in the campaign file), a run is the fleet server
//! ([`flexdyn_server::fleet::run`], what `flexdyn run --fleet` runs) with the run's fleet: the
//! observer answers every vehicle's ticks as sender 9 (added to each vehicle's participants),
//! and each `[[controllers]]` entry is a process with its own sender id and its log
//! `controller-<vehicle>-<sender>.log`. `result.json` then holds a hash per vehicle
//! (`vehicle_state_sha256`, by id; `state_sha256` is empty) and each controller's exit status
//! (`controller_exits`, by `<vehicle>/<sender>`); `applied` keys start with the vehicle's id.
//! A `range` criterion reads the deputy's RelativeStateMsg stream, recorded by the observer.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use flexdyn_proto::{decode_state, encode, CommandMsg, FswMsg, Header, Mode, StateMsg, Topics};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

use super::command::split_command;
use super::plan::{readback, Plan, RunPlan};
use super::readback::fleet_readback;
use super::spec::Campaign;
pub use super::spec::OBSERVER_ID;
use super::verdict::Outcome;
use flexdyn_proto::client::transport::{declared_key, zenoh_config, Role, ZenohArgs};
use flexdyn_server::{ServerError, ServerSettings};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::world::FleetConfig;
/// The flight code's sender id (`{sender_id}`).
pub const CONTROLLER_ID: u32 = 1;
/// The spacecraft id of every run (`{sc_id}`); runs are separated by port.
pub const SC_ID: &str = "sc1";

/// A run's recording, in its folder.
pub const RECORDING: &str = "recording.mcap";

/// How long after a controller exits 0 the server may still take to end by itself: a
/// controller that stops on the end-of-run status exits while the server closes its session.
const EXIT_GRACE: Duration = Duration::from_secs(2);

pub use super::judge::CriterionResult;
use super::judge::{evaluate, evaluate_fsw, reduce, relative_series};

/// What one run did (`run-NNNN/result.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    /// Index.
    pub run: u32,
    /// The run's seed and its sensors' seeds.
    pub run_seed: u64,
    /// Sensor seeds by key.
    pub sensor_seeds: BTreeMap<String, u64>,
    /// Draws rejected before the accepted one.
    pub redraws: u32,
    /// Dispersed parameters as read back from the built model, by key.
    pub applied: BTreeMap<String, f64>,
    /// SHA-256 over the StateMsg payloads, ticks `start_tick`..=N in order (empty if the run
    /// failed, and over a fleet).
    pub state_sha256: String,
    /// The first tick observed, hashed and judged: the checkpoint's in a campaign that starts
    /// every run from one (`start_from`), else 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub start_tick: u64,
    /// SHA-256 (hex) of the checkpoint file this run started from (`start_from`), as the run
    /// read it; empty for a run from t = 0. `summarize` flags a run whose checkpoint is not the
    /// manifest's.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub start_from_sha256: String,
    /// Over a fleet: the SHA-256 over each vehicle's StateMsg payloads, ticks 0..=N in order,
    /// by vehicle id (empty if the run failed).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub vehicle_state_sha256: BTreeMap<String, String>,
    /// States received (over a fleet: of each vehicle).
    pub states: u64,
    /// \[ns\] each fault's first activation as the run published it (the `edge_ns` of its
    /// first FaultEventMsg with `active`), by `faults[k]` (over a fleet `<vehicle>.faults[k]`);
    /// a fault that never activated is absent.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub fault_activations_ns: BTreeMap<String, u64>,
    /// Criteria.
    pub criteria: Vec<CriterionResult>,
    /// Every criterion passed and the run completed (`outcome` is `passed`).
    pub passed: bool,
    /// `passed`, `failed` (it ran, and the flight code did not meet the campaign) or
    /// `not_run` (it could not be run): what the campaign's exit code counts.
    pub outcome: Outcome,
    /// `ok`, or why the run failed (server error, controller exit, invalid draw).
    pub status: String,
    /// The controller's exit status (`exit 0`, `exit 3`, `signal 9`, `still running: stopped`).
    pub controller_exit: Option<String>,
    /// Over a fleet: each controller's exit status, by `<vehicle>/<sender_id>`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub controller_exits: BTreeMap<String, String>,
    /// \[s\] wall time of the run.
    pub wall_s: f64,
    /// \[s\] simulated time reached.
    pub sim_s: f64,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

impl RunResult {
    /// Planned run `rp` before it ran (or when it could not run): its seeds and redraws, no
    /// results, outcome `not_run`, `status`.
    pub fn not_run(rp: &RunPlan, status: String) -> Self {
        Self {
            run: rp.run,
            run_seed: rp.run_seed,
            sensor_seeds: rp.sensor_seeds.clone(),
            redraws: rp.redraws,
            applied: BTreeMap::new(),
            state_sha256: String::new(),
            start_tick: 0,
            start_from_sha256: String::new(),
            vehicle_state_sha256: BTreeMap::new(),
            states: 0,
            fault_activations_ns: BTreeMap::new(),
            criteria: Vec::new(),
            passed: false,
            outcome: Outcome::NotRun,
            status,
            controller_exit: None,
            controller_exits: BTreeMap::new(),
            wall_s: 0.0,
            sim_s: 0.0,
        }
    }
}

/// Options of `campaign run`.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Output directory (the plan's).
    pub dir: PathBuf,
    /// First port; run i uses `base_port + i`. 0: each run takes a free port from the OS.
    pub base_port: u16,
    /// Record each run to `run-NNNN/recording.mcap`.
    pub record: bool,
}

/// Every (tick, StateMsg payload) the observer received.
pub type Received = Arc<Mutex<Vec<(u64, Vec<u8>)>>>;

/// A passive lockstep participant: records every state payload and answers it with
/// `NoCommand` as its sender id, so it sees every tick from 0, and records every fault event.
/// Also the tests' recorder.
pub struct Observer {
    /// Every (tick, payload) received, in arrival order.
    pub states: Received,
    /// Every (tick, FaultEventMsg payload) received, in arrival order (the server publishes a
    /// tick's events after its state, before it waits for the answers).
    pub faults: Received,
    /// Every (tick, RelativeStateMsg payload) of each key given to
    /// [`Self::start_with_relative`], in arrival order.
    pub relative: Vec<Received>,
    _sub: zenoh::pubsub::Subscriber<()>,
    _fault_sub: zenoh::pubsub::Subscriber<()>,
    _relative_subs: Vec<zenoh::pubsub::Subscriber<()>>,
    _token: zenoh::liveliness::LivelinessToken,
    session: Session,
}

fn zenoh_args(endpoint: &str, listen: bool) -> ZenohArgs {
    let ep = endpoint.to_owned();
    ZenohArgs {
        listen: if listen { vec![ep.clone()] } else { vec![] },
        connect: if listen { vec![] } else { vec![ep] },
        zenoh_config: None,
    }
}

impl Observer {
    /// Connects to the server at `endpoint` and declares `sender_id`'s liveliness token.
    pub fn start(endpoint: &str, topics: &Topics, sender_id: u32) -> Result<Self, String> {
        Self::start_with_relative(endpoint, topics, sender_id, &[])
    }

    /// [`Self::start`], recording the relative-state keys `relative` too (subscribed before
    /// the token is declared, so from tick 0).
    pub fn start_with_relative(
        endpoint: &str,
        topics: &Topics,
        sender_id: u32,
        relative: &[String],
    ) -> Result<Self, String> {
        let cfg =
            zenoh_config(&zenoh_args(endpoint, false), Role::Tool).map_err(|e| e.to_string())?;
        let session = zenoh::open(cfg)
            .wait()
            .map_err(|e| format!("observer session: {e}"))?;
        let declared = declared_key(&session, topics.cmd(sender_id))
            .map_err(|e| format!("observer publisher: {e}"))?;
        let publisher = session
            .declare_publisher(declared)
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(|e| format!("observer publisher: {e}"))?;
        let states: Received = Arc::default();
        let rec = states.clone();
        let mut seq = 0u64;
        let sub = session
            .declare_subscriber(topics.state().to_owned())
            .callback_mut(move |sample| {
                let bytes = sample.payload().to_bytes().into_owned();
                let Ok(state) = decode_state(&bytes) else {
                    return;
                };
                let h = state.header;
                rec.lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push((h.tick, bytes));
                let cmd = CommandMsg::no_command(
                    Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, seq),
                    sender_id,
                );
                seq += 1;
                let _ = publisher.put(encode(&cmd)).wait();
            })
            .wait()
            .map_err(|e| format!("observer subscriber: {e}"))?;
        let (faults, fault_sub) = record_key(&session, topics.fault_events(), |b| {
            flexdyn_proto::decode_fault_event(b)
                .ok()
                .map(|m| m.header.tick)
        })?;
        let mut relative_states = Vec::with_capacity(relative.len());
        let mut relative_subs = Vec::with_capacity(relative.len());
        for key in relative {
            let (received, sub) = record_key(&session, key.clone(), |b| {
                flexdyn_proto::decode_relative_state(b)
                    .ok()
                    .map(|m| m.header.tick)
            })?;
            relative_states.push(received);
            relative_subs.push(sub);
        }
        let token = session
            .liveliness()
            .declare_token(topics.participant(sender_id))
            .wait()
            .map_err(|e| format!("observer token: {e}"))?;
        Ok(Self {
            states,
            faults,
            relative: relative_states,
            _sub: sub,
            _fault_sub: fault_sub,
            _relative_subs: relative_subs,
            _token: token,
            session,
        })
    }
}

/// A subscriber on `key` that records (tick, payload) of every sample `tick_of` decodes.
fn record_key(
    session: &Session,
    key: String,
    tick_of: fn(&[u8]) -> Option<u64>,
) -> Result<(Received, zenoh::pubsub::Subscriber<()>), String> {
    let received: Received = Arc::default();
    let rec = received.clone();
    let sub = session
        .declare_subscriber(key.clone())
        .callback(move |sample| {
            let bytes = sample.payload().to_bytes().into_owned();
            if let Some(tick) = tick_of(&bytes) {
                rec.lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push((tick, bytes));
            }
        })
        .wait()
        .map_err(|e| format!("observer subscriber {key}: {e}"))?;
    Ok((received, sub))
}

fn exit_text(s: std::process::ExitStatus) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(sig) = s.signal() {
            return format!("signal {sig}");
        }
    }
    s.code().map_or("unknown".into(), |c| format!("exit {c}"))
}

/// Runs one planned run and writes its `result.json`.
pub fn execute(plan: &Plan, rp: &RunPlan, opts: &RunOptions) -> RunResult {
    let started = Instant::now();
    let c = &plan.campaign;
    let run_dir = opts.dir.join(&rp.dir);
    let _ = std::fs::create_dir_all(&run_dir);
    let mut result = RunResult::not_run(rp, String::new());
    (result.status, result.outcome) = match run_inner(c, rp, opts, &run_dir, &mut result) {
        Ok(()) if result.criteria.iter().all(|k| k.passed) => ("ok".into(), Outcome::Passed),
        Ok(()) => ("ok".into(), Outcome::Failed),
        Err(e) => (e.message, e.outcome),
    };
    result.passed = result.outcome == Outcome::Passed;
    result.wall_s = started.elapsed().as_secs_f64();
    if let Ok(text) = serde_json::to_string_pretty(&result) {
        let _ = std::fs::write(run_dir.join("result.json"), text + "\n");
    }
    result
}

/// Why a run did not complete, and whether it ran (see [`Outcome`]).
struct RunFailure {
    outcome: Outcome,
    message: String,
}

/// Anything that stops a run before the flight code was judged: it could not be run.
impl From<String> for RunFailure {
    fn from(message: String) -> Self {
        RunFailure {
            outcome: Outcome::NotRun,
            message,
        }
    }
}

/// A server error as a run's failure: the flight code stopping to answer, or a state that
/// became non-finite, is a verdict on the run; anything else means it could not be run.
fn server_failure(e: ServerError) -> RunFailure {
    let outcome = match e {
        ServerError::ParticipantTimeout { .. } | ServerError::NonFinite { .. } => Outcome::Failed,
        ServerError::Vehicle { ref source, .. }
            if matches!(
                **source,
                ServerError::ParticipantTimeout { .. } | ServerError::NonFinite { .. }
            ) =>
        {
            Outcome::Failed
        }
        _ => Outcome::NotRun,
    };
    RunFailure {
        outcome,
        message: e.to_string(),
    }
}

/// A flight-code process of a run.
struct Launch {
    /// Its command line, every `{…}` but `{endpoint}` substituted.
    line: String,
    /// Its log file (stdout and stderr) in the run's folder.
    log: String,
    /// How a failure names it (`the controller`).
    who: String,
}

/// `line` with `{sc_id}`, `{sender_id}` and `{run}` substituted (and `{vehicle}`, over a
/// fleet); `{endpoint}` is substituted once the server listens.
fn substitute(line: &str, sc_id: &str, sender_id: u32, run: u32, vehicle: Option<&str>) -> String {
    let line = line
        .replace("{sc_id}", sc_id)
        .replace("{sender_id}", &sender_id.to_string())
        .replace("{run}", &run.to_string());
    match vehicle {
        Some(v) => line.replace("{vehicle}", v),
        None => line,
    }
}

/// Starts the controller `l` with the server's `endpoint`, its output to its log.
fn start_controller(l: &Launch, endpoint: &str, run_dir: &Path) -> Result<Child, String> {
    let line = l.line.replace("{endpoint}", endpoint);
    let words = split_command(&line)?;
    let program = words
        .first()
        .ok_or("the controller's command line is empty")?;
    let log = std::fs::File::create(run_dir.join(&l.log)).map_err(|e| e.to_string())?;
    let err = log.try_clone().map_err(|e| e.to_string())?;
    Command::new(program)
        .args(&words[1..])
        .stdin(Stdio::null())
        .stdout(log)
        .stderr(err)
        .spawn()
        .map_err(|e| format!("cannot start the controller {program:?}: {e}"))
}

/// The lockstep server of a run: one spacecraft, or a fleet.
enum Server {
    Single(ServerSettings, Box<SimConfig>),
    Fleet(ServerSettings, Box<FleetConfig>),
}

/// (tick, payload) for ticks 0..=N in order.
type Stream = Vec<(u64, Vec<u8>)>;

/// What the observer saw of a completed run.
struct Observed {
    /// Per observed vehicle, its StateMsg stream.
    states: Vec<Stream>,
    /// Per observed vehicle, the stream of each relative-state key it records.
    relative: Vec<Vec<Stream>>,
    /// Per observed vehicle, its fault events (tick order; a tick's in publication order).
    faults: Vec<Stream>,
    /// \[ns\] simulated time reached.
    sim_time_ns: u64,
}

/// The port run `run` listens on (0: one from the OS).
fn run_port(opts: &RunOptions, run: u32) -> Result<u16, String> {
    match opts.base_port {
        0 => Ok(0),
        base => {
            let port = u32::from(base) + run;
            u16::try_from(port)
                .map_err(|_| format!("port {port} is out of range: lower --base-port"))
        }
    }
}

/// The settings of a one-spacecraft run's server, without its recording: lockstep, spacecraft
/// [`SC_ID`], the observer and (with a controller) the flight code as participants. A
/// campaign's checkpoint must fit these ([`super::fork`]).
pub fn single_settings(c: &Campaign) -> ServerSettings {
    let mut participants = vec![OBSERVER_ID];
    if c.controller.is_some() {
        participants.insert(0, CONTROLLER_ID);
    }
    ServerSettings {
        sc_id: SC_ID.into(),
        participants,
        ..shared_settings(c)
    }
}

/// The lockstep settings every run shares, without a recording.
fn shared_settings(c: &Campaign) -> ServerSettings {
    ServerSettings {
        mode: Mode::Lockstep,
        participant_timeout: Duration::from_secs_f64(c.participant_timeout_s),
        presence_timeout: Duration::from_secs_f64(c.participant_timeout_s.max(10.0)),
        duration_ns: Some(c.duration_ns),
        summary_interval: Duration::from_secs(3600),
        ..ServerSettings::default()
    }
}

/// The lockstep settings every run shares (a single spacecraft adds its ids and participants).
fn lockstep_settings(c: &Campaign, opts: &RunOptions, run_dir: &Path) -> ServerSettings {
    ServerSettings {
        // The flight code's telemetry is judged from the recording (the observer, a peer of the
        // server, does not hear the controller's samples).
        record: (opts.record || c.criteria.iter().any(|k| k.fsw.is_some()))
            .then(|| run_dir.join(RECORDING)),
        ..shared_settings(c)
    }
}

/// SHA-256 (hex) over the payloads, in order.
fn sha256_hex(states: &[(u64, Vec<u8>)]) -> String {
    let mut h = Sha256::new();
    for (_, p) in states {
        h.update(p);
    }
    hex(&h.finalize())
}

/// Lower-case hex of `bytes` (a digest, as the manifest and results write it).
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// `r`'s samples, sorted by tick.
fn sorted(r: &Received) -> Vec<(u64, Vec<u8>)> {
    let mut s = r.lock().unwrap_or_else(|e| e.into_inner()).clone();
    s.sort_by_key(|(t, _)| *t);
    s
}

/// Whether `s` holds ticks `first`..=`last` exactly once each, in order.
fn complete(s: &[(u64, Vec<u8>)], first: u64, last: u64) -> bool {
    last >= first
        && s.len() as u64 == last - first + 1
        && s.iter()
            .enumerate()
            .all(|(i, (t, _))| *t == first + i as u64)
}

fn close(observers: &[Observer]) {
    for o in observers {
        let _ = o.session.close().wait();
    }
}

/// Runs `server` to its end in lockstep with an observer per vehicle of `observe` (its id and
/// the relative-state keys to record) and the `controllers`; each controller's exit status is
/// pushed to `exits`, in order, whatever the outcome. A controller that exits before the end
/// stops the run at once. The server starts at `first_tick` (a resumed checkpoint's, else 0):
/// the observer must see every tick from it to the end.
fn run_lockstep(
    server: Server,
    first_tick: u64,
    observe: &[(String, Vec<String>)],
    controllers: &[Launch],
    port: u16,
    run_dir: &Path,
    exits: &mut Vec<String>,
) -> Result<Observed, RunFailure> {
    let topics = observe
        .iter()
        .map(|(id, _)| Topics::new(id).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    // The server, on its own runtime and thread; `stop` ends it early (controller exit).
    let stop = Arc::new(tokio::sync::Notify::new());
    let zcfg = zenoh_config(
        &zenoh_args(&format!("tcp/127.0.0.1:{port}"), true),
        Role::Server,
    )
    .map_err(|e| e.to_string())?;
    // Opened here, so the observer and the controller get the endpoint it really listens on.
    let session = zenoh::open(zcfg)
        .wait()
        .map_err(|e| format!("server session: {e}"))?;
    let endpoint = flexdyn_proto::client::transport::listening_on(&session)
        .into_iter()
        .next()
        .ok_or_else(|| "the server session listens nowhere".to_owned())?;
    let stop2 = stop.clone();
    let server = std::thread::spawn(move || {
        let rt = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()
            .map_err(|e| e.to_string())?;
        rt.block_on(async move {
            let stopped = async move { stop2.notified().await };
            // (last tick, simulated time): a fleet's are every vehicle's.
            let r = match server {
                Server::Single(settings, cfg) => {
                    flexdyn_server::run(session.clone(), settings, *cfg, stopped)
                        .await
                        .map(|r| (r.last_tick, r.sim_time_ns))
                }
                Server::Fleet(settings, fleet) => {
                    flexdyn_server::fleet::run(session.clone(), settings, *fleet, stopped)
                        .await
                        .map(|r| {
                            r.vehicles
                                .first()
                                .map_or((0, 0), |(_, v)| (v.last_tick, v.sim_time_ns))
                        })
                }
            }
            .map_err(server_failure);
            let _ = session.close().await;
            r
        })
    });
    // Until the controllers run, a failure stops the server (it would wait for presence).
    let abandon = |server: std::thread::JoinHandle<_>, why: String| {
        stop.notify_one();
        let _ = server.join();
        RunFailure::from(why)
    };
    let mut observers = Vec::with_capacity(observe.len());
    for ((_, relative), t) in observe.iter().zip(&topics) {
        match Observer::start_with_relative(&endpoint, t, OBSERVER_ID, relative) {
            Ok(o) => observers.push(o),
            Err(why) => {
                close(&observers);
                return Err(abandon(server, why));
            }
        }
    }
    let mut children = Vec::with_capacity(controllers.len());
    for l in controllers {
        match start_controller(l, &endpoint, run_dir) {
            Ok(child) => children.push(child),
            Err(why) => {
                for ch in &mut children {
                    let _ = ch.kill();
                    let _ = ch.wait();
                }
                close(&observers);
                return Err(abandon(server, why));
            }
        }
    }
    // Wait for the server; a controller that exits first stops it. One that exits 0 may have
    // stopped on the server's end-of-run status, which is published before the server thread
    // returns: it counts as early only if the server has not ended by itself EXIT_GRACE later.
    let mut early_exit: Option<(usize, std::process::ExitStatus)> = None;
    let mut grace_until = None;
    let mut stopped_early = false;
    while !server.is_finished() {
        if early_exit.is_none() {
            for (k, ch) in children.iter_mut().enumerate() {
                if let Ok(Some(status)) = ch.try_wait() {
                    early_exit = Some((k, status));
                    if status.success() {
                        grace_until = Some(Instant::now() + EXIT_GRACE);
                    } else {
                        stop.notify_one();
                        stopped_early = true;
                    }
                    break;
                }
            }
        }
        if grace_until.is_some_and(|g| Instant::now() >= g) {
            stop.notify_one();
            stopped_early = true;
            grace_until = None;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    if !stopped_early {
        early_exit = None;
    }
    let server_result = server
        .join()
        .map_err(|_| "the server thread panicked".to_owned())?;
    // The run is over: give the controllers a moment to leave, then stop them.
    let give_up = Instant::now() + Duration::from_secs(2);
    for (k, ch) in children.iter_mut().enumerate() {
        let status = match early_exit {
            Some((j, s)) if j == k => exit_text(s),
            _ => loop {
                if let Ok(Some(s)) = ch.try_wait() {
                    break exit_text(s);
                }
                if Instant::now() >= give_up {
                    let _ = ch.kill();
                    let _ = ch.wait();
                    break "still running at the end: stopped".into();
                }
                std::thread::sleep(Duration::from_millis(10));
            },
        };
        exits.push(status);
    }
    if let Some((k, s)) = early_exit {
        close(&observers);
        return Err(RunFailure {
            outcome: Outcome::Failed,
            message: format!(
                "{} exited before the end ({}); the run stopped",
                controllers[k].who,
                exit_text(s)
            ),
        });
    }
    let (last_tick, sim_time_ns) = match server_result {
        Ok(r) => r,
        Err(e) => {
            close(&observers);
            return Err(e);
        }
    };
    // The server ends on the answers to the last tick; a relative state published after that
    // tick's state may still be on its way: wait for it, briefly.
    let give_up = Instant::now() + Duration::from_secs(2);
    let arrived = |o: &Observer| {
        let n = |r: &Received| r.lock().unwrap_or_else(|e| e.into_inner()).len() as u64;
        let due = (last_tick + 1).saturating_sub(first_tick);
        n(&o.states) >= due && o.relative.iter().all(|r| n(r) >= due)
    };
    while !observers.iter().all(&arrived) && Instant::now() < give_up {
        std::thread::sleep(Duration::from_millis(5));
    }
    let mut out = Observed {
        states: Vec::with_capacity(observers.len()),
        relative: Vec::with_capacity(observers.len()),
        faults: Vec::with_capacity(observers.len()),
        sim_time_ns,
    };
    for (o, (id, _)) in observers.iter().zip(observe) {
        // One spacecraft's message names no vehicle.
        let of = if observe.len() > 1 {
            format!(" of {id:?}")
        } else {
            String::new()
        };
        let states = sorted(&o.states);
        if !complete(&states, first_tick, last_tick) {
            close(&observers);
            return Err(RunFailure::from(format!(
                "the observer saw {} states{of} for ticks {first_tick}..={last_tick}",
                states.len(),
            )));
        }
        let relative: Vec<_> = o.relative.iter().map(sorted).collect();
        if let Some(r) = relative
            .iter()
            .find(|r| !complete(r, first_tick, last_tick))
        {
            close(&observers);
            return Err(RunFailure::from(format!(
                "the observer saw {} relative states{of} for ticks {first_tick}..={last_tick}",
                r.len(),
            )));
        }
        out.states.push(states);
        out.relative.push(relative);
        out.faults.push(sorted(&o.faults));
    }
    close(&observers);
    Ok(out)
}

/// The dispersed parameters of `rp` as the built `model` has them.
fn applied(rp: &RunPlan, model: &BTreeMap<String, f64>) -> BTreeMap<String, f64> {
    rp.dispersed
        .keys()
        .filter_map(|k| model.get(k).map(|v| (k.clone(), *v)))
        .collect()
}

/// \[ns\] each fault's first activation in `events` (its first FaultEventMsg with `active`:
/// `edge_ns`), by `<prefix>faults[k]`.
fn first_activations(prefix: &str, events: &[(u64, Vec<u8>)]) -> BTreeMap<String, u64> {
    let mut first = BTreeMap::new();
    for m in events
        .iter()
        .filter_map(|(_, p)| flexdyn_proto::decode_fault_event(p).ok())
        .filter(|m| m.active)
    {
        first
            .entry(format!("{prefix}faults[{}]", m.fault_index))
            .or_insert(m.edge_ns);
    }
    first
}

fn decode_states(states: &[(u64, Vec<u8>)]) -> Vec<StateMsg> {
    states
        .iter()
        .filter_map(|(_, p)| decode_state(p).ok())
        .collect()
}

/// `flexdyn campaign checkpoint`: flies campaign `c`'s base configuration `cfg`, undispersed,
/// as its runs are flown (its lockstep server, observer and controller, spacecraft [`SC_ID`])
/// up to `tick` and saves the checkpoint there to `file`: the checkpoint a `start_from` of the
/// same campaign fits ([`super::fork::checkpoint_at`] gives `cfg` and `tick`, and refuses a
/// campaign that has none). An older `file` is removed first, and the one written is read back
/// and its tick checked, so a stale file is never reported as written. Its controller's log is
/// `file` with `.controller.log` appended. Returns the checkpoint's \[ns\] simulation time.
pub fn nominal_checkpoint(
    c: &Campaign,
    cfg: SimConfig,
    tick: u64,
    file: &Path,
    base_port: u16,
) -> Result<u64, String> {
    let dir = file
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(format!(
            "cannot write {}: the directory {} does not exist",
            file.display(),
            dir.display()
        ));
    }
    match std::fs::remove_file(file) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => {
            return Err(format!(
                "cannot remove the older {} before writing it: {e}",
                file.display()
            ))
        }
    }
    let mut settings = single_settings(c);
    settings.duration_ns = Some(tick.saturating_mul(cfg.frame_ns));
    settings.checkpoints.save_at = Some((tick, file.to_owned()));
    settings.checkpoints.source = flexdyn_vehicle::checkpoint::Source::of(c.base_path.as_deref())
        .map_err(|e| c.base_error(e).to_string())?;
    let log = format!(
        "{}.controller.log",
        file.file_name()
            .map_or("checkpoint".into(), |f| f.to_string_lossy())
    );
    let controllers: Vec<Launch> = c
        .controller
        .iter()
        .map(|line| Launch {
            line: substitute(line, SC_ID, CONTROLLER_ID, 0, None),
            log: log.clone(),
            who: "the controller".into(),
        })
        .collect();
    let mut exits = Vec::new();
    let port = run_port(
        &RunOptions {
            dir: dir.to_owned(),
            base_port,
            record: false,
        },
        0,
    )?;
    let observed = run_lockstep(
        Server::Single(settings, Box::new(cfg)),
        0,
        &[(SC_ID.to_owned(), Vec::new())],
        &controllers,
        port,
        dir,
        &mut exits,
    )
    .map_err(|e| match c.controller {
        Some(_) => format!(
            "{} (the controller's log: {})",
            e.message,
            dir.join(&log).display()
        ),
        None => e.message,
    })?;
    if !file.is_file() {
        return Err(format!(
            "the run reached t = {} s and no checkpoint was written to {}",
            observed.sim_time_ns as f64 * 1e-9,
            file.display()
        ));
    }
    let (_, header) = flexdyn_server::checkpoint::read(file, flexdyn_server::checkpoint::FRONT_END)
        .map_err(|e| format!("the checkpoint written does not read back: {e}"))?;
    if header.tick != tick {
        return Err(format!(
            "{} holds tick {}, not tick {tick} as asked",
            file.display(),
            header.tick
        ));
    }
    Ok(observed.sim_time_ns)
}

fn run_inner(
    c: &Campaign,
    rp: &RunPlan,
    opts: &RunOptions,
    run_dir: &Path,
    result: &mut RunResult,
) -> Result<(), RunFailure> {
    if !rp.valid {
        return Err(RunFailure::from(format!(
            "invalid: no valid draw in {} tries (last: {})",
            rp.redraws,
            rp.redraw_reasons.last().map_or("", String::as_str)
        )));
    }
    if c.fleet.is_some() {
        return run_fleet(c, rp, opts, run_dir, result);
    }
    let cfg = SimConfig::from_toml_str(&rp.config_toml).map_err(|e| format!("config: {e}"))?;
    let model = readback(&cfg).map_err(|e| format!("model: {e}"))?;
    result.applied = applied(rp, &model);
    // Base port 0: every run's server takes a free port from the OS.
    let port = run_port(opts, rp.run)?;
    let frame_s = cfg.frame_ns as f64 * 1e-9;
    let mut settings = ServerSettings {
        record: lockstep_settings(c, opts, run_dir).record,
        ..single_settings(c)
    };
    // A forked campaign: the server resumes the checkpoint (its own checks refuse one that
    // does not fit the run's configuration) and publishes from its tick on.
    let start_tick = c.start_from.as_ref().map_or(0, |s| s.tick);
    if let Some(start) = &c.start_from {
        settings.checkpoints.source = start.source.clone();
        settings.checkpoints.resume = Some(start.resumed());
    }
    let controllers: Vec<Launch> = c
        .controller
        .iter()
        .map(|line| Launch {
            line: substitute(line, SC_ID, CONTROLLER_ID, rp.run, None),
            log: "controller.log".into(),
            who: "the controller".into(),
        })
        .collect();
    let mut exits = Vec::new();
    let observed = run_lockstep(
        Server::Single(settings, Box::new(cfg)),
        start_tick,
        &[(SC_ID.to_owned(), Vec::new())],
        &controllers,
        port,
        run_dir,
        &mut exits,
    );
    result.controller_exit = exits.into_iter().next();
    let observed = observed?;
    let states = &observed.states[0];
    result.start_tick = start_tick;
    result.start_from_sha256 = c
        .start_from
        .as_ref()
        .map_or_else(String::new, |s| s.sha256.clone());
    result.state_sha256 = sha256_hex(states);
    result.states = states.len() as u64;
    result.fault_activations_ns = first_activations("", &observed.faults[0]);
    result.sim_s = observed.sim_time_ns as f64 * 1e-9;
    let decoded = decode_states(states);
    let fsw = recorded_fsw(c, run_dir, &[(SC_ID, None)])?;
    result.criteria = c
        .criteria
        .iter()
        .map(|k| match &k.fsw {
            Some(f) => evaluate_fsw(
                k,
                fsw.get(&(SC_ID.to_owned(), f.decl.name.clone()))
                    .map_or(&[][..], Vec::as_slice),
                &result.fault_activations_ns,
                "",
                observed.sim_time_ns,
                frame_s,
            ),
            None => evaluate(k, &decoded, c.sigma_rn, frame_s),
        })
        .collect();
    if let Some(start) = &c.start_from {
        for (r, k) in result.criteria.iter_mut().zip(&c.criteria) {
            if super::judge::reads_the_whole_run(k) {
                let seen = start.seen_from();
                r.note = Some(match r.note.take() {
                    Some(n) => format!("{n}; {seen}"),
                    None => seen,
                });
            }
        }
    }
    Ok(())
}

/// The flight code's samples of every stream a criterion reads, from the run's recording, by
/// (spacecraft id, stream), in tick order. `vehicles` are the recording's spacecraft ids with
/// their vehicle (`None`: the one spacecraft). The recording holds what the server accepted:
/// a refused sample is not there, so the criteria judge what the server recorded.
fn recorded_fsw(
    c: &Campaign,
    run_dir: &Path,
    vehicles: &[(&str, Option<&str>)],
) -> Result<BTreeMap<(String, String), Vec<FswMsg>>, String> {
    let mut keys = BTreeMap::new();
    for k in &c.criteria {
        let Some(f) = &k.fsw else { continue };
        for (sc, vehicle) in vehicles {
            if *vehicle == k.vehicle.as_deref() {
                let key = flexdyn_proto::fsw_key(sc, &f.decl.name).map_err(|e| e.to_string())?;
                keys.insert(key, ((*sc).to_owned(), f.decl.name.clone()));
            }
        }
    }
    let mut out: BTreeMap<(String, String), Vec<FswMsg>> = BTreeMap::new();
    if keys.is_empty() {
        return Ok(out);
    }
    let path = run_dir.join(RECORDING);
    let rec = flexdyn_sinks::reader::read_recording(&path)
        .map_err(|e| format!("the flight-code criteria read the run's recording: {e}"))?;
    if let Some(why) = &rec.truncated {
        return Err(format!("{} is cut short: {why}", path.display()));
    }
    for v in keys.values() {
        out.entry(v.clone()).or_default();
    }
    for sample in &rec.samples {
        if let Some(id) = keys.get(&sample.key) {
            let msg = flexdyn_proto::decode_fsw(&sample.payload).map_err(|e| {
                format!("{}: a recorded {} sample: {e}", path.display(), sample.key)
            })?;
            out.entry(id.clone()).or_default().push(msg);
        }
    }
    for samples in out.values_mut() {
        samples.sort_by_key(|m| m.header.tick);
    }
    Ok(out)
}

/// [`run_inner`] over a fleet.
fn run_fleet(
    c: &Campaign,
    rp: &RunPlan,
    opts: &RunOptions,
    run_dir: &Path,
    result: &mut RunResult,
) -> Result<(), RunFailure> {
    let mut fleet = rp.fleet().map_err(|e| format!("config: {e}"))?;
    let model = fleet_readback(&fleet).map_err(|e| format!("model: {e}"))?;
    result.applied = applied(rp, &model);
    let port = run_port(opts, rp.run)?;
    let frame_s = fleet.vehicles[0].cfg.frame_ns as f64 * 1e-9;
    // Each vehicle: its id and, for a deputy judged on its range, its relative-state key.
    let mut observe = Vec::with_capacity(fleet.vehicles.len());
    for v in &fleet.vehicles {
        let mut relative = Vec::new();
        let ranged = c
            .criteria
            .iter()
            .any(|k| k.quantity.is_relative() && k.vehicle.as_deref() == Some(&v.id));
        if let (Some(ci), true) = (v.chief, ranged) {
            let key = Topics::new(&v.id)
                .and_then(|t| t.relative_state(&fleet.vehicles[ci].id))
                .map_err(|e| e.to_string())?;
            relative.push(key);
        }
        observe.push((v.id.clone(), relative));
    }
    // Each deputy's chief, by id (`chief_pointing` reads the chief's states).
    let chiefs: Vec<(String, String)> = fleet
        .vehicles
        .iter()
        .filter_map(|v| Some((v.id.clone(), fleet.vehicles[v.chief?].id.clone())))
        .collect();
    // The observer answers every vehicle's ticks.
    for v in &mut fleet.vehicles {
        if !v.participants.contains(&OBSERVER_ID) {
            v.participants.push(OBSERVER_ID);
        }
    }
    let controllers: Vec<Launch> = c
        .controllers
        .iter()
        .map(|k| Launch {
            line: substitute(
                &k.command,
                &k.vehicle,
                k.sender_id,
                rp.run,
                Some(k.vehicle.as_str()),
            ),
            log: format!("controller-{}-{}.log", k.vehicle, k.sender_id),
            who: format!("the controller of {:?} (sender {})", k.vehicle, k.sender_id),
        })
        .collect();
    let mut exits = Vec::new();
    let observed = run_lockstep(
        Server::Fleet(lockstep_settings(c, opts, run_dir), Box::new(fleet)),
        0,
        &observe,
        &controllers,
        port,
        run_dir,
        &mut exits,
    );
    result.controller_exits = c
        .controllers
        .iter()
        .zip(exits)
        .map(|(k, s)| (format!("{}/{}", k.vehicle, k.sender_id), s))
        .collect();
    let observed = observed?;
    result.states = observed.states.first().map_or(0, |s| s.len() as u64);
    result.sim_s = observed.sim_time_ns as f64 * 1e-9;
    let mut decoded = BTreeMap::new();
    let mut relatives = BTreeMap::new();
    for ((((id, _), states), relative), faults) in observe
        .iter()
        .zip(&observed.states)
        .zip(&observed.relative)
        .zip(&observed.faults)
    {
        result
            .vehicle_state_sha256
            .insert(id.clone(), sha256_hex(states));
        result
            .fault_activations_ns
            .extend(first_activations(&format!("{id}."), faults));
        decoded.insert(id.as_str(), decode_states(states));
        if let Some(r) = relative.first() {
            let msgs: Vec<_> = r
                .iter()
                .filter_map(|(_, p)| flexdyn_proto::decode_relative_state(p).ok())
                .collect();
            relatives.insert(id.as_str(), msgs);
        }
    }
    let chief_of: BTreeMap<&str, &str> = chiefs
        .iter()
        .map(|(d, ch)| (d.as_str(), ch.as_str()))
        .collect();
    let ids: Vec<(&str, Option<&str>)> = observe
        .iter()
        .map(|(id, _)| (id.as_str(), Some(id.as_str())))
        .collect();
    let fsw = recorded_fsw(c, run_dir, &ids)?;
    let none: &[StateMsg] = &[];
    result.criteria = c
        .criteria
        .iter()
        .map(|k| {
            let id = k.vehicle.as_deref().unwrap_or_default();
            let states = |v: &str| decoded.get(v).map_or(none, Vec::as_slice);
            match (&k.fsw, k.quantity.is_relative()) {
                (Some(f), _) => evaluate_fsw(
                    k,
                    fsw.get(&(id.to_owned(), f.decl.name.clone()))
                        .map_or(&[][..], Vec::as_slice),
                    &result.fault_activations_ns,
                    &format!("{id}."),
                    observed.sim_time_ns,
                    frame_s,
                ),
                (None, true) => {
                    let series = relative_series(
                        k,
                        relatives.get(id).map_or(&[][..], Vec::as_slice),
                        states(id),
                        chief_of.get(id).map_or(none, |ch| states(ch)),
                    );
                    reduce(k, &series, frame_s)
                }
                (None, false) => evaluate(k, states(id), c.sigma_rn, frame_s),
            }
        })
        .collect();
    Ok(())
}

/// Runs `indices` of `plan`, `jobs` at a time, with progress on stderr: a bar on a terminal,
/// else (CI, a pipe, a file) plain [`Progress`] lines; returns the results in index order.
pub fn execute_many(
    plan: &Plan,
    runs: &[RunPlan],
    indices: &[u32],
    jobs: usize,
    opts: &RunOptions,
) -> Vec<RunResult> {
    use std::io::IsTerminal as _;
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<RunResult>> = Mutex::new(Vec::new());
    let terminal = std::io::stderr().is_terminal();
    let bar = if terminal {
        indicatif::ProgressBar::new(indices.len() as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} runs, {elapsed} elapsed, ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let failed = AtomicUsize::new(0);
    let (done_tx, done_rx) = std::sync::mpsc::channel::<Outcome>();
    let started = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..jobs.max(1) {
            let done_tx = done_tx.clone();
            let (next, results, failed, bar) = (&next, &results, &failed, &bar);
            s.spawn(move || loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(&index) = indices.get(i) else { break };
                let r = execute(plan, &runs[index as usize], opts);
                if !r.passed {
                    failed.fetch_add(1, Ordering::Relaxed);
                }
                bar.set_message(format!("({} not passed)", failed.load(Ordering::Relaxed)));
                bar.inc(1);
                let _ = done_tx.send(r.outcome);
                results.lock().unwrap_or_else(|e| e.into_inner()).push(r);
            });
        }
        drop(done_tx);
        if !terminal {
            // Plain lines for a log: each run's outcome as it arrives, a line at least every
            // PROGRESS_EVERY, until every worker has finished.
            let mut p = Progress::new(indices.len(), started);
            loop {
                let wait = p.next_due().saturating_duration_since(Instant::now());
                let line = match done_rx.recv_timeout(wait) {
                    Ok(outcome) => p.record(outcome, Instant::now()),
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => p.tick(Instant::now()),
                    Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
                };
                if let Some(line) = line {
                    eprintln!("{line}");
                }
            }
        }
    });
    bar.finish();
    let mut out = results.into_inner().unwrap_or_else(|e| e.into_inner());
    out.sort_by_key(|r| r.run);
    out
}

/// The longest a campaign that is not on a terminal stays silent.
pub const PROGRESS_EVERY: Duration = Duration::from_secs(5);

/// A campaign's progress as plain lines (for a log, where a bar's carriage returns do not
/// show): `campaign: 7/20 runs done (3 pass, 4 fail, 0 could not run), 12.3 s elapsed`, at
/// every tenth of the runs, at the last one, and every [`PROGRESS_EVERY`] in between.
#[derive(Clone, Debug)]
pub struct Progress {
    total: usize,
    done: usize,
    passed: usize,
    failed: usize,
    not_run: usize,
    started: Instant,
    last_line: Instant,
    last_done: usize,
}

impl Progress {
    /// Progress over `total` runs started at `started`.
    pub fn new(total: usize, started: Instant) -> Self {
        Progress {
            total,
            done: 0,
            passed: 0,
            failed: 0,
            not_run: 0,
            started,
            last_line: started,
            last_done: 0,
        }
    }

    /// When the next line is due if no run finishes before.
    pub fn next_due(&self) -> Instant {
        self.last_line + PROGRESS_EVERY
    }

    /// A run finished with `outcome` at `now`: the line to print, if one is due (a tenth of
    /// the runs since the last line, the last run, or [`PROGRESS_EVERY`] since the last line).
    pub fn record(&mut self, outcome: Outcome, now: Instant) -> Option<String> {
        self.done += 1;
        match outcome {
            Outcome::Passed => self.passed += 1,
            Outcome::Failed => self.failed += 1,
            Outcome::NotRun => self.not_run += 1,
        }
        let step = self.total.div_ceil(10).max(1);
        if self.done == self.total || self.done >= self.last_done + step || now >= self.next_due() {
            Some(self.line(now))
        } else {
            None
        }
    }

    /// No run finished: the line to print if [`PROGRESS_EVERY`] has passed since the last.
    pub fn tick(&mut self, now: Instant) -> Option<String> {
        (now >= self.next_due()).then(|| self.line(now))
    }

    fn line(&mut self, now: Instant) -> String {
        self.last_line = now;
        self.last_done = self.done;
        format!(
            "campaign: {}/{} runs done ({} pass, {} fail, {} could not run), {:.1} s elapsed",
            self.done,
            self.total,
            self.passed,
            self.failed,
            self.not_run,
            now.saturating_duration_since(self.started).as_secs_f64()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A forked run's stream is complete from the checkpoint's tick: every tick K..=N once, in
    /// order; one from tick 0, a gap or a repeat is not.
    #[test]
    fn a_stream_is_complete_from_its_first_tick() {
        let s = |ticks: &[u64]| ticks.iter().map(|t| (*t, Vec::new())).collect::<Vec<_>>();
        assert!(complete(&s(&[40, 41, 42]), 40, 42));
        assert!(complete(&s(&[0, 1, 2]), 0, 2));
        assert!(!complete(&s(&[0, 1, 2]), 1, 2));
        assert!(!complete(&s(&[40, 42]), 40, 42));
        assert!(!complete(&s(&[40, 41, 41]), 40, 42));
        assert!(!complete(&s(&[]), 40, 39));
    }

    /// Issue 36: without a terminal the progress is plain lines, at every tenth of the runs,
    /// at the last, and every 5 s while nothing finishes.
    #[test]
    fn plain_progress_lines_come_at_a_steady_rate() {
        let t0 = Instant::now();
        let at = |s: f64| t0 + Duration::from_secs_f64(s);
        let mut p = Progress::new(20, t0);
        assert_eq!(p.tick(at(1.0)), None);
        assert_eq!(
            p.tick(at(5.0)).as_deref(),
            Some("campaign: 0/20 runs done (0 pass, 0 fail, 0 could not run), 5.0 s elapsed")
        );
        assert_eq!(p.record(Outcome::Passed, at(6.0)), None);
        assert_eq!(
            p.record(Outcome::Failed, at(6.5)).as_deref(),
            Some("campaign: 2/20 runs done (1 pass, 1 fail, 0 could not run), 6.5 s elapsed")
        );
        assert_eq!(p.record(Outcome::NotRun, at(7.0)), None);
        assert!(p.record(Outcome::Passed, at(12.0)).is_some());
        for k in 5..=20 {
            let line = p.record(Outcome::Passed, at(12.0 + f64::from(k) * 0.01));
            assert_eq!(line.is_some(), k % 2 == 0 || k == 20, "{k}: {line:?}");
        }
    }
}
