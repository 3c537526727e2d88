//! [`DeviceCounters`]: a device's tallies of frames sent and received and of malformed
//! input by reason. Sized at construction; updating them allocates nothing.

use crate::framing::DecodeCounters;

/// Frames out, frames in by message, malformed input by reason, values clamped.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct DeviceCounters {
    /// Frames written to the driver (outputs and responses).
    pub frames_out: u64,
    /// Frames accepted from the driver, by message index
    /// ([`crate::device::Device::message_names`]).
    pub frames_in: Vec<u64>,
    /// The framing layer's tallies: frames delimited, garbage octets, and frames rejected for a
    /// bad check, bad length field, oversize, bad escape, bad encoding or abort.
    pub framing: DecodeCounters,
    /// Frames whose id (or APID) selects no message.
    pub unknown_id: u64,
    /// Frames whose id selects a message of the device's own (an output): not a request or
    /// command the device takes.
    pub unknown_request: u64,
    /// Frames of a known message whose payload is not that message's length.
    pub bad_length: u64,
    /// Frames whose constant octets (sync-to-length header, a field's `const_bytes`, a CCSDS
    /// header's type or secondary-header flag) are not the described ones.
    pub bad_constant: u64,
    /// Frames with a floating-point field that is NaN or infinite.
    pub bad_value: u64,
    /// Values clamped: to a field's declared `min`/`max`, or saturated to an integer field's
    /// range (a NaN written as 0 counts too).
    pub clamped: u64,
    /// Outputs due that could not be encoded (no epoch for a UTC time, a value an NMEA
    /// field cannot hold, a time before the CUC epoch): nothing is written for them.
    pub unsendable: u64,
}

impl DeviceCounters {
    /// Malformed frames from the driver, every reason together (garbage octets excluded).
    pub fn rejected_frames(&self) -> u64 {
        self.framing.rejected_frames()
            + self.unknown_id
            + self.unknown_request
            + self.bad_length
            + self.bad_constant
            + self.bad_value
    }

    /// Frames accepted, every message together.
    pub fn accepted_frames(&self) -> u64 {
        self.frames_in.iter().sum()
    }
}
