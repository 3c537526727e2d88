//! Encoded sizes and the per-message length rule the decoder checks before
//! handing bytes to bincode.

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::{
    CommandKind, CommandMsg, CssMsg, DecodeError, EnvironmentMsg, FssMsg, Header, ImuMsg,
    MagnetometerMsg, OperatorMsg, StarTrackerMsg, StateMsg, StatusMsg, TimeMsg,
};
use crate::{FaultCommandMsg, FaultEventMsg};
// The relative state of a fleet's deputy (protocol 9).
use crate::RelativeStateMsg;

/// Encoded [`Header`] size (bytes).
pub const HEADER_LEN: usize = 30;
/// Offset of the u64 effector count in a [`StateMsg`].
pub const STATE_EFFECTOR_COUNT_OFFSET: usize = 319;
/// Encoded [`StateMsg`] size with no effectors (bytes).
pub const STATE_FIXED_LEN: usize = 327;
/// Encoded [`crate::EffectorState`] size with no states and no outputs (bytes): u16 kind,
/// u32 flags, two u64 counts. Add 8 per value.
pub const EFFECTOR_STATE_FIXED_LEN: usize = 22;
/// Encoded [`crate::EffectorInput`] size with no values (bytes): u32 index, u64 count.
pub const EFFECTOR_INPUT_FIXED_LEN: usize = 12;
/// Encoded [`ImuMsg`] size (bytes).
pub const IMU_LEN: usize = 127;
/// Encoded [`StarTrackerMsg`] size (bytes).
pub const STAR_TRACKER_LEN: usize = 64;
/// Encoded [`MagnetometerMsg`] size (bytes).
pub const MAGNETOMETER_LEN: usize = 55;
/// Encoded [`CssMsg`] size (bytes).
pub const CSS_LEN: usize = 159;
/// Encoded [`FssMsg`] size (bytes).
pub const FSS_LEN: usize = 47;
/// Encoded [`crate::GpsMsg`] size (bytes).
pub const GPS_LEN: usize = 147;
/// Encoded [`EnvironmentMsg`] size (bytes).
pub const ENVIRONMENT_LEN: usize = 368;
/// Encoded [`TimeMsg`] size (bytes).
pub const TIME_LEN: usize = 122;
/// Offset of the 8 CCSDS CUC octets in a [`TimeMsg`].
pub const TIME_CUC_OFFSET: usize = 98;
/// Offset of the u32 [`CommandKind`] tag in a [`CommandMsg`].
pub const COMMAND_KIND_OFFSET: usize = 34;
/// Encoded [`CommandMsg`] size with [`CommandKind::Wrench`] (bytes).
pub const COMMAND_WRENCH_LEN: usize = 86;
/// Encoded [`CommandMsg`] size with [`CommandKind::NoCommand`] (bytes).
pub const COMMAND_NO_COMMAND_LEN: usize = 38;
/// Encoded [`CommandMsg`] size with [`CommandKind::Actuators`] and no inputs (bytes); the
/// u64 input count sits at offset 86.
pub const COMMAND_ACTUATORS_FIXED_LEN: usize = 94;
/// Encoded [`StatusMsg`] size (bytes).
pub const STATUS_LEN: usize = 235;
/// Encoded [`OperatorMsg`] size (bytes).
pub const OPERATOR_LEN: usize = 42;
/// Encoded [`FaultEventMsg`] size (bytes). Protocol version 8.
pub const FAULT_EVENT_LEN: usize = 199;
/// Encoded [`FaultCommandMsg`] size (bytes). Protocol version 8.
pub const FAULT_COMMAND_LEN: usize = 214;
/// Encoded [`RelativeStateMsg`] size (bytes). Protocol version 9.
pub const RELATIVE_STATE_LEN: usize = 102;
/// Largest effector count a [`StateMsg`] (or input count a [`CommandKind::Actuators`]) may
/// carry; decoders reject more.
pub const MAX_EFFECTORS: usize = 1024;
/// Largest panel-pair count a configuration may have (each pair is one effector).
pub const MAX_PANEL_PAIRS: usize = MAX_EFFECTORS;
/// Largest length of an effector's `states`, `outputs` or input `values`; decoders reject
/// more.
pub const MAX_EFFECTOR_VALUES: usize = 8;
/// Largest buffer any decoder accepts (bytes); also the bincode decode limit.
pub const MAX_MESSAGE_BYTES: usize = 65536;

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
        /// Returns the total length implied by the bytes, or the error to report.
        walk: fn(&[u8]) -> Result<usize, DecodeError>,
    },
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::StateMsg {}
    impl Sealed for super::ImuMsg {}
    impl Sealed for super::CommandMsg {}
    impl Sealed for super::StatusMsg {}
    impl Sealed for super::StarTrackerMsg {}
    impl Sealed for super::MagnetometerMsg {}
    impl Sealed for super::CssMsg {}
    impl Sealed for super::FssMsg {}
    impl Sealed for crate::GpsMsg {}
    impl Sealed for super::EnvironmentMsg {}
    impl Sealed for super::TimeMsg {}
    impl Sealed for super::OperatorMsg {}
    impl Sealed for super::FaultEventMsg {}
    impl Sealed for super::RelativeStateMsg {}
    impl Sealed for super::FaultCommandMsg {}
}

