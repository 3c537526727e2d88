//! Encoded sizes and the per-message length rule the decoder checks before
//! handing bytes to bincode.

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::{CommandKind, CommandMsg, DecodeError, Header, ImuMsg, StateMsg, StatusMsg};

/// Encoded [`Header`] size (bytes).
pub const HEADER_LEN: usize = 30;
/// Encoded [`crate::PanelPairState`] size (bytes).
pub const PANEL_PAIR_LEN: usize = 32;
/// Offset of the u64 panel count in a [`StateMsg`].
pub const STATE_PANEL_COUNT_OFFSET: usize = 319;
/// Encoded [`StateMsg`] size with no panels (bytes); add [`PANEL_PAIR_LEN`] per pair.
pub const STATE_FIXED_LEN: usize = 327;
/// Encoded [`ImuMsg`] size (bytes).
pub const IMU_LEN: usize = 127;
/// Offset of the u32 [`CommandKind`] tag in a [`CommandMsg`].
pub const COMMAND_KIND_OFFSET: usize = 34;
/// Encoded [`CommandMsg`] size with [`CommandKind::Wrench`] (bytes).
pub const COMMAND_WRENCH_LEN: usize = 86;
/// Encoded [`CommandMsg`] size with [`CommandKind::NoCommand`] (bytes).
pub const COMMAND_NO_COMMAND_LEN: usize = 38;
/// Encoded [`StatusMsg`] size (bytes).
pub const STATUS_LEN: usize = 163;
/// Largest panel count a [`StateMsg`] may carry; decoders reject more.
pub const MAX_PANEL_PAIRS: usize = 1024;
/// Largest buffer any decoder accepts (bytes); also the bincode decode limit.
pub const MAX_MESSAGE_BYTES: usize = 65536;

/// How the total encoded length of a message type follows from its bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WireLayout {
    /// Always `len` bytes.
    Fixed {
        /// Encoded length (bytes).
        len: usize,
    },
    /// `fixed_len` bytes, the last 8 of which (at `count_offset`) are a u64 LE
    /// element count, then `count * elem_len` bytes.
    TrailingSeq {
        /// Length with zero elements, count prefix included (bytes).
        fixed_len: usize,
        /// Offset of the u64 LE count.
        count_offset: usize,
        /// Encoded element size (bytes).
        elem_len: usize,
        /// Largest accepted count.
        max_count: usize,
    },
    /// A u32 LE enum tag at `tag_offset`; `lens[tag]` is the total length.
    Tagged {
        /// Offset of the u32 LE tag.
        tag_offset: usize,
        /// Total length per tag value.
        lens: &'static [usize],
    },
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::StateMsg {}
    impl Sealed for super::ImuMsg {}
    impl Sealed for super::CommandMsg {}
    impl Sealed for super::StatusMsg {}
}

/// A top-level message that can go on the wire. Implemented (only) by
/// [`StateMsg`], [`ImuMsg`], [`CommandMsg`] and [`StatusMsg`].
pub trait WireMessage: Serialize + DeserializeOwned + sealed::Sealed {
    /// Type name used in error messages.
    const NAME: &'static str;
    /// Length rule for the encoding.
    const LAYOUT: WireLayout;
    /// Shortest possible encoding (bytes).
    const MIN_LEN: usize;

    /// The common header.
    fn header(&self) -> &Header;

    /// Semantic checks applied after decoding (and usable before sending):
    /// commands must have finite numbers. Other messages always pass.
    fn validate(&self) -> Result<(), DecodeError> {
        Ok(())
    }
}

impl WireMessage for StateMsg {
    const NAME: &'static str = "StateMsg";
    const LAYOUT: WireLayout = WireLayout::TrailingSeq {
        fixed_len: STATE_FIXED_LEN,
        count_offset: STATE_PANEL_COUNT_OFFSET,
        elem_len: PANEL_PAIR_LEN,
        max_count: MAX_PANEL_PAIRS,
    };
    const MIN_LEN: usize = STATE_FIXED_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for ImuMsg {
    const NAME: &'static str = "ImuMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed { len: IMU_LEN };
    const MIN_LEN: usize = IMU_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for StatusMsg {
    const NAME: &'static str = "StatusMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed { len: STATUS_LEN };
    const MIN_LEN: usize = STATUS_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

const TORQUE_FIELDS: [&str; 3] = [
    "kind.torque_b_nm[0]",
    "kind.torque_b_nm[1]",
    "kind.torque_b_nm[2]",
];
const FORCE_FIELDS: [&str; 3] = [
    "kind.force_b_newton[0]",
    "kind.force_b_newton[1]",
    "kind.force_b_newton[2]",
];

impl WireMessage for CommandMsg {
    const NAME: &'static str = "CommandMsg";
    const LAYOUT: WireLayout = WireLayout::Tagged {
        tag_offset: COMMAND_KIND_OFFSET,
        lens: &[COMMAND_WRENCH_LEN, COMMAND_NO_COMMAND_LEN],
    };
    const MIN_LEN: usize = COMMAND_NO_COMMAND_LEN;
    fn header(&self) -> &Header {
        &self.header
    }

    /// Rejects NaN/infinite components with [`DecodeError::NonFinite`] naming
    /// the first offending field (torque checked before force).
    fn validate(&self) -> Result<(), DecodeError> {
        if let CommandKind::Wrench {
            torque_b_nm,
            force_b_newton,
        } = &self.kind
        {
            let fields = TORQUE_FIELDS
                .iter()
                .zip(torque_b_nm)
                .chain(FORCE_FIELDS.iter().zip(force_b_newton));
            for (field, v) in fields {
                if !v.is_finite() {
                    return Err(DecodeError::NonFinite { field });
                }
            }
        }
        Ok(())
    }
}

impl WireLayout {
    /// Total encoded length implied by `bytes` (which must start with a message
    /// of this layout), or the error to report. Never reads out of bounds.
    pub fn expected_len(&self, bytes: &[u8]) -> Result<usize, DecodeError> {
        match *self {
            WireLayout::Fixed { len } => Ok(len),
            WireLayout::TrailingSeq {
                fixed_len,
                count_offset,
                elem_len,
                max_count,
            } => {
                let count = read_u64_le(bytes, count_offset).ok_or(DecodeError::Length {
                    needed: fixed_len,
                    actual: bytes.len(),
                })?;
                if count > max_count as u64 {
                    return Err(DecodeError::Malformed(format!(
                        "element count {count} exceeds maximum {max_count}"
                    )));
                }
                // count <= max_count, so this cannot overflow.
                Ok(fixed_len + count as usize * elem_len)
            }
            WireLayout::Tagged { tag_offset, lens } => {
                let min = lens.iter().copied().min().unwrap_or(0).max(tag_offset + 4);
                let tag = read_u32_le(bytes, tag_offset).ok_or(DecodeError::Length {
                    needed: min,
                    actual: bytes.len(),
                })?;
                lens.get(tag as usize).copied().ok_or_else(|| {
                    DecodeError::Malformed(format!("unknown enum tag {tag} at offset {tag_offset}"))
                })
            }
        }
    }
}

fn read_u64_le(bytes: &[u8], at: usize) -> Option<u64> {
    let b: [u8; 8] = bytes.get(at..at.checked_add(8)?)?.try_into().ok()?;
    Some(u64::from_le_bytes(b))
}

fn read_u32_le(bytes: &[u8], at: usize) -> Option<u32> {
    let b: [u8; 4] = bytes.get(at..at.checked_add(4)?)?.try_into().ok()?;
    Some(u32::from_le_bytes(b))
}
