//! The FDIR demo of issue 21 in lockstep: the flexdyn server runs `scenarios/fdir.toml` (in
//! this process, on a loopback port the OS chose) and `flexdyn-acs-demo --fdir` (a separate
//! process) points the spacecraft on the star tracker, the gyro of `imu_a` and four wheels while
//! a fault breaks one of them. Each case keeps one fault (the scenario's, or a variant of it):
//! - **stuck gyro** (`imus.imu_a.gyro`, `stuck_current` at 3 s): the frozen-output test declares
//!   it after exactly [`PERSISTENCE`] repeated samples; the rate feedback moves to `imu_b`;
//!   two FDIR runs give the same state stream bit for bit (sha256) and the same transcript;
//! - **gyro bias step** (the same target, `bias_step` of [`BIAS_RAD_S`] on axis 1 at 3 s): the
//!   star-tracker consistency test declares it within the window derived in
//!   [`bias_detection_window`]; the rate feedback moves to `imu_b`;
//! - **seized wheel** (`reaction_wheels.rw2`, `seized` at 60 s): the speed residual declares it
//!   after exactly [`PERSISTENCE`] frames (the braking torque shows in the first); the
//!   allocation moves to rw1, rw3, rw4;
//! - **both gyros stuck** (imu_b's gyro too, the same fault): both declared at once, the rate
//!   feedback moves to the star-tracker-derived rate;
//! - **healthy**: no detection at all (no false alarm); the largest statistics (1 = the
//!   threshold) are printed as the margins.
//!
//! For each fault the pointing error (truth) is under [`POINTING_BOUND_DEG`] for good within
//! [`RECOVERY_S`] of the detection, and a run of the same fault without `--fdir` is above it
//! after that time: the fault breaks the pointing and the FDIR is what restores it.
//!
//! Each run is 120 s of simulation at 10 Hz, 1200 lockstep ticks (about a second of wall time).

use flexdyn_testkit::demo_bin;

use std::process::{Command, Stdio};
use std::time::Duration;

use crate::support::{digest, endpoint, ChildGuard, Recorder, ServerHandle};
use flexdyn_faults::{FaultMode, FaultSpec};
use flexdyn_proto::{decode_state, Mode, Topics};
use flexdyn_server::ServerSettings;
use nalgebra::Vector3;

const FRAME_S: f64 = 0.1;
const DURATION_S: f64 = 120.0;
/// The scenario's fault times [s].
const GYRO_FAULT_S: f64 = 3.0;
const WHEEL_FAULT_S: f64 = 60.0;
/// The demo's persistence (`flexdyn_acs_demo::fdir::{GYRO,WHEEL}_PERSISTENCE`): failed tests
/// in a row before a unit is declared failed.
const PERSISTENCE: u64 = 3;
/// The bias step of the bias case [rad/s] (0.057°/s), on imu_a's axis 1 (x_B).
const BIAS_RAD_S: f64 = 1.0e-3;

/// The pointing bound [deg]. The demo's loop (K = 100 N·m, P = 300 N·m·s) points on the star
/// tracker with the gyro's rate: a gyro bias b leaves σ = P b / K, 4·3·|b| rad, 0.012° for the
/// scenario's |b_c| = 1.8e-5 rad/s (plus the bias instability's wander): 0.05° is four times
/// that. The healthy run is checked under it from [`SETTLE_S`].
const POINTING_BOUND_DEG: f64 = 0.05;
/// The healthy run starts on target turning at 0.033°/s; the loop's decay rate is
/// P/(2 I) ≈ 300/(2 · 1400) = 0.107 s⁻¹ (I about z), so its 0.12° overshoot is under 0.05°
/// after ln(0.12/0.05)/0.107 ≈ 8 s past the peak (~8 s): 30 s.
const SETTLE_S: f64 = 30.0;
/// A fault's transient (≤ 0.5°: the seized wheel's 1.5 N·m·s dumped into the hub) decays to the
/// bound in ln(10)/0.107 ≈ 22 s once the FDIR has reconfigured; 40 s leaves margin for the
/// braking (7.5 s) and the bias wander.
const RECOVERY_S: f64 = 40.0;

struct Run {
    states: Vec<(u64, Vec<u8>)>,
    /// The demo's standard output.
    transcript: String,
}

fn scenario() -> flexdyn_vehicle::config::SimConfig {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/fdir.toml");
    flexdyn_vehicle::config::SimConfig::from_file(&path).expect("fdir.toml")
}

