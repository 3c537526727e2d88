//! Messages read in place, without allocating: for the callers that must judge a message on a
//! path that allocates nothing (the server's check of each flight-code telemetry sample, on a
//! thread that may step the frames in lockstep; its damaged-link check, which reads each damaged
//! command on the stepping thread).
//!
//! Every message of the wire table has a view, generated from the table into `views.rs`
//! (`cargo run -p flexdyn-wiregen`): `view_<message>(bytes)` (`view_command`, `view_fsw`, …)
//! returns an `…View` (`CommandView`, `FswView`, …) with one accessor per field, or the class of
//! [`DecodeError`] that the message's `decode_*` gives for the same bytes. A view accepts exactly
//! the bytes its decoder accepts, with the same values (`tests/proptests.rs` checks every view
//! against its decoder on arbitrary, truncated and bit-damaged messages). The checks, in
//! `decode`'s order (module docs of the codec): at most [`MAX_MESSAGE_BYTES`]; the protocol
//! version; the length the layout implies (the walk of the counts and the tag, shared with the
//! decoder) against the buffer; what bincode refuses (an enum tag it does not know, a bool byte
//! other than 0 or 1) and the rest of step 4 (a bounded `u8` count, a text field's padding), all
//! [`ViewError::Malformed`]; then step 5, every `finite` number ([`ViewError::NonFinite`]).
//!
//! A variable-length part is read as a [`Prims`] (a `vec` of numbers) or a [`List`] of element
//! views (a `vec` of structs, `EffectorInputView`, `EffectorStateView`), walked as it is
//! iterated. This file is the machinery the generated views use.

use std::marker::PhantomData;

use crate::layout::WireLayout;
use crate::{DecodeError, WireMessage, MAX_MESSAGE_BYTES, PROTOCOL_VERSION};

pub use crate::views::*;

/// Why a view refused: the class of the [`DecodeError`] the message's decoder gives for the same
/// bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewError {
    /// [`DecodeError::UnknownVersion`].
    UnknownVersion {
        /// The version the bytes carry.
        found: u16,
    },
    /// [`DecodeError::NonFinite`].
    NonFinite,
    /// Any other: too large, too short, trailing bytes, an unknown tag, a count too large, a
    /// bool byte other than 0 or 1, a text field's padding.
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

/// A message's view: what the generic callers (the property tests, tools) use.
pub trait MessageView<'a>: Sized + Copy {
    /// The message it reads.
    type Msg: WireMessage;

    /// Reads `bytes` in place (module docs). Allocates nothing.
    fn read(bytes: &'a [u8]) -> Result<Self, ViewError>;

    /// The owned message (allocates for a `vec`): for tests and tools.
    fn to_msg(&self) -> Self::Msg;
}

/// A number as the wire holds it: little-endian, fixed width. The one reader of numbers at an
/// offset, for the views and for the decoder's walk of the counts (`layout.rs`).
pub trait WirePrim: Copy + Default {
    /// Its encoded size (bytes).
    const SIZE: usize;

    /// The value at byte `at` of `b`, if `b` holds it.
    fn read_le(b: &[u8], at: usize) -> Option<Self>;

    /// The value at byte `at` of `b` (the default if `b` ends first: a view reads validated
    /// bytes, so that never happens).
    fn at(b: &[u8], at: usize) -> Self {
        Self::read_le(b, at).unwrap_or_default()
    }
}

macro_rules! wire_prim {
    ($($t:ty),*) => {$(
        impl WirePrim for $t {
            const SIZE: usize = std::mem::size_of::<$t>();

            fn read_le(b: &[u8], at: usize) -> Option<Self> {
                let bytes = b.get(at..at.checked_add(Self::SIZE)?)?;
                Some(<$t>::from_le_bytes(bytes.try_into().ok()?))
            }
        }
    )*};
}

wire_prim!(u8, u16, u32, u64, i32, f64);

impl WirePrim for bool {
    const SIZE: usize = 1;

    fn read_le(b: &[u8], at: usize) -> Option<Self> {
        b.get(at).map(|&x| x != 0)
    }
}

/// The `T` at byte `at` of `b`.
pub(crate) fn rd<T: WirePrim>(b: &[u8], at: usize) -> T {
    T::at(b, at)
}

/// The `N` `T`s from byte `at` of `b`.
pub(crate) fn rd_arr<T: WirePrim, const N: usize>(b: &[u8], at: usize) -> [T; N] {
    let mut out = [T::default(); N];
    for (k, x) in out.iter_mut().enumerate() {
        *x = T::at(b, at + k * T::SIZE);
    }
    out
}

