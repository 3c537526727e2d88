//! Faults in fleet mode (issue 21): `server::fleet::run` (what `flexdyn run --fleet` calls, in
//! this process on a loopback port the OS chose) in lockstep with two vehicles of the same
//! spacecraft file (`scenarios/wheels_star_tracker.toml`, same place, same seeds), each with its
//! own `[[faults]]`, and a live fault put on the deputy's key `flexdyn/deputy/fault` for a named
//! tick before the run starts.
//!
//! - chief: fault 0, wheel rw2 seized from 0.8 s (tick 80);
//! - deputy: fault 0, its gyro biased +0.25 rad/s on axis 3 at 0.1 s for 0.05 s (ticks
//!   10–15); fault 1, live, its gyro biased −0.5 rad/s on axis 1 at tick 40 for 10 frames.
//!
//! Each vehicle publishes exactly its own events under its own id with its own spacecraft id,
//! and its StatusMsg its own active set. Nothing acts on the vehicles but the faults (the
//! participants answer `NoCommand`), and a gyro fault does not change the dynamics, so before
//! tick 80 the two IMU streams are identical except where the deputy's faults act, by exactly
//! the bias (a healthy-versus-faulted comparison, sample by sample).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::support::{connecting_session, FleetServerHandle, Recorder};
use flexdyn_proto::{
    decode_fault_event, decode_imu, decode_status, encode, FaultAction, FaultCommandMsg,
    FaultEventMsg, FaultSource, FaultTarget, Header, Mode, RunState, StatusMsg, Topics,
};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::world::FleetConfig;
use zenoh::Wait;

/// \[s\] simulated (100 Hz frames).
const DURATION_S: f64 = 1.0;
const TICKS: u64 = 100;
/// The live fault's tick and length \[frames\].
const K: u64 = 40;
const LEN: u64 = 10;

fn fleet(dir: &Path) -> FleetConfig {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let base = std::fs::read_to_string(root.join("scenarios/wheels_star_tracker.toml")).unwrap();
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join("chief.toml"),
        format!(
            "{base}\n[[faults]]\ntarget = \"reaction_wheels.rw2\"\nmode = \"seized\"\n\
             start_s = 0.8\n"
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("deputy.toml"),
        format!(
            "{base}\n[[faults]]\ntarget = \"imus.hub.gyro\"\nmode = \"bias_step\"\nvalue = 0.25\n\
             axes = [3]\nstart_s = 0.1\nduration_s = 0.05\n"
        ),
    )
    .unwrap();
    let text = r#"
[[vehicles]]
id = "chief"
spacecraft_file = "chief.toml"
participants = [9]

[[vehicles]]
id = "deputy"
spacecraft_file = "deputy.toml"
participants = [9]
"#;
    FleetConfig::from_toml_str_in(text, dir).unwrap()
}

type Heard<T> = Arc<Mutex<Vec<T>>>;

