//! [`BinaryDevice`]: a device of described binary messages: it sends its out-messages when
//! due, decodes the driver's frames, applies commands, answers requests and runs its speed
//! loop. Every buffer is sized at construction.

use super::counters::DeviceCounters;
use super::engine::MAX_READ_CHUNK;
use super::field::Dest;
use super::message::{Direction, IdField, Message, Reject, Schedule};
use super::speed_loop::SpeedLoop;
use super::time::TickTime;
use super::wire::{Wire, WireReject};
use crate::framing::{DecodeCounters, StreamDecoder};

/// A described binary device.
pub struct BinaryDevice {
    tx: Transmitter,
    decoder: Box<dyn StreamDecoder + Send>,
    messages: Vec<Message>,
    speed_loop: Option<SpeedLoop>,
    /// Framing rejections found after the decoder (SLIP's and COBS's checks).
    wire_rejects: DecodeCounters,
}

/// What sending a message needs: the framing, the id field and a payload buffer.
#[derive(Debug)]
struct Transmitter {
    wire: Wire,
    id_field: Option<IdField>,
    /// The payload being encoded (capacity: the longest payload).
    payload: Vec<u8>,
    /// Where each frame appended by the current call ends in `out` (capacity: the most frames
    /// one call appends), so a datagram endpoint sends each frame as its own datagram.
    frame_ends: Vec<usize>,
}

impl Transmitter {
    /// Encodes and frames out-message `message` into `out`.
    fn send(
        &mut self,
        message: &mut Message,
        now: &TickTime,
        values: &[f64],
        counters: &mut DeviceCounters,
        out: &mut Vec<u8>,
    ) {
        self.payload.clear();
        message.encode(self.id_field, now, values, counters, &mut self.payload);
        match self
            .wire
            .encode(&self.payload, message.apid, true, now, out)
        {
            Ok(()) => {
                counters.frames_out += 1;
                if self.frame_ends.len() < self.frame_ends.capacity() {
                    self.frame_ends.push(out.len());
                }
            }
            Err(_) => counters.unsendable += 1,
        }
    }
}

impl std::fmt::Debug for BinaryDevice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BinaryDevice")
            .field("wire", &self.tx.wire)
            .field("messages", &self.messages)
            .finish_non_exhaustive()
    }
}

/// Frames and lockstep inputs taken by one [`BinaryDevice::take_bytes`] call.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Taken {
    /// Frames accepted and applied (commands) or answered (requests).
    pub frames_accepted: u32,
    /// Of those, frames of messages the driver owes in lockstep (`due_every_s`).
    pub due_received: u32,
}

impl BinaryDevice {
    /// A device of these messages over this wire.
    pub fn new(
        wire: Wire,
        id_field: Option<IdField>,
        messages: Vec<Message>,
        speed_loop: Option<SpeedLoop>,
    ) -> Self {
        let max_payload = messages.iter().map(|m| m.payload_len).max().unwrap_or(0);
        let max_in_payload = messages
            .iter()
            .filter(|m| m.direction == Direction::In)
            .map(|m| m.payload_len)
            .max()
            .unwrap_or(0);
        Self {
            decoder: wire.decoder(max_in_payload.max(1)),
            tx: Transmitter {
                wire,
                id_field,
                payload: Vec::with_capacity(max_payload),
                // One call appends at most every out-message (emit_due) or one response per
                // octet of a read chunk (take_bytes).
                frame_ends: Vec::with_capacity(messages.len().max(MAX_READ_CHUNK + 1)),
            },
            messages,
            speed_loop,
            wire_rejects: DecodeCounters::default(),
        }
    }

    /// Where each frame the last `emit_due` or `take_bytes` call appended ends in its `out`.
    pub fn frame_ends(&self) -> &[usize] {
        &self.tx.frame_ends
    }

    /// The messages, in description order.
    pub fn messages(&self) -> &[Message] {
        &self.messages
    }

    /// The speed loop, if the device has one.
    pub fn speed_loop(&self) -> Option<&SpeedLoop> {
        self.speed_loop.as_ref()
    }

    /// The most octets one [`BinaryDevice::emit_due`] call appends: every scheduled message.
    pub fn max_emit_len(&self) -> usize {
        self.messages
            .iter()
            .filter(|m| m.direction == Direction::Out && m.schedule != Schedule::Never)
            .map(|m| self.tx.wire.max_frame_len(m.payload_len))
            .sum()
    }

    /// The most octets one [`BinaryDevice::take_bytes`] call of `input_len` octets appends:
    /// each response needs a request frame, all but the first wholly inside the input.
    pub fn max_take_len(&self, input_len: usize) -> usize {
        let requests = self
            .messages
            .iter()
            .filter(|m| m.direction == Direction::In)
            .filter_map(|m| {
                let response = &self.messages[m.response?];
                Some((
                    self.tx.wire.min_frame_len(m.payload_len).max(1),
                    self.tx.wire.max_frame_len(response.payload_len),
                ))
            });
        let min_request = requests.clone().map(|(min, _)| min).min();
        let max_response = requests.map(|(_, max)| max).max();
        match (min_request, max_response) {
            (Some(min), Some(max)) => (1 + input_len / min) * max,
            _ => 0,
        }
    }