/// Whether the `n` text bytes from `at` follow the text rule: after the first NUL, only NULs
/// (`FaultTarget::check_padding`).
pub(crate) fn text_ok(b: &[u8], at: usize, n: usize) -> bool {
    let text = b.get(at..at + n).unwrap_or_default();
    text.iter()
        .position(|&x| x == 0)
        .is_none_or(|end| text[end..].iter().all(|&x| x == 0))
}

/// Whether `x` holds a NaN or an infinity.
pub(crate) fn any_non_finite<const N: usize>(x: &[f64; N]) -> bool {
    x.iter().any(|v| !v.is_finite())
}

/// The offset after the `vec` of `size`-byte elements whose count is at byte `at` of `b`.
pub(crate) fn skip_vec(b: &[u8], at: usize, size: usize) -> usize {
    let n = usize::try_from(rd::<u64>(b, at)).unwrap_or(usize::MAX);
    at.saturating_add(8).saturating_add(n.saturating_mul(size))
}

/// `decode`'s first three checks: at most [`MAX_MESSAGE_BYTES`], the protocol version, and
/// the length `layout` implies. Allocates nothing.
pub(crate) fn check_frame(bytes: &[u8], layout: WireLayout) -> Result<(), ViewError> {
    if bytes.len() > MAX_MESSAGE_BYTES {
        return Err(ViewError::Malformed);
    }
    let found = u16::read_le(bytes, 0).ok_or(ViewError::Malformed)?;
    if found != PROTOCOL_VERSION {
        return Err(ViewError::UnknownVersion { found });
    }
    let expected = match layout {
        WireLayout::Fixed { len } => len,
        WireLayout::Walked { walk, .. } => walk(bytes).map_err(|_| ViewError::Malformed)?,
    };
    if bytes.len() == expected {
        Ok(())
    } else {
        Err(ViewError::Malformed)
    }
}

/// A `vec` of numbers, read in place.
#[derive(Clone, Copy, PartialEq)]
pub struct Prims<'a, T> {
    bytes: &'a [u8],
    of: PhantomData<T>,
}

impl<'a, T: WirePrim> Prims<'a, T> {
    /// The `vec` whose count is at byte `at` of `b`.
    pub(crate) fn at(b: &'a [u8], at: usize) -> Self {
        let end = skip_vec(b, at, T::SIZE).min(b.len());
        Self {
            bytes: b.get(at.saturating_add(8)..end).unwrap_or_default(),
            of: PhantomData,
        }
    }

    /// How many numbers.
    pub fn len(&self) -> usize {
        self.bytes.len() / T::SIZE
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// Number `i` (`None` beyond [`Self::len`]).
    pub fn get(&self, i: usize) -> Option<T> {
        (i < self.len()).then(|| T::at(self.bytes, i * T::SIZE))
    }

    /// The numbers, in order.
    pub fn iter(&self) -> impl Iterator<Item = T> + 'a {
        let bytes = self.bytes;
        (0..bytes.len() / T::SIZE).map(move |i| T::at(bytes, i * T::SIZE))
    }
}

impl<T: WirePrim + std::fmt::Debug> std::fmt::Debug for Prims<'_, T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

/// A struct of a `vec` read in place: it knows its own length.
pub trait Element<'a>: Copy {
    /// The element at the start of `bytes`, and the bytes after it.
    fn split(bytes: &'a [u8]) -> (Self, &'a [u8]);
}

/// A `vec` of structs, read in place: its elements are walked as it is iterated.
#[derive(Clone, Copy, PartialEq)]
pub struct List<'a, E> {
    count: usize,
    bytes: &'a [u8],
    of: PhantomData<E>,
}

impl<'a, E: Element<'a>> List<'a, E> {
    /// The `vec` whose count is at byte `at` of `b` (its elements run to the end of `b`).
    pub(crate) fn at(b: &'a [u8], at: usize) -> Self {
        Self {
            count: usize::try_from(rd::<u64>(b, at)).unwrap_or(0),
            bytes: b.get(at.saturating_add(8)..).unwrap_or_default(),
            of: PhantomData,
        }
    }

    /// How many elements.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The elements, in order.
    pub fn iter(&self) -> impl Iterator<Item = E> + 'a {
        let mut rest = self.bytes;
        (0..self.count).map(move |_| {
            let (e, after) = E::split(rest);
            rest = after;
            e
        })
    }
}

impl<'a, E: Element<'a> + std::fmt::Debug> std::fmt::Debug for List<'a, E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}
