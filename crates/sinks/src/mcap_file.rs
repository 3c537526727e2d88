//! The MCAP recording format of flexdyn: one writer shared by `flexdyn run --record` and
//! `flexdyn record`.
//!
//! # Channels
//! - **Raw**: topic = the Zenoh key (`flexdyn/sc1/tlm/state`), `message_encoding`
//!   [`RAW_ENCODING`], schema `flexdyn.<Message>` with encoding [`RAW_SCHEMA_ENCODING`] whose data
//!   is the message's wire layout from `proto/README.md` and the protocol version. The payload is
//!   the exact wire bytes, so a recording can be hashed and replayed bit for bit.
//! - **Decoded**: topic = `/` + key ([`decoded_topic`]), `message_encoding` `json`, schema
//!   `flexdyn.<Message>` (`jsonschema`, from the wire table): readable by any MCAP tool.
//! - **3D**: `/flexdyn/<sc>/tf` (`foxglove.FrameTransforms`) for every state and
//!   `/flexdyn/<sc>/scene` (`foxglove.SceneUpdate`) once per vehicle, when the vehicle's
//!   configuration is known ([`VehicleInfo`]); `/flexdyn/<sc>/actuators` (thruster and rod
//!   arrows and the propellant left in each tank, [`actuator_topic`]) for every state of a
//!   vehicle that has any of them; and
//!   `/flexdyn/<sc>/environment` (the Sun and magnetic-field arrows, [`environment_topic`]) for
//!   every EnvironmentMsg.
//!
//! Log time is the message's simulation time (`header.sim_time_ns`); publish time is the
//! wall-clock stamp of the sample (its Zenoh attachment, or StatusMsg's `wall_time_unix_ns`, or
//! the time it was received). Chunks are zstd-compressed and flushed at least once a second,
//! so after a crash everything up to the last finished chunk can still be read; a clean stop
//! writes the summary section and indexes.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::gaps::SeqGaps;
use super::scene::Geometry;
use super::scene::{
    actuator_scene, environment_scene, frame_transforms, frame_transforms_schema, scene_update,
    scene_update_schema,
};
use super::topics::{classify, json_schema, wire_layout_text, Decoded, TopicKind};
use flexdyn_vehicle::config::SimConfig;

/// `message_encoding` of the raw channels.
pub const RAW_ENCODING: &str = "flexdyn-proto";
/// Schema encoding of the raw channels: the schema data is the layout text.
pub const RAW_SCHEMA_ENCODING: &str = "flexdyn-proto-layout";
/// The topic of a key's decoded channel: the key with a leading `/` (`/flexdyn/sc1/tlm/state`),
/// Foxglove's topic convention, so message paths like `/flexdyn/sc1/tlm/state.sigma_bn[0]` work
/// unquoted.
pub fn decoded_topic(key: &str) -> String {
    format!("/{key}")
}

/// The topic of a vehicle's `foxglove.FrameTransforms`.
pub fn tf_topic(sc_id: &str) -> String {
    format!("/flexdyn/{sc_id}/tf")
}

/// The topic of a vehicle's `foxglove.SceneUpdate`.
pub fn scene_topic(sc_id: &str) -> String {
    format!("/flexdyn/{sc_id}/scene")
}

/// The topic of a vehicle's Sun and magnetic-field arrows, a `foxglove.SceneUpdate` per
/// EnvironmentMsg ([`super::scene::environment_scene`]).
pub fn environment_topic(sc_id: &str) -> String {
    format!("/flexdyn/{sc_id}/environment")
}

/// The topic of a vehicle's actuator arrows (thruster firings, rod dipoles) and of the
/// propellant left in its tanks, a `foxglove.SceneUpdate` per state
/// ([`super::scene::actuator_scene`]).
pub fn actuator_topic(sc_id: &str) -> String {
    format!("/flexdyn/{sc_id}/actuators")
}
/// Uncompressed bytes per chunk (Foxglove's own default is of this order).
pub const CHUNK_SIZE_BYTES: u64 = 1 << 20;

/// The flexdyn build that wrote a file.
pub fn flexdyn_version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// The git commit flexdyn was built from, when the build saw a git checkout.
pub fn git_commit() -> Option<&'static str> {
    option_env!("FLEXDYN_GIT_COMMIT").filter(|s| !s.is_empty())
}

