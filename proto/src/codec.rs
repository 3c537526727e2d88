//! The one place that calls bincode.
//!
//! Format: bincode 2.0.1 serde encoding with `config::legacy()` — little-endian,
//! fixed-width integers, `f64` as IEEE-754 binary64 LE, `bool` as one byte
//! (0/1), enum variants as a u32 LE index, `Vec` as a u64 LE count followed by
//! the elements, fixed arrays and structs as their fields in order with no
//! padding — plus a decode limit of [`MAX_MESSAGE_BYTES`] (the encoder ignores it).
//!
//! Decoding is layered so that it never panics and reports precise errors:
//! 1. buffer larger than [`MAX_MESSAGE_BYTES`] → [`DecodeError::TooLarge`];
//! 2. first two bytes (u16 LE) ≠ [`PROTOCOL_VERSION`] → [`DecodeError::UnknownVersion`]
//!    (fewer than two bytes → [`DecodeError::Length`]);
//! 3. the total length implied by the message's [`WireLayout`](crate::WireLayout)
//!    (fixed size, enum tag, or the walked count prefixes) is compared with the buffer →
//!    [`DecodeError::Length`] / [`DecodeError::TrailingBytes`], or
//!    [`DecodeError::Malformed`] for an unknown tag or an excessive count; this
//!    also bounds any allocation before bincode sees a length prefix;
//! 4. bincode decodes; bad enum tags, bool bytes etc. → [`DecodeError::Malformed`];
//! 5. [`WireMessage::validate`], from the wire table: first the rest of step 4 that bincode
//!    does not check (a bounded `u8` count such as a [`crate::CssMsg`]'s detectors, a text
//!    field's padding → [`DecodeError::Malformed`]), then step 5 proper (a non-finite value
//!    where the table says `finite` → [`DecodeError::NonFinite`]).
//!
//! Each message's `decode_*` function and its `WireMessage` impl are generated from the wire
//! table into `wire.rs`.

use bincode::config::{Configuration, Fixint, Limit, LittleEndian};

use crate::{DecodeError, Header, WireMessage, HEADER_LEN, MAX_MESSAGE_BYTES, PROTOCOL_VERSION};

/// The bincode configuration of the wire format.
const CONFIG: Configuration<LittleEndian, Fixint, Limit<MAX_MESSAGE_BYTES>> =
    bincode::config::legacy().with_limit::<MAX_MESSAGE_BYTES>();

/// Encode a message into a new buffer.
pub fn encode<M: WireMessage>(msg: &M) -> Vec<u8> {
    let mut buf = Vec::new();
    encode_into(msg, &mut buf);
    buf
}

/// Encode a message into `buf`, replacing its contents but keeping its
/// capacity, so a publisher can reuse one buffer without allocating per frame.
///
/// Encoding cannot fail; it does not run [`WireMessage::validate`], and a
/// [`crate::StateMsg`] with more than [`crate::MAX_EFFECTORS`] effectors encodes fine but
/// is rejected by decoders.
pub fn encode_into<M: WireMessage>(msg: &M, buf: &mut Vec<u8>) {
    buf.clear();
    // Writing to a Vec cannot fail, and every WireMessage is made of fixed-width
    // numbers, bools, unit/struct enum variants and one Vec with a known length,
    // none of which can make bincode's serde encoder error.
    bincode::serde::encode_into_std_write(msg, buf, CONFIG)
        .expect("encoding a WireMessage into a Vec is infallible");
}

/// Decode one message occupying all of `bytes`. Never panics.
pub fn decode<M: WireMessage>(bytes: &[u8]) -> Result<M, DecodeError> {
    check_size_and_version(bytes, M::MIN_LEN)?;
    let expected = M::LAYOUT.expected_len(bytes)?;
    if bytes.len() < expected {
        return Err(DecodeError::Length {
            needed: expected,
            actual: bytes.len(),
        });
    }
    if bytes.len() > expected {
        return Err(DecodeError::TrailingBytes {
            expected,
            actual: bytes.len(),
        });
    }
    let (msg, used): (M, usize) = bincode::serde::decode_from_slice(bytes, CONFIG)
        .map_err(|e| map_err(M::NAME, bytes.len(), e))?;
    if used != bytes.len() {
        return Err(DecodeError::TrailingBytes {
            expected: used,
            actual: bytes.len(),
        });
    }
    msg.validate()?;
    Ok(msg)
}

/// Decode only the leading [`Header`] of any message (e.g. to count a
/// wrong-spacecraft command before decoding it fully). Checks size limit,
/// version and that at least [`HEADER_LEN`] bytes are present; the rest of the
/// buffer is not inspected.
pub fn decode_header(bytes: &[u8]) -> Result<Header, DecodeError> {
    check_size_and_version(bytes, HEADER_LEN)?;
    let head = bytes.get(..HEADER_LEN).ok_or(DecodeError::Length {
        needed: HEADER_LEN,
        actual: bytes.len(),
    })?;
    let (header, _): (Header, usize) = bincode::serde::decode_from_slice(head, CONFIG)
        .map_err(|e| map_err("Header", head.len(), e))?;
    Ok(header)
}

fn check_size_and_version(bytes: &[u8], min_len: usize) -> Result<(), DecodeError> {
    if bytes.len() > MAX_MESSAGE_BYTES {
        return Err(DecodeError::TooLarge {
            actual: bytes.len(),
            max: MAX_MESSAGE_BYTES,
        });
    }
    let found = match bytes {
        [lo, hi, ..] => u16::from_le_bytes([*lo, *hi]),
        _ => {
            return Err(DecodeError::Length {
                needed: min_len,
                actual: bytes.len(),
            })
        }
    };
    if found != PROTOCOL_VERSION {
        return Err(DecodeError::UnknownVersion { found });
    }
    Ok(())
}

fn map_err(what: &str, actual: usize, e: bincode::error::DecodeError) -> DecodeError {
    use bincode::error::DecodeError as B;
    match e {
        B::UnexpectedEnd { additional } => DecodeError::Length {
            needed: actual.saturating_add(additional),
            actual,
        },
        B::LimitExceeded => DecodeError::TooLarge {
            actual,
            max: MAX_MESSAGE_BYTES,
        },
        other => DecodeError::Malformed(format!("{what}: {other}")),
    }
}
