//! flexdyn wire protocol: the messages exchanged over Zenoh between the flexdyn
//! dynamics server and flight code, their key expressions, and the one codec.
//!
//! By default this crate has no Zenoh or async dependency; it only turns messages into
//! bytes and back. Two optional features make it the one dependency of Rust flight code
//! (the template `flexdyn-acs-demo` uses both):
//! - `attitude` ([`attitude`], nalgebra): the MRP, DCM and quaternion kernels the simulator
//!   itself uses;
//! - `client` ([`client`], Zenoh): the session rules (loopback, multicast scouting off), the
//!   command-line conventions, the served vehicle configuration, and lockstep ticks handed
//!   over complete ([`client::lockstep::TickReceiver`]).
//!
//! `proto/README.md` is the language-neutral specification (byte tables, Python example,
//! lockstep rules) for non-Rust flight code. Its byte tables, this crate's message types and
//! their per-message codec are generated from the wire table `proto/schema/messages.toml`
//! (`cargo run -p flexdyn-wiregen`), which the tests of `proto/gen` check against the
//! hand-derived goldens.
//!
//! # Topics
//!
//! | key | message | direction |
//! |---|---|---|
//! | `flexdyn/<sc-id>/tlm/time` | [`TimeMsg`] | server → flight code, every frame, first |
//! | `flexdyn/<sc-id>/tlm/env` | [`EnvironmentMsg`] | server → anyone, at `[environment] telemetry_rate_hz` |
//! | `flexdyn/<sc-id>/tlm/state` | [`StateMsg`] | server → flight code, every frame |
//! | `flexdyn/<sc-id>/tlm/imu/<name>` | [`ImuMsg`] | server → flight code |
//! | `flexdyn/<sc-id>/tlm/st/<name>` | [`StarTrackerMsg`] | server → flight code |
//! | `flexdyn/<sc-id>/tlm/mag/<name>` | [`MagnetometerMsg`] | server → flight code |
//! | `flexdyn/<sc-id>/tlm/css/<name>` | [`CssMsg`] | server → flight code |
//! | `flexdyn/<sc-id>/tlm/fss/<name>` | [`FssMsg`] | server → flight code |
//! | `flexdyn/<sc-id>/tlm/gps/<name>` | [`GpsMsg`] | server → flight code |
//! | `flexdyn/<deputy-id>/tlm/rel/<chief-id>` | [`RelativeStateMsg`] | fleet server → anyone, every frame |
//! | `flexdyn/<sc-id>/cmd/<sender-id>` | [`CommandMsg`] | flight code → server |
//! | `flexdyn/<sc-id>/status` | [`StatusMsg`] | server → anyone |
//! | `flexdyn/<sc-id>/tlm/fault` | [`FaultEventMsg`] | server → anyone, at each fault's activation and clearance |
//! | `flexdyn/<sc-id>/fault` | [`FaultCommandMsg`] | operator → server |
//! | `flexdyn/<sc-id>/operator` | [`OperatorMsg`] | operator → server |
//! | `flexdyn/<sc-id>/fsw/<name>` | [`FswMsg`] | flight code → server and recorders (its own telemetry) |
//! | `flexdyn/<sc-id>/participant/<sender-id>` | Zenoh liveliness token (no payload) | lockstep participant → server |
//!
//! Build keys with [`Topics`] or [`state_key`] & co; ids are validated
//! ([`KeyError`]).
//!
//! # Layout
//!
//! Every message is bincode 2.0.1 with `config::legacy()` (see [`codec`]):
//! little-endian fixed-width integers, `f64` as IEEE-754 binary64 LE, `bool` as
//! one byte 0/1, enums as a u32 LE variant index followed by the variant's
//! fields, `Vec<T>` as a u64 LE element count followed by the elements, fixed
//! arrays and nested structs inline, no padding, no field names, no framing.
//! Struct field order in this crate is the wire order.
//!
//! Every message starts with the 30-byte [`Header`], whose first two bytes are
//! the u16 LE [`PROTOCOL_VERSION`]; decoders check it before anything else.
//!
//! | message | size (bytes) |
//! |---|---|
//! | [`Header`] | [`HEADER_LEN`] = 30 |
//! | [`StateMsg`] | [`STATE_FIXED_LEN`] = 327 + per effector [`EFFECTOR_STATE_FIXED_LEN`] = 22 + 8 per value (count prefix at offset 319, effectors last) |
//! | [`ImuMsg`] | [`IMU_LEN`] = 127 |
//! | [`StarTrackerMsg`] | [`STAR_TRACKER_LEN`] = 64 |
//! | [`MagnetometerMsg`] | [`MAGNETOMETER_LEN`] = 55 |
//! | [`CssMsg`] | [`CSS_LEN`] = 159 |
//! | [`FssMsg`] | [`FSS_LEN`] = 47 |
//! | [`GpsMsg`] | [`GPS_LEN`] = 147 |
//! | [`TimeMsg`] | [`TIME_LEN`] = 122 |
//! | [`EnvironmentMsg`] | [`ENVIRONMENT_LEN`] = 368 |
//! | [`CommandMsg`] | [`COMMAND_WRENCH_LEN`] = 86 (tag 0 `Wrench`), [`COMMAND_NO_COMMAND_LEN`] = 38 (tag 1 `NoCommand`) or [`COMMAND_ACTUATORS_FIXED_LEN`] = 94 + per input [`EFFECTOR_INPUT_FIXED_LEN`] = 12 + 8 per value (tag 2 `Actuators`); tag at offset 34 |
//! | [`StatusMsg`] | [`STATUS_LEN`] = 243 |
//! | [`OperatorMsg`] | [`OPERATOR_LEN`] = 42 |
//! | [`FaultEventMsg`] | [`FAULT_EVENT_LEN`] = 199 |
//! | [`FaultCommandMsg`] | [`FAULT_COMMAND_LEN`] = 214 |
//! | [`RelativeStateMsg`] | [`RELATIVE_STATE_LEN`] = 102 |
//! | [`FswMsg`] | [`FSW_FIXED_LEN`] = 148 + 8 per value word (count prefix at offset 140, values last) |
//!
//! Decoders accept at most [`MAX_MESSAGE_BYTES`], [`MAX_EFFECTORS`] and
//! [`MAX_EFFECTOR_VALUES`], reject trailing bytes, and never panic ([`DecodeError`]).
//!
//! # Lockstep
//!
//! In [`Mode::Lockstep`] the server publishes the state for tick `k`, then waits
//! until every lockstep participant has published a [`CommandMsg`] with
//! `header.tick == k` (any [`CommandKind`]: `Wrench`, `NoCommand` or `Actuators`;
//! exactly one per participant per tick, so a participant that commands both a wrench
//! and reaction wheels sends one `Actuators`) before stepping to `k + 1`. Before tick 0 it waits
//! until every participant has declared its Zenoh liveliness token
//! [`Topics::participant`] (declared after the participant's state subscriber),
//! so the first publication is not lost.
//!
//! # Example
//!
//! ```
//! use flexdyn_proto::{decode_command, encode, CommandMsg, Header};
//!
//! let cmd = CommandMsg::wrench(Header::new(7, 42, 42_000_000, 3), 1, [0.0, 0.0, 0.01], [0.0; 3]);
//! let bytes = encode(&cmd);
//! assert_eq!(bytes.len(), flexdyn_proto::COMMAND_WRENCH_LEN);
//! assert_eq!(decode_command(&bytes).unwrap(), cmd);
//! ```
#![warn(missing_docs)]
#![forbid(unsafe_code)]

