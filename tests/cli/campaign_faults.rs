//! A campaign with random wheel failures, through the binary: each run's seized-wheel fault
//! (`mtbf_s`) gets a seed derived from the campaign seed, `summary.csv` lists each run's failure
//! time (the fault's first activation, empty when after the run's end), and the summary reports
//! the pass rate of the runs with a failure and of those without, each with its Wilson
//! interval. `--without-random-faults` runs the same campaign without them.
//!
//! The oracle for the failure times is each run's own `config.toml` (the seed the plan wrote
//! there) through [`failure_delay_ns`], the documented exponential draw.

use std::path::{Path, PathBuf};

use crate::campaign_support::flexdyn;

use flexdyn_campaign::summary::{wilson, Z_95};
use flexdyn_faults::failure_delay_ns;

const RUNS: u32 = 8;
/// \[s\] the wheel's MTBF and the run's length: P(failure within a run) = 1 − e^(−1/2) ≈ 0.39.
const MTBF_S: f64 = 2.0;
const DURATION_S: f64 = 1.0;

/// Writes the base (`scenarios/acs_full.toml` with a random seizure of rw1 from t = 0.25 s) and
/// the campaign file (open loop, |ω| below 1 rad/s) into a fresh folder.
fn campaign_file() -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("campaign_faults");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let base = format!(
        "{}\n[[faults]]\ntarget = \"reaction_wheels.rw1\"\nmode = \"seized\"\nstart_s = 0.25\n\
         mtbf_s = {MTBF_S:?}\n",
        include_str!("../../scenarios/acs_full.toml")
    );
    std::fs::write(dir.join("base.toml"), base).unwrap();
    let text = format!(
        "base = \"base.toml\"\nruns = {RUNS}\nseed = 5\nduration_s = {DURATION_S:?}\n\
         participant_timeout_s = 5.0\n[[criteria]]\nname = \"rate\"\nquantity = \"omega\"\n\
         statistic = \"max\"\nbelow = 1.0\n"
    );
    let file = dir.join("campaign.toml");
    std::fs::write(&file, text).unwrap();
    (file, dir)
}

fn run_and_summarize(file: &Path, out: &Path, extra: &[&str]) -> String {
    let (f, o) = (file.to_str().unwrap(), out.to_str().unwrap());
    let mut args = vec!["campaign", "run", f, "--output", o, "--base-port", "0"];
    args.extend_from_slice(extra);
    let run = flexdyn(&args);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let sum = flexdyn(&["campaign", "summarize", o]);
    let text = String::from_utf8_lossy(&sum.stderr).into_owned();
    assert_eq!(sum.status.code(), Some(0), "{text}");
    text
}

/// The CSV's rows as (header, cells).
fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| l.split(',').map(str::to_owned).collect());
    let header: Vec<String> = lines.next().unwrap();
    (header, lines.collect())
}

#[test]
fn random_wheel_failures_are_timed_per_run_and_split_the_pass_rate() {
    let (file, dir) = campaign_file();
    let out = dir.join("with");
    let text = run_and_summarize(&file, &out, &[]);
    let (header, rows) = csv(&out.join("summary.csv"));
    let col = header
        .iter()
        .position(|h| h == "faults[0].failure_s")
        .expect("a failure-time column");
    assert_eq!(rows.len(), RUNS as usize);
    let mut with_failure = 0;
    let mut seeds = Vec::new();
    for (run, row) in rows.iter().enumerate() {
        // The seed the plan derived for this run, as written into its configuration.
        let cfg: toml::Table =
            std::fs::read_to_string(out.join(format!("run-{run:04}/config.toml")))
                .unwrap()
                .parse()
                .unwrap();
        let seed = cfg["faults"][0]["seed"].as_integer().unwrap() as u64;
        seeds.push(seed);
        let t_ns = 250_000_000 + failure_delay_ns(MTBF_S, seed);
        let cell = &row[col];
        if t_ns <= (DURATION_S * 1e9) as u64 {
            with_failure += 1;
            // Written exactly: seconds with nine decimals.
            let (s, ns) = cell.split_once('.').expect("seconds.nanoseconds");
            assert_eq!(ns.len(), 9, "{cell}");
            let got = s.parse::<u64>().unwrap() * 1_000_000_000 + ns.parse::<u64>().unwrap();
            assert_eq!(got, t_ns, "run {run}: {cell}");
        } else {
            assert_eq!(cell, "", "run {run}: fails at {t_ns} ns, after the run");
        }
    }
    seeds.sort_unstable();
    seeds.dedup();
    assert_eq!(seeds.len(), RUNS as usize, "a seed of its own per run");
    // Every run passes (|ω| stays below 1 rad/s): the split is with_failure of 8 and the rest.
    let want = format!("a failure within the run in {with_failure} of {RUNS} runs");
    assert!(text.contains(&want), "{text}");
    let line = |k: u32, n: u32| {
        let (lo, hi) = wilson(k, n, Z_95);
        format!(
            "{k} of {n} passed ({:.1} %); Wilson 95 % interval {:.1} %–{:.1} %",
            100.0 * f64::from(k) / f64::from(n.max(1)),
            100.0 * lo,
            100.0 * hi
        )
    };
    assert!(
        text.contains(&format!(
            "runs with a random failure: {}",
            line(with_failure, with_failure)
        )),
        "{text}"
    );
    let without = RUNS - with_failure;
    assert!(
        text.contains(&format!("runs without: {}", line(without, without))),
        "{text}"
    );

    // The same campaign without the random faults: no failure column, the same dispersions.
    let out = dir.join("without");
    let text = run_and_summarize(&file, &out, &["--without-random-faults"]);
    assert!(text.contains("random faults removed"), "{text}");
    let (header, _) = csv(&out.join("summary.csv"));
    assert!(
        !header.iter().any(|h| h.contains("failure_s")),
        "{header:?}"
    );
    let cfg = std::fs::read_to_string(out.join("run-0000/config.toml")).unwrap();
    assert!(!cfg.contains("mtbf_s"), "{cfg}");
}
