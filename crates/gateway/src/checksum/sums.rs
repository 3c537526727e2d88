//! The two simplest checks: the XOR of all octets (NMEA 0183's sentence checksum) and their sum modulo 256.

/// The XOR of every octet of `data`.
pub fn xor8(data: &[u8]) -> u8 {
    data.iter().fold(0, |acc, b| acc ^ b)
}

/// The sum of every octet of `data`, modulo 256.
pub fn sum8(data: &[u8]) -> u8 {
    data.iter().fold(0u8, |acc, &b| acc.wrapping_add(b))
}