#[cfg(feature = "attitude")]
pub mod attitude;
#[cfg(feature = "client")]
pub mod client;
pub mod codec;
mod error;
// Written by flexdyn-wiregen from proto/schema/messages.toml.
#[rustfmt::skip]
mod json_schemas;
pub mod keys;
mod layout;
// Written by flexdyn-wiregen from proto/schema/messages.toml: every message type, with its docs;
// their methods are hand-written in messages/methods.rs.
mod messages;
pub mod view;
// Written by flexdyn-wiregen from proto/schema/messages.toml: every message's in-place view; the
// machinery they use is hand-written in view.rs.
#[rustfmt::skip]
mod views;
// Written by flexdyn-wiregen from proto/schema/messages.toml: each message's sizes, length rule,
// checks and decoder, and the protocol's constants.
#[rustfmt::skip]
mod wire;

pub use codec::{decode, decode_header, encode, encode_into};
// Every message's decode_* function, the table's constants and every encoded size and offset:
// all of wire.rs, so a message added to the table needs no line here.
pub use error::{DecodeError, KeyError};
#[doc(inline)]
pub use wire::*;
// The JSON Schemas of the messages' JSON (MCAP decoded channels, Foxglove), from the wire table.
pub use json_schemas::json_schema_text;
// The GPS receiver (issue 20, protocol 7).
pub use keys::GPS_PREFIX;
pub use keys::{
    cmd_key, cmd_wildcard_key, imu_key, imu_wildcard_key, operator_key, participant_key,
    participant_wildcard_key, sensor_key, star_tracker_key, star_tracker_wildcard_key, state_key,
    status_key, validate_imu_name, validate_sc_id, validate_sensor_name,
    validate_star_tracker_name, Telemetry, Topics, CMD_PREFIX, CSS_PREFIX, ENVIRONMENT_SUFFIX,
    FSS_PREFIX, IMU_PREFIX, KEY_ROOT, MAGNETOMETER_PREFIX, MAX_ID_LEN, OPERATOR_SUFFIX,
    PARTICIPANT_PREFIX, STAR_TRACKER_PREFIX, STATE_SUFFIX, STATUS_SUFFIX, TIME_SUFFIX,
};
pub use layout::{
    WalkError, WireLayout, WireMessage, MAX_PANEL_PAIRS, STATE_EFFECTOR_COUNT_OFFSET,
    TIME_CUC_OFFSET,
};
pub use messages::{
    command_flags, eclipse, effector_kind, environment_flags, fss_flags, magnetometer_flags,
    magnetorquer_flags, propellant_tank_flags, saturation_flags, star_tracker_flags,
    thruster_flags, time_flags, wheel_flags, AppliedWrench, CommandKind, CommandMsg, CommandStatus,
    Conserved, CssMsg, EffectorInput, EffectorState, EnvironmentMsg, FrameTiming, FssMsg, Header,
    ImuMsg, MagnetometerMsg, Mode, OperatorAction, OperatorMsg, RejectCounters, RunState,
    StalePolicy, StarTrackerMsg, StateMsg, StatusMsg, SysTime, TimeMsg, UtcTime,
};
pub use messages::{gps_flags, GpsMsg};
// Fault injection (issue 21, protocol 8).
pub use keys::{FAULT_EVENT_SUFFIX, FAULT_SUFFIX};
pub use messages::{
    FaultAction, FaultCommandMsg, FaultEventMsg, FaultSource, FaultTarget, FAULT_MODE_NAMES,
};
// A fleet deputy's state relative to its chief (issue 22, protocol 9).
pub use keys::{relative_state_key, RELATIVE_STATE_PREFIX};
pub use messages::RelativeStateMsg;
// The flight code's own telemetry (issue 37, protocol 10).
pub use keys::{fsw_key, fsw_wildcard_key, FSW_PREFIX};
pub use messages::{fsw_flags, FswMsg};

