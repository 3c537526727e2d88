//! The hand-written half of the message types: their methods, the fault target (the Rust type
//! of the table's text fields: its own serde form, a string in JSON) and the fault modes' names.
//! The types themselves are generated from the wire table into `messages.rs`.

use serde::{Deserialize, Serialize};

use super::{CommandKind, CommandMsg, EffectorInput, FswMsg, Header, OperatorAction, OperatorMsg};
use super::{RejectCounters, RunState};
use crate::{FAULT_TARGET_LEN, PROTOCOL_VERSION};

impl Header {
    /// Header with the current [`PROTOCOL_VERSION`].
    pub fn new(spacecraft_id: u32, tick: u64, sim_time_ns: u64, seq: u64) -> Self {
        Self {
            protocol_version: PROTOCOL_VERSION,
            spacecraft_id,
            tick,
            sim_time_ns,
            seq,
        }
    }
}

impl CommandMsg {
    /// A `Wrench` command.
    pub fn wrench(
        header: Header,
        sender_id: u32,
        torque_b_nm: [f64; 3],
        force_b_newton: [f64; 3],
    ) -> Self {
        Self {
            header,
            sender_id,
            kind: CommandKind::Wrench {
                torque_b_nm,
                force_b_newton,
            },
        }
    }

    /// An `Actuators` command: a wrench and effector inputs.
    pub fn actuators(
        header: Header,
        sender_id: u32,
        torque_b_nm: [f64; 3],
        force_b_newton: [f64; 3],
        inputs: Vec<EffectorInput>,
    ) -> Self {
        Self {
            header,
            sender_id,
            kind: CommandKind::Actuators {
                torque_b_nm,
                force_b_newton,
                inputs,
            },
        }
    }

    /// A `NoCommand` command.
    pub fn no_command(header: Header, sender_id: u32) -> Self {
        Self {
            header,
            sender_id,
            kind: CommandKind::NoCommand,
        }
    }
}

impl RunState {
    /// Whether the run is over: `Finished`, `Failed` or `Stopped` (the last status a server
    /// publishes; every client stops on it).
    pub const fn ended(self) -> bool {
        matches!(self, Self::Finished | Self::Failed | Self::Stopped)
    }

    /// The state of wire tag `tag`, `None` for an unknown tag.
    pub const fn from_tag(tag: u32) -> Option<Self> {
        match tag {
            0 => Some(Self::Starting),
            1 => Some(Self::Running),
            2 => Some(Self::Stopping),
            3 => Some(Self::Finished),
            4 => Some(Self::Failed),
            5 => Some(Self::Stopped),
            6 => Some(Self::Paused),
            _ => None,
        }
    }
}

impl RejectCounters {
    /// Count one decode failure under its reason: `UnknownVersion` →
    /// `bad_version`, `NonFinite` → `non_finite`, everything else → `malformed`.
    pub fn record(&mut self, err: &crate::DecodeError) {
        use crate::DecodeError as E;
        let c = match err {
            E::UnknownVersion { .. } => &mut self.bad_version,
            E::NonFinite { .. } => &mut self.non_finite,
            E::Length { .. } | E::TrailingBytes { .. } | E::TooLarge { .. } | E::Malformed(_) => {
                &mut self.malformed
            }
        };
        *c = c.saturating_add(1);
    }

    /// Sum of all counters (saturating).
    pub fn total(&self) -> u64 {
        [
            self.malformed,
            self.bad_version,
            self.non_finite,
            self.wrong_spacecraft,
            self.stale_tick,
            self.unknown_sender,
            self.bad_effector_input,
            self.wrong_identity,
            self.operator_refused,
            self.fault_refused,
            self.fsw_refused,
        ]
        .iter()
        .fold(0u64, |a, &b| a.saturating_add(b))
    }
}

impl OperatorMsg {
    /// An operator command with `action` and `ticks`.
    pub fn new(header: Header, action: OperatorAction, ticks: u64) -> Self {
        Self {
            header,
            action,
            ticks,
        }
    }
}

/// The fault modes' names by code (the `mode` of [`FaultEventMsg`](super::FaultEventMsg) and
/// [`FaultCommandMsg`](super::FaultCommandMsg)):
/// `proto/README.md`, "Fault modes"; the names a configuration's `[[faults]]` use.
pub const FAULT_MODE_NAMES: [&str; 21] = [
    "stuck_current",
    "stuck_value",
    "bias_step",
    "bias_ramp",
    "scale",
    "noise",
    "spikes",
    "dropout",
    "validity_off",
    "friction_scale",
    "torque_limit",
    "seized",
    "command_ignored",
    "stuck_on",
    "stuck_off",
    "thrust_scale",
    "dead",
    "dipole_scale",
    "dropped",
    "delayed",
    "corrupted",
];

