//! Command-link faults in lockstep (`links.<sender id>`: `crates/faults/src/link.rs`). A scripted
//! participant answers tick k with the torque f(k) = (0, 0, 10⁻⁴ (k + 1)) N·m, a different value
//! every tick, so the wrench the server applied over frame k → k + 1 (the `wrench_applied` of
//! the state of tick k + 1) names the command it came from. Each faulty run is compared, tick by
//! tick, with a healthy run of the same configuration:
//! - `dropped` over ticks [20, 40): the participant's commands are not applied (its last one, of
//!   tick 19, stays held: `stale_policy = "hold"`), and the run still reaches its last tick: a
//!   dropped link is answered with nothing, once per tick of the window;
//! - `delayed` by N = 5 frames over [20, 40): the command applied at tick k is the healthy run's
//!   of tick k − 5 inside the window, and the healthy run's outside it;
//! - `corrupted` with bit error rate 1 over [20, 40): every bit of each command inverted, so
//!   its version byte 7 becomes 0xF8 and every one is rejected as `bad_version` (20 of them),
//!   counted, answering its tick with nothing; no panic, no hang.
//!
//! - `corrupted` with bit error rate 2·10⁻³ over [20, 40): each command's encoding damaged by
//!   [`damage`] (pinned by its own unit test) and then judged as the documented checks say,
//!   re-stated here: a decode error by its reason, then the spacecraft, the sender and the tick;
//!   a damaged command that passes is applied as damaged (its wrench, or NoCommand's hold), a
//!   rejected one leaves the last applied wrench held. Both outcomes occur in the window.
//! - `dropped` from tick 20 on, cleared live at tick 30 by a FaultCommandMsg (put before the
//!   answer to tick 0): applied as dropped over [20, 30) only, healthy again from tick 30.
//!
//! The windows: frames at 100 Hz, start_s = 0.2 and duration_s = 0.2 are ticks 20 to 39.

use crate::server_support;

use std::time::Duration;

use flexdyn_faults::link::{damage, LinkStats};
use flexdyn_proto::{
    decode_command, decode_state, encode, CommandKind, CommandMsg, DecodeError, FaultAction,
    FaultCommandMsg, FaultTarget, Header, Mode, RejectCounters, Topics,
};
use flexdyn_server::{RunReport, ServerSettings};
use flexdyn_vehicle::config::{SimConfig, DEFAULT_CONFIG_TOML};
use server_support::{connecting_session, ServerHandle};
use zenoh::Wait;

const WAIT: Duration = Duration::from_secs(30);
const LAST_TICK: u64 = 60;
const WINDOW: std::ops::Range<u64> = 20..40;

/// The participant's torque for tick `k` \[N·m\].
fn f(k: u64) -> f64 {
    1e-4 * (k + 1) as f64
}

/// The reference spacecraft (100 Hz frames) with `faults` appended.
fn config(faults: &str) -> SimConfig {
    let text = format!("{DEFAULT_CONFIG_TOML}\n{faults}\n");
    SimConfig::from_toml_str(&text).unwrap()
}

/// A lockstep run to tick 60 with participant 1 answering every state with f(tick): the
/// applied torque z of each tick 0..=60 and the report.
fn run(faults: &str) -> (Vec<f64>, RunReport) {
    run_with(faults, None)
}

/// [`run`], with a live clear of fault 0 at tick `clear_at` put before the answer to tick 0.
fn run_with(faults: &str, clear_at: Option<u64>) -> (Vec<f64>, RunReport) {
    let (applied, report) = run_full(faults, clear_at);
    (applied.iter().map(|w| w[2]).collect(), report)
}

