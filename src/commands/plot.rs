//! `flexdyn plot`: PNG figures of a recording or a `simulate`/`export` CSV.

use std::process::ExitCode;

use super::{exit, summary};
use flexdyn_sinks::plot::{plot, PlotArgs};
use flexdyn_sinks::SinkError;

/// Draws the figures; each file written and each figure skipped (and why) on stderr.
pub fn main(args: &PlotArgs) -> ExitCode {
    match exit(plot(args), SinkError::exit_code) {
        Ok(r) => {
            for p in &r.written {
                summary(format_args!("wrote {}", p.display()));
            }
            for (figure, why) in &r.skipped {
                summary(format_args!("skipped {figure}: {why}"));
            }
            ExitCode::SUCCESS
        }
        Err(code) => code,
    }
}
