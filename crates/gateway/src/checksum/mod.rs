//! Checksums and CRCs of byte strings.
//!
//! - [`crc`]: a CRC of any width from 1 to 32 bits in the Rocksoft™ model of Williams (1993),
//!   table-driven, with the named presets of [`presets`];
//! - [`sums`]: the 8-bit XOR (NMEA 0183's checksum) and the 8-bit modular sum;
//! - [`fletcher`]: Fletcher-16 and Fletcher-32;
//! - [`kind`]: [`Checksum`], one of the above chosen at run time (by a device description).

pub mod crc;
pub mod error;
pub mod fletcher;
pub mod kind;
pub mod presets;
pub mod sums;

pub use crc::{Crc, CrcParams};
pub use error::ChecksumError;
pub use kind::Checksum;
