//! End-to-end campaigns with `flexdyn-acs-demo` as the flight code, through
//! `flexdyn_campaign::main` (what `flexdyn campaign …` calls): 20 short runs two at a time all
//! finish, the summary has 20 rows, the criteria evaluate and a deliberately failing one fails
//! everywhere; a run rerun alone with `--index` has the same state hash; a controller that
//! crashes in one run fails that run with its exit status and the campaign goes on. The exit
//! code is the verdict: 3 when the runs ran and failed. Random wheel seizures under the demo
//! without FDIR fail exactly the runs they strike, the summary splits the pass rate accordingly,
//! and each run's published failure time is the planned one to the nanosecond.

use std::path::{Path, PathBuf};

use flexdyn_campaign::execute::RunResult;
use flexdyn_campaign::verdict::Outcome;
use flexdyn_campaign::{main as campaign, CampaignCommand};
use flexdyn_faults::failure_delay_ns;

use demo_bin::acs_demo as demo;
use flexdyn_testkit::demo_bin;

fn write_campaign(name: &str, runs: u32, controller: &str) -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("campaign.toml");
    std::fs::write(
        &file,
        format!(
            r#"runs = {runs}
seed = 11
duration_s = 3.0
sigma_rn = [0.1, 0.2, -0.1]
participant_timeout_s = 5.0
controller = '''{controller}'''

[[dispersions]]
key = "hub.inertia_bc_b_kg_m2[0][0]"
distribution = "normal"
sigma = 45.0

[[dispersions]]
key = "panel_pairs[*].panel1.k_nm_rad"
distribution = "uniform"
low = 80.0
high = 120.0

[[dispersions]]
key = "initial.omega_bn_b_rad_s"
distribution = "normal"
sigma = 0.01

# |ω| stays far below 1 rad/s: passes.
[[criteria]]
name = "rate_bounded"
quantity = "omega"
statistic = "max"
below = 1.0

# Exact pointing after 3 s is impossible: fails in every run.
[[criteria]]
name = "impossible_pointing"
quantity = "sigma_br"
statistic = "final"
below = 1e-12
"#
        ),
    )
    .unwrap();
    (file, dir.join("out"))
}

use crate::support::campaign_result as result;

fn demo_line() -> String {
    format!(
        "{} --connect {{endpoint}} --sc-id {{sc_id}} --sender-id {{sender_id}} \
         --sigma-rn 0.1,0.2,-0.1 --rate-source truth --log-every-s 0 --idle-exit-s 1",
        demo()
    )
}

#[test]
fn twenty_runs_two_at_a_time_then_one_again_alone() {
    let (file, out) = write_campaign("campaign_e2e", 20, &demo_line());
    let report = campaign(&CampaignCommand::Run {
        file: file.clone(),
        output: out.clone(),
        jobs: Some(2),
        index: None,
        record: false,
        base_port: 0,
        without_random_faults: false,
    })
    .unwrap();
    eprintln!("{}", report.text);
    // Every run ran, and every run fails `impossible_pointing`.
    assert_eq!(report.exit_code, 3, "{}", report.text);
    assert!(report
        .text
        .ends_with("verdict: FAILED: 20 of 20 runs failed (exit code 3)"));
    let results: Vec<RunResult> = (0..20).map(|r| result(&out, r)).collect();
    for r in &results {
        assert_eq!(r.status, "ok", "run {}: {}", r.run, r.status);
        assert_eq!(r.states, 301, "run {}: 3 s at 100 Hz", r.run);
        assert_eq!(r.state_sha256.len(), 64);
        assert_eq!(
            r.controller_exit.as_deref(),
            Some("exit 0"),
            "run {}",
            r.run
        );
        assert_eq!(r.applied.len(), 6, "run {}: {:?}", r.run, r.applied);
        let rate = &r.criteria[0];
        assert!(
            rate.value.is_finite() && rate.value > 0.0 && rate.passed,
            "{rate:?}"
        );
        let pointing = &r.criteria[1];
        assert!(pointing.value > 1e-6 && !pointing.passed, "{pointing:?}");
        assert!(!r.passed);
        assert_eq!(r.outcome, Outcome::Failed, "run {}", r.run);
    }
    // Dispersed runs differ; the hashes say so.
    let mut hashes: Vec<&str> = results.iter().map(|r| r.state_sha256.as_str()).collect();
    hashes.sort_unstable();
    hashes.dedup();
    assert_eq!(hashes.len(), 20);

    let summary = campaign(&CampaignCommand::Summarize {
        dir: out.clone(),
        slurm_array: None,
    })
    .unwrap();
    let text = summary.text;
    eprintln!("{text}");
    assert_eq!(summary.exit_code, 3);
    assert!(text.contains("0 of 20 planned runs passed"), "{text}");
    assert!(
        text.contains("criterion impossible_pointing: 20 failing"),
        "{text}"
    );
    assert!(text.contains("criterion rate_bounded: 0 failing"), "{text}");
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    assert!(
        header.starts_with("run,state_sha256,passed,hub.inertia_bc_b_kg_m2[0][0],"),
        "{header}"
    );
    assert!(header.ends_with(",status"), "{header}");
    assert!(
        header.contains("panel_pairs[1].panel1.k_nm_rad")
            && header.contains("impossible_pointing_passed")
    );
    assert_eq!(lines.count(), 20);
    assert!(out.join("figures/hist_0_rate_bounded.png").is_file());

    // Run 7 again, alone, in another directory and on another port: the same stream.
    let again = out.with_file_name("again");
    let alone = campaign(&CampaignCommand::Run {
        file,
        output: again.clone(),
        jobs: None,
        index: Some(7),
        record: false,
        base_port: 0,
        without_random_faults: false,
    })
    .unwrap();
    assert_eq!(alone.exit_code, 3, "{}", alone.text);
    assert_eq!(result(&again, 7).state_sha256, results[7].state_sha256);
    assert!(!again.join("run-0006/result.json").exists());
}

