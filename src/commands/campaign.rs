//! `flexdyn campaign`: Monte Carlo campaigns (plan, run, summarize), exiting with the verdict.

use std::process::ExitCode;

use super::summary;
use flexdyn_campaign::CampaignCommand;

/// Runs the campaign subcommand; its report on stderr and its verdict as the exit code.
pub fn main(command: &CampaignCommand) -> ExitCode {
    match flexdyn_campaign::main(command) {
        Ok(report) => {
            summary(&report.text);
            ExitCode::from(report.exit_code)
        }
        Err((code, message)) => {
            summary(format_args!("error: {message}"));
            ExitCode::from(code)
        }
    }
}
