//! Fault events in a recording (issue 21, protocol 8): `flexdyn run --mode batch --record` of
//! the wheel scenario with a repeating gyro fault and a wheel fault from the configuration. An
//! independent MCAP reader (the `mcap` crate's message stream, not flexdyn's reader) finds the
//! raw channel `flexdyn/sc1/tlm/fault` and its decoded twin `/flexdyn/sc1/tlm/fault` (JSON,
//! schema `flexdyn.FaultEventMsg`); the JSON, read as plain JSON, carries the events the
//! configuration implies, and equals the raw payloads decoded, field by field.

use crate::py_support;
use flexdyn_testkit::ports;

use std::path::Path;
use std::process::Command;

use flexdyn_proto::decode_fault_event;

/// \[ns\] the scenario's frame (100 Hz).
const FRAME_NS: u64 = 10_000_000;

#[test]
fn fault_events_are_recorded_raw_and_decoded() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("recording_faults");
    std::fs::create_dir_all(&dir).unwrap();
    let (config, file) = (dir.join("faults.toml"), dir.join("faults.mcap"));
    let _ = std::fs::remove_file(&file);
    // Fault 0: a gyro bias on at 0.1 s for 0.05 s, every 0.2 s (ticks 10–15, 30–35, 50–55…);
    // fault 1: wheel rw2 seized from 0.25 s to the end (tick 25).
    let scenario = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wheels_star_tracker.toml"),
    )
    .unwrap();
    std::fs::write(
        &config,
        format!(
            "{scenario}
[[faults]]
target = \"imus.hub.gyro\"
mode = \"bias_step\"
value = 0.25
axes = [3]
start_s = 0.1
duration_s = 0.05
period_s = 0.2

[[faults]]
target = \"reaction_wheels.rw2\"
mode = \"seized\"
start_s = 0.25
"
        ),
    )
    .unwrap();
    py_support::run(
        Command::new(env!("CARGO_BIN_EXE_flexdyn"))
            .args(["run", "--mode", "batch", "--duration-s", "0.6"])
            .args(["--listen", ports::ANY_PORT])
            .arg("--config")
            .arg(&config)
            .arg("--record")
            .arg(&file),
        "flexdyn run --mode batch --record",
    );

    let bytes = std::fs::read(&file).unwrap();
    let (mut raw, mut json) = (Vec::new(), Vec::new());
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let schema = m.channel.schema.as_ref().map(|s| s.name.clone());
        if m.channel.topic == "flexdyn/sc1/tlm/fault" {
            assert_eq!(m.channel.message_encoding, "flexdyn-proto");
            assert_eq!(schema.as_deref(), Some("flexdyn.FaultEventMsg"));
            raw.push(m.data.to_vec());
        } else if m.channel.topic == "/flexdyn/sc1/tlm/fault" {
            assert_eq!(m.channel.message_encoding, "json");
            let s = m.channel.schema.as_ref().unwrap();
            assert_eq!(
                (s.name.as_str(), s.encoding.as_str()),
                ("flexdyn.FaultEventMsg", "jsonschema")
            );
            let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            assert_eq!(m.log_time, v["header"]["sim_time_ns"].as_u64().unwrap());
            json.push(v);
        }
    }
    // What the configuration implies, in publication order (by tick, then fault index).
    let expected: Vec<(u64, u64, bool, &str, u64)> = vec![
        (10, 0, true, "imus.hub.gyro", 10),
        (15, 0, false, "imus.hub.gyro", 15),
        (25, 1, true, "reaction_wheels.rw2", 25),
        (30, 0, true, "imus.hub.gyro", 30),
        (35, 0, false, "imus.hub.gyro", 35),
        (50, 0, true, "imus.hub.gyro", 50),
        (55, 0, false, "imus.hub.gyro", 55),
    ];
    let got: Vec<(u64, u64, bool, &str, u64)> = json
        .iter()
        .map(|v| {
            (
                v["header"]["tick"].as_u64().unwrap(),
                v["fault_index"].as_u64().unwrap(),
                v["active"].as_bool().unwrap(),
                v["target"].as_str().unwrap(),
                v["edge_ns"].as_u64().unwrap() / FRAME_NS,
            )
        })
        .collect();
    assert_eq!(got, expected);
    for (i, v) in json.iter().enumerate() {
        assert_eq!(v["header"]["seq"].as_u64(), Some(i as u64));
        assert_eq!(v["source"], "Config");
    }
    assert_eq!(json[0]["mode"], 2); // bias_step
    assert_eq!(json[0]["axes"], 0b100);
    assert_eq!(json[0]["params"][0], 0.25);
    assert_eq!(json[2]["mode"], 11); // seized
                                     // Raw = decoded, field by field.
    assert_eq!(raw.len(), json.len());
    for (r, v) in raw.iter().zip(&json) {
        let m = decode_fault_event(r).unwrap();
        assert_eq!(serde_json::to_value(m).unwrap(), *v);
    }
}
