//! Typed errors for decoding wire messages and building key expressions.

use thiserror::Error;

/// Why a byte buffer could not be decoded into a wire message.
///
/// Decoding never panics; every malformed input maps to one of these variants.
/// [`crate::RejectCounters::record`] maps each variant onto the rejection
/// counters published in [`crate::StatusMsg`].
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DecodeError {
    /// The buffer is shorter than the message it announces.
    ///
    /// `needed` is the exact total length implied by the bytes that could be read
    /// (fixed layout, `CommandKind` tag or panel count prefix); when even those are
    /// missing it is the shortest possible length of the message type.
    #[error("message too short: need {needed} bytes, got {actual}")]
    Length {
        /// Total length (bytes) the message must have.
        needed: usize,
        /// Length (bytes) of the buffer received.
        actual: usize,
    },
    /// The buffer holds a complete message followed by extra bytes.
    #[error("trailing bytes: message is {expected} bytes, buffer is {actual}")]
    TrailingBytes {
        /// Length (bytes) of the message itself.
        expected: usize,
        /// Length (bytes) of the buffer received.
        actual: usize,
    },
    /// The buffer is larger than [`crate::MAX_MESSAGE_BYTES`]; it was not parsed.
    #[error("message of {actual} bytes exceeds the {max}-byte limit")]
    TooLarge {
        /// Length (bytes) of the buffer received.
        actual: usize,
        /// The limit, [`crate::MAX_MESSAGE_BYTES`].
        max: usize,
    },
    /// The first two bytes (`header.protocol_version`, u16 LE) are not
    /// [`crate::PROTOCOL_VERSION`]. Nothing else was decoded.
    #[error(
        "unknown protocol version {found} (expected {})",
        crate::PROTOCOL_VERSION
    )]
    UnknownVersion {
        /// The version found on the wire.
        found: u16,
    },
    /// A number in a command is NaN or infinite.
    #[error("non-finite value in field {field}")]
    NonFinite {
        /// Path of the offending field, e.g. `"kind.torque_b_nm[2]"`.
        field: &'static str,
    },
    /// Structurally invalid content: unknown enum tag, bool byte other than 0/1,
    /// a count above its documented maximum, ...
    #[error("malformed message: {0}")]
    Malformed(String),
}

/// Why a spacecraft id or IMU name cannot be used in a key expression.
///
/// Valid ids are 1..=[`crate::MAX_ID_LEN`] characters from `[A-Za-z0-9_-]`.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum KeyError {
    /// The id is the empty string.
    #[error("{what} is empty")]
    Empty {
        /// Which id: `"spacecraft id"` or `"imu name"`.
        what: &'static str,
    },
    /// The id is longer than [`crate::MAX_ID_LEN`] bytes.
    #[error("{what} is {len} bytes long (max {max})")]
    TooLong {
        /// Which id: `"spacecraft id"` or `"imu name"`.
        what: &'static str,
        /// Its length in bytes.
        len: usize,
        /// The limit, [`crate::MAX_ID_LEN`].
        max: usize,
    },
    /// The id contains a character outside `[A-Za-z0-9_-]`
    /// (this excludes the key-expression metacharacters `/ * $ ? #`).
    #[error("{what} contains invalid character {ch:?} at byte {index}")]
    InvalidChar {
        /// Which id: `"spacecraft id"` or `"imu name"`.
        what: &'static str,
        /// The offending character.
        ch: char,
        /// Its byte offset in the id.
        index: usize,
    },
}
