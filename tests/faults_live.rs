//! Live faults (issue 21, protocol 8) on a real lockstep server: a FaultCommandMsg for tick K,
//! put by the participant before its answer to tick K − 1, shows in the IMU stream at exactly
//! tick K (and not before), as the documented transform of the healthy run's sample, sample by
//! sample; its FaultEventMsg is published at K (activation) and K + 5 (clearance, the duration
//! of five frames); StatusMsg lists it active while held at K + 2 and inactive at the end;
//! refused commands (an unknown target, a tick already stepped past, a clear naming no fault)
//! are never applied and are counted in `rejected.fault_refused`. Both handoffs: the lockstep
//! core (direct) and the physics thread (thread).

mod server_support;

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn::config::SimConfig;
use flexdyn::server::{Handoff, ServerSettings};
use flexdyn_proto::{
    decode_fault_event, decode_imu, decode_state, encode, CommandMsg, FaultAction, FaultCommandMsg,
    FaultEventMsg, FaultSource, FaultTarget, Header, Mode, OperatorAction, OperatorMsg, RunState,
    Topics,
};
use server_support::{connecting_session, wait_until, Observer, ServerHandle};
use zenoh::{Session, Wait};

const WHEELS: &str = include_str!("../scenarios/wheels_star_tracker.toml");
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

/// A lockstep participant (sender 1) answering every state with NoCommand; with `inject`, it
/// puts the live fault for tick K (and the refused ones) before its answer to tick K − 1, from
/// the same session.
fn participant(port: u16, topics: &Topics, inject: bool) -> (Session, Vec<Box<dyn std::any::Any>>) {
    let s = connecting_session(port);
    let (p, key, fault_key) = (s.clone(), topics.cmd(1), topics.fault());
    let sub = s
        .declare_subscriber(topics.state().to_owned())
        .callback(move |sample| {
            let st = decode_state(&sample.payload().to_bytes()).unwrap();
            let k = st.header.tick;
            if inject && k == K - 1 {
                let put = |m: &FaultCommandMsg| p.put(fault_key.as_str(), encode(m)).wait();
                put(&fault(FaultAction::Inject, K, "imus.hub.gyro", 0)).unwrap();
                // Refused: no such IMU; a tick already stepped past; no fault 9.
                put(&fault(FaultAction::Inject, K, "imus.nope.gyro", 0)).unwrap();
                put(&fault(FaultAction::Inject, 3, "imus.hub.gyro", 0)).unwrap();
                put(&fault(FaultAction::Clear, K, "", 9)).unwrap();
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

/// One lockstep run of TICKS ticks; with `inject`, the live fault, and a hold at K + 2 where
/// the status is read. Returns what was seen, the status while held (if injected) and the last
/// status, and the run's reject counters.
fn run(
    handoff: Handoff,
    inject: bool,
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
    if inject {
        operator(OperatorAction::RunTicks, K + 2);
        std::thread::sleep(Duration::from_millis(200));
    }
    let (_p, _keep) = participant(server.port, &topics, inject);
    let mut held = None;
    if inject {
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

fn live_fault_lands_at_its_tick(handoff: Handoff) {
    let (healthy, _, healthy_last, _) = run(handoff, false);
    let (faulty, held, last, rejected) = run(handoff, true);
    assert_eq!(healthy.gyro.len() as u64, TICKS + 1);
    assert_eq!(faulty.gyro.len() as u64, TICKS + 1);
    // Sample by sample: healthy before K and from K + LEN on, healthy + BIAS on [K, K + LEN).
    for (k, h) in &healthy.gyro {
        let f = faulty.gyro[k];
        if (K..K + LEN).contains(k) {
            assert_eq!(f, h.map(|x| x + BIAS), "tick {k}: the bias step");
        } else {
            assert_eq!(f, *h, "tick {k}: healthy");
        }
    }
    assert!(healthy.events.is_empty());
    assert_eq!(healthy_last.faults_active, 0);
    // Its events: activated at K, cleared at K + LEN; index 0 (the configuration has none).
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
