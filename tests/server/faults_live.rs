//! Live faults (issue 21, protocol 8) on a real lockstep server: a FaultCommandMsg for tick K,
//! put by the participant before its answer to tick K − 1, shows in the IMU stream at exactly
//! tick K (and not before), as the documented transform of the healthy run's sample, sample by
//! sample; its FaultEventMsg is published at K (activation) and K + 5 (clearance, the duration
//! of five frames); StatusMsg lists it active while held at K + 2 and inactive at the end;
//! refused commands (an unknown target, a tick already stepped past, a clear naming no fault)
//! are never applied and are counted in `rejected.fault_refused`. Both handoffs: the lockstep
//! core (direct) and the physics thread (thread).
//!
//! A live `Clear` stops the effect: a fault injected at K until cleared, cleared at K + 5, is
//! healthy before K, transformed on [K, K + 5) and healthy again from K + 5, sample by sample,
//! with its activation and clearance events at those edges. Malformed, bad-version,
//! non-finite and wrong-spacecraft fault commands put beside it are counted under those
//! reasons (`crates/server/src/fault_cmd.rs`) and never applied.

use crate::server_support;

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn_proto::{
    decode_fault_event, decode_imu, decode_state, encode, CommandMsg, FaultAction, FaultCommandMsg,
    FaultEventMsg, FaultSource, FaultTarget, Header, Mode, OperatorAction, OperatorMsg,
    RejectCounters, RunState, Topics, PROTOCOL_VERSION,
};
use flexdyn_server::{Handoff, ServerSettings};
use flexdyn_vehicle::config::SimConfig;
use server_support::{connecting_session, wait_until, Observer, ServerHandle};
use zenoh::{Session, Wait};

const WHEELS: &str = include_str!("../../scenarios/wheels_star_tracker.toml");
const TICKS: u64 = 40;
/// The tick the live fault starts at, and its length in frames.
const K: u64 = 12;
const LEN: u64 = 5;
/// \[rad/s\] the gyro bias step.
const BIAS: f64 = 0.5;
/// \[ns\] the frame period of the configuration (100 Hz).
const FRAME_NS: u64 = 10_000_000;

/// What a run's one telemetry subscriber saw: the IMU gyro by tick, the fault events.
#[derive(Default)]
struct Seen {
    gyro: BTreeMap<u64, [f64; 3]>,
    events: Vec<FaultEventMsg>,
}

fn fault(action: FaultAction, at_tick: u64, target: &str, index: u32) -> FaultCommandMsg {
    FaultCommandMsg {
        header: Header::new(1, 0, 0, 0),
        action,
        at_tick,
        fault_index: index,
        mode: 2, // bias_step
        params: [BIAS, 0.0],
        axes: 0,
        duration_ns: LEN * FRAME_NS,
        seed: 0,
        target: FaultTarget::new(target).unwrap(),
    }
}

/// What a participant puts on the fault key before its answer to tick k: `script(k)`.
type Script = fn(u64) -> Vec<Vec<u8>>;

/// No fault commands.
fn none(_: u64) -> Vec<Vec<u8>> {
    Vec::new()
}

/// The live fault for tick K and the refused ones, before the answer to tick K − 1.
fn inject_and_refused(k: u64) -> Vec<Vec<u8>> {
    if k != K - 1 {
        return Vec::new();
    }
    vec![
        encode(&fault(FaultAction::Inject, K, "imus.hub.gyro", 0)),
        // Refused: no such IMU; a tick already stepped past; no fault 9.
        encode(&fault(FaultAction::Inject, K, "imus.nope.gyro", 0)),
        encode(&fault(FaultAction::Inject, 3, "imus.hub.gyro", 0)),
        encode(&fault(FaultAction::Clear, K, "", 9)),
    ]
}

/// A lockstep participant (sender 1) answering every state with NoCommand; before its answer
/// to tick k it puts `script(k)` on the fault key, from the same session.
fn participant(
    port: u16,
    topics: &Topics,
    script: Script,
) -> (Session, Vec<Box<dyn std::any::Any>>) {
    let s = connecting_session(port);
    let (p, key, fault_key) = (s.clone(), topics.cmd(1), topics.fault());
    let sub = s
        .declare_subscriber(topics.state().to_owned())
        .callback(move |sample| {
            let st = decode_state(&sample.payload().to_bytes()).unwrap();
            let k = st.header.tick;
            for payload in script(k) {
                p.put(fault_key.as_str(), payload).wait().unwrap();
            }
            let h = Header::new(1, k, st.header.sim_time_ns, k);
            let _ = p
                .put(key.as_str(), encode(&CommandMsg::no_command(h, 1)))
                .wait();
        })
        .wait()
        .unwrap();
    let token = s
        .liveliness()
        .declare_token(topics.participant(1))
        .wait()
        .unwrap();
    (s, vec![Box::new(sub), Box::new(token)])
}

