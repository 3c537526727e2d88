//! Newline-terminated text lines (NMEA 0183 sentences, command consoles): a line ends at LF
//! (0x0A), and a CR (0x0D) just before it is dropped, so CRLF and LF endings both work. Empty
//! lines are ignored. A line longer than the maximum is dropped whole, counted once as oversize
//! when its LF arrives.

use super::accumulator::Accumulator;
use super::{DecodeCounters, FramingError, Malformed, StreamDecoder};

/// Carriage return.
pub const CR: u8 = b'\r';
/// Line feed.
pub const LF: u8 = b'\n';

/// The terminator the encoder writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineEnding {
    /// CR LF (NMEA 0183, IEC 61162-1).
    CrLf,
    /// LF alone.
    Lf,
}

/// Appends `line` and its terminator; a line holding a CR or LF is refused.
pub fn encode(line: &[u8], ending: LineEnding, out: &mut Vec<u8>) -> Result<(), FramingError> {
    if let Some(position) = line.iter().position(|&b| b == CR || b == LF) {
        let what = if line[position] == CR { "CR" } else { "LF" };
        return Err(FramingError::TerminatorInLine { what, position });
    }
    out.extend_from_slice(line);
    match ending {
        LineEnding::CrLf => out.extend_from_slice(&[CR, LF]),
        LineEnding::Lf => out.push(LF),
    }
    Ok(())
}

/// Incremental line decoder.
#[derive(Debug, Clone)]
pub struct LineDecoder {
    line: Accumulator,
    max_line_bytes: usize,
    counters: DecodeCounters,
}

impl LineDecoder {
    /// A decoder of lines up to `max_line_bytes` octets, terminator excluded.
    pub fn new(max_line_bytes: usize) -> Self {
        // One more octet for a CR before the LF.
        Self {
            line: Accumulator::new(max_line_bytes + 1),
            max_line_bytes,
            counters: DecodeCounters::default(),
        }
    }
}

impl StreamDecoder for LineDecoder {
    fn feed(&mut self, input: &[u8], on_frame: &mut dyn FnMut(&[u8])) {
        for &b in input {
            if b != LF {
                self.line.push(b);
                continue;
            }
            let Some(line) = self.line.end(&mut self.counters) else {
                continue;
            };
            let line = line.strip_suffix(&[CR]).unwrap_or(line);
            if line.len() > self.max_line_bytes {
                self.counters.record(Malformed::Oversize);
            } else if !line.is_empty() {
                on_frame(line);
                self.counters.frames += 1;
            }
        }
    }

    fn counters(&self) -> &DecodeCounters {
        &self.counters
    }

    fn pending_bytes(&self) -> usize {
        self.line.len()
    }
}
