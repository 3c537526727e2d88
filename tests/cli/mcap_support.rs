//! Recordings written by the tests themselves with the recorder's own sink, for what a batch
//! run cannot record (the flight code's telemetry): one vehicle described by its configuration.

use std::collections::BTreeMap;
use std::path::Path;

use flexdyn_sinks::mcap_file::{McapSink, RecordingInfo, VehicleInfo};

/// A sink writing `file`, with the vehicle `sc1` (spacecraft id 1) configured by `config_toml`.
pub fn sink_for(file: &Path, config_toml: &str) -> McapSink {
    let mut sink = McapSink::create(
        file,
        &RecordingInfo {
            recorder: "test".into(),
            command_line: String::new(),
        },
    )
    .unwrap();
    sink.describe_vehicle(&VehicleInfo {
        sc_id: "sc1".into(),
        spacecraft_id: 1,
        config_toml: config_toml.to_owned(),
        server_settings: String::new(),
        flexdyn_version: "test".into(),
        git_commit: None,
        epoch_utc: None,
    })
    .unwrap();
    sink
}

/// The first message of each JSON (decoded) channel of the MCAP file `bytes`, by topic.
pub fn first_json_messages(bytes: &[u8]) -> BTreeMap<String, serde_json::Value> {
    let mut first = BTreeMap::new();
    for m in mcap::MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.message_encoding == "json" && !first.contains_key(&m.channel.topic) {
            first.insert(
                m.channel.topic.clone(),
                serde_json::from_slice(&m.data).unwrap(),
            );
        }
    }
    first
}
