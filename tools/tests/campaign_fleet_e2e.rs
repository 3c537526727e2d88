//! A campaign over a fleet, end to end (issue 22, "campaigns disperse per-vehicle keys"),
//! through `flexdyn_campaign::main` (what `flexdyn campaign …` calls): the fleet server, the
//! observer on both vehicles, and a controller process per vehicle, `flexdyn-acs-demo` for the
//! chief (sender 1) and `flexdyn-formation-demo` for the deputy (sender 2). Four short runs two
//! at a time:
//! - every run completes, each controller exits 0, and the dispersions of both vehicles are
//!   read back from the built models;
//! - criteria are evaluated per vehicle: the rate of each, and the deputy's range to the chief
//!   from the RelativeStateMsg stream, whose maximum is at least the initial range read back
//!   from the models (t = 0 is in the window; both are computed from the same built states, to
//!   rounding at |r| ≈ 1e7 m, 1e-6 m allowed) and at most 2 m more (3 s of a PD law at
//!   ω_c = 0.1 rad/s from a 6 m error moves the deputy less than ½·ω_c²·e0·t² ≈ 0.3 m);
//!   an impossible criterion fails every run: exit code 3;
//! - `summary.csv` has one row per run, a hash column per vehicle and the dispersed columns
//!   named `<vehicle>.<key>`;
//! - run 2 rerun alone with `--index` gives the same hash for each vehicle.

use std::path::{Path, PathBuf};

use flexdyn_campaign::execute::RunResult;
use flexdyn_campaign::{main as campaign, CampaignCommand};

use flexdyn_testkit::demo_bin;

const RUNS: u32 = 4;

fn write_campaign(name: &str) -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let reference = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/reference.toml");
    std::fs::write(
        dir.join("formation.toml"),
        format!(
            r#"[[vehicles]]
id = "chief"
spacecraft_file = {reference:?}
participants = [1]

[[vehicles]]
id = "deputy"
spacecraft_file = {reference:?}
participants = [2]
[vehicles.relative]
chief = "chief"
hill_position_m = [3.0, -95.0, 2.0]
"#,
            reference = reference.display().to_string()
        ),
    )
    .unwrap();
    let file = dir.join("campaign.toml");
    std::fs::write(
        &file,
        format!(
            r#"fleet = "formation.toml"
runs = {RUNS}
seed = 3
duration_s = 3.0
participant_timeout_s = 5.0

[[controllers]]
vehicle = "chief"
command = '''{acs} --connect {{endpoint}} --sc-id {{sc_id}} --sender-id {{sender_id}} --rate-source truth --log-every-s 0 --idle-exit-s 1'''

[[controllers]]
vehicle = "deputy"
command = '''{formation} --connect {{endpoint}} --sc-id {{vehicle}} --chief chief --sender-id {{sender_id}} --station-m 0,-100,0 --idle-exit-s 1'''

[[dispersions]]
vehicle = "chief"
key = "hub.inertia_bc_b_kg_m2[0][0]"
distribution = "normal"
sigma = 45.0

[[dispersions]]
vehicle = "deputy"
key = "relative.hill_position_m"
distribution = "normal"
sigma = 1.0

[[criteria]]
vehicle = "chief"
name = "chief_rate"
quantity = "omega"
statistic = "max"
below = 1.0

[[criteria]]
vehicle = "deputy"
name = "deputy_rate"
quantity = "omega"
statistic = "max"
below = 1.0

[[criteria]]
vehicle = "deputy"
name = "deputy_range_max"
quantity = "range"
statistic = "max"
below = 150.0

# The deputy cannot be within a metre of the chief: fails in every run.
[[criteria]]
vehicle = "deputy"
name = "impossible_range"
quantity = "range"
statistic = "final"
below = 1.0
"#,
            acs = demo_bin::acs_demo(),
            formation = demo_bin::formation_demo(),
        ),
    )
    .unwrap();
    (file, dir.join("out"))
}

fn result(dir: &Path, run: u32) -> RunResult {
    let p = dir.join(format!("run-{run:04}/result.json"));
    serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap()
}

fn run(
    file: &Path,
    out: &Path,
    jobs: Option<usize>,
    index: Option<u32>,
) -> flexdyn_campaign::Report {
    let report = campaign(&CampaignCommand::Run {
        file: file.to_owned(),
        output: out.to_owned(),
        jobs,
        index,
        record: false,
        base_port: 0,
        without_random_faults: false,
    })
    .unwrap();
    eprintln!("{}", report.text);
    report
}

