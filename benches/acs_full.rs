//! The full ACS scenario (`scenarios/acs_full.toml`: hub, two dual-hinged pairs, four wheels,
//! rods, thrusters, facets, gravity gradient, drag, SRP, the field, and every sensor kind),
//! offline, in two cases:
//! - **shipped**: the file as it is (10 ms RK4 step, 10 Hz frames and sensors);
//! - **1 ms + GPS**: a 1 ms step and a 1 Hz GPS receiver added.
//!
//! Each case is timed four ways, per RK4 step:
//! - `vehicle`: the vehicle runtime alone, frame by frame as the server steps it
//!   (`Simulation::step_frame`, then the sensors due at the next tick), with the environment
//!   models on their worker thread as the server runs them (`offload_environment`);
//! - `+records`: the same, plus the records the server fills at each tick: the state, and the
//!   environment record when `telemetry_rate_hz` makes it due (every frame in this file);
//! - `1 thread`: the same with the environment models on the stepping thread, i.e. everything
//!   on one core, as Basilisk runs;
//! - `simulate`: the `flexdyn simulate` loop writing a row every second into a sink, so the
//!   cost of the front end shows beside the runtime's.
//!
//! The worker is a cache: a sample it has not answered in time is evaluated on the stepping
//! thread, and the output is the same bits either way. The summary prints the share of samples
//! the worker answered.
//!
//! Issue 41's goal is the full scenario at ≥ 20× Basilisk's same scenario, measured in the same
//! run. With `FLEXDYN_PEERS_PYTHON` (a Python with `bsk==2.12.1` and numpy) and
//! `FLEXDYN_PEER_BSK_ACS` (the path of `bsk_acs_full.py`, Basilisk's closest equivalent of
//! this file, kept outside the project) set, each round also runs Basilisk on the same case,
//! alternating with flexdyn (A B A B) so that a change in machine load hits both alike, and the
//! summary prints Basilisk's median beside flexdyn's with the speed-up. Without them the peer
//! columns say so.
//!
//! `cargo bench --bench acs_full`; environment `FLEXDYN_BENCH_ROUNDS` (default 5).

use flexdyn_testkit::median;
use std::hint::black_box;
use std::io;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use flexdyn::commands::simulate::simulate_to;
use flexdyn_proto::EnvironmentMsg;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

const ACS_FULL: &str = include_str!("../scenarios/acs_full.toml");
/// Simulated seconds per timed span (flexdyn and Basilisk alike).
const SPAN_S: f64 = 10.0;
/// Spans per flexdyn vehicle measurement, whose median it reports ([`time_vehicle`]).
const SPANS: usize = 5;

/// The LEO scenario, whose 1 Hz GPS receiver the "1 ms + GPS" case adds.
const LEO: &str = include_str!("../scenarios/leo_environment.toml");

/// The `[[gps_receivers]]` table of `scenarios/leo_environment.toml`, up to the next table.
fn leo_gps_receiver() -> &'static str {
    let start = LEO
        .find("\n[[gps_receivers]]\n")
        .expect("leo_environment.toml has a [[gps_receivers]] table");
    let rest = &LEO[start + 1..];
    let end = rest[1..].find("\n[").map_or(rest.len(), |i| i + 2);
    &rest[..end]
}

struct Case {
    label: &'static str,
    toml: String,
    /// What Basilisk's script is given for the same case.
    peer_args: &'static [&'static str],
}

fn cases() -> Vec<Case> {
    let one_ms = ACS_FULL.replacen("step_s = 0.01\n", "step_s = 0.001\n", 1);
    assert_ne!(
        one_ms, ACS_FULL,
        "acs_full.toml no longer says `step_s = 0.01`"
    );
    vec![
        Case {
            label: "shipped (10 ms)",
            toml: ACS_FULL.to_owned(),
            peer_args: &["--step-ms", "10"],
        },
        Case {
            label: "1 ms + GPS",
            toml: format!("{one_ms}\n{}", leo_gps_receiver()),
            peer_args: &["--step-ms", "1", "--gps"],
        },
    ]
}

