//! Server settings: the `[server]` table of the configuration file and the matching
//! `flexdyn run` options (a command-line option overrides the table).
//!
//! Every setting has one TOML key `x_y` and one option `--x-y`; both go through
//! [`ServerSettings::apply`], so they accept the same values and report errors the same way,
//! naming the setting as the user wrote it (`server.x_y` or `--x-y`). [`KEYS`] lists them; the
//! book's "Server settings" table (docs/guides/server.md) documents each one and its default.

use std::time::Duration;

use std::path::Path;

use flexdyn_proto::{validate_sc_id, Mode, StalePolicy};

use super::error::SettingsError;
use flexdyn_kernel::numfmt::Num;
use flexdyn_vehicle::config::{beyond_max_time, whole_ns, SimConfig};

/// What the real-time loop does when a frame's work ends after the next frame's deadline.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OverrunPolicy {
    /// `catch_up` (default): keep the absolute schedule t0 + k·period; late frames run back to
    /// back without sleeping until the loop is on time again, so simulation time never drifts
    /// from wall time.
    #[default]
    CatchUp,
    /// `skip`: when a frame boundary is reached one or more whole periods late, drop those
    /// deadlines (counted in `frames_skipped`): the schedule moves forward by the missed periods
    /// and simulation time falls behind wall time by as much. Smaller lateness is caught up.
    Skip,
    /// `abort`: like `catch_up`, but stop the run with an error once more than
    /// `overrun_limit` consecutive frames overran.
    Abort,
}

impl OverrunPolicy {
    /// The setting's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            OverrunPolicy::CatchUp => "catch_up",
            OverrunPolicy::Skip => "skip",
            OverrunPolicy::Abort => "abort",
        }
    }
}

/// Which thread publishes a frame's telemetry (`server.handoff`, see [`super::publish`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Handoff {
    /// `auto` (default): `direct`, except in real time with `--record` or under SCHED_FIFO
    /// (`realtime_priority` > 0), where `thread`. With `--record`: the benchmark
    /// (`tools/benches/realtime.rs`) showed the recorder's threads making the physics thread's
    /// own puts slow (about 100 puts over 100 µs per 30 000 frames instead of about 20) and
    /// doubling the overruns, and recording must never slow the physics thread. Under
    /// SCHED_FIFO: a put takes Zenoh's locks, which Zenoh threads of normal priority also take,
    /// so the physics thread could wait for one of them (priority inversion); the `thread`
    /// handoff takes no lock at all (see `physics`).
    #[default]
    Auto,
    /// `direct`: the thread that finishes the frame publishes it: the physics thread at the
    /// boundary in real time (never waiting for the network), and in lockstep the Zenoh thread
    /// that delivers the tick's last answer steps the frame and publishes it. Batch always uses
    /// the telemetry thread.
    Direct,
    /// `thread`: the physics thread hands every frame to the telemetry thread, which publishes
    /// it (the design before `direct`; one more thread hop per frame).
    Thread,
}

impl Handoff {
    /// The setting's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Handoff::Auto => "auto",
            Handoff::Direct => "direct",
            Handoff::Thread => "thread",
        }
    }

    /// Whether frames are published directly (not by the telemetry thread) in `mode`, with or
    /// without a recording, with or without the physics thread under SCHED_FIFO (`fifo`).
    pub fn is_direct(self, mode: Mode, recording: bool, fifo: bool) -> bool {
        match self {
            _ if mode == Mode::Batch => false,
            Handoff::Auto => !(mode == Mode::RealTime && (recording || fifo)),
            Handoff::Direct => true,
            Handoff::Thread => false,
        }
    }
}

pub use flexdyn_proto::client::transport::mode_name;

/// The spelling of a [`StalePolicy`] in settings and logs.
pub fn stale_policy_name(p: StalePolicy) -> &'static str {
    match p {
        StalePolicy::Hold => "hold",
        StalePolicy::Zero => "zero",
    }
}

/// Every key of the `[server]` table (and, with `-` for `_`, every `flexdyn run` option that
/// sets a server setting).
pub const KEYS: &[&str] = &[
    "mode",
    "sc_id",
    "spacecraft_id",
    "participants",
    "participant_timeout_s",
    "presence_timeout_s",
    "duration_s",
    "overrun_policy",
    "overrun_limit",
    "stale_after_s",
    "stale_policy",
    "status_hz",
    "summary_interval_s",
    "spin_us",
    "realtime_priority",
    "lock_memory",
    "physics_cpu",
    "cpu_dma_latency",
    "telemetry_buffers",
    "command_queue",
    "handoff",
    "participant_subjects",
    "speed",
];