/// What a server says about the vehicle it runs: written into a recording's metadata, and the
/// reply of the server's `flexdyn/<sc-id>/config` queryable.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleInfo {
    /// The string spacecraft id of the keys.
    pub sc_id: String,
    /// The numeric spacecraft id of the headers.
    pub spacecraft_id: u32,
    /// The configuration's TOML text, verbatim.
    pub config_toml: String,
    /// The server settings in effect (file and command line), as `key=value` pairs.
    pub server_settings: String,
    /// The server's flexdyn version.
    pub flexdyn_version: String,
    /// The server's git commit, when known.
    pub git_commit: Option<String>,
    /// The configuration's `[epoch]` in UTC, ISO 8601 with nanoseconds
    /// (`2026-11-24T06:00:00.000000000Z`): simulation time 0. `None` without an `[epoch]`
    /// (and in recordings made before it was written).
    #[serde(default)]
    pub epoch_utc: Option<String>,
}

impl VehicleInfo {
    /// Name of the metadata record that describes the vehicle `sc_id`.
    pub fn metadata_name(sc_id: &str) -> String {
        format!("flexdyn/{sc_id}")
    }

    /// The metadata record's key/value pairs.
    pub fn to_metadata(&self) -> BTreeMap<String, String> {
        let mut meta = BTreeMap::new();
        meta.insert("sc_id".to_owned(), self.sc_id.clone());
        meta.insert("spacecraft_id".to_owned(), self.spacecraft_id.to_string());
        meta.insert("config_toml".to_owned(), self.config_toml.clone());
        meta.insert("server_settings".to_owned(), self.server_settings.clone());
        meta.insert("flexdyn_version".to_owned(), self.flexdyn_version.clone());
        meta.insert(
            "git_commit".to_owned(),
            self.git_commit
                .clone()
                .unwrap_or_else(|| "unknown".to_owned()),
        );
        if let Some(epoch) = &self.epoch_utc {
            meta.insert("epoch_utc".to_owned(), epoch.clone());
        }
        meta
    }

    /// The 3D geometry of the configuration this vehicle runs.
    pub fn geometry(&self) -> Result<Geometry, flexdyn_vehicle::config::ConfigError> {
        SimConfig::from_toml_str(&self.config_toml).map(|cfg| Geometry::from_config(&cfg))
    }

    /// Reads a metadata record written by [`Self::to_metadata`]; `None` if a field is missing.
    pub fn from_metadata(meta: &BTreeMap<String, String>) -> Option<Self> {
        let get = |k: &str| meta.get(k).cloned();
        Some(Self {
            sc_id: get("sc_id")?,
            spacecraft_id: get("spacecraft_id")?.parse().ok()?,
            config_toml: get("config_toml")?,
            server_settings: get("server_settings")?,
            flexdyn_version: get("flexdyn_version")?,
            git_commit: get("git_commit").filter(|c| c != "unknown"),
            epoch_utc: get("epoch_utc"),
        })
    }
}

/// Who is recording, for the file's `flexdyn` metadata record.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordingInfo {
    /// `flexdyn run --record` or `flexdyn record`.
    pub recorder: String,
    /// The command line, for a reader to see how the file was made.
    pub command_line: String,
}

/// An error of the recorder.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RecordError {
    /// The file cannot be created.
    #[error("cannot create the recording {}: {source}", path.display())]
    Create {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Writing the file failed (disk full, …).
    #[error("cannot write the recording {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The MCAP writer's error.
        #[source]
        source: mcap::McapError,
    },
}

/// What a recording holds, at the end.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SinkStats {
    /// Samples given to the writer.
    pub samples: u64,
    /// Their payload bytes.
    pub payload_bytes: u64,
    /// Samples on keys that carry no flexdyn message (recorded raw only, untyped).
    pub unknown_keys: u64,
    /// Samples whose payload did not decode (recorded raw only).
    pub undecodable: u64,
    /// MCAP messages written (raw, decoded, transforms and scenes).
    pub mcap_messages: u64,
    /// Telemetry messages missing between those recorded, per key with any missing: the jumps
    /// of the publishers' sequence numbers ([`super::gaps`]).
    pub missing: BTreeMap<String, u64>,
}

impl SinkStats {
    /// Telemetry messages missing between those recorded, over every key.
    pub fn missing_total(&self) -> u64 {
        self.missing.values().sum()
    }
}

struct ChannelIds {
    kind: Option<TopicKind>,
    sc_id: String,
    raw: u16,
    decoded: Option<u16>,
}

/// States of a vehicle heard before its description, kept (up to this many) so their
/// transforms can be written once the description arrives.
pub const PENDING_STATES_MAX: usize = 20_000;

