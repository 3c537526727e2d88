//! The time service (`flexdyn/<sc>/tlm/time`) of a real server: published every frame before the
//! frame's sensors and state, consistent with itself, leap-second aware, and paced by `--speed`.
//!
//! The calendar expectations are derived by hand in `crates/server/src/clock.rs` and
//! `proto/README.md` ("TimeMsg"); here they are checked on the stream a real run publishes.

use crate::server_support;

use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn_proto::{decode_header, decode_time, time_flags, Mode, RunState, TimeMsg, Topics};
use flexdyn_server::{self as server, ServerSettings};
use flexdyn_vehicle::config::SimConfig;
use server_support::{
    connecting_session, listening_session, reference_config, wait_for_subscriber, wait_until,
    ServerHandle,
};
use zenoh::Wait;

const S: u64 = 1_000_000_000;
/// \[s\] TAI − 19 s − 8,040 days (1958-01-01 … 1980-01-06): the GPS epoch in TAI since 1958.
const GPS_EPOCH_TAI_1958_NS: u64 = (8_040 * 86_400 + 19) * S;

/// The reference spacecraft at `frame_hz` with `epoch_utc` as its `[epoch]`.
fn config_with_epoch(frame_hz: f64, epoch_utc: Option<&str>) -> SimConfig {
    let mut text = reference_config(frame_hz).source_toml.clone();
    if let Some(e) = epoch_utc {
        text.push_str(&format!("\n[epoch]\nutc = \"{e}\"\n"));
    }
    SimConfig::from_toml_str(&text).unwrap()
}

/// Every sample under `flexdyn/<sc>/tlm/**` in arrival order: its key, its header tick, the
/// decoded time message (for `tlm/time`) and the frame-boundary stamp.
type Sample = (String, u64, Option<TimeMsg>, Option<u64>);

fn run_and_collect(settings: ServerSettings, cfg: SimConfig) -> Vec<Sample> {
    let topics = Topics::new(&settings.sc_id).unwrap();
    // Subscribed before the run starts: the tests expect every tick from 0.
    let (server_session, port) = listening_session();
    let session = connecting_session(port);
    let seen: Arc<Mutex<Vec<Sample>>> = Arc::default();
    let s = seen.clone();
    let time_key = topics.time();
    let time_key_probe = time_key.clone();
    let _sub = session
        .declare_subscriber(topics.telemetry_wildcard())
        .callback(move |sample| {
            let key = sample.key_expr().as_str().to_owned();
            let bytes = sample.payload().to_bytes();
            let tick = decode_header(&bytes).map(|h| h.tick).unwrap_or(u64::MAX);
            let time = (key == time_key).then(|| decode_time(&bytes).expect("a TimeMsg"));
            let stamp = server::frame_stamp_ns(&sample);
            s.lock().unwrap().push((key, tick, time, stamp));
        })
        .wait()
        .unwrap();
    wait_for_subscriber(&server_session, &time_key_probe);
    let mut server = ServerHandle::start_with_session(server_session, settings, cfg);
    let report = server.join(Duration::from_secs(60));
    server.stop();
    report.expect("the run ends normally");
    // The last samples may still be in flight.
    wait_until(Duration::from_secs(2), || false);
    let out = seen.lock().unwrap().clone();
    out
}

fn times(samples: &[Sample]) -> Vec<(TimeMsg, u64)> {
    samples
        .iter()
        .filter_map(|(_, _, t, stamp)| Some(((*t)?, stamp.expect("frame stamp"))))
        .collect()
}

/// The fields of one message agree with each other (and with the run's constants).
fn assert_consistent(m: &TimeMsg, frame_ns: u64, tai0_ns: u64) {
    let t = m.header.sim_time_ns;
    assert_eq!(t, m.header.tick * frame_ns, "tick · frame_ns");
    assert_eq!(
        (m.header.seq, m.met_ns, m.frame_ns),
        (m.header.tick, t, frame_ns)
    );
    assert_eq!(m.tai_ns_1958, tai0_ns + t, "TAI runs with simulation time");
    // GPS = TAI − 19 s from 1980-01-06.
    assert_eq!(
        u64::from(m.gps_week) * 604_800 * S + m.gps_ns_of_week,
        m.tai_ns_1958 - GPS_EPOCH_TAI_1958_NS
    );
    // UTC = TAI − ΔAT: the time of day, or 23:59:60.x in a leap second.
    let utc_s = m.tai_ns_1958 / S - u64::try_from(m.tai_minus_utc_s).unwrap();
    let u = m.utc;
    let tod = u64::from(u.hour) * 3600 + u64::from(u.minute) * 60 + u64::from(u.second);
    if m.flags & time_flags::LEAP_SECOND != 0 {
        assert_eq!((u.hour, u.minute, u.second), (23, 59, 60));
        // ΔAT is still the old value inside the leap second, so TAI − ΔAT already counts the
        // next day's 00:00:00 (the inserted second is the one UTC's count cannot show).
        assert_eq!(utc_s % 86_400, 0, "the second after 23:59:59");
    } else {
        assert_eq!(utc_s % 86_400, tod);
    }
    assert_eq!(u64::from(u.nanosecond), m.tai_ns_1958 % S);
    // CUC: P-field, then the TAI seconds and 2⁻²⁴ s, big-endian.
    let c = m.cuc_tai;
    assert_eq!(c[0], 0x1F);
    assert_eq!(
        u64::from(u32::from_be_bytes([c[1], c[2], c[3], c[4]])),
        m.tai_ns_1958 / S
    );
    let fine = u64::from(u32::from_be_bytes([0, c[5], c[6], c[7]]));
    assert_eq!(fine, ((m.tai_ns_1958 % S) << 24) / S);
    // The time at the tone is the last whole TAI second of the run (none, zero, before the
    // first), and the tone flag marks crossing it.
    let last_whole_ns = m.tai_ns_1958 / S * S;
    let tone_s = if last_whole_ns >= tai0_ns {
        m.tai_ns_1958 / S
    } else {
        0
    };
    assert_eq!(u64::from(m.tone_tai.seconds), tone_s, "tone_tai");
    let crossed = m.header.tick > 0 && (m.tai_ns_1958 - frame_ns) / S < m.tai_ns_1958 / S;
    assert_eq!(
        m.flags & time_flags::TONE != 0,
        crossed,
        "tone at tick {}",
        m.header.tick
    );
}