/// Bounds of `speed`: slower than 1/1000 or faster than 1000 × real time is not a real-time run
/// (a 1 ms frame would be paced every second, or every microsecond).
pub const SPEED_RANGE: (f64, f64) = (1e-3, 1e3);

/// Validated server settings. [`Default`] gives the documented defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct ServerSettings {
    /// Pacing: real time (default), lockstep or batch.
    pub mode: Mode,
    /// String spacecraft id used in the key expressions `flexdyn/<sc_id>/…` (default `sc1`).
    pub sc_id: String,
    /// Numeric spacecraft id written in every header and required in commands (default 1).
    pub spacecraft_id: u32,
    /// Sender ids allowed to command, sorted and unique (default `[1]`, the demo controller).
    /// In lockstep every one of them must answer every tick.
    pub participants: Vec<u32>,
    /// Lockstep: how long to wait for a participant's answer to one tick (default 10 s).
    pub participant_timeout: Duration,
    /// Lockstep: how long to wait before tick 0 for every participant to be present (default 30 s).
    pub presence_timeout: Duration,
    /// \[ns\] simulated duration, a whole number of frames; `None` runs until stopped.
    pub duration_ns: Option<u64>,
    /// Real time: what to do on overruns (default `catch_up`).
    pub overrun_policy: OverrunPolicy,
    /// Real time, `abort` policy: consecutive overrun frames tolerated (default 10).
    pub overrun_limit: u32,
    /// Real time/batch: a command held longer than this (simulation time) is stale (default 0.1 s).
    pub stale_after: Duration,
    /// What a stale command turns into: `hold` (keep it, default) or `zero`.
    pub stale_policy: StalePolicy,
    /// \[Hz\] StatusMsg publication rate (default 10).
    pub status_hz: f64,
    /// Interval of the timing summary in the log (default 10 s).
    pub summary_interval: Duration,
    /// Real time: the loop sleeps until this long before a deadline, then spins (default 200 µs).
    pub spin: Duration,
    /// Real time: SCHED_FIFO priority 1–99 for the physics thread, 0 = the normal scheduler
    /// (default 0). Needs CAP_SYS_NICE (or root); if the OS refuses, the run stops with an
    /// error ([`super::rt`]).
    pub realtime_priority: u8,
    /// Real time: lock the process's memory (`mlockall`) and pre-fault the physics thread's
    /// stack, so the frame loop takes no page fault (default off; needs CAP_IPC_LOCK or a
    /// large enough RLIMIT_MEMLOCK).
    pub lock_memory: bool,
    /// Real time: the CPU the physics thread runs on alone; every other thread of the server
    /// runs on the remaining CPUs (default `None`: no pinning).
    pub physics_cpu: Option<usize>,
    /// Real time: hold `/dev/cpu_dma_latency` open with 0 while running, keeping the CPUs out
    /// of deep idle states (default off; needs write access to the device).
    pub cpu_dma_latency: bool,
    /// Preallocated telemetry buffers between the physics and the I/O threads (default 64:
    /// 64 ms at 1 kHz of a telemetry thread not scheduled before a frame's telemetry is dropped).
    pub telemetry_buffers: usize,
    /// Capacity of the command queue from the I/O side to the physics thread (default 1024).
    pub command_queue: usize,
    /// Which thread publishes the frames (default `auto`).
    pub handoff: Handoff,
    /// The authenticated Zenoh subject (usrpwd user name) each participant's sender id is bound
    /// to, e.g. `{ "1" = "fsw" }`. Empty (default): no binding. When set, every participant
    /// needs one, and the server refuses to start unless its Zenoh configuration authenticates
    /// peers and its access-control list lets only that subject put on the participant's
    /// command key ([`super::access`]).
    pub participant_subjects: std::collections::BTreeMap<u32, String>,
    /// Real time: simulated seconds per wall-clock second (default 1.0; 2.0 runs twice as fast,
    /// 0.5 half as fast). Frame boundary `k` is due `k · frame_ns / speed` after the start. Not
    /// used in lockstep and batch.
    pub speed: f64,
    /// `flexdyn run --record FILE.mcap`: record the server's own output (state, sensors, status,
    /// and every command received) to this file. Command line only (not a `[server]` key).
    pub record: Option<std::path::PathBuf>,
    /// `flexdyn run --checkpoint-at-tick/--checkpoint`, `--checkpoint-dir`, `--resume`: the
    /// checkpoints this run saves and the one it resumes from (docs/guides/checkpoints.md).
    pub checkpoints: super::checkpoint::CheckpointSettings,
}

