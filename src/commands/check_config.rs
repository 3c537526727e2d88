//! `flexdyn check-config FILE`: every check `run` and `simulate` make on a file, and a
//! one-line summary.

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;

use super::{exit, load, CliError};
use flexdyn_server::settings::ServerSettings;
use flexdyn_vehicle::config::warning_message;

/// `flexdyn check-config FILE`: parses, validates and builds the spacecraft; returns one
/// `warning: FILE: field: …` line per implausible value (`SimConfig::warnings`: legal, but
/// almost surely a unit slip), then the summary line `ok: FILE: …`.
///
/// It runs every check that `flexdyn run` and `flexdyn simulate` run on a file, the `[server]`
/// table's included (keys, values, cross-setting rules, and a duration that is a whole number of
/// frames), and says `ok` only when all pass. Warnings do not make it fail.
pub fn check_config(path: &Path) -> Result<String, CliError> {
    let cfg = load(Some(path))?;
    cfg.build_spacecraft().map_err(|source| CliError::Config {
        file: Some(path.to_path_buf()),
        source,
    })?;
    ServerSettings::resolve(&cfg, Some(path), &[])?;
    let mut out = String::new();
    for w in cfg.warnings() {
        out.push_str(&format!("warning: {}\n", warning_message(Some(path), &w)));
    }
    out.push_str(&format!("ok: {}: {}", path.display(), cfg.summary()));
    Ok(out)
}

/// `flexdyn check-config FILE`: the warnings and the summary on stdout (exit 2 if invalid).
pub fn main(file: &Path) -> ExitCode {
    let printed = check_config(file).and_then(|text| {
        let mut out = std::io::stdout().lock();
        writeln!(out, "{text}")
            .and_then(|()| out.flush())
            .map_err(|source| CliError::Output {
                target: "stdout".into(),
                source,
            })
    });
    match exit(printed, CliError::exit_code) {
        Ok(()) => ExitCode::SUCCESS,
        Err(code) => code,
    }
}
