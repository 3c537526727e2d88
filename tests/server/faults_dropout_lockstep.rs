//! A `dropout` fault in lockstep does not stall the flight code's wait for its tick: the server
//! publishes nothing from the IMU in dropout (ticks 10 to 19 here), and the client's
//! [`TickReceiver`] learns so from the fault events (`flexdyn/<sc>/tlm/fault`) instead of
//! waiting out its sensor time limit. The limit is set to an hour, so the run can only reach its
//! last tick if each withheld sample is known as withheld; each tick of the window is handed out
//! with `imu/hub` missing, every other one complete.

use crate::server_support;

use std::time::Duration;

use flexdyn_proto::client::lockstep::{SensorSchedule, TickReceiver};
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_proto::{encode, CommandMsg, Header, Mode, Topics};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::config::SimConfig;
use server_support::{connecting_session, ServerHandle};
use zenoh::Wait;

const WHEELS: &str = include_str!("../../scenarios/wheels_star_tracker.toml");
const TICKS: u64 = 40;
/// \[ns\] the frame period of the configuration (100 Hz).
const FRAME_NS: u64 = 10_000_000;
/// The ticks whose IMU sample the dropout withholds: start_s = 0.1, duration_s = 0.1.
const DROPPED: std::ops::Range<u64> = 10..20;

#[test]
fn a_dropout_in_lockstep_releases_each_tick_without_waiting() {
    let text = format!(
        "{WHEELS}\n[[faults]]\ntarget = \"imus.hub\"\nmode = \"dropout\"\nstart_s = 0.1\n\
         duration_s = 0.1\n"
    );
    let topics = Topics::new("sc1").unwrap();
    let server = ServerHandle::start(
        ServerSettings {
            mode: Mode::Lockstep,
            duration_ns: Some(TICKS * FRAME_NS),
            participant_timeout: Duration::from_secs(20),
            ..ServerSettings::default()
        },
        SimConfig::from_toml_str(&text).unwrap(),
    );
    let schedule = SensorSchedule::from_config(&VehicleConfig::from_toml(&text).unwrap()).unwrap();
    let session = connecting_session(server.port);
    let mut ticks =
        TickReceiver::declare(&session, &topics, schedule, 256, Duration::from_secs(3600)).unwrap();
    let commands = session.declare_publisher(topics.cmd(1)).wait().unwrap();
    let _token = session
        .liveliness()
        .declare_token(topics.participant(1))
        .wait()
        .unwrap();
    let mut seen = Vec::new();
    loop {
        let t = ticks
            .recv_timeout(Duration::from_secs(30))
            .unwrap()
            .expect("each tick within 30 s (the sensor time limit is an hour)");
        let k = t.tick();
        seen.push((k, t.missing.clone()));
        let h = Header::new(1, k, t.state.header.sim_time_ns, k);
        commands
            .put(encode(&CommandMsg::no_command(h, 1)))
            .wait()
            .unwrap();
        if k == TICKS {
            break;
        }
    }
    let report = server.join(Duration::from_secs(30)).expect("the run");
    assert_eq!(report.last_tick, TICKS);
    let want: Vec<(u64, Vec<String>)> = (0..=TICKS)
        .map(|k| {
            let missing = if DROPPED.contains(&k) {
                vec!["imu/hub".to_owned()]
            } else {
                vec![]
            };
            (k, missing)
        })
        .collect();
    assert_eq!(seen, want);
    assert_eq!(ticks.incomplete, DROPPED.end - DROPPED.start);
}