impl Default for ServerSettings {
    fn default() -> Self {
        Self {
            mode: Mode::RealTime,
            sc_id: "sc1".into(),
            spacecraft_id: 1,
            participants: vec![1],
            participant_timeout: Duration::from_secs(10),
            presence_timeout: Duration::from_secs(30),
            duration_ns: None,
            overrun_policy: OverrunPolicy::CatchUp,
            overrun_limit: 10,
            stale_after: Duration::from_millis(100),
            stale_policy: StalePolicy::Hold,
            status_hz: 10.0,
            summary_interval: Duration::from_secs(10),
            spin: Duration::from_micros(200),
            realtime_priority: 0,
            lock_memory: false,
            physics_cpu: None,
            cpu_dma_latency: false,
            telemetry_buffers: 64,
            command_queue: 1024,
            handoff: Handoff::Auto,
            participant_subjects: std::collections::BTreeMap::new(),
            speed: 1.0,
            record: None,
            checkpoints: super::checkpoint::CheckpointSettings::default(),
        }
    }
}

/// Where a setting came from; decides how errors name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// The `[server]` TOML table: `server.<key>`.
    Table,
    /// A `flexdyn run` option: `--<key with - for _>`.
    Cli,
}

impl Origin {
    /// How the user wrote the setting `key`.
    pub fn name(self, key: &str) -> String {
        match self {
            Origin::Table => format!("server.{key}"),
            Origin::Cli => format!("--{}", key.replace('_', "-")),
        }
    }
}

/// A setting's value before validation.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A string.
    Str(String),
    /// An integer (also accepted where a float is expected).
    Int(i64),
    /// A float.
    Float(f64),
    /// A list of integers.
    Ints(Vec<i64>),
    /// A table of strings (`{ "1" = "fsw" }`; on the command line `1=fsw,2=gnc`).
    Strings(Vec<(String, String)>),
    /// A boolean.
    Bool(bool),
}

impl Value {
    fn describe(&self) -> String {
        match self {
            Value::Str(s) => format!("string {s:?}"),
            Value::Int(i) => format!("integer {i}"),
            Value::Float(f) => format!("float {f}"),
            Value::Ints(v) => format!("list {v:?}"),
            Value::Strings(v) => format!("table {v:?}"),
            Value::Bool(b) => format!("boolean {b}"),
        }
    }

    /// A TOML value as a setting value (`None` for types no setting takes).
    fn from_toml(v: &toml::Value) -> Option<Self> {
        Some(match v {
            toml::Value::String(s) => Value::Str(s.clone()),
            toml::Value::Integer(i) => Value::Int(*i),
            toml::Value::Float(f) => Value::Float(*f),
            toml::Value::Boolean(b) => Value::Bool(*b),
            toml::Value::Array(a) => Value::Ints(
                a.iter()
                    .map(|x| x.as_integer())
                    .collect::<Option<Vec<i64>>>()?,
            ),
            toml::Value::Table(t) => Value::Strings(
                t.iter()
                    .map(|(k, v)| Some((k.clone(), v.as_str()?.to_owned())))
                    .collect::<Option<Vec<_>>>()?,
            ),
            _ => return None,
        })
    }
}

struct Setter<'a> {
    name: String,
    value: &'a Value,
}

