//! The JSON Schemas of the messages' JSON (draft 2020-12), written by flexdyn-wiregen from
//! proto/schema/messages.toml into proto/schema/json/: do not edit; change the table and run
//! `cargo run -p flexdyn-wiregen`.

/// The JSON Schema text of the message named `name` (`"ImuMsg"`, a
/// [`crate::WireMessage::NAME`]), `None` for another name.
pub fn json_schema_text(name: &str) -> Option<&'static str> {
    match name {
        "StateMsg" => Some(include_str!("../schema/json/StateMsg.json")),
        "ImuMsg" => Some(include_str!("../schema/json/ImuMsg.json")),
        "StarTrackerMsg" => Some(include_str!("../schema/json/StarTrackerMsg.json")),
        "MagnetometerMsg" => Some(include_str!("../schema/json/MagnetometerMsg.json")),
        "CssMsg" => Some(include_str!("../schema/json/CssMsg.json")),
        "FssMsg" => Some(include_str!("../schema/json/FssMsg.json")),
        "GpsMsg" => Some(include_str!("../schema/json/GpsMsg.json")),
        "CommandMsg" => Some(include_str!("../schema/json/CommandMsg.json")),
        "TimeMsg" => Some(include_str!("../schema/json/TimeMsg.json")),
        "EnvironmentMsg" => Some(include_str!("../schema/json/EnvironmentMsg.json")),
        "OperatorMsg" => Some(include_str!("../schema/json/OperatorMsg.json")),
        "FaultEventMsg" => Some(include_str!("../schema/json/FaultEventMsg.json")),
        "FaultCommandMsg" => Some(include_str!("../schema/json/FaultCommandMsg.json")),
        "RelativeStateMsg" => Some(include_str!("../schema/json/RelativeStateMsg.json")),
        "StatusMsg" => Some(include_str!("../schema/json/StatusMsg.json")),
        "FswMsg" => Some(include_str!("../schema/json/FswMsg.json")),
        _ => None,
    }
}