/// The scenario's fault on `target`.
fn fault(target: &str) -> FaultSpec {
    let faults = scenario().faults;
    assert_eq!(faults.len(), 2, "the scenario's two faults");
    faults
        .into_iter()
        .find(|f| f.target == target)
        .unwrap_or_else(|| panic!("no fault on {target}"))
}

/// One lockstep run of `scenarios/fdir.toml` with `faults` instead of its own.
fn run(faults: &[FaultSpec], fdir: bool) -> Run {
    let topics = Topics::new("sc1").unwrap();
    let mut cfg = scenario();
    cfg.faults = faults.to_vec();
    let server = ServerHandle::start(
        ServerSettings {
            mode: Mode::Lockstep,
            participants: vec![1, 2],
            participant_timeout: Duration::from_secs(30),
            presence_timeout: Duration::from_secs(30),
            duration_ns: Some((DURATION_S * 1e9).round() as u64),
            ..ServerSettings::default()
        },
        cfg,
    );
    let port = server.port;
    let recorder = Recorder::start(port, &topics, 2);
    let mut cmd = Command::new(demo_bin::acs_demo());
    cmd.args(["--connect", &endpoint(port), "--sender-id", "1"])
        .args(["--actuator", "wheels"])
        .args(["--attitude-source", "star-tracker", "--star-tracker", "st1"])
        .args(["--rate-source", "gyro", "--imu", "imu_a"])
        .args(["--log-every-s", "0", "--idle-exit-s", "2"]);
    if fdir {
        cmd.arg("--fdir");
    }
    let mut demo = ChildGuard(
        cmd.stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn flexdyn-acs-demo"),
    );
    let report = server
        .join(Duration::from_secs(300))
        .expect("the lockstep run");
    assert_eq!(report.last_tick, (DURATION_S / FRAME_S).round() as u64);
    let transcript = crate::support::finish_demo(&mut demo);
    let mut states = recorder.states.lock().unwrap().clone();
    states.sort_by_key(|(t, _)| *t);
    Run { states, transcript }
}

/// The truth pointing error [deg] by tick: the rotation angle of σ_BR (target σ_RN = 0),
/// 4 atan |σ_BN|.
fn pointing_deg(states: &[(u64, Vec<u8>)]) -> Vec<f64> {
    states
        .iter()
        .map(|(_, b)| {
            let s = Vector3::from(decode_state(b).unwrap().sigma_bn);
            (4.0 * s.norm().atan()).to_degrees()
        })
        .collect()
}

/// `key=value` of a transcript line.
fn field<'a>(line: &'a str, key: &str) -> &'a str {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
        .unwrap_or_else(|| panic!("no {key}= in `{line}`"))
}

/// The transcript's lines starting with `prefix`.
fn lines<'a>(transcript: &'a str, prefix: &str) -> Vec<&'a str> {
    transcript
        .lines()
        .filter(|l| l.starts_with(prefix))
        .collect()
}

/// The largest pointing error [deg] from `from_s` to the end.
fn worst_after(pointing: &[f64], from_s: f64) -> f64 {
    let first = (from_s / FRAME_S).round() as usize;
    pointing[first..].iter().copied().fold(0.0, f64::max)
}

/// The star-tracker test's threshold across the boresight [rad], re-derived from
/// `scenarios/fdir.toml`'s specifications (module docs of `flexdyn_acs_demo::fdir`): a window
/// W = 1 s, gyro ARW N = 4.3633e-5 rad/s/√Hz, bias |b_c| = |(1.4544, −0.9696, 0.4848)e-5| rad/s,
/// bias instability σ_bi = 7.8530e-6 rad/s, tracker σ_x = 2.4241e-5 rad across its boresight:
/// 5 √(2σ_x² + N² W) + (|b_c| + 4√3 σ_bi) W = 3.50e-4 rad.
fn threshold_across_rad() -> f64 {
    let w: f64 = 1.0;
    let n = 4.3633e-5;
    let sigma_x = 2.4241e-5;
    let b_c = Vector3::new(1.4544e-5, -0.9696e-5, 0.4848e-5).norm();
    let b_max = b_c + 4.0 * 3f64.sqrt() * 7.8530e-6;
    5.0 * (2.0 * sigma_x * sigma_x + n * n * w).sqrt() + b_max * w
}

