//! Fleet mode in real time: the frames are paced on the wall clock for every vehicle at once,
//! and each vehicle's StatusMsg and run report carry the frame boundaries' lateness (p50, p99,
//! maximum), as a one-vehicle server's do.
//!
//! The fleet has one boundary per frame, so one lateness per frame: every vehicle's telemetry
//! thread reads the same values from the physics thread, and the vehicles' figures are equal.
//! Each vehicle's last StatusMsg is published after its telemetry thread has read the last
//! value, so it equals that vehicle's report exactly.

use crate::server_support;

use std::path::PathBuf;
use std::time::Duration;

use flexdyn_proto::{Mode, Topics};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::world::FleetConfig;
use server_support::{wait_until, FleetServerHandle, Observer};

/// Two reference spacecraft (100 Hz frames), the deputy 100 m behind the chief.
fn fleet() -> FleetConfig {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let reference = root.join("scenarios/reference.toml");
    let text = format!(
        "[[vehicles]]\nid = \"chief\"\nspacecraft_file = {reference:?}\nparticipants = [9]\n\
         [[vehicles]]\nid = \"deputy\"\nspacecraft_file = {reference:?}\nparticipants = [9]\n\
         [vehicles.relative]\nchief = \"chief\"\nhill_position_m = [0.0, -100.0, 0.0]\n"
    );
    FleetConfig::from_toml_str_in(&text, &root).unwrap()
}

#[test]
fn a_real_time_fleet_is_paced_and_every_status_carries_the_frame_lateness() {
    const SECONDS: u64 = 2;
    let settings = ServerSettings {
        mode: Mode::RealTime,
        duration_ns: Some(SECONDS * 1_000_000_000),
        ..ServerSettings::default()
    };
    let server = FleetServerHandle::start(settings, fleet());
    let observers: Vec<(String, Observer)> = ["chief", "deputy"]
        .into_iter()
        .map(|id| {
            let topics = Topics::new(id).unwrap();
            (id.to_owned(), Observer::start(server.port, &topics))
        })
        .collect();
    let report = server
        .join(Duration::from_secs(30))
        .expect("the fleet run ends");
    let vehicles = &report.vehicles;
    assert_eq!(vehicles.len(), 2);

    // Paced on the wall clock: 2 s of 100 Hz frames, ticks 0..=200, take at least 2 s.
    for (id, r) in vehicles {
        assert_eq!(r.last_tick, 200, "{id}");
        assert!(r.wall_s >= 1.99, "{id}: {} s for 2 s of frames", r.wall_s);
    }

    // Every frame's lateness was recorded for every vehicle: a late boundary is late by more
    // than 0 ns, the quantiles are ordered, and the two vehicles saw the same values.
    let (_, first) = &vehicles[0];
    let t = first.timing;
    assert!(t.lateness_max_ns > 0, "no lateness recorded: {t:?}");
    assert!(
        t.lateness_p50_ns <= t.lateness_p99_ns && t.lateness_p99_ns <= t.lateness_max_ns,
        "{t:?}"
    );
    for (id, r) in vehicles {
        assert_eq!(
            (
                r.timing.lateness_p50_ns,
                r.timing.lateness_p99_ns,
                r.timing.lateness_max_ns
            ),
            (t.lateness_p50_ns, t.lateness_p99_ns, t.lateness_max_ns),
            "{id}: the vehicles share one frame boundary"
        );
    }

    // Each vehicle's last StatusMsg says what its report says.
    for ((id, obs), (rid, r)) in observers.iter().zip(vehicles) {
        assert_eq!(id, rid);
        let matches = || {
            obs.last_status().is_some_and(|s| {
                (
                    s.timing.lateness_p50_ns,
                    s.timing.lateness_p99_ns,
                    s.timing.lateness_max_ns,
                ) == (
                    r.timing.lateness_p50_ns,
                    r.timing.lateness_p99_ns,
                    r.timing.lateness_max_ns,
                )
            })
        };
        assert!(
            wait_until(Duration::from_secs(5), matches),
            "{id}: last status {:?}, report {:?}",
            obs.last_status().map(|s| s.timing),
            r.timing
        );
    }
}
