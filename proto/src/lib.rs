//! flexdyn wire protocol: the messages exchanged over Zenoh between the flexdyn
//! dynamics server and flight code, their key expressions, and the one codec.
//!
//! This crate has no Zenoh or async dependency; it only turns messages into
//! bytes and back. `proto/README.md` is the language-neutral specification
//! (byte tables, Python example, lockstep rules) for non-Rust flight code.
//!
//! # Topics
//!
//! | key | message | direction |
//! |---|---|---|
//! | `flexdyn/<sc-id>/tlm/state` | [`StateMsg`] | server → flight code, every frame |
//! | `flexdyn/<sc-id>/tlm/imu/<name>` | [`ImuMsg`] | server → flight code |
//! | `flexdyn/<sc-id>/cmd/wrench` | [`CommandMsg`] | flight code → server |
//! | `flexdyn/<sc-id>/status` | [`StatusMsg`] | server → anyone |
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
//! | [`StateMsg`] | [`STATE_FIXED_LEN`] = 327 + [`PANEL_PAIR_LEN`] = 32 per panel pair (count prefix at offset 319, panels last) |
//! | [`ImuMsg`] | [`IMU_LEN`] = 127 |
//! | [`CommandMsg`] | [`COMMAND_WRENCH_LEN`] = 86 (tag 0 `Wrench`) or [`COMMAND_NO_COMMAND_LEN`] = 38 (tag 1 `NoCommand`), tag at offset 34 |
//! | [`StatusMsg`] | [`STATUS_LEN`] = 163 |
//!
//! Decoders accept at most [`MAX_MESSAGE_BYTES`] and [`MAX_PANEL_PAIRS`], reject
//! trailing bytes, and never panic ([`DecodeError`]).
//!
//! # Lockstep
//!
//! In [`Mode::Lockstep`] the server publishes the state for tick `k`, then waits
//! until every lockstep participant has published a [`CommandMsg`] with
//! `header.tick == k` (either [`CommandKind::Wrench`] or
//! [`CommandKind::NoCommand`]) before stepping to `k + 1`. Before tick 0 it waits
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

pub mod codec;
mod error;
pub mod keys;
mod layout;
mod messages;

pub use codec::{
    decode, decode_command, decode_header, decode_imu, decode_state, decode_status, encode,
    encode_into,
};
pub use error::{DecodeError, KeyError};
pub use keys::{
    cmd_wrench_key, imu_key, imu_wildcard_key, participant_key, participant_wildcard_key,
    state_key, status_key, validate_imu_name, validate_sc_id, Topics, CMD_WRENCH_SUFFIX,
    IMU_PREFIX, KEY_ROOT, MAX_ID_LEN, PARTICIPANT_PREFIX, STATE_SUFFIX, STATUS_SUFFIX,
};
pub use layout::{
    WireLayout, WireMessage, COMMAND_KIND_OFFSET, COMMAND_NO_COMMAND_LEN, COMMAND_WRENCH_LEN,
    HEADER_LEN, IMU_LEN, MAX_MESSAGE_BYTES, MAX_PANEL_PAIRS, PANEL_PAIR_LEN, STATE_FIXED_LEN,
    STATE_PANEL_COUNT_OFFSET, STATUS_LEN,
};
pub use messages::{
    command_flags, saturation_flags, AppliedWrench, CommandKind, CommandMsg, CommandStatus,
    Conserved, FrameTiming, Header, ImuMsg, Mode, PanelPairState, RejectCounters, RunState,
    StalePolicy, StateMsg, StatusMsg, NO_COMMAND,
};

/// Wire protocol version carried in every [`Header`]. Bump it on any layout change.
pub const PROTOCOL_VERSION: u16 = 2;
