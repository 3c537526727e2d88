//! A message's field: where it sits, how its value is written (type, octet order, scale,
//! offset, unit, range), and where an out-field's value comes from or an in-field's goes.
//!
//! For a numeric field the engineering value is `eng = raw · scale + offset`, in the field's
//! `unit`; the catalog side is SI, `eng = si · factor` ([`crate::device::units`]). An integer
//! field sends `raw = round((eng − offset) / scale)` (half away from zero), saturated to the
//! type's range; a float field sends `(eng − offset) / scale` as IEEE 754 binary32 or binary64.

use crate::device::time::{TickTime, TimeSource};
use crate::ByteOrder;

/// A numeric wire type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    /// Unsigned integer of this many octets (1, 2, 4, 8).
    Unsigned(usize),
    /// Two's-complement integer of this many octets.
    Signed(usize),
    /// IEEE 754 binary32.
    F32,
    /// IEEE 754 binary64.
    F64,
}

impl Scalar {
    /// Every type name and its scalar.
    pub const NAMES: [(&'static str, Scalar); 10] = [
        ("u8", Scalar::Unsigned(1)),
        ("u16", Scalar::Unsigned(2)),
        ("u32", Scalar::Unsigned(4)),
        ("u64", Scalar::Unsigned(8)),
        ("i8", Scalar::Signed(1)),
        ("i16", Scalar::Signed(2)),
        ("i32", Scalar::Signed(4)),
        ("i64", Scalar::Signed(8)),
        ("f32", Scalar::F32),
        ("f64", Scalar::F64),
    ];

    /// The scalar of a type name.
    pub fn by_name(name: &str) -> Option<Scalar> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, s)| s)
    }

    /// Octets on the wire.
    pub fn width(self) -> usize {
        match self {
            Scalar::Unsigned(w) | Scalar::Signed(w) => w,
            Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// An integer type.
    pub fn is_integer(self) -> bool {
        matches!(self, Scalar::Unsigned(_) | Scalar::Signed(_))
    }

    /// The integer range as `f64` (the bounds of a 64-bit type are rounded to the nearest
    /// `f64`: saturating casts keep the written value in range).
    fn range(self) -> (f64, f64) {
        match self {
            Scalar::Unsigned(w) => (0.0, ((1u128 << (8 * w)) - 1) as f64),
            Scalar::Signed(w) => {
                let half = 1i128 << (8 * w - 1);
                (-half as f64, (half - 1) as f64)
            }
            Scalar::F32 | Scalar::F64 => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }

    /// Writes a raw wire value (integers are rounded and saturated; returns whether it was
    /// clamped, a NaN counting as clamped and written as 0).
    fn put(self, raw: f64, order: ByteOrder, dest: &mut [u8]) -> bool {
        match self {
            Scalar::F32 => {
                order.put_uint(u64::from((raw as f32).to_bits()), dest);
                false
            }
            Scalar::F64 => {
                order.put_uint(raw.to_bits(), dest);
                false
            }
            Scalar::Unsigned(_) | Scalar::Signed(_) => {
                let (lo, hi) = self.range();
                let rounded = raw.round();
                let clamped = rounded.is_nan() || rounded < lo || rounded > hi;
                let bits = match self {
                    // `as` casts saturate and map NaN to 0.
                    Scalar::Unsigned(_) => rounded.clamp(lo, hi) as u64,
                    _ => (rounded.clamp(lo, hi) as i64) as u64,
                };
                order.put_uint(bits, dest);
                clamped
            }
        }
    }

    /// Reads a raw wire value.
    fn get(self, order: ByteOrder, src: &[u8]) -> f64 {
        let bits = order.read_uint(src);
        match self {
            Scalar::Unsigned(_) => bits as f64,
            Scalar::Signed(w) => {
                let shift = 64 - 8 * w as u32;
                (((bits << shift) as i64) >> shift) as f64
            }
            Scalar::F32 => f64::from(f32::from_bits(bits as u32)),
            Scalar::F64 => f64::from_bits(bits),
        }
    }
}

/// How a numeric field's value is written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Numeric {
    /// Wire type.
    pub scalar: Scalar,
    /// Octet order.
    pub order: ByteOrder,
    /// Engineering units per raw count.
    pub scale: f64,
    /// Engineering value of raw 0.
    pub offset: f64,
    /// From SI to the field's unit: eng = si · factor.
    pub factor: f64,
    /// Lowest engineering value (clamped and counted).
    pub min: Option<f64>,
    /// Highest engineering value (clamped and counted).
    pub max: Option<f64>,
}

/// A declared `min`/`max` clamp; returns the value and whether it moved.
fn clamp_declared(value: f64, min: Option<f64>, max: Option<f64>) -> (f64, bool) {
    match (min, max) {
        (Some(lo), _) if value < lo => (lo, true),
        (_, Some(hi)) if value > hi => (hi, true),
        _ => (value, false),
    }
}

impl Numeric {
    /// Writes an SI value; returns the number of clamps (0, 1 or 2).
    pub fn encode_si(&self, si: f64, dest: &mut [u8]) -> u64 {
        let (eng, declared) = clamp_declared(si * self.factor, self.min, self.max);
        let raw = (eng - self.offset) / self.scale;
        u64::from(declared) + u64::from(self.scalar.put(raw, self.order, dest))
    }

    /// Writes a counter, modulo the field's width (integer fields only).
    pub fn encode_count(&self, count: u64, dest: &mut [u8]) {
        self.order.put_uint(count, dest);
    }

    /// Reads an SI value: `None` if it is NaN or infinite (a float field); the flag says it was
    /// clamped to the declared range.
    pub fn decode_si(&self, src: &[u8]) -> Option<(f64, bool)> {
        let eng = self.scalar.get(self.order, src) * self.scale + self.offset;
        if !eng.is_finite() {
            return None;
        }
        let (eng, clamped) = clamp_declared(eng, self.min, self.max);
        Some((eng / self.factor, clamped))
    }
}

/// A field's wire form.
#[derive(Debug, Clone, PartialEq)]
pub enum Codec {
    /// A number.
    Number(Numeric),
    /// Constant octets.
    Const(Vec<u8>),
}

/// The catalog channels behind a validity flag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Validity {
    /// The group's first channel.
    pub first_channel: usize,
    /// Its channel count.
    pub channel_count: usize,
    /// Its `valid` channel, if it has one.
    pub flag: Option<usize>,
}