#[derive(Default)]
struct Vehicle {
    described: bool,
    geometry: Option<Geometry>,
    tf: Option<u16>,
    /// (log time, publish time, state) of states recorded before the description.
    pending: Vec<(u64, u64, flexdyn_proto::StateMsg)>,
    pending_overflow: bool,
}

/// The MCAP writer with flexdyn's channel layout.
pub struct McapSink {
    path: PathBuf,
    writer: mcap::Writer<BufWriter<File>>,
    schemas: HashMap<String, u16>,
    channels: HashMap<String, ChannelIds>,
    vehicles: HashMap<String, Vehicle>,
    /// Arrow channels by topic ([`Self::scene_update_channel`]).
    scene_channels: HashMap<String, u16>,
    sequences: HashMap<u16, u32>,
    last_log_time_ns: u64,
    gaps: SeqGaps,
    stats: SinkStats,
}

impl McapSink {
    /// Creates `path` and writes the `flexdyn` metadata record.
    pub fn create(path: &Path, info: &RecordingInfo) -> Result<Self, RecordError> {
        let file = File::create(path).map_err(|source| RecordError::Create {
            path: path.to_owned(),
            source,
        })?;
        let writer = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .chunk_size(Some(CHUNK_SIZE_BYTES))
            .profile("")
            .library(format!("flexdyn {}", flexdyn_version()))
            .create(BufWriter::new(file))
            .map_err(|source| RecordError::Write {
                path: path.to_owned(),
                source,
            })?;
        let mut sink = Self {
            path: path.to_owned(),
            writer,
            schemas: HashMap::new(),
            channels: HashMap::new(),
            vehicles: HashMap::new(),
            scene_channels: HashMap::new(),
            sequences: HashMap::new(),
            last_log_time_ns: 0,
            gaps: SeqGaps::default(),
            stats: SinkStats::default(),
        };
        let mut meta = BTreeMap::new();
        meta.insert("recorder".to_owned(), info.recorder.clone());
        meta.insert("command_line".to_owned(), info.command_line.clone());
        meta.insert("flexdyn_version".to_owned(), flexdyn_version().to_owned());
        meta.insert(
            "git_commit".to_owned(),
            git_commit().unwrap_or("unknown").to_owned(),
        );
        meta.insert(
            "protocol_version".to_owned(),
            flexdyn_proto::PROTOCOL_VERSION.to_string(),
        );
        sink.metadata("flexdyn", meta)?;
        Ok(sink)
    }

    fn err(&self, source: mcap::McapError) -> RecordError {
        RecordError::Write {
            path: self.path.clone(),
            source,
        }
    }

    fn metadata(
        &mut self,
        name: &str,
        metadata: BTreeMap<String, String>,
    ) -> Result<(), RecordError> {
        let m = mcap::records::Metadata {
            name: name.to_owned(),
            metadata,
        };
        self.writer.write_metadata(&m).map_err(|e| self.err(e))
    }

    /// Records `info` as the metadata record `flexdyn/<sc-id>` and, when its configuration
    /// parses, starts the vehicle's transform and scene channels.
    pub fn describe_vehicle(&mut self, info: &VehicleInfo) -> Result<(), RecordError> {
        self.metadata(&VehicleInfo::metadata_name(&info.sc_id), info.to_metadata())?;
        let geometry = match info.geometry() {
            Ok(g) => Some(g),
            Err(e) => {
                tracing::warn!(sc_id = %info.sc_id, error = %e, "the vehicle's configuration does not parse here; recording without its 3D transforms");
                None
            }
        };
        let v = self.vehicles.entry(info.sc_id.clone()).or_default();
        v.described = true;
        v.geometry = geometry;
        // States heard before the description get their transforms now (MCAP readers order
        // messages by log time, so writing them late is fine).
        let pending = std::mem::take(&mut v.pending);
        for (log_time, publish_time, state) in &pending {
            self.write_transforms(&info.sc_id, state, *log_time, *publish_time)?;
        }
        Ok(())
    }

