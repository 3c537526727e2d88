//! Faults are deterministic in lockstep (issue 21): the demo controller closes its loop on the
//! star tracker, the gyro and the four wheels of `scenarios/wheels_star_tracker.toml` while
//! scheduled faults hit a sensor (gyro bias step), a sensor again and again (star-tracker
//! validity forced off, periodic; not `dropout`, which the demo would wait out for its
//! `--sensor-timeout-s` at every lost sample), an actuator (wheel torque limit) and the controller's command link
//! (dropped, delayed by 3 frames, corrupted at a bit error rate of 10⁻³), and one random fault
//! seizes wheel rw4 at a time drawn from its seed (`mtbf_s`).
//!
//! - Two runs with the same seed give bit-identical StateMsg streams (sha256 over every state,
//!   ticks 0…N contiguous), as in `e2e_lockstep.rs`.
//! - A run with another seed gives another stream, and identical to the first up to the earlier
//!   of the two failure times ([`failure_delay_ns`]): the difference is the random fault's.

use flexdyn_testkit::demo_bin;

use std::process::Command;
use std::time::Duration;

use crate::support::{endpoint, ChildGuard, Recorder, ServerHandle};
use flexdyn_faults::failure_delay_ns;
use flexdyn_proto::{Mode, Topics};
use flexdyn_server::ServerSettings;
use sha2::{Digest, Sha256};

const RUN_S: f64 = 10.0;
const MTBF_S: f64 = 4.0;
const FRAME_NS: u64 = 10_000_000;

/// The scenario with every fault; `seed` is the random fault's.
fn config(seed: u64) -> flexdyn_vehicle::config::SimConfig {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios/wheels_star_tracker.toml");
    let faults = format!(
        r#"
[[faults]]
target = "imus.hub.gyro"
mode = "bias_step"
value = 2e-4
start_s = 1.0
duration_s = 1.5

[[faults]]
target = "star_trackers.st1"
mode = "validity_off"
start_s = 0.5
duration_s = 0.3
period_s = 2.0

[[faults]]
target = "reaction_wheels.rw2"
mode = "torque_limit"
fraction = 0.25
start_s = 2.0
duration_s = 2.0

[[faults]]
target = "links.1"
mode = "dropped"
start_s = 3.0
duration_s = 0.25

[[faults]]
target = "links.1"
mode = "delayed"
frames = 3.0
start_s = 4.0
duration_s = 1.0

[[faults]]
target = "links.1"
mode = "corrupted"
probability = 1e-3
start_s = 5.5
duration_s = 0.5
seed = 11

[[faults]]
target = "reaction_wheels.rw4"
mode = "seized"
mtbf_s = {MTBF_S:?}
seed = {seed}
"#
    );
    let text = std::fs::read_to_string(&path).unwrap() + &faults;
    flexdyn_vehicle::config::SimConfig::from_toml_str(&text).expect("the faulty scenario")
}

/// One lockstep run (participants: the demo controller 1 and the recorder 2): the report and
/// every state, sorted by tick.
fn run(seed: u64) -> (flexdyn_server::RunReport, Vec<(u64, Vec<u8>)>) {
    let topics = Topics::new("sc1").unwrap();
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        participants: vec![1, 2],
        participant_timeout: Duration::from_secs(10),
        presence_timeout: Duration::from_secs(30),
        duration_ns: Some((RUN_S * 1e9) as u64),
        ..ServerSettings::default()
    };
    let server = ServerHandle::start(settings, config(seed));
    let port = server.port;
    let recorder = Recorder::start(port, &topics, 2);
    let _ctrl = ChildGuard::spawn(crate::support::on_sensors(
        Command::new(demo_bin::acs_demo())
            .args(["--connect", &endpoint(port), "--sender-id", "1"])
            .args(["--k-nm", "10", "--p-nms", "150", "--log-every-s", "0"]),
        "hub",
    ));
    let report = server.join(Duration::from_secs(120)).expect("the run");
    let mut states = recorder.states.lock().unwrap().clone();
    states.sort_by_key(|(t, _)| *t);
    (report, states)
}

fn digest(states: &[(u64, Vec<u8>)]) -> String {
    let mut h = Sha256::new();
    for (i, (tick, bytes)) in states.iter().enumerate() {
        assert_eq!(*tick, i as u64, "ticks are not contiguous from 0");
        h.update(bytes);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The first two seeds whose failure falls within (1 s, 9 s) of the run, at different ticks.
fn two_seeds() -> [(u64, u64); 2] {
    let mut found = (0u64..)
        .map(|s| (s, failure_delay_ns(MTBF_S, s)))
        .filter(|(_, t)| (1_000_000_000..9_000_000_000).contains(t));
    let a = found.next().unwrap();
    let b = found.find(|b| b.1 / FRAME_NS != a.1 / FRAME_NS).unwrap();
    [a, b]
}

#[test]
fn scheduled_link_and_random_faults_are_bit_identical_for_a_seed() {
    let [(seed_a, fail_a_ns), (seed_b, fail_b_ns)] = two_seeds();
    let n_ticks = (RUN_S * 100.0) as usize + 1;
    let (report, a) = run(seed_a);
    assert_eq!(a.len(), n_ticks, "{report}");
    let hash_a = digest(&a);
    eprintln!(
        "seed {seed_a} (rw4 seizes at {} s): sha256 {hash_a}; {report}",
        fail_a_ns as f64 * 1e-9
    );
    // The link faults acted: the dropped window's 25 ticks were answered with nothing, the
    // delayed window's 100 frames held delayed commands, and the corrupted window damaged the
    // commands of its 50 ticks.
    let l = report.link_faults;
    assert_eq!(l.empty_answers, 25, "{report}");
    assert_eq!(l.delayed_frames, 100, "{report}");
    assert_eq!(l.commands_corrupted, 50, "{report}");

    let (_, b) = run(seed_a);
    assert_eq!(digest(&b), hash_a, "two runs with the same seed differ");

    let (_, c) = run(seed_b);
    assert_eq!(c.len(), n_ticks);
    assert_ne!(digest(&c), hash_a, "another seed, the same stream");
    let first_diff = a
        .iter()
        .zip(&c)
        .position(|(x, y)| x.1 != y.1)
        .expect("the streams differ") as u64;
    // The state of tick k carries the frame k−1 → k, where the seizure of tick ⌈t/frame⌉ first acts.
    let earliest = fail_a_ns.min(fail_b_ns) / FRAME_NS;
    assert!(
        first_diff >= earliest,
        "the streams differ at tick {first_diff}, before the earlier failure (tick {earliest})"
    );
    eprintln!(
        "seed {seed_b} (rw4 seizes at {} s): streams part at tick {first_diff}",
        fail_b_ns as f64 * 1e-9
    );
}
