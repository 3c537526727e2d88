//! Consistent Overhead Byte Stuffing: S. Cheshire and M. Baker, "Consistent Overhead Byte
//! Stuffing", IEEE/ACM Transactions on Networking 7(2):159–172, 1999, §3.
//!
//! The payload, with a zero appended in thought, is cut after each zero and after every run of
//! 254 non-zero octets. Each block is sent as a code octet (its length + 1; 0xFF for a run of
//! 254 with no zero) followed by its non-zero octets; the zero that ends a block is implied by
//! a code below 0xFF. The encoded frame has no zero, so a 0x00 delimits frames (the paper's
//! §3 packet framing). Worst-case overhead: one octet per 254, plus one.

use super::accumulator::Accumulator;
use super::{DecodeCounters, Malformed, StreamDecoder};

/// Octets of the encoding of `payload_bytes` octets at most, delimiter excluded.
pub fn max_encoded_len(payload_bytes: usize) -> usize {
    payload_bytes + payload_bytes / 254 + 1
}

/// Appends `payload` COBS-encoded, then the 0x00 delimiter.
pub fn encode(payload: &[u8], out: &mut Vec<u8>) {
    let mut code_at = out.len();
    out.push(0);
    let mut code = 1u8;
    for &b in payload {
        if code == 0xFF {
            // A full block of 254 and more to come: close it (no implied zero) and open another.
            out[code_at] = code;
            code_at = out.len();
            out.push(0);
            code = 1;
        }
        if b == 0 {
            out[code_at] = code;
            code_at = out.len();
            out.push(0);
            code = 1;
        } else {
            out.push(b);
            code += 1;
        }
    }
    out[code_at] = code;
    out.push(0);
}

/// Decodes one frame (delimiter excluded) in place; returns the payload length, or `None` if a
/// block runs past the end or a code octet is zero.
pub fn decode_in_place(frame: &mut [u8]) -> Option<usize> {
    let (mut read, mut write) = (0, 0);
    while read < frame.len() {
        let code = usize::from(frame[read]);
        if code == 0 {
            return None;
        }
        let start = read + 1;
        let end = start + code - 1;
        if end > frame.len() {
            return None;
        }
        // `write` never passes `start`: each block gives at most one implied zero for its code.
        frame.copy_within(start..end, write);
        write += code - 1;
        read = end;
        if code < 0xFF && read < frame.len() {
            frame[write] = 0;
            write += 1;
        }
    }
    Some(write)
}

/// Incremental COBS decoder (frames delimited by 0x00).
#[derive(Debug, Clone)]
pub struct CobsDecoder {
    frame: Accumulator,
    max_payload_bytes: usize,
    counters: DecodeCounters,
}

impl CobsDecoder {
    /// A decoder of payloads up to `max_payload_bytes` octets.
    pub fn new(max_payload_bytes: usize) -> Self {
        Self {
            frame: Accumulator::new(max_encoded_len(max_payload_bytes)),
            max_payload_bytes,
            counters: DecodeCounters::default(),
        }
    }
}

impl StreamDecoder for CobsDecoder {
    fn feed(&mut self, input: &[u8], on_frame: &mut dyn FnMut(&[u8])) {
        for &b in input {
            if b != 0 {
                self.frame.push(b);
                continue;
            }
            let Some(encoded) = self.frame.end(&mut self.counters) else {
                continue;
            };
            match decode_in_place(encoded) {
                None => self.counters.record(Malformed::BadEncoding),
                Some(len) if len > self.max_payload_bytes => {
                    self.counters.record(Malformed::Oversize)
                }
                Some(len) => {
                    on_frame(&encoded[..len]);
                    self.counters.frames += 1;
                }
            }
        }
    }

    fn counters(&self) -> &DecodeCounters {
        &self.counters
    }

    fn pending_bytes(&self) -> usize {
        self.frame.len()
    }
}
