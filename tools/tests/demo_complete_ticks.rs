//! The demo flight code answers tick k from tick k's own sensor samples, even when one of them
//! reaches it after the state of its tick (as it can with separate Zenoh subscribers, each
//! delivered on its own thread) and later than any fixed wait.
//!
//! A stand-in lockstep server in this test serves `scenarios/imu_tactical.toml` on the
//! configuration queryable and publishes 20 ticks, waiting for the demo's answer to each. On
//! three ticks it publishes the state first and that tick's IMU samples 300 ms later. With
//! K = 0 and P = 1 N·m·s the demo's torque is −ω_B, and the `hub` IMU's mounting is the
//! identity, so every answer must be exactly −(the gyro rate of its own tick). The previous
//! demo waited at most 50 ms for a sample, then held the previous tick's rate: it failed here.
//! Both of the demo's ways of answering are checked: on the Zenoh thread that completes the
//! tick (its default) and on its main thread (`--answer-on main-thread`).

use flexdyn_testkit::demo_bin;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use flexdyn_proto::client::transport::{listening_on, zenoh_config, Role, ZenohArgs};
use flexdyn_proto::{decode_command, encode, CommandKind, Header, ImuMsg, StateMsg, Topics};
use zenoh::Wait;

const TICKS: u64 = 20;
const LATE: [u64; 3] = [0, 7, 13];

/// The gyro rate of tick k [rad/s], different every tick.
fn omega(k: u64) -> [f64; 3] {
    let k = k as f64 + 1.0;
    [1e-3 * k, -2e-3 * k, 5e-4 * k]
}

#[test]
fn the_demo_answers_each_tick_from_its_own_imu_sample_however_late() {
    answers_from_own_samples("zenoh-thread");
}

#[test]
fn the_demo_answering_on_its_main_thread_does_too() {
    answers_from_own_samples("main-thread");
}

/// The stand-in server's 20 ticks, answered by the demo with `--answer-on answer_on`.
fn answers_from_own_samples(answer_on: &str) {
    // The stand-in server listens on a port the OS picks, and reports it.
    let zargs = ZenohArgs {
        listen: vec!["tcp/127.0.0.1:0".to_owned()],
        ..ZenohArgs::default()
    };
    let session = zenoh::open(zenoh_config(&zargs, Role::Server).unwrap())
        .wait()
        .unwrap();
    let endpoint = listening_on(&session)
        .into_iter()
        .next()
        .expect("the stand-in server listens");
    let topics = Topics::new("sc1").unwrap();
    let scenario =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/imu_tactical.toml");
    let reply = serde_json::json!({
        "sc_id": "sc1", "spacecraft_id": 1,
        "config_toml": std::fs::read_to_string(scenario).unwrap(),
        "server_settings": "mode=lockstep", "flexdyn_version": "test", "git_commit": null,
    })
    .to_string();
    let _config = session
        .declare_queryable(topics.config())
        .callback(move |q| {
            let _ = q.reply(q.key_expr().clone(), reply.clone()).wait();
        })
        .wait()
        .unwrap();
    let commands = session.declare_subscriber(topics.cmd(1)).wait().unwrap();
    let state_pub = session
        .declare_publisher(topics.state().to_owned())
        .wait()
        .unwrap();
    let imu_pubs: Vec<_> = ["hub", "bracket"]
        .iter()
        .map(|n| {
            session
                .declare_publisher(topics.imu(n).unwrap())
                .wait()
                .unwrap()
        })
        .collect();

    let mut demo = Command::new(demo_bin::acs_demo())
        .args([
            "--connect",
            &endpoint,
            "--sender-id",
            "1",
            "--k-nm",
            "0",
            "--p-nms",
            "1",
        ])
        .args([
            "--rate-source",
            "gyro",
            "--imu",
            "hub",
            "--log-every-s",
            "0",
        ])
        .args(["--idle-exit-s", "10", "--answer-on", answer_on])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();

    // The demo's liveliness token: it is subscribed.
    let give_up = Instant::now() + Duration::from_secs(30);
    loop {
        let replies = session
            .liveliness()
            .get(topics.participant(1))
            .timeout(Duration::from_millis(500))
            .wait()
            .unwrap();
        if replies.recv().is_ok() {
            break;
        }
        assert!(
            Instant::now() < give_up,
            "the demo never declared its token"
        );
        std::thread::sleep(Duration::from_millis(50));
    }

    let mut wrong = Vec::new();
    for k in 0..TICKS {
        let header = Header::new(1, k, k * 10_000_000, k);
        let state = encode(&StateMsg {
            header,
            ..StateMsg::default()
        });
        let imus = |pubs: &[zenoh::pubsub::Publisher<'_>]| {
            for (p, w) in pubs.iter().zip([omega(k), [0.0; 3]]) {
                let m = ImuMsg {
                    header,
                    omega_p_rad_s: w,
                    ..ImuMsg::default()
                };
                p.put(encode(&m)).wait().unwrap();
            }
        };
        if LATE.contains(&k) {
            state_pub.put(state).wait().unwrap();
            std::thread::sleep(Duration::from_millis(300));
            imus(&imu_pubs);
        } else {
            imus(&imu_pubs);
            state_pub.put(state).wait().unwrap();
        }
        let answer = loop {
            let sample = commands
                .recv_timeout(Duration::from_secs(10))
                .unwrap()
                .unwrap_or_else(|| panic!("no answer to tick {k}"));
            let cmd = decode_command(&sample.payload().to_bytes()).unwrap();
            if cmd.header.tick == k {
                break cmd;
            }
        };
        let want = omega(k).map(|w| -w);
        match answer.kind {
            CommandKind::Wrench { torque_b_nm, .. } if torque_b_nm == want => {}
            other => wrong.push(format!("tick {k}: {other:?}, want torque {want:?}")),
        }
    }
    let _ = demo.kill();
    let _ = demo.wait();
    assert!(
        wrong.is_empty(),
        "--answer-on {answer_on}: answers not from their own tick:\n{}",
        wrong.join("\n")
    );
}
