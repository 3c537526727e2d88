//! Fletcher's checksums (J. G. Fletcher, "An arithmetic checksum for serial transmissions",
//! IEEE Trans. Commun. 30(1), 1982; RFC 1146 appendix for the 8-bit form). Two running sums,
//! both modulo 2^k − 1: `a = Σ dᵢ`, `b = Σ a` after each block; the checksum is `b << k | a`.

use crate::ByteOrder;

/// Fletcher-16: 8-bit blocks, sums modulo 255, `b << 8 | a`.
pub fn fletcher16(data: &[u8]) -> u16 {
    let (a, b) = data.iter().fold((0u32, 0u32), |(a, b), &d| {
        let a = (a + u32::from(d)) % 255;
        (a, (b + a) % 255)
    });
    ((b << 8) | a) as u16
}

/// Fletcher-32: 16-bit blocks read in `order` (a last odd octet is padded with a zero octet),
/// sums modulo 65535, `b << 16 | a`. Wikipedia's test vectors use little-endian blocks.
pub fn fletcher32(data: &[u8], order: ByteOrder) -> u32 {
    let (a, b) = data.chunks(2).fold((0u32, 0u32), |(a, b), pair| {
        let block = match (order, pair) {
            (ByteOrder::LittleEndian, [lo, hi]) | (ByteOrder::BigEndian, [hi, lo]) => {
                u32::from(*hi) << 8 | u32::from(*lo)
            }
            (ByteOrder::LittleEndian, [lo]) => u32::from(*lo),
            (ByteOrder::BigEndian, [hi]) => u32::from(*hi) << 8,
            _ => 0,
        };
        let a = (a + block) % 65535;
        (a, (b + a) % 65535)
    });
    (b << 16) | a
}
