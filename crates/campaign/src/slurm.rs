//! A campaign on a Slurm cluster: `campaign submit --slurm`, `campaign resubmit` and the
//! summarize job's read of the array's task states.
//!
//! `submit` plans the campaign into the output directory (which every node must see at the
//! same path), writes two job scripts under `<dir>/slurm/`, and submits one job array with a
//! task per run (`sbatch --array`, each task `flexdyn campaign run … --index
//! $SLURM_ARRAY_TASK_ID --base-port 0`, with the campaign's `[resources]`) and a summarize job
//! that waits for the whole array (`--dependency=afterany:<array>`). It records the submission
//! in `<dir>/slurm/submissions.json` and prints the two job ids; with `--wait` it waits for the
//! summarize job and returns the campaign's verdict as `campaign run` does.
//!
//! The summarize job (`campaign summarize <dir> --slurm-array <id>`) first asks Slurm how each
//! task ended (`sacct`, or `scontrol show job` where the cluster keeps no accounting). A task
//! that ended without a `result.json` (a node lost, the time limit, cancelled, out of memory, a
//! binary missing on the node) could not be run: it gets a `result.json` with outcome `not_run`
//! and the Slurm state in its status (`Slurm task 12_7 ended TIMEOUT (exit 0:0) without a
//! result`), so the summary names it and the verdict is INCOMPLETE (exit 1).
//! `campaign resubmit <dir>` then submits exactly the runs without a `passed` or `failed` result, and a new
//! summarize job.
//!
//! Nothing here runs on the stepping path: it starts `sbatch`, `squeue`, `sacct` and
//! `scontrol` as child processes and reads their output.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use serde::{Deserialize, Serialize};

use super::execute::RunResult;
use super::plan::RunPlan;
use super::spec::Resources;
use super::verdict::Outcome;

/// The directory of the job scripts, their logs and the submissions, under the campaign's.
pub const SLURM_DIR: &str = "slurm";
/// The record of every submission, in `<dir>/slurm/`.
pub const SUBMISSIONS_FILE: &str = "submissions.json";

/// How `campaign submit --slurm` submits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SlurmOptions {
    /// The `flexdyn` binary the tasks run (the same path on every node).
    pub flexdyn: PathBuf,
    /// `sbatch --partition`; `None`: the cluster's default.
    pub partition: Option<String>,
    /// The runs without the base configuration's random faults.
    pub without_random_faults: bool,
}

/// One submission: what `resubmit` needs to submit again, and the jobs' ids.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Submission {
    /// The campaign file (absolute).
    pub campaign: PathBuf,
    /// The `flexdyn` binary the tasks run.
    pub flexdyn: PathBuf,
    /// `sbatch --partition`, if given.
    pub partition: Option<String>,
    /// `--without-random-faults`.
    pub without_random_faults: bool,
    /// The array job's id.
    pub array_job: String,
    /// The summarize job's id.
    pub summarize_job: String,
    /// The runs the array holds, in task order (task id = run index).
    pub indices: Vec<u32>,
}

/// How one array task ended, as Slurm tells it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TaskState {
    /// The task id (the run index).
    pub task: u32,
    /// Slurm's job state (`COMPLETED`, `FAILED`, `TIMEOUT`, `NODE_FAIL`, `PENDING`, …).
    pub state: String,
    /// Slurm's `exit:signal`.
    pub exit_code: String,
}

impl TaskState {
    /// Whether the task has ended (Slurm keeps it no longer pending or running).
    pub fn ended(&self) -> bool {
        !matches!(
            self.state.as_str(),
            "PENDING"
                | "RUNNING"
                | "CONFIGURING"
                | "COMPLETING"
                | "REQUEUED"
                | "RESIZING"
                | "SUSPENDED"
                | "STAGE_OUT"
                | "SIGNALING"
                | "REQUEUE_HOLD"
                | "REQUEUE_FED"
        )
    }
}

