//! `flexdyn export`: one CSV per topic of a recording.

use std::process::ExitCode;

use super::{exit, summary};
use flexdyn_sinks::export::{export, ExportArgs};
use flexdyn_sinks::SinkError;

/// Exports the file; each CSV written and its rows on stderr.
pub fn main(args: &ExportArgs) -> ExitCode {
    match exit(export(args), SinkError::exit_code) {
        Ok(written) => {
            for (path, rows) in &written {
                summary(format_args!("{}: {rows} rows", path.display()));
            }
            ExitCode::SUCCESS
        }
        Err(code) => code,
    }
}
