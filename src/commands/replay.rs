//! `flexdyn replay`: a recording's raw channels republished to Zenoh with the recorded spacing.

use std::process::ExitCode;

use super::{exit, summary};
use flexdyn_sinks::replay::{replay, ReplayArgs};
use flexdyn_sinks::SinkError;

/// Replays the file; what was published on stderr.
pub fn main(args: &ReplayArgs) -> ExitCode {
    match exit(replay(args), SinkError::exit_code) {
        Ok(r) => {
            let unheard = if r.unheard > 0 {
                format!(
                    "; {} of them while no subscriber matched their key (nobody received those)",
                    r.unheard
                )
            } else {
                String::new()
            };
            let truncated = r
                .truncated
                .as_ref()
                .map_or(String::new(), |why| format!(" (file ends early: {why})"));
            summary(format_args!(
                "replayed {} samples in {:.3} s{unheard}{truncated}",
                r.published, r.wall_s
            ));
            ExitCode::SUCCESS
        }
        Err(code) => code,
    }
}