    /// Appends every out-message due at `now`; returns the frames written.
    pub fn emit_due(
        &mut self,
        now: &TickTime,
        values: &[f64],
        fresh: &[bool],
        counters: &mut DeviceCounters,
        out: &mut Vec<u8>,
    ) -> usize {
        let before = counters.frames_out;
        let Self { tx, messages, .. } = self;
        tx.frame_ends.clear();
        for message in messages.iter_mut() {
            let due = message.direction == Direction::Out
                && match message.schedule {
                    Schedule::Every { period_ticks } => now.tick.is_multiple_of(period_ticks),
                    Schedule::OnSample { group } => fresh.get(group).copied().unwrap_or(false),
                    Schedule::Never => false,
                };
            if due {
                tx.send(message, now, values, counters, out);
            }
        }
        (counters.frames_out - before) as usize
    }

    /// Decodes the driver's octets: applies commands, answers requests, counts the rest.
    pub fn take_bytes(
        &mut self,
        bytes: &[u8],
        now: &TickTime,
        values: &[f64],
        commands: &mut [f64],
        counters: &mut DeviceCounters,
        out: &mut Vec<u8>,
    ) -> Taken {
        let mut taken = Taken::default();
        let Self {
            tx,
            decoder,
            messages,
            speed_loop,
            wire_rejects,
        } = self;
        tx.frame_ends.clear();
        decoder.feed(bytes, &mut |frame| {
            let unwrapped = match tx.wire.unwrap(frame, wire_rejects) {
                Ok(u) => u,
                Err(WireReject::Counted) => return,
                Err(WireReject::BadConstant) => {
                    counters.bad_constant += 1;
                    return;
                }
            };
            let id = match tx.id_field {
                Some(id) => match unwrapped.payload.get(..id.width) {
                    Some(octets) => Some(id.order.read_uint(octets)),
                    None => {
                        counters.bad_length += 1;
                        return;
                    }
                },
                None => None,
            };
            let selects = |m: &Message| {
                (id.is_none() || m.id == id)
                    && (unwrapped.apid.is_none() || m.apid == unwrapped.apid)
            };
            // An in-message first: a reply may carry its request's id.
            let Some(index) = messages
                .iter()
                .position(|m| m.direction == Direction::In && selects(m))
            else {
                if messages.iter().any(selects) {
                    counters.unknown_request += 1;
                } else {
                    counters.unknown_id += 1;
                }
                return;
            };
            let message = &mut messages[index];
            match message.decode(unwrapped.payload) {
                Err(Reject::BadLength) => counters.bad_length += 1,
                Err(Reject::BadConstant) => counters.bad_constant += 1,
                Err(Reject::BadValue) => counters.bad_value += 1,
                Ok(clamped) => {
                    counters.clamped += clamped;
                    for (dest, value) in message.decoded_values() {
                        match dest {
                            Dest::Input(input) => {
                                if let Some(slot) = commands.get_mut(input) {
                                    *slot = value;
                                }
                                if let Some(speed_loop) = speed_loop.as_mut() {
                                    if speed_loop.torque_input == input {
                                        speed_loop.set_torque_mode();
                                    }
                                }
                            }
                            Dest::SpeedSetpoint => {
                                if let Some(speed_loop) = speed_loop.as_mut() {
                                    speed_loop.set_speed(value);
                                }
                            }
                            Dest::Ignore => {}
                        }
                    }
                    if let Some(slot) = counters.frames_in.get_mut(index) {
                        *slot += 1;
                    }
                    taken.frames_accepted += 1;
                    if message.due_period_ticks.is_some() {
                        taken.due_received += 1;
                    }
                    if let Some(response) = message.response {
                        let response = &mut messages[response];
                        tx.send(response, now, values, counters, out);
                    }
                }
            }
        });
        counters.framing = merge(decoder.counters(), wire_rejects);
        taken
    }

    /// The speed loop's torque, in speed mode.
    pub fn drive(&mut self, values: &[f64], commands: &mut [f64]) {
        if let Some(speed_loop) = &self.speed_loop {
            speed_loop.drive(values, commands);
        }
    }

    /// Whether in-message `message` is due from the driver at `tick` (lockstep).
    pub fn input_due(&self, message: usize, tick: u64) -> bool {
        self.messages
            .get(message)
            .and_then(|m| m.due_period_ticks)
            .is_some_and(|p| tick.is_multiple_of(p))
    }

    /// Whether the device takes input messages of which none is ever due (in lockstep the
    /// runtime never waits for them).
    pub fn has_undue_inputs(&self) -> bool {
        let inputs = self
            .messages
            .iter()
            .filter(|m| m.direction == Direction::In);
        inputs.clone().next().is_some() && inputs.clone().all(|m| m.due_period_ticks.is_none())
    }

    /// In-messages owed at `tick` in lockstep.
    pub fn inputs_due(&self, tick: u64) -> u32 {
        self.messages
            .iter()
            .filter_map(|m| m.due_period_ticks)
            .filter(|&p| tick.is_multiple_of(p))
            .count() as u32
    }
}

/// The decoder's tallies plus the rejections made after it.
fn merge(decoder: &DecodeCounters, after: &DecodeCounters) -> DecodeCounters {
    DecodeCounters {
        frames: decoder.frames,
        garbage_bytes: decoder.garbage_bytes + after.garbage_bytes,
        bad_checksum: decoder.bad_checksum + after.bad_checksum,
        bad_length: decoder.bad_length + after.bad_length,
        oversize: decoder.oversize + after.oversize,
        bad_escape: decoder.bad_escape + after.bad_escape,
        bad_encoding: decoder.bad_encoding + after.bad_encoding,
        aborted: decoder.aborted + after.aborted,
    }
}