#[test]
fn a_crashing_controller_fails_its_run_and_the_campaign_goes_on() {
    let line = format!(
        "sh -c 'if [ {{run}} -eq 1 ]; then exit 3; fi; exec \"$0\" \"$@\"' {}",
        demo_line()
    );
    let (file, out) = write_campaign("campaign_crash", 3, &line);
    let report = campaign(&CampaignCommand::Run {
        file,
        output: out.clone(),
        jobs: Some(1),
        index: None,
        record: false,
        base_port: 0,
        without_random_faults: false,
    })
    .unwrap();
    eprintln!("{}", report.text);
    // The flight code crashing in run 1 is a failed run, not one that could not be run.
    assert_eq!(report.exit_code, 3, "{}", report.text);
    let crashed = result(&out, 1);
    assert_eq!(crashed.controller_exit.as_deref(), Some("exit 3"));
    assert!(crashed.status.contains("exit 3"), "{}", crashed.status);
    assert!(!crashed.passed && crashed.state_sha256.is_empty());
    assert_eq!(crashed.outcome, Outcome::Failed);
    for r in [0, 2] {
        assert_eq!(result(&out, r).status, "ok");
    }
    let summary = campaign(&CampaignCommand::Summarize {
        dir: out,
        slurm_array: None,
    })
    .unwrap();
    assert!(
        summary.text.contains("failed run 1: the controller exited"),
        "{}",
        summary.text
    );
    assert_eq!(summary.exit_code, 3);
}

/// `scenarios/fdir.toml` without its own faults, plus a random seizure of rw2 from
/// [`SEIZE_FROM_S`] with an MTBF of [`MTBF_S`], flown by the demo without `--fdir` on the star
/// tracker and true rates (so no gyro bias sets a pointing floor).
const SEIZE_FROM_S: f64 = 30.0;
const MTBF_S: f64 = 36.0;
const SEIZURE_RUNS: u32 = 8;
const SEIZURE_DURATION_S: f64 = 60.0;
/// Campaign seed 1 puts four of the eight failures within the run and none in the last
/// [`BREAK_S`] of it (the test checks this from the seeds).
const SEIZURE_SEED: u32 = 1;
/// The pointing bound of `tools/tests/fdir.rs`, 0.05°, from [`SEIZE_FROM_S`] on (the criterion's
/// `after_s`): the healthy runs settle from the initial 3e-4 rad/s under it by 30 s (their
/// largest error from there, 0.017°, is the tail of that transient). As |σ_BR| (what `sigma_br`
/// measures) it is tan(θ/4).
const BOUND_DEG: f64 = 0.05;
/// A seizure breaks the bound within this time: the brake dumps rw2's 1.5 N·m·s into the hub at
/// 0.2 N·m (7.5 s) and the 4-wheel allocation keeps asking the seized wheel; without FDIR the
/// error peaks at 0.33° (docs/guides/faults.md, "FDIR demo"). Seizures 5.4 s before the end were measured to
/// break it (0.11°), 2.9 s before the end not (0.04°); 10 s is the margin. A failure later than
/// this before the end could go either way: the chosen seed has none.
const BREAK_S: f64 = 10.0;

