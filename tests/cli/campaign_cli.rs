//! `flexdyn campaign run` and `summarize` through the binary, as a CI job calls them: the exit
//! code carries the verdict. 0: every run passed; 1: a run could not be run (the controller
//! could not be started, a run missing from the directory); 2: invalid input; 3: every run ran
//! and one failed its criteria. Open-loop runs (no flight code), so each takes about a second.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::campaign_support::flexdyn;

/// Writes `name/campaign.toml`: one open-loop run of 0.5 s with `extra` appended.
fn campaign(name: &str, extra: &str) -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("campaign_cli_{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("campaign.toml");
    let text =
        format!("runs = 1\nseed = 3\nduration_s = 0.5\nparticipant_timeout_s = 5.0\n{extra}");
    std::fs::write(&file, text).unwrap();
    (file, dir.join("out"))
}

/// `flexdyn campaign run FILE -o OUT` then `flexdyn campaign summarize OUT`: both exit codes and
/// both reports (stderr).
fn run_and_summarize(file: &Path, out: &Path) -> ((Option<i32>, String), (Option<i32>, String)) {
    let (f, o) = (file.to_str().unwrap(), out.to_str().unwrap());
    // Base port 0: each run's server takes a free port from the OS.
    let run = flexdyn(&["campaign", "run", f, "--output", o, "--base-port", "0"]);
    let sum = flexdyn(&["campaign", "summarize", o]);
    let text = |x: &Output| String::from_utf8_lossy(&x.stderr).into_owned();
    (
        (run.status.code(), text(&run)),
        (sum.status.code(), text(&sum)),
    )
}

const RATE_BELOW_1: &str =
    "[[criteria]]\nname = \"rate\"\nquantity = \"omega\"\nstatistic = \"max\"\nbelow = 1.0\n";

#[test]
fn every_run_passing_exits_0() {
    // The reference tumbles at |ω| = 0.087 rad/s: below 1 rad/s throughout.
    let (file, out) = campaign("passing", RATE_BELOW_1);
    let ((run, run_err), (sum, sum_err)) = run_and_summarize(&file, &out);
    assert_eq!(run, Some(0), "{run_err}");
    assert!(run_err.contains("verdict: PASSED"), "{run_err}");
    assert_eq!(sum, Some(0), "{sum_err}");
    assert!(sum_err.contains("verdict: PASSED"), "{sum_err}");
}

#[test]
fn a_failed_criterion_exits_3() {
    // |ω| = 0.087 rad/s is never below 0.01 rad/s.
    let extra = format!(
        "{RATE_BELOW_1}[[criteria]]\nname = \"still\"\nquantity = \"omega\"\n\
         statistic = \"final\"\nbelow = 0.01\n"
    );
    let (file, out) = campaign("failing", &extra);
    let ((run, run_err), (sum, sum_err)) = run_and_summarize(&file, &out);
    assert_eq!(run, Some(3), "{run_err}");
    assert!(
        run_err.contains("verdict: FAILED: 1 of 1 runs failed"),
        "{run_err}"
    );
    assert_eq!(sum, Some(3), "{sum_err}");
    let result = std::fs::read_to_string(out.join("run-0000/result.json")).unwrap();
    assert!(result.contains("\"outcome\": \"failed\""), "{result}");
}

#[test]
fn a_controller_that_cannot_start_exits_1() {
    let extra =
        format!("controller = \"/nonexistent/flight-code --connect {{endpoint}}\"\n{RATE_BELOW_1}");
    let (file, out) = campaign("no_controller", &extra);
    let started = std::time::Instant::now();
    let ((run, run_err), (sum, sum_err)) = run_and_summarize(&file, &out);
    assert_eq!(run, Some(1), "{run_err}");
    assert!(run_err.contains("cannot start the controller"), "{run_err}");
    assert!(run_err.contains("verdict: INCOMPLETE"), "{run_err}");
    assert_eq!(sum, Some(1), "{sum_err}");
    let result = std::fs::read_to_string(out.join("run-0000/result.json")).unwrap();
    assert!(result.contains("\"outcome\": \"not_run\""), "{result}");
    // The server is stopped at once, not left waiting for the controller's presence (30 s).
    assert!(started.elapsed().as_secs() < 20, "{:?}", started.elapsed());
}

#[test]
fn a_missing_run_makes_summarize_exit_1_and_bad_input_exits_2() {
    let (file, out) = campaign("missing", RATE_BELOW_1);
    let (f, o) = (file.to_str().unwrap(), out.to_str().unwrap());
    let plan = flexdyn(&["campaign", "plan", f, "--output", o]);
    assert_eq!(plan.status.code(), Some(0));
    let sum = flexdyn(&["campaign", "summarize", o]);
    let err = String::from_utf8_lossy(&sum.stderr);
    assert_eq!(sum.status.code(), Some(1), "{err}");
    assert!(err.contains("missing runs"), "{err}");
    let (bad, _) = campaign("bad", "sigma_rn = [nan, 0, 0]\n");
    let run = flexdyn(&["campaign", "run", bad.to_str().unwrap(), "--output", o]);
    assert_eq!(run.status.code(), Some(2));
}

/// Issue 36: with stderr not a terminal (CI, here a pipe) the campaign prints plain progress
/// lines as runs finish, the count of done runs rising to the total, instead of nothing until
/// the end (an invisible bar).
#[test]
fn progress_is_printed_as_plain_lines_when_stderr_is_not_a_terminal() {
    let (file, out) = campaign("progress", RATE_BELOW_1);
    let text = std::fs::read_to_string(&file)
        .unwrap()
        .replace("runs = 1", "runs = 3");
    std::fs::write(&file, text).unwrap();
    let (f, o) = (file.to_str().unwrap(), out.to_str().unwrap());
    let run = flexdyn(&["campaign", "run", f, "--output", o, "--base-port", "0"]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{err}");
    let done: Vec<u32> = err
        .lines()
        .filter_map(|l| {
            l.strip_prefix("campaign: ")?
                .split_once("/3 runs done (")
                .map(|(k, _)| k.parse().unwrap())
        })
        .collect();
    assert!(!done.is_empty(), "no progress line in: {err}");
    assert!(done.windows(2).all(|w| w[0] <= w[1]), "{done:?}");
    assert_eq!(done.last(), Some(&3), "{err}");
    assert!(
        err.contains("campaign: 3/3 runs done (3 pass, 0 fail, 0 could not run), "),
        "{err}"
    );
    // No carriage-return bar.
    assert!(!err.contains('\r'), "{err:?}");
}
