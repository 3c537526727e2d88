//! The length rule a decoder checks before handing bytes to bincode, and the trait every wire
//! message implements. Each message's sizes, length rule, checks and decoder are generated from
//! the wire table into `wire.rs`; this file is the machinery they use.

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::view::WirePrim;
use crate::{DecodeError, Header};

/// Largest panel-pair count a configuration may have (each pair is one effector).
pub const MAX_PANEL_PAIRS: usize = crate::MAX_EFFECTORS;
/// Offset of the u64 effector count in a [`crate::StateMsg`] (the name from before the wire
/// table; the table's is [`crate::STATE_EFFECTORS_COUNT_OFFSET`]).
pub const STATE_EFFECTOR_COUNT_OFFSET: usize = crate::STATE_EFFECTORS_COUNT_OFFSET;
/// Offset of the 8 CCSDS CUC octets in a [`crate::TimeMsg`] (the name from before the wire
/// table; the table's is [`crate::TIME_CUC_TAI_OFFSET`]).
pub const TIME_CUC_OFFSET: usize = crate::TIME_CUC_TAI_OFFSET;

/// How the total encoded length of a message type follows from its bytes.
#[derive(Clone, Copy, Debug)]
pub enum WireLayout {
    /// Always `len` bytes.
    Fixed {
        /// Encoded length (bytes).
        len: usize,
    },
    /// Nested variable-length lists: the length is found by walking the count
    /// prefixes (each bounded before it is used).
    Walked {
        /// Shortest possible encoding (bytes).
        min_len: usize,
        /// Returns the total length implied by the bytes, or why it cannot (without
        /// allocating: the in-place views walk on paths that allocate nothing).
        walk: fn(&[u8]) -> Result<usize, WalkError>,
    },
}

pub(crate) mod sealed {
    /// Only the messages of the wire table (`wire.rs`) implement [`super::WireMessage`].
    pub trait Sealed {}
}

/// A top-level message that can go on the wire: every message of the wire table, and only
/// those (the impls are generated into `wire.rs`).
pub trait WireMessage: Serialize + DeserializeOwned + sealed::Sealed {
    /// Type name used in error messages.
    const NAME: &'static str;
    /// Length rule for the encoding.
    const LAYOUT: WireLayout;
    /// Shortest possible encoding (bytes).
    const MIN_LEN: usize;

    /// The common header.
    fn header(&self) -> &Header;

    /// Semantic checks applied after decoding (and usable before sending): the decoder rules
    /// bincode does not apply (a bounded count, a text field's padding, finite numbers).
    /// Messages without such rules always pass.
    fn validate(&self) -> Result<(), DecodeError> {
        Ok(())
    }
}

/// Why a walk of the count prefixes stopped: the decoder's [`DecodeError`], not yet written
/// out (a view only needs its class, and must not allocate).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WalkError {
    /// The buffer ends first: [`DecodeError::Length`].
    Length {
        /// Bytes the walk needed.
        needed: usize,
        /// Bytes there are.
        actual: usize,
    },
    /// A count beyond its bound: [`DecodeError::Malformed`].
    Count {
        /// The vec (`inputs[].values`).
        what: &'static str,
        /// The count read.
        count: u64,
        /// Where it was read.
        at: usize,
        /// Its bound.
        max: usize,
    },
    /// A union tag that names no variant: [`DecodeError::Malformed`].
    Tag {
        /// The union field (`kind`).
        what: &'static str,
        /// The tag read.
        tag: u32,
        /// Where it was read.
        at: usize,
    },
}

impl From<WalkError> for DecodeError {
    fn from(e: WalkError) -> Self {
        match e {
            WalkError::Length { needed, actual } => DecodeError::Length { needed, actual },
            WalkError::Count {
                what,
                count,
                at,
                max,
            } => DecodeError::Malformed(format!(
                "{what} count {count} at offset {at} exceeds maximum {max}"
            )),
            WalkError::Tag { what, tag, at } => {
                DecodeError::Malformed(format!("unknown {what} tag {tag} at offset {at}"))
            }
        }
    }
}

/// A bounds-checked reader of count prefixes, for [`WireLayout::Walked`].
pub(crate) struct Walker<'b> {
    bytes: &'b [u8],
    at: usize,
}

impl<'b> Walker<'b> {
    /// A walker at byte `at` of `bytes`.
    pub(crate) fn at(bytes: &'b [u8], at: usize) -> Self {
        Self { bytes, at }
    }

    /// Where the walk has got to: the length implied so far.
    pub(crate) fn end(&self) -> usize {
        self.at
    }

    /// Skips `n` bytes; an error if the buffer ends first.
    pub(crate) fn skip(&mut self, n: usize) -> Result<(), WalkError> {
        let end = self.at.checked_add(n).ok_or(WalkError::Length {
            needed: usize::MAX,
            actual: self.bytes.len(),
        })?;
        if end > self.bytes.len() {
            return Err(WalkError::Length {
                needed: end,
                actual: self.bytes.len(),
            });
        }
        self.at = end;
        Ok(())
    }

    /// Reads a u64 LE count at the cursor and checks it against `max`.
    pub(crate) fn count(&mut self, what: &'static str, max: usize) -> Result<usize, WalkError> {
        let count = u64::read_le(self.bytes, self.at).ok_or(WalkError::Length {
            needed: self.at + 8,
            actual: self.bytes.len(),
        })?;
        if count > max as u64 {
            return Err(WalkError::Count {
                what,
                count,
                at: self.at,
                max,
            });
        }
        self.at += 8;
        Ok(count as usize)
    }

    /// Reads a count of at most `max` values of `size` bytes and skips them.
    pub(crate) fn values(
        &mut self,
        what: &'static str,
        max: usize,
        size: usize,
    ) -> Result<(), WalkError> {
        let n = self.count(what, max)?;
        self.skip(size * n)
    }
}

impl WireLayout {
    /// Total encoded length implied by `bytes` (which must start with a message
    /// of this layout), or the error to report. Never reads out of bounds.
    pub fn expected_len(&self, bytes: &[u8]) -> Result<usize, DecodeError> {
        match *self {
            WireLayout::Fixed { len } => Ok(len),
            WireLayout::Walked { walk, .. } => walk(bytes).map_err(DecodeError::from),
        }
    }
}