/// One lockstep run of TICKS ticks with the participant's fault commands `script`; with
/// `hold`, a hold at K + 2 where the status is read. Returns what was seen, the status while
/// held (if held) and the last status, and the run's reject counters.
fn run(
    handoff: Handoff,
    script: Script,
    hold: bool,
) -> (
    Seen,
    Option<flexdyn_proto::StatusMsg>,
    flexdyn_proto::StatusMsg,
    flexdyn_proto::RejectCounters,
) {
    let topics = Topics::new("sc1").unwrap();
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        handoff,
        duration_ns: Some(TICKS * FRAME_NS),
        participant_timeout: Duration::from_secs(20),
        ..ServerSettings::default()
    };
    let cfg = SimConfig::from_toml_str(WHEELS).unwrap();
    let server = ServerHandle::start(settings, cfg);
    let obs = Observer::start(server.port, &topics);
    let seen: Arc<Mutex<Seen>> = Arc::default();
    let s = seen.clone();
    let (imu_key, fault_key) = (topics.imu("hub").unwrap(), topics.fault_events());
    let _tlm = obs
        .session
        .declare_subscriber(topics.telemetry_wildcard())
        .callback(move |sample| {
            let key = sample.key_expr().as_str();
            let bytes = sample.payload().to_bytes();
            let mut s = s.lock().unwrap();
            if key == imu_key {
                let m = decode_imu(&bytes).unwrap();
                s.gyro.insert(m.header.tick, m.omega_p_rad_s);
            } else if key == fault_key {
                s.events.push(decode_fault_event(&bytes).unwrap());
            }
        })
        .wait()
        .unwrap();
    assert!(wait_until(Duration::from_secs(20), || obs
        .last_status()
        .is_some()));
    let op = connecting_session(server.port);
    let operator = |action, ticks| {
        let m = OperatorMsg::new(Header::new(1, 0, 0, 0), action, ticks);
        op.put(topics.operator(), encode(&m)).wait().unwrap();
    };
    if hold {
        operator(OperatorAction::RunTicks, K + 2);
        std::thread::sleep(Duration::from_millis(200));
    }
    let (_p, _keep) = participant(server.port, &topics, script);
    let mut held = None;
    if hold {
        assert!(
            wait_until(Duration::from_secs(20), || obs.last_status().is_some_and(
                |st| st.run_state == RunState::Paused && st.header.tick == K + 2
            )),
            "never held at K + 2"
        );
        // A status published while held.
        let n = obs.seen.lock().unwrap().statuses.len();
        assert!(wait_until(Duration::from_secs(5), || obs
            .seen
            .lock()
            .unwrap()
            .statuses
            .len()
            > n + 1));
        held = obs.last_status();
        operator(OperatorAction::Resume, 0);
    }
    let report = server.join(Duration::from_secs(60)).expect("the run ends");
    assert_eq!(report.last_tick, TICKS);
    assert!(wait_until(Duration::from_secs(5), || obs
        .last_status()
        .is_some_and(|st| st.run_state == RunState::Finished)));
    std::thread::sleep(Duration::from_millis(300));
    let last = obs.last_status().unwrap();
    let seen = std::mem::take(&mut *seen.lock().unwrap());
    (seen, held, last, report.rejected)
}

/// Sample by sample: the faulted gyro is healthy before K and from K + LEN on, healthy + BIAS
/// on [K, K + LEN); its events: activated at K, cleared at K + LEN, each edge at its boundary;
/// index 0 (the configuration has none).
fn biased_on_k_to_k_plus_len(healthy: &Seen, faulty: &Seen) {
    assert_eq!(healthy.gyro.len() as u64, TICKS + 1);
    assert_eq!(faulty.gyro.len() as u64, TICKS + 1);
    for (k, h) in &healthy.gyro {
        let f = faulty.gyro[k];
        if (K..K + LEN).contains(k) {
            assert_eq!(f, h.map(|x| x + BIAS), "tick {k}: the bias step");
        } else {
            assert_eq!(f, *h, "tick {k}: healthy");
        }
    }
    let ev = |tick: u64, active: bool, seq: u64| FaultEventMsg {
        header: Header::new(1, tick, tick * FRAME_NS, seq),
        fault_index: 0,
        source: FaultSource::Live,
        mode: 2,
        active,
        edge_ns: tick * FRAME_NS,
        axes: 0,
        params: [BIAS, 0.0],
        target: FaultTarget::new("imus.hub.gyro").unwrap(),
    };
    assert_eq!(faulty.events, vec![ev(K, true, 0), ev(K + LEN, false, 1)]);
}