    fn write_transforms(
        &mut self,
        sc_id: &str,
        state: &flexdyn_proto::StateMsg,
        log_time: u64,
        publish_time: u64,
    ) -> Result<(), RecordError> {
        let Some(tf) = self.vehicle_channels(sc_id, log_time)? else {
            return Ok(());
        };
        let geometry = self.vehicles.get(sc_id).and_then(|v| v.geometry.as_ref());
        let Some(g) = geometry else {
            return Ok(());
        };
        let prefix = format!("{sc_id}/");
        let json = frame_transforms(state, g, &prefix).to_string();
        let arrows = actuator_scene(g, state, &prefix, state.header.sim_time_ns);
        self.put(tf, log_time, publish_time, json.as_bytes())?;
        if let Some(arrows) = arrows {
            let channel = self.scene_update_channel(&actuator_topic(sc_id))?;
            self.put(
                channel,
                log_time,
                publish_time,
                arrows.to_string().as_bytes(),
            )?;
        }
        Ok(())
    }

    fn schema(
        &mut self,
        name: &str,
        encoding: &str,
        data: &dyn Fn() -> Vec<u8>,
    ) -> Result<u16, RecordError> {
        let key = format!("{encoding}\u{0}{name}");
        if let Some(id) = self.schemas.get(&key) {
            return Ok(*id);
        }
        let id = self
            .writer
            .add_schema(name, encoding, &data())
            .map_err(|e| self.err(e))?;
        self.schemas.insert(key, id);
        Ok(id)
    }

    fn channel(&mut self, schema: u16, topic: &str, encoding: &str) -> Result<u16, RecordError> {
        self.writer
            .add_channel(schema, topic, encoding, &BTreeMap::new())
            .map_err(|e| self.err(e))
    }

    fn open_channels(&mut self, key: &str) -> Result<(), RecordError> {
        if self.channels.contains_key(key) {
            return Ok(());
        }
        let ids = match classify(key) {
            Some(topic) => {
                let kind = topic.kind;
                let name = format!("flexdyn.{}", kind.message_name());
                let raw_schema = self.schema(&name, RAW_SCHEMA_ENCODING, &|| {
                    wire_layout_text(kind).into_bytes()
                })?;
                let json_schema_id = self.schema(&name, "jsonschema", &|| {
                    json_schema(kind).to_string().into_bytes()
                })?;
                let raw = self.channel(raw_schema, key, RAW_ENCODING)?;
                let decoded = self.channel(json_schema_id, &decoded_topic(key), "json")?;
                ChannelIds {
                    kind: Some(kind),
                    sc_id: topic.sc_id.to_owned(),
                    raw,
                    decoded: Some(decoded),
                }
            }
            // Another application's key under the subscription: kept, untyped (schema id 0).
            None => ChannelIds {
                kind: None,
                sc_id: String::new(),
                raw: self.channel(0, key, "application/octet-stream")?,
                decoded: None,
            },
        };
        self.channels.insert(key.to_owned(), ids);
        Ok(())
    }

