//! The `flexdyn` binary's subcommands, one file each. `src/main.rs` parses the arguments and
//! calls the subcommand's `main`, which prints its summary or its error and returns the exit
//! code. The work itself is in plain functions that the tests call (`simulate::simulate_to`,
//! `fleet::fleet_to`, `check_config::check_config`).
//!
//! Exit codes: 0 on success, 2 for invalid input (configuration, arguments, settings), 1 for a
//! failure while running; `record` exits 3 when the file it wrote is incomplete, `campaign` with
//! its verdict. Every error is one `error: …` line on stderr; nothing panics on bad input.

use std::io;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use flexdyn_kernel::numfmt::Num;
use flexdyn_proto::client::logging::print_error;
use flexdyn_server::error::SettingsError;
use flexdyn_vehicle::config::{config_message, whole_ns, ConfigError, SimConfig};

pub mod campaign;
pub mod check_config;
pub mod checkpoint;
pub mod export;
pub mod fleet;
pub mod gateway;
pub mod plot;
pub mod print_default_config;
pub mod record;
pub mod replay;
pub mod run;
pub mod simulate;
pub mod view;

/// The options `simulate` and `fleet` share: how long to fly, and where the CSV goes.
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct OfflineRun {
    /// Simulated duration in seconds; must be a whole number of RK4 steps.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 10.0,
        allow_negative_numbers = true
    )]
    pub duration_s: f64,
    /// CSV output file; `-` (or no option) writes to standard output.
    #[arg(long, short, value_name = "FILE.csv")]
    pub output: Option<PathBuf>,
}

impl Default for OfflineRun {
    fn default() -> Self {
        Self {
            duration_s: 10.0,
            output: None,
        }
    }
}

impl OfflineRun {
    /// Opens the CSV destination (creating, and truncating, the file) and names it for errors:
    /// `stdout`, or ``CSV output `FILE` ``.
    pub fn open_csv(&self) -> Result<(Box<dyn io::Write>, String), CliError> {
        match self.output.as_deref() {
            None => Ok((Box::new(io::stdout().lock()), "stdout".to_owned())),
            Some(p) if p == Path::new("-") => {
                Ok((Box::new(io::stdout().lock()), "stdout".to_owned()))
            }
            Some(p) => {
                let target = format!("CSV output `{}`", p.display());
                match std::fs::File::create(p) {
                    Ok(file) => Ok((Box::new(file), target)),
                    Err(source) => Err(CliError::Output { target, source }),
                }
            }
        }
    }
}

/// An error of an offline subcommand.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CliError {
    /// The configuration is invalid or unreadable.
    #[error("{}", config_message(file.as_deref(), source))]
    Config {
        /// The file, or `None` for the embedded default.
        file: Option<PathBuf>,
        /// The error; it names the field.
        #[source]
        source: ConfigError,
    },
    /// A command-line value is invalid.
    #[error("{flag}: {problem}")]
    Arg {
        /// The option, e.g. `--log-every-s`.
        flag: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// The `[server]` table is invalid (checked by `check-config`, as `run` would); the error
    /// names the file, `server.<key>` and its line.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The propagated state stopped being finite; the row was not written.
    #[error(
        "the state became non-finite at step {step} (t = {} s): {quantity} is NaN or infinite; \
         stopping without writing that row (check the configuration's rates, stiffnesses and \
         wrenches for values the step cannot resolve)",
        Num(*t_s)
    )]
    NonFinite {
        /// The RK4 step count at the row.
        step: u64,
        /// \[s\] simulation time of the row.
        t_s: f64,
        /// The first non-finite quantity, by its CSV column name.
        quantity: String,
    },
    /// A checkpoint is refused (damaged, of another version, or not fitting this run).
    #[error("checkpoint `{}`: {source}", file.display())]
    Checkpoint {
        /// The checkpoint file.
        file: PathBuf,
        /// Why.
        #[source]
        source: flexdyn_vehicle::checkpoint::CheckpointError,
    },
    /// Reading an input failed.
    #[error("cannot read {target}: {source}")]
    Input {
        /// What was being read.
        target: String,
        /// The I/O error.
        #[source]
        source: io::Error,
    },
    /// Writing the output failed.
    #[error("cannot write {target}: {source}")]
    Output {
        /// Where the output was going.
        target: String,
        /// The I/O error.
        #[source]
        source: io::Error,
    },
}

impl CliError {
    /// The process exit code for this error: 2 for invalid input (configuration or arguments),
    /// 1 for a failure while running (output not writable).
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Config { .. }
            | CliError::Arg { .. }
            | CliError::Settings(_)
            | CliError::Checkpoint { .. }
            | CliError::Input { .. } => 2,
            CliError::Output { .. } | CliError::NonFinite { .. } => 1,
        }
    }
}

/// [`flexdyn_vehicle::config::load_config`], its error as a [`CliError::Config`] naming the file.
pub(crate) fn load(path: Option<&Path>) -> Result<SimConfig, CliError> {
    flexdyn_vehicle::config::load_config(path).map_err(|source| CliError::Config {
        file: path.map(Path::to_path_buf),
        source,
    })
}

/// A duration option as a whole number of steps.
pub(crate) fn whole_steps(
    flag: &'static str,
    seconds: f64,
    step_ns: u64,
    allow_zero: bool,
) -> Result<u64, CliError> {
    let step_s = step_ns as f64 * 1e-9;
    if !seconds.is_finite() {
        return Err(CliError::Arg {
            flag,
            problem: format!("must be finite (got {seconds})"),
        });
    }
    if seconds < 0.0 || (!allow_zero && seconds == 0.0) {
        let bound = if allow_zero { ">= 0" } else { "> 0" };
        return Err(CliError::Arg {
            flag,
            problem: format!("must be {bound} (got {seconds})"),
        });
    }
    match whole_ns(seconds) {
        Some(ns) if ns % step_ns == 0 => Ok(ns / step_ns),
        _ => Err(CliError::Arg {
            flag,
            problem: format!(
                "{seconds} s is not a whole number of RK4 steps (step = {step_s} s = {step_ns} ns)"
            ),
        }),
    }
}

/// The exit code of a subcommand's result; an error is printed first, as `error: …`.
pub(crate) fn exit<T, E>(result: Result<T, E>, code: impl FnOnce(&E) -> u8) -> Result<T, ExitCode>
where
    E: std::fmt::Display,
{
    result.map_err(|e| {
        print_error(&e);
        ExitCode::from(code(&e))
    })
}

/// Prints `line` on stderr (a subcommand's summary); a closed stderr is not an error.
pub(crate) fn summary(line: impl std::fmt::Display) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{line}");
}
