//! Sync-and-length framing, the shape of most vendor binary protocols on RS-422/UART:
//!
//! ```text
//! | sync (1..) | header (0..) | length field (1, 2 or 4) | payload | check (0..4) |
//! ^ frame start                                                  covered from `check_from`
//! ```
//!
//! The length field's value, plus `adjust`, counts what [`LengthCounts`] says (CCSDS-style
//! "octets − 1" is `adjust = 1`). The check, if any, covers the frame from `check_from` (an
//! offset from the frame start, 0 to include the sync) to the end of the payload.
//!
//! - [`LengthFraming`]: the validated layout and the encoder ([`encode`]);
//! - [`LengthDecoder`]: the incremental decoder ([`decode`]).

pub mod decode;
pub mod encode;

pub use decode::LengthDecoder;

use super::{FrameCheck, FramingError, Malformed};
use crate::ByteOrder;

/// What the length field's value (plus the adjustment) counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthCounts {
    /// The payload's octets.
    Payload,
    /// The octets after the length field: payload and check.
    AfterField,
    /// The whole frame: sync, header, length field, payload and check.
    WholeFrame,
}

/// Where the length field is and how to read it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LengthField {
    /// Offset from the frame start (at or after the end of the sync octets).
    pub offset_bytes: usize,
    /// 1, 2 or 4 octets.
    pub width_bytes: usize,
    /// Octet order.
    pub order: ByteOrder,
    /// What it counts.
    pub counts: LengthCounts,
    /// Added to the field's value to get the count (`1` when the field holds "octets − 1").
    pub adjust: i64,
}

/// The configuration of a sync-and-length framing, as a device description gives it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LengthFramingConfig {
    /// The octets every frame starts with.
    pub sync: Vec<u8>,
    /// The length field.
    pub length: LengthField,
    /// The check, if any, after the payload.
    pub check: Option<FrameCheck>,
    /// Offset from the frame start where the check's coverage begins.
    pub check_from_bytes: usize,
    /// The longest frame accepted or sent, in octets; the decoder's buffer size.
    pub max_frame_bytes: usize,
}

/// A validated sync-and-length framing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LengthFraming {
    config: LengthFramingConfig,
}

impl LengthFraming {
    /// Checks the layout: a sync pattern, a 1-, 2- or 4-octet field after it, a coverage start
    /// within the header, and room for at least an empty payload.
    pub fn new(config: LengthFramingConfig) -> Result<Self, FramingError> {
        let sync_len_bytes = config.sync.len();
        let LengthField {
            offset_bytes,
            width_bytes,
            ..
        } = config.length;
        if sync_len_bytes == 0 {
            return Err(FramingError::EmptySync);
        }
        if ![1, 2, 4].contains(&width_bytes) {
            return Err(FramingError::LengthWidth { width_bytes });
        }
        if offset_bytes < sync_len_bytes {
            return Err(FramingError::LengthInsideSync {
                offset_bytes,
                sync_len_bytes,
            });
        }
        let framing = Self { config };
        let header_len_bytes = framing.header_len();
        if framing.config.check_from_bytes > header_len_bytes {
            return Err(FramingError::CheckFromBeyondHeader {
                check_from_bytes: framing.config.check_from_bytes,
                header_len_bytes,
            });
        }
        let min_bytes = header_len_bytes + framing.check_len();
        if framing.config.max_frame_bytes < min_bytes {
            return Err(FramingError::MaxFrameTooSmall {
                max_bytes: framing.config.max_frame_bytes,
                min_bytes,
            });
        }
        Ok(framing)
    }

    /// The configuration.
    pub fn config(&self) -> &LengthFramingConfig {
        &self.config
    }

    /// Octets before the payload: sync, header, length field.
    pub fn header_len(&self) -> usize {
        self.config.length.offset_bytes + self.config.length.width_bytes
    }

    /// Octets of the check.
    pub fn check_len(&self) -> usize {
        self.config.check.as_ref().map_or(0, FrameCheck::len_bytes)
    }

    /// What the count covers beyond the payload.
    fn counted_overhead(&self) -> usize {
        match self.config.length.counts {
            LengthCounts::Payload => 0,
            LengthCounts::AfterField => self.check_len(),
            LengthCounts::WholeFrame => self.header_len() + self.check_len(),
        }
    }

    /// The frame length a length field's value announces.
    fn frame_len_of(&self, field_value: u64) -> Result<usize, Malformed> {
        let counted = i128::from(field_value) + i128::from(self.config.length.adjust);
        let payload = counted - self.counted_overhead() as i128;
        if payload < 0 {
            return Err(Malformed::BadLength);
        }
        let frame = payload + (self.header_len() + self.check_len()) as i128;
        if frame > self.config.max_frame_bytes as i128 {
            return Err(Malformed::Oversize);
        }
        Ok(frame as usize)
    }

    /// The payload of a frame the decoder delivered (empty if `frame` is shorter than the
    /// header and check).
    pub fn payload<'a>(&self, frame: &'a [u8]) -> &'a [u8] {
        frame
            .get(self.header_len()..frame.len().saturating_sub(self.check_len()))
            .unwrap_or_default()
    }
}
