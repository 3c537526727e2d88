//! `flexdyn print-default-config`: the embedded reference spacecraft
//! (`scenarios/reference.toml`) verbatim.

use std::io::Write;
use std::process::ExitCode;

use super::{exit, CliError};
use flexdyn_vehicle::config::DEFAULT_CONFIG_TOML;

/// Writes the embedded default configuration to stdout.
pub fn print_default_config() -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_all(DEFAULT_CONFIG_TOML.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|source| CliError::Output {
            target: "stdout".into(),
            source,
        })
}

/// `flexdyn print-default-config`.
pub fn main() -> ExitCode {
    match exit(print_default_config(), CliError::exit_code) {
        Ok(()) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}
