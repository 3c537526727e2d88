//! CCSDS Space Packets (CCSDS 133.0-B-2 §4.1) as a described device's framing: each message
//! is one packet of its APID, back to back on the stream, with
//!
//! ```text
//! | primary header (6) | secondary header: CUC time (optional) | payload | check (optional) |
//! ```
//!
//! - packet type: telemetry for out-messages, telecommand for in-messages; sequence flags
//!   `11` (unsegmented); the sequence count runs per APID, from 0, modulo 16384 (§4.1.3.4);
//! - the secondary header, if described, is a CUC time code (CCSDS 301.0-B-4 §3.2) of the
//!   tick's TAI since 1958 (level 1) or of the mission elapsed time (level 2, agency epoch);
//! - the optional check (a packet error control, §4.1.4.3 leaves its form to the mission)
//!   covers the whole packet before it, and is counted in the data length.
//!
//! The decoder ([`CcsdsDecoder`]) reads the stream in a window like the sync-and-length
//! decoder: a candidate whose version is not 000 is dropped one octet at a time as garbage, an
//! impossible data length rejects it (bad length, oversize), a check mismatch rejects it; each
//! rejection drops one octet and searches again. There is no sync marker, so after garbage
//! the first octet whose top three bits are 000 is taken as a header.

use super::time::TickTime;
use crate::ccsds::packet::MAX_DATA_FIELD_BYTES;
use crate::ccsds::primary_header::PRIMARY_HEADER_BYTES;
use crate::ccsds::{Apid, CucFormat, PacketTemplate, PacketType, SequenceCounter, SequenceFlags};
use crate::framing::window::Window;
use crate::framing::{DecodeCounters, FrameCheck, Malformed, StreamDecoder};

/// What the CUC secondary header counts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CucSource {
    /// TAI since 1958-01-01 (needs an epoch).
    Tai1958,
    /// Mission elapsed time (agency-defined epoch).
    Met,
}

/// The Space Packet framing of a device.
#[derive(Debug, Clone, PartialEq)]
pub struct CcsdsFraming {
    /// The secondary header's time code, if any.
    pub secondary: Option<(CucFormat, CucSource)>,
    /// The packet error control, if any.
    pub check: Option<FrameCheck>,
    /// Sequence counters, one per APID sent.
    pub counters: Vec<(u16, SequenceCounter)>,
    /// The secondary header being written (capacity 8 from construction: no allocation).
    scratch: Vec<u8>,
}

/// Why a packet could not be written: a time before the CUC epoch or beyond its range, no
/// epoch for a TAI time, an APID with no counter, or a data field of no octet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unsendable;

impl CcsdsFraming {
    /// A framing with a counter from 0 for each APID of `apids`.
    pub fn new(
        secondary: Option<(CucFormat, CucSource)>,
        check: Option<FrameCheck>,
        apids: &[u16],
    ) -> Self {
        let mut counters: Vec<(u16, SequenceCounter)> = Vec::new();
        for &apid in apids {
            if !counters.iter().any(|(a, _)| *a == apid) {
                counters.push((apid, SequenceCounter::default()));
            }
        }
        Self {
            secondary,
            check,
            counters,
            scratch: Vec::with_capacity(8),
        }
    }

    /// Octets around a payload: primary header, secondary header, check.
    pub fn overhead(&self) -> usize {
        PRIMARY_HEADER_BYTES + self.secondary_len() + self.check_len()
    }

    /// Octets of the secondary header.
    pub fn secondary_len(&self) -> usize {
        self.secondary.map_or(0, |(f, _)| f.len_bytes())
    }

    /// Octets of the check.
    pub fn check_len(&self) -> usize {
        self.check.as_ref().map_or(0, FrameCheck::len_bytes)
    }