impl Setter<'_> {
    fn bad(&self, problem: impl Into<String>) -> SettingsError {
        SettingsError::Invalid {
            name: self.name.clone(),
            problem: problem.into(),
        }
    }

    fn expected(&self, what: &str) -> SettingsError {
        self.bad(format!("expected {what}, got {}", self.value.describe()))
    }

    fn string(&self) -> Result<&str, SettingsError> {
        match self.value {
            Value::Str(s) => Ok(s),
            _ => Err(self.expected("a string")),
        }
    }

    fn boolean(&self) -> Result<bool, SettingsError> {
        match self.value {
            Value::Bool(b) => Ok(*b),
            _ => Err(self.expected("true or false")),
        }
    }

    fn float(&self) -> Result<f64, SettingsError> {
        let f = match self.value {
            Value::Float(f) => *f,
            Value::Int(i) => *i as f64,
            _ => return Err(self.expected("a number")),
        };
        if !f.is_finite() {
            return Err(self.bad(format!("must be finite (got {})", Num(f))));
        }
        Ok(f)
    }

    fn positive(&self) -> Result<f64, SettingsError> {
        let f = self.float()?;
        if f <= 0.0 {
            return Err(self.bad(format!("must be > 0 (got {})", Num(f))));
        }
        Ok(f)
    }

    /// A positive time in seconds that a `u64` count of nanoseconds holds (as every time in a
    /// configuration).
    fn seconds_f64(&self) -> Result<f64, SettingsError> {
        let s = self.positive()?;
        match beyond_max_time(s) {
            Some(problem) => Err(self.bad(problem)),
            None => Ok(s),
        }
    }

    fn seconds(&self) -> Result<Duration, SettingsError> {
        Ok(Duration::from_secs_f64(self.seconds_f64()?))
    }

    fn int_in(&self, lo: i64, hi: i64) -> Result<i64, SettingsError> {
        match self.value {
            Value::Int(i) if (lo..=hi).contains(i) => Ok(*i),
            Value::Int(i) => Err(self.bad(format!("must be in {lo}..={hi} (got {i})"))),
            _ => Err(self.expected("an integer")),
        }
    }
}

impl ServerSettings {
    /// Whether this run's frames are published directly (by whoever steps them) rather than by
    /// a telemetry thread ([`Handoff::is_direct`] for these settings' mode, `--record` and
    /// SCHED_FIFO priority).
    pub fn direct_handoff(&self) -> bool {
        self.handoff
            .is_direct(self.mode, self.record.is_some(), self.realtime_priority > 0)
    }

    /// Every command-link fault of `cfg` (`links.<sender id>`) must name one of these
    /// participants (the file's were checked at load; the command line may change them).
    pub fn check_link_faults(&self, cfg: &SimConfig) -> Result<(), SettingsError> {
        match flexdyn_faults::link::unknown_participant(&cfg.faults, &self.participants) {
            Some((name, problem)) => Err(SettingsError::Invalid { name, problem }),
            None => Ok(()),
        }
    }

    /// The settings of a configuration's `[server]` table (empty table: the defaults).
    /// Unknown keys and bad values are errors naming `server.<key>`.
    pub fn from_table(table: &toml::Table) -> Result<Self, SettingsError> {
        let mut s = Self::default();
        for (key, v) in table {
            if !KEYS.contains(&key.as_str()) {
                return Err(SettingsError::UnknownKey {
                    key: key.clone(),
                    expected: KEYS.join(", "),
                });
            }
            let value = Value::from_toml(v).ok_or_else(|| SettingsError::Invalid {
                name: Origin::Table.name(key),
                problem: format!("unsupported value type {}", v.type_str()),
            })?;
            s.apply(key, &value, Origin::Table)?;
        }
        Ok(s)
    }

