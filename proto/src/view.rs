//! A [`CommandMsg`] read in place, without allocating: for the one caller that must judge a
//! command on a path that allocates nothing, the server's damaged-link check (a `corrupted`
//! command-link fault decodes each damaged command on the stepping thread).
//!
//! [`view_command`] accepts exactly the bytes [`crate::decode_command`] accepts, with the same
//! values, and refuses the others with the class of [`DecodeError`] that `decode_command`
//! gives (`tests/proptests.rs` checks both on arbitrary, truncated and bit-damaged commands).
//! The checks, in `decode`'s order (module docs of the codec): at most [`MAX_MESSAGE_BYTES`];
//! the protocol version; the length the layout implies (the tag at [`COMMAND_KIND_OFFSET`], and
//! for `Actuators` each count within [`MAX_EFFECTORS`] / [`MAX_EFFECTOR_VALUES`]) against the
//! buffer; then every number finite.

use crate::{
    CommandMsg, DecodeError, Header, COMMAND_ACTUATORS_FIXED_LEN, COMMAND_KIND_OFFSET,
    COMMAND_NO_COMMAND_LEN, COMMAND_WRENCH_LEN, HEADER_LEN, MAX_EFFECTORS, MAX_EFFECTOR_VALUES,
    MAX_MESSAGE_BYTES, PROTOCOL_VERSION,
};

/// Why [`view_command`] refused: the class of the [`DecodeError`] `decode_command` gives for the
/// same bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewError {
    /// [`DecodeError::UnknownVersion`].
    UnknownVersion {
        /// The version the bytes carry.
        found: u16,
    },
    /// [`DecodeError::NonFinite`].
    NonFinite,
    /// Any other: too large, too short, trailing bytes, an unknown tag, a count too large.
    Malformed,
}

impl ViewError {
    /// The class of a [`DecodeError`].
    pub fn of(e: &DecodeError) -> Self {
        match e {
            DecodeError::UnknownVersion { found } => Self::UnknownVersion { found: *found },
            DecodeError::NonFinite { .. } => Self::NonFinite,
            _ => Self::Malformed,
        }
    }
}

/// A command, read in place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandView<'a> {
    /// Its header.
    pub header: Header,
    /// Its sender.
    pub sender_id: u32,
    /// What it commands.
    pub kind: CommandViewKind<'a>,
}

/// [`crate::CommandKind`], read in place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CommandViewKind<'a> {
    /// Tag 0.
    Wrench {
        /// Torque about B, B components (N·m).
        torque_b_nm: [f64; 3],
        /// Force at B, B components (N).
        force_b_newton: [f64; 3],
    },
    /// Tag 1.
    NoCommand,
    /// Tag 2.
    Actuators {
        /// Torque about B, B components (N·m).
        torque_b_nm: [f64; 3],
        /// Force at B, B components (N).
        force_b_newton: [f64; 3],
        /// The per-effector inputs.
        inputs: InputsView<'a>,
    },
}

/// The effector inputs of an `Actuators` command: their encoding, already walked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputsView<'a> {
    count: usize,
    bytes: &'a [u8],
}

impl<'a> InputsView<'a> {
    /// How many inputs.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Each input: its effector index and its values.
    pub fn iter(&self) -> impl Iterator<Item = (u32, ValuesView<'a>)> + 'a {
        let mut rest = self.bytes;
        (0..self.count).map(move |_| {
            // Walked by `view_command`: the reads are in bounds.
            let index = u32_at(rest, 0).unwrap_or_default();
            let n = u64_at(rest, 4).unwrap_or_default() as usize;
            let end = 12 + 8 * n;
            let values = ValuesView {
                bytes: rest.get(12..end).unwrap_or_default(),
            };
            rest = rest.get(end..).unwrap_or_default();
            (index, values)
        })
    }
}

/// The values of one effector input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValuesView<'a> {
    bytes: &'a [u8],
}

impl<'a> ValuesView<'a> {
    /// How many values.
    pub fn len(&self) -> usize {
        self.bytes.len() / 8
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// The values, in order.
    pub fn iter(&self) -> impl Iterator<Item = f64> + 'a {
        self.bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
    }
}

pub(crate) fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

pub(crate) fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

pub(crate) fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

pub(crate) fn f64_at(b: &[u8], at: usize) -> Option<f64> {
    u64_at(b, at).map(f64::from_bits)
}

fn v3_at(b: &[u8], at: usize) -> Option<[f64; 3]> {
    Some([f64_at(b, at)?, f64_at(b, at + 8)?, f64_at(b, at + 16)?])
}

