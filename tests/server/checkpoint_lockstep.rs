//! Server checkpoints (issue 40 §2) on a real lockstep server: a run that saves a checkpoint at
//! tick k goes on unchanged, and a new server resumed from that file publishes, from tick k on,
//! every telemetry sample of the uninterrupted run bit for bit, whichever thread steps its
//! frames (`handoff = "direct"` or `"thread"`). The flight code is a stateless rate-and-attitude
//! controller living in the test, so its commands depend on the state it is sent alone, and the
//! resumed server's command book must hold what the first one held for the stream to match.
//! The same holds for a fleet server (every vehicle's stream and the relative states) and for a
//! checkpoint an operator asks for while the run goes on (OperatorMsg `Checkpoint`, written
//! into `--checkpoint-dir`). A checkpoint another front end wrote, or a damaged one, is refused
//! with the file's name.

use crate::server_support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn_proto::{
    decode_header, decode_state, decode_time, encode, CommandMsg, Header, Mode, OperatorAction,
    OperatorMsg, RunState, Topics,
};
use flexdyn_server::checkpoint::{self, CheckpointSettings};
use flexdyn_server::{Handoff, ServerError, ServerSettings};
use flexdyn_vehicle::checkpoint::Source;
use flexdyn_vehicle::config::SimConfig;
use server_support::{connecting_session, ServerHandle};
use zenoh::{Session, Wait};

/// Every telemetry payload per key, each with its header tick, in publication order.
type Recorded = BTreeMap<String, Vec<(u64, Vec<u8>)>>;
type Streams = Arc<Mutex<Recorded>>;

/// The flight code: answers every state with a torque from that state alone (a PD law on the
/// attitude quaternion's vector part and the rate), and records every telemetry sample.
struct FlightCode {
    streams: Streams,
    _subs: Vec<zenoh::pubsub::Subscriber<()>>,
    _token: zenoh::liveliness::LivelinessToken,
    _session: Session,
}

impl FlightCode {
    /// Flight code of sender 1.
    fn start(port: u16, topics: &Topics) -> Self {
        Self::start_as(port, topics, 1, Duration::ZERO)
    }

    /// Flight code of `sender_id` for the vehicle of `topics`, taking `think` before each answer
    /// (so that an operator's commands land while the run goes on).
    fn start_as(port: u16, topics: &Topics, sender_id: u32, think: Duration) -> Self {
        let session = connecting_session(port);
        let streams: Streams = Arc::default();
        let s = streams.clone();
        let tlm = session
            .declare_subscriber(topics.telemetry_wildcard())
            .callback(move |sample| {
                let bytes = sample.payload().to_bytes().into_owned();
                let tick = decode_header(&bytes).expect("a flexdyn message").tick;
                s.lock()
                    .unwrap()
                    .entry(sample.key_expr().as_str().to_owned())
                    .or_default()
                    .push((tick, bytes));
            })
            .wait()
            .unwrap();
        let publisher = session
            .declare_publisher(topics.cmd(sender_id))
            .congestion_control(zenoh::qos::CongestionControl::Block)
            .wait()
            .unwrap();
        let state = session
            .declare_subscriber(topics.state().to_owned())
            .callback(move |sample| {
                let st = decode_state(&sample.payload().to_bytes()).expect("a StateMsg");
                let h = st.header;
                let sign = if st.q_bn[0] < 0.0 { -1.0 } else { 1.0 };
                let torque_b_nm: [f64; 3] = std::array::from_fn(|i| {
                    -0.2 * sign * st.q_bn[i + 1] - 2.0 * st.omega_bn_b_rad_s[i]
                });
                let cmd = CommandMsg::wrench(
                    Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, h.tick),
                    sender_id,
                    torque_b_nm,
                    [0.0; 3],
                );
                std::thread::sleep(think);
                publisher.put(encode(&cmd)).wait().unwrap();
            })
            .wait()
            .unwrap();
        let token = session
            .liveliness()
            .declare_token(topics.participant(sender_id))
            .wait()
            .unwrap();
        Self {
            streams,
            _subs: vec![tlm, state],
            _token: token,
            _session: session,
        }
    }

    /// Each key's payloads (the status messages, on the wall clock, left out).
    fn recorded(&self) -> Recorded {
        let mut all = self.streams.lock().unwrap().clone();
        all.retain(|k, _| !k.ends_with("/status"));
        all
    }
}

fn acs_full() -> (SimConfig, Source) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/acs_full.toml");
    let source = Source::of(Some(&path)).unwrap();
    (source.config().unwrap(), source)
}