fn live_fault_lands_at_its_tick(handoff: Handoff) {
    let (healthy, _, healthy_last, _) = run(handoff, none, false);
    let (faulty, held, last, rejected) = run(handoff, inject_and_refused, true);
    biased_on_k_to_k_plus_len(&healthy, &faulty);
    assert!(healthy.events.is_empty());
    assert_eq!(healthy_last.faults_active, 0);
    // Active while held at K + 2, cleared by the end.
    let held = held.unwrap();
    assert_eq!(held.header.tick, K + 2);
    assert_eq!(
        (held.faults_active, held.faults_active_bits),
        (1, [1, 0, 0, 0])
    );
    assert_eq!((last.faults_active, last.faults_active_bits), (0, [0; 4]));
    // The three bad commands were counted, and never applied (the samples above).
    assert_eq!(rejected.fault_refused, 3);
    assert_eq!(last.rejected.fault_refused, 3);
}

#[test]
fn a_live_fault_lands_at_its_tick_in_lockstep_direct() {
    live_fault_lands_at_its_tick(Handoff::Direct);
}

#[test]
fn a_live_fault_lands_at_its_tick_in_lockstep_thread() {
    live_fault_lands_at_its_tick(Handoff::Thread);
}

/// The bias until cleared, injected at K and cleared at K + LEN, with four bad commands beside
/// the injection that the server must count and never apply: the same injection truncated
/// (malformed), with the next protocol version (bad version), a NaN parameter (non-finite), and
/// for spacecraft 2 with a bias of 100 rad/s (wrong spacecraft).
fn inject_then_clear(k: u64) -> Vec<Vec<u8>> {
    let until_cleared = FaultCommandMsg {
        duration_ns: 0,
        ..fault(FaultAction::Inject, K, "imus.hub.gyro", 0)
    };
    if k == K - 1 {
        let good = encode(&until_cleared);
        let truncated = good[..good.len() - 1].to_vec();
        let mut next_version = good.clone();
        next_version[..2].copy_from_slice(&(PROTOCOL_VERSION + 1).to_le_bytes());
        let non_finite = encode(&FaultCommandMsg {
            params: [f64::NAN, 0.0],
            ..until_cleared
        });
        let other_spacecraft = encode(&FaultCommandMsg {
            header: Header::new(2, 0, 0, 0),
            params: [100.0, 0.0],
            ..until_cleared
        });
        vec![good, truncated, next_version, non_finite, other_spacecraft]
    } else if k == K + LEN - 1 {
        vec![encode(&fault(FaultAction::Clear, K + LEN, "", 0))]
    } else {
        Vec::new()
    }
}

fn a_live_clear_stops_the_effect(handoff: Handoff) {
    let (healthy, _, _, healthy_rejected) = run(handoff, none, false);
    let (faulty, _, last, rejected) = run(handoff, inject_then_clear, false);
    // The fault itself has no duration: the clearance ends it at K + LEN, the boundary it
    // takes effect at (the clearance event's edge).
    biased_on_k_to_k_plus_len(&healthy, &faulty);
    assert_eq!((last.faults_active, last.faults_active_bits), (0, [0; 4]));
    // Each bad command counted once under its reason, in the report and in StatusMsg.
    let want = RejectCounters {
        malformed: 1,
        bad_version: 1,
        non_finite: 1,
        wrong_spacecraft: 1,
        ..healthy_rejected
    };
    assert_eq!(healthy_rejected, RejectCounters::default());
    assert_eq!(rejected, want);
    assert_eq!(last.rejected, want);
}

#[test]
fn a_live_clear_stops_the_effect_direct() {
    a_live_clear_stops_the_effect(Handoff::Direct);
}

#[test]
fn a_live_clear_stops_the_effect_thread() {
    a_live_clear_stops_the_effect(Handoff::Thread);
}
