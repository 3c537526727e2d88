//! Typed errors of the server layer (STYLE 13): settings, Zenoh configuration, and the run itself.

use std::path::{Path, PathBuf};

pub use flexdyn_proto::client::transport::ZenohConfigError;

use flexdyn_vehicle::config::{config_message, At, ConfigError, SourceMap};

/// An invalid server setting. The message starts with the setting's name as the user wrote it:
/// `server.<key>` for the `[server]` TOML table, `--<flag>` for a command-line option.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SettingsError {
    /// A key of the `[server]` table that the server does not know.
    #[error("server.{key}: unknown key (expected one of: {expected})")]
    UnknownKey {
        /// The key as written (without the `server.` prefix).
        key: String,
        /// Every accepted key, comma-separated.
        expected: String,
    },
    /// A value of the wrong type or out of range.
    #[error("{name}: {problem}")]
    Invalid {
        /// `server.<key>` or `--<flag>`.
        name: String,
        /// What is wrong, with the offending value.
        problem: String,
    },
    /// A `[server]` key of a configuration file: the error, prefixed with the file's name and
    /// followed by the key's line and column, as every other section's errors are.
    #[error("{}{source}{at}", file.as_ref().map_or(String::new(), |f| format!("{}: ", f.display())))]
    InFile {
        /// The configuration file (`None`: the embedded default).
        file: Option<PathBuf>,
        /// The error; it names `server.<key>`.
        source: Box<SettingsError>,
        /// Where the key is in the file.
        at: At,
    },
}

impl SettingsError {
    /// The `[server]` key the error is about (`duration_s`), if it names one.
    pub fn key(&self) -> Option<&str> {
        match self {
            SettingsError::UnknownKey { key, .. } => Some(key),
            SettingsError::Invalid { name, .. } => name.strip_prefix("server."),
            SettingsError::InFile { source, .. } => source.key(),
        }
    }

    /// The error as one about the file `file` whose text is `source`: prefixed with the file's
    /// name and followed by the position of `server.<key>`.
    pub(crate) fn in_file(self, file: Option<&Path>, source: &str) -> Self {
        let at = match (&self, self.key()) {
            (SettingsError::UnknownKey { key, .. }, _) => {
                SourceMap::locate_key(source, &format!("server.{key}"))
            }
            (_, Some(key)) => SourceMap::locate(source, &format!("server.{key}")),
            (_, None) => At::default(),
        };
        SettingsError::InFile {
            file: file.map(Path::to_path_buf),
            source: Box::new(self),
            at,
        }
    }

    /// The error named as the command-line option `--<key>` (the user set it there).
    pub(crate) fn into_option(self) -> Self {
        match self {
            SettingsError::Invalid { name, problem } => {
                let key = name.strip_prefix("server.").unwrap_or(&name);
                SettingsError::Invalid {
                    name: super::settings::Origin::Cli.name(key),
                    problem,
                }
            }
            other => other,
        }
    }
}

