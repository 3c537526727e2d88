//! Bad commands are rejected, counted by reason in StatusMsg.rejected, and the server keeps
//! running (and still accepts good commands).

use crate::server_support;

use std::time::Duration;

use flexdyn_proto::{command_flags, encode, CommandMsg, Header, RejectCounters, Topics};
use flexdyn_server::{Outcome, ServerSettings};
use server_support::{reference_config, wait_until, Observer, ServerHandle};
use zenoh::Wait;

const WAIT: Duration = Duration::from_secs(20);

/// A real-time server of spacecraft `sc1` (the reference spacecraft at `frame_hz`) on a free
/// port, and an observer that has seen its first states.
fn running(settings: ServerSettings, frame_hz: f64) -> (ServerHandle, Observer) {
    let server = ServerHandle::start(settings, reference_config(frame_hz));
    let port = server.port;
    let obs = Observer::start(port, &Topics::new("sc1").unwrap());
    assert!(
        wait_until(WAIT, || obs.last_tick().is_some_and(|t| t >= 2)),
        "no telemetry"
    );
    (server, obs)
}

#[test]
fn bad_commands_are_counted_and_the_server_keeps_running() {
    let topics = Topics::new("sc1").unwrap();
    let (mut server, obs) = running(
        ServerSettings {
            participants: vec![1],
            status_hz: 50.0,
            ..ServerSettings::default()
        },
        100.0,
    );
    let cmd_pub = obs.session.declare_publisher(topics.cmd(1)).wait().unwrap();
    let put = |bytes: Vec<u8>| cmd_pub.put(bytes).wait().unwrap();
    let put_on = |key: String, bytes: Vec<u8>| obs.session.put(key, bytes).wait().unwrap();
    let tick = obs.last_tick().unwrap();
    let good = CommandMsg::wrench(Header::new(1, tick, 0, 0), 1, [0.0, 0.0, 0.5], [0.0; 3]);

    // Malformed: too short, and a valid command with a trailing byte.
    let mut short = flexdyn_proto::PROTOCOL_VERSION.to_le_bytes().to_vec();
    short.push(7);
    put(short);
    let mut trailing = encode(&good);
    trailing.push(0);
    put(trailing);
    // Wrong protocol version.
    let mut other_version = encode(&good);
    other_version[..2].copy_from_slice(&(flexdyn_proto::PROTOCOL_VERSION + 1).to_le_bytes());
    put(other_version);
    // NaN torque.
    put(encode(&CommandMsg::wrench(
        Header::new(1, tick, 0, 0),
        1,
        [0.0, f64::NAN, 0.0],
        [0.0; 3],
    )));
    // Another spacecraft.
    put(encode(&CommandMsg {
        header: Header::new(99, tick, 0, 0),
        ..good.clone()
    }));
    // Unknown sender, on its own key.
    put_on(
        topics.cmd(42),
        encode(&CommandMsg {
            sender_id: 42,
            ..good.clone()
        }),
    );
    // Wrong identity: sender 1 on sender 2's key, and on the protocol-3 key naming no sender.
    put_on(topics.cmd(2), encode(&good));
    put_on("flexdyn/sc1/cmd/wrench".to_owned(), encode(&good));
    // A tick in the future.
    put(encode(&CommandMsg {
        header: Header::new(1, tick + 1_000_000, 0, 0),
        ..good.clone()
    }));

    // Effector inputs the reference spacecraft cannot take: its effectors (two panel pairs)
    // have no inputs, and there is no effector 99.
    for index in [0, 99] {
        put(encode(&CommandMsg::actuators(
            Header::new(1, tick, 0, 0),
            1,
            [0.0; 3],
            [0.0; 3],
            vec![flexdyn_proto::EffectorInput {
                effector_index: index,
                values: vec![0.1],
            }],
        )));
    }

    let want = RejectCounters {
        malformed: 2,
        bad_version: 1,
        non_finite: 1,
        wrong_spacecraft: 1,
        stale_tick: 1,
        unknown_sender: 1,
        bad_effector_input: 2,
        wrong_identity: 2,
        operator_refused: 0,
        fault_refused: 0,
        fsw_refused: 0,
    };
    assert!(
        wait_until(WAIT, || obs
            .last_status()
            .is_some_and(|s| s.rejected == want)),
        "status never showed the rejections: {:?}",
        obs.last_status()
    );

    // Still running: telemetry advances and a good command is applied.
    let now = obs.last_tick().unwrap();
    assert!(wait_until(WAIT, || obs
        .last_tick()
        .is_some_and(|t| t >= now + 10)));
    let fresh = CommandMsg {
        header: Header::new(1, obs.last_tick().unwrap(), 0, 1),
        ..good.clone()
    };
    put(encode(&fresh));
    let applied = || {
        obs.seen.lock().unwrap().states.iter().any(|(s, _)| {
            s.wrench_applied.torque_b_nm == [0.0, 0.0, 0.5]
                && s.command_flags & command_flags::NO_COMMAND_YET == 0
        })
    };
    assert!(
        wait_until(WAIT, applied),
        "the good command was never applied"
    );

    server.stop();
    let report = server.join(WAIT).expect("server run");
    assert_eq!(report.outcome, Outcome::Stopped);
    assert_eq!(report.rejected, want);
}

