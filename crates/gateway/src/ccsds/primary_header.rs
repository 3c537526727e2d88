//! The Space Packet primary header, CCSDS 133.0-B-2 §4.1 (bit 0 is the most significant bit
//! of the first octet):
//!
//! ```text
//! bits 0–2   packet version number (000)
//! bit  3     packet type (0 telemetry, 1 telecommand)
//! bit  4     secondary header flag
//! bits 5–15  APID (11 bits)
//! bits 16–17 sequence flags (01 first, 00 continuation, 10 last, 11 unsegmented)
//! bits 18–31 packet sequence count (14 bits, modulo 16384)
//! bits 32–47 packet data length = octets of the packet data field − 1
//! ```

use super::CcsdsError;

/// Octets of the primary header.
pub const PRIMARY_HEADER_BYTES: usize = 6;

/// Packet type (bit 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PacketType {
    /// 0: telemetry (or reporting).
    Telemetry,
    /// 1: telecommand (or requesting).
    Telecommand,
}

/// Sequence flags (bits 16–17).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SequenceFlags {
    /// 00: a continuation segment of user data.
    Continuation,
    /// 01: the first segment.
    First,
    /// 10: the last segment.
    Last,
    /// 11: unsegmented user data.
    Unsegmented,
}

impl SequenceFlags {
    fn bits(self) -> u16 {
        match self {
            SequenceFlags::Continuation => 0b00,
            SequenceFlags::First => 0b01,
            SequenceFlags::Last => 0b10,
            SequenceFlags::Unsegmented => 0b11,
        }
    }

    fn from_bits(bits: u16) -> Self {
        match bits & 0b11 {
            0b00 => SequenceFlags::Continuation,
            0b01 => SequenceFlags::First,
            0b10 => SequenceFlags::Last,
            _ => SequenceFlags::Unsegmented,
        }
    }
}

/// An application process identifier, 0 to 2047 (2047 is the idle packet's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Apid(u16);

impl Apid {
    /// The largest APID.
    pub const MAX: u16 = 0x7FF;
    /// The APID of idle packets (all ones).
    pub const IDLE: Apid = Apid(0x7FF);

    /// An APID, refused above 2047.
    pub fn new(apid: u16) -> Result<Self, CcsdsError> {
        if apid > Self::MAX {
            return Err(CcsdsError::Apid { apid });
        }
        Ok(Apid(apid))
    }

    /// The value.
    pub fn get(self) -> u16 {
        self.0
    }
}

/// A packet sequence count, 0 to 16383.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct SequenceCount(u16);

impl SequenceCount {
    /// The largest count.
    pub const MAX: u16 = 0x3FFF;

    /// A count, refused above 16383.
    pub fn new(count: u16) -> Result<Self, CcsdsError> {
        if count > Self::MAX {
            return Err(CcsdsError::SequenceCount { count });
        }
        Ok(SequenceCount(count))
    }

    /// The value.
    pub fn get(self) -> u16 {
        self.0
    }

    /// The next count, modulo 16384 (16383 is followed by 0).
    pub fn next(self) -> Self {
        SequenceCount((self.0 + 1) & Self::MAX)
    }
}

/// The count of one APID's packets: each call to [`SequenceCounter::advance`] gives the count
/// of the next packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SequenceCounter {
    next: SequenceCount,
}

impl SequenceCounter {
    /// A counter whose first packet has count `first`.
    pub fn starting_at(first: SequenceCount) -> Self {
        Self { next: first }
    }

    /// The count of this packet; the counter moves to the next (wrapping after 16383).
    pub fn advance(&mut self) -> SequenceCount {
        let this = self.next;
        self.next = this.next();
        this
    }
}

/// A primary header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PrimaryHeader {
    /// Packet type.
    pub packet_type: PacketType,
    /// A secondary header follows.
    pub secondary_header: bool,
    /// APID.
    pub apid: Apid,
    /// Sequence flags.
    pub sequence_flags: SequenceFlags,
    /// Sequence count.
    pub sequence_count: SequenceCount,
    /// The packet data length field: octets of the packet data field − 1.
    pub data_length: u16,
}

impl PrimaryHeader {
    /// Octets of the packet data field (secondary header and user data).
    pub fn data_field_len(&self) -> usize {
        usize::from(self.data_length) + 1
    }

    /// Octets of the whole packet.
    pub fn packet_len(&self) -> usize {
        PRIMARY_HEADER_BYTES + self.data_field_len()
    }

    /// The six octets (version 0).
    pub fn encode(&self) -> [u8; PRIMARY_HEADER_BYTES] {
        let packet_type = match self.packet_type {
            PacketType::Telemetry => 0,
            PacketType::Telecommand => 1,
        };
        let id: u16 =
            (packet_type << 12) | (u16::from(self.secondary_header) << 11) | self.apid.get();
        let sequence: u16 = (self.sequence_flags.bits() << 14) | self.sequence_count.get();
        let [i0, i1] = id.to_be_bytes();
        let [s0, s1] = sequence.to_be_bytes();
        let [l0, l1] = self.data_length.to_be_bytes();
        [i0, i1, s0, s1, l0, l1]
    }

    /// Reads a header from the first six octets of `octets`.
    pub fn decode(octets: &[u8]) -> Result<Self, CcsdsError> {
        let &[i0, i1, s0, s1, l0, l1, ..] = octets else {
            return Err(CcsdsError::TooShort {
                what: "a Space Packet primary header",
                needed_bytes: PRIMARY_HEADER_BYTES,
                got_bytes: octets.len(),
            });
        };
        let id = u16::from_be_bytes([i0, i1]);
        let sequence = u16::from_be_bytes([s0, s1]);
        let version = (id >> 13) as u8;
        if version != 0 {
            return Err(CcsdsError::Version { version });
        }
        Ok(Self {
            packet_type: if id & (1 << 12) != 0 {
                PacketType::Telecommand
            } else {
                PacketType::Telemetry
            },
            secondary_header: id & (1 << 11) != 0,
            apid: Apid(id & Apid::MAX),
            sequence_flags: SequenceFlags::from_bits(sequence >> 14),
            sequence_count: SequenceCount(sequence & SequenceCount::MAX),
            data_length: u16::from_be_bytes([l0, l1]),
        })
    }
}