fn seizure_campaign() -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("campaign_seizures");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = include_str!("../../scenarios/fdir.toml");
    let own_faults = scenario.find("\n[[faults]]").expect("fdir.toml's faults");
    let base = format!(
        "{}\n[[faults]]\ntarget = \"reaction_wheels.rw2\"\nmode = \"seized\"\n\
         start_s = {SEIZE_FROM_S:?}\nmtbf_s = {MTBF_S:?}\n",
        &scenario[..own_faults]
    );
    std::fs::write(dir.join("base.toml"), base).unwrap();
    let bound = (BOUND_DEG.to_radians() / 4.0).tan();
    let file = dir.join("campaign.toml");
    std::fs::write(
        &file,
        format!(
            r#"base = "base.toml"
runs = {SEIZURE_RUNS}
seed = {SEIZURE_SEED}
duration_s = {SEIZURE_DURATION_S:?}
participant_timeout_s = 10.0
controller = '''{} --connect {{endpoint}} --sc-id {{sc_id}} --sender-id {{sender_id}} --actuator wheels --attitude-source star-tracker --star-tracker st1 --rate-source truth --log-every-s 0 --idle-exit-s 1'''

[[criteria]]
name = "pointing"
quantity = "sigma_br"
statistic = "max"
after_s = {SEIZE_FROM_S:?}
below = {bound:e}
"#,
            demo()
        ),
    )
    .unwrap();
    (file, dir)
}

/// The Wilson score interval, solved here as the roots of (p̂ − p)² = z² p (1 − p)/n (Wilson
/// 1927), a quadratic in p: (1 + z²/n) p² − (2p̂ + z²/n) p + p̂² = 0.
fn wilson_roots(k: u32, n: u32) -> (f64, f64) {
    let z = 1.959_963_984_540_054_f64; // Φ⁻¹(0.975)
    let (p, n) = (f64::from(k) / f64::from(n), f64::from(n));
    let (a, b, c) = (1.0 + z * z / n, -(2.0 * p + z * z / n), p * p);
    let root = (b * b - 4.0 * a * c).max(0.0).sqrt();
    ((-b - root) / (2.0 * a), (-b + root) / (2.0 * a))
}

fn rate_line(k: u32, n: u32) -> String {
    let (lo, hi) = wilson_roots(k, n);
    format!(
        "{k} of {n} passed ({:.1} %); Wilson 95 % interval {:.1} %–{:.1} %",
        100.0 * f64::from(k) / f64::from(n),
        100.0 * lo,
        100.0 * hi
    )
}

/// `s.nnnnnnnnn` (or empty) as nanoseconds.
fn cell_ns(cell: &str) -> Option<u64> {
    let (s, ns) = cell.split_once('.')?;
    assert_eq!(ns.len(), 9, "{cell}");
    Some(s.parse::<u64>().unwrap() * 1_000_000_000 + ns.parse::<u64>().unwrap())
}

/// The StateMsg payloads of a run's `recording.mcap` (its raw channel), in tick order.
fn recorded_states(out: &Path, run: usize) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(out.join(format!("run-{run:04}/recording.mcap"))).unwrap();
    let topic = flexdyn_proto::Topics::new("sc1")
        .unwrap()
        .state()
        .to_owned();
    let mut states: Vec<(u64, Vec<u8>)> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.channel.topic == topic)
        .map(|m| {
            let tick = flexdyn_proto::decode_state(&m.data).unwrap().header.tick;
            (tick, m.data.into_owned())
        })
        .collect();
    states.sort_by_key(|(t, _)| *t);
    states.into_iter().map(|(_, p)| p).collect()
}

fn run_seizures(file: &Path, out: &Path, without_random_faults: bool) -> u8 {
    let report = campaign(&CampaignCommand::Run {
        file: file.to_owned(),
        output: out.to_owned(),
        jobs: Some(2),
        index: None,
        record: true,
        base_port: 0,
        without_random_faults,
    })
    .unwrap();
    eprintln!("{}", report.text);
    report.exit_code
}

