//! The error of the sink subcommands (`record`, `replay`, `export`, `view`, `plot`).

use std::path::PathBuf;

use super::mcap_file::RecordError;
use flexdyn_proto::client::transport::ZenohConfigError;

/// Why a sink subcommand failed. Every variant names the file, option or operation.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SinkError {
    /// A command-line value is invalid.
    #[error("{flag}: {problem}")]
    Arg {
        /// The option, e.g. `--speed`.
        flag: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// An input file cannot be read or is not what the command expects.
    #[error("{}: {problem}", path.display())]
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// Writing an output failed.
    #[error("cannot write {}: {problem}", path.display())]
    Output {
        /// The file or directory.
        path: PathBuf,
        /// What failed.
        problem: String,
    },
    /// The recording could not be written.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// The Zenoh configuration cannot be built.
    #[error(transparent)]
    ZenohConfig(#[from] ZenohConfigError),
    /// A Zenoh operation failed.
    #[error("zenoh: cannot {what}: {message}")]
    Zenoh {
        /// What was being done.
        what: &'static str,
        /// What Zenoh reported.
        message: String,
    },
    /// `flexdyn replay`: no subscriber appeared for any of the recording's keys, so there was
    /// nobody to replay to.
    #[error(
        "no subscriber matched any of the recording's {keys} keys within {waited_s} s \
         (--wait-subscriber-s), so nothing was replayed: start the subscriber (`flexdyn view`, \
         `flexdyn record`, `flexdyn-monitor`, your ground tool) on the replay's endpoint (the \
         replay {endpoints}; the tools connect to tcp/127.0.0.1:7447 by default)"
    )]
    NoSubscriber {
        /// The keys replayed.
        keys: usize,
        /// \[s\] how long the replay waited.
        waited_s: f64,
        /// Where the replay listens or connects (`listens on tcp/…`), for the message.
        endpoints: String,
    },
    /// Anything else that stops the command (runtime, signal handlers, the viewer server).
    #[error("{0}")]
    Runtime(String),
}

impl SinkError {
    /// 2 for invalid input (options, input files), 1 for a failure while running.
    pub fn exit_code(&self) -> u8 {
        match self {
            SinkError::Arg { .. } | SinkError::Input { .. } | SinkError::ZenohConfig(_) => 2,
            _ => 1,
        }
    }

    pub(crate) fn zenoh(what: &'static str, e: impl std::fmt::Display) -> Self {
        SinkError::Zenoh {
            what,
            message: flexdyn_proto::client::transport::clean_zenoh_message(&e.to_string()),
        }
    }
}

/// The tokio runtime of a sink subcommand (two workers: Zenoh's I/O and ours).
pub(crate) fn runtime() -> Result<tokio::runtime::Runtime, SinkError> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| SinkError::Runtime(format!("cannot start the tokio runtime: {e}")))
}
