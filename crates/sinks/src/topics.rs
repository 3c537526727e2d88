//! Which flexdyn message a Zenoh key carries, and the message decoded from its payload.
//!
//! Every sink (recorder, exporter, viewer, plotter) starts here: a key expression
//! `flexdyn/<sc-id>/<suffix>` (see `proto/README.md`, "Topics") names the message type, and the
//! payload decodes with the one `flexdyn-proto` codec.

use flexdyn_proto::keys::{
    CMD_PREFIX, ENVIRONMENT_SUFFIX, KEY_ROOT, OPERATOR_SUFFIX, STATE_SUFFIX, STATUS_SUFFIX,
    TIME_SUFFIX,
};
use flexdyn_proto::{
    decode_command, decode_environment, decode_operator, decode_state, decode_status, decode_time,
    CommandMsg, DecodeError, EnvironmentMsg, Header, OperatorMsg, StateMsg, StatusMsg, TimeMsg,
};
// Fault injection (protocol 8).
use flexdyn_proto::{
    decode_fault_command, decode_fault_event, FaultCommandMsg, FaultEventMsg, FAULT_EVENT_SUFFIX,
    FAULT_SUFFIX,
};
// A fleet deputy's relative state (protocol 9).
use flexdyn_proto::{decode_relative_state, RelativeStateMsg, RELATIVE_STATE_PREFIX};
// The flight code's own telemetry (protocol 10).
use flexdyn_proto::{decode_fsw, FswMsg, FSW_PREFIX};

use flexdyn_sensors::{SensorKind, KINDS};

/// The message type a flexdyn key carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TopicKind {
    /// `flexdyn/<sc>/tlm/state`: [`StateMsg`].
    State,
    /// `flexdyn/<sc>/<key prefix>/<name>`: the message of sensor kind `KINDS[i]`
    /// ([`flexdyn_sensors::KINDS`]; `tlm/imu/<name>`: `ImuMsg`, `tlm/st/<name>`:
    /// `StarTrackerMsg`).
    Sensor(usize),
    /// `flexdyn/<sc>/cmd/<sender_id>`: [`CommandMsg`].
    Command,
    /// `flexdyn/<sc>/status`: [`StatusMsg`].
    Status,
    /// `flexdyn/<sc>/tlm/time`: [`TimeMsg`] (the time service).
    Time,
    /// `flexdyn/<sc>/operator`: [`OperatorMsg`] (pause, resume, run N ticks).
    Operator,
    /// `flexdyn/<sc>/tlm/env`: [`EnvironmentMsg`] (the environment's truth).
    Environment,
    /// `flexdyn/<sc>/tlm/fault`: [`FaultEventMsg`] (a fault's activation or clearance).
    FaultEvent,
    /// `flexdyn/<sc>/fault`: [`FaultCommandMsg`] (a live fault command).
    FaultCommand,
    /// `flexdyn/<deputy>/tlm/rel/<chief>`: [`RelativeStateMsg`] (a fleet deputy relative to
    /// its chief; the chief's id is the topic's `sensor`).
    RelativeState,
    /// `flexdyn/<sc>/fsw/<name>`: [`FswMsg`] (the flight code's telemetry stream `<name>`,
    /// the topic's `sensor`).
    Fsw,
}

impl TopicKind {
    /// Every kind, in a fixed order: the state, each registered sensor kind, commands, status.
    pub fn all() -> impl Iterator<Item = TopicKind> {
        std::iter::once(TopicKind::State)
            .chain((0..KINDS.len()).map(TopicKind::Sensor))
            .chain([
                TopicKind::Command,
                TopicKind::Status,
                TopicKind::Time,
                TopicKind::Operator,
                TopicKind::Environment,
                TopicKind::FaultEvent,
                TopicKind::FaultCommand,
                TopicKind::RelativeState,
                TopicKind::Fsw,
            ])
    }

    /// The topic kind of sensor kind `kind` (`None` if it is not registered).
    pub fn sensor(kind: &'static SensorKind) -> Option<TopicKind> {
        kind.index().map(TopicKind::Sensor)
    }