/// [`run_with`], with the whole applied wrench of each tick: torque about B, then force \[SI\].
fn run_full(faults: &str, clear_at: Option<u64>) -> (Vec<[f64; 6]>, RunReport) {
    let topics = Topics::new("sc1").unwrap();
    let server = ServerHandle::start(
        ServerSettings {
            mode: Mode::Lockstep,
            participants: vec![1],
            participant_timeout: Duration::from_secs(20),
            duration_ns: Some(LAST_TICK * 10_000_000),
            ..ServerSettings::default()
        },
        config(faults),
    );
    let session = connecting_session(server.port);
    let publisher = session.declare_publisher(topics.cmd(1)).wait().unwrap();
    let states = session
        .declare_subscriber(topics.state().to_owned())
        .wait()
        .unwrap();
    let _token = session
        .liveliness()
        .declare_token(topics.participant(1))
        .wait()
        .unwrap();
    let mut applied = vec![[f64::NAN; 6]; LAST_TICK as usize + 1];
    while let Ok(Some(sample)) = states.recv_timeout(WAIT) {
        let s = decode_state(&sample.payload().to_bytes()).unwrap();
        let k = s.header.tick;
        let w = &s.wrench_applied;
        let (t, n) = (w.torque_b_nm, w.force_b_newton);
        applied[k as usize] = [t[0], t[1], t[2], n[0], n[1], n[2]];
        if let (0, Some(at_tick)) = (k, clear_at) {
            let clear = FaultCommandMsg {
                header: Header::new(1, 0, 0, 0),
                action: FaultAction::Clear,
                at_tick,
                fault_index: 0,
                mode: 0,
                params: [0.0; 2],
                axes: 0,
                duration_ns: 0,
                seed: 0,
                target: FaultTarget::default(),
            };
            session.put(topics.fault(), encode(&clear)).wait().unwrap();
        }
        let h = Header::new(1, k, s.header.sim_time_ns, k);
        let cmd = CommandMsg::wrench(h, 1, [0.0, 0.0, f(k)], [0.0; 3]);
        publisher.put(encode(&cmd)).wait().unwrap();
        if k == LAST_TICK {
            break;
        }
    }
    let report = server.join(WAIT).expect("the run");
    assert_eq!(report.last_tick, LAST_TICK, "the run reached its end");
    assert!(
        applied.iter().flatten().all(|a| a.is_finite()),
        "every tick seen"
    );
    (applied, report)
}

fn window(mode: &str) -> String {
    format!("[[faults]]\ntarget = \"links.1\"\nstart_s = 0.2\nduration_s = 0.2\n{mode}")
}

/// The healthy run: the state of tick k + 1 carries f(k) (tick 0 precedes any command).
fn healthy() -> Vec<f64> {
    let (applied, report) = run("");
    assert_eq!(applied[0], 0.0);
    for k in 0..LAST_TICK {
        assert_eq!(applied[k as usize + 1], f(k), "healthy tick {}", k + 1);
    }
    assert!(report.link_faults.is_zero());
    applied
}

#[test]
fn a_dropped_link_is_not_applied_and_the_run_goes_on() {
    let ok = healthy();
    let (got, report) = run(&window("mode = \"dropped\""));
    for k in 0..LAST_TICK {
        let want = if WINDOW.contains(&k) {
            ok[WINDOW.start as usize] // f(19), held
        } else {
            ok[k as usize + 1]
        };
        assert_eq!(got[k as usize + 1], want, "command applied over frame {k}");
    }
    assert_eq!(report.link_faults.empty_answers, 20, "{report}");
    // Each of the 20 commands sent for a dropped tick is discarded, or, if it arrives after
    // the server stepped past the window on its own, refused as stale.
    assert_eq!(
        report.link_faults.commands_dropped + report.rejected.stale_tick,
        20,
        "{report}"
    );
    assert!(
        report.to_string().contains("link_faults dropped="),
        "{report}"
    );
}

#[test]
fn a_delayed_link_applies_the_command_of_n_frames_before() {
    let ok = healthy();
    let (got, report) = run(&window("mode = \"delayed\"\nframes = 5.0"));
    for k in 0..LAST_TICK {
        let t = k as usize + 1;
        let want = if WINDOW.contains(&k) {
            ok[t - 5]
        } else {
            ok[t]
        };
        assert_eq!(got[t], want, "command applied over frame {k}");
    }
    assert_eq!(
        report.link_faults,
        LinkStats {
            delayed_frames: 20,
            ..LinkStats::default()
        }
    );
    assert_eq!(report.rejected, RejectCounters::default());
}