/// A fault's target as written in a configuration (`imus.hub.gyro`, `reaction_wheels.rw2`):
/// [`FAULT_TARGET_LEN`] bytes of UTF-8, padded with NUL bytes (no length prefix on the wire; in
/// JSON, a string).
/// Protocol version 8.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct FaultTarget(pub [u8; FAULT_TARGET_LEN]);

impl FaultTarget {
    /// `target` padded with NULs; `None` if longer than [`FAULT_TARGET_LEN`] bytes or holding a
    /// NUL.
    pub fn new(target: &str) -> Option<Self> {
        let b = target.as_bytes();
        if b.len() > FAULT_TARGET_LEN || b.contains(&0) {
            return None;
        }
        let mut out = [0u8; FAULT_TARGET_LEN];
        out[..b.len()].copy_from_slice(b);
        Some(Self(out))
    }

    /// The bytes up to the first NUL, as UTF-8 (`None` if they are not).
    pub fn as_str(&self) -> Option<&str> {
        let n = self
            .0
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(FAULT_TARGET_LEN);
        std::str::from_utf8(&self.0[..n]).ok()
    }

    /// `target` truncated to [`FAULT_TARGET_LEN`] bytes at a character boundary (for an event
    /// whose target is longer; the fault index stays exact).
    pub fn truncated(target: &str) -> Self {
        let mut end = target.len().min(FAULT_TARGET_LEN);
        while !target.is_char_boundary(end) {
            end -= 1;
        }
        let mut out = [0u8; FAULT_TARGET_LEN];
        for (o, b) in out.iter_mut().zip(&target.as_bytes()[..end]) {
            *o = if *b == 0 { b'?' } else { *b };
        }
        Self(out)
    }
}

impl FaultTarget {
    /// The text rule of `proto/README.md` ("Decoder rules", step 4): the text ends at its first
    /// NUL byte and every byte after it is NUL, so one target has one encoding. Another byte in
    /// the padding is [`crate::DecodeError::Malformed`], naming `field`.
    pub fn check_padding(&self, field: &str) -> Result<(), crate::DecodeError> {
        let Some(end) = self.0.iter().position(|&b| b == 0) else {
            return Ok(());
        };
        match self.0[end..].iter().position(|&b| b != 0) {
            None => Ok(()),
            Some(i) => Err(crate::DecodeError::Malformed(format!(
                "{field}: byte {} is 0x{:02x}, after the text ended (NUL) at byte {end}; the \
                 padding must be NUL",
                end + i,
                self.0[end + i]
            ))),
        }
    }
}

impl Default for FaultTarget {
    fn default() -> Self {
        Self([0; FAULT_TARGET_LEN])
    }
}

impl std::fmt::Debug for FaultTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.as_str() {
            Some(s) => write!(f, "FaultTarget({s:?})"),
            None => write!(f, "FaultTarget(<not UTF-8>)"),
        }
    }
}

impl Serialize for FaultTarget {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeTuple;
        // JSON (recordings, viewers): the text, bytes that are not UTF-8 replaced.
        if s.is_human_readable() {
            let n = self
                .0
                .iter()
                .position(|&b| b == 0)
                .unwrap_or(FAULT_TARGET_LEN);
            return s.serialize_str(&String::from_utf8_lossy(&self.0[..n]));
        }
        // A tuple: the bytes in order, no length prefix (as `[u8; N]` for N ≤ 32).
        let mut t = s.serialize_tuple(FAULT_TARGET_LEN)?;
        for b in &self.0 {
            t.serialize_element(b)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for FaultTarget {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Bytes;
        impl<'de> serde::de::Visitor<'de> for Bytes {
            type Value = FaultTarget;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{FAULT_TARGET_LEN} bytes")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<Self::Value, A::Error> {
                let mut out = [0u8; FAULT_TARGET_LEN];
                for (i, o) in out.iter_mut().enumerate() {
                    *o = a
                        .next_element()?
                        .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
                }
                Ok(FaultTarget(out))
            }
        }
        if d.is_human_readable() {
            let text = String::deserialize(d)?;
            return FaultTarget::new(&text)
                .ok_or_else(|| serde::de::Error::custom("a fault target of at most 128 bytes"));
        }
        d.deserialize_tuple(FAULT_TARGET_LEN, Bytes)
    }
}

impl FswMsg {
    /// The events raised, as indices in the stream's `events` (at most `event_count`, bounded by
    /// the array).
    pub fn event_indices(&self) -> &[u16] {
        &self.events[..usize::from(self.event_count).min(self.events.len())]
    }
}
