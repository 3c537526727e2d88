//! The error of a checksum's parameters.

use thiserror::Error;

/// Parameters that describe no valid checksum.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ChecksumError {
    /// The CRC width is 0 or above 32 bits.
    #[error("CRC `{name}`: width {width_bits} bits is outside 1..=32")]
    Width {
        /// The CRC's name.
        name: &'static str,
        /// The width given.
        width_bits: u8,
    },
    /// A parameter has bits set above the CRC width.
    #[error("CRC `{name}`: {parameter} = {value:#x} does not fit in {width_bits} bits")]
    ParameterTooWide {
        /// The CRC's name.
        name: &'static str,
        /// `poly`, `init` or `xorout`.
        parameter: &'static str,
        /// The value given.
        value: u32,
        /// The CRC width.
        width_bits: u8,
    },
    /// The generator polynomial has no x⁰ term (an even `poly`): such a CRC misses every
    /// error confined to the last bit and is in no catalogue.
    #[error("CRC `{name}`: poly = {poly:#x} is even (no x^0 term)")]
    EvenPoly {
        /// The CRC's name.
        name: &'static str,
        /// The value given.
        poly: u32,
    },
}