fn config(case: &Case) -> SimConfig {
    SimConfig::from_toml_str_in(&case.toml, Path::new(env!("CARGO_MANIFEST_DIR")))
        .unwrap_or_else(|e| panic!("{}: {e}", case.label))
}

/// ns per RK4 step of the vehicle's frame as the server runs it (`step_frame`, then the sensors
/// due at the next tick sampled): the median of [`SPANS`] consecutive spans, after a one-second
/// warm-up; with `offload`, the environment models on their worker thread. Also the share of
/// environment samples the worker answered (0 without it).
///
/// One span of the shipped case is 1,000 steps, about 4 ms of wall time: one interrupt or
/// migration moves a single span's figure by tens of percent (session 21 saw a binary's rounds
/// swing between two modes), so each measurement is the median of several, as Basilisk's peer
/// takes the median of its spans.
///
/// With `records`, each frame also fills the records the server publishes at its tick
/// (`flexdyn_server::stepper`): the state record, and the environment record on the ticks
/// that are multiples of `environment_every_frames`.
fn time_vehicle(cfg: &SimConfig, offload: bool, records: bool) -> (f64, f64) {
    let mut sim = Simulation::new(cfg).expect("the scenario builds");
    if offload {
        sim.offload_environment()
            .expect("the environment worker starts");
    }
    let frames_per_s = (1e9 / cfg.frame_ns as f64).round() as u64;
    let mut tick = 0u64;
    let mut state = sim.blank_state();
    let mut environment = EnvironmentMsg::default();
    let mut frame = |sim: &mut Simulation| {
        sim.step_frame();
        tick += 1;
        sim.sample_sensors(|s| s.due(tick));
        if records {
            sim.state_into(&mut state);
            if let Some(every) = sim.environment_every_frames() {
                if tick.is_multiple_of(every) {
                    sim.environment_into(&mut environment);
                }
            }
            black_box((&state, &environment));
        }
    };
    for _ in 0..frames_per_s {
        frame(&mut sim);
    }
    let frames = (SPAN_S * frames_per_s as f64) as u64;
    let steps = (frames * sim.steps_per_frame()) as f64;
    let mut spans = Vec::with_capacity(SPANS);
    for _ in 0..SPANS {
        let t = Instant::now();
        for _ in 0..frames {
            frame(&mut sim);
        }
        spans.push(t.elapsed().as_nanos() as f64 / steps);
    }
    black_box(sim.t_sim_ns());
    let updates_per_s = cfg
        .environment
        .as_ref()
        .map_or(0.0, |e| 1e9 / e.update_ns as f64);
    let updates = (SPAN_S * SPANS as f64 + 1.0) * updates_per_s;
    let answered = sim.environment().map_or(0, |e| e.prefetched_samples()) as f64;
    (
        median(spans),
        if updates > 0.0 {
            answered / updates
        } else {
            0.0
        },
    )
}

/// ns per RK4 step of the `simulate` loop writing a row every second into a sink.
fn time_simulate(cfg: &SimConfig) -> f64 {
    let report = simulate_to(cfg, SPAN_S, 1.0, io::sink(), "sink").expect("simulate runs");
    report.wall_s * 1e9 / report.steps as f64
}

