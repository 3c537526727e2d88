//! SLIP, "A Nonstandard for Transmission of IP Datagrams over Serial Lines" (RFC 1055, 1988).
//!
//! A frame ends with END (0xC0); an END or ESC (0xDB) octet in the payload is sent as ESC
//! ESC_END (0xDB 0xDC) or ESC ESC_ESC (0xDB 0xDD). The encoder also sends an END before the
//! frame, as RFC 1055's `send_packet` suggests, to flush line noise into an empty frame, which
//! the decoder ignores. An ESC followed by anything but ESC_END or ESC_ESC is a protocol
//! violation the RFC leaves to the implementation: here the frame is rejected (bad escape).

use super::unstuffer::{Stuffing, Unstuffer};
use super::{DecodeCounters, Malformed, StreamDecoder};

/// Frame end.
pub const END: u8 = 0xC0;
/// Escape.
pub const ESC: u8 = 0xDB;
/// Escaped END.
pub const ESC_END: u8 = 0xDC;
/// Escaped ESC.
pub const ESC_ESC: u8 = 0xDD;

/// Appends `payload` as one SLIP frame: END, the escaped payload, END.
pub fn encode(payload: &[u8], out: &mut Vec<u8>) {
    out.push(END);
    for &b in payload {
        match b {
            END => out.extend_from_slice(&[ESC, ESC_END]),
            ESC => out.extend_from_slice(&[ESC, ESC_ESC]),
            _ => out.push(b),
        }
    }
    out.push(END);
}

/// SLIP's stuffing: ESC ESC_END for END, ESC ESC_ESC for ESC, nothing else after ESC.
#[derive(Debug, Clone, Copy)]
pub struct Slip;

impl Stuffing for Slip {
    const DELIMITER: u8 = END;
    const ESCAPE: u8 = ESC;
    const ESCAPED_DELIMITER: Malformed = Malformed::BadEscape;

    fn unescape(octet: u8) -> Option<u8> {
        match octet {
            ESC_END => Some(END),
            ESC_ESC => Some(ESC),
            _ => None,
        }
    }
}

/// Incremental SLIP decoder.
#[derive(Debug, Clone)]
pub struct SlipDecoder {
    frame: Unstuffer<Slip>,
    counters: DecodeCounters,
}

impl SlipDecoder {
    /// A decoder of payloads up to `max_payload_bytes` octets.
    pub fn new(max_payload_bytes: usize) -> Self {
        Self {
            frame: Unstuffer::new(max_payload_bytes),
            counters: DecodeCounters::default(),
        }
    }
}

impl StreamDecoder for SlipDecoder {
    fn feed(&mut self, input: &[u8], on_frame: &mut dyn FnMut(&[u8])) {
        for &b in input {
            if let Some(payload) = self.frame.push(b, &mut self.counters) {
                on_frame(payload);
                self.counters.frames += 1;
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