/// Polls `cond` every 10 ms until it holds (`true`) or `timeout` passes (`false`).
fn wait_until(timeout: Duration, cond: impl Fn() -> bool) -> bool {
    let end = std::time::Instant::now() + timeout;
    while !cond() {
        if std::time::Instant::now() >= end {
            return false;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    true
}

/// Subscribes to `key`, keeping what `decode` makes of each sample.
fn listen<T: Send + 'static>(
    session: &zenoh::Session,
    key: String,
    decode: fn(&[u8]) -> Option<T>,
) -> (Heard<T>, zenoh::pubsub::Subscriber<()>) {
    let heard: Heard<T> = Arc::default();
    let h = heard.clone();
    let sub = session
        .declare_subscriber(key)
        .callback(move |s| {
            if let Some(v) = decode(&s.payload().to_bytes()) {
                h.lock().unwrap().push(v);
            }
        })
        .wait()
        .unwrap();
    (heard, sub)
}

#[test]
fn each_vehicle_has_its_own_faults_events_and_live_fault_key() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fleet_faults");
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        participant_timeout: Duration::from_secs(10),
        presence_timeout: Duration::from_secs(30),
        duration_ns: Some((DURATION_S * 1e9) as u64),
        ..ServerSettings::default()
    };
    let server = FleetServerHandle::start(settings, fleet(&dir));
    let port = server.port;
    let (chief, deputy) = (
        Topics::new("chief").unwrap(),
        Topics::new("deputy").unwrap(),
    );
    let session = connecting_session(port);
    let imu = |t: &Topics| format!("flexdyn/{}/tlm/imu/hub", t.sc_id());
    let decode_imu_sample = |b: &[u8]| decode_imu(b).ok();
    let (imu_c, _s1) = listen(&session, imu(&chief), decode_imu_sample);
    let (imu_d, _s2) = listen(&session, imu(&deputy), decode_imu_sample);
    let decode_event = |b: &[u8]| decode_fault_event(b).ok();
    let (ev_c, _s3) = listen(&session, chief.fault_events(), decode_event);
    let (ev_d, _s4) = listen(&session, deputy.fault_events(), decode_event);
    let decode_st = |b: &[u8]| decode_status(b).ok();
    let (st_c, _s5) = listen(&session, chief.status().to_owned(), decode_st);
    let (st_d, _s6) = listen(&session, deputy.status().to_owned(), decode_st);

    // The run waits for the participants; the deputy's status says its endpoints (its fault
    // key among them) are declared. The live fault goes in before the run starts.
    let chief_rec = Recorder::start(port, &chief, 9);
    assert!(wait_until(Duration::from_secs(30), || !st_d
        .lock()
        .unwrap()
        .is_empty()));
    let live = FaultCommandMsg {
        header: Header::new(2, 0, 0, 0),
        action: FaultAction::Inject,
        at_tick: K,
        fault_index: 0,
        mode: 2, // bias_step
        params: [-0.5, 0.0],
        axes: 0b1,
        duration_ns: LEN * 10_000_000,
        seed: 0,
        target: FaultTarget::new("imus.hub.gyro").unwrap(),
    };
    session.put(deputy.fault(), encode(&live)).wait().unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let deputy_rec = Recorder::start(port, &deputy, 9);
    let report = server
        .join(Duration::from_secs(120))
        .expect("the fleet run failed");
    // The last status of each vehicle (published after the run ends).
    assert!(wait_until(Duration::from_secs(10), || [&st_c, &st_d]
        .iter()
        .all(|s| s.lock().unwrap().last().is_some_and(
            |m: &StatusMsg| m.run_state == RunState::Finished
        ))));
    let _ = session.close().wait();
    for (_, r) in &report.vehicles {
        assert_eq!(r.last_tick, TICKS);
        assert_eq!(r.rejected.total(), 0, "{r}");
    }
    assert!(chief_rec.wait_for_tick(TICKS, Duration::from_secs(1)));
    assert!(deputy_rec.wait_for_tick(TICKS, Duration::from_secs(1)));

    // Events: each vehicle's own, under its own id and spacecraft id.
    let summary = |ev: &[FaultEventMsg]| -> Vec<(u32, u64, u32, bool, FaultSource, String, u64)> {
        ev.iter()
            .map(|e| {
                (
                    e.header.spacecraft_id,
                    e.header.tick,
                    e.fault_index,
                    e.active,
                    e.source,
                    e.target.as_str().unwrap().to_owned(),
                    e.edge_ns,
                )
            })
            .collect()
    };
    let (gyro, wheel) = ("imus.hub.gyro".to_owned(), "reaction_wheels.rw2".to_owned());
    assert_eq!(
        summary(&ev_c.lock().unwrap()),
        [(1, 80, 0, true, FaultSource::Config, wheel, 800_000_000)]
    );
    assert_eq!(
        summary(&ev_d.lock().unwrap()),
        [
            (
                2,
                10,
                0,
                true,
                FaultSource::Config,
                gyro.clone(),
                100_000_000
            ),
            (
                2,
                15,
                0,
                false,
                FaultSource::Config,
                gyro.clone(),
                150_000_000
            ),
            (
                2,
                K,
                1,
                true,
                FaultSource::Live,
                gyro.clone(),
                K * 10_000_000
            ),
            (
                2,
                K + LEN,
                1,
                false,
                FaultSource::Live,
                gyro,
                (K + LEN) * 10_000_000
            ),
        ]
    );
    // The active sets at the end: the chief's wheel (fault 0); none of the deputy's.
    let last = |s: &Heard<StatusMsg>| *s.lock().unwrap().last().unwrap();
    let (c, d) = (last(&st_c), last(&st_d));
    assert_eq!((c.faults_active, c.faults_active_bits), (1, [1, 0, 0, 0]));
    assert_eq!((d.faults_active, d.faults_active_bits), (0, [0; 4]));

    // The gyro samples: before the chief's wheel seizes, the deputy's equal the chief's but
    // for its two biases, each exactly on its axis and ticks.
    let by_tick = |h: &Heard<flexdyn_proto::ImuMsg>| -> BTreeMap<u64, [f64; 3]> {
        h.lock()
            .unwrap()
            .iter()
            .map(|m| (m.header.tick, m.omega_p_rad_s))
            .collect()
    };
    let (wc, wd) = (by_tick(&imu_c), by_tick(&imu_d));
    let mut compared = 0;
    for k in 0..80 {
        let (Some(c), Some(d)) = (wc.get(&k), wd.get(&k)) else {
            continue;
        };
        let mut want = *c;
        if (10..15).contains(&k) {
            want[2] += 0.25;
        }
        if (K..K + LEN).contains(&k) {
            want[0] += -0.5;
        }
        assert_eq!(*d, want, "tick {k}: deputy {d:?}, chief {c:?}");
        compared += 1;
    }
    assert_eq!(compared, 80, "IMU samples missing");
}
