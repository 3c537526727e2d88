//! HDLC-like framing with octet stuffing, RFC 1662 ("PPP in HDLC-like Framing", 1994) §4.2.
//!
//! A frame is Flag (0x7E), the stuffed content, Flag. Stuffing: the Flag and the Control
//! Escape (0x7D) octets, and any octet below 0x20 whose bit is set in the Async-Control-
//! Character-Map (ACCM, RFC 1662 §7.1), are sent as 0x7D followed by the octet XOR 0x20. The
//! optional FCS (RFC 1662 §C: FCS-16 = CRC-16/IBM-SDLC, FCS-32 = CRC-32/ISO-HDLC, both sent
//! least significant octet first) is computed over the content before stuffing and stuffed with
//! it. The decoder ignores empty frames (a flag may close one frame and open the next), counts
//! 0x7D then Flag as an abort (§4.2), and counts the octets before the first flag as garbage.
//! It does not drop unescaped control characters (§7.1 lets a receiver do so); the address
//! and control fields, if any, are the caller's content.

use super::unstuffer::{Stuffing, Unstuffer};
use super::{DecodeCounters, FrameCheck, Malformed, StreamDecoder};

/// Flag sequence.
pub const FLAG: u8 = 0x7E;
/// Control escape.
pub const ESCAPE: u8 = 0x7D;
/// XORed into an escaped octet.
pub const ESCAPE_XOR: u8 = 0x20;

/// The framing's parameters.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HdlcFraming {
    /// The frame check sequence, if any.
    pub fcs: Option<FrameCheck>,
    /// Octets below 0x20 to escape when sending: bit `n` escapes octet `n`. RFC 1662's default
    /// is `0xFFFF_FFFF` (all of them).
    pub accm: u32,
}

impl HdlcFraming {
    /// Appends `content` as one frame: Flag, stuffed content and FCS, Flag.
    pub fn encode(&self, content: &[u8], out: &mut Vec<u8>) {
        out.push(FLAG);
        let (fcs, fcs_len) = match &self.fcs {
            Some(check) => (check.octets(content), check.len_bytes()),
            None => ([0; 4], 0),
        };
        for &b in content.iter().chain(&fcs[..fcs_len]) {
            let control = b < 0x20 && self.accm & (1 << b) != 0;
            if b == FLAG || b == ESCAPE || control {
                out.extend_from_slice(&[ESCAPE, b ^ ESCAPE_XOR]);
            } else {
                out.push(b);
            }
        }
        out.push(FLAG);
    }
}

/// RFC 1662's stuffing: 0x7D then the octet XOR 0x20; 0x7D then the flag aborts the frame.
#[derive(Debug, Clone, Copy)]
pub struct Hdlc;

impl Stuffing for Hdlc {
    const DELIMITER: u8 = FLAG;
    const ESCAPE: u8 = ESCAPE;
    const ESCAPED_DELIMITER: Malformed = Malformed::Aborted;

    fn unescape(octet: u8) -> Option<u8> {
        Some(octet ^ ESCAPE_XOR)
    }
}

/// Incremental decoder of HDLC-like frames.
#[derive(Debug, Clone)]
pub struct HdlcDecoder {
    fcs: Option<FrameCheck>,
    frame: Unstuffer<Hdlc>,
    /// No flag seen yet: octets are garbage.
    hunting: bool,
    counters: DecodeCounters,
}

impl HdlcDecoder {
    /// A decoder of frames whose content (FCS excluded) is up to `max_content_bytes` octets.
    pub fn new(framing: &HdlcFraming, max_content_bytes: usize) -> Self {
        let fcs_len = framing.fcs.as_ref().map_or(0, FrameCheck::len_bytes);
        Self {
            fcs: framing.fcs.clone(),
            frame: Unstuffer::new(max_content_bytes + fcs_len),
            hunting: true,
            counters: DecodeCounters::default(),
        }
    }
}

impl StreamDecoder for HdlcDecoder {
    fn feed(&mut self, input: &[u8], on_frame: &mut dyn FnMut(&[u8])) {
        for &b in input {
            if self.hunting {
                if b == FLAG {
                    self.hunting = false;
                } else {
                    self.counters.garbage_bytes += 1;
                }
                continue;
            }
            let Some(frame) = self.frame.push(b, &mut self.counters) else {
                continue;
            };
            let content = match &self.fcs {
                None => Ok(&*frame),
                Some(check) if frame.len() < check.len_bytes() => Err(Malformed::BadLength),
                Some(check) => check.strip(frame).ok_or(Malformed::BadChecksum),
            };
            match content {
                Ok(content) => {
                    on_frame(content);
                    self.counters.frames += 1;
                }
                Err(reason) => self.counters.record(reason),
            }
        }
    }

    fn counters(&self) -> &DecodeCounters {
        &self.counters
    }

    fn pending_bytes(&self) -> usize {
        self.frame.pending_bytes()
    }
}
