//! [`Device`]: one configured device as the runtime drives it, whatever its protocol: its
//! name and endpoint, its output schedule, its input decoding, its behaviour (a speed loop),
//! its lockstep expectations, its latency and its counters.
//!
//! After construction, [`Device::emit_due`], [`Device::take_bytes`] (with at most
//! [`MAX_READ_CHUNK`] octets) and [`Device::drive`] allocate nothing when `out` has
//! [`Device::max_output_len`] octets of spare capacity (`tests/no_alloc.rs`).

use std::time::Duration;

use super::binary::BinaryDevice;
pub use super::binary::Taken;
use super::counters::DeviceCounters;
use super::endpoint::EndpointSpec;
use super::nmea_device::NmeaDevice;
use super::time::TickTime;

/// The most octets the runtime should hand [`Device::take_bytes`] per call for the bound of
/// [`Device::max_output_len`] to hold (a larger chunk is decoded the same, but its responses
/// may need more room than reserved).
pub const MAX_READ_CHUNK: usize = 4096;

/// A device's protocol engine.
#[derive(Debug)]
pub enum Behaviour {
    /// Described binary messages.
    Binary(BinaryDevice),
    /// NMEA 0183 from a GPS receiver.
    Nmea(NmeaDevice),
}

/// One configured device.
#[derive(Debug)]
pub struct Device {
    name: String,
    endpoint: EndpointSpec,
    latency_ns: u64,
    timeout: Duration,
    message_names: Vec<String>,
    counters: DeviceCounters,
    behaviour: Behaviour,
}

impl Device {
    /// A device; `message_names` index [`DeviceCounters::frames_in`].
    pub fn new(
        name: String,
        endpoint: EndpointSpec,
        latency_ns: u64,
        timeout: Duration,
        message_names: Vec<String>,
        behaviour: Behaviour,
    ) -> Self {
        let counters = DeviceCounters {
            frames_in: vec![0; message_names.len()],
            ..DeviceCounters::default()
        };
        Self {
            name,
            endpoint,
            latency_ns,
            timeout,
            message_names,
            counters,
            behaviour,
        }
    }

    /// The device's name in the list.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Where its byte stream is exposed.
    pub fn endpoint(&self) -> &EndpointSpec {
        &self.endpoint
    }

    /// The protocol engine.
    pub fn behaviour(&self) -> &Behaviour {
        &self.behaviour
    }

    /// The message names, in the order of [`DeviceCounters::frames_in`] (NMEA: the sentences).
    pub fn message_names(&self) -> &[String] {
        &self.message_names
    }

    /// Upper bound of the octets one [`Device::emit_due`] call, or one [`Device::take_bytes`]
    /// call of at most [`MAX_READ_CHUNK`] octets, appends to `out`.
    pub fn max_output_len(&self) -> usize {
        match &self.behaviour {
            Behaviour::Binary(b) => b.max_emit_len().max(b.max_take_len(MAX_READ_CHUNK)),
            Behaviour::Nmea(n) => n.max_emit_len(),
        }
    }

    /// Appends every output frame due at this tick (periodic by rate, or on a fresh sample of
    /// its group); returns the frames written. `values[channel]` holds each catalog channel's
    /// latest value, `fresh[group]` whether that group published at this tick.
    pub fn emit_due(
        &mut self,
        now: &TickTime,
        values: &[f64],
        fresh: &[bool],
        out: &mut Vec<u8>,
    ) -> usize {
        match &mut self.behaviour {
            Behaviour::Binary(b) => b.emit_due(now, values, fresh, &mut self.counters, out),
            Behaviour::Nmea(n) => n.emit_due(now, values, fresh, &mut self.counters, out),
        }
    }

    /// Takes octets read from the driver (any chunking): a command frame writes its fields
    /// into `commands[input]`, a request frame appends its response to `out`; malformed input
    /// is counted by reason and never applied.
    pub fn take_bytes(
        &mut self,
        bytes: &[u8],
        now: &TickTime,
        values: &[f64],
        commands: &mut [f64],
        out: &mut Vec<u8>,
    ) -> Taken {
        match &mut self.behaviour {
            Behaviour::Binary(b) => {
                b.take_bytes(bytes, now, values, commands, &mut self.counters, out)
            }
            Behaviour::Nmea(n) => {
                n.take_bytes(bytes, &mut self.counters);
                Taken::default()
            }
        }
    }

    /// Where each frame appended to `out` by the last [`Device::emit_due`] or
    /// [`Device::take_bytes`] call ends (offsets into that `out`, in order), so a datagram
    /// endpoint can send one frame per datagram.
    pub fn frame_ends(&self) -> &[usize] {
        match &self.behaviour {
            Behaviour::Binary(b) => b.frame_ends(),
            Behaviour::Nmea(n) => n.frame_ends(),
        }
    }

    /// Once per tick, after the inputs and before the commands go to the server: device
    /// behaviour (a wheel drive's speed loop in speed mode).
    pub fn drive(&mut self, _now: &TickTime, values: &[f64], commands: &mut [f64]) {
        if let Behaviour::Binary(b) = &mut self.behaviour {
            b.drive(values, commands);
        }
    }

    /// Lockstep: whether message `message` (an index of [`Device::message_names`] and of
    /// [`DeviceCounters::frames_in`]) is owed by the driver at `tick`.
    pub fn input_due(&self, message: usize, tick: u64) -> bool {
        match &self.behaviour {
            Behaviour::Binary(b) => b.input_due(message, tick),
            Behaviour::Nmea(_) => false,
        }
    }

    /// Whether the device takes input messages none of which is ever due: in lockstep nothing
    /// waits for them, so the runtime reads them at no defined tick (it warns at start).
    pub fn has_undue_inputs(&self) -> bool {
        match &self.behaviour {
            Behaviour::Binary(b) => b.has_undue_inputs(),
            Behaviour::Nmea(_) => false,
        }
    }

    /// Lockstep: the input frames (commands and requests) the driver owes at `tick`.
    pub fn inputs_due(&self, tick: u64) -> u32 {
        match &self.behaviour {
            Behaviour::Binary(b) => b.inputs_due(tick),
            Behaviour::Nmea(_) => 0,
        }
    }

    /// Lockstep: how long to wait for the inputs due (the longest declared `timeout_ms` of its
    /// messages; 1 s if none declares one).
    pub fn timeout(&self) -> Duration {
        self.timeout
    }

    /// Real time: \[ns\] the declared output latency.
    pub fn latency_ns(&self) -> u64 {
        self.latency_ns
    }

    /// Frames out, frames in by message, malformed input by reason, values clamped.
    pub fn counters(&self) -> &DeviceCounters {
        &self.counters
    }
}
