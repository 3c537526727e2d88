//! The configured `[epoch]` travels with the data (issue 19: "the epoch is in the config
//! queryable, the recording metadata and the CSV header comment"): `simulate` and `export` CSVs
//! open with `# epoch_utc=…`, a recording's vehicle metadata (which `flexdyn replay` serves as
//! the config queryable's reply) carries `epoch_utc`, and `flexdyn plot` reads such a CSV.
//! Without an `[epoch]` nothing changes: the CSV starts with its header.
//!
//! Oracle: the scenario file's own `epoch.utc` (`2026-11-24T06:00:00Z` in
//! `scenarios/leo_environment.toml`), written with nanoseconds.

use std::path::{Path, PathBuf};
use std::process::Command;

use flexdyn_sinks::export::{export, ExportArgs};
use flexdyn_sinks::reader::read_recording;

const LEO: &str = "scenarios/leo_environment.toml";
const LEO_EPOCH: &str = "2026-11-24T06:00:00.000000000Z";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("flexdyn-epoch-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn flexdyn(args: &[&str]) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "flexdyn {args:?}: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn first_lines(path: &Path, n: usize) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .take(n)
        .map(str::to_owned)
        .collect()
}

#[test]
fn the_scenario_states_the_epoch_this_test_expects() {
    let toml: toml::Table = std::fs::read_to_string(root().join(LEO))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(toml["epoch"]["utc"].as_str(), Some("2026-11-24T06:00:00Z"));
}

#[test]
fn simulate_writes_the_epoch_above_the_header_and_plot_reads_it() {
    let dir = scratch("simulate");
    let csv = dir.join("leo.csv");
    flexdyn(&[
        "simulate",
        "--config",
        LEO,
        "--duration-s",
        "1",
        "--log-every-s",
        "0.1",
        "-o",
        csv.to_str().unwrap(),
    ]);
    let lines = first_lines(&csv, 2);
    assert_eq!(lines[0], format!("# epoch_utc={LEO_EPOCH}"));
    assert!(lines[1].starts_with("t_s,"), "{}", lines[1]);
    flexdyn(&[
        "plot",
        csv.to_str().unwrap(),
        "--output",
        dir.join("figures").to_str().unwrap(),
    ]);
    assert!(dir.join("figures/attitude.png").is_file());

    // Without an [epoch], the header comes first, as before.
    let plain = dir.join("plain.csv");
    flexdyn(&[
        "simulate",
        "--duration-s",
        "0.1",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(first_lines(&plain, 1)[0].starts_with("t_s,"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_recording_carries_the_epoch_and_export_writes_it() {
    let dir = scratch("record");
    let mcap = dir.join("leo.mcap");
    flexdyn(&[
        "run",
        "--config",
        LEO,
        "--mode",
        "batch",
        "--duration-s",
        "0.5",
        "--listen",
        "tcp/127.0.0.1:0",
        "--record",
        mcap.to_str().unwrap(),
    ]);
    let rec = read_recording(&mcap).unwrap();
    let vehicles = rec.vehicles();
    assert_eq!(vehicles.len(), 1);
    assert_eq!(vehicles[0].epoch_utc.as_deref(), Some(LEO_EPOCH));
    // The same record is what the config queryable answers (JSON).
    let json = serde_json::to_value(&vehicles[0]).unwrap();
    assert_eq!(json["epoch_utc"], LEO_EPOCH);

    let csv_dir = dir.join("csv");
    export(&ExportArgs {
        file: mcap.clone(),
        csv: csv_dir.clone(),
    })
    .unwrap();
    let state_csv = csv_dir.join("flexdyn_sc1_tlm_state.csv");
    let lines = first_lines(&state_csv, 2);
    assert_eq!(lines[0], format!("# epoch_utc={LEO_EPOCH}"));
    assert!(lines[1].starts_with("t_s,"), "{}", lines[1]);
    std::fs::remove_dir_all(&dir).unwrap();
}
