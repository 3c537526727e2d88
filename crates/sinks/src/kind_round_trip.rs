//! Every registered sensor kind through the generic paths above the model: its key, the
//! vehicle's sensor bank and the recording's topic classification and decoder. A test of the
//! sinks layer, since it needs the vehicle (to sample) and the decoder (to read back).

use flexdyn_proto::keys::Topics;
use flexdyn_proto::Header;

use crate::topics::{classify, Decoded, TopicKind};
use flexdyn_sensors::{coarse_sun_sensor, fine_sun_sensor, gps, magnetometer, star_tracker, KINDS};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

/// Every registered kind round-trips through the generic paths: its key classifies back to
/// it, its sensors sit in registry then config order, and what a sensor encodes its kind
/// decodes, with the frame's header (a star tracker's `seq` counting its updates).
#[test]
fn every_kind_round_trips_through_key_bank_and_codec() {
    // Between them, these scenarios have every kind.
    let mut seen = vec![false; KINDS.len()];
    for scenario in ["wheels_star_tracker", "leo_environment"] {
        round_trip(scenario, &mut seen);
    }
    assert!(seen.iter().all(|&s| s), "{seen:?}");
}

fn round_trip(scenario: &str, seen: &mut [bool]) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../scenarios/{scenario}.toml"));
    let cfg = SimConfig::from_file(&path).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    // Tick 20: every 10 Hz sensor is due at it (100 Hz frames), and the 1 Hz GPS receiver
    // with 0.2 s latency publishes there what it measured at tick 0.
    let tick: u64 = 20;
    for k in 0..tick {
        sim.sample_sensors(|s| s.due(k));
        sim.step_frame();
    }
    sim.sample_sensors(|_| true);
    let topics = Topics::new("sc1").unwrap();
    let bank = sim.sensors();
    assert_eq!(bank.sampled().len(), bank.len());
    let kinds: Vec<usize> = bank
        .sensors()
        .iter()
        .map(|s| s.kind().index().unwrap())
        .collect();
    assert!(kinds.windows(2).all(|w| w[0] <= w[1]), "{kinds:?}");
    for &k in &kinds {
        seen[k] = true;
    }
    let mut buf = Vec::new();
    for s in bank.sensors() {
        let kind = s.kind();
        let key = (kind.key)(&topics, s.name()).unwrap();
        assert_eq!(key, format!("flexdyn/sc1/{}/{}", kind.key_prefix, s.name()));
        assert!(kind
            .key_prefix
            .ends_with(&format!("/{}", kind.column_prefix)));
        let topic = classify(&key).unwrap();
        assert_eq!(topic.kind, TopicKind::sensor(kind).unwrap());
        assert_eq!(topic.kind.message_name(), kind.message_name);
        let header = Header::new(1, tick, sim.t_sim_ns(), tick);
        s.encode(header, &mut buf);
        let Decoded::Sensor {
            header: h, json, ..
        } = Decoded::decode(topic.kind, &buf).unwrap()
        else {
            panic!("{key} did not decode as a sensor");
        };
        assert_eq!((h.tick, h.sim_time_ns), (tick, sim.t_sim_ns()));
        let every = |e: Option<u64>| e.unwrap();
        let s = &cfg.sensors;
        let seq = match kind.noun {
            "star tracker" => {
                tick / every(
                    s.of::<star_tracker::StarTrackerConfig>()
                        .next()
                        .map(|c| c.every_frames),
                )
            }
            "magnetometer" => {
                tick / every(
                    s.of::<magnetometer::MagnetometerConfig>()
                        .next()
                        .map(|c| c.every_frames),
                )
            }
            "coarse sun sensor" => {
                tick / every(
                    s.of::<coarse_sun_sensor::CoarseSunSensorConfig>()
                        .next()
                        .map(|c| c.every_frames),
                )
            }
            "GPS receiver" => {
                let g = s.of::<gps::GpsConfig>().next().unwrap();
                (tick - g.latency_frames) / g.every_frames
            }
            "fine sun sensor" => {
                tick / every(
                    s.of::<fine_sun_sensor::FineSunSensorConfig>()
                        .next()
                        .map(|c| c.every_frames),
                )
            }
            _ => tick,
        };
        assert_eq!(h.seq, seq, "{key}");
        // Every field of the message, as the kind's default JSON names them.
        let fields = |v: &serde_json::Value| -> Vec<String> {
            v.as_object().unwrap().keys().cloned().collect()
        };
        assert_eq!(fields(&json), fields(&(kind.default_json)()), "{key}");
    }
}