/// Basilisk's median ns per step for `case`, from its `median_ns_per_step=` field.
fn time_peer(python: &str, script: &Path, init_csv: &Path, case: &Case) -> Result<f64, String> {
    let out = Command::new(python)
        .arg(script)
        .args(["--init-csv", &init_csv.to_string_lossy()])
        .args(case.peer_args)
        .args(["--sim-s", &SPAN_S.to_string(), "--reps", "3"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run {python} {}: {e}", script.display()))?;
    if !out.status.success() {
        return Err(format!("{} exited with {}", script.display(), out.status));
    }
    String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .find_map(|kv| kv.strip_prefix("median_ns_per_step="))
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| format!("{} printed no median_ns_per_step=", script.display()))
}

/// The peer's Python and script, when both are given.
fn peer() -> Option<(String, PathBuf)> {
    let python = std::env::var("FLEXDYN_PEERS_PYTHON").ok()?;
    let script = PathBuf::from(std::env::var("FLEXDYN_PEER_BSK_ACS").ok()?);
    Some((python, script))
}

fn main() {
    // `cargo bench` passes `--bench`; a plain `cargo test` build of the benches runs nothing.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let rounds: usize = std::env::var("FLEXDYN_BENCH_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5)
        .max(1);
    let peer = peer();
    let scratch = std::env::temp_dir().join(format!("flexdyn-bench-acs-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).expect("a scratch folder");
    println!("acs_full: {rounds} rounds of {SPAN_S} s simulated per case and measurement");
    let mut summary = Vec::new();
    for case in cases() {
        let cfg = config(&case);
        // Basilisk starts from flexdyn's own t = 0 state: the first row of a simulate CSV.
        let init_csv = scratch.join("t0.csv");
        let file = std::fs::File::create(&init_csv).expect("the t = 0 CSV");
        simulate_to(
            &cfg,
            cfg.step_ns as f64 * 1e-9,
            cfg.step_ns as f64 * 1e-9,
            file,
            "t0.csv",
        )
        .expect("the t = 0 row");
        let (mut vehicle, mut records, mut one_thread, mut simulate, mut basilisk) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut answered = Vec::new();
        for round in 0..rounds {
            let (ns, share) = time_vehicle(&cfg, true, false);
            vehicle.push(ns);
            answered.push(share);
            records.push(time_vehicle(&cfg, true, true).0);
            one_thread.push(time_vehicle(&cfg, false, false).0);
            simulate.push(time_simulate(&cfg));
            let peer_ns = peer
                .as_ref()
                .map(|(python, script)| time_peer(python, script, &init_csv, &case));
            match &peer_ns {
                Some(Ok(ns)) => basilisk.push(*ns),
                Some(Err(e)) => println!("  basilisk: {e}"),
                None => {}
            }
            println!(
                "{:<16} round {round}: vehicle {:>8.0} ns/step ({:.0} % of samples from the worker), \
                 +records {:>8.0}, 1 thread {:>8.0}, simulate {:>8.0}{}",
                case.label,
                vehicle[round],
                answered[round] * 100.0,
                records[round],
                one_thread[round],
                simulate[round],
                match peer_ns {
                    Some(Ok(ns)) => format!(", basilisk {ns:>9.0} ns/step"),
                    _ => String::new(),
                }
            );
        }
        summary.push((
            case.label,
            [
                median(vehicle),
                median(records),
                median(one_thread),
                median(simulate),
            ],
            (!basilisk.is_empty()).then(|| median(basilisk)),
        ));
    }
    let _ = std::fs::remove_dir_all(&scratch);
    println!(
        "\nns per step (medians), and Basilisk's time over each:\n{:<16} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "case", "vehicle", "+records", "1 thread", "simulate", "basilisk", "×vehicle", "×records", "×1thread", "×simul."
    );
    for (label, ns, b) in summary {
        let [v, rec, one, s] = ns;
        match b {
            Some(b) => println!(
                "{label:<16} {v:>9.0} {rec:>9.0} {one:>9.0} {s:>9.0} {b:>9.0} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
                b / v,
                b / rec,
                b / one,
                b / s
            ),
            None => println!(
                "{label:<16} {v:>9.0} {rec:>9.0} {one:>9.0} {s:>9.0} {:>9} {:>9} {:>9} {:>9} {:>9}",
                "(no peer)", "-", "-", "-", "-"
            ),
        }
    }
    if peer.is_none() {
        println!(
            "\nbasilisk: skipped (set FLEXDYN_PEERS_PYTHON and FLEXDYN_PEER_BSK_ACS; \
             see docs/developer/benchmarks.md, \"Performance\")"
        );
    }
}
