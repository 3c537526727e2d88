//! `flexdyn run --record` in lockstep with the demo controller in the loop: the recording holds
//! exactly the stream a participant received (same SHA-256 over the StateMsg payloads, one state
//! per tick), every command each participant sent, decoded channels equal to the raw ones field
//! by field, and the configuration in its metadata.

use flexdyn_testkit::demo_bin;

use std::process::Command;
use std::time::Duration;

use crate::support::{endpoint, reference_config, ChildGuard, Recorder, ServerHandle};
use flexdyn_proto::{decode_command, decode_state, Mode, StateMsg, Topics};
use flexdyn_server::ServerSettings;
use flexdyn_sinks::reader::read_recording;
use sha2::{Digest, Sha256};

const DURATION_S: f64 = 20.0;

fn sha(payloads: &[&[u8]]) -> String {
    let mut h = Sha256::new();
    for p in payloads {
        h.update(p);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn a_lockstep_recording_is_the_stream_the_participants_saw() {
    let file = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("lockstep_record.mcap");
    let _ = std::fs::remove_file(&file);
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        participants: vec![1, 2],
        duration_ns: Some((DURATION_S * 1e9) as u64),
        record: Some(file.clone()),
        ..ServerSettings::default()
    };
    let cfg = reference_config(100.0);
    let config_toml = cfg.source_toml.clone();
    let topics = Topics::new("sc1").unwrap();
    let server = ServerHandle::start(settings, cfg);
    let port = server.port;
    let participant = Recorder::start(port, &topics, 2);
    let _ctrl = ChildGuard::spawn(
        Command::new(demo_bin::acs_demo())
            .args(["--connect", &endpoint(port), "--sender-id", "1"])
            .args(["--rate-source", "truth", "--log-every-s", "0"]),
    );
    let report = server.join(Duration::from_secs(120)).expect("run");
    let recording = report.recording.expect("a recording report");
    assert_eq!(recording.dropped, 0, "lockstep drops nothing");

    let mut seen = participant.states.lock().unwrap().clone();
    seen.sort_by_key(|(t, _)| *t);
    let ticks = report.last_tick;
    assert_eq!(ticks, (DURATION_S * 100.0) as u64);
    assert_eq!(
        seen.len() as u64,
        ticks + 1,
        "the participant saw ticks 0..=N"
    );

    let rec = read_recording(&file).unwrap();
    assert!(rec.truncated.is_none(), "{:?}", rec.truncated);
    let states: Vec<&[u8]> = rec
        .samples
        .iter()
        .filter(|s| s.key == topics.state())
        .map(|s| s.payload.as_slice())
        .collect();
    assert_eq!(
        states.len() as u64,
        ticks + 1,
        "one recorded state per tick"
    );
    let seen_payloads: Vec<&[u8]> = seen.iter().map(|(_, p)| p.as_slice()).collect();
    let (a, b) = (sha(&states), sha(&seen_payloads));
    eprintln!(
        "recorded {} states, sha256 {a}; participant sha256 {b}",
        states.len()
    );
    assert_eq!(
        a, b,
        "the recorded state stream differs from the participant's"
    );

    // Every answer of both participants to ticks 0..N−1 is in the file once, decodable. (An
    // answer to the last state N may land before the server stops listening, or not.)
    let mut answered: [Vec<u64>; 3] = Default::default();
    for s in rec
        .samples
        .iter()
        .filter(|s| s.key == topics.cmd(1) || s.key == topics.cmd(2))
    {
        let cmd = decode_command(&s.payload).unwrap();
        answered[cmd.sender_id as usize].push(cmd.header.tick);
    }
    for sender in [1, 2] {
        let mut t = answered[sender].clone();
        t.retain(|&k| k < ticks);
        assert_eq!(
            t,
            (0..ticks).collect::<Vec<_>>(),
            "sender {sender}'s answers"
        );
    }

    // Decoded channel = raw channel, field by field (the JSON round-trips every f64 exactly).
    let bytes = std::fs::read(&file).unwrap();
    let mut decoded = Vec::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic == format!("/{}", topics.state()) {
            assert_eq!(m.channel.message_encoding, "json");
            let schema = m.channel.schema.as_ref().expect("a schema");
            assert_eq!(
                (schema.name.as_str(), schema.encoding.as_str()),
                ("flexdyn.StateMsg", "jsonschema")
            );
            let s: StateMsg = serde_json::from_slice(&m.data).unwrap();
            assert_eq!(m.log_time, s.header.sim_time_ns);
            decoded.push(s);
        }
    }
    assert_eq!(decoded.len(), states.len());
    for (raw, json) in states.iter().zip(&decoded) {
        assert_eq!(&decode_state(raw).unwrap(), json);
    }

    // The metadata names the configuration that ran.
    let vehicles = rec.vehicles();
    assert_eq!(vehicles.len(), 1);
    assert_eq!(vehicles[0].config_toml, config_toml);
    assert!(vehicles[0].server_settings.contains("mode=lockstep"));
    assert_eq!(rec.metadata["flexdyn.recorder"]["dropped_samples"], "0");
}