impl Validity {
    /// 1 if every channel of the group is finite and its `valid` channel (if any) is ≥ 0.5.
    pub fn value(&self, values: &[f64]) -> f64 {
        let channels = values
            .get(self.first_channel..self.first_channel + self.channel_count)
            .unwrap_or_default();
        let finite = channels.len() == self.channel_count && channels.iter().all(|v| v.is_finite());
        let flagged = self
            .flag
            .is_none_or(|f| values.get(f).is_some_and(|&v| v >= 0.5));
        if finite && flagged {
            1.0
        } else {
            0.0
        }
    }
}

/// Where an out-field's value comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Source {
    /// A catalog channel (SI).
    Channel(usize),
    /// A group's validity flag, 1 or 0.
    Valid(Validity),
    /// A time of the tick.
    Time(TimeSource),
    /// The message's own counter, wrapping at the field's width.
    Counter,
    /// A constant engineering value (converted to SI at build time).
    Constant(f64),
    /// Nothing: constant octets, or an in-field.
    None,
}

impl Source {
    /// The SI value at `now` (`Counter` and `None` give 0: the caller writes counters).
    pub fn si_value(&self, now: &TickTime, values: &[f64]) -> f64 {
        match self {
            Source::Channel(c) => values.get(*c).copied().unwrap_or(f64::NAN),
            Source::Valid(v) => v.value(values),
            Source::Time(t) => t.value(now),
            Source::Constant(c) => *c,
            Source::Counter | Source::None => 0.0,
        }
    }
}

/// Where an in-field's value goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dest {
    /// A catalog input (`commands[input]`).
    Input(usize),
    /// The speed loop's setpoint (rad/s); puts the loop in speed mode.
    SpeedSetpoint,
    /// Read and checked, not used.
    Ignore,
}

/// A field of a message.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Name (for people).
    pub name: String,
    /// Offset in the payload.
    pub offset: usize,
    /// Wire form.
    pub codec: Codec,
    /// Out-field source.
    pub source: Source,
    /// In-field destination.
    pub dest: Dest,
}

impl Field {
    /// Octets on the wire.
    pub fn width(&self) -> usize {
        match &self.codec {
            Codec::Number(n) => n.scalar.width(),
            Codec::Const(bytes) => bytes.len(),
        }
    }
}
