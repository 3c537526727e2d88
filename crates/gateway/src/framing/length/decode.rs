//! The sync-and-length decoder.
//!
//! The stream is held in a window of `max_frame_bytes` octets. From the window's start:
//! 1. while the start does not match the sync pattern (as far as octets have arrived), one
//!    octet is dropped as garbage;
//! 2. once the header has arrived, the length field gives the frame length; an impossible one
//!    (bad length, oversize) rejects the candidate;
//! 3. once the frame has arrived, the check is verified; a mismatch rejects it;
//! 4. a good frame is delivered whole (sync to check) and skipped.
//!
//! A rejected candidate is counted once for its reason and only its first octet is dropped:
//! the rest is searched again for a sync pattern, so a frame that starts inside a corrupted
//! or truncated one is still found (the octets skipped on the way count as garbage). Each
//! decision waits for the octets it needs and depends on nothing else, so the chunking of the
//! input cannot change the outcome.

use super::LengthFraming;
use crate::framing::window::Window;
use crate::framing::{DecodeCounters, StreamDecoder};

/// Incremental decoder of a [`LengthFraming`].
#[derive(Debug, Clone)]
pub struct LengthDecoder {
    framing: LengthFraming,
    window: Window,
    counters: DecodeCounters,
}

impl LengthDecoder {
    /// A decoder with a window of the framing's maximum frame length (allocated here only).
    pub fn new(framing: LengthFraming) -> Self {
        let window = Window::new(framing.config().max_frame_bytes);
        Self {
            framing,
            window,
            counters: DecodeCounters::default(),
        }
    }

    /// The framing decoded.
    pub fn framing(&self) -> &LengthFraming {
        &self.framing
    }

    /// Takes every decision the octets in the window allow.
    fn parse(&mut self, on_frame: &mut dyn FnMut(&[u8])) {
        let config = self.framing.config();
        let sync = config.sync.as_slice();
        let field = config.length;
        let header_len = self.framing.header_len();
        loop {
            let pending = self.window.pending();
            let seen = pending.len().min(sync.len());
            if pending[..seen] != sync[..seen] {
                self.counters.garbage_bytes += 1;
                self.window.consume(1);
                continue;
            }
            if pending.len() < header_len {
                return;
            }
            let value = field
                .order
                .read_uint(&pending[field.offset_bytes..header_len]);
            let frame_len = match self.framing.frame_len_of(value) {
                Ok(len) => len,
                Err(reason) => {
                    self.counters.record(reason);
                    self.window.consume(1);
                    continue;
                }
            };
            if pending.len() < frame_len {
                return;
            }
            let frame = &pending[..frame_len];
            let good = config.check.as_ref().is_none_or(|check| {
                let content_end = frame_len - check.len_bytes();
                check.verify(
                    &frame[config.check_from_bytes..content_end],
                    &frame[content_end..],
                )
            });
            if good {
                on_frame(frame);
                self.counters.frames += 1;
                self.window.consume(frame_len);
            } else {
                self.counters.bad_checksum += 1;
                self.window.consume(1);
            }
        }
    }
}

impl StreamDecoder for LengthDecoder {
    fn feed(&mut self, mut input: &[u8], on_frame: &mut dyn FnMut(&[u8])) {
        while !input.is_empty() {
            self.window.fill_from(&mut input);
            self.parse(on_frame);
        }
    }

    fn counters(&self) -> &DecodeCounters {
        &self.counters
    }

    fn pending_bytes(&self) -> usize {
        self.window.pending().len()
    }
}