    /// The settings of `cfg`'s `[server]` table (read from `file`; `None`: the embedded default)
    /// with the command-line `overrides` applied on top, checked across settings
    /// ([`Self::validate`]) and against the frame ([`Self::duration_frames`]): what `flexdyn run`
    /// starts with and `flexdyn check-config` checks. An error about a key of the file starts
    /// with the file's name and ends with the key's line and column; one about a setting the
    /// command line gave names the option (`--duration-s`).
    pub fn resolve(
        cfg: &SimConfig,
        file: Option<&Path>,
        overrides: &[(&'static str, Value)],
    ) -> Result<Self, SettingsError> {
        let in_file = |e: SettingsError| e.in_file(file, &cfg.source_toml);
        let mut s = Self::from_table(&cfg.server).map_err(in_file)?;
        for (key, value) in overrides {
            s.apply(key, value, Origin::Cli)?;
        }
        let named = |e: SettingsError| {
            let from_cli = e
                .key()
                .is_some_and(|k| overrides.iter().any(|(o, _)| *o == k));
            if from_cli {
                e.into_option()
            } else {
                in_file(e)
            }
        };
        s.validate().map_err(named)?;
        s.check_link_faults(cfg).map_err(named)?;
        s.duration_frames(cfg.frame_ns).map_err(named)?;
        Ok(s)
    }

    /// Sets one setting. `key` is one of [`KEYS`]; `origin` decides how errors name it.
    pub fn apply(&mut self, key: &str, value: &Value, origin: Origin) -> Result<(), SettingsError> {
        let set = Setter {
            name: origin.name(key),
            value,
        };
        match key {
            "mode" => {
                self.mode = match set.string()? {
                    "realtime" => Mode::RealTime,
                    "lockstep" => Mode::Lockstep,
                    "batch" => Mode::Batch,
                    other => {
                        return Err(set.bad(format!(
                        "unknown mode {other:?} (expected \"realtime\", \"lockstep\" or \"batch\")"
                    )))
                    }
                }
            }
            "sc_id" => {
                let id = set.string()?;
                validate_sc_id(id).map_err(|e| set.bad(e.to_string()))?;
                self.sc_id = id.to_owned();
            }
            "spacecraft_id" => self.spacecraft_id = set.int_in(0, u32::MAX.into())? as u32,
            "participants" => {
                let Value::Ints(ids) = value else {
                    return Err(set.expected("a list of sender ids (integers)"));
                };
                let mut out = Vec::with_capacity(ids.len());
                for &id in ids {
                    let id = u32::try_from(id)
                        .map_err(|_| set.bad(format!("sender id {id} is not in 0..=4294967295")))?;
                    if out.contains(&id) {
                        return Err(set.bad(format!("sender id {id} is listed twice")));
                    }
                    out.push(id);
                }
                out.sort_unstable();
                self.participants = out;
            }
            "participant_timeout_s" => self.participant_timeout = set.seconds()?,
            "presence_timeout_s" => self.presence_timeout = set.seconds()?,
            "duration_s" => {
                let s = set.seconds_f64()?;
                let ns = whole_ns(s).ok_or_else(|| {
                    set.bad(format!("{} s is not a whole number of nanoseconds", Num(s)))
                })?;
                self.duration_ns = Some(ns);
            }
            "overrun_policy" => {
                self.overrun_policy = match set.string()? {
                    "catch_up" => OverrunPolicy::CatchUp,
                    "skip" => OverrunPolicy::Skip,
                    "abort" => OverrunPolicy::Abort,
                    other => {
                        return Err(set.bad(format!(
                        "unknown policy {other:?} (expected \"catch_up\", \"skip\" or \"abort\")"
                    )))
                    }
                }
            }
            "overrun_limit" => self.overrun_limit = set.int_in(0, u32::MAX.into())? as u32,
            "stale_after_s" => self.stale_after = set.seconds()?,
            "stale_policy" => {
                self.stale_policy = match set.string()? {
                    "hold" => StalePolicy::Hold,
                    "zero" => StalePolicy::Zero,
                    other => {
                        return Err(set.bad(format!(
                            "unknown policy {other:?} (expected \"hold\" or \"zero\")"
                        )))
                    }
                }
            }
            "status_hz" => {
                let hz = set.positive()?;
                if hz > 1000.0 {
                    return Err(set.bad(format!("must be <= 1000 Hz (got {})", Num(hz))));
                }
                self.status_hz = hz;
            }
            "summary_interval_s" => self.summary_interval = set.seconds()?,
            "spin_us" => self.spin = Duration::from_micros(set.int_in(0, 1_000_000)? as u64),
            "realtime_priority" => self.realtime_priority = set.int_in(0, 99)? as u8,
            "lock_memory" => self.lock_memory = set.boolean()?,
            // -1: no pinning (so the command line can undo the file's choice).
            "physics_cpu" => {
                self.physics_cpu = usize::try_from(set.int_in(-1, 4095)?).ok();
            }
            "cpu_dma_latency" => self.cpu_dma_latency = set.boolean()?,
            "telemetry_buffers" => self.telemetry_buffers = set.int_in(2, 1 << 16)? as usize,
            "command_queue" => self.command_queue = set.int_in(1, 1 << 20)? as usize,
            "handoff" => {
                self.handoff = match set.string()? {
                    "auto" => Handoff::Auto,
                    "direct" => Handoff::Direct,
                    "thread" => Handoff::Thread,
                    other => {
                        return Err(set.bad(format!(
                        "unknown handoff {other:?} (expected \"auto\", \"direct\" or \"thread\")"
                    )))
                    }
                }
            }
            "participant_subjects" => {
                let Value::Strings(pairs) = value else {
                    return Err(
                        set.expected("a table of sender id = subject, e.g. { \"1\" = \"fsw\" }")
                    );
                };
                let mut out = std::collections::BTreeMap::new();
                for (id, subject) in pairs {
                    let sender = id.parse::<u32>().ok().filter(|n| n.to_string() == *id);
                    let Some(sender) = sender else {
                        return Err(set.bad(format!(
                            "{id:?} is not a sender id (a decimal integer 0..=4294967295)"
                        )));
                    };
                    if subject.is_empty() || subject.contains(char::is_whitespace) {
                        return Err(set.bad(format!(
                            "sender {sender}: {subject:?} is not a Zenoh user name (non-empty, \
                             no spaces)"
                        )));
                    }
                    if out.insert(sender, subject.clone()).is_some() {
                        return Err(set.bad(format!("sender {sender} is listed twice")));
                    }
                }
                self.participant_subjects = out;
            }
            "speed" => {
                let x = set.positive()?;
                let (lo, hi) = SPEED_RANGE;
                if !(lo..=hi).contains(&x) {
                    return Err(set.bad(format!(
                        "must be in {}..={} (× real time; got {})",
                        Num(lo),
                        Num(hi),
                        Num(x)
                    )));
                }
                self.speed = x;
            }
            other => {
                return Err(SettingsError::UnknownKey {
                    key: other.to_owned(),
                    expected: KEYS.join(", "),
                })
            }
        }
        Ok(())
    }

    /// Checks that hold across settings (called by the server before it starts):
    /// lockstep needs at least one participant.
    pub fn validate(&self) -> Result<(), SettingsError> {
        if !self.participant_subjects.is_empty() {
            if let Some(id) = self
                .participant_subjects
                .keys()
                .find(|id| !self.participants.contains(id))
            {
                return Err(SettingsError::Invalid {
                    name: "server.participant_subjects".into(),
                    problem: format!(
                        "sender {id} is not in server.participants {:?}",
                        self.participants
                    ),
                });
            }
            if let Some(id) = self
                .participants
                .iter()
                .find(|id| !self.participant_subjects.contains_key(id))
            {
                return Err(SettingsError::Invalid {
                    name: "server.participant_subjects".into(),
                    problem: format!(
                        "participant {id} has no subject: once one participant is bound to an \
                         authenticated subject, every participant must be"
                    ),
                });
            }
        }
        if self.mode == Mode::Lockstep && self.participants.is_empty() {
            return Err(SettingsError::Invalid {
                name: "server.participants".into(),
                problem: "lockstep needs at least one participant (use mode \"batch\" to run \
                          without any)"
                    .into(),
            });
        }
        Ok(())
    }

    /// \[ns\] the StatusMsg period.
    pub fn status_period(&self) -> Duration {
        Duration::from_secs_f64(1.0 / self.status_hz)
    }

    /// The number of frames in [`Self::duration_ns`] for a frame of `frame_ns`, or an error
    /// naming the setting if it is not a whole number of frames.
    pub fn duration_frames(&self, frame_ns: u64) -> Result<Option<u64>, SettingsError> {
        match self.duration_ns {
            None => Ok(None),
            Some(ns) if ns % frame_ns == 0 => Ok(Some(ns / frame_ns)),
            Some(ns) => Err(SettingsError::Invalid {
                name: "server.duration_s".into(),
                problem: format!(
                    "{} s is not a whole number of frames (frame = {} s = {frame_ns} ns)",
                    Num(ns as f64 / 1e9),
                    Num(frame_ns as f64 / 1e9)
                ),
            }),
        }
    }

    /// One-line description for the start-up log.
    pub fn summary(&self) -> String {
        format!(
            "mode={} sc_id={} spacecraft_id={} participants={:?} participant_timeout_s={} \
             presence_timeout_s={} duration_s={} overrun_policy={} overrun_limit={} \
             stale_after_s={} stale_policy={} status_hz={} summary_interval_s={} spin_us={} \
             realtime_priority={} lock_memory={} physics_cpu={} cpu_dma_latency={} \
             telemetry_buffers={} command_queue={} handoff={} participant_subjects={:?} \
             speed={} record={}",
            mode_name(self.mode),
            self.sc_id,
            self.spacecraft_id,
            self.participants,
            self.participant_timeout.as_secs_f64(),
            self.presence_timeout.as_secs_f64(),
            self.duration_ns
                .map_or("unlimited".to_owned(), |ns| Num(ns as f64 / 1e9)
                    .to_string()),
            self.overrun_policy.as_str(),
            self.overrun_limit,
            self.stale_after.as_secs_f64(),
            stale_policy_name(self.stale_policy),
            self.status_hz,
            self.summary_interval.as_secs_f64(),
            self.spin.as_micros(),
            self.realtime_priority,
            self.lock_memory,
            self.physics_cpu
                .map_or("none".to_owned(), |c| c.to_string()),
            self.cpu_dma_latency,
            self.telemetry_buffers,
            self.command_queue,
            self.handoff.as_str(),
            self.participant_subjects,
            Num(self.speed),
            self.record
                .as_ref()
                .map_or("off".to_owned(), |p| p.display().to_string()),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handoff_parses_and_resolves_per_mode() {
        let s = ServerSettings::from_table(&table("handoff = \"thread\"")).unwrap();
        assert_eq!(s.handoff, Handoff::Thread);
        assert_eq!(ServerSettings::default().handoff, Handoff::Auto);
        let e = ServerSettings::from_table(&table("handoff = \"inline\"")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "server.handoff: unknown handoff \"inline\" (expected \"auto\", \"direct\" or \"thread\")"
        );
        use Mode::{Batch, Lockstep, RealTime};
        // (handoff, mode, recording, SCHED_FIFO) -> direct?
        for (h, mode, rec, fifo, want) in [
            (Handoff::Auto, RealTime, false, false, true),
            (Handoff::Auto, RealTime, true, false, false),
            (Handoff::Auto, RealTime, false, true, false),
            (Handoff::Auto, Lockstep, true, false, true),
            (Handoff::Auto, Lockstep, false, true, true),
            (Handoff::Auto, Batch, false, false, false),
            (Handoff::Direct, RealTime, true, false, true),
            (Handoff::Direct, RealTime, false, true, true),
            (Handoff::Direct, Batch, false, false, false),
            (Handoff::Thread, Lockstep, false, false, false),
        ] {
            assert_eq!(
                h.is_direct(mode, rec, fifo),
                want,
                "{h:?} {mode:?} record={rec} fifo={fifo}"
            );
        }
        let s = ServerSettings::from_table(&table(
            "participants = [1, 2]\nparticipant_subjects = { \"1\" = \"fsw\", \"2\" = \"gnc\" }",
        ))
        .unwrap();
        assert_eq!(
            s.participant_subjects.get(&2).map(String::as_str),
            Some("gnc")
        );
        s.validate().unwrap();
        for (toml_text, want) in [
            (
                "participant_subjects = { \"01\" = \"fsw\" }",
                "server.participant_subjects: \"01\" is not a sender id",
            ),
            (
                "participant_subjects = { \"1\" = \"\" }",
                "server.participant_subjects: sender 1: \"\" is not a Zenoh user name",
            ),
            (
                "participant_subjects = [1]",
                "server.participant_subjects: expected a table of sender id = subject",
            ),
        ] {
            let e = ServerSettings::from_table(&table(toml_text)).unwrap_err();
            assert!(e.to_string().starts_with(want), "{e}");
        }
        let partial = ServerSettings::from_table(&table(
            "participants = [1, 2]\nparticipant_subjects = { \"1\" = \"fsw\" }",
        ))
        .unwrap();
        assert!(partial
            .validate()
            .unwrap_err()
            .to_string()
            .contains("participant 2 has no subject"));
    }

    fn table(s: &str) -> toml::Table {
        s.parse().unwrap()
    }

    #[test]
    fn empty_table_gives_defaults() {
        assert_eq!(
            ServerSettings::from_table(&toml::Table::new()).unwrap(),
            ServerSettings::default()
        );
    }

    #[test]
    fn every_key_parses() {
        let s = ServerSettings::from_table(&table(
            r#"
            mode = "lockstep"
            sc_id = "craft-2"
            spacecraft_id = 42
            participants = [3, 1, 2]
            participant_timeout_s = 2.5
            presence_timeout_s = 5
            duration_s = 12.0
            overrun_policy = "skip"
            overrun_limit = 3
            stale_after_s = 0.05
            stale_policy = "zero"
            status_hz = 20
            summary_interval_s = 1
            spin_us = 50
            lock_memory = true
            physics_cpu = 1
            cpu_dma_latency = true
            telemetry_buffers = 4
            command_queue = 16
            "#,
        ))
        .unwrap();
        assert_eq!(s.mode, Mode::Lockstep);
        assert_eq!(s.sc_id, "craft-2");
        assert_eq!(s.spacecraft_id, 42);
        assert_eq!(s.participants, vec![1, 2, 3]);
        assert_eq!(s.participant_timeout, Duration::from_millis(2500));
        assert_eq!(s.presence_timeout, Duration::from_secs(5));
        assert_eq!(s.duration_ns, Some(12_000_000_000));
        assert_eq!(s.overrun_policy, OverrunPolicy::Skip);
        assert_eq!(s.overrun_limit, 3);
        assert_eq!(s.stale_after, Duration::from_millis(50));
        assert_eq!(s.stale_policy, StalePolicy::Zero);
        assert_eq!(s.status_hz, 20.0);
        assert_eq!(s.summary_interval, Duration::from_secs(1));
        assert_eq!(s.spin, Duration::from_micros(50));
        assert!(s.lock_memory);
        assert_eq!(s.physics_cpu, Some(1));
        assert!(s.cpu_dma_latency);
        assert_eq!(s.telemetry_buffers, 4);
        assert_eq!(s.command_queue, 16);
        assert_eq!(s.duration_frames(10_000_000).unwrap(), Some(1200));
        assert!(s.duration_frames(7_000_000).is_err());
        s.validate().unwrap();
    }

    #[test]
    fn errors_name_the_key() {
        let cases = [
            ("colour = 1", "server.colour: unknown key"),
            ("mode = \"fast\"", "server.mode: unknown mode"),
            ("mode = 1", "server.mode: expected a string"),
            ("sc_id = \"a/b\"", "server.sc_id: spacecraft id contains"),
            ("spacecraft_id = -1", "server.spacecraft_id: must be in"),
            (
                "participants = [1, 1]",
                "server.participants: sender id 1 is listed twice",
            ),
            (
                "participants = [\"a\"]",
                "server.participants: unsupported value type",
            ),
            (
                "participant_timeout_s = 0",
                "server.participant_timeout_s: must be > 0",
            ),
            ("duration_s = -1.0", "server.duration_s: must be > 0"),
            (
                "overrun_policy = \"panic\"",
                "server.overrun_policy: unknown policy",
            ),
            (
                "stale_policy = \"drop\"",
                "server.stale_policy: unknown policy",
            ),
            ("status_hz = 1e6", "server.status_hz: must be <= 1000"),
            ("spin_us = 1.5", "server.spin_us: expected an integer"),
            (
                "realtime_priority = 100",
                "server.realtime_priority: must be in 0..=99",
            ),
            (
                "lock_memory = 1",
                "server.lock_memory: expected true or false, got integer 1",
            ),
            (
                "physics_cpu = -2",
                "server.physics_cpu: must be in -1..=4095",
            ),
            (
                "cpu_dma_latency = \"yes\"",
                "server.cpu_dma_latency: expected true or false",
            ),
            (
                "telemetry_buffers = 1",
                "server.telemetry_buffers: must be in 2..=",
            ),
            (
                "stale_after_s = inf",
                "server.stale_after_s: must be finite",
            ),
        ];
        for (text, want) in cases {
            let e = ServerSettings::from_table(&table(text)).unwrap_err();
            assert!(e.to_string().starts_with(want), "{text}: {e}");
        }
        let lockstep_alone =
            ServerSettings::from_table(&table("mode = \"lockstep\"\nparticipants = []")).unwrap();
        assert!(lockstep_alone
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("server.participants:"));
    }

    #[test]
    fn huge_values_print_in_their_shortest_form() {
        for (text, want) in [
            (
                "duration_s = 1e300",
                "server.duration_s: 1e300 s is beyond the maximum simulation time",
            ),
            (
                "participant_timeout_s = 1e300",
                "server.participant_timeout_s: 1e300 s is beyond the maximum simulation time",
            ),
            (
                "status_hz = 1e300",
                "server.status_hz: must be <= 1000 Hz (got 1e300)",
            ),
            (
                "stale_after_s = -1e300",
                "server.stale_after_s: must be > 0 (got -1e300)",
            ),
        ] {
            let e = ServerSettings::from_table(&table(text))
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(want), "{text}: {e}");
            assert!(e.len() < 160, "{text}: {} characters: {e}", e.len());
        }
    }

    #[test]
    fn cli_names() {
        let mut s = ServerSettings::default();
        let e = s
            .apply("stale_after_s", &Value::Float(-1.0), Origin::Cli)
            .unwrap_err();
        assert!(
            e.to_string().starts_with("--stale-after-s: must be > 0"),
            "{e}"
        );
        s.apply("mode", &Value::Str("batch".into()), Origin::Cli)
            .unwrap();
        assert_eq!(s.mode, Mode::Batch);
    }
}
