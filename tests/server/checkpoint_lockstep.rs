//! Server checkpoints (issue 40 §2) on a real lockstep server: a run that saves a checkpoint at
//! tick k goes on unchanged, and a new server resumed from that file publishes, from tick k on,
//! every telemetry sample of the uninterrupted run bit for bit, whichever thread steps its
//! frames (`handoff = "direct"` or `"thread"`). The flight code is a stateless rate-and-attitude
//! controller living in the test, so its commands depend on the state it is sent alone, and the
//! resumed server's command book must hold what the first one held for the stream to match.
//! A checkpoint another front end wrote, or a damaged one, is refused with the file's name.

use crate::server_support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn_proto::{decode_header, decode_state, encode, CommandMsg, Header, Mode, Topics};
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
    fn start(port: u16, topics: &Topics) -> Self {
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
            .declare_publisher(topics.cmd(1))
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
                    1,
                    torque_b_nm,
                    [0.0; 3],
                );
                publisher.put(encode(&cmd)).wait().unwrap();
            })
            .wait()
            .unwrap();
        let token = session
            .liveliness()
            .declare_token(topics.participant(1))
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

#[test]
fn a_resumed_lockstep_server_publishes_the_uninterrupted_stream_bit_for_bit() {
    const FRAMES: u64 = 160;
    const AT: u64 = 70;
    let (cfg, source) = acs_full();
    let file = tmp("acs_full_70.ckpt");
    let saving = CheckpointSettings {
        save_at: Some((AT, file.clone())),
        source: source.clone(),
        ..CheckpointSettings::default()
    };
    let (report, whole) = run(cfg.clone(), settings(Handoff::Direct, FRAMES, saving));
    let report = report.unwrap();
    assert_eq!(report.last_tick, FRAMES);
    let saved = report.checkpoints.expect("this run saves checkpoints");
    assert_eq!((saved.written, saved.failed), (1, 0), "{report}");
    assert!(file.exists());
    // The state, the time, every sensor and the environment, each from tick 0.
    assert!(whole.len() >= 6, "keys: {:?}", whole.keys());
    for (key, v) in &whole {
        assert_eq!(v.first().map(|s| s.0), Some(0), "{key}");
    }

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
        // Nothing before the checkpoint's tick was published.
        for (key, v) in &after {
            assert_eq!(v.first().map(|s| s.0), Some(AT), "{handoff:?}: {key}");
        }
        let expected = later(&whole, AT);
        assert_eq!(
            after.keys().collect::<Vec<_>>(),
            expected.keys().collect::<Vec<_>>()
        );
        for (key, v) in &expected {
            let got = &after[key];
            assert_eq!(got.len(), v.len(), "{handoff:?}: {key}: samples");
            if let Some(i) = (0..v.len()).find(|&i| got[i] != v[i]) {
                panic!(
                    "{handoff:?}: {key}: the sample of tick {} differs from the uninterrupted run's",
                    v[i].0
                );
            }
        }
    }
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
