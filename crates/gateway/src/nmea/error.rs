//! The errors of writing and reading NMEA sentences.

use thiserror::Error;

/// An input that cannot be written, or a sentence that does not read.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NmeaError {
    /// A talker id that is not two upper-case letters or digits.
    #[error("talker id `{0}`: must be two upper-case ASCII letters or digits (GP, GN, GL, …)")]
    Talker(String),
    /// A number that is NaN or infinite.
    #[error("{field} is {value}: a sentence needs a finite number")]
    NotFinite {
        /// The input field.
        field: &'static str,
        /// The value given.
        value: f64,
    },
    /// A number outside its field's range.
    #[error("{field} = {value} is outside {range}")]
    OutOfRange {
        /// The input field.
        field: &'static str,
        /// The value given.
        value: f64,
        /// The range allowed, in words.
        range: &'static str,
    },
    /// A year that the field cannot hold (ZDA: 4 digits; RMC: the date's 2 digits are written
    /// for any year from 0 to 9999).
    #[error("UTC year {year} is outside 0..=9999")]
    Year {
        /// The year.
        year: i32,
    },
    /// A decimal count above the style's limit.
    #[error("{field}: {decimals} decimals requested, at most {max}")]
    Decimals {
        /// The style field.
        field: &'static str,
        /// Decimals requested.
        decimals: u8,
        /// The limit.
        max: u8,
    },
    /// A sentence that does not start with `$`.
    #[error("sentence does not start with `$`: {0:?}")]
    NoDollar(String),
    /// A sentence with no `*hh` checksum.
    #[error("sentence has no `*hh` checksum: {0:?}")]
    NoChecksum(String),
    /// A checksum that is not two hex digits.
    #[error("checksum `{0}` is not two hex digits")]
    ChecksumDigits(String),
    /// A checksum that does not match the sentence.
    #[error(
        "checksum mismatch: the sentence says {stated:02X}, its characters give {computed:02X}"
    )]
    ChecksumMismatch {
        /// The sentence's checksum.
        stated: u8,
        /// The XOR of its characters.
        computed: u8,
    },
    /// A character outside printable ASCII.
    #[error("sentence has a character outside printable ASCII at {position}")]
    NotPrintable {
        /// Its index.
        position: usize,
    },
    /// An address that is not 5 characters (talker + formatter).
    #[error("address `{0}` is not a 2-character talker id and a 3-character formatter")]
    Address(String),
    /// A sentence with the wrong number of fields for its formatter.
    #[error("{formatter} sentence has {got} fields, expected {expected}")]
    FieldCount {
        /// The sentence formatter (GGA, RMC, ZDA).
        formatter: String,
        /// Fields expected (any of).
        expected: &'static str,
        /// Fields found.
        got: usize,
    },
    /// A field that does not parse.
    #[error("field {index} `{text}` is not a valid {what}")]
    Field {
        /// Its index after the address (0-based).
        index: usize,
        /// Its text.
        text: String,
        /// What it should be.
        what: &'static str,
    },
}
