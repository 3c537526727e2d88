//! `flexdyn plot`: PNG figures of a recording or a `simulate`/`export` CSV.

use std::process::ExitCode;

use super::{exit, summary};
use flexdyn_sinks::plot::{plot_with, PlotArgs};
use flexdyn_sinks::SinkError;

/// Draws the figures; the reading progress, each file as it is written and each figure
/// skipped (and why) on stderr.
pub fn main(args: &PlotArgs) -> ExitCode {
    let mut written = |p: &std::path::Path| summary(format_args!("wrote {}", p.display()));
    match exit(plot_with(args, &mut written), SinkError::exit_code) {
        Ok(r) => {
            for (figure, why) in &r.skipped {
                summary(format_args!("skipped {figure}: {why}"));
            }
            ExitCode::SUCCESS
        }
        Err(code) => code,
    }
}
