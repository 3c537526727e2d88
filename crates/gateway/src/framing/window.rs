//! The fixed-capacity stream window of the decoders that parse in place (sync-and-length, and
//! the device CCSDS Space Packet decoder): the octets received and not yet decided, between a
//! start and an end in a buffer allocated once.

/// Octets of the stream not yet consumed, at most the capacity given at construction.
#[derive(Debug, Clone)]
pub struct Window {
    bytes: Box<[u8]>,
    start: usize,
    end: usize,
}

impl Window {
    /// A window of `capacity` octets (allocated here, and only here).
    pub fn new(capacity: usize) -> Self {
        Self {
            bytes: vec![0; capacity].into_boxed_slice(),
            start: 0,
            end: 0,
        }
    }

    /// The most octets the window holds.
    pub fn capacity(&self) -> usize {
        self.bytes.len()
    }

    /// Copies as much of `input` as fits and advances `input` past it; returns how many octets
    /// were taken. When the buffer's end is reached, the pending octets are first moved to its
    /// front.
    pub fn fill_from(&mut self, input: &mut &[u8]) -> usize {
        if self.end == self.bytes.len() {
            self.bytes.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
        }
        let take = input.len().min(self.bytes.len() - self.end);
        self.bytes[self.end..self.end + take].copy_from_slice(&input[..take]);
        self.end += take;
        *input = &input[take..];
        take
    }

    /// The octets received and not yet consumed.
    pub fn pending(&self) -> &[u8] {
        &self.bytes[self.start..self.end]
    }

    /// Drops the first `n` pending octets (`n` ≤ `pending().len()`); once none is pending, the
    /// window starts again at the buffer's front.
    pub fn consume(&mut self, n: usize) {
        debug_assert!(n <= self.end - self.start);
        self.start += n;
        if self.start == self.end {
            self.start = 0;
            self.end = 0;
        }
    }
}
