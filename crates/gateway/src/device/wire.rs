//! [`Wire`]: a described device's framing, from a message payload to the octets on the
//! stream and back. Each variant is one of the crate's framings ([`crate::framing`],
//! [`super::ccsds_framing`]); SLIP and COBS carry the description's check (if any) after the
//! payload, as the last octets of the frame content.

use super::ccsds_framing::{CcsdsDecoder, CcsdsFraming, Unsendable};
use super::time::TickTime;
use crate::ccsds::{PacketType, PrimaryHeader};
use crate::framing::cobs::{self, CobsDecoder};
use crate::framing::hdlc::{HdlcDecoder, HdlcFraming};
use crate::framing::length::{LengthDecoder, LengthFraming};
use crate::framing::slip::{self, SlipDecoder};
use crate::framing::{DecodeCounters, FrameCheck, Malformed, StreamDecoder};

/// A device's framing.
#[derive(Debug, Clone, PartialEq)]
pub enum Wire {
    /// Sync octets, constant header octets, length field, payload, check.
    Length {
        /// The layout.
        framing: LengthFraming,
        /// The constant octets between sync and length field.
        header: Vec<u8>,
    },
    /// SLIP (RFC 1055), with an optional check after the payload.
    Slip(Option<FrameCheck>),
    /// COBS (Cheshire & Baker 1999), zero-delimited, with an optional check after the payload.
    Cobs(Option<FrameCheck>),
    /// HDLC-like (RFC 1662 §4.2) with an optional FCS.
    Hdlc(HdlcFraming),
    /// CCSDS Space Packets.
    Ccsds(CcsdsFraming),
}

/// What a received frame carries once unwrapped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unwrapped<'a> {
    /// The message payload (id first).
    pub payload: &'a [u8],
    /// The APID, for Space Packets.
    pub apid: Option<u16>,
}

impl Wire {
    /// The most octets a payload of `payload_len` octets takes on the wire.
    pub fn max_frame_len(&self, payload_len: usize) -> usize {
        match self {
            Wire::Length { framing, .. } => {
                framing.header_len() + payload_len + framing.check_len()
            }
            Wire::Slip(check) => 2 + 2 * (payload_len + check_len(check)),
            Wire::Cobs(check) => cobs::max_encoded_len(payload_len + check_len(check)) + 1,
            Wire::Hdlc(h) => 2 + 2 * (payload_len + check_len(&h.fcs)),
            Wire::Ccsds(c) => c.overhead() + payload_len,
        }
    }

    /// The fewest octets a frame of a `payload_len`-octet payload takes (for the bound on the
    /// responses a chunk of input can ask for).
    pub fn min_frame_len(&self, payload_len: usize) -> usize {
        match self {
            Wire::Length { framing, .. } => {
                framing.header_len() + payload_len + framing.check_len()
            }
            Wire::Slip(check) | Wire::Cobs(check) => 1 + payload_len + check_len(check),
            Wire::Hdlc(h) => 1 + payload_len + check_len(&h.fcs),
            Wire::Ccsds(c) => c.overhead() + payload_len,
        }
    }

    /// A stream decoder for frames of payloads up to `max_payload_len` octets (the one
    /// allocation of the receive path).
    pub fn decoder(&self, max_payload_len: usize) -> Box<dyn StreamDecoder + Send> {
        match self {
            Wire::Length { framing, .. } => Box::new(LengthDecoder::new(framing.clone())),
            Wire::Slip(check) => Box::new(SlipDecoder::new(max_payload_len + check_len(check))),
            Wire::Cobs(check) => Box::new(CobsDecoder::new(max_payload_len + check_len(check))),
            Wire::Hdlc(h) => Box::new(HdlcDecoder::new(h, max_payload_len)),
            Wire::Ccsds(c) => Box::new(CcsdsDecoder::new(c, self.max_frame_len(max_payload_len))),
        }
    }

