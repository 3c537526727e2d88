//! Monte Carlo campaigns with flight code in the loop (`flexdyn campaign plan|run|summarize`).
//!
//! - [`spec`]: the campaign file, validated with field-named errors.
//! - [`command`]: the controller's command line, split into words without a shell.
//! - [`keys`]: TOML paths into a configuration (`panel_pairs[*].panel1.k_nm_rad`).
//! - [`fleet`]: a campaign over a fleet file (`fleet` in place of `base`): each vehicle's
//!   document to disperse, and a run's fleet file and vehicle configurations.
//! - [`fork`]: a campaign whose runs all start from one checkpoint (`start_from`): the file
//!   read and checked, what may be dispersed after it, what a run observes from its tick.
//! - [`readback`]: the parameters of the built model, of one spacecraft or of every vehicle.
//! - [`plan`]: per-run draws from the master seed, redraws of invalid draws, sensor seeds and
//!   the manifest.
//! - [`execute`]: one run = a lockstep server on its own port (the fleet server over a fleet),
//!   an observer participant and the flight code (a controller per `[[controllers]]` entry
//!   over a fleet); `--jobs N` runs N at a time, `--index I` exactly one.
//! - [`slurm`]: the campaign as a Slurm job array and a dependent summarize job (`submit
//!   --slurm`, `resubmit`), and the tasks that could not run as Slurm tells it.
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
pub mod fork;
pub mod judge;
pub mod keys;
pub mod plan;
pub mod readback;
pub mod slurm;
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
    /// Fly the campaign's base configuration, undispersed, as its runs are flown (lockstep
    /// server, controller, observer) up to --at-s and save a checkpoint there: the file a
    /// campaign's `start_from` starts every run from.
    Checkpoint {
        /// The campaign file (TOML), without `start_from`.
        file: PathBuf,
        /// \[s\] when: a whole number of frames, after t = 0 and before the campaign's
        /// duration_s.
        #[arg(long, value_name = "SECONDS")]
        at_s: f64,
        /// The checkpoint file to write.
        #[arg(long, short, value_name = "FILE")]
        output: PathBuf,
        /// The server listens on 127.0.0.1:PORT; 0: a free port from the OS.
        #[arg(long, value_name = "PORT", default_value_t = 0)]
        base_port: u16,
    },
    /// Write summary.csv, summary.txt and figures from a campaign directory. Exit code: 0 every
    /// planned run passed, 1 a run is missing or could not be run, 3 a run failed.
    Summarize {
        /// The output directory of `plan`/`run`.
        dir: PathBuf,
        /// First mark the runs of this Slurm array job that ended without a result as not run,
        /// with their Slurm state (what the summarize job of `submit --slurm` does).
        #[arg(long, value_name = "JOB_ID")]
        slurm_array: Option<String>,
    },
    /// Plan the campaign into a directory every node sees and submit it to Slurm: a job array
    /// with one task per run (the campaign's `[resources]` per task), then a summarize job
    /// after it. Prints the job ids; with --wait, waits and exits with the verdict as `run`.
    Submit {
        /// The campaign file (TOML).
        file: PathBuf,
        /// Output directory, on a file system every node mounts at the same path.
        #[arg(long, short, value_name = "DIR")]
        output: PathBuf,
        /// Submit to Slurm (`sbatch`; the only scheduler today).
        #[arg(long, required = true)]
        slurm: bool,
        /// Wait for the summarize job, then report and exit with the campaign's verdict.
        #[arg(long)]
        wait: bool,
        /// `sbatch --partition` (default: the cluster's default partition).
        #[arg(long, value_name = "NAME")]
        partition: Option<String>,
        /// The flexdyn binary the tasks run, at the same path on every node [default: this
        /// one].
        #[arg(long, value_name = "PATH")]
        flexdyn: Option<PathBuf>,
        /// Remove the base configuration's random faults (`[[faults]]` with `mtbf_s`).
        #[arg(long)]
        without_random_faults: bool,
    },
    /// Submit again, to the same scheduler and with the same options, exactly the runs of a
    /// submitted campaign that have no passed or failed result (lost nodes, time limits,
    /// cancelled tasks), then a new summarize job.
    Resubmit {
        /// The output directory of `submit`.
        dir: PathBuf,
        /// Wait for the summarize job, then report and exit with the campaign's verdict.
        #[arg(long)]
        wait: bool,
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

/// `output` as a campaign file `campaign` names it in `start_from` (relative to the campaign
/// file's folder): the path below that folder, else the absolute path.
fn relative_to_campaign(campaign: &std::path::Path, output: &std::path::Path) -> PathBuf {
    let abs = |p: &std::path::Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_owned());
    let out = abs(output);
    let folder = abs(campaign
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new(".")));
    out.strip_prefix(&folder)
        .map_or(out.clone(), |p| p.to_owned())
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
            // Simulated time flown: a forked run starts at its checkpoint's time.
            let t_start_s = plan.campaign.start_from.as_ref().map_or(0.0, |s| s.t_s());
            let sim: f64 = results
                .iter()
                .filter(|r| r.sim_s > 0.0)
                .map(|r| r.sim_s - t_start_s)
                .sum();
            let mut text = format!(
                "{} runs in {wall:.1} s ({:.1} runs/min, {:.1} simulated s per wall s): {passed} passed",
                results.len(),
                results.len() as f64 / wall * 60.0,
                sim / wall
            );
            if let Some(start) = &plan.campaign.start_from {
                text.push_str(&format!("\n{}", fork::line(start)));
            }
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
        CampaignCommand::Checkpoint {
            file,
            at_s,
            output,
            base_port,
        } => {
            let c = load(file, false).map_err(bad)?;
            let (cfg, tick) = fork::checkpoint_at(&c, *at_s).map_err(bad)?;
            let started = std::time::Instant::now();
            let t_ns = execute::nominal_checkpoint(&c, cfg, tick, output, *base_port)
                .map_err(|e| (verdict::EXIT_NOT_RUN, format!("{}: {e}", file.display())))?;
            // start_from is read relative to the campaign file, not to where this runs.
            let from_campaign = relative_to_campaign(file, output);
            Ok(Report {
                text: format!(
                    "wrote {} at tick {tick} (t = {} s) in {:.1} s: start_from = \"{}\" \
                     (relative to the campaign file) starts every run of the campaign there",
                    output.display(),
                    flexdyn_kernel::numfmt::Num(t_ns as f64 * 1e-9),
                    started.elapsed().as_secs_f64(),
                    from_campaign.display()
                ),
                exit_code: verdict::EXIT_PASSED,
            })
        }
        CampaignCommand::Summarize { dir, slurm_array } => {
            let mut text = String::new();
            if let Some(job) = slurm_array {
                text = mark_slurm_failures(dir, job)?;
            }
            summarize(dir, text)
        }
        CampaignCommand::Submit {
            file,
            output,
            slurm: _,
            wait,
            partition,
            flexdyn,
            without_random_faults,
        } => {
            let campaign = load(file, *without_random_faults).map_err(bad)?;
            let resources = campaign.resources;
            let plan = plan::Plan::new(campaign).map_err(bad)?;
            let runs = plan
                .write(output)
                .map_err(|e| (1, format!("{}: {e}", output.display())))?;
            let absolute = |p: &std::path::Path| {
                std::fs::canonicalize(p).map_err(|e| (1, format!("{}: {e}", p.display())))
            };
            let opts = slurm::SlurmOptions {
                flexdyn: match flexdyn {
                    Some(f) => absolute(f)?,
                    None => std::env::current_exe()
                        .map_err(|e| (1, format!("the flexdyn binary's path: {e}")))?,
                },
                partition: partition.clone(),
                without_random_faults: *without_random_faults,
            };
            let indices: Vec<u32> = runs.iter().map(|r| r.run).collect();
            let dir = absolute(output)?;
            let sub = slurm::submit(&absolute(file)?, &dir, &indices, &resources, &opts)
                .map_err(|e| (1, e))?;
            submitted(&dir, &sub, *wait)
        }
        CampaignCommand::Resubmit { dir, wait } => {
            let last = slurm::submissions(dir)
                .map_err(|e| (verdict::EXIT_INVALID_INPUT, e))?
                .pop()
                .ok_or_else(|| {
                    (
                        verdict::EXIT_INVALID_INPUT,
                        format!("{}: no submission recorded", dir.display()),
                    )
                })?;
            let plans = summary::planned_runs(dir).map_err(|e| (verdict::EXIT_INVALID_INPUT, e))?;
            let missing = slurm::missing_runs(dir, &plans);
            if missing.is_empty() {
                return summarize(
                    dir,
                    "every planned run has a result: nothing to resubmit\n".into(),
                );
            }
            // The reruns write their own results: the not-run ones go.
            for p in plans.iter().filter(|p| missing.contains(&p.run)) {
                let _ = std::fs::remove_file(dir.join(&p.dir).join("result.json"));
            }
            let resources = load(&last.campaign, last.without_random_faults)
                .map_err(bad)?
                .resources;
            let opts = slurm::SlurmOptions {
                flexdyn: last.flexdyn.clone(),
                partition: last.partition.clone(),
                without_random_faults: last.without_random_faults,
            };
            let dir =
                std::fs::canonicalize(dir).map_err(|e| (1, format!("{}: {e}", dir.display())))?;
            let sub = slurm::submit(&last.campaign, &dir, &missing, &resources, &opts)
                .map_err(|e| (1, e))?;
            submitted(&dir, &sub, *wait)
        }
    }
}

