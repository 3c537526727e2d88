//! Lockstep throughput versus a plain Zenoh ping-pong, measured in the same run.
//!
//! Each round runs, on loopback with the same transport settings:
//! 1. ping-pong: this process pings (a StateMsg-sized sample), `flexdyn-pingpong pong` (a child
//!    process) answers with a CommandMsg-sized sample; once right before and once right after
//!    case 2's direct run, and the round's ping-pong rate is the geometric mean of the two (the
//!    load of this VM drifts within seconds: with one ping-pong per round, before every lockstep
//!    run, the per-round ratios of one binary ranged from 0.76 to 1.13 on 2026-12-01). Every
//!    case's ratio divides by it; only case 2's runs between the two;
//! 2. lockstep, one RK4 step per frame (1 kHz frames): the server in this process, the demo
//!    controller `flexdyn-acs-demo` as a child process (answering each tick on the Zenoh thread
//!    that completes it, its default `--answer-on zenoh-thread`), once with the server's
//!    `handoff = "direct"` (the default: the Zenoh thread that delivers the answer steps and
//!    publishes) and once with `handoff = "thread"` (the previous design: physics thread +
//!    telemetry thread), so the before and after are measured side by side;
//! 3. lockstep with the reference configuration (100 Hz frames, 10 RK4 steps per frame), direct;
//! 4. case 2, direct, with the demo publishing the flight code's telemetry every tick (a declared
//!    `[[fsw_streams]]`: one FswMsg per tick, 1 kHz), against case 2 without it in the same
//!    round: what the telemetry intake costs the loop (issue 37).
//! 5. case 2, direct, with the demo answering on its main thread (`--answer-on main-thread`,
//!    its design before it answered on the Zenoh thread that completes the tick): the client's
//!    own thread hop, side by side.
//!
//! It prints each round and the medians: round trips/s, ticks/s, and the median of the per-round
//! ratios (target ≥ 0.95 × the ping-pong for the one-step case, where the link dominates).
//!
//! Both sides leave their first 1000 iterations out: the ping-pong its first 1000 round trips
//! (unmeasured), the lockstep runs their first 1000 ticks (the server's settled tick rate,
//! `settled_ticks_per_s` of its run report, [`flexdyn_server::tick_cost`]). The first
//! iterations after an idle spell are slower on this VM, for both: a ping-pong started after
//! 400 ms idle took 101–105 µs per round trip over its first 1000 and 85–88 µs after. The
//! whole-run lockstep rate (first ticks included) is printed beside it for the one-step case,
//! with the server's per-tick breakdown (stepping, publishing, waiting for the answer).
//! Rounds alternate the measurements so that a change in machine load hits every side alike.
//! The physics cost of a frame is measured alone too, to explain the reference case.
//!
//! `cargo bench -p flexdyn-tools --bench lockstep`; environment: `FLEXDYN_BENCH_TICKS`
//! (default 10000 ticks per measurement), `FLEXDYN_BENCH_ROUNDS` (default 9, at most 11).
//! Every process listens on a port the OS chose (port 0) and reports it.

use flexdyn_testkit::demo_bin;
use flexdyn_testkit::median_mut;
use flexdyn_testkit_server as support;

use std::process::Command;
use std::time::{Duration, Instant};

use flexdyn_proto::Mode;
use flexdyn_server::{Handoff, ServerSettings};
use flexdyn_vehicle::sim::Simulation;
use support::{endpoint, reference_config, ChildGuard, ServerHandle};

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Round trips per second of `ticks` ping-pongs; the pong answers inside its Zenoh callback, or
/// from a receive loop (`recv_loop`, the demo controller's structure).
fn pingpong_rate(ticks: usize, recv_loop: bool) -> f64 {
    let rtts = pingpong_rtts(1000, ticks, recv_loop);
    let total: Duration = rtts.iter().sum();
    ticks as f64 / total.as_secs_f64()
}

