//! `flexdyn view`: the live stream (or a recording) served to Foxglove over its WebSocket
//! protocol, and to a browser as a web page on the same port (a client of that protocol).

use std::process::ExitCode;

use super::{exit, summary};
use flexdyn_sinks::view::{view, ViewArgs};
use flexdyn_sinks::SinkError;

/// Serves until stopped; the port and the samples served on stderr.
pub fn main(args: &ViewArgs) -> ExitCode {
    match exit(view(args), SinkError::exit_code) {
        Ok(r) => {
            summary(format_args!(
                "viewer on port {} stopped after {} samples",
                r.port, r.samples
            ));
            ExitCode::SUCCESS
        }
        Err(code) => code,
    }
}
