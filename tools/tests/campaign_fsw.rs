//! Issue 37 §3: a campaign judged on what the flight code decided. `scenarios/fdir.toml` with a
//! random seizure of rw2 (`mtbf_s`) instead of its own faults, flown by `flexdyn-acs-demo
//! --fdir`, which publishes its FDIR events on the stream the scenario declares (`acs`). The
//! criterion `detection` is the latency from the seizure's activation to the flight code's first
//! `wheel-failure` event.
//!
//! The oracle recomputes every run's latency from its recording alone, with the `mcap` crate
//! and the wire decoders (not the campaign's reader): the seizure's first FaultEventMsg with
//! `active` gives its activation, the first recorded `acs` sample at or after it listing the
//! event's index (its position in the scenario's TOML) gives the detection. The campaign's
//! `result.json` and `summary.csv` must hold exactly that number; runs the seizure did not strike
//! must say the criterion does not apply. The same campaign without `--fdir` detects nothing:
//! every struck run fails with no value.

use std::path::{Path, PathBuf};

use flexdyn_campaign::verdict::Outcome;

use flexdyn_testkit::demo_bin::acs_demo as demo;

const RUNS: u32 = 6;
const SEIZE_FROM_S: f64 = 10.0;
const MTBF_S: f64 = 30.0;
const DURATION_S: f64 = 40.0;
/// \[s\] the bound: the demo declares a wheel failed after `WHEEL_PERSISTENCE` = 3 failed
/// frames of 0.1 s, and a seized wheel fails from its first frame (|r| ≈ u_max at once:
/// `flexdyn_acs_demo::fdir`), so about 0.3–0.4 s; 1 s is the requirement.
const BOUND_S: f64 = 1.0;

fn files(dir_name: &str, fdir: bool) -> (PathBuf, PathBuf, String) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(dir_name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = include_str!("../../scenarios/fdir.toml");
    // Its own two faults out, a random seizure in; its [[fsw_streams]] kept.
    let faults = scenario.find("\n[[faults]]").expect("fdir.toml's faults");
    let streams = scenario
        .find("\n# The flight code's own telemetry")
        .expect("fdir.toml's stream");
    let base = format!(
        "{}\n[[faults]]\ntarget = \"reaction_wheels.rw2\"\nmode = \"seized\"\n\
         start_s = {SEIZE_FROM_S:?}\nmtbf_s = {MTBF_S:?}\n{}",
        &scenario[..faults],
        &scenario[streams..]
    );
    std::fs::write(dir.join("base.toml"), &base).unwrap();
    let file = dir.join("campaign.toml");
    std::fs::write(
        &file,
        format!(
            r#"base = "base.toml"
runs = {RUNS}
seed = 3
duration_s = {DURATION_S:?}
participant_timeout_s = 10.0
controller = '''{} --connect {{endpoint}} --sc-id {{sc_id}} --sender-id {{sender_id}} --actuator wheels --attitude-source star-tracker --star-tracker st1 --rate-source gyro --imu imu_a --log-every-s 0 --idle-exit-s 1{}'''

[[criteria]]
name = "detection"
quantity = "fsw_event_latency"
stream = "acs"
event = "wheel-failure"
fault = "faults[0]"
below = {BOUND_S:?}
"#,
            demo(),
            if fdir { " --fdir" } else { "" }
        ),
    )
    .unwrap();
    (file, dir.join("out"), base)
}

fn run(file: &Path, out: &Path) -> (u8, String) {
    crate::support::campaign_run_and_summarize(file, out, false)
}

use crate::support::campaign_result as result;

/// From run `run`'s recording alone: (the seizure's activation \[ns\], the first `event`
/// sample's time at or after it \[ns\]).
fn recomputed(out: &Path, run: u32, event: u16) -> (Option<u64>, Option<u64>) {
    let bytes = std::fs::read(out.join(format!("run-{run:04}/recording.mcap"))).unwrap();
    let topics = flexdyn_proto::Topics::new("sc1").unwrap();
    let fsw_topic = flexdyn_proto::fsw_key("sc1", "acs").unwrap();
    let mut activation = None;
    let mut samples = Vec::new();
    for m in mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
    {
        if m.channel.topic == topics.fault_events() {
            let f = flexdyn_proto::decode_fault_event(&m.data).unwrap();
            if f.active && f.fault_index == 0 {
                activation = Some(activation.map_or(f.edge_ns, |a: u64| a.min(f.edge_ns)));
            }
        } else if m.channel.topic == fsw_topic {
            samples.push(flexdyn_proto::decode_fsw(&m.data).unwrap());
        }
    }
    assert!(!samples.is_empty(), "run {run}: no telemetry recorded");
    let detected = activation.and_then(|at| {
        samples
            .iter()
            .filter(|s| s.header.sim_time_ns >= at && s.event_indices().contains(&event))
            .map(|s| s.header.sim_time_ns)
            .min()
    });
    (activation, detected)
}

