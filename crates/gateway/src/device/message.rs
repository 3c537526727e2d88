//! A described message: its id, fields and schedule; the payload it encodes from the catalog
//! values and the tick's time, and the payload it decodes into values for its destinations.
//!
//! The payload is the id field (if the description has one) then the fields in order, back to
//! back: every message has a fixed length.

use std::time::Duration;

use super::counters::DeviceCounters;
use super::field::{Codec, Dest, Field, Source};
use super::time::TickTime;
use crate::ByteOrder;

/// Who sends it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Driver → device: a command or a request.
    In,
    /// Device → driver.
    Out,
}

/// When an out-message is sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Schedule {
    /// At every tick that is a multiple of this many frames.
    Every {
        /// Frames per period.
        period_ticks: u64,
    },
    /// When this catalog group publishes.
    OnSample {
        /// The group.
        group: usize,
    },
    /// Only as the response to a request (or an in-message).
    Never,
}

/// The id field at the start of every payload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IdField {
    /// Octets.
    pub width: usize,
    /// Octet order.
    pub order: ByteOrder,
}

/// A message of a binary device.
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    /// Name.
    pub name: String,
    /// Who sends it.
    pub direction: Direction,
    /// The id field's value, if the description has an id field.
    pub id: Option<u64>,
    /// The CCSDS APID, if framed as Space Packets.
    pub apid: Option<u16>,
    /// Fields after the id.
    pub fields: Vec<Field>,
    /// Octets of the payload (id included).
    pub payload_len: usize,
    /// Out: when it is sent.
    pub schedule: Schedule,
    /// In: index of the out-message sent back.
    pub response: Option<usize>,
    /// In, lockstep: one is due every this many frames.
    pub due_period_ticks: Option<u64>,
    /// In, lockstep: how long the gateway waits for it.
    pub timeout: Option<Duration>,
    /// Frames of it sent (out) so far: the `counter` source.
    pub count: u64,
    /// Decoded SI values of the last frame, one per field (sized at build).
    pub decoded: Vec<f64>,
}

/// Why a received payload is not applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reject {
    /// Not this message's length.
    BadLength,
    /// A constant that differs.
    BadConstant,
    /// A NaN or infinite float.
    BadValue,
}

impl Message {
    /// Appends this message's payload at `now`: the id, then every field from its source.
    /// Values clamped are counted in `counters`; the message's counter advances.
    pub fn encode(
        &mut self,
        id_field: Option<IdField>,
        now: &TickTime,
        values: &[f64],
        counters: &mut DeviceCounters,
        out: &mut Vec<u8>,
    ) {
        let start = out.len();
        out.resize(start + self.payload_len, 0);
        let payload = &mut out[start..];
        if let (Some(id), Some(value)) = (id_field, self.id) {
            id.order.put_uint(value, &mut payload[..id.width]);
        }
        for field in &self.fields {
            let dest = &mut payload[field.offset..field.offset + field.width()];
            match (&field.codec, &field.source) {
                (Codec::Const(bytes), _) => dest.copy_from_slice(bytes),
                (Codec::Number(n), Source::Counter) => n.encode_count(self.count, dest),
                (Codec::Number(n), source) => {
                    counters.clamped += n.encode_si(source.si_value(now, values), dest);
                }
            }
        }
        self.count = self.count.wrapping_add(1);
    }

    /// Reads a payload (id included) into [`Message::decoded`]; nothing is applied yet.
    /// Returns the number of values clamped to their declared range.
    pub fn decode(&mut self, payload: &[u8]) -> Result<u64, Reject> {
        if payload.len() != self.payload_len {
            return Err(Reject::BadLength);
        }
        let mut clamped = 0;
        for (field, slot) in self.fields.iter().zip(self.decoded.iter_mut()) {
            let src = &payload[field.offset..field.offset + field.width()];
            match &field.codec {
                Codec::Const(bytes) => {
                    if src != bytes.as_slice() {
                        return Err(Reject::BadConstant);
                    }
                }
                Codec::Number(n) => {
                    let (si, was_clamped) = n.decode_si(src).ok_or(Reject::BadValue)?;
                    *slot = si;
                    clamped += u64::from(was_clamped);
                }
            }
        }
        Ok(clamped)
    }

    /// The decoded values with their destinations.
    pub fn decoded_values(&self) -> impl Iterator<Item = (Dest, f64)> + '_ {
        self.fields
            .iter()
            .zip(&self.decoded)
            .filter(|(f, _)| matches!(f.codec, Codec::Number(_)))
            .map(|(f, &v)| (f.dest, v))
    }
}
