//! A [`TickReceiver`] with a [`TickHandler`] (`declare_with_handler`): each complete tick is
//! answered where it completes, on the Zenoh thread that delivered its last sample, in tick
//! order and once; a tick held for a sample that never comes is released after the sensor time
//! limit by `recv_timeout`, on the caller's thread, to the same handler.

use crate::server_support;

use std::collections::HashSet;
use std::sync::{Arc, Mutex};
use std::thread::ThreadId;
use std::time::{Duration, Instant};

use flexdyn_proto::client::lockstep::{SensorSchedule, Tick, TickHandler, TickReceiver};
use flexdyn_proto::client::participant::Participant;
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_proto::{CommandMsg, Header, Mode, Topics};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::config::SimConfig;
use server_support::{connecting_session, ServerHandle};

const WHEELS: &str = include_str!("../../scenarios/wheels_star_tracker.toml");
/// \[ns\] the frame period of the configuration (100 Hz).
const FRAME_NS: u64 = 10_000_000;

/// Answers each tick with no command, and notes the tick, what it lacked and the thread.
struct Answer {
    /// The command publisher and the token, declared after the receiver (as a participant
    /// must, so it cannot miss tick 0); the server sends no tick before the token.
    participant: Option<Participant>,
    buf: Vec<u8>,
    seen: Vec<(u64, Vec<String>)>,
    /// The tick of each tick's time message (`None`: it carried none).
    timed: Vec<Option<u64>>,
    /// When each tick was handled.
    at: Vec<Instant>,
    threads: HashSet<ThreadId>,
}

impl TickHandler for Answer {
    fn on_tick(&mut self, tick: Tick) {
        let k = tick.tick();
        self.seen.push((k, tick.missing.clone()));
        self.timed.push(tick.time.map(|t| t.header.tick));
        self.at.push(Instant::now());
        self.threads.insert(std::thread::current().id());
        let h = Header::new(1, k, tick.state.header.sim_time_ns, k);
        self.participant
            .as_ref()
            .expect("no tick before the token")
            .send(&CommandMsg::no_command(h, 1), &mut self.buf)
            .unwrap();
    }
}

/// A lockstep run of `ticks` frames of `server_toml`, answered by an [`Answer`] whose receiver
/// follows the schedule of `client_toml` (without the time message unless `time`) with
/// `sensor_timeout`; the main thread keeps calling
/// `recv_timeout` until the last tick is answered. Returns the handler and the receiver's count
/// of incomplete ticks.
fn run(
    server_toml: &str,
    client_toml: &str,
    ticks: u64,
    sensor_timeout: Duration,
    time: bool,
) -> (Answer, u64) {
    let topics = Topics::new("sc1").unwrap();
    let server = ServerHandle::start(
        ServerSettings {
            mode: Mode::Lockstep,
            duration_ns: Some(ticks * FRAME_NS),
            participant_timeout: Duration::from_secs(20),
            ..ServerSettings::default()
        },
        SimConfig::from_toml_str(server_toml).unwrap(),
    );
    let schedule =
        SensorSchedule::from_config(&VehicleConfig::from_toml(client_toml).unwrap()).unwrap();
    let schedule = if time {
        schedule
    } else {
        schedule.without_time()
    };
    let session = connecting_session(server.port);
    let answer = Arc::new(Mutex::new(Answer {
        participant: None,
        buf: Vec::new(),
        seen: Vec::new(),
        timed: Vec::new(),
        at: Vec::new(),
        threads: HashSet::new(),
    }));
    let mut receiver = TickReceiver::declare_with_handler(
        &session,
        &topics,
        schedule,
        sensor_timeout,
        answer.clone(),
    )
    .unwrap();
    // Under the handler's lock: tick 0 can come as soon as the token exists.
    {
        let mut a = answer.lock().unwrap();
        a.participant = Some(Participant::declare(&session, &topics, 1).unwrap());
    }
    let give_up = Instant::now() + Duration::from_secs(60);
    while answer.lock().unwrap().seen.last().map(|s| s.0) != Some(ticks) {
        assert!(
            Instant::now() < give_up,
            "the last tick was not answered within 60 s"
        );
        let none = receiver.recv_timeout(Duration::from_millis(20)).unwrap();
        assert!(
            none.is_none(),
            "a receiver with a handler hands out no tick"
        );
    }
    let report = server.join(Duration::from_secs(30)).expect("the run");
    assert_eq!(report.last_tick, ticks);
    let incomplete = receiver.incomplete;
    drop(receiver);
    let answer = Arc::try_unwrap(answer).ok().unwrap().into_inner().unwrap();
    (answer, incomplete)
}