/// `s` quoted for `sh` (single quotes, a quote inside written as `'\''`).
fn sh_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// Runs `program args…` and returns its stdout, or an error naming the command.
fn run(program: &str, args: &[String]) -> Result<String, String> {
    let out = Command::new(program)
        .args(args)
        .output()
        .map_err(|e| format!("{program}: could not be started: {e} (is Slurm installed here?)"))?;
    if !out.status.success() {
        return Err(format!(
            "{program} {}: {} ({})",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim(),
            out.status
        ));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// `D-HH:MM:SS` for `sbatch --time`.
fn slurm_time(seconds: u64) -> String {
    format!(
        "{}-{:02}:{:02}:{:02}",
        seconds / 86_400,
        seconds / 3600 % 24,
        seconds / 60 % 60,
        seconds % 60
    )
}

/// `0-19`, or `3,7,12` (what `sbatch --array` takes).
fn array_spec(indices: &[u32]) -> String {
    let contiguous = indices.windows(2).all(|w| w[1] == w[0] + 1);
    match (indices.first(), indices.last()) {
        (Some(a), Some(b)) if contiguous && indices.len() > 1 => format!("{a}-{b}"),
        _ => indices
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(","),
    }
}

/// Writes the two job scripts and submits the array of `indices` and the summarize job;
/// appends the submission to `<dir>/slurm/submissions.json`. `dir` and `campaign` are
/// absolute.
pub fn submit(
    campaign: &Path,
    dir: &Path,
    indices: &[u32],
    resources: &Resources,
    opts: &SlurmOptions,
) -> Result<Submission, String> {
    if indices.is_empty() {
        return Err("no run to submit".into());
    }
    let slurm_dir = dir.join(SLURM_DIR);
    std::fs::create_dir_all(&slurm_dir).map_err(|e| format!("{}: {e}", slurm_dir.display()))?;
    let flexdyn = sh_quote(&opts.flexdyn.to_string_lossy());
    let run_script = slurm_dir.join("run.sh");
    let script = format!(
        "#!/bin/sh\n# Written by `flexdyn campaign submit --slurm`: array task N is run N of the campaign.\nexec {flexdyn} campaign run {} --output {} --index \"$SLURM_ARRAY_TASK_ID\" --base-port 0{}\n",
        sh_quote(&campaign.to_string_lossy()),
        sh_quote(&dir.to_string_lossy()),
        if opts.without_random_faults {
            " --without-random-faults"
        } else {
            ""
        }
    );
    write_script(&run_script, &script)?;
    let summarize_script = slurm_dir.join("summarize.sh");
    let script = format!(
        "#!/bin/sh\n# Written by `flexdyn campaign submit --slurm`: after the whole array ($1), the campaign's summary.\nexec {flexdyn} campaign summarize {} --slurm-array \"$1\"\n",
        sh_quote(&dir.to_string_lossy())
    );
    write_script(&summarize_script, &script)?;

    let mut common = vec![
        "--parsable".to_owned(),
        format!("--chdir={}", dir.display()),
    ];
    if let Some(p) = &opts.partition {
        common.push(format!("--partition={p}"));
    }
    let mut array = common.clone();
    array.extend([
        "--job-name=flexdyn-campaign".to_owned(),
        format!("--array={}", array_spec(indices)),
        "--ntasks=1".to_owned(),
        format!("--cpus-per-task={}", resources.cpus_per_run),
        format!("--output={}", slurm_dir.join("run-%a.out").display()),
    ]);
    if let Some(mb) = resources.memory_mb {
        array.push(format!("--mem={mb}M"));
    }
    if let Some(s) = resources.time_limit_s {
        array.push(format!("--time={}", slurm_time(s)));
    }
    array.push(run_script.to_string_lossy().into_owned());
    let array_job = job_id(&run("sbatch", &array)?)?;

    let mut summarize = common;
    summarize.extend([
        "--job-name=flexdyn-campaign-summary".to_owned(),
        format!("--dependency=afterany:{array_job}"),
        "--ntasks=1".to_owned(),
        format!("--output={}", slurm_dir.join("summarize-%j.out").display()),
        summarize_script.to_string_lossy().into_owned(),
        array_job.clone(),
    ]);
    let summarize_job = job_id(&run("sbatch", &summarize)?)?;

    let submission = Submission {
        campaign: campaign.to_owned(),
        flexdyn: opts.flexdyn.clone(),
        partition: opts.partition.clone(),
        without_random_faults: opts.without_random_faults,
        array_job,
        summarize_job,
        indices: indices.to_vec(),
    };
    let mut all = submissions(dir).unwrap_or_default();
    all.push(submission.clone());
    let path = slurm_dir.join(SUBMISSIONS_FILE);
    let text = serde_json::to_string_pretty(&all).map_err(|e| e.to_string())?;
    std::fs::write(&path, text + "\n").map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(submission)
}

/// Writes an executable job script.
fn write_script(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755))
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

/// The job id of `sbatch --parsable`'s answer (`12` or `12;cluster`).
fn job_id(parsable: &str) -> Result<String, String> {
    let id = parsable.trim().split(';').next().unwrap_or_default();
    if id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!("sbatch answered {parsable:?}, not a job id"));
    }
    Ok(id.to_owned())
}

