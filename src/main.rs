//! The `flexdyn` command-line entry point: parses arguments, initialises logging and calls the
//! library. Every error is reported as one `error: …` line on stderr with a non-zero exit code
//! (2 for invalid input, 1 for a failure while running); nothing here panics on bad input.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use flexdyn::cli::{self, CliError, SimulateArgs};
use flexdyn::config::DEFAULT_CONFIG_TOML;
use flexdyn::logging::print_error;
use flexdyn::server::cli::{run_from_args, RunArgs};

/// Real-time flight-software-in-the-loop spacecraft dynamics: rigid hub + dual-hinged panels.
///
/// Without a subcommand, `flexdyn [OPTIONS]` is `flexdyn run [OPTIONS]`.
#[derive(Debug, Parser)]
#[command(
    name = "flexdyn",
    version,
    about,
    long_about = None,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// The `run` options, accepted without the subcommand.
    #[command(flatten)]
    run: Box<RunArgs>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the server (the default without a subcommand): propagate the spacecraft and talk to
    /// flight code over Zenoh, in real time, lockstep or batch.
    Run(Box<RunArgs>),
    /// Propagate a configuration offline and write the state history as CSV.
    Simulate(SimulateArgs),
    /// Validate a configuration file and print a one-line summary (exit 2 if invalid).
    CheckConfig {
        /// The configuration file (TOML).
        file: PathBuf,
    },
    /// Print the embedded default configuration (scenarios/reference.toml) verbatim.
    PrintDefaultConfig,
}

fn print_default_config() -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_all(DEFAULT_CONFIG_TOML.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|source| CliError::Output {
            target: "stdout".into(),
            source,
        })
}

/// `flexdyn run`: the server until its duration, a signal or an error. Exit code 0 on success,
/// 2 for invalid settings or configuration, 1 for a failure while running.
fn run_server(args: &RunArgs) -> ExitCode {
    match run_from_args(args) {
        Ok(_report) => ExitCode::SUCCESS,
        Err(e) => {
            print_error(&e);
            ExitCode::from(e.exit_code())
        }
    }
}

fn main() -> ExitCode {
    let args = match flexdyn::logging::parse_args::<Cli>() {
        Ok(a) => a,
        Err(code) => return code,
    };
    flexdyn::cli::init_tracing();
    let result = match args.command {
        Some(Command::Simulate(a)) => cli::simulate(&a).map(|report| {
            let _ = writeln!(std::io::stderr(), "{report}");
        }),
        Some(Command::CheckConfig { file }) => cli::check_config(&file).and_then(|summary| {
            let mut out = std::io::stdout().lock();
            writeln!(out, "{summary}")
                .and_then(|()| out.flush())
                .map_err(|source| CliError::Output {
                    target: "stdout".into(),
                    source,
                })
        }),
        Some(Command::PrintDefaultConfig) => print_default_config(),
        Some(Command::Run(a)) => return run_server(&a),
        // No subcommand: `flexdyn run` with the options given.
        None => return run_server(&args.run),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            print_error(&e);
            ExitCode::from(e.exit_code())
        }
    }
}
