//! The decoders' tallies of accepted frames and of malformed input by reason.

/// Why a frame was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Malformed {
    /// Its check value does not match its content.
    BadChecksum,
    /// Its length field (or its length, for a framing without one) is impossible: shorter than
    /// the header and check it must hold.
    BadLength,
    /// Longer than the decoder's capacity (a length field beyond it, or a delimiter not seen
    /// within it).
    Oversize,
    /// An escape octet followed by an octet that may not follow it (SLIP).
    BadEscape,
    /// Not a valid encoding (COBS: a block that runs past the frame's end).
    BadEncoding,
    /// Aborted by the sender (HDLC: escape then flag, RFC 1662 §4.2).
    Aborted,
}

/// Frames accepted and input rejected since construction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DecodeCounters {
    /// Frames delivered.
    pub frames: u64,
    /// Octets skipped outside any frame while looking for one (before a sync pattern or the
    /// first flag).
    pub garbage_bytes: u64,
    /// Frames rejected for [`Malformed::BadChecksum`].
    pub bad_checksum: u64,
    /// Frames rejected for [`Malformed::BadLength`].
    pub bad_length: u64,
    /// Frames rejected for [`Malformed::Oversize`].
    pub oversize: u64,
    /// Frames rejected for [`Malformed::BadEscape`].
    pub bad_escape: u64,
    /// Frames rejected for [`Malformed::BadEncoding`].
    pub bad_encoding: u64,
    /// Frames rejected for [`Malformed::Aborted`].
    pub aborted: u64,
}

impl DecodeCounters {
    /// Counts one rejected frame.
    pub fn record(&mut self, reason: Malformed) {
        let counter = match reason {
            Malformed::BadChecksum => &mut self.bad_checksum,
            Malformed::BadLength => &mut self.bad_length,
            Malformed::Oversize => &mut self.oversize,
            Malformed::BadEscape => &mut self.bad_escape,
            Malformed::BadEncoding => &mut self.bad_encoding,
            Malformed::Aborted => &mut self.aborted,
        };
        *counter += 1;
    }

    /// Frames rejected, all reasons together.
    pub fn rejected_frames(&self) -> u64 {
        self.bad_checksum
            + self.bad_length
            + self.oversize
            + self.bad_escape
            + self.bad_encoding
            + self.aborted
    }
}