#[test]
fn random_wheel_seizures_fail_the_runs_they_strike() {
    let (file, dir) = seizure_campaign();
    let out = dir.join("with");
    let code = run_seizures(&file, &out, false);
    let end_ns = (SEIZURE_DURATION_S * 1e9) as u64;
    let break_ns = ((SEIZURE_DURATION_S - BREAK_S) * 1e9) as u64;
    // Each run's failure time, from the seed the plan wrote into its configuration.
    let mut step_frame_ns = (0, 0);
    let failure_ns: Vec<u64> = (0..SEIZURE_RUNS)
        .map(|run| {
            let path = out.join(format!("run-{run:04}/config.toml"));
            let cfg = flexdyn_vehicle::config::SimConfig::from_toml_str(
                &std::fs::read_to_string(path).unwrap(),
            )
            .unwrap();
            step_frame_ns = (cfg.step_ns, cfg.frame_ns);
            (SEIZE_FROM_S * 1e9) as u64 + failure_delay_ns(MTBF_S, cfg.faults[0].seed)
        })
        .collect();
    let struck: Vec<bool> = failure_ns.iter().map(|t| *t <= end_ns).collect();
    for (run, t) in failure_ns.iter().enumerate() {
        assert!(
            *t <= break_ns || *t > end_ns,
            "run {run} seizes at {t} ns, too close to the end to say: choose another seed"
        );
    }
    let k = struck.iter().filter(|s| **s).count() as u32;
    let m = SEIZURE_RUNS - k;
    assert!(k > 0 && m > 0, "both groups: {failure_ns:?}");
    assert_eq!(code, 3, "the struck runs fail");

    let summary = campaign(&CampaignCommand::Summarize {
        dir: out.clone(),
        slurm_array: None,
    })
    .unwrap();
    let text = summary.text;
    eprintln!("{text}");
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let mut lines = csv.lines().map(|l| l.split(',').collect::<Vec<&str>>());
    let header = lines.next().unwrap();
    let rows: Vec<Vec<&str>> = lines.collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (planned, observed) = (col("faults[0].failure_s"), col("faults[0].observed_s"));
    let results: Vec<RunResult> = (0..SEIZURE_RUNS).map(|r| result(&out, r)).collect();
    for (run, r) in results.iter().enumerate() {
        assert_eq!(r.status, "ok", "run {run}");
        let want = struck[run].then_some(failure_ns[run]);
        // The seizure breaks the pointing; without it the run holds it.
        let outcome = if struck[run] {
            Outcome::Failed
        } else {
            Outcome::Passed
        };
        assert_eq!(r.outcome, outcome, "run {run}: {:?}", r.criteria);
        // The server published the activation at the planned nanosecond, and only then.
        assert_eq!(
            r.fault_activations_ns,
            want.map(|t| ("faults[0]".to_owned(), t))
                .into_iter()
                .collect(),
            "run {run}"
        );
        assert_eq!(cell_ns(rows[run][planned]), want, "run {run}");
        assert_eq!(cell_ns(rows[run][observed]), want, "run {run}");
    }
    let within = format!("a failure within the run in {k} of {SEIZURE_RUNS} runs");
    assert!(text.contains(&within), "{text}");
    // Every struck run failed, every other passed: 0 of k, and m of m.
    let with = format!("runs with a random failure: {}\n", rate_line(0, k));
    assert!(text.contains(&with), "{text}");
    let without = format!("runs without: {}\n", rate_line(m, m));
    assert!(text.contains(&without), "{text}");
    assert!(!text.contains("published at"), "{text}");

    // Without the random faults every run passes, and the runs no seizure struck are the same
    // runs bit for bit: the faults are the only difference.
    let healthy = dir.join("without");
    assert_eq!(run_seizures(&file, &healthy, true), 0);
    let (step_ns, frame_ns) = step_frame_ns;
    for (run, with) in results.iter().enumerate() {
        let without = result(&healthy, run as u32);
        assert!(without.passed, "run {run}: {:?}", without.criteria);
        assert!(without.fault_activations_ns.is_empty());
        let same = without.state_sha256 == with.state_sha256;
        assert_eq!(same, !struck[run], "run {run}");
        if !struck[run] {
            continue;
        }
        // The physics departs from the healthy twin where the brake starts: the wheel port
        // applies the seizure from the first step starting at or after the failure time
        // (crates/faults/src/ports.rs), so the first state to differ is the one ending that step's
        // frame. Recorded by the server, independently of the observer.
        let (a, b) = (recorded_states(&out, run), recorded_states(&healthy, run));
        assert_eq!(
            (a.len(), b.len()),
            (with.states as usize, with.states as usize)
        );
        let first_differing = a.iter().zip(&b).position(|(x, y)| x != y);
        let first_step_ns = failure_ns[run].div_ceil(step_ns) * step_ns;
        let want = first_step_ns / frame_ns + 1;
        assert_eq!(first_differing, Some(want as usize), "run {run}");
    }
    let text = campaign(&CampaignCommand::Summarize {
        dir: healthy,
        slurm_array: None,
    })
    .unwrap()
    .text;
    let all = format!("{SEIZURE_RUNS} of {SEIZURE_RUNS} planned runs passed");
    assert!(text.contains(&all), "{text}");
}