/// The window of ticks in which the bias step's detection must fall. The step β = [`BIAS_RAD_S`]
/// along x_B (across the boresight −y_B) adds −β t_on to the residual's across part once it has
/// been on for t_on ≤ W; the healthy part is within the threshold T (that is how T is made, at
/// 5σ), so a test fails for sure once β t_on > 2T. The first faulted test is one tracker period
/// after the fault, so with [`PERSISTENCE`] failed tests in a row the detection is no earlier
/// than fault + 3 periods (the healthy run shows no earlier failure), and no later than the
/// first test with t_on ≥ 2T/β plus two periods.
fn bias_detection_window(fault_tick: u64) -> (u64, u64) {
    let certain_s = 2.0 * threshold_across_rad() / BIAS_RAD_S;
    let certain_tick = fault_tick + (certain_s / FRAME_S).ceil() as u64;
    (fault_tick + PERSISTENCE, certain_tick + PERSISTENCE - 1)
}

/// The detection of a run: its one `fdir-detect` line, checked to be `what`/`unit`, and its tick.
fn the_detection(run: &Run, what: &str, unit: &str, test: &str) -> u64 {
    let detections = lines(&run.transcript, "fdir-detect");
    assert_eq!(detections.len(), 1, "{}", run.transcript);
    let d = detections[0];
    assert_eq!(field(d, "what"), what, "{d}");
    assert_eq!(field(d, "unit"), unit, "{d}");
    assert_eq!(field(d, "test"), test, "{d}");
    field(d, "tick").parse().unwrap()
}

/// The pointing checks of a fault detected at `tick`: with FDIR (`on`) under the bound for good
/// within [`RECOVERY_S`]; without (`off`) above it at some time after that. Prints the figures.
fn check_recovery(name: &str, tick: u64, on: &Run, off: &Run) {
    assert!(
        lines(&off.transcript, "fdir-").is_empty(),
        "{}",
        off.transcript
    );
    let t_det = tick as f64 * FRAME_S;
    let from = t_det + RECOVERY_S;
    let (p_on, p_off) = (pointing_deg(&on.states), pointing_deg(&off.states));
    let recovered_at = (0..p_on.len())
        .rev()
        .find(|&k| p_on[k] >= POINTING_BOUND_DEG)
        .map_or(0.0, |k| (k + 1) as f64 * FRAME_S);
    let (peak_on, peak_off) = (worst_after(&p_on, t_det), worst_after(&p_off, t_det));
    let (after_on, after_off) = (worst_after(&p_on, from), worst_after(&p_off, from));
    eprintln!(
        "{name}: detected at {t_det:.1} s; FDIR on: peak {peak_on:.4} deg, under \
         {POINTING_BOUND_DEG} deg for good from {recovered_at:.1} s ({:.1} s after the \
         detection), worst from {from:.1} s {after_on:.4} deg; FDIR off: peak {peak_off:.4} deg, \
         worst from {from:.1} s {after_off:.4} deg",
        recovered_at - t_det
    );
    assert!(
        after_on < POINTING_BOUND_DEG,
        "{name}: FDIR on, {after_on} deg"
    );
    assert!(
        after_off > POINTING_BOUND_DEG,
        "{name}: FDIR off, {after_off} deg"
    );
}

#[test]
fn a_stuck_gyro_is_detected_isolated_and_recovered() {
    let stuck = fault("imus.imu_a.gyro");
    assert_eq!(stuck.mode, FaultMode::StuckCurrent);
    let a = run(std::slice::from_ref(&stuck), true);
    let tick = the_detection(&a, "gyro", "imu_a", "frozen");
    // The first stuck sample is the one at the fault's tick (the healthy value, held): the
    // next PERSISTENCE samples repeat it.
    let fault_tick = (GYRO_FAULT_S / FRAME_S).round() as u64;
    assert_eq!(tick, fault_tick + PERSISTENCE, "{}", a.transcript);
    let switch = lines(&a.transcript, "fdir-rate-source");
    assert_eq!(switch.len(), 1, "{}", a.transcript);
    assert_eq!(field(switch[0], "source"), "imu_b");
    assert_eq!(field(switch[0], "tick"), tick.to_string());

    let b = run(std::slice::from_ref(&stuck), true);
    let hash = digest(&a.states);
    assert_eq!(digest(&b.states), hash, "two FDIR runs differ");
    assert_eq!(b.transcript, a.transcript);
    eprintln!(
        "stuck gyro, FDIR on: two runs, {} ticks, sha256 {hash}",
        a.states.len()
    );

    let off = run(&[stuck], false);
    check_recovery("stuck gyro", tick, &a, &off);
}

