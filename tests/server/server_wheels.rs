//! Reaction-wheel commands and star-tracker telemetry through the server, in lockstep: an
//! `Actuators` command answers the tick and drives the wheels; every malformed effector input
//! is rejected, counted under its reason, and does not answer the tick; the star tracker
//! publishes on its own topic at its own rate. Magnetorquers and thrusters follow the same rules.

use crate::server_support;

use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn_proto::{
    decode_star_tracker, decode_state, effector_kind, encode, CommandMsg, EffectorInput, Header,
    Mode, RejectCounters, StarTrackerMsg, Topics,
};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::config::SimConfig;
use server_support::{connecting_session, wait_until, Observer, ServerHandle};
use zenoh::Wait;

const WAIT: Duration = Duration::from_secs(30);
const U: [f64; 4] = [0.1, -0.1, 0.05, 0.0];

fn input(effector_index: u32, values: &[f64]) -> EffectorInput {
    EffectorInput {
        effector_index,
        values: values.to_vec(),
    }
}

fn wheels_config() -> SimConfig {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wheels_star_tracker.toml");
    SimConfig::from_file(&path).unwrap()
}

#[test]
fn actuators_drive_the_wheels_and_bad_inputs_are_counted() {
    let topics = Topics::new("sc1").unwrap();
    let server = ServerHandle::start(
        ServerSettings {
            mode: Mode::Lockstep,
            participants: vec![1],
            participant_timeout: Duration::from_secs(20),
            duration_ns: Some(1_000_000_000),
            status_hz: 50.0,
            ..ServerSettings::default()
        },
        wheels_config(),
    );
    let port = server.port;
    let obs = Observer::start(port, &topics);
    let trackers: Arc<Mutex<Vec<StarTrackerMsg>>> = Arc::default();
    let t = trackers.clone();
    let _st_sub = obs
        .session
        .declare_subscriber(topics.star_tracker("st1").unwrap())
        .callback(move |s| {
            t.lock()
                .unwrap()
                .push(decode_star_tracker(&s.payload().to_bytes()).unwrap())
        })
        .wait()
        .unwrap();

    // The participant: answers every state with the wheel torques; at tick 5 it first sends
    // every kind of bad effector input, none of which may answer the tick.
    let session = connecting_session(port);
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
    let good_inputs: Vec<EffectorInput> = (0..4).map(|j| input(2 + j, &[U[j as usize]])).collect();
    let mut answered = 0;
    while let Ok(Some(sample)) = states.recv_timeout(WAIT) {
        let s = decode_state(&sample.payload().to_bytes()).unwrap();
        let h = Header::new(1, s.header.tick, s.header.sim_time_ns, s.header.tick);
        let put = |c: &CommandMsg| publisher.put(encode(c)).wait().unwrap();
        let actuators =
            |inputs: Vec<EffectorInput>| CommandMsg::actuators(h, 1, [0.0; 3], [0.0; 3], inputs);
        if s.header.tick == 5 {
            put(&actuators(vec![input(9, &[0.1])])); // no effector 9
            put(&actuators(vec![input(0, &[0.1])])); // a panel pair takes no input
            put(&actuators(vec![input(2, &[0.1, 0.2])])); // a wheel takes one value
            put(&actuators(vec![input(3, &[0.1]), input(3, &[0.2])])); // named twice
            put(&actuators(vec![input(2, &[f64::NAN])])); // non-finite
            put(&CommandMsg::actuators(
                Header::new(99, s.header.tick, 0, 0),
                1,
                [0.0; 3],
                [0.0; 3],
                good_inputs.clone(),
            )); // another spacecraft
            std::thread::sleep(Duration::from_millis(200));
        }
        put(&actuators(good_inputs.clone()));
        answered += 1;
        if s.header.tick == 100 {
            break;
        }
    }
    assert_eq!(answered, 101, "every tick answered");
    let report = server.join(WAIT).expect("the run");
    assert_eq!(report.last_tick, 100);
    // Where the ticks went: 100 frames stepped; tick 5 was answered 200 ms after its state
    // came, so one tick period is at least that long. The wait for tick 5 starts once the
    // state's put returned, which the participant may have seen a few µs earlier: at least
    // 199.9 ms of it, so the mean wait over the 100 frames is at least 1999 µs. The other two
    // means are non-zero when the loops sum them. 100 ticks are too few for a settled rate
    // (SETTLE_TICKS = 1000).
    let ticks = report.ticks.expect("a lockstep run reports its ticks");
    assert_eq!(ticks.frames, 100);
    assert!(ticks.period_max_us >= 200_000.0, "{ticks:?}");
    assert!(ticks.wait_us >= 1_999.0, "{ticks:?}");
    assert!(
        ticks.physics_us > 0.0 && ticks.publish_us > 0.0,
        "{ticks:?}"
    );
    assert_eq!(ticks.settled_ticks_per_s, None);
    let want = RejectCounters {
        bad_effector_input: 4,
        non_finite: 1,
        wrong_spacecraft: 1,
        ..RejectCounters::default()
    };
    assert_eq!(report.rejected, want);
    assert!(wait_until(WAIT, || obs
        .last_status()
        .is_some_and(|s| s.rejected == want)));

    // The wheels applied the commanded torques from tick 1 on (tick 0 precedes any command).
    let seen = obs.seen.lock().unwrap();
    let at = |tick: u64| {
        &seen
            .states
            .iter()
            .find(|(s, _)| s.header.tick == tick)
            .unwrap()
            .0
    };
    for tick in [1, 6, 100] {
        let wheels = &at(tick).effectors[2..];
        for (j, w) in wheels.iter().enumerate() {
            assert_eq!(w.kind, effector_kind::REACTION_WHEEL);
            assert_eq!(w.outputs[0], U[j], "tick {tick} wheel {j}");
        }
    }
    assert!(at(0).effectors[2..].iter().all(|w| w.outputs[0] == 0.0));
    // Wheel 1 (u = +0.1 N·m, J_s = 0.05) sped up by about u t / J_s = 2 rad/s in 1 s.
    let dw = at(100).effectors[2].states[0] - at(0).effectors[2].states[0];
    assert!((dw - 2.0).abs() < 0.05, "wheel 1 speed change {dw}");

    // The star tracker: 10 Hz on 100 Hz frames, ticks 0, 10, …, 100, seq counting its own
    // messages, all valid (slow rate, boresight far from the Sun).
    assert!(wait_until(WAIT, || trackers.lock().unwrap().len() >= 11));
    let st = trackers.lock().unwrap();
    let ticks: Vec<u64> = st.iter().map(|m| m.header.tick).collect();
    assert_eq!(ticks, (0..=10).map(|k| 10 * k).collect::<Vec<_>>());
    assert!(st
        .iter()
        .all(|m| m.valid && m.header.seq == m.header.tick / 10));
}

