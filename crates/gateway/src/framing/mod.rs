//! Byte-stream framings: each an encoder (payload → bytes on the wire) and an incremental
//! decoder (bytes on the wire, in any chunks → payloads).
//!
//! - [`length`]: fixed sync bytes, a length field, an optional check (vendor binary protocols);
//! - [`slip`]: SLIP, RFC 1055;
//! - [`cobs`]: Consistent Overhead Byte Stuffing (Cheshire & Baker, IEEE/ACM Trans.
//!   Networking 7(2), 1999), zero-delimited;
//! - [`hdlc`]: HDLC-like byte stuffing (RFC 1662 §4.2) with an optional FCS;
//! - [`lines`]: newline-terminated text lines (NMEA 0183, command consoles);
//! - [`accumulator`] and [`unstuffer`]: the frame buffer of the delimiter framings and the
//!   unstuffing state machine SLIP and HDLC share;
//! - [`window`]: the stream window of the decoders that parse in place (sync-and-length, and
//!   the device CCSDS Space Packets).
//!
//! Every decoder implements [`StreamDecoder`]. Its contract:
//! - **chunking does not matter**: feeding a stream byte by byte or all at once gives the same
//!   frames and the same [`DecodeCounters`];
//! - **malformed input is counted, never delivered**: each rejected frame adds one to the
//!   counter of its reason ([`Malformed`]), bytes outside any frame add to
//!   [`DecodeCounters::garbage_bytes`], and the decoder resynchronises on the next frame;
//! - **bounded**: nothing longer than the capacity given at construction is held: a delimited
//!   frame that outgrows it is dropped whole, a length field that announces more is rejected,
//!   each counted once as oversize, so a flood costs no memory;
//! - **no allocation after construction**: buffers are sized by `new`, and `feed` hands each
//!   frame to the callback as a borrowed slice of them (`tests/no_alloc.rs` checks it).

pub mod accumulator;
pub mod cobs;
pub mod counters;
pub mod error;
pub mod frame_check;
pub mod hdlc;
pub mod length;
pub mod lines;
pub mod slip;
pub mod unstuffer;
pub mod window;

pub use counters::{DecodeCounters, Malformed};
pub use error::FramingError;
pub use frame_check::FrameCheck;

/// An incremental decoder of one framing.
pub trait StreamDecoder {
    /// Consumes `input` (any part of the stream, of any length) and calls `on_frame` with each
    /// frame completed by it, in order. Bytes of an incomplete frame are kept for the next call.
    fn feed(&mut self, input: &[u8], on_frame: &mut dyn FnMut(&[u8]));

    /// What has been accepted and rejected so far.
    fn counters(&self) -> &DecodeCounters;

    /// Bytes held of a frame not yet complete.
    fn pending_bytes(&self) -> usize;
}
