//! `flexdyn run` (and `flexdyn` without a subcommand): the server, one spacecraft or a fleet
//! (`--fleet`), until its duration, a signal or an error.

use std::process::ExitCode;

use super::exit;
use flexdyn_server::cli::RunArgs;
use flexdyn_server::ServerError;

/// Runs the server. Exit code 0 on success, 2 for invalid settings or configuration, 1 for a
/// failure while running.
pub fn main(args: &RunArgs) -> ExitCode {
    let result = match &args.fleet {
        Some(fleet) => flexdyn_server::fleet::run_from_args(args, fleet).map(drop),
        None => flexdyn_server::cli::run_from_args(args).map(drop),
    };
    match exit(result, ServerError::exit_code) {
        Ok(()) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}