/// Magnetorquers and thrusters take `Actuators` inputs at their indices after the wheels
/// (`scenarios/acs_full.toml`: rods 6–8, thrusters 9–12), their telemetry follows, and their bad
/// inputs are rejected and counted like a wheel's.
#[test]
fn actuators_drive_rods_and_thrusters_and_bad_inputs_are_counted() {
    let topics = Topics::new("sc1").unwrap();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/acs_full.toml");
    let server = ServerHandle::start(
        ServerSettings {
            mode: Mode::Lockstep,
            participants: vec![1],
            participant_timeout: Duration::from_secs(20),
            duration_ns: Some(2_000_000_000),
            status_hz: 50.0,
            ..ServerSettings::default()
        },
        SimConfig::from_file(&path).unwrap(),
    );
    let port = server.port;
    let obs = Observer::start(port, &topics);
    let session = connecting_session(port);
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
    // Rods at 100, −500 (saturates at 400) and 0 A·m²; thr_pz1 and thr_pz2 fire 0.05 s of every
    // 0.1 s frame (a +z couple), the others stay shut.
    let good = vec![
        input(6, &[100.0]),
        input(7, &[-500.0]),
        input(8, &[0.0]),
        input(9, &[0.05]),
        input(10, &[0.05]),
        input(11, &[0.0]),
        input(12, &[0.0]),
    ];
    while let Ok(Some(sample)) = states.recv_timeout(WAIT) {
        let s = decode_state(&sample.payload().to_bytes()).unwrap();
        let h = Header::new(1, s.header.tick, s.header.sim_time_ns, s.header.tick);
        let put = |c: &CommandMsg| publisher.put(encode(c)).wait().unwrap();
        let actuators =
            |inputs: Vec<EffectorInput>| CommandMsg::actuators(h, 1, [0.0; 3], [0.0; 3], inputs);
        if s.header.tick == 3 {
            put(&actuators(vec![input(9, &[0.05, 0.05])])); // a thruster takes one value
            put(&actuators(vec![input(13, &[0.05])])); // no effector 13
            put(&actuators(vec![input(6, &[f64::INFINITY])])); // non-finite
            std::thread::sleep(Duration::from_millis(200));
        }
        put(&actuators(good.clone()));
        if s.header.tick == 20 {
            break;
        }
    }
    let report = server.join(WAIT).expect("the run");
    assert_eq!(report.last_tick, 20);
    let want = RejectCounters {
        bad_effector_input: 2,
        non_finite: 1,
        ..RejectCounters::default()
    };
    assert_eq!(report.rejected, want);
    let seen = obs.seen.lock().unwrap();
    let last = &seen
        .states
        .iter()
        .find(|(s, _)| s.header.tick == 20)
        .unwrap()
        .0;
    let e = &last.effectors;
    assert_eq!(e.len(), 13);
    assert_eq!(
        (e[6].kind, e[6].outputs[0], e[6].flags),
        (effector_kind::MAGNETORQUER, 100.0, 0)
    );
    assert_eq!(
        (e[7].outputs[0], e[7].flags),
        (-400.0, flexdyn_proto::magnetorquer_flags::SATURATED)
    );
    // Each answer to ticks 0..=19 fires in the frame that follows it: 20 pulses by tick 20.
    for (k, pulses) in [(9, 20.0), (10, 20.0), (11, 0.0), (12, 0.0)] {
        assert_eq!(e[k].kind, effector_kind::THRUSTER);
        assert_eq!(e[k].outputs[1], pulses, "thruster {k}");
    }
    // The +z couple turned the hub about z.
    let w0 = seen
        .states
        .iter()
        .find(|(s, _)| s.header.tick == 0)
        .unwrap()
        .0
        .omega_bn_b_rad_s[2];
    assert!(
        last.omega_bn_b_rad_s[2] > w0,
        "{} vs {w0}",
        last.omega_bn_b_rad_s[2]
    );
}
