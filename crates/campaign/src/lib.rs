//! Monte Carlo campaigns with flight code in the loop (`flexdyn campaign plan|run|summarize`).
//!
//! - [`spec`]: the campaign file, validated with field-named errors.
//! - [`command`]: the controller's command line, split into words without a shell.
//! - [`keys`]: TOML paths into a configuration (`panel_pairs[*].panel1.k_nm_rad`).
//! - [`fleet`]: a campaign over a fleet file (`fleet` in place of `base`): each vehicle's
//!   document to disperse, and a run's fleet file and vehicle configurations.
//! - [`readback`]: the parameters of the built model, of one spacecraft or of every vehicle.
//! - [`plan`]: per-run draws from the master seed, redraws of invalid draws, sensor seeds and
//!   the manifest.
//! - [`execute`]: one run = a lockstep server on its own port (the fleet server over a fleet),
//!   an observer participant and the flight code (a controller per `[[controllers]]` entry
//!   over a fleet); `--jobs N` runs N at a time, `--index I` exactly one.
//! - [`summary`]: `summary.csv`, the pass rate with its Wilson interval, worst and failed runs,
//!   figures.
//! - [`verdict`]: each run's outcome, and the exit code of `run` and `summarize` (0 every run
//!   passed, 1 a run could not be run, 2 invalid input, 3 a run failed).
//!
//! A crate of its own (`flexdyn-campaign`), above the server: a run is a server (in this
//! process) with the flight code as a child process, so it depends on `flexdyn-server`, the
//! vehicle layer (the configuration each run disperses), the sinks (the summary's figures) and
//! the model crates. It must never depend on the command line, which uses it; `.ci/layers`
//! checks the order.

#![warn(missing_docs)]

pub mod command;
pub mod criteria;
pub mod execute;
pub mod fleet;
pub mod judge;
pub mod keys;
pub mod plan;
pub mod readback;
pub mod spec;
pub mod summary;
pub mod verdict;

use std::path::PathBuf;

/// Arguments of `flexdyn campaign`.
#[derive(Debug, clap::Subcommand)]
pub enum CampaignCommand {
    /// Write every run's resolved configuration and the manifest; launch nothing.
    Plan {
        /// The campaign file (TOML).
        file: PathBuf,
        /// Output directory.
        #[arg(long, short, value_name = "DIR")]
        output: PathBuf,
        /// Remove the base configuration's random faults (`[[faults]]` with `mtbf_s`): the
        /// same runs without them, to compare pass rates.
        #[arg(long)]
        without_random_faults: bool,
    },
    /// Run the campaign (or one run of it) and write each run's result.json. Exit code: 0 every
    /// run passed, 1 a run could not be run, 2 invalid input, 3 a run failed.
    Run {
        /// The campaign file (TOML).
        file: PathBuf,
        /// Output directory (the plan is written there too).
        #[arg(long, short, value_name = "DIR")]
        output: PathBuf,
        /// Runs at a time on this machine [default: 1].
        #[arg(long, value_name = "N", conflicts_with = "index")]
        jobs: Option<usize>,
        /// Run exactly this run (for Slurm arrays, Kubernetes Indexed Jobs, GNU parallel).
        #[arg(long, value_name = "I")]
        index: Option<u32>,
        /// Record each run to run-NNNN/recording.mcap.
        #[arg(long)]
        record: bool,
        /// Run i's server listens on 127.0.0.1:(base-port + i); 0: each run's server takes a
        /// free port from the OS.
        #[arg(long, value_name = "PORT", default_value_t = 17_600)]
        base_port: u16,
        /// Remove the base configuration's random faults (`[[faults]]` with `mtbf_s`): the
        /// same runs without them, to compare pass rates.
        #[arg(long)]
        without_random_faults: bool,
    },
    /// Write summary.csv, summary.txt and figures from a campaign directory. Exit code: 0 every
    /// planned run passed, 1 a run is missing or could not be run, 3 a run failed.
    Summarize {
        /// The output directory of `plan`/`run`.
        dir: PathBuf,
    },
}