    /// The sensor kind of a [`TopicKind::Sensor`].
    pub fn sensor_kind(self) -> Option<&'static SensorKind> {
        match self {
            TopicKind::Sensor(i) => KINDS.get(i).copied(),
            _ => None,
        }
    }

    /// The wire message's name, as in `proto/README.md` (`StateMsg`, …).
    pub fn message_name(self) -> &'static str {
        match self {
            TopicKind::State => "StateMsg",
            TopicKind::Sensor(_) => self.sensor_kind().map_or("", |k| k.message_name),
            TopicKind::Command => "CommandMsg",
            TopicKind::Status => "StatusMsg",
            TopicKind::Time => "TimeMsg",
            TopicKind::Operator => "OperatorMsg",
            TopicKind::Environment => "EnvironmentMsg",
            TopicKind::FaultEvent => "FaultEventMsg",
            TopicKind::FaultCommand => "FaultCommandMsg",
            TopicKind::RelativeState => "RelativeStateMsg",
            TopicKind::Fsw => "FswMsg",
        }
    }
}

/// A flexdyn key split into its spacecraft id, kind and (for sensors) sensor name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Topic<'a> {
    /// The string spacecraft id.
    pub sc_id: &'a str,
    /// The message type.
    pub kind: TopicKind,
    /// The sensor name, a command key's decimal sender id, or a relative state's chief id;
    /// `None` for the other kinds.
    pub sensor: Option<&'a str>,
}

/// Classifies `key`; `None` for keys that carry no flexdyn message (liveliness tokens, other
/// applications' keys).
pub fn classify(key: &str) -> Option<Topic<'_>> {
    let rest = key.strip_prefix(KEY_ROOT)?.strip_prefix('/')?;
    let (sc_id, suffix) = rest.split_once('/')?;
    if sc_id.is_empty() {
        return None;
    }
    let sensor = |prefix: &str| {
        suffix
            .strip_prefix(prefix)
            .and_then(|s| s.strip_prefix('/'))
            .filter(|name| !name.is_empty() && !name.contains('/'))
    };
    let (kind, sensor) = if suffix == STATE_SUFFIX {
        (TopicKind::State, None)
    } else if suffix == TIME_SUFFIX {
        (TopicKind::Time, None)
    } else if suffix == ENVIRONMENT_SUFFIX {
        (TopicKind::Environment, None)
    } else if suffix == FAULT_EVENT_SUFFIX {
        (TopicKind::FaultEvent, None)
    } else if suffix == FAULT_SUFFIX {
        (TopicKind::FaultCommand, None)
    } else if let Some(sender) =
        sensor(CMD_PREFIX).filter(|s| s.bytes().all(|b| b.is_ascii_digit()))
    {
        (TopicKind::Command, Some(sender))
    } else if let Some(chief) = sensor(RELATIVE_STATE_PREFIX) {
        (TopicKind::RelativeState, Some(chief))
    } else if let Some(stream) = sensor(FSW_PREFIX) {
        (TopicKind::Fsw, Some(stream))
    } else if suffix == STATUS_SUFFIX {
        (TopicKind::Status, None)
    } else if suffix == OPERATOR_SUFFIX {
        (TopicKind::Operator, None)
    } else if let Some((i, name)) = KINDS
        .iter()
        .enumerate()
        .find_map(|(i, k)| Some((i, sensor(k.key_prefix)?)))
    {
        (TopicKind::Sensor(i), Some(name))
    } else {
        return None;
    };
    Some(Topic {
        sc_id,
        kind,
        sensor,
    })
}

/// One decoded flexdyn message.
#[derive(Clone, Debug, PartialEq)]
pub enum Decoded {
    /// A state.
    State(StateMsg),
    /// A sensor sample of kind `KINDS[kind]`: its header and its JSON (fields as in the wire
    /// struct, header included).
    Sensor {
        /// Index in [`flexdyn_sensors::KINDS`].
        kind: usize,
        /// The message header.
        header: Header,
        /// The message as JSON.
        json: serde_json::Value,
    },
    /// A command.
    Command(CommandMsg),
    /// A server status.
    Status(StatusMsg),
    /// A time-service message.
    Time(TimeMsg),
    /// An operator command.
    Operator(OperatorMsg),
    /// An environment message.
    Environment(EnvironmentMsg),
    /// A fault event.
    FaultEvent(FaultEventMsg),
    /// A live fault command.
    FaultCommand(FaultCommandMsg),
    /// A fleet deputy's state relative to its chief.
    RelativeState(RelativeStateMsg),
    /// A sample of the flight code's own telemetry.
    Fsw(FswMsg),
}

