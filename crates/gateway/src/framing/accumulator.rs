//! The fixed-capacity buffer of the delimiter-based decoders (SLIP, COBS, HDLC, lines): octets
//! of the current frame up to the next delimiter, and the first fault seen in it.

use super::{DecodeCounters, Malformed};

/// One frame's octets, at most the capacity given at construction.
#[derive(Debug, Clone)]
pub struct Accumulator {
    bytes: Box<[u8]>,
    len: usize,
    fault: Option<Malformed>,
}

impl Accumulator {
    /// A buffer of `capacity` octets (allocated here, and only here).
    pub fn new(capacity: usize) -> Self {
        Self {
            bytes: vec![0; capacity].into_boxed_slice(),
            len: 0,
            fault: None,
        }
    }

    /// Appends an octet; past the capacity the frame is marked oversize and the octet dropped.
    pub fn push(&mut self, byte: u8) {
        if self.fault.is_some() {
            return;
        }
        match self.bytes.get_mut(self.len) {
            Some(slot) => {
                *slot = byte;
                self.len += 1;
            }
            None => self.fault = Some(Malformed::Oversize),
        }
    }

    /// Marks the current frame as malformed (the first fault is the one counted).
    pub fn poison(&mut self, reason: Malformed) {
        self.fault.get_or_insert(reason);
    }

    /// Octets held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Nothing held.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Ends the frame at a delimiter and starts the next one. Returns the frame's octets if it
    /// is clean and not empty; a faulty frame is counted in `counters` and yields `None`, and
    /// an empty one (back-to-back delimiters) is ignored.
    pub fn end(&mut self, counters: &mut DecodeCounters) -> Option<&mut [u8]> {
        let len = std::mem::take(&mut self.len);
        if let Some(reason) = self.fault.take() {
            counters.record(reason);
            return None;
        }
        (len > 0).then(|| &mut self.bytes[..len])
    }
}
