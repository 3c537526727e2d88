//! The sentence envelope: `$`, address and fields, `*hh`, CR LF.

use std::fmt::Write;

use super::style::Talker;
use crate::checksum::sums::xor8;

/// Writes a sentence into `out` (appended): `start` opens it with `$` and the address,
/// [`SentenceWriter::finish`] closes it with the checksum and CR LF.
pub struct SentenceWriter<'a> {
    out: &'a mut String,
    start: usize,
}

impl<'a> SentenceWriter<'a> {
    /// Opens a sentence of `talker` and `formatter` (`GGA`, `RMC`, `ZDA`).
    pub fn start(out: &'a mut String, talker: Talker, formatter: &str) -> Self {
        let start = out.len();
        out.push('$');
        out.push_str(talker.as_str());
        out.push_str(formatter);
        Self { out, start }
    }

    /// Starts the next field (writes the comma) and returns the buffer to write it into.
    pub fn field(&mut self) -> &mut String {
        self.out.push(',');
        self.out
    }

    /// Writes `*hh` (the XOR of every character between `$` and `*`) and CR LF.
    pub fn finish(self) {
        let checksum = xor8(&self.out.as_bytes()[self.start + 1..]);
        let _ = write!(self.out, "*{checksum:02X}\r\n");
    }
}
