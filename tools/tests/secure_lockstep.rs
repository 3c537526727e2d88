//! Issue 10: who may command the spacecraft on a lab network.
//!
//! The server runs with the shipped `scenarios/zenoh/secure-server.json5` (user/password
//! authentication with `scenarios/zenoh/users.txt`, an access-control list that lets only user
//! `fsw` put on `flexdyn/sc1/cmd/1`) and `participant_subjects = { 1 = "fsw" }`. The demo
//! controller (a separate process) connects with `scenarios/zenoh/secure-client.json5`.
//!
//! 1. A lockstep run under attack equals, bit for bit, a plain loopback run without it:
//!    - an authenticated operator (`operator-client.json5`) receives every state and puts an
//!      impostor command for sender 1 on `cmd/1` for each one: the ACL drops them all, so no
//!      rejection is even counted;
//!    - a peer without credentials and one with a wrong password cannot connect: no peer, no
//!      state received, and their puts never arrive.
//! 2. A second participant bound to `operator` (a test ACL) that claims sender 1's id on its
//!    own key is rejected and counted under `rejected.wrong_identity`, once per impostor command,
//!    and the trajectory is still the baseline's.
//!
//! Every peer is given its endpoint on the command line (`--listen`/`--connect`; the server
//! listens on port 0, takes a free port from the OS and the others connect to it), which replaces the endpoint the shipped JSON5 files name (7447); their authentication
//! and access control are used exactly as shipped.

use flexdyn_testkit::demo_bin;

use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::support::{endpoint, reference_config, ChildGuard, ServerHandle};
use flexdyn_proto::client::transport::{zenoh_config, Role};
use flexdyn_proto::{
    decode_state, decode_status, encode, CommandMsg, Header, Mode, RejectCounters, StatusMsg,
    Topics,
};
use flexdyn_server::{ServerSettings, ZenohArgs};
use sha2::{Digest, Sha256};
use zenoh::{Session, Wait};

const TICKS: u64 = 2000;

fn scenario(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../scenarios/zenoh/{name}"))
}

/// A Zenoh configuration built like every flexdyn session's, from `file` (if any), listening
/// or connecting on `port` (a server given port 0 listens on a free port the OS chooses).
fn config(port: u16, role: Role, file: Option<PathBuf>) -> zenoh::Config {
    let ep = vec![endpoint(port)];
    let args = ZenohArgs {
        listen: if role == Role::Server {
            ep.clone()
        } else {
            vec![]
        },
        connect: if role == Role::Tool { ep } else { vec![] },
        zenoh_config: file,
    };
    zenoh_config(&args, role).unwrap()
}

fn session(port: u16, role: Role, file: Option<PathBuf>) -> Session {
    open(config(port, role, file))
}

fn open(config: zenoh::Config) -> Session {
    zenoh::open(config).wait().unwrap()
}

fn settings(participants: &[(u32, &str)], secure: bool) -> ServerSettings {
    ServerSettings {
        mode: Mode::Lockstep,
        participants: participants.iter().map(|(id, _)| *id).collect(),
        participant_subjects: if secure {
            participants
                .iter()
                .map(|(id, u)| (*id, (*u).to_owned()))
                .collect()
        } else {
            Default::default()
        },
        duration_ns: Some(TICKS * 10_000_000),
        participant_timeout: Duration::from_secs(10),
        ..ServerSettings::default()
    }
}

/// Every state payload (by tick) and status a session receives.
#[derive(Default)]
struct Seen {
    states: Mutex<Vec<(u64, Vec<u8>)>>,
    statuses: Mutex<Vec<StatusMsg>>,
}

fn observe(s: &Session, topics: &Topics) -> (Arc<Seen>, Vec<zenoh::pubsub::Subscriber<()>>) {
    let seen: Arc<Seen> = Arc::default();
    let a = seen.clone();
    let states = s
        .declare_subscriber(topics.state().to_owned())
        .callback(move |sample| {
            let bytes = sample.payload().to_bytes().to_vec();
            if let Ok(st) = decode_state(&bytes) {
                a.states.lock().unwrap().push((st.header.tick, bytes));
            }
        })
        .wait()
        .unwrap();
    let b = seen.clone();
    let statuses = s
        .declare_subscriber(topics.status().to_owned())
        .callback(move |sample| {
            if let Ok(st) = decode_status(&sample.payload().to_bytes()) {
                b.statuses.lock().unwrap().push(st);
            }
        })
        .wait()
        .unwrap();
    (seen, vec![states, statuses])
}