fn settings(handoff: Handoff, frames: u64, checkpoints: CheckpointSettings) -> ServerSettings {
    ServerSettings {
        mode: Mode::Lockstep,
        handoff,
        participants: vec![1],
        duration_ns: Some(100_000_000 * frames),
        checkpoints,
        ..ServerSettings::default()
    }
}

/// Runs a lockstep server with the flight code to its end; the streams it published.
fn run(
    cfg: SimConfig,
    settings: ServerSettings,
) -> (Result<flexdyn_server::RunReport, ServerError>, Recorded) {
    let topics = Topics::new(&settings.sc_id).unwrap();
    let server = ServerHandle::start(settings, cfg);
    let fsw = FlightCode::start(server.port, &topics);
    let result = server.join(Duration::from_secs(120));
    // The last samples are in flight when the run ends.
    std::thread::sleep(Duration::from_millis(300));
    (result, fsw.recorded())
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("flexdyn-ckpt-server-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Each key's payloads of tick ≥ `from`.
fn later(streams: &Recorded, from: u64) -> Recorded {
    streams
        .iter()
        .map(|(k, v)| {
            let later = v.iter().filter(|(t, _)| *t >= from).cloned().collect();
            (k.clone(), later)
        })
        .collect()
}

/// `got` must be `expected`'s samples of tick ≥ `from`, key for key and bit for bit (so nothing
/// before `from`).
fn assert_same_from(expected: &Recorded, got: &Recorded, from: u64, what: &str) {
    let expected = later(expected, from);
    assert_eq!(
        got.keys().collect::<Vec<_>>(),
        expected.keys().collect::<Vec<_>>(),
        "{what}"
    );
    for (key, v) in &expected {
        let got = &got[key];
        assert_eq!(got.len(), v.len(), "{what}: {key}: samples");
        if let Some(i) = (0..v.len()).find(|&i| got[i] != v[i]) {
            panic!(
                "{what}: {key}: the sample of tick {} differs from the uninterrupted run's",
                v[i].0
            );
        }
    }
}

/// Link faults on participant 1 around the checkpoint of [`resumes_bit_for_bit`] (tick 70,
/// 7 s): delayed by 3 frames over it, then corrupted, then dropped.
const LINK_FAULTS: &str = r#"
[[faults]]
target = "links.1"
mode = "delayed"
frames = 3
start_s = 3.0
duration_s = 5.0

[[faults]]
target = "links.1"
mode = "corrupted"
probability = 1e-3
start_s = 9.0
duration_s = 4.0
seed = 3

[[faults]]
target = "links.1"
mode = "dropped"
start_s = 14.0
duration_s = 1.0
"#;

/// A run that saves a checkpoint at tick 70 publishes what a run that saves none publishes,
/// under either handoff, and both write the same file; servers resumed from it, under either
/// handoff, publish the uninterrupted stream from tick 70 on, bit for bit.
fn resumes_bit_for_bit(cfg: SimConfig, source: Source, name: &str) {
    const FRAMES: u64 = 160;
    const AT: u64 = 70;
    let (report, whole) = run(
        cfg.clone(),
        settings(Handoff::Thread, FRAMES, CheckpointSettings::default()),
    );
    assert_eq!(report.unwrap().last_tick, FRAMES);
    // The state, the time, every sensor and the environment, each from tick 0.
    assert!(whole.len() >= 6, "keys: {:?}", whole.keys());
    let mut files = Vec::new();
    for handoff in [Handoff::Direct, Handoff::Thread] {
        let file = tmp(&format!("{name}_{handoff:?}_70.ckpt"));
        let saving = CheckpointSettings {
            save_at: Some((AT, file.clone())),
            source: source.clone(),
            ..CheckpointSettings::default()
        };
        let (report, saved) = run(cfg.clone(), settings(handoff, FRAMES, saving));
        let report = report.unwrap();
        assert_eq!(report.last_tick, FRAMES);
        let c = report.checkpoints.expect("this run saves checkpoints");
        assert_eq!((c.written, c.failed), (1, 0), "{report}");
        // Saving changes nothing the run publishes.
        assert_same_from(
            &whole,
            &saved,
            0,
            &format!("{name}, saving under {handoff:?}"),
        );
        files.push(std::fs::read(&file).unwrap());
    }
    assert!(
        files[0] == files[1],
        "{name}: the two handoffs saved different checkpoints"
    );
    let file = tmp(&format!("{name}_{:?}_70.ckpt", Handoff::Direct));
    for handoff in [Handoff::Direct, Handoff::Thread] {
        let (resumed, header) = checkpoint::read(&file, checkpoint::FRONT_END).unwrap();
        assert_eq!(header.tick, AT);
        let resuming = CheckpointSettings {
            resume: Some(resumed),
            source: source.clone(),
            ..CheckpointSettings::default()
        };
        let (report, after) = run(cfg.clone(), settings(handoff, FRAMES, resuming));
        assert_eq!(report.unwrap().last_tick, FRAMES);
        assert_same_from(
            &whole,
            &after,
            AT,
            &format!("{name}, resumed under {handoff:?}"),
        );
    }
}

#[test]
fn a_resumed_lockstep_server_publishes_the_uninterrupted_stream_bit_for_bit() {
    let (cfg, source) = acs_full();
    resumes_bit_for_bit(cfg, source, "acs_full");
}

#[test]
fn the_command_links_delay_lines_and_damage_resume_bit_for_bit() {
    let (_, mut source) = acs_full();
    source.text.push_str(LINK_FAULTS);
    let cfg = source.config().unwrap();
    assert_eq!(cfg.faults.len(), 3 + acs_full().0.faults.len());
    resumes_bit_for_bit(cfg, source, "acs_full_links");
}

/// A fleet file of two reference spacecraft, chief (participant 1) and deputy (participant 2).
fn formation() -> (flexdyn_vehicle::world::FleetConfig, Source) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/formation.toml");
    let source = Source::of(Some(&path)).unwrap();
    (
        flexdyn_vehicle::world::FleetConfig::from_file(&path).unwrap(),
        source,
    )
}

/// Runs the formation's lockstep fleet server with flight code for both vehicles; what each
/// vehicle published (keys `flexdyn/<id>/…`).
fn run_fleet(settings: ServerSettings) -> (flexdyn_server::fleet::FleetReport, Recorded) {
    let (fleet, _) = formation();
    let server = server_support::FleetServerHandle::start(settings, fleet);
    let chief = FlightCode::start_as(
        server.port,
        &Topics::new("chief").unwrap(),
        1,
        Duration::ZERO,
    );
    let deputy = FlightCode::start_as(
        server.port,
        &Topics::new("deputy").unwrap(),
        2,
        Duration::ZERO,
    );
    let report = server.join(Duration::from_secs(120)).unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let mut all = chief.recorded();
    all.extend(deputy.recorded());
    (report, all)
}

#[test]
fn a_resumed_fleet_server_publishes_every_vehicles_stream_bit_for_bit() {
    const FRAMES: u64 = 120;
    const AT: u64 = 45;
    let (_, source) = formation();
    let file = tmp("formation_45.ckpt");
    // The reference spacecraft's frame: 10 ms.
    let fleet_settings = |checkpoints, handoff| ServerSettings {
        mode: Mode::Lockstep,
        handoff,
        duration_ns: Some(FRAMES * 10_000_000),
        checkpoints,
        ..ServerSettings::default()
    };
    let saving = CheckpointSettings {
        save_at: Some((AT, file.clone())),
        source: source.clone(),
        ..CheckpointSettings::default()
    };
    let (report, whole) = run_fleet(fleet_settings(saving, Handoff::Direct));
    let (_, first) = &report.vehicles[0];
    assert_eq!(first.last_tick, FRAMES);
    assert_eq!(first.checkpoints.map(|c| c.written), Some(1));
    // Both vehicles' streams, and the deputy's relative state.
    assert!(whole.keys().any(|k| k.starts_with("flexdyn/chief/")));
    assert!(
        whole.keys().any(|k| k.contains("/tlm/rel/")),
        "{:?}",
        whole.keys()
    );
    for handoff in [Handoff::Direct, Handoff::Thread] {
        let (resumed, _) = checkpoint::read(&file, checkpoint::FRONT_END_FLEET).unwrap();
        let resuming = CheckpointSettings {
            resume: Some(resumed),
            source: source.clone(),
            ..CheckpointSettings::default()
        };
        let (report, after) = run_fleet(fleet_settings(resuming, handoff));
        assert_eq!(report.vehicles[1].1.last_tick, FRAMES);
        assert_same_from(&whole, &after, AT, &format!("fleet, {handoff:?}"));
    }
    // A one-spacecraft server refuses the fleet's checkpoint, naming both front ends.
    let e = checkpoint::read(&file, checkpoint::FRONT_END)
        .unwrap_err()
        .to_string();
    assert!(e.contains("`run --fleet`") && e.contains("`run`"), "{e}");
}

/// Whether the last TimeMsg `fsw` received says the run is paused.
fn held(fsw: &FlightCode, topics: &Topics) -> bool {
    let streams = fsw.streams.lock().unwrap();
    streams
        .get(&topics.time())
        .and_then(|v| v.last())
        .is_some_and(|(_, b)| decode_time(b).unwrap().run_state == RunState::Paused)
}

fn operator(session: &Session, topics: &Topics, action: OperatorAction, ticks: u64) {
    let msg = OperatorMsg::new(Header::new(1, 0, 0, 0), action, ticks);
    session.put(topics.operator(), encode(&msg)).wait().unwrap();
}

#[test]
fn an_operator_checkpoint_lands_in_the_checkpoint_dir_and_resumes_bit_for_bit() {
    const FRAMES: u64 = 200;
    let (cfg, source) = acs_full();
    let dir = tmp("operator");
    std::fs::create_dir_all(&dir).unwrap();
    let checkpoints = CheckpointSettings {
        dir: Some(dir.clone()),
        source: source.clone(),
        ..CheckpointSettings::default()
    };
    let topics = Topics::new("sc1").unwrap();
    let server = ServerHandle::start(settings(Handoff::Direct, FRAMES, checkpoints), cfg.clone());
    let fsw = FlightCode::start_as(server.port, &topics, 1, Duration::from_millis(5));
    let op = connecting_session(server.port);
    server_support::wait_until(Duration::from_secs(30), || {
        fsw.streams.lock().unwrap().contains_key(topics.state())
    });
    // Hold the run, then ask for a checkpoint at the next boundary (0), and one at a tick
    // already published (refused), then release it.
    operator(&op, &topics, OperatorAction::Pause, 0);
    assert!(server_support::wait_until(
        Duration::from_secs(30),
        || held(&fsw, &topics)
    ));
    let k = fsw.streams.lock().unwrap()[&topics.time()]
        .last()
        .unwrap()
        .0;
    operator(&op, &topics, OperatorAction::Checkpoint, 0);
    operator(&op, &topics, OperatorAction::Checkpoint, 1);
    std::thread::sleep(Duration::from_millis(200));
    operator(&op, &topics, OperatorAction::Resume, 0);
    let report = server.join(Duration::from_secs(120)).unwrap();
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(report.last_tick, FRAMES);
    // The pending one (the second request came while the first waited) is refused too: one
    // refusal either way, and one checkpoint, of tick k + 1.
    assert_eq!(report.rejected.operator_refused, 1, "{report}");
    assert_eq!(
        report.checkpoints.map(|c| (c.written, c.failed)),
        Some((1, 0))
    );
    let file = dir.join(format!("sc1-tick{}.ckpt", k + 1));
    assert!(file.exists(), "{} missing", file.display());
    let whole = fsw.recorded();

    let (resumed, header) = checkpoint::read(&file, checkpoint::FRONT_END).unwrap();
    assert_eq!(header.tick, k + 1);
    let resuming = CheckpointSettings {
        resume: Some(resumed),
        source,
        ..CheckpointSettings::default()
    };
    let (report, after) = run(cfg, settings(Handoff::Thread, FRAMES, resuming));
    assert_eq!(report.unwrap().last_tick, FRAMES);
    assert_same_from(&whole, &after, k + 1, "operator checkpoint");
}

#[test]
fn a_checkpoint_of_another_front_end_or_a_damaged_one_is_refused_naming_the_file() {
    // An offline run's checkpoint, from the same configuration.
    let (cfg, source) = acs_full();
    let mut world = flexdyn_vehicle::world::World::of_one(
        "sc1".into(),
        1,
        flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap(),
    );
    world.step_n(50);
    let mut header = flexdyn_vehicle::checkpoint::CheckpointHeader {
        front_end: "simulate".into(),
        tick: 5,
        t_sim_ns: world.t_sim_ns(),
        step_ns: 10_000_000,
        frame_ns: 100_000_000,
        ..Default::default()
    };
    source.into_header(&mut header);
    let bytes = flexdyn_vehicle::checkpoint::save(&header, &mut world).unwrap();
    let file = tmp("offline.ckpt");
    std::fs::write(&file, &bytes).unwrap();
    let e = checkpoint::read(&file, checkpoint::FRONT_END)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("offline.ckpt") && e.contains("`simulate`") && e.contains("`run`"),
        "{e}"
    );

    let mut damaged = bytes.clone();
    let mid = damaged.len() / 2;
    damaged[mid] ^= 1;
    let file = tmp("damaged.ckpt");
    std::fs::write(&file, &damaged).unwrap();
    let e = checkpoint::read(&file, checkpoint::FRONT_END)
        .unwrap_err()
        .to_string();
    assert!(e.contains("damaged.ckpt") && e.contains("SHA-256"), "{e}");

    let e = checkpoint::read(&tmp("missing.ckpt"), checkpoint::FRONT_END)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("missing.ckpt") && e.contains("cannot read"),
        "{e}"
    );
}