#[test]
fn a_formation_campaign_runs_a_controller_per_vehicle_and_judges_each_vehicle() {
    let (file, out) = write_campaign("campaign_fleet_e2e");
    let report = run(&file, &out, Some(2), None);
    assert_eq!(report.exit_code, 3, "{}", report.text);
    assert!(
        report.text.ends_with(&format!(
            "verdict: FAILED: {RUNS} of {RUNS} runs failed (exit code 3)"
        )),
        "{}",
        report.text
    );
    let results: Vec<RunResult> = (0..RUNS).map(|r| result(&out, r)).collect();
    for r in &results {
        assert_eq!(r.status, "ok", "run {}: {}", r.run, r.status);
        assert_eq!(r.states, 301, "run {}: 3 s at 100 Hz, each vehicle", r.run);
        assert!(r.state_sha256.is_empty(), "the hash is per vehicle");
        let ids: Vec<&str> = r.vehicle_state_sha256.keys().map(String::as_str).collect();
        assert_eq!(ids, ["chief", "deputy"], "run {}", r.run);
        assert!(r.vehicle_state_sha256.values().all(|h| h.len() == 64));
        assert_eq!(
            r.controller_exits
                .iter()
                .map(|(k, v)| (k.as_str(), v.as_str()))
                .collect::<Vec<_>>(),
            [("chief/1", "exit 0"), ("deputy/2", "exit 0")],
            "run {}",
            r.run
        );
        // Both vehicles' dispersions, read back from the built models.
        let keys: Vec<&str> = r.applied.keys().map(String::as_str).collect();
        assert_eq!(
            keys,
            [
                "chief.hub.inertia_bc_b_kg_m2[0][0]",
                "deputy.relative.hill_position_m[0]",
                "deputy.relative.hill_position_m[1]",
                "deputy.relative.hill_position_m[2]",
            ]
        );
        let rho0: f64 = (0..3)
            .map(|i| r.applied[&format!("deputy.relative.hill_position_m[{i}]")].powi(2))
            .sum::<f64>()
            .sqrt();
        let by_name = |n: &str| r.criteria.iter().find(|c| c.name == n).unwrap();
        for n in ["chief_rate", "deputy_rate"] {
            let c = by_name(n);
            assert!(c.value > 0.0 && c.passed, "run {}: {c:?}", r.run);
        }
        let range = by_name("deputy_range_max");
        assert!(
            range.value >= rho0 - 1e-6 && range.value < rho0 + 2.0 && range.passed,
            "run {}: max range {} against the initial {rho0}",
            r.run,
            range.value
        );
        let impossible = by_name("impossible_range");
        assert!(
            impossible.value > 90.0 && !impossible.passed,
            "{impossible:?}"
        );
        let folder = out.join(format!("run-{:04}", r.run));
        for f in [
            "fleet.toml",
            "config-chief.toml",
            "config-deputy.toml",
            "controller-chief-1.log",
            "controller-deputy-2.log",
        ] {
            assert!(folder.join(f).is_file(), "run {}: {f}", r.run);
        }
    }
    // The two vehicles' streams differ, and so do the dispersed runs'.
    let mut hashes: Vec<&str> = results
        .iter()
        .flat_map(|r| r.vehicle_state_sha256.values().map(String::as_str))
        .collect();
    hashes.sort_unstable();
    hashes.dedup();
    assert_eq!(hashes.len(), 2 * RUNS as usize);

    let summary = campaign(&CampaignCommand::Summarize { dir: out.clone() }).unwrap();
    eprintln!("{}", summary.text);
    assert_eq!(summary.exit_code, 3);
    assert!(
        summary
            .text
            .contains(&format!("criterion impossible_range: {RUNS} failing")),
        "{}",
        summary.text
    );
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header[..8],
        [
            "run",
            "chief.state_sha256",
            "deputy.state_sha256",
            "passed",
            "chief.hub.inertia_bc_b_kg_m2[0][0]",
            "deputy.relative.hill_position_m[0]",
            "deputy.relative.hill_position_m[1]",
            "deputy.relative.hill_position_m[2]",
        ]
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), RUNS as usize);
    for (row, r) in rows.iter().zip(&results) {
        assert_eq!(row[1], r.vehicle_state_sha256["chief"]);
        assert_eq!(row[2], r.vehicle_state_sha256["deputy"]);
        assert_eq!(
            row[4].parse::<f64>().unwrap(),
            r.applied["chief.hub.inertia_bc_b_kg_m2[0][0]"]
        );
    }

    // Run 2 again, alone, in another directory on another port: the same streams.
    let again = out.with_file_name("again");
    let alone = run(&file, &again, None, Some(2));
    assert_eq!(alone.exit_code, 3, "{}", alone.text);
    assert_eq!(
        result(&again, 2).vehicle_state_sha256,
        results[2].vehicle_state_sha256
    );
    assert!(!again.join("run-0001/result.json").exists());
}