/// Waits (bounded) until `cond` holds.
fn wait_for(what: &str, timeout: Duration, cond: impl Fn() -> bool) {
    let give_up = std::time::Instant::now() + timeout;
    while !cond() {
        assert!(std::time::Instant::now() < give_up, "timed out: {what}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn digest(states: &[(u64, Vec<u8>)]) -> String {
    let mut sorted = states.to_vec();
    sorted.sort_by_key(|(t, _)| *t);
    let mut h = Sha256::new();
    for (i, (tick, bytes)) in sorted.iter().enumerate() {
        assert_eq!(*tick, i as u64, "ticks are not contiguous from 0");
        h.update(bytes);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

fn controller(port: u16, client_config: Option<PathBuf>) -> ChildGuard {
    let mut cmd = Command::new(demo_bin::acs_demo());
    cmd.args(["--connect", &endpoint(port), "--sender-id", "1"])
        .args(["--log-every-s", "0", "--rate-source", "truth"])
        .args(["--sigma-rn", "0.1,0.2,-0.1"]);
    if let Some(f) = client_config {
        cmd.arg("--zenoh-config").arg(f);
    }
    ChildGuard::spawn(&mut cmd)
}

/// The plain loopback lockstep run: the demo controller alone, no authentication.
fn baseline() -> String {
    let topics = Topics::new("sc1").unwrap();
    let server = ServerHandle::start_with_session(
        session(0, Role::Server, None),
        settings(&[(1, "")], false),
        reference_config(100.0),
    );
    let port = server.port;
    let obs = session(port, Role::Tool, None);
    let (seen, _subs) = observe(&obs, &topics);
    wait_for("a status before tick 0", Duration::from_secs(20), || {
        !seen.statuses.lock().unwrap().is_empty()
    });
    let _ctrl = controller(port, None);
    let report = server.join(Duration::from_secs(120)).expect("baseline run");
    assert_eq!(report.last_tick, TICKS);
    assert_eq!(report.rejected, RejectCounters::default());
    wait_for("every state", Duration::from_secs(10), || {
        seen.states.lock().unwrap().len() as u64 > TICKS
    });
    let states = seen.states.lock().unwrap().clone();
    digest(&states)
}

#[test]
fn only_the_authenticated_flight_code_commands_the_spacecraft() {
    let plain = baseline();

    let topics = Topics::new("sc1").unwrap();
    let server_file = scenario("secure-server.json5");
    let s = settings(&[(1, "fsw")], true);
    // The server's own start-up check (as `flexdyn run` makes it) accepts the shipped files.
    let zcfg = config(0, Role::Server, Some(server_file));
    flexdyn_server::access::check(&zcfg, &s).expect("the shipped ACL binds sender 1 to fsw");
    let server = ServerHandle::start_with_session(open(zcfg), s, reference_config(100.0));
    let port = server.port;

    // An authenticated operator: sees the telemetry, and tries to command as sender 1.
    let operator = session(port, Role::Tool, Some(scenario("operator-client.json5")));
    let (seen, _subs) = observe(&operator, &topics);
    let impostor_puts = Arc::new(AtomicU64::new(0));
    let (op, n) = (operator.clone(), impostor_puts.clone());
    let key = topics.cmd(1);
    let _impostor = operator
        .declare_subscriber(topics.state().to_owned())
        .callback(move |sample| {
            let Ok(st) = decode_state(&sample.payload().to_bytes()) else {
                return;
            };
            let h = st.header;
            let cmd = CommandMsg::wrench(
                Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, h.tick),
                1,
                [5.0, -5.0, 5.0],
                [0.0; 3],
            );
            if op.put(key.as_str(), encode(&cmd)).wait().is_ok() {
                n.fetch_add(1, Ordering::Relaxed);
            }
        })
        .wait()
        .unwrap();
    wait_for(
        "the operator's first status",
        Duration::from_secs(20),
        || !seen.statuses.lock().unwrap().is_empty(),
    );

    // Peers that cannot authenticate: no credentials, and fsw with a wrong password.
    let anonymous = session(port, Role::Tool, None);
    let wrong_password_file =
        std::env::temp_dir().join(format!("flexdyn-wrong-pw-{}.json5", std::process::id()));
    std::fs::write(
        &wrong_password_file,
        std::fs::read_to_string(scenario("secure-client.json5"))
            .unwrap()
            .replace("change-me-fsw-4c1d", "guess"),
    )
    .unwrap();
    let guesser = session(port, Role::Tool, Some(wrong_password_file.clone()));
    let outsiders = [anonymous, guesser];
    let outsider_states: Vec<_> = outsiders.iter().map(|s| observe(s, &topics)).collect();
    let stop = Arc::new(AtomicBool::new(false));
    let flood = {
        let (stop, outsiders, key) = (stop.clone(), outsiders.clone(), topics.cmd(1));
        std::thread::spawn(move || {
            let mut sent = 0u64;
            while !stop.load(Ordering::Relaxed) {
                for s in &outsiders {
                    let cmd =
                        CommandMsg::wrench(Header::new(1, sent, 0, sent), 1, [9.0; 3], [0.0; 3]);
                    let _ = s.put(key.as_str(), encode(&cmd)).wait();
                }
                sent += 1;
                std::thread::sleep(Duration::from_millis(1));
            }
            sent
        })
    };

    let _ctrl = controller(port, Some(scenario("secure-client.json5")));
    let report = server.join(Duration::from_secs(120)).expect("secure run");
    stop.store(true, Ordering::Relaxed);
    let flooded = flood.join().unwrap();
    std::fs::remove_file(&wrong_password_file).ok();

    assert_eq!(report.last_tick, TICKS);
    wait_for(
        "every state at the operator",
        Duration::from_secs(10),
        || seen.states.lock().unwrap().len() as u64 > TICKS,
    );
    let states = seen.states.lock().unwrap().clone();
    assert_eq!(
        digest(&states),
        plain,
        "the run under attack differs from the plain run"
    );
    // The impostor was active all along (it saw every state), and none of its puts reached the
    // server's command callback: nothing was even rejected.
    assert!(
        impostor_puts.load(Ordering::Relaxed) > TICKS,
        "the impostor never put"
    );
    assert_eq!(report.rejected, RejectCounters::default());
    // The outsiders have no peer, saw nothing, and flooded in vain.
    assert!(flooded > 100, "the outsiders did not flood ({flooded})");
    for (s, (seen, _)) in outsiders.iter().zip(&outsider_states) {
        assert_eq!(
            s.info().peers_zid().wait().count(),
            0,
            "an outsider connected"
        );
        assert!(seen.states.lock().unwrap().is_empty());
        assert!(seen.statuses.lock().unwrap().is_empty());
    }
    eprintln!(
        "secure lockstep: {} states = baseline {plain}; impostor puts {}, outsider puts {}",
        states.len(),
        impostor_puts.load(Ordering::Relaxed),
        2 * flooded
    );
}

/// The shipped ACL plus a second participant: `operator` may put on `cmd/2` and declare
/// participant 2's token.
fn two_participant_acl() -> PathBuf {
    let text = std::fs::read_to_string(scenario("secure-server.json5"))
        .unwrap()
        .replace(
            "{ id: \"telemetry\",",
            "{ id: \"operator-commands\", messages: [\"put\"], flows: [\"ingress\"], \
             permission: \"allow\", key_exprs: [\"flexdyn/sc1/cmd/2\"] },\n      \
             { id: \"operator-presence\", messages: [\"liveliness_token\"], flows: [\"ingress\"], \
             permission: \"allow\", key_exprs: [\"flexdyn/sc1/participant/2\"] },\n      \
             { id: \"telemetry\",",
        )
        .replace(
            "{ id: \"flight-code\", usernames: [\"fsw\"] },",
            "{ id: \"flight-code\", usernames: [\"fsw\"] },\n      \
             { id: \"second\", usernames: [\"operator\"] },",
        )
        .replace(
            "{ rules: [\"fsw-commands\", \"fsw-presence\"], subjects: [\"flight-code\"] },",
            "{ rules: [\"fsw-commands\", \"fsw-presence\"], subjects: [\"flight-code\"] },\n      \
             { rules: [\"operator-commands\", \"operator-presence\"], subjects: [\"second\"] },",
        )
        .replace(
            "dictionary_file: \"users.txt\"",
            &format!(
                "dictionary_file: {:?}",
                scenario("users.txt").to_string_lossy()
            ),
        );
    let path = std::env::temp_dir().join(format!("flexdyn-acl2-{}.json5", std::process::id()));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_participant_claiming_another_ones_sender_id_is_rejected_and_counted() {
    let plain = baseline();

    let topics = Topics::new("sc1").unwrap();
    let acl = two_participant_acl();
    let s = settings(&[(1, "fsw"), (2, "operator")], true);
    let zcfg = config(0, Role::Server, Some(acl.clone()));
    flexdyn_server::access::check(&zcfg, &s).expect("the test ACL binds 1 to fsw, 2 to operator");
    let server = ServerHandle::start_with_session(open(zcfg), s, reference_config(100.0));
    let port = server.port;

    // Participant 2 (user `operator`): for every state, first an impostor command claiming
    // sender 1 on its own key, then its real answer.
    let p2 = session(port, Role::Tool, Some(scenario("operator-client.json5")));
    let (seen, _subs) = observe(&p2, &topics);
    let claims = Arc::new(AtomicU64::new(0));
    let (p, c, key) = (p2.clone(), claims.clone(), topics.cmd(2));
    let _answers = p2
        .declare_subscriber(topics.state().to_owned())
        .callback(move |sample| {
            let Ok(st) = decode_state(&sample.payload().to_bytes()) else {
                return;
            };
            let h = Header::new(st.header.spacecraft_id, st.header.tick, 0, st.header.tick);
            let impostor = CommandMsg::wrench(h, 1, [5.0; 3], [0.0; 3]);
            if p.put(key.as_str(), encode(&impostor)).wait().is_ok() {
                c.fetch_add(1, Ordering::Relaxed);
            }
            let _ = p
                .put(key.as_str(), encode(&CommandMsg::no_command(h, 2)))
                .wait();
        })
        .wait()
        .unwrap();
    let _token = p2
        .liveliness()
        .declare_token(topics.participant(2))
        .wait()
        .unwrap();
    wait_for(
        "participant 2's first status",
        Duration::from_secs(20),
        || !seen.statuses.lock().unwrap().is_empty(),
    );
    let _ctrl = controller(port, Some(scenario("secure-client.json5")));
    let report = server
        .join(Duration::from_secs(120))
        .expect("two-participant run");
    std::fs::remove_file(&acl).ok();
    assert_eq!(report.last_tick, TICKS);
    // Every impostor command answered a state of ticks 0..TICKS-1 and arrived before the real
    // answer of its tick, so each one was rejected; the one for the last state may come after
    // the server stopped listening.
    let claimed = claims.load(Ordering::Relaxed);
    assert!(claimed >= TICKS, "{claimed} impostor commands");
    assert!(
        report.rejected.wrong_identity == claimed || report.rejected.wrong_identity == TICKS,
        "wrong_identity {} for {claimed} impostor commands",
        report.rejected.wrong_identity
    );
    assert_eq!(
        report.rejected,
        RejectCounters {
            wrong_identity: report.rejected.wrong_identity,
            ..RejectCounters::default()
        }
    );
    // The status said so too.
    wait_for("a status with the count", Duration::from_secs(10), || {
        seen.statuses
            .lock()
            .unwrap()
            .iter()
            .any(|s| s.rejected.wrong_identity >= TICKS)
    });
    wait_for("every state", Duration::from_secs(10), || {
        seen.states.lock().unwrap().len() as u64 > TICKS
    });
    let states = seen.states.lock().unwrap().clone();
    assert_eq!(
        digest(&states),
        plain,
        "NoCommand answers and rejected impostors changed the trajectory"
    );
}
