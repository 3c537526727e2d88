//! CCSDS Space Packets and CCSDS Unsegmented Time Codes.
//!
//! - [`primary_header`]: the 6-octet Space Packet primary header (CCSDS 133.0-B-2, "Space
//!   Packet Protocol", Blue Book issue 2, June 2020, §4.1), its fields' types, and the
//!   per-APID sequence counter;
//! - [`packet`]: a whole packet from a [`PacketTemplate`] (type, APID, flags), its sequence
//!   count, an optional secondary header and the user data, with the data length computed;
//! - [`cuc`]: the CCSDS Unsegmented time Code (CCSDS 301.0-B-4, "Time Code Formats", 2010,
//!   §3.2) from integer nanoseconds since an epoch, with or without its P-field, as a
//!   packet's secondary header;
//! - [`error`] holds [`CcsdsError`].

pub mod cuc;
pub mod error;
pub mod packet;
pub mod primary_header;

pub use cuc::{CucEpoch, CucFormat, CucTime};
pub use error::CcsdsError;
pub use packet::PacketTemplate;
pub use primary_header::{
    Apid, PacketType, PrimaryHeader, SequenceCount, SequenceCounter, SequenceFlags,
};
