//! The receive side of byte stuffing, shared by SLIP (RFC 1055) and HDLC-like framing (RFC
//! 1662 §4.2): a delimiter octet ends a frame, an escape octet gives the next one another
//! meaning, and a frame's unescaped octets are gathered up to the decoder's capacity.

use std::marker::PhantomData;

use super::accumulator::Accumulator;
use super::{DecodeCounters, Malformed};

/// A byte-stuffing scheme.
pub trait Stuffing {
    /// Ends a frame.
    const DELIMITER: u8;
    /// Gives the next octet another meaning.
    const ESCAPE: u8;
    /// What an escape followed by the delimiter means (SLIP: a bad escape; HDLC: an abort).
    const ESCAPED_DELIMITER: Malformed;

    /// The octet an escaped `octet` stands for, or `None` if it may not follow the escape.
    fn unescape(octet: u8) -> Option<u8>;
}

/// One frame being unstuffed.
#[derive(Debug, Clone)]
pub struct Unstuffer<S> {
    frame: Accumulator,
    escaped: bool,
    scheme: PhantomData<S>,
}

impl<S: Stuffing> Unstuffer<S> {
    /// Frames of up to `capacity` unescaped octets.
    pub fn new(capacity: usize) -> Self {
        Self {
            frame: Accumulator::new(capacity),
            escaped: false,
            scheme: PhantomData,
        }
    }

    /// Takes one octet. At a delimiter, returns the frame it ends if that frame is clean and
    /// not empty (a faulty frame is counted in `counters` instead).
    pub fn push(&mut self, octet: u8, counters: &mut DecodeCounters) -> Option<&mut [u8]> {
        let escaped = std::mem::take(&mut self.escaped);
        if octet == S::DELIMITER {
            if escaped {
                self.frame.poison(S::ESCAPED_DELIMITER);
            }
            return self.frame.end(counters);
        }
        if escaped {
            match S::unescape(octet) {
                Some(original) => self.frame.push(original),
                None => self.frame.poison(Malformed::BadEscape),
            }
        } else if octet == S::ESCAPE {
            self.escaped = true;
        } else {
            self.frame.push(octet);
        }
        None
    }

    /// Octets held of the frame not yet ended (an escape pending counts as one).
    pub fn pending_bytes(&self) -> usize {
        self.frame.len() + usize::from(self.escaped)
    }
}