/// A top-level message that can go on the wire. Implemented (only) by
/// [`StateMsg`], [`ImuMsg`], [`StarTrackerMsg`], the other sensor messages
/// ([`MagnetometerMsg`]), [`TimeMsg`], [`CommandMsg`], [`StatusMsg`] and [`OperatorMsg`].
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
    const LAYOUT: WireLayout = WireLayout::Walked {
        min_len: STATE_FIXED_LEN,
        walk: walk_state,
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

impl WireMessage for StarTrackerMsg {
    const NAME: &'static str = "StarTrackerMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed {
        len: STAR_TRACKER_LEN,
    };
    const MIN_LEN: usize = STAR_TRACKER_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for MagnetometerMsg {
    const NAME: &'static str = "MagnetometerMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed {
        len: MAGNETOMETER_LEN,
    };
    const MIN_LEN: usize = MAGNETOMETER_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for CssMsg {
    const NAME: &'static str = "CssMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed { len: CSS_LEN };
    const MIN_LEN: usize = CSS_LEN;
    fn header(&self) -> &Header {
        &self.header
    }

    /// Rejects a `detector_count` above [`crate::MAX_CSS_DETECTORS`].
    fn validate(&self) -> Result<(), DecodeError> {
        if usize::from(self.detector_count) > crate::MAX_CSS_DETECTORS {
            return Err(DecodeError::Malformed(format!(
                "detector count {} at offset {} exceeds maximum {}",
                self.detector_count,
                HEADER_LEN,
                crate::MAX_CSS_DETECTORS
            )));
        }
        Ok(())
    }
}

impl WireMessage for FssMsg {
    const NAME: &'static str = "FssMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed { len: FSS_LEN };
    const MIN_LEN: usize = FSS_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for crate::GpsMsg {
    const NAME: &'static str = "GpsMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed { len: GPS_LEN };
    const MIN_LEN: usize = GPS_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for EnvironmentMsg {
    const NAME: &'static str = "EnvironmentMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed {
        len: ENVIRONMENT_LEN,
    };
    const MIN_LEN: usize = ENVIRONMENT_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for TimeMsg {
    const NAME: &'static str = "TimeMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed { len: TIME_LEN };
    const MIN_LEN: usize = TIME_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for OperatorMsg {
    const NAME: &'static str = "OperatorMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed { len: OPERATOR_LEN };
    const MIN_LEN: usize = OPERATOR_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl WireMessage for FaultEventMsg {
    const NAME: &'static str = "FaultEventMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed {
        len: FAULT_EVENT_LEN,
    };
    const MIN_LEN: usize = FAULT_EVENT_LEN;
    fn header(&self) -> &Header {
        &self.header
    }

    /// Rejects bytes after the target's terminating NUL (the text rule).
    fn validate(&self) -> Result<(), DecodeError> {
        self.target.check_padding("target")
    }
}

impl WireMessage for FaultCommandMsg {
    const NAME: &'static str = "FaultCommandMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed {
        len: FAULT_COMMAND_LEN,
    };
    const MIN_LEN: usize = FAULT_COMMAND_LEN;
    fn header(&self) -> &Header {
        &self.header
    }

    /// Rejects bytes after the target's terminating NUL (the text rule, step 4 of the decoder
    /// rules), then non-finite parameters with [`DecodeError::NonFinite`] (step 5).
    fn validate(&self) -> Result<(), DecodeError> {
        self.target.check_padding("target")?;
        for (field, v) in ["params[0]", "params[1]"].into_iter().zip(self.params) {
            if !v.is_finite() {
                return Err(DecodeError::NonFinite { field });
            }
        }
        Ok(())
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
    const LAYOUT: WireLayout = WireLayout::Walked {
        min_len: COMMAND_NO_COMMAND_LEN,
        walk: walk_command,
    };
    const MIN_LEN: usize = COMMAND_NO_COMMAND_LEN;
    fn header(&self) -> &Header {
        &self.header
    }

    /// Rejects NaN/infinite components with [`DecodeError::NonFinite`] naming
    /// the first offending field (torque, then force, then the inputs in order).
    fn validate(&self) -> Result<(), DecodeError> {
        let (torque_b_nm, force_b_newton, inputs) = match &self.kind {
            CommandKind::Wrench {
                torque_b_nm,
                force_b_newton,
            } => (torque_b_nm, force_b_newton, &[][..]),
            CommandKind::Actuators {
                torque_b_nm,
                force_b_newton,
                inputs,
            } => (torque_b_nm, force_b_newton, inputs.as_slice()),
            CommandKind::NoCommand => return Ok(()),
        };
        let fields = TORQUE_FIELDS
            .iter()
            .zip(torque_b_nm)
            .chain(FORCE_FIELDS.iter().zip(force_b_newton));
        for (field, v) in fields {
            if !v.is_finite() {
                return Err(DecodeError::NonFinite { field });
            }
        }
        if inputs
            .iter()
            .flat_map(|i| &i.values)
            .any(|v| !v.is_finite())
        {
            return Err(DecodeError::NonFinite {
                field: "kind.inputs[].values[]",
            });
        }
        Ok(())
    }
}

/// A bounds-checked reader of count prefixes, for [`WireLayout::Walked`].
struct Walker<'b> {
    bytes: &'b [u8],
    at: usize,
}

impl Walker<'_> {
    /// Skips `n` bytes; an error if the buffer ends first.
    fn skip(&mut self, n: usize) -> Result<(), DecodeError> {
        let end = self.at.checked_add(n).ok_or(DecodeError::Length {
            needed: usize::MAX,
            actual: self.bytes.len(),
        })?;
        if end > self.bytes.len() {
            return Err(DecodeError::Length {
                needed: end,
                actual: self.bytes.len(),
            });
        }
        self.at = end;
        Ok(())
    }

    /// Reads a u64 LE count at the cursor and checks it against `max`.
    fn count(&mut self, what: &str, max: usize) -> Result<usize, DecodeError> {
        let count = read_u64_le(self.bytes, self.at).ok_or(DecodeError::Length {
            needed: self.at + 8,
            actual: self.bytes.len(),
        })?;
        if count > max as u64 {
            return Err(DecodeError::Malformed(format!(
                "{what} count {count} at offset {} exceeds maximum {max}",
                self.at
            )));
        }
        self.at += 8;
        Ok(count as usize)
    }

    /// Reads a count of f64 values and skips them.
    fn values(&mut self, what: &str) -> Result<(), DecodeError> {
        let n = self.count(what, MAX_EFFECTOR_VALUES)?;
        self.skip(8 * n)
    }
}

/// Length of a [`StateMsg`]: the fixed part, then each [`crate::EffectorState`].
fn walk_state(bytes: &[u8]) -> Result<usize, DecodeError> {
    let mut w = Walker {
        bytes,
        at: STATE_EFFECTOR_COUNT_OFFSET,
    };
    let n = w.count("effector", MAX_EFFECTORS)?;
    for _ in 0..n {
        w.skip(6)?;
        w.values("effector states")?;
        w.values("effector outputs")?;
    }
    Ok(w.at)
}

/// Length of a [`CommandMsg`]: fixed by the tag, or walked for `Actuators`.
fn walk_command(bytes: &[u8]) -> Result<usize, DecodeError> {
    let tag = read_u32_le(bytes, COMMAND_KIND_OFFSET).ok_or(DecodeError::Length {
        needed: COMMAND_NO_COMMAND_LEN,
        actual: bytes.len(),
    })?;
    match tag {
        0 => Ok(COMMAND_WRENCH_LEN),
        1 => Ok(COMMAND_NO_COMMAND_LEN),
        2 => {
            let mut w = Walker {
                bytes,
                at: COMMAND_ACTUATORS_FIXED_LEN - 8,
            };
            let n = w.count("effector input", MAX_EFFECTORS)?;
            for _ in 0..n {
                w.skip(4)?;
                w.values("effector input values")?;
            }
            Ok(w.at)
        }
        _ => Err(DecodeError::Malformed(format!(
            "unknown enum tag {tag} at offset {COMMAND_KIND_OFFSET}"
        ))),
    }
}

impl WireLayout {
    /// Total encoded length implied by `bytes` (which must start with a message
    /// of this layout), or the error to report. Never reads out of bounds.
    pub fn expected_len(&self, bytes: &[u8]) -> Result<usize, DecodeError> {
        match *self {
            WireLayout::Fixed { len } => Ok(len),
            WireLayout::Walked { walk, .. } => walk(bytes),
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

impl WireMessage for RelativeStateMsg {
    const NAME: &'static str = "RelativeStateMsg";
    const LAYOUT: WireLayout = WireLayout::Fixed {
        len: RELATIVE_STATE_LEN,
    };
    const MIN_LEN: usize = RELATIVE_STATE_LEN;
    fn header(&self) -> &Header {
        &self.header
    }
}