    fn put(
        &mut self,
        channel: u16,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), RecordError> {
        let seq = self.sequences.entry(channel).or_insert(0);
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: *seq,
            log_time,
            publish_time,
        };
        *seq = seq.wrapping_add(1);
        self.stats.mcap_messages += 1;
        self.writer
            .write_to_known_channel(&header, data)
            .map_err(|e| self.err(e))
    }

    /// The `foxglove.SceneUpdate` channel on `topic`, opened on first use (the actuator and
    /// environment arrows: only vehicles that have them get the channel).
    fn scene_update_channel(&mut self, topic: &str) -> Result<u16, RecordError> {
        if let Some(c) = self.scene_channels.get(topic) {
            return Ok(*c);
        }
        let schema = self.schema("foxglove.SceneUpdate", "jsonschema", &|| {
            scene_update_schema().to_string().into_bytes()
        })?;
        let c = self.channel(schema, topic, "json")?;
        self.scene_channels.insert(topic.to_owned(), c);
        Ok(c)
    }

    fn vehicle_channels(&mut self, sc_id: &str, t_ns: u64) -> Result<Option<u16>, RecordError> {
        let Some(v) = self.vehicles.get(sc_id) else {
            return Ok(None);
        };
        if let Some(tf) = v.tf {
            return Ok(Some(tf));
        }
        let Some(geometry) = &v.geometry else {
            return Ok(None);
        };
        // First transforms of this vehicle: open its channels and write its scene once.
        let scene_json = scene_update(geometry, &format!("{sc_id}/"), t_ns).to_string();
        let tf_schema = self.schema("foxglove.FrameTransforms", "jsonschema", &|| {
            frame_transforms_schema().to_string().into_bytes()
        })?;
        let scene_schema = self.schema("foxglove.SceneUpdate", "jsonschema", &|| {
            scene_update_schema().to_string().into_bytes()
        })?;
        let tf = self.channel(tf_schema, &tf_topic(sc_id), "json")?;
        let scene = self.channel(scene_schema, &scene_topic(sc_id), "json")?;
        self.put(scene, t_ns, t_ns, scene_json.as_bytes())?;
        if let Some(v) = self.vehicles.get_mut(sc_id) {
            v.tf = Some(tf);
        }
        Ok(Some(tf))
    }

    /// Records one sample: its raw channel always, its decoded channel when it decodes, and the
    /// vehicle's transforms for a StateMsg. `publish_time_ns` is the sample's wall-clock stamp
    /// (the Zenoh attachment), `received_unix_ns` the time it reached the recorder.
    pub fn write(
        &mut self,
        key: &str,
        payload: &[u8],
        publish_time_ns: Option<u64>,
        received_unix_ns: u64,
    ) -> Result<(), RecordError> {
        self.stats.samples += 1;
        self.stats.payload_bytes += payload.len() as u64;
        self.open_channels(key)?;
        let Some(ids) = self.channels.get(key) else {
            return Ok(());
        };
        let (raw, decoded_channel, kind) = (ids.raw, ids.decoded, ids.kind);
        let sc_id = ids.sc_id.clone();
        let Some(kind) = kind else {
            self.stats.unknown_keys += 1;
            let t = self.last_log_time_ns;
            return self.put(raw, t, publish_time_ns.unwrap_or(received_unix_ns), payload);
        };
        let decoded = match Decoded::decode(kind, payload) {
            Ok(d) => d,
            Err(e) => {
                self.stats.undecodable += 1;
                if self.stats.undecodable.is_power_of_two() {
                    tracing::warn!(key, error = %e, count = self.stats.undecodable, "recording a payload that does not decode (raw channel only)");
                }
                let t = self.last_log_time_ns;
                return self.put(raw, t, publish_time_ns.unwrap_or(received_unix_ns), payload);
            }
        };
        let log_time = decoded.header().sim_time_ns;
        self.last_log_time_ns = log_time;
        let gap = self.gaps.observe(key, kind, decoded.header().seq);
        if gap > 0 {
            *self.stats.missing.entry(key.to_owned()).or_default() += gap;
        }
        let publish_time = match (&decoded, publish_time_ns) {
            (_, Some(t)) => t,
            (Decoded::Status(s), None) => s.wall_time_unix_ns,
            (_, None) => received_unix_ns,
        };
        self.put(raw, log_time, publish_time, payload)?;
        if let Some(channel) = decoded_channel {
            let json = decoded.to_json_bytes();
            self.put(channel, log_time, publish_time, &json)?;
        }
        if let Decoded::Environment(env) = &decoded {
            let channel = self.scene_update_channel(&environment_topic(&sc_id))?;
            let arrows = environment_scene(env, &format!("{sc_id}/"), log_time).to_string();
            self.put(channel, log_time, publish_time, arrows.as_bytes())?;
        }
        if let Decoded::State(state) = decoded {
            let v = self.vehicles.entry(sc_id.clone()).or_default();
            if v.described {
                self.write_transforms(&sc_id, &state, log_time, publish_time)?;
            } else if v.pending.len() < PENDING_STATES_MAX {
                v.pending.push((log_time, publish_time, state));
            } else if !v.pending_overflow {
                v.pending_overflow = true;
                tracing::warn!(sc_id = %sc_id, kept = PENDING_STATES_MAX, "no configuration from this vehicle's server yet; later states get no 3D transforms until it answers");
            }
        }
        Ok(())
    }

    /// Finishes the current chunk and flushes it to the file, so a crash after this loses
    /// nothing written before.
    pub fn flush_chunk(&mut self) -> Result<(), RecordError> {
        self.writer.flush().map_err(|e| self.err(e))
    }

    /// Writes `metadata` as a record named `name` (e.g. the recorder's final counters).
    pub fn write_metadata(
        &mut self,
        name: &str,
        metadata: BTreeMap<String, String>,
    ) -> Result<(), RecordError> {
        self.metadata(name, metadata)
    }

    /// What has been written so far.
    pub fn stats(&self) -> &SinkStats {
        &self.stats
    }

    /// Writes the summary section and indexes, and closes the file.
    pub fn finish(mut self) -> Result<SinkStats, RecordError> {
        self.writer.finish().map_err(|e| self.err(e))?;
        let path = self.path.clone();
        let inner = self.writer.into_inner();
        inner
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all())
            .map_err(|source| RecordError::Write {
                path,
                source: mcap::McapError::Io(source),
            })?;
        Ok(self.stats)
    }
}