fn realtime(speed: f64, duration_s: f64) -> ServerSettings {
    ServerSettings {
        mode: Mode::RealTime,
        duration_ns: Some((duration_s * 1e9) as u64),
        speed,
        status_hz: 5.0,
        ..ServerSettings::default()
    }
}

/// \[ns\] the largest deviation of the wall-clock stamps from `t_sim / speed` (both from the
/// first message).
fn pacing_error_ns(ts: &[(TimeMsg, u64)], speed: f64) -> f64 {
    let (m0, w0) = ts[0];
    ts.iter()
        .map(|(m, w)| {
            let sim = (m.header.sim_time_ns - m0.header.sim_time_ns) as f64;
            let wall = (w - w0) as f64;
            (sim / speed - wall).abs()
        })
        .fold(0.0, f64::max)
}

/// `--speed 2` across the 2016 leap second: sim time runs at twice wall time within one (wall)
/// frame period, every message is consistent, and the UTC field reads 23:59:59 → 23:59:60 →
/// 00:00:00 with ΔAT 36 → 37.
#[test]
fn speed_2_across_a_leap_second() {
    let frame_hz = 10.0;
    let frame_ns = 100_000_000;
    let cfg = config_with_epoch(frame_hz, Some("2016-12-31T23:59:58.5Z"));
    let samples = run_and_collect(realtime(2.0, 4.0), cfg);
    let ts = times(&samples);
    let ticks: Vec<u64> = ts.iter().map(|(m, _)| m.header.tick).collect();
    assert_eq!(
        ticks,
        (0..=40).collect::<Vec<_>>(),
        "one time message per tick"
    );
    // 2016-12-31T23:59:58.5 UTC = 2017-01-01T00:00:34.5 TAI = 21,550 days − 1.5 s + 36 s.
    let tai0 = (21_550 * 86_400 + 34) * S + S / 2;
    for (m, _) in &ts {
        assert_consistent(m, frame_ns, tai0);
        assert_eq!(
            (m.run_state, m.mode, m.speed),
            (RunState::Running, Mode::RealTime, 2.0)
        );
        assert_ne!(m.flags & time_flags::EPOCH_VALID, 0);
    }
    let at = |tick: usize| {
        let u = ts[tick].0.utc;
        (
            (
                u.year,
                u.month,
                u.day,
                u.hour,
                u.minute,
                u.second,
                u.nanosecond,
            ),
            ts[tick].0.tai_minus_utc_s,
        )
    };
    assert_eq!(at(0), ((2016, 12, 31, 23, 59, 58, 500_000_000), 36));
    assert_eq!(at(15), ((2016, 12, 31, 23, 59, 60, 0), 36));
    assert_eq!(at(24), ((2016, 12, 31, 23, 59, 60, 900_000_000), 36));
    assert_eq!(at(25), ((2017, 1, 1, 0, 0, 0, 0), 37));
    let wall_period_ns = frame_ns as f64 / 2.0;
    let err = pacing_error_ns(&ts, 2.0);
    assert!(
        err < wall_period_ns,
        "sim time at 2× wall time: off by {:.1} ms (a wall frame is {:.1} ms)",
        err * 1e-6,
        wall_period_ns * 1e-6
    );
    // Published first: in arrival order the time message of a tick precedes its other samples.
    let mut first_of_tick = std::collections::BTreeMap::new();
    for (key, tick, _, _) in &samples {
        first_of_tick.entry(*tick).or_insert(key.clone());
    }
    assert!(first_of_tick.values().all(|k| k.ends_with("/tlm/time")));
}

/// `--speed 0.5` without an epoch: half wall speed within a frame period; calendar fields zero.
#[test]
fn speed_half_without_an_epoch() {
    let frame_ns = 100_000_000;
    let samples = run_and_collect(realtime(0.5, 1.0), config_with_epoch(10.0, None));
    let ts = times(&samples);
    assert_eq!(ts.len(), 11);
    for (m, _) in &ts {
        assert_eq!(m.flags & time_flags::EPOCH_VALID, 0);
        assert_eq!((m.tai_ns_1958, m.cuc_tai, m.gps_week), (0, [0; 8], 0));
        assert_eq!(m.met_ns, m.header.sim_time_ns);
        assert_eq!(m.speed, 0.5);
    }
    let tones: Vec<u64> = ts
        .iter()
        .filter(|(m, _)| m.flags & time_flags::TONE != 0)
        .map(|(m, _)| m.header.tick)
        .collect();
    assert_eq!(tones, [0, 10], "whole simulation seconds");
    let wall_period_ns = frame_ns as f64 / 0.5;
    let err = pacing_error_ns(&ts, 0.5);
    assert!(
        err < wall_period_ns,
        "sim time at 0.5× wall time: off by {:.1} ms",
        err * 1e-6
    );
    // And it really is slower than real time: 1 s of simulation took about 2 s.
    let wall_s = (ts[10].1 - ts[0].1) as f64 * 1e-9;
    assert!(
        (wall_s - 2.0).abs() < 0.2,
        "1 s simulated in {wall_s} s of wall time"
    );
}
