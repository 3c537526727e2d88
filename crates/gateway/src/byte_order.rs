//! Byte order of multi-octet integers on the wire, and the reading and writing of unsigned
//! integers of 1 to 8 octets in either order.

/// The order in which the octets of a multi-octet integer are sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ByteOrder {
    /// Most significant octet first ("network order"; CCSDS, NMEA's hex digits).
    BigEndian,
    /// Least significant octet first (RFC 1662's FCS, most vendor UART protocols on x86/ARM).
    LittleEndian,
}

impl ByteOrder {
    /// Writes the low `dest.len()` octets of `value` (at most 8) into `dest` in this order.
    pub fn put_uint(self, value: u64, dest: &mut [u8]) {
        let width = dest.len().min(8);
        for (i, slot) in dest.iter_mut().take(width).enumerate() {
            let shift = match self {
                ByteOrder::BigEndian => 8 * (width - 1 - i),
                ByteOrder::LittleEndian => 8 * i,
            };
            *slot = (value >> shift) as u8;
        }
    }

    /// Appends the low `width_bytes` octets of `value` (at most 8) in this order.
    pub fn write_uint(self, value: u64, width_bytes: usize, out: &mut Vec<u8>) {
        let mut octets = [0u8; 8];
        let octets = &mut octets[..width_bytes.min(8)];
        self.put_uint(value, octets);
        out.extend_from_slice(octets);
    }

    /// Reads an unsigned integer from all of `bytes` (at most 8 are used) in this order.
    pub fn read_uint(self, bytes: &[u8]) -> u64 {
        let bytes = &bytes[..bytes.len().min(8)];
        let fold = |acc: u64, b: &u8| (acc << 8) | u64::from(*b);
        match self {
            ByteOrder::BigEndian => bytes.iter().fold(0, fold),
            ByteOrder::LittleEndian => bytes.iter().rev().fold(0, fold),
        }
    }
}