    /// Appends one packet of `apid` and `packet_type` carrying `payload`: the primary header
    /// (data length counting secondary header, payload and check), the time code, the payload
    /// and the check over all before it. Nothing is appended on error.
    pub fn encode(
        &mut self,
        apid: u16,
        packet_type: PacketType,
        payload: &[u8],
        now: &TickTime,
        out: &mut Vec<u8>,
    ) -> Result<(), Unsendable> {
        let apid_checked = Apid::new(apid).map_err(|_| Unsendable)?;
        self.scratch.clear();
        if let Some((format, source)) = self.secondary {
            let time_ns = match source {
                CucSource::Tai1958 if !now.has_epoch => return Err(Unsendable),
                CucSource::Tai1958 => now.tai_ns_1958,
                CucSource::Met => now.met_ns,
            };
            let time_ns = i64::try_from(time_ns).map_err(|_| Unsendable)?;
            format
                .encode(time_ns, &mut self.scratch)
                .map_err(|_| Unsendable)?;
        }
        let check_len = self.check_len();
        let data_len = self.scratch.len() + payload.len() + check_len;
        if data_len == 0 || data_len > MAX_DATA_FIELD_BYTES {
            return Err(Unsendable);
        }
        let Some((_, counter)) = self.counters.iter_mut().find(|(a, _)| *a == apid) else {
            return Err(Unsendable);
        };
        let template = PacketTemplate {
            packet_type,
            apid: apid_checked,
            sequence_flags: SequenceFlags::Unsegmented,
        };
        let start = out.len();
        template
            .encode(counter.advance(), &self.scratch, payload, out)
            .map_err(|_| Unsendable)?;
        if let Some(check) = &self.check {
            // The data length counts the check too (data_len ≤ 65536, so − 1 fits 16 bits).
            let length = (data_len - 1) as u16;
            out[start + 4..start + 6].copy_from_slice(&length.to_be_bytes());
            check.append_over(out, start);
        }
        Ok(())
    }
}

/// Incremental decoder of back-to-back Space Packets (see the module documentation).
#[derive(Debug, Clone)]
pub struct CcsdsDecoder {
    check: Option<FrameCheck>,
    /// The fewest octets a packet may have: header, secondary header, one octet, check.
    min_packet_bytes: usize,
    window: Window,
    counters: DecodeCounters,
}

impl CcsdsDecoder {
    /// A decoder of packets up to `max_packet_bytes` octets (the window, allocated here).
    pub fn new(framing: &CcsdsFraming, max_packet_bytes: usize) -> Self {
        let min_packet_bytes = framing.overhead() + 1;
        Self {
            check: framing.check.clone(),
            min_packet_bytes,
            window: Window::new(max_packet_bytes.max(min_packet_bytes)),
            counters: DecodeCounters::default(),
        }
    }

    fn parse(&mut self, on_frame: &mut dyn FnMut(&[u8])) {
        loop {
            let pending = self.window.pending();
            let Some(&first) = pending.first() else {
                return;
            };
            // Version number 000 (bits 0–2).
            if first >> 5 != 0 {
                self.counters.garbage_bytes += 1;
                self.window.consume(1);
                continue;
            }
            if pending.len() < PRIMARY_HEADER_BYTES {
                return;
            }
            let data_length = usize::from(u16::from_be_bytes([pending[4], pending[5]]));
            let packet_len = PRIMARY_HEADER_BYTES + data_length + 1;
            let reason = if packet_len < self.min_packet_bytes {
                Some(Malformed::BadLength)
            } else if packet_len > self.window.capacity() {
                Some(Malformed::Oversize)
            } else {
                None
            };
            if let Some(reason) = reason {
                self.counters.record(reason);
                self.window.consume(1);
                continue;
            }
            if pending.len() < packet_len {
                return;
            }
            let packet = &pending[..packet_len];
            let good = self
                .check
                .as_ref()
                .is_none_or(|c| c.strip(packet).is_some());
            if good {
                on_frame(packet);
                self.counters.frames += 1;
                self.window.consume(packet_len);
            } else {
                self.counters.bad_checksum += 1;
                self.window.consume(1);
            }
        }
    }
}

impl StreamDecoder for CcsdsDecoder {
    fn feed(&mut self, mut input: &[u8], on_frame: &mut dyn FnMut(&[u8])) {
        while !input.is_empty() {
            self.window.fill_from(&mut input);
            self.parse(on_frame);
        }
    }

    fn counters(&self) -> &DecodeCounters {
        &self.counters
    }

    fn pending_bytes(&self) -> usize {
        self.window.pending().len()
    }
}