/// A flood of commands that cannot be applied, sent at once to a real-time server with a small
/// command queue, is counted under its reasons; `commands_dropped` counts only valid commands
/// that found the queue full. (Before the command callback checked ticks and effector inputs,
/// such commands filled the queue and part of them landed in `commands_dropped`.)
#[test]
fn a_flood_of_bad_commands_is_counted_by_reason_not_as_dropped() {
    const FUTURE: u64 = 3000;
    const BAD_INPUTS: u64 = 1000;
    const VALID: u64 = 3000;
    const QUEUE: usize = 8;
    let topics = Topics::new("sc1").unwrap();
    // 10 Hz: the physics thread empties the queue every 100 ms, so a burst of valid commands
    // larger than the queue must lose some.
    let (mut server, obs) = running(
        ServerSettings {
            participants: vec![1],
            command_queue: QUEUE,
            status_hz: 20.0,
            ..ServerSettings::default()
        },
        10.0,
    );
    // Blocking congestion control: Zenoh's default (drop) may shed part of a 7,000-put burst on
    // a busy machine, and the counts below need every command to arrive.
    let cmd_pub = obs
        .session
        .declare_publisher(topics.cmd(1))
        .congestion_control(zenoh::qos::CongestionControl::Block)
        .wait()
        .unwrap();
    let put = |cmd: &CommandMsg| cmd_pub.put(encode(cmd)).wait().unwrap();
    let seen = obs.last_tick().unwrap();
    let wrench =
        |tick: u64| CommandMsg::wrench(Header::new(1, tick, 0, 0), 1, [0.0, 0.0, 1e-3], [0.0; 3]);
    // Ticks 10 s and more ahead of the last state seen: never published while they arrive.
    for i in 0..FUTURE {
        put(&wrench(seen + 100 + i));
    }
    // An input for a panel pair, which takes none.
    for _ in 0..BAD_INPUTS {
        put(&CommandMsg::actuators(
            Header::new(1, seen, 0, 0),
            1,
            [0.0; 3],
            [0.0; 3],
            vec![flexdyn_proto::EffectorInput {
                effector_index: 0,
                values: vec![0.1],
            }],
        ));
    }
    // Valid: a tick already published, the same for all, so none is older than the last.
    for _ in 0..VALID {
        put(&wrench(seen));
    }
    // One more future tick after everything: once it is counted, the callback has seen the
    // whole flood (one publisher, reliable and in order).
    put(&wrench(u64::MAX));
    let counted = wait_until(WAIT, || {
        obs.last_status()
            .is_some_and(|s| s.rejected.stale_tick == FUTURE + 1)
    });
    server.stop();
    let report = server.join(WAIT).expect("server run");
    eprintln!("{report}");
    assert!(
        counted,
        "the status never counted every future tick: {report}"
    );
    assert_eq!(
        report.rejected,
        RejectCounters {
            stale_tick: FUTURE + 1,
            bad_effector_input: BAD_INPUTS,
            ..RejectCounters::default()
        },
        "{report}"
    );
    // At most QUEUE valid commands are taken per 100 ms frame; the burst is far larger.
    assert!(
        report.commands_dropped > 0 && report.commands_dropped <= VALID,
        "commands_dropped {} of {VALID} valid commands: {report}",
        report.commands_dropped
    );
}
