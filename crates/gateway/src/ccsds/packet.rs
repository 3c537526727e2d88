//! A whole Space Packet (CCSDS 133.0-B-2 §4.1): primary header, then the packet data field of
//! an optional secondary header and the user data, at least 1 and at most 65536 octets.

use super::primary_header::{Apid, PacketType, PrimaryHeader, SequenceCount, SequenceFlags};
use super::CcsdsError;

/// The largest packet data field: the 16-bit data length counts octets − 1.
pub const MAX_DATA_FIELD_BYTES: usize = 65536;

/// What the packets of one stream share: type, APID and sequence flags. Each packet adds its
/// sequence count, secondary header and user data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PacketTemplate {
    /// Packet type.
    pub packet_type: PacketType,
    /// APID.
    pub apid: Apid,
    /// Sequence flags.
    pub sequence_flags: SequenceFlags,
}

impl PacketTemplate {
    /// Appends a packet: the primary header (the secondary header flag set if
    /// `secondary_header` is not empty, the data length computed), the secondary header and
    /// the user data; returns the header written. Nothing is appended on error.
    pub fn encode(
        &self,
        sequence_count: SequenceCount,
        secondary_header: &[u8],
        user_data: &[u8],
        out: &mut Vec<u8>,
    ) -> Result<PrimaryHeader, CcsdsError> {
        let len_bytes = secondary_header.len() + user_data.len();
        if len_bytes == 0 {
            return Err(CcsdsError::EmptyDataField);
        }
        if len_bytes > MAX_DATA_FIELD_BYTES {
            return Err(CcsdsError::DataFieldTooLong { len_bytes });
        }
        let header = PrimaryHeader {
            packet_type: self.packet_type,
            secondary_header: !secondary_header.is_empty(),
            apid: self.apid,
            sequence_flags: self.sequence_flags,
            sequence_count,
            // 1 ≤ len_bytes ≤ 65536, so len_bytes − 1 fits 16 bits.
            data_length: (len_bytes - 1) as u16,
        };
        out.extend_from_slice(&header.encode());
        out.extend_from_slice(secondary_header);
        out.extend_from_slice(user_data);
        Ok(header)
    }
}
