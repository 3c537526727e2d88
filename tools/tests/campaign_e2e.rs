//! End-to-end campaigns with `flexdyn-acs-demo` as the flight code, through
//! `flexdyn::campaign::main` (what `flexdyn campaign …` calls): 20 short runs two at a time all
//! finish, the summary has 20 rows, the criteria evaluate and a deliberately failing one fails
//! everywhere; a run rerun alone with `--index` has the same state hash; a controller that
//! crashes in one run fails that run with its exit status and the campaign goes on. The exit
//! code is the verdict: 3 when the runs ran and failed.

use std::path::{Path, PathBuf};

use flexdyn::campaign::execute::RunResult;
use flexdyn::campaign::verdict::Outcome;
use flexdyn::campaign::{main as campaign, CampaignCommand};

#[path = "acs_demo_bin/mod.rs"]
mod acs_demo_bin;
use acs_demo_bin::acs_demo as demo;

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

fn result(dir: &Path, run: u32) -> RunResult {
    let p = dir.join(format!("run-{run:04}/result.json"));
    serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap()
}

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

    let summary = campaign(&CampaignCommand::Summarize { dir: out.clone() }).unwrap();
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
    let summary = campaign(&CampaignCommand::Summarize { dir: out }).unwrap();
    assert!(
        summary.text.contains("failed run 1: the controller exited"),
        "{}",
        summary.text
    );
    assert_eq!(summary.exit_code, 3);
}