/// The index of `name` among the events of the base's first `[[fsw_streams]]`, read from its
/// TOML.
fn event_index(base: &str, name: &str) -> u16 {
    let doc: toml::Table = base.parse().unwrap();
    let events = doc["fsw_streams"][0]["events"].as_array().unwrap();
    events
        .iter()
        .position(|e| e["name"].as_str() == Some(name))
        .unwrap() as u16
}

/// The summary.csv column `name` of each row.
fn column(out: &Path, name: &str) -> Vec<String> {
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let mut lines = csv
        .lines()
        .map(|l| l.split(',').map(str::to_owned).collect::<Vec<_>>());
    let header = lines.next().unwrap();
    let col = header.iter().position(|h| h == name).unwrap();
    lines.map(|r| r[col].clone()).collect()
}

#[test]
fn detection_latency_is_judged_from_the_recorded_flight_code_events() {
    let (file, out, base) = files("campaign_fsw_fdir", true);
    let (code, text) = run(&file, &out);
    let wheel_failure = event_index(&base, "wheel-failure");
    let cells = column(&out, "detection");
    let passed = column(&out, "detection_passed");
    let (mut struck, mut spared) = (0, 0);
    for run in 0..RUNS {
        let r = result(&out, run);
        assert_eq!(r.status, "ok", "run {run}");
        let d = &r.criteria[0];
        let (activation, detected) = recomputed(&out, run, wheel_failure);
        assert_eq!(
            activation,
            r.fault_activations_ns.get("faults[0]").copied(),
            "run {run}: the recording's activation is the observer's"
        );
        match activation {
            Some(at) => {
                struck += 1;
                let t = detected.unwrap_or_else(|| panic!("run {run}: never detected"));
                let latency_s = (t - at) as f64 / 1e9;
                assert_eq!(d.value, latency_s, "run {run}");
                assert!(
                    d.applies && d.passed == (latency_s < BOUND_S),
                    "run {run}: {d:?}"
                );
                // The FDIR answers within a few frames, never before the fault.
                assert!(
                    (0.0..BOUND_S).contains(&latency_s),
                    "run {run}: {latency_s}"
                );
                assert_eq!(cells[run as usize].parse::<f64>().unwrap(), latency_s);
                assert_eq!(passed[run as usize], "true");
                assert_eq!(r.outcome, Outcome::Passed);
            }
            None => {
                spared += 1;
                assert!(
                    d.value.is_nan() && d.passed && !d.applies,
                    "run {run}: {d:?}"
                );
                assert_eq!(
                    d.note.as_deref(),
                    Some("faults[0] did not activate within the run")
                );
                assert_eq!(
                    (cells[run as usize].as_str(), passed[run as usize].as_str()),
                    ("", "true")
                );
            }
        }
    }
    assert!(
        struck > 0 && spared > 0,
        "both kinds of run: {struck} struck, {spared} spared"
    );
    assert_eq!(code, 0, "{text}");
    let rate = format!("  {struck} of {struck} passed (100.0 %); Wilson 95 % interval",);
    assert!(text.contains(&rate), "{text}");
    let skipped = format!(
        "(does not apply to {spared} run{}: faults[0] did not activate within the run)",
        if spared == 1 { "" } else { "s" }
    );
    assert!(text.contains(&skipped), "{text}");
    assert!(text.contains("criterion detection: 0 failing"), "{text}");

    // Without --fdir nothing is detected: each struck run fails with no value, and says why.
    let (file, out_off, _) = files("campaign_fsw_nofdir", false);
    let (code, text) = run(&file, &out_off);
    assert_eq!(code, 3, "{text}");
    for run in 0..RUNS {
        let d = result(&out_off, run).criteria[0].clone();
        let on = result(&out, run);
        let was_struck = on.fault_activations_ns.contains_key("faults[0]");
        assert!(d.value.is_nan(), "run {run}: {d:?}");
        assert_eq!(d.passed, !was_struck, "run {run}: {d:?}");
        if was_struck {
            let note = d.note.unwrap();
            assert!(
                note.starts_with("no \"wheel-failure\" event after faults[0] activated at "),
                "{note}"
            );
        }
    }
    assert!(
        text.contains(&format!(
            "criterion detection: {struck} failing; worst: run "
        )),
        "{text}"
    );
    assert!(
        text.contains("none (no \"wheel-failure\" event after faults[0]"),
        "{text}"
    );
}