/// The flight code's telemetry stream the demo publishes when the configuration declares it
/// (`flexdyn_acs_demo::telemetry`: its estimate and target, its control rate, its wheel
/// momentum), one FswMsg per answered tick.
const FSW_STREAM: &str = "
[[fsw_streams]]
name = \"acs\"
modes = [\"pointing\"]
values = [
  { name = \"rate_b_rad_s\", type = \"f64\", len = 3, unit = \"rad/s\" },
  { name = \"wheel_momentum_b_nms\", type = \"f64\", len = 3, unit = \"N·m·s\" },
]
";

/// A lockstep run's rates and the server's per-tick breakdown.
#[derive(Clone, Copy)]
struct Measured {
    /// Ticks per second from the 1000th tick to the last (the server's settled rate).
    settled_ticks_per_s: f64,
    /// Ticks per second over the whole run (its first 1000 ticks included).
    whole_ticks_per_s: f64,
    /// Where the server's ticks went.
    ticks: flexdyn_server::tick_cost::TickSummary,
}

/// A lockstep run of `ticks` frames at `frame_hz` with the demo controller answering on the
/// Zenoh thread that delivered the tick (its default `--answer-on zenoh-thread`).
fn lockstep_rate(ticks: usize, frame_hz: f64, handoff: Handoff) -> Measured {
    lockstep_rate_of(
        ticks,
        reference_config(frame_hz),
        handoff,
        "zenoh-thread",
        false,
    )
}

/// [`lockstep_rate`] with the demo publishing its telemetry every tick ([`FSW_STREAM`]).
fn lockstep_rate_with_telemetry(ticks: usize, frame_hz: f64) -> Measured {
    lockstep_rate_of(
        ticks,
        support::reference_config_with(frame_hz, FSW_STREAM),
        Handoff::Direct,
        "zenoh-thread",
        true,
    )
}

/// A lockstep run of `ticks` frames (plus the 1000 the settled rate leaves out) of `cfg`, the
/// server stepping with `handoff`, the demo answering on `answer_on` (its `--answer-on`); with
/// `expect_telemetry`, checks that the demo's telemetry came every answered tick.
fn lockstep_rate_of(
    ticks: usize,
    cfg: flexdyn_vehicle::config::SimConfig,
    handoff: Handoff,
    answer_on: &str,
    expect_telemetry: bool,
) -> Measured {
    // At least one tick after the settled one, so that the run has a settled rate.
    let ticks = ticks.max(1) + flexdyn_server::tick_cost::SETTLE_TICKS as usize;
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        handoff,
        participants: vec![1],
        duration_ns: Some(ticks as u64 * cfg.frame_ns),
        summary_interval: Duration::from_secs(3600),
        ..ServerSettings::default()
    };
    let server = ServerHandle::start(settings, cfg);
    let port = server.port;
    // The reference config has no IMU: take the rate from the state (one message each way per
    // tick, like the ping-pong) rather than letting `auto` spend a second looking for a gyro.
    let _ctrl = ChildGuard::spawn(Command::new(demo_bin::acs_demo()).args([
        "--connect",
        &endpoint(port),
        "--log-every-s",
        "0",
        "--rate-source",
        "truth",
        "--answer-on",
        answer_on,
    ]));
    let report = server.join(Duration::from_secs(300)).expect("lockstep run");
    if expect_telemetry {
        // The demo answers ticks 0..last; the last tick's sample is not recorded (a lockstep
        // run awaits no answer to it).
        assert_eq!(
            report.fsw_accepted, report.last_tick,
            "the demo's telemetry: one sample per answered tick, none refused ({:?})",
            report.rejected
        );
    }
    let summary = report.ticks.expect("a lockstep run reports its ticks");
    let whole = report.last_tick as f64 / report.wall_s;
    Measured {
        settled_ticks_per_s: summary
            .settled_ticks_per_s
            .expect("a run past its settling ticks"),
        whole_ticks_per_s: whole,
        ticks: summary,
    }
}

/// \[µs\] physics cost of one frame (step_frame + state_into), alone.
fn physics_frame_us(frame_hz: f64) -> f64 {
    let cfg = reference_config(frame_hz);
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut state = sim.blank_state();
    let n = 20_000;
    let t = Instant::now();
    for _ in 0..n {
        sim.step_frame();
        sim.state_into(&mut state);
    }
    std::hint::black_box(&state);
    t.elapsed().as_secs_f64() * 1e6 / n as f64
}

fn main() {
    // `cargo bench` passes `--bench`; ignore arguments.
    let ticks = env_usize("FLEXDYN_BENCH_TICKS", 10_000);
    let rounds = env_usize("FLEXDYN_BENCH_ROUNDS", 9).clamp(1, 11);
    println!("lockstep benchmark: {rounds} rounds x {ticks} ticks, loopback TCP, 2-core machine");
    let (mut pp, mut ppl, mut ls1, mut lst, mut lsr) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut ratio1, mut ratio1l, mut ratiot, mut ratior) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut lsf, mut ratiof) = (Vec::new(), Vec::new());
    let (mut lsd, mut ratiod) = (Vec::new(), Vec::new());
    let (mut ratio1w, mut breakdown) = (Vec::new(), Vec::new());
    for r in 0..rounds {
        // The one-step direct case between two ping-pongs: the yardstick is their geometric
        // mean, so a change of load during the round weighs on both sides alike.
        let p_before = pingpong_rate(ticks, false);
        let am = lockstep_rate(ticks, 1000.0, Handoff::Direct);
        let p_after = pingpong_rate(ticks, false);
        let p = (p_before * p_after).sqrt();
        let pl = pingpong_rate(ticks, true);
        let a = am.settled_ticks_per_s;
        let t = lockstep_rate(ticks, 1000.0, Handoff::Thread).settled_ticks_per_s;
        let b = lockstep_rate(ticks / 4, 100.0, Handoff::Direct).settled_ticks_per_s;
        let f = lockstep_rate_with_telemetry(ticks, 1000.0).settled_ticks_per_s;
        let d = lockstep_rate_of(
            ticks,
            reference_config(1000.0),
            Handoff::Direct,
            "main-thread",
            false,
        )
        .settled_ticks_per_s;
        let x = am.ticks;
        println!(
            "round {r}: lockstep 1 step/frame, direct, per tick: stepping {:.1} us, publishing \
             {:.1} us, waiting for the answer {:.1} us; period p50 {:.1} us, p99 {:.1} us; whole \
             run (first ticks included) {:.0} ticks/s (ratio {:.2})",
            x.physics_us,
            x.publish_us,
            x.wait_us,
            x.period_p50_us,
            x.period_p99_us,
            am.whole_ticks_per_s,
            am.whole_ticks_per_s / p
        );
        ratio1w.push(am.whole_ticks_per_s / p);
        breakdown.push(x);
        println!(
            "round {r}: lockstep 1 step/frame, direct, the demo answering on its main thread \
             (--answer-on main-thread): {d:.0} ticks/s (ratio {:.2})",
            d / p
        );
        lsd.push(d);
        ratiod.push(d / p);
        println!(
            "round {r}: lockstep 1 step/frame, direct, the demo publishing its telemetry every \
             tick: {f:.0} ticks/s (ratio to without {:.2})",
            f / a
        );
        lsf.push(f);
        ratiof.push(f / a);
        println!(
            "round {r}: ping-pong {p:.0} rt/s ({p_before:.0} before, {p_after:.0} after the direct \
             case; recv-loop pong {pl:.0}) | lockstep 1 step/frame: direct {a:.0} ticks/s (ratio \
             {:.2}), thread {t:.0} ticks/s (ratio {:.2}) | reference 10 steps/frame, direct {b:.0} \
             ticks/s (ratio {:.2})",
            a / p,
            t / p,
            b / p
        );
        ratio1.push(a / p);
        ratio1l.push(a / pl);
        ratiot.push(t / p);
        ratior.push(b / p);
        pp.push(p);
        ppl.push(pl);
        ls1.push(a);
        lst.push(t);
        lsr.push(b);
    }
    let (p, pl) = (median_mut(&mut pp), median_mut(&mut ppl));
    let (a, t, b) = (
        median_mut(&mut ls1),
        median_mut(&mut lst),
        median_mut(&mut lsr),
    );
    let phys1 = physics_frame_us(1000.0);
    let phys10 = physics_frame_us(100.0);
    println!(
        "median ping-pong round trips/s: {p:.0} (rtt {:.1} us); with a receive-loop pong: {pl:.0} \
         (rtt {:.1} us)",
        1e6 / p,
        1e6 / pl
    );
    let (r1, r1l, rt, rr) = (
        median_mut(&mut ratio1),
        median_mut(&mut ratio1l),
        median_mut(&mut ratiot),
        median_mut(&mut ratior),
    );
    println!(
        "median lockstep ticks/s, 1 RK4 step per frame, handoff direct: {a:.0} ({:.1} us/tick); \
         median ratio {r1:.2} (target >= 0.95), {r1l:.2} vs the receive-loop pong",
        1e6 / a
    );
    let med = |f: fn(&flexdyn_server::tick_cost::TickSummary) -> f64| {
        let mut v: Vec<f64> = breakdown.iter().map(f).collect();
        median_mut(&mut v)
    };
    let (xs, xp, xw) = (
        med(|x| x.physics_us),
        med(|x| x.publish_us),
        med(|x| x.wait_us),
    );
    println!(
        "  its server side per tick (medians): stepping {xs:.1} us, publishing {xp:.1} us, \
         waiting for the answer {xw:.1} us; whole-run ratio (first 1000 ticks included) {:.2}",
        median_mut(&mut ratio1w)
    );
    println!(
        "median lockstep ticks/s, 1 RK4 step per frame, handoff thread (before): {t:.0} ({:.1} \
         us/tick); median ratio {rt:.2}",
        1e6 / t
    );
    println!(
        "median lockstep ticks/s, reference (10 RK4 steps per frame), direct: {b:.0} ({:.1} \
         us/tick); median ratio {rr:.2}",
        1e6 / b
    );
    let (f, rf) = (median_mut(&mut lsf), median_mut(&mut ratiof));
    println!(
        "median lockstep ticks/s, 1 RK4 step per frame, direct, with the flight code's telemetry \
         (one FswMsg per tick, 1 kHz): {f:.0} ({:.1} us/tick); median ratio to without {rf:.2}",
        1e6 / f
    );
    let (d, rd) = (median_mut(&mut lsd), median_mut(&mut ratiod));
    println!(
        "median lockstep ticks/s, 1 RK4 step per frame, direct, the demo answering on its main \
         thread (before): {d:.0} ({:.1} us/tick); median ratio {rd:.2}",
        1e6 / d
    );
    println!("physics alone per frame: {phys1:.1} us (1 step), {phys10:.1} us (10 steps)");
}

/// Round-trip times of `count` StateMsg-sized pings after `warmup` ones, against a
/// `flexdyn-pingpong pong` child ([`flexdyn_tools::pingpong::round_trips`]).
fn pingpong_rtts(warmup: usize, count: usize, recv_loop: bool) -> Vec<Duration> {
    let pong = std::path::Path::new(env!("CARGO_BIN_EXE_flexdyn-pingpong"));
    flexdyn_tools::pingpong::round_trips(pong, warmup, count, recv_loop).expect("ping-pong")
}