impl Decoded {
    /// Decodes `payload` as the message `kind` names.
    pub fn decode(kind: TopicKind, payload: &[u8]) -> Result<Self, DecodeError> {
        Ok(match kind {
            TopicKind::State => Decoded::State(decode_state(payload)?),
            TopicKind::Sensor(i) => {
                let Some(k) = KINDS.get(i) else {
                    return Err(DecodeError::Malformed(format!("no sensor kind {i}")));
                };
                let (header, json) = (k.decode)(payload)?;
                Decoded::Sensor {
                    kind: i,
                    header,
                    json,
                }
            }
            TopicKind::Command => Decoded::Command(decode_command(payload)?),
            TopicKind::Status => Decoded::Status(decode_status(payload)?),
            TopicKind::Time => Decoded::Time(decode_time(payload)?),
            TopicKind::Operator => Decoded::Operator(decode_operator(payload)?),
            TopicKind::Environment => Decoded::Environment(decode_environment(payload)?),
            TopicKind::FaultEvent => Decoded::FaultEvent(decode_fault_event(payload)?),
            TopicKind::FaultCommand => Decoded::FaultCommand(decode_fault_command(payload)?),
            TopicKind::RelativeState => Decoded::RelativeState(decode_relative_state(payload)?),
            TopicKind::Fsw => Decoded::Fsw(decode_fsw(payload)?),
        })
    }

    /// The message header.
    pub fn header(&self) -> &Header {
        match self {
            Decoded::State(m) => &m.header,
            Decoded::Sensor { header, .. } => header,
            Decoded::Command(m) => &m.header,
            Decoded::Status(m) => &m.header,
            Decoded::Time(m) => &m.header,
            Decoded::Operator(m) => &m.header,
            Decoded::Environment(m) => &m.header,
            Decoded::FaultEvent(m) => &m.header,
            Decoded::FaultCommand(m) => &m.header,
            Decoded::RelativeState(m) => &m.header,
            Decoded::Fsw(m) => &m.header,
        }
    }

    /// The message as JSON text, serialised straight from the struct (the recorder's and the
    /// viewer's path: no intermediate [`serde_json::Value`]).
    pub fn to_json_bytes(&self) -> Vec<u8> {
        let v = match self {
            Decoded::State(m) => serde_json::to_vec(m),
            Decoded::Sensor { json, .. } => serde_json::to_vec(json),
            Decoded::Command(m) => serde_json::to_vec(m),
            Decoded::Status(m) => serde_json::to_vec(m),
            Decoded::Time(m) => serde_json::to_vec(m),
            Decoded::Operator(m) => serde_json::to_vec(m),
            Decoded::Environment(m) => serde_json::to_vec(m),
            Decoded::FaultEvent(m) => serde_json::to_vec(m),
            Decoded::FaultCommand(m) => serde_json::to_vec(m),
            Decoded::RelativeState(m) => serde_json::to_vec(m),
            Decoded::Fsw(m) => serde_json::to_vec(m),
        };
        v.unwrap_or_else(|_| b"null".to_vec())
    }

    /// The message as JSON, field names as in the wire structs (they carry their units).
    pub fn to_json(&self) -> serde_json::Value {
        let v = match self {
            Decoded::State(m) => serde_json::to_value(m),
            Decoded::Sensor { json, .. } => Ok(json.clone()),
            Decoded::Command(m) => serde_json::to_value(m),
            Decoded::Status(m) => serde_json::to_value(m),
            Decoded::Time(m) => serde_json::to_value(m),
            Decoded::Operator(m) => serde_json::to_value(m),
            Decoded::Environment(m) => serde_json::to_value(m),
            Decoded::FaultEvent(m) => serde_json::to_value(m),
            Decoded::FaultCommand(m) => serde_json::to_value(m),
            Decoded::RelativeState(m) => serde_json::to_value(m),
            Decoded::Fsw(m) => serde_json::to_value(m),
        };
        // The wire structs hold only numbers, bools, enums and vectors: always representable.
        v.unwrap_or(serde_json::Value::Null)
    }
}

/// The JSON Schema (draft 2020-12) of the decoded JSON of `kind`, from the wire table
/// (`proto/schema/json/`, written by flexdyn-wiregen).
pub fn json_schema(kind: TopicKind) -> serde_json::Value {
    use flexdyn_sensors::message_json_schema as of;
    match kind {
        TopicKind::State => of::<StateMsg>(),
        TopicKind::Sensor(_) => kind
            .sensor_kind()
            .map_or(serde_json::Value::Null, |k| (k.json_schema)()),
        TopicKind::Command => of::<CommandMsg>(),
        TopicKind::Status => of::<StatusMsg>(),
        TopicKind::Time => of::<TimeMsg>(),
        TopicKind::Operator => of::<OperatorMsg>(),
        TopicKind::Environment => of::<EnvironmentMsg>(),
        TopicKind::FaultEvent => of::<FaultEventMsg>(),
        TopicKind::FaultCommand => of::<FaultCommandMsg>(),
        TopicKind::RelativeState => of::<RelativeStateMsg>(),
        TopicKind::Fsw => of::<FswMsg>(),
    }
}