/// The IMU dropout of `faults_dropout_lockstep` (ticks 10 to 19 withheld): every tick is
/// answered once, in order, on a thread other than the caller's, the withheld ones without
/// `imu/hub` (released by the fault events, not the hour-long time limit), and each with its
/// own time message. The receiver takes the state, the IMU, the star tracker, the time message
/// and the fault events through one subscriber each, so this shows that they reach its
/// assembler in the server's publication order: a time message after its state would leave
/// its tick without one, a fault event after the next state would hold a tick for an hour.
#[test]
fn a_handler_answers_each_tick_where_it_completes() {
    let text = format!(
        "{WHEELS}\n[[faults]]\ntarget = \"imus.hub\"\nmode = \"dropout\"\nstart_s = 0.1\n\
         duration_s = 0.1\n"
    );
    let ticks = 40;
    let (answer, incomplete) = run(&text, &text, ticks, Duration::from_secs(3600), true);
    let want: Vec<(u64, Vec<String>)> = (0..=ticks)
        .map(|k| {
            let missing = if (10..20).contains(&k) {
                vec!["imu/hub".to_owned()]
            } else {
                vec![]
            };
            (k, missing)
        })
        .collect();
    assert_eq!(answer.seen, want);
    assert_eq!(answer.timed, (0..=ticks).map(Some).collect::<Vec<_>>());
    assert_eq!(incomplete, 10);
    assert!(
        !answer.threads.contains(&std::thread::current().id()),
        "a tick was answered on the caller's thread"
    );
}

/// The client expects an IMU `ghost` the server does not have, so no tick completes: each is
/// released after the 100 ms sensor limit by `recv_timeout`, on the caller's thread, and
/// reaches the handler in order with `imu/ghost` missing. The server publishes tick k + 1 only
/// once tick k is answered, so consecutive answers are at least the limit apart.
#[test]
fn a_tick_released_after_the_sensor_limit_goes_to_the_handler() {
    let hub = WHEELS
        .find("\n[[imus]]\n")
        .expect("the scenario has an [[imus]] table");
    let rest = &WHEELS[hub + 1..];
    let end = rest[1..]
        .find("\n[[")
        .map_or(rest.len(), |i| i + 2)
        .min(rest.len());
    let ghost = rest[..end].replacen("name = \"hub\"", "name = \"ghost\"", 1);
    let client = format!("{WHEELS}\n{ghost}");
    let ticks = 4;
    let (answer, incomplete) = run(WHEELS, &client, ticks, Duration::from_millis(100), true);
    let want: Vec<(u64, Vec<String>)> = (0..=ticks)
        .map(|k| (k, vec!["imu/ghost".to_owned()]))
        .collect();
    assert_eq!(answer.seen, want);
    assert_eq!(incomplete, ticks + 1);
    let gaps: Vec<Duration> = answer.at.windows(2).map(|p| p[1] - p[0]).collect();
    eprintln!("sensor limit 100 ms: answers {gaps:?} apart");
    for (k, pair) in answer.at.windows(2).enumerate() {
        let gap = pair[1] - pair[0];
        assert!(
            gap >= Duration::from_millis(100),
            "tick {} was answered {gap:?} after tick {k}, within the sensor limit",
            k + 1
        );
    }
    assert_eq!(
        answer.threads,
        HashSet::from([std::thread::current().id()]),
        "the released ticks are answered by recv_timeout's caller"
    );
}

/// A schedule without the time message: every tick still comes complete and in order, without
/// one (the receiver never subscribed to it).
#[test]
fn a_schedule_without_time_answers_every_tick_without_it() {
    let ticks = 20;
    let (answer, incomplete) = run(WHEELS, WHEELS, ticks, Duration::from_secs(3600), false);
    let want: Vec<(u64, Vec<String>)> = (0..=ticks).map(|k| (k, vec![])).collect();
    assert_eq!(answer.seen, want);
    assert_eq!(answer.timed, vec![None; ticks as usize + 1]);
    assert_eq!(incomplete, 0);
}
