//! The campaign's verdict over its runs, and the exit code a CI job reads from it.
//!
//! | code | meaning |
//! |---|---|
//! | 0 | every run ran and passed every criterion |
//! | 1 | at least one run could not be run (no valid draw, the controller could not be started or never joined, the server could not start, a run missing from the directory): the verdict is incomplete |
//! | 2 | invalid input (the campaign file, its base, `--index`), as in the rest of the CLI |
//! | 3 | every run ran, and at least one failed: a criterion not met, the controller exited before the end or stopped answering, the state became non-finite |
//!
//! "Could not run" wins over "failed": a retry after fixing the set-up can only confirm or
//! replace an incomplete verdict.

use serde::{Deserialize, Serialize};

/// What one run came to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// It ran to the end and met every criterion.
    Passed,
    /// It ran, and the flight code did not meet the campaign: a criterion failed, the
    /// controller exited before the end or stopped answering a tick, or the state became
    /// non-finite.
    Failed,
    /// It could not be run: no valid draw, the controller could not be started or never joined
    /// the lockstep, the server or the observer could not start, or states went missing.
    NotRun,
}

/// Exit code: every run passed.
pub const EXIT_PASSED: u8 = 0;
/// Exit code: at least one run could not be run (or is missing).
pub const EXIT_NOT_RUN: u8 = 1;
/// Exit code: invalid input (campaign file, base configuration, options).
pub const EXIT_INVALID_INPUT: u8 = 2;
/// Exit code: every run ran, and at least one failed.
pub const EXIT_FAILED: u8 = 3;

/// The runs counted by outcome.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Verdict {
    /// Runs that passed.
    pub passed: u32,
    /// Runs that ran and failed.
    pub failed: u32,
    /// Runs that could not be run (or have no result).
    pub not_run: u32,
}

impl Verdict {
    /// Counts `outcomes`.
    pub fn of(outcomes: impl IntoIterator<Item = Outcome>) -> Self {
        let mut v = Self::default();
        for o in outcomes {
            match o {
                Outcome::Passed => v.passed += 1,
                Outcome::Failed => v.failed += 1,
                Outcome::NotRun => v.not_run += 1,
            }
        }
        v
    }

    /// The process exit code (module docs).
    pub fn exit_code(&self) -> u8 {
        if self.not_run > 0 {
            EXIT_NOT_RUN
        } else if self.failed > 0 {
            EXIT_FAILED
        } else {
            EXIT_PASSED
        }
    }

    /// One line for the report: `verdict: …`.
    pub fn line(&self) -> String {
        let n = self.passed + self.failed + self.not_run;
        let what = match self.exit_code() {
            EXIT_NOT_RUN => format!(
                "INCOMPLETE: {} of {n} runs could not be run ({} failed, {} passed)",
                self.not_run, self.failed, self.passed
            ),
            EXIT_FAILED => format!("FAILED: {} of {n} runs failed", self.failed),
            _ => format!("PASSED: all {n} runs passed"),
        };
        format!("verdict: {what} (exit code {})", self.exit_code())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Outcome::{Failed, NotRun, Passed};

    #[test]
    fn could_not_run_wins_over_failed_which_wins_over_passed() {
        for (outcomes, code) in [
            (vec![Passed, Passed], 0),
            (vec![], 0),
            (vec![Passed, Failed], 3),
            (vec![Failed, NotRun, Passed], 1),
            (vec![NotRun], 1),
        ] {
            let v = Verdict::of(outcomes.clone());
            assert_eq!(v.exit_code(), code, "{outcomes:?}");
            assert!(
                v.line().ends_with(&format!("(exit code {code})")),
                "{}",
                v.line()
            );
        }
    }
}
