//! The errors of Space Packets and CUC time codes.

use thiserror::Error;

/// A field out of its range, a packet that cannot be built, or octets that do not decode.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum CcsdsError {
    /// An APID above 11 bits.
    #[error(
        "APID {apid} is above 2047 (the 11-bit APID field of the Space Packet primary header)"
    )]
    Apid {
        /// The APID given.
        apid: u16,
    },
    /// A sequence count above 14 bits.
    #[error("sequence count {count} is above 16383 (the 14-bit packet sequence count)")]
    SequenceCount {
        /// The count given.
        count: u16,
    },
    /// A packet data field of no octet.
    #[error("the packet data field is empty: a Space Packet holds at least one octet of secondary header or user data")]
    EmptyDataField,
    /// A packet data field above 65536 octets.
    #[error("packet data field of {len_bytes} octets is above the 65536 the 16-bit data length (octets − 1) can count")]
    DataFieldTooLong {
        /// Octets of secondary header and user data.
        len_bytes: usize,
    },
    /// Fewer octets than the structure needs.
    #[error("{what} needs {needed_bytes} octets, {got_bytes} given")]
    TooShort {
        /// What was being decoded.
        what: &'static str,
        /// Octets needed.
        needed_bytes: usize,
        /// Octets given.
        got_bytes: usize,
    },
    /// A packet version number other than 0 (version 1 packets are the only ones defined).
    #[error("packet version number {version}: only 0 (binary 000, the Space Packet) is handled")]
    Version {
        /// The version read.
        version: u8,
    },
    /// CUC coarse time octets outside 1..=4.
    #[error("CUC coarse time of {octets} octets: 1 to 4 without a P-field extension (CCSDS 301.0-B-4 §3.2)")]
    CoarseOctets {
        /// Octets requested.
        octets: u8,
    },
    /// CUC fine time octets above 3.
    #[error("CUC fine time of {octets} octets: 0 to 3 without a P-field extension (CCSDS 301.0-B-4 §3.2)")]
    FineOctets {
        /// Octets requested.
        octets: u8,
    },
    /// A time before the epoch.
    #[error("time {time_ns} ns is before the epoch: CUC counts up from it")]
    NegativeTime {
        /// The time given, ns since the epoch.
        time_ns: i64,
    },
    /// A time beyond the coarse time's range.
    #[error("{seconds} s since the epoch does not fit {octets} octets of CUC coarse time")]
    CoarseOverflow {
        /// Whole seconds since the epoch.
        seconds: u64,
        /// Coarse octets.
        octets: u8,
    },
    /// A P-field that this codec does not read.
    #[error("CUC P-field {p_field:#04x}: {reason}")]
    PField {
        /// The octet read.
        p_field: u8,
        /// What is wrong with it.
        reason: &'static str,
    },
}
