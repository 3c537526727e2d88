//! [`Checksum`]: one check chosen at run time, as a device description names it.

use super::fletcher::{fletcher16, fletcher32};
use super::sums::{sum8, xor8};
use super::Crc;
use crate::ByteOrder;

/// A check over a byte string, with its width on the wire.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Checksum {
    /// A CRC (boxed: its table is 1 KiB).
    Crc(Box<Crc>),
    /// XOR of all octets, 1 octet.
    Xor8,
    /// Sum of all octets modulo 256, 1 octet.
    Sum8,
    /// Fletcher-16, 2 octets.
    Fletcher16,
    /// Fletcher-32 over 16-bit blocks in this order, 4 octets.
    Fletcher32(ByteOrder),
}

impl Checksum {
    /// Octets the value takes on the wire.
    pub fn width_bytes(&self) -> usize {
        match self {
            Checksum::Crc(crc) => crc.width_bytes(),
            Checksum::Xor8 | Checksum::Sum8 => 1,
            Checksum::Fletcher16 => 2,
            Checksum::Fletcher32(_) => 4,
        }
    }

    /// The check value of `data`.
    pub fn compute(&self, data: &[u8]) -> u32 {
        match self {
            Checksum::Crc(crc) => crc.checksum(data),
            Checksum::Xor8 => u32::from(xor8(data)),
            Checksum::Sum8 => u32::from(sum8(data)),
            Checksum::Fletcher16 => u32::from(fletcher16(data)),
            Checksum::Fletcher32(order) => fletcher32(data, *order),
        }
    }
}