/// Wire protocol version carried in every [`Header`]. Bump it on any layout change.
/// Version 3: generic effector states in [`StateMsg`], [`CommandKind::Actuators`],
/// [`StarTrackerMsg`], [`RejectCounters::bad_effector_input`]. Version 4: one command key per
/// sender (`flexdyn/<sc-id>/cmd/<sender_id>`) and [`RejectCounters::wrong_identity`]. Version 5:
/// the sensor messages of issue 20 ([`MagnetometerMsg`]), and the time service [`TimeMsg`] on
/// `flexdyn/<sc-id>/tlm/time` with [`RunState::Paused`]. Version 6: the sun sensors of issue 20
/// ([`CssMsg`] on `tlm/css/<name>`, [`FssMsg`] on `tlm/fss/<name>`), and operator control of
/// issue 23 ([`OperatorMsg`] on `flexdyn/<sc-id>/operator`, [`RejectCounters::operator_refused`];
/// StatusMsg grows to 187 bytes), and the environment message [`EnvironmentMsg`] on
/// `flexdyn/<sc-id>/tlm/env` (issue 19).
/// Version 7: the GPS receiver of issue 20 ([`GpsMsg`] on `tlm/gps/<name>`).
/// Version 8: fault injection of issue 21 ([`FaultEventMsg`] on `tlm/fault`, the live
/// [`FaultCommandMsg`] on `flexdyn/<sc-id>/fault`, [`RejectCounters::fault_refused`] and the
/// active faults in StatusMsg, which grows to 235 bytes).
/// Version 9: a fleet deputy's state relative to its chief (issue 22, [`RelativeStateMsg`] on
/// `flexdyn/<deputy>/tlm/rel/<chief>`).
/// Version 10: the flight code's own telemetry (issue 37, [`FswMsg`] on
/// `flexdyn/<sc-id>/fsw/<name>`, [`RejectCounters::fsw_refused`]; StatusMsg grows to 243 bytes).
///
/// The number itself is the wire table's `protocol_version` (`proto/schema/messages.toml`),
/// exported with the table's other constants, sizes and `decode_*` functions above.
pub use wire::PROTOCOL_VERSION;