#[test]
fn a_gyro_bias_is_detected_against_the_star_tracker() {
    let mut bias = fault("imus.imu_a.gyro");
    bias.mode = FaultMode::BiasStep { value: BIAS_RAD_S };
    bias.axes = 0b001;
    let a = run(std::slice::from_ref(&bias), true);
    let tick = the_detection(&a, "gyro", "imu_a", "star-tracker");
    let fault_tick = (GYRO_FAULT_S / FRAME_S).round() as u64;
    let (lo, hi) = bias_detection_window(fault_tick);
    eprintln!(
        "gyro bias step at {GYRO_FAULT_S} s: detected at {:.1} s, derived window [{:.1}, {:.1}] s \
         (threshold {:.3e} rad across the boresight)",
        tick as f64 * FRAME_S,
        lo as f64 * FRAME_S,
        hi as f64 * FRAME_S,
        threshold_across_rad()
    );
    assert!(
        (lo..=hi).contains(&tick),
        "tick {tick}, window [{lo}, {hi}]"
    );
    let switch = lines(&a.transcript, "fdir-rate-source");
    assert_eq!(switch.len(), 1, "{}", a.transcript);
    assert_eq!(field(switch[0], "source"), "imu_b");

    let off = run(&[bias], false);
    check_recovery("gyro bias step", tick, &a, &off);
}

#[test]
fn a_seized_wheel_is_detected_and_dropped() {
    let seized = fault("reaction_wheels.rw2");
    assert_eq!(seized.mode, FaultMode::Seized);
    let a = run(std::slice::from_ref(&seized), true);
    let tick = the_detection(&a, "wheel", "rw2", "speed");
    // The brake acts from the fault's first step: the speed at the next tick already shows it
    // (|r| ≈ 0.2 N·m against a threshold of ~1.1e-3 N·m), so the third failed frame ends at
    // fault + 3 frames.
    let fault_tick = (WHEEL_FAULT_S / FRAME_S).round() as u64;
    assert_eq!(tick, fault_tick + PERSISTENCE, "{}", a.transcript);
    let wheels = lines(&a.transcript, "fdir-wheels");
    assert_eq!(wheels.len(), 1, "{}", a.transcript);
    assert_eq!(field(wheels[0], "active"), "rw1,rw3,rw4");
    assert_eq!(field(wheels[0], "tick"), tick.to_string());
    assert!(lines(&a.transcript, "fdir-rate-source").is_empty());

    let off = run(&[seized], false);
    check_recovery("seized wheel", tick, &a, &off);
}

#[test]
fn a_healthy_run_raises_no_alarm() {
    let a = run(&[], true);
    assert!(
        lines(&a.transcript, "fdir-detect").is_empty(),
        "{}",
        a.transcript
    );
    let summary = lines(&a.transcript, "fdir-summary");
    assert_eq!(summary.len(), 1, "{}", a.transcript);
    eprintln!("healthy, FDIR on: {}", summary[0]);
    let settled = worst_after(&pointing_deg(&a.states), SETTLE_S);
    eprintln!("healthy, FDIR on: worst error from {SETTLE_S} s {settled:.4} deg");
    assert!(settled < POINTING_BOUND_DEG, "{settled} deg");
}

#[test]
fn both_gyros_stuck_fall_back_to_star_tracker_rates() {
    // The scenario with imu_b's gyro stuck at the same time as imu_a's.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/fdir.toml");
    let text = std::fs::read_to_string(&path).unwrap()
        + "\n[[faults]]\ntarget = \"imus.imu_b.gyro\"\nmode = \"stuck_current\"\nstart_s = 3.0\n";
    let both = flexdyn_vehicle::config::SimConfig::from_toml_str(&text)
        .unwrap()
        .faults;
    let faults: Vec<FaultSpec> = both
        .into_iter()
        .filter(|f| f.target.contains("gyro"))
        .collect();
    assert_eq!(faults.len(), 2);
    let a = run(&faults, true);
    let tick = (GYRO_FAULT_S / FRAME_S).round() as u64 + PERSISTENCE;
    let detections = lines(&a.transcript, "fdir-detect");
    assert_eq!(detections.len(), 2, "{}", a.transcript);
    for (d, unit) in detections.iter().zip(["imu_a", "imu_b"]) {
        assert_eq!(field(d, "unit"), unit, "{d}");
        assert_eq!(field(d, "test"), "frozen", "{d}");
        assert_eq!(field(d, "tick"), tick.to_string(), "{d}");
    }
    let switch = lines(&a.transcript, "fdir-rate-source");
    assert_eq!(switch.len(), 1, "{}", a.transcript);
    assert_eq!(field(switch[0], "source"), "star-tracker");
    let off = run(&faults, false);
    check_recovery("both gyros stuck", tick, &a, &off);
}