/// Why a server run failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ServerError {
    /// An invalid server setting (`[server]` table or command line).
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The simulation configuration is invalid or unreadable.
    #[error("{}", config_message(file.as_deref(), source))]
    Config {
        /// The file, or `None` for the embedded default.
        file: Option<PathBuf>,
        /// The error; it names the TOML field.
        #[source]
        source: ConfigError,
    },
    /// The Zenoh configuration cannot be built.
    #[error(transparent)]
    ZenohConfig(#[from] ZenohConfigError),
    /// A Zenoh operation failed (opening the session, declaring a publisher, ...).
    #[error("zenoh: cannot {what}: {message}")]
    Zenoh {
        /// What was being done, e.g. `open the session`.
        what: &'static str,
        /// What Zenoh reported.
        message: String,
    },
    /// Lockstep: some participants did not show up (no liveliness token
    /// `flexdyn/<sc>/participant/<id>`, or no subscriber on the state topic) before tick 0.
    #[error(
        "lockstep participant(s) {} not present after {} s (server.presence_timeout_s): \
         start the flight code and check it connects to this server and declares its \
         liveliness token flexdyn/{sc_id}/participant/<id>",
        list_ids(missing),
        flexdyn_kernel::numfmt::Rounded(*waited_s, 3)
    )]
    ParticipantsAbsent {
        /// Sender ids whose token (or state subscriber) was not seen.
        missing: Vec<u32>,
        /// The string spacecraft id of the key expressions.
        sc_id: String,
        /// \[s\] how long the server waited.
        waited_s: f64,
    },
    /// Lockstep: a participant did not answer a tick in time.
    #[error(
        "lockstep participant {participant} did not answer tick {tick} within {} s \
         (server.participant_timeout_s); stopping the run",
        flexdyn_kernel::numfmt::Rounded(*timeout_s, 4)
    )]
    ParticipantTimeout {
        /// Sender id of the first participant that has not answered.
        participant: u32,
        /// The tick whose answer is missing.
        tick: u64,
        /// \[s\] the configured timeout.
        timeout_s: f64,
    },
    /// Fleet mode (`flexdyn run --fleet`): what went wrong, and with which vehicle (a
    /// participant timeout names the vehicle and the participant).
    #[error("vehicle {vehicle:?}: {source}")]
    Vehicle {
        /// The vehicle's id (`flexdyn/<id>/…`).
        vehicle: String,
        /// What went wrong.
        #[source]
        source: Box<ServerError>,
    },
    /// The fleet file (or a vehicle's spacecraft configuration) is invalid.
    #[error(transparent)]
    Fleet(#[from] flexdyn_vehicle::world::FleetError),
    /// Real time with `overrun_policy = "abort"`: too many consecutive overruns.
    #[error(
        "aborting: {consecutive} consecutive frame overruns at tick {tick} exceed \
         server.overrun_limit = {limit} (overrun_policy = \"abort\")"
    )]
    OverrunLimit {
        /// The tick at which the limit was exceeded.
        tick: u64,
        /// Consecutive overrun frames.
        consecutive: u32,
        /// The configured limit.
        limit: u32,
    },
    /// The propagated state (or a quantity derived from it) stopped being finite: the run is
    /// stopped before that frame is published.
    #[error(
        "the state became non-finite at tick {tick} (t = {} s): {quantity} is NaN or \
         infinite; stopping the run without publishing it (check the configuration's rates, \
         stiffnesses and wrenches for values the step cannot resolve)",
        flexdyn_kernel::numfmt::Num(*t_s)
    )]
    NonFinite {
        /// The tick whose state is not finite.
        tick: u64,
        /// \[s\] its simulation time.
        t_s: f64,
        /// The first non-finite quantity, by its CSV column name.
        quantity: String,
    },
    /// `--record`: the recording could not be created or written.
    #[error(transparent)]
    Record(#[from] flexdyn_sinks::mcap_file::RecordError),
    /// A real-time setting the OS refused (`lock_memory`, `physics_cpu`, `cpu_dma_latency`,
    /// `realtime_priority`): the run does not start without what it asked for.
    #[error("{setting}: {problem}")]
    Realtime {
        /// The setting, `server.<key>`.
        setting: &'static str,
        /// What the OS refused and what the setting needs.
        problem: String,
    },
    /// A checkpoint to resume from that cannot be used.
    #[error("checkpoint `{}`: {problem}", file.display())]
    Checkpoint {
        /// The checkpoint file.
        file: PathBuf,
        /// Why it is refused.
        problem: String,
    },
    /// A thread of the server could not be started or panicked.
    #[error("internal error: {0}")]
    Internal(String),
    /// Installing the signal handlers failed.
    #[error("cannot install the {signal} handler: {source}")]
    Signal {
        /// `SIGINT` or `SIGTERM`.
        signal: &'static str,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

fn list_ids(ids: &[u32]) -> String {
    ids.iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

impl ServerError {
    /// Process exit code: 2 for invalid input (settings, configuration files), 1 for a failure
    /// while running (participant timeout, overrun abort, Zenoh failure).
    pub fn exit_code(&self) -> u8 {
        match self {
            ServerError::Settings(_)
            | ServerError::Config { .. }
            | ServerError::ZenohConfig(_)
            | ServerError::Fleet(_) => 2,
            ServerError::Vehicle { source, .. } => source.exit_code(),
            _ => 1,
        }
    }

    /// A [`ServerError::Zenoh`] from any Zenoh error.
    pub(crate) fn zenoh(what: &'static str, e: impl std::fmt::Display) -> Self {
        ServerError::Zenoh {
            what,
            message: flexdyn_proto::client::transport::clean_zenoh_message(&e.to_string()),
        }
    }
}