/// The report of `summarize`, after the lines in `text`.
fn summarize(dir: &std::path::Path, text: String) -> Result<Report, (u8, String)> {
    let s = summary::summarize(dir).map_err(|e| (verdict::EXIT_INVALID_INPUT, e))?;
    Ok(Report {
        text: format!(
            "{text}{}wrote {} and {} figures\n{}",
            s.text,
            dir.join("summary.csv").display(),
            s.figures.len(),
            s.verdict.line()
        ),
        exit_code: s.verdict.exit_code(),
    })
}

/// Marks the tasks of Slurm array `job` that ended without a result as not run; one line per
/// run marked.
fn mark_slurm_failures(dir: &std::path::Path, job: &str) -> Result<String, (u8, String)> {
    let plans = summary::planned_runs(dir).map_err(|e| (verdict::EXIT_INVALID_INPUT, e))?;
    let states = slurm::task_states(job).map_err(|e| (verdict::EXIT_NOT_RUN, e))?;
    // The array's tasks as submitted (the record of the submission), else those Slurm names.
    let indices: Vec<u32> = match slurm::submissions(dir)
        .ok()
        .and_then(|all| all.into_iter().find(|s| s.array_job == job))
    {
        Some(sub) => sub.indices,
        None => states.iter().map(|t| t.task).collect(),
    };
    let marked = slurm::mark_not_run(dir, &plans, job, &indices, &states).map_err(|e| (1, e))?;
    Ok(marked
        .iter()
        .map(|run| format!("run {run} could not run on Slurm (its result.json says why)\n"))
        .collect())
}

/// The report of a submission: its job ids; with `wait`, the campaign's verdict once its
/// summarize job has ended.
fn submitted(
    dir: &std::path::Path,
    sub: &slurm::Submission,
    wait: bool,
) -> Result<Report, (u8, String)> {
    let head = format!(
        "submitted {} runs as Slurm array job {} and the summarize job {} (job scripts and logs in {})\n",
        sub.indices.len(),
        sub.array_job,
        sub.summarize_job,
        dir.join(slurm::SLURM_DIR).display()
    );
    if !wait {
        return Ok(Report {
            text: format!(
                "{head}when the summarize job has ended: flexdyn campaign summarize {}",
                dir.display()
            ),
            exit_code: verdict::EXIT_PASSED,
        });
    }
    slurm::wait_for(&sub.summarize_job).map_err(|e| (1, e))?;
    // The summarize job marked the failed tasks; marking again finds them marked.
    let marked = mark_slurm_failures(dir, &sub.array_job)?;
    summarize(dir, head + &marked)
}