/// The length an `Actuators` command's inputs imply (walked from the input count at offset
/// [`COMMAND_ACTUATORS_FIXED_LEN`] − 8), and the count; `Malformed` as `decode` refuses it.
fn walk_inputs(bytes: &[u8]) -> Result<(usize, usize), ViewError> {
    let mut at = COMMAND_ACTUATORS_FIXED_LEN - 8;
    let count = u64_at(bytes, at).ok_or(ViewError::Malformed)?;
    if count > MAX_EFFECTORS as u64 {
        return Err(ViewError::Malformed);
    }
    at += 8;
    for _ in 0..count {
        at += 4;
        let n = u64_at(bytes, at).ok_or(ViewError::Malformed)?;
        if n > MAX_EFFECTOR_VALUES as u64 {
            return Err(ViewError::Malformed);
        }
        at += 8 + 8 * n as usize;
        if at > bytes.len() {
            return Err(ViewError::Malformed);
        }
    }
    Ok((at, count as usize))
}

/// `decode`'s first two checks: at most [`MAX_MESSAGE_BYTES`], and the protocol version
/// (returned).
pub(crate) fn size_and_version(bytes: &[u8]) -> Result<u16, ViewError> {
    if bytes.len() > MAX_MESSAGE_BYTES {
        return Err(ViewError::Malformed);
    }
    let found = u16_at(bytes, 0).ok_or(ViewError::Malformed)?;
    if found != PROTOCOL_VERSION {
        return Err(ViewError::UnknownVersion { found });
    }
    Ok(found)
}

/// The [`Header`] at the start of `bytes`, whose version is `found`.
pub(crate) fn header_at(bytes: &[u8], found: u16) -> Result<Header, ViewError> {
    Ok(Header {
        protocol_version: found,
        spacecraft_id: u32_at(bytes, 2).ok_or(ViewError::Malformed)?,
        tick: u64_at(bytes, 6).ok_or(ViewError::Malformed)?,
        sim_time_ns: u64_at(bytes, 14).ok_or(ViewError::Malformed)?,
        seq: u64_at(bytes, 22).ok_or(ViewError::Malformed)?,
    })
}

/// Reads a [`CommandMsg`] in place (module docs). Allocates nothing.
pub fn view_command(bytes: &[u8]) -> Result<CommandView<'_>, ViewError> {
    let found = size_and_version(bytes)?;
    let tag = u32_at(bytes, COMMAND_KIND_OFFSET).ok_or(ViewError::Malformed)?;
    let (expected, inputs) = match tag {
        0 => (COMMAND_WRENCH_LEN, 0),
        1 => (COMMAND_NO_COMMAND_LEN, 0),
        2 => walk_inputs(bytes)?,
        _ => return Err(ViewError::Malformed),
    };
    if bytes.len() != expected {
        return Err(ViewError::Malformed);
    }
    let header = header_at(bytes, found)?;
    let sender_id = u32_at(bytes, HEADER_LEN).ok_or(ViewError::Malformed)?;
    let wrench = || -> Result<([f64; 3], [f64; 3]), ViewError> {
        let torque = v3_at(bytes, COMMAND_KIND_OFFSET + 4).ok_or(ViewError::Malformed)?;
        let force = v3_at(bytes, COMMAND_KIND_OFFSET + 28).ok_or(ViewError::Malformed)?;
        if torque.iter().chain(&force).all(|v| v.is_finite()) {
            Ok((torque, force))
        } else {
            Err(ViewError::NonFinite)
        }
    };
    let kind = match tag {
        0 => {
            let (torque_b_nm, force_b_newton) = wrench()?;
            CommandViewKind::Wrench {
                torque_b_nm,
                force_b_newton,
            }
        }
        1 => CommandViewKind::NoCommand,
        _ => {
            let (torque_b_nm, force_b_newton) = wrench()?;
            let inputs = InputsView {
                count: inputs,
                bytes: bytes
                    .get(COMMAND_ACTUATORS_FIXED_LEN..)
                    .ok_or(ViewError::Malformed)?,
            };
            if inputs.iter().any(|(_, v)| v.iter().any(|x| !x.is_finite())) {
                return Err(ViewError::NonFinite);
            }
            CommandViewKind::Actuators {
                torque_b_nm,
                force_b_newton,
                inputs,
            }
        }
    };
    Ok(CommandView {
        header,
        sender_id,
        kind,
    })
}

impl CommandView<'_> {
    /// The owned command (allocates for `Actuators`): for tests and tools.
    pub fn to_owned_msg(&self) -> CommandMsg {
        let kind = match self.kind {
            CommandViewKind::Wrench {
                torque_b_nm,
                force_b_newton,
            } => crate::CommandKind::Wrench {
                torque_b_nm,
                force_b_newton,
            },
            CommandViewKind::NoCommand => crate::CommandKind::NoCommand,
            CommandViewKind::Actuators {
                torque_b_nm,
                force_b_newton,
                inputs,
            } => crate::CommandKind::Actuators {
                torque_b_nm,
                force_b_newton,
                inputs: inputs
                    .iter()
                    .map(|(effector_index, v)| crate::EffectorInput {
                        effector_index,
                        values: v.iter().collect(),
                    })
                    .collect(),
            },
        };
        CommandMsg {
            header: self.header,
            sender_id: self.sender_id,
            kind,
        }
    }
}