/// The section of `proto/README.md` that specifies the wire layout of `kind`, after the
/// encoding rules and the header: what a raw recording channel's schema holds.
pub fn wire_layout_text(kind: TopicKind) -> String {
    const README: &str = include_str!("../../../proto/README.md");
    let section = |starts: &str| -> &str {
        let Some(begin) = README.find(starts) else {
            return "";
        };
        let body = &README[begin..];
        // Up to the next second-level heading.
        let end = body[3..].find("\n## ").map_or(body.len(), |i| i + 4);
        &body[..end]
    };
    let title = README.lines().next().unwrap_or_default();
    format!(
        "{title}\n\nflexdyn protocol_version {}; payload = one {} encoded as below.\n\n{}\n{}\n{}",
        flexdyn_proto::PROTOCOL_VERSION,
        kind.message_name(),
        section("## Encoding rules"),
        section("## Header"),
        section(&format!("## {} ", kind.message_name())),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_classify_by_their_suffix() {
        let t = classify("flexdyn/sc1/tlm/state").unwrap();
        assert_eq!((t.sc_id, t.kind, t.sensor), ("sc1", TopicKind::State, None));
        let imu = TopicKind::sensor(&flexdyn_sensors::imu::KIND).unwrap();
        let st = TopicKind::sensor(&flexdyn_sensors::star_tracker::KIND).unwrap();
        assert_ne!(imu, st);
        let t = classify("flexdyn/a-b/tlm/imu/hub").unwrap();
        assert_eq!((t.sc_id, t.kind, t.sensor), ("a-b", imu, Some("hub")));
        assert_eq!(imu.message_name(), "ImuMsg");
        let t = classify("flexdyn/x/tlm/st/st1").unwrap();
        assert_eq!(t.kind, st);
        assert_eq!(st.message_name(), "StarTrackerMsg");
        let t = classify("flexdyn/x/cmd/12").unwrap();
        assert_eq!((t.kind, t.sensor), (TopicKind::Command, Some("12")));
        assert_eq!(classify("flexdyn/x/cmd/wrench"), None, "the protocol-3 key");
        assert_eq!(
            classify("flexdyn/x/status").unwrap().kind,
            TopicKind::Status
        );
        let t = classify("flexdyn/x/tlm/time").unwrap();
        assert_eq!((t.kind, t.sensor), (TopicKind::Time, None));
        assert_eq!(TopicKind::Time.message_name(), "TimeMsg");
        assert_eq!(classify("flexdyn/x/tlm/time/y"), None);
        let t = classify("flexdyn/x/operator").unwrap();
        assert_eq!((t.kind, t.sensor), (TopicKind::Operator, None));
        assert_eq!(TopicKind::Operator.message_name(), "OperatorMsg");
        assert_eq!(classify("flexdyn/x/operator/1"), None);
        let t = classify("flexdyn/x/tlm/env").unwrap();
        assert_eq!((t.kind, t.sensor), (TopicKind::Environment, None));
        assert_eq!(TopicKind::Environment.message_name(), "EnvironmentMsg");
        let t = classify("flexdyn/deputy/tlm/rel/chief").unwrap();
        assert_eq!(
            (t.sc_id, t.kind, t.sensor),
            ("deputy", TopicKind::RelativeState, Some("chief"))
        );
        assert_eq!(classify("flexdyn/deputy/tlm/rel/a/b"), None);
        for other in [
            "flexdyn/x/participant/1",
            "flexdyn/x/tlm/imu/",
            "flexdyn/x/tlm/imu/a/b",
            "flexdyn//status",
            "other/x/status",
            "flexdyn/x",
        ] {
            assert_eq!(classify(other), None, "{other}");
        }
    }

    #[test]
    fn the_layout_text_holds_the_message_section_and_the_version() {
        for kind in TopicKind::all() {
            let text = wire_layout_text(kind);
            assert!(text.contains("## Encoding rules"), "{kind:?}");
            assert!(text.contains("## Header"), "{kind:?}");
            assert!(
                text.contains(&format!("## {} ", kind.message_name())),
                "{kind:?}: {text}"
            );
            assert!(text.contains(&format!(
                "protocol_version {}",
                flexdyn_proto::PROTOCOL_VERSION
            )));
        }
    }
}
