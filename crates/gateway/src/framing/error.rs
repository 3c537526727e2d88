//! The errors of a framing's configuration and of encoding.

use thiserror::Error;

/// A framing that cannot be built, or a payload it cannot carry.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum FramingError {
    /// Sync-and-length framing without sync octets: the decoder could not find a frame start.
    #[error("the sync pattern is empty: a frame start could not be found in a stream")]
    EmptySync,
    /// A length field of another width than 1, 2 or 4 octets.
    #[error("length field width {width_bytes} octets: must be 1, 2 or 4")]
    LengthWidth {
        /// The width given.
        width_bytes: usize,
    },
    /// The length field would overlap the sync octets.
    #[error("length field at offset {offset_bytes} overlaps the {sync_len_bytes} sync octets")]
    LengthInsideSync {
        /// The field's offset from the frame start.
        offset_bytes: usize,
        /// Sync octets.
        sync_len_bytes: usize,
    },
    /// The check's coverage starts after the header.
    #[error("check coverage starts at offset {check_from_bytes}, after the {header_len_bytes}-octet header")]
    CheckFromBeyondHeader {
        /// The coverage start given.
        check_from_bytes: usize,
        /// Octets of sync, header and length field.
        header_len_bytes: usize,
    },
    /// The maximum frame length cannot hold even an empty payload.
    #[error("maximum frame length {max_bytes} octets is below the {min_bytes} octets of header and check")]
    MaxFrameTooSmall {
        /// The maximum given.
        max_bytes: usize,
        /// Header and check octets.
        min_bytes: usize,
    },
    /// The header octets given to the encoder are not the number between sync and length.
    #[error("header of {got_bytes} octets given, the framing has {expected_bytes} between sync and length field")]
    HeaderLength {
        /// Octets expected.
        expected_bytes: usize,
        /// Octets given.
        got_bytes: usize,
    },
    /// The payload makes a frame longer than the framing allows.
    #[error("payload of {payload_bytes} octets makes a {frame_bytes}-octet frame, above the maximum {max_bytes}")]
    PayloadTooLong {
        /// Payload octets.
        payload_bytes: usize,
        /// Frame octets it would make.
        frame_bytes: usize,
        /// The framing's maximum.
        max_bytes: usize,
    },
    /// The length to write does not fit the length field.
    #[error("length value {value} does not fit a {width_bytes}-octet length field")]
    LengthDoesNotFit {
        /// The value to write (after the adjustment).
        value: i128,
        /// The field's width.
        width_bytes: usize,
    },
    /// A text line to send contains a line terminator.
    #[error("line contains a {what} at octet {position}: it would end the line early")]
    TerminatorInLine {
        /// `CR` or `LF`.
        what: &'static str,
        /// Its index in the line.
        position: usize,
    },
}