/// The submissions recorded in `dir`, oldest first.
pub fn submissions(dir: &Path) -> Result<Vec<Submission>, String> {
    let path = dir.join(SLURM_DIR).join(SUBMISSIONS_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Waits until Slurm no longer lists job `id` as pending or running.
pub fn wait_for(id: &str) -> Result<(), String> {
    loop {
        let out = run(
            "squeue",
            &[
                "--noheader".into(),
                "--jobs".into(),
                id.into(),
                "--format=%i".into(),
            ],
        );
        match out {
            Ok(text) if text.trim().is_empty() => return Ok(()),
            Ok(_) => {}
            // A job Slurm has forgotten is finished too.
            Err(e) if e.contains("Invalid job id") => return Ok(()),
            Err(e) => return Err(e),
        }
        std::thread::sleep(Duration::from_millis(500));
    }
}

/// How each task of array job `array_job` ended: from `sacct`, or, where the cluster keeps no
/// accounting, from `scontrol show job` (which remembers a job for `MinJobAge` after it ends).
pub fn task_states(array_job: &str) -> Result<Vec<TaskState>, String> {
    let sacct = run(
        "sacct",
        &[
            "--noheader".into(),
            "--parsable2".into(),
            "--allocations".into(),
            "--jobs".into(),
            array_job.into(),
            "--format=JobID,State,ExitCode".into(),
        ],
    );
    match sacct {
        Ok(text) if !text.trim().is_empty() => Ok(parse_sacct(&text)),
        _ => Ok(parse_scontrol(&run(
            "scontrol",
            &[
                "--oneliner".into(),
                "show".into(),
                "job".into(),
                array_job.into(),
            ],
        )?)),
    }
}

/// The task ids of `spec`: `7`, a range `3-9` or a list `[3-5,8]` (a `%2` throttle ignored).
fn task_ids(spec: &str) -> Vec<u32> {
    let spec = spec.split('%').next().unwrap_or_default();
    let spec = spec.trim_start_matches('[').trim_end_matches(']');
    let mut ids = Vec::new();
    for part in spec.split(',') {
        match part.split_once('-') {
            Some((a, b)) => {
                if let (Ok(a), Ok(b)) = (a.parse::<u32>(), b.parse::<u32>()) {
                    ids.extend(a..=b.min(a.saturating_add(1_000_000)));
                }
            }
            None => ids.extend(part.parse::<u32>().ok()),
        }
    }
    ids
}

/// `sacct --parsable2` lines `12_7|TIMEOUT|0:0`, and `12_[3-9]|CANCELLED by 0|0:0` for the
/// tasks Slurm keeps as one record (pending ones, or cancelled before they started).
fn parse_sacct(text: &str) -> Vec<TaskState> {
    text.lines()
        .flat_map(|line| {
            let mut f = line.split('|');
            let id = f.next().unwrap_or_default();
            let state = f
                .next()
                .and_then(|s| s.split_whitespace().next())
                .unwrap_or_default()
                .to_owned();
            let exit_code = f.next().unwrap_or_default().to_owned();
            let tasks = id
                .split_once('_')
                .map(|(_, t)| task_ids(t))
                .unwrap_or_default();
            tasks.into_iter().map(move |task| TaskState {
                task,
                state: state.clone(),
                exit_code: exit_code.clone(),
            })
        })
        .filter(|t| !t.state.is_empty())
        .collect()
}

/// `scontrol --oneliner show job` lines, one per task (`… ArrayTaskId=7 … JobState=TIMEOUT
/// … ExitCode=0:0 …`), or one for the tasks not started yet (`ArrayTaskId=3-9`).
fn parse_scontrol(text: &str) -> Vec<TaskState> {
    text.lines()
        .flat_map(|line| {
            let field = |key: &str| {
                line.split_whitespace()
                    .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
                    .unwrap_or_default()
                    .to_owned()
            };
            let (state, exit_code) = (field("JobState"), field("ExitCode"));
            task_ids(&field("ArrayTaskId"))
                .into_iter()
                .map(move |task| TaskState {
                    task,
                    state: state.clone(),
                    exit_code: exit_code.clone(),
                })
        })
        .filter(|t| !t.state.is_empty())
        .collect()
}

/// Gives every run of array job `array_job` (its tasks `indices`, all ended) that has no
/// `result.json` one saying it could not be run: with its Slurm state from `states`, or, for a
/// task Slurm keeps no record of (cancelled before it started, on a cluster without
/// accounting), saying so. Returns the runs it marked.
pub fn mark_not_run(
    dir: &Path,
    plans: &[RunPlan],
    array_job: &str,
    indices: &[u32],
    states: &[TaskState],
) -> Result<Vec<u32>, String> {
    let mut marked = Vec::new();
    for &task in indices {
        let how = match states.iter().find(|t| t.task == task) {
            Some(t) if !t.ended() => continue,
            Some(t) => format!("ended {} (exit {})", t.state, t.exit_code),
            None => "has no record (cancelled before it started?)".to_owned(),
        };
        let Some(rp) = plans.iter().find(|p| p.run == task) else {
            continue;
        };
        let path = dir.join(&rp.dir).join("result.json");
        if path.exists() {
            continue;
        }
        let result = RunResult::not_run(
            rp,
            format!("Slurm task {array_job}_{task} {how} and left no result"),
        );
        std::fs::create_dir_all(dir.join(&rp.dir)).map_err(|e| e.to_string())?;
        let text = serde_json::to_string_pretty(&result).map_err(|e| e.to_string())?;
        std::fs::write(&path, text + "\n").map_err(|e| format!("{}: {e}", path.display()))?;
        marked.push(rp.run);
    }
    Ok(marked)
}

/// The planned runs of `dir` without a `passed` or `failed` result: what `resubmit` submits.
pub fn missing_runs(dir: &Path, plans: &[RunPlan]) -> Vec<u32> {
    plans
        .iter()
        .filter(|p| p.valid)
        .filter(|p| {
            let path = dir.join(&p.dir).join("result.json");
            let outcome = std::fs::read_to_string(path)
                .ok()
                .and_then(|t| serde_json::from_str::<RunResult>(&t).ok())
                .map(|r| r.outcome);
            !matches!(outcome, Some(Outcome::Passed | Outcome::Failed))
        })
        .map(|p| p.run)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_specs_and_time_limits_are_slurms() {
        assert_eq!(array_spec(&[0, 1, 2, 3]), "0-3");
        assert_eq!(array_spec(&[3, 7, 12]), "3,7,12");
        assert_eq!(array_spec(&[5]), "5");
        assert_eq!(slurm_time(90_061), "1-01:01:01");
        assert_eq!(slurm_time(59), "0-00:00:59");
        assert_eq!(job_id("12\n").unwrap(), "12");
        assert_eq!(job_id("12;cluster\n").unwrap(), "12");
        assert!(job_id("Submitted batch job 12").is_err());
        assert_eq!(sh_quote("a b'c"), r"'a b'\''c'");
    }

    /// The two sources of task states, as Slurm 22.05 prints them.
    #[test]
    fn task_states_are_read_from_sacct_and_scontrol() {
        let st = |task: u32, state: &str, exit_code: &str| TaskState {
            task,
            state: state.into(),
            exit_code: exit_code.into(),
        };
        let sacct = "12_0|COMPLETED|0:0\n12_1|TIMEOUT|0:0\n12_2|CANCELLED by 0|0:15\n\
                     12_[3-4]|PENDING|0:0\n";
        assert_eq!(
            parse_sacct(sacct),
            [
                st(0, "COMPLETED", "0:0"),
                st(1, "TIMEOUT", "0:0"),
                st(2, "CANCELLED", "0:15"),
                st(3, "PENDING", "0:0"),
                st(4, "PENDING", "0:0"),
            ]
        );
        let scontrol = "JobId=14 ArrayJobId=12 ArrayTaskId=2 JobName=x JobState=FAILED \
                        Reason=NonZeroExitCode ExitCode=3:0\n\
                        JobId=12 ArrayJobId=12 ArrayTaskId=3-4 JobState=PENDING ExitCode=0:0\n";
        let s = parse_scontrol(scontrol);
        assert_eq!(
            s,
            [
                st(2, "FAILED", "3:0"),
                st(3, "PENDING", "0:0"),
                st(4, "PENDING", "0:0")
            ]
        );
        assert!(s[0].ended());
        assert!(!s[1].ended());
        assert_eq!(task_ids("[3-5,8]%2"), [3, 4, 5, 8]);
        assert_eq!(task_ids("7"), [7]);
    }
}