#[test]
fn a_corrupted_link_is_rejected_counted_and_answers_its_tick() {
    let ok = healthy();
    let (got, report) = run(&window("mode = \"corrupted\"\nprobability = 1.0"));
    for k in 0..LAST_TICK {
        let want = if WINDOW.contains(&k) {
            ok[WINDOW.start as usize]
        } else {
            ok[k as usize + 1]
        };
        assert_eq!(got[k as usize + 1], want, "command applied over frame {k}");
    }
    assert_eq!(
        report.rejected,
        RejectCounters {
            bad_version: 20,
            ..RejectCounters::default()
        }
    );
    assert_eq!(
        report.link_faults,
        LinkStats {
            commands_corrupted: 20,
            corrupted_rejected: 20,
            ..LinkStats::default()
        }
    );
}

#[test]
fn a_live_clear_restores_a_dropped_link_at_its_tick() {
    const CLEARED: u64 = 30;
    let ok = healthy();
    let open_ended = "[[faults]]\ntarget = \"links.1\"\nstart_s = 0.2\nmode = \"dropped\"";
    let (got, report) = run_with(open_ended, Some(CLEARED));
    for k in 0..LAST_TICK {
        let want = if (WINDOW.start..CLEARED).contains(&k) {
            ok[WINDOW.start as usize] // f(19), held
        } else {
            ok[k as usize + 1]
        };
        assert_eq!(got[k as usize + 1], want, "command applied over frame {k}");
    }
    assert_eq!(
        report.link_faults.empty_answers,
        CLEARED - WINDOW.start,
        "{report}"
    );
    assert_eq!(report.rejected.fault_refused, 0, "{report}");
}

#[test]
fn a_corrupted_link_at_a_low_bit_error_rate_applies_what_passes_the_checks() {
    const P: f64 = 2e-3;
    let (healthy, _) = run_full("", None);
    let (got, report) = run_full(
        &window(&format!("mode = \"corrupted\"\nprobability = {P}")),
        None,
    );
    // The expectation, tick by tick: the command the participant sent for tick k (the run's
    // f(k) wrench, stamped with the state's tick and time), damaged with the fault's seed (its
    // index, 0) and the tick, then the checks in the order docs/guides/server.md gives them.
    let mut want = healthy.clone();
    let mut rejected = RejectCounters::default();
    let (mut accepted, mut refused) = (0, 0);
    for k in WINDOW {
        let h = Header::new(1, k, k * 10_000_000, k);
        let mut bytes = encode(&CommandMsg::wrench(h, 1, [0.0, 0.0, f(k)], [0.0; 3]));
        damage(&mut bytes, 0, k, P);
        let held = want[k as usize];
        let applied = match decode_command(&bytes) {
            Err(DecodeError::UnknownVersion { .. }) => Err(&mut rejected.bad_version),
            Err(DecodeError::NonFinite { .. }) => Err(&mut rejected.non_finite),
            Err(_) => Err(&mut rejected.malformed),
            Ok(d) if d.header.spacecraft_id != 1 => Err(&mut rejected.wrong_spacecraft),
            Ok(d) if d.sender_id != 1 => Err(&mut rejected.wrong_identity),
            Ok(d) if d.header.tick != k => Err(&mut rejected.stale_tick),
            Ok(d) => match d.kind {
                CommandKind::Wrench {
                    torque_b_nm: t,
                    force_b_newton: n,
                } => Ok([t[0], t[1], t[2], n[0], n[1], n[2]]),
                CommandKind::NoCommand => Ok(held),
                // The reference spacecraft has no effectors: any input is refused.
                CommandKind::Actuators { .. } => Err(&mut rejected.bad_effector_input),
            },
        };
        want[k as usize + 1] = match applied {
            Ok(w) => {
                accepted += 1;
                w
            }
            Err(counter) => {
                *counter += 1;
                refused += 1;
                held
            }
        };
    }
    eprintln!("p = {P}: {accepted} applied as damaged, {refused} refused ({rejected:?})");
    assert!(
        accepted > 0 && refused > 0,
        "both outcomes: {accepted} applied, {refused} refused"
    );
    for k in 0..LAST_TICK {
        let t = k as usize + 1;
        assert_eq!(got[t], want[t], "wrench applied over frame {k}");
    }
    assert_eq!(report.rejected, rejected, "{report}");
    assert_eq!(
        report.link_faults,
        LinkStats {
            commands_corrupted: 20,
            corrupted_rejected: refused,
            ..LinkStats::default()
        }
    );
}