/// What a `flexdyn campaign` subcommand reports: its text (for stderr) and the process exit
/// code ([`verdict`]: 0 every run passed, 1 a run could not be run, 3 a run failed).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Report {
    /// The report's lines; `run` and `summarize` end with the verdict line.
    pub text: String,
    /// The process exit code.
    pub exit_code: u8,
}

/// The campaign in `file`, without its base's random faults if `without_random_faults`.
fn load(
    file: &std::path::Path,
    without_random_faults: bool,
) -> Result<spec::Campaign, spec::CampaignError> {
    let mut c = spec::Campaign::from_file(file)?;
    if without_random_faults {
        c.without_random_faults()?;
    }
    Ok(c)
}

/// Runs a `flexdyn campaign` subcommand; returns its report, or the exit code (2 for invalid
/// input, 1 for a directory that cannot be written or read) and an error message.
pub fn main(cmd: &CampaignCommand) -> Result<Report, (u8, String)> {
    let bad = |e: spec::CampaignError| (verdict::EXIT_INVALID_INPUT, e.to_string());
    match cmd {
        CampaignCommand::Plan {
            file,
            output,
            without_random_faults,
        } => {
            let plan =
                plan::Plan::new(load(file, *without_random_faults).map_err(bad)?).map_err(bad)?;
            let runs = plan
                .write(output)
                .map_err(|e| (1, format!("{}: {e}", output.display())))?;
            let invalid = runs.iter().filter(|r| !r.valid).count();
            let redraws: u32 = runs.iter().map(|r| r.redraws).sum();
            Ok(Report {
                text: format!(
                    "planned {} runs in {} ({} redraws, {invalid} invalid); nothing launched",
                    runs.len(),
                    output.display(),
                    redraws
                ),
                exit_code: verdict::EXIT_PASSED,
            })
        }
        CampaignCommand::Run {
            file,
            output,
            jobs,
            index,
            record,
            base_port,
            without_random_faults,
        } => {
            let plan =
                plan::Plan::new(load(file, *without_random_faults).map_err(bad)?).map_err(bad)?;
            let runs = plan
                .write(output)
                .map_err(|e| (1, format!("{}: {e}", output.display())))?;
            let indices: Vec<u32> = match index {
                Some(i) if *i < plan.campaign.runs => vec![*i],
                Some(i) => {
                    return Err((
                        verdict::EXIT_INVALID_INPUT,
                        format!(
                            "--index: {i} is not a run of this campaign (0..{})",
                            plan.campaign.runs
                        ),
                    ))
                }
                None => (0..plan.campaign.runs).collect(),
            };
            let opts = execute::RunOptions {
                dir: output.clone(),
                base_port: *base_port,
                record: *record,
            };
            let started = std::time::Instant::now();
            let results = execute::execute_many(&plan, &runs, &indices, jobs.unwrap_or(1), &opts);
            let wall = started.elapsed().as_secs_f64();
            let passed = results.iter().filter(|r| r.passed).count();
            let sim: f64 = results.iter().map(|r| r.sim_s).sum();
            let mut text = format!(
                "{} runs in {wall:.1} s ({:.1} runs/min, {:.1} simulated s per wall s): {passed} passed",
                results.len(),
                results.len() as f64 / wall * 60.0,
                sim / wall
            );
            for r in results.iter().filter(|r| r.status != "ok") {
                text.push_str(&format!("\nrun {}: {}", r.run, r.status));
            }
            let verdict = verdict::Verdict::of(results.iter().map(|r| r.outcome));
            text.push_str(&format!("\n{}", verdict.line()));
            Ok(Report {
                text,
                exit_code: verdict.exit_code(),
            })
        }
        CampaignCommand::Summarize { dir } => {
            let s = summary::summarize(dir).map_err(|e| (verdict::EXIT_INVALID_INPUT, e))?;
            Ok(Report {
                text: format!(
                    "{}wrote {} and {} figures\n{}",
                    s.text,
                    dir.join("summary.csv").display(),
                    s.figures.len(),
                    s.verdict.line()
                ),
                exit_code: s.verdict.exit_code(),
            })
        }
    }
}
