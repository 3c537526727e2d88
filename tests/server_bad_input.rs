//! Bad commands are rejected, counted by reason in StatusMsg.rejected, and the server keeps
//! running (and still accepts good commands).

mod server_support;

use std::time::Duration;

use flexdyn::server::{Outcome, ServerSettings};
use flexdyn_proto::{command_flags, encode, CommandMsg, Header, RejectCounters, Topics};
use server_support::{free_port, reference_config, wait_until, Observer, ServerHandle};
use zenoh::Wait;

const WAIT: Duration = Duration::from_secs(20);

#[test]
fn bad_commands_are_counted_and_the_server_keeps_running() {
    let port = free_port();
    let topics = Topics::new("sc1").unwrap();
    let mut server = ServerHandle::start(
        port,
        ServerSettings {
            participants: vec![1],
            status_hz: 50.0,
            ..ServerSettings::default()
        },
        reference_config(100.0),
    );
    let obs = Observer::start(port, &topics);
    assert!(
        wait_until(WAIT, || obs.last_tick().is_some_and(|t| t >= 5)),
        "no telemetry"
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