    /// Appends `payload` framed. `apid` is the message's (Space Packets), `direction_out`
    /// chooses the packet type (telemetry for the device's outputs).
    pub fn encode(
        &mut self,
        payload: &[u8],
        apid: Option<u16>,
        direction_out: bool,
        now: &TickTime,
        out: &mut Vec<u8>,
    ) -> Result<(), Unsendable> {
        match self {
            Wire::Length { framing, header } => {
                framing.encode(header, payload, out).map_err(|_| Unsendable)
            }
            Wire::Slip(check) => {
                slip::encode(&with_check(payload, check.as_ref()), out);
                Ok(())
            }
            Wire::Cobs(check) => {
                cobs::encode(&with_check(payload, check.as_ref()), out);
                Ok(())
            }
            Wire::Hdlc(h) => {
                h.encode(payload, out);
                Ok(())
            }
            Wire::Ccsds(c) => {
                let packet_type = if direction_out {
                    PacketType::Telemetry
                } else {
                    PacketType::Telecommand
                };
                c.encode(apid.ok_or(Unsendable)?, packet_type, payload, now, out)
            }
        }
    }

    /// The payload of a frame the decoder delivered, after the checks the decoder does not
    /// make (SLIP's and COBS's check, the constant header octets, the Space Packet's type and
    /// secondary-header flag). A frame rejected for a framing reason is counted in `rejects`.
    pub fn unwrap<'a>(
        &self,
        frame: &'a [u8],
        rejects: &mut DecodeCounters,
    ) -> Result<Unwrapped<'a>, WireReject> {
        let plain = |payload| {
            Ok(Unwrapped {
                payload,
                apid: None,
            })
        };
        match self {
            Wire::Length { framing, header } => {
                let sync_len = framing.config().sync.len();
                if frame.get(sync_len..sync_len + header.len()) != Some(header.as_slice()) {
                    return Err(WireReject::BadConstant);
                }
                plain(framing.payload(frame))
            }
            Wire::Slip(None) | Wire::Cobs(None) | Wire::Hdlc(_) => plain(frame),
            Wire::Slip(Some(check)) | Wire::Cobs(Some(check)) => {
                if frame.len() < check.len_bytes() {
                    rejects.record(Malformed::BadLength);
                    return Err(WireReject::Counted);
                }
                match check.strip(frame) {
                    Some(payload) => plain(payload),
                    None => {
                        rejects.record(Malformed::BadChecksum);
                        Err(WireReject::Counted)
                    }
                }
            }
            Wire::Ccsds(c) => {
                let Ok(header) = PrimaryHeader::decode(frame) else {
                    rejects.record(Malformed::BadLength);
                    return Err(WireReject::Counted);
                };
                let secondary_len = c.secondary_len();
                if header.packet_type != PacketType::Telecommand
                    || header.secondary_header != (secondary_len > 0)
                {
                    return Err(WireReject::BadConstant);
                }
                let from = crate::ccsds::primary_header::PRIMARY_HEADER_BYTES + secondary_len;
                let to = frame.len().saturating_sub(c.check_len());
                Ok(Unwrapped {
                    payload: frame.get(from..to).unwrap_or_default(),
                    apid: Some(header.apid.get()),
                })
            }
        }
    }
}

/// Why [`Wire::unwrap`] refused a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WireReject {
    /// For a framing reason, already counted.
    Counted,
    /// A constant octet that differs from the description's.
    BadConstant,
}

fn check_len(check: &Option<FrameCheck>) -> usize {
    check.as_ref().map_or(0, FrameCheck::len_bytes)
}

/// The payload and its check octets, on the stack (payloads of described messages are
/// bounded by [`MAX_PAYLOAD_BYTES`]).
fn with_check(payload: &[u8], check: Option<&FrameCheck>) -> StackBytes {
    let mut bytes = StackBytes::default();
    bytes.extend(payload);
    if let Some(check) = check {
        let octets = check.octets(payload);
        bytes.extend(&octets[..check.len_bytes()]);
    }
    bytes
}

/// The longest payload a described message may have, in octets.
pub const MAX_PAYLOAD_BYTES: usize = 1024;

/// A payload and its check, on the stack.
struct StackBytes {
    bytes: [u8; MAX_PAYLOAD_BYTES + 4],
    len: usize,
}

impl Default for StackBytes {
    fn default() -> Self {
        Self {
            bytes: [0; MAX_PAYLOAD_BYTES + 4],
            len: 0,
        }
    }
}

impl StackBytes {
    fn extend(&mut self, more: &[u8]) {
        let room = self.bytes.len() - self.len;
        let n = more.len().min(room);
        self.bytes[self.len..self.len + n].copy_from_slice(&more[..n]);
        self.len += n;
    }
}

impl std::ops::Deref for StackBytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
}
