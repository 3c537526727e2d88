//! The devices at run time: each described device with its endpoint and its outbox, fed one
//! complete tick at a time, and the actuator inputs its driver set.
//!
//! Per tick, in this order:
//! 1. the tick's samples are copied into the channels ([`VehicleCatalog::fill`]);
//! 2. each device writes the outputs due at the tick (periodic, or on a fresh sample) into its
//!    outbox, to go at once in lockstep and its declared latency later in real time;
//! 3. **lockstep**: the gateway reads each device whose driver owes input at this tick (its
//!    commands and requests, [`Device::inputs_due`]) until it has them all or the device's
//!    time-out passes, answering each request from this tick's values; a device that owes
//!    nothing is not read, so a driver's early bytes wait for the tick they are due at.
//!    **Real time**: whatever the drivers wrote is read;
//! 4. each device's behaviour runs ([`Device::drive`]: a wheel drive's speed loop);
//! 5. the inputs go to the server as one `Actuators` command ([`Gateway::commands`]).
//!
//! The same drivers, paced by the devices' outputs, therefore give the same command at the same
//! tick on every run.

use std::path::Path;
use std::time::{Duration, Instant};

use flexdyn_gateway::device::engine::Behaviour;
use flexdyn_gateway::device::{Device, DeviceCounters, DeviceSet, EndpointSpec, TickTime, Utc};
use flexdyn_proto::client::lockstep::Tick;
use flexdyn_proto::{time_flags, TimeMsg};

use crate::catalog::VehicleCatalog;
use crate::endpoint::outbox::{Outbox, OutboxCounters};
use crate::endpoint::{poll_any, Endpoint, EndpointError};

/// Bytes an outbox holds at most before it drops frames (a driver that does not read).
const OUTBOX_BYTES: usize = 64 * 1024;
/// Bytes taken from a driver per read.
const READ_CHUNK: usize = 4096;

/// How the server paces the run (from its time messages).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pacing {
    /// The server waits for the gateway every tick.
    Lockstep,
    /// The server runs on the wall clock (real time, at any speed).
    RealTime,
}

/// One device at run time.
#[derive(Debug)]
struct Slot {
    device: Device,
    endpoint: Endpoint,
    outbox: Outbox,
    /// Not a text-line protocol (canonical mode on its line would hold bytes back).
    binary: bool,
    /// Ticks at which the driver's due input did not all come within the time-out.
    late_ticks: u64,
    /// Due input frames that never came.
    missing_inputs: u64,
}

/// What a device did over the run: the engine's counters and the line's.
#[derive(Clone, Debug)]
pub struct DeviceReport {
    /// The device's name.
    pub name: String,
    /// Where its driver found it.
    pub endpoint: String,
    /// Its messages' names, in the order of `engine.frames_in`.
    pub messages: Vec<String>,
    /// Frames in and out, and malformed input by reason.
    pub engine: DeviceCounters,
    /// What became of its output frames.
    pub line: OutboxCounters,
    /// Lockstep ticks whose due input did not all come within the time-out.
    pub late_ticks: u64,
    /// Due input frames that never came.
    pub missing_inputs: u64,
}

/// The devices, their endpoints and the arrays the engine reads and writes.
#[derive(Debug)]
pub struct Gateway {
    catalog: VehicleCatalog,
    slots: Vec<Slot>,
    values: Vec<f64>,
    fresh: Vec<bool>,
    commands: Vec<f64>,
    out: Vec<u8>,
    read_buf: Vec<u8>,
    now: TickTime,
}

impl Gateway {
    /// Opens every device's endpoint (relative pseudo-terminal links under `link_dir`).
    pub fn open(
        set: DeviceSet,
        catalog: VehicleCatalog,
        link_dir: &Path,
    ) -> Result<Self, (String, EndpointError)> {
        let mut slots = Vec::new();
        let mut out_len = 0;
        for device in set.devices {
            let endpoint = Endpoint::open(device.endpoint(), link_dir)
                .map_err(|e| (device.name().to_owned(), e))?;
            let baud = match device.endpoint() {
                EndpointSpec::Pty { baud, .. } => *baud,
                _ => None,
            };
            out_len = out_len.max(device.max_output_len());
            slots.push(Slot {
                binary: matches!(device.behaviour(), Behaviour::Binary(_)),
                outbox: Outbox::new(OUTBOX_BYTES.max(4 * device.max_output_len()), baud),
                device,
                endpoint,
                late_ticks: 0,
                missing_inputs: 0,
            });
        }
        let c = catalog.catalog();
        Ok(Self {
            values: vec![0.0; c.channel_count()],
            fresh: vec![false; c.group_count()],
            commands: vec![0.0; c.input_count()],
            catalog,
            slots,
            out: Vec::with_capacity(out_len),
            read_buf: vec![0; READ_CHUNK],
            now: TickTime::default(),
        })
    }

    /// Each device's name and where its driver finds it.
    pub fn endpoints(&self) -> Vec<(String, String)> {
        self.slots
            .iter()
            .map(|s| (s.device.name().to_owned(), s.endpoint.describe()))
            .collect()
    }

    /// The devices whose driver is not there yet.
    pub fn absent(&mut self) -> Vec<String> {
        self.slots
            .iter_mut()
            .filter_map(|s| {
                (!s.endpoint.driver_present(s.binary)).then(|| s.device.name().to_owned())
            })
            .collect()
    }

    /// Runs one tick's steps 1–4 (module note); the command is then [`Gateway::commands`].
    pub fn tick(&mut self, tick: &Tick, pacing: Pacing) -> std::io::Result<()> {
        self.now = tick_time(tick);
        self.catalog.fill(tick, &mut self.values, &mut self.fresh);
        let arrived = Instant::now();
        for s in &mut self.slots {
            // Presence also accepts a waiting TCP connection.
            s.endpoint.driver_present(s.binary);
            self.out.clear();
            if s.device
                .emit_due(&self.now, &self.values, &self.fresh, &mut self.out)
                > 0
            {
                let at = match pacing {
                    Pacing::Lockstep => arrived,
                    Pacing::RealTime => arrived + Duration::from_nanos(s.device.latency_ns()),
                };
                queue(s, &self.out, at, pacing == Pacing::RealTime);
            }
            s.outbox.flush(Instant::now(), &mut s.endpoint)?;
        }
        match pacing {
            Pacing::Lockstep => self.collect_due()?,
            Pacing::RealTime => self.read_available()?,
        }
        for s in &mut self.slots {
            s.device.drive(&self.now, &self.values, &mut self.commands);
        }
        Ok(())
    }

    /// Lockstep step 3: reads each device that owes input at this tick until it has it all or
    /// its time-out passes.
    fn collect_due(&mut self) -> std::io::Result<()> {
        let start = Instant::now();
        let tick = self.now.tick;
        let mut owed: Vec<u32> = self
            .slots
            .iter()
            .map(|s| s.device.inputs_due(tick))
            .collect();
        loop {
            let mut waiting = false;
            let mut wait_ms = i32::MAX;
            for (s, owe) in self.slots.iter_mut().zip(owed.iter_mut()) {
                if *owe == 0 {
                    continue;
                }
                // Take everything there is now.
                loop {
                    let n = s.endpoint.read(&mut self.read_buf)?;
                    if n == 0 {
                        break;
                    }
                    self.out.clear();
                    let taken = s.device.take_bytes(
                        &self.read_buf[..n],
                        &self.now,
                        &self.values,
                        &mut self.commands,
                        &mut self.out,
                    );
                    if !self.out.is_empty() {
                        // Lockstep: an answer goes at once (no latency, no baud timing).
                        queue(s, &self.out, Instant::now(), false);
                        s.outbox.flush(Instant::now(), &mut s.endpoint)?;
                    }
                    *owe = owe.saturating_sub(taken.due_received);
                    if *owe == 0 {
                        break;
                    }
                }
                if *owe == 0 {
                    continue;
                }
                let limit = s.device.timeout();
                let spent = start.elapsed();
                if spent >= limit {
                    s.late_ticks += 1;
                    s.missing_inputs += u64::from(*owe);
                    tracing::warn!(
                        device = s.device.name(),
                        tick,
                        missing = *owe,
                        timeout_ms = limit.as_millis() as u64,
                        "the driver's input due at this tick did not all come in time: the tick goes on without it"
                    );
                    *owe = 0;
                    continue;
                }
                waiting = true;
                wait_ms = wait_ms.min(((limit - spent).as_micros().div_ceil(1000)) as i32);
            }
            if !waiting {
                return Ok(());
            }
            let fds: Vec<_> = self
                .slots
                .iter()
                .zip(&owed)
                .filter(|(_, o)| **o > 0)
                .filter_map(|(s, _)| s.endpoint.fd())
                .collect();
            // A TCP device without a connection has only its listener, and a full line holds a
            // frame back: look again soon.
            poll_any(&fds, wait_ms.clamp(1, 10)).map_err(std::io::Error::from)?;
            for (s, o) in self.slots.iter_mut().zip(&owed) {
                if *o > 0 {
                    s.endpoint.driver_present(s.binary);
                }
                s.outbox.flush(Instant::now(), &mut s.endpoint)?;
            }
        }
    }

    /// Real time: takes whatever every driver wrote, answering requests at once.
    fn read_available(&mut self) -> std::io::Result<()> {
        for s in &mut self.slots {
            s.endpoint.driver_present(s.binary);
            loop {
                let n = s.endpoint.read(&mut self.read_buf)?;
                if n == 0 {
                    break;
                }
                self.out.clear();
                s.device.take_bytes(
                    &self.read_buf[..n],
                    &self.now,
                    &self.values,
                    &mut self.commands,
                    &mut self.out,
                );
                if !self.out.is_empty() {
                    queue(s, &self.out, Instant::now(), true);
                }
            }
            s.outbox.flush(Instant::now(), &mut s.endpoint)?;
        }
        Ok(())
    }

    /// Real time, between ticks: waits up to `limit` for a driver's bytes or an outbox's next
    /// frame, then reads and writes what is due.
    pub fn service(&mut self, limit: Duration) -> std::io::Result<()> {
        let now = Instant::now();
        let next = self
            .slots
            .iter()
            .filter_map(|s| s.outbox.next_due())
            .min()
            .map_or(limit, |t| t.saturating_duration_since(now).min(limit));
        let fds: Vec<_> = self.slots.iter().filter_map(|s| s.endpoint.fd()).collect();
        poll_any(&fds, next.as_millis() as i32).map_err(std::io::Error::from)?;
        self.read_available()
    }

    /// The inputs the drivers set, in the catalog's input order.
    pub fn commands(&self) -> &[f64] {
        &self.commands
    }

    /// The catalog the devices were resolved against.
    pub fn catalog(&self) -> &VehicleCatalog {
        &self.catalog
    }

    /// Writes what is still in the outboxes (at the end of a run), for up to `limit`.
    pub fn drain(&mut self, limit: Duration) {
        let end = Instant::now() + limit;
        while Instant::now() < end && self.slots.iter().any(|s| !s.outbox.is_empty()) {
            for s in &mut self.slots {
                let _ = s.outbox.flush(Instant::now(), &mut s.endpoint);
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// What each device did.
    pub fn report(&self) -> Vec<DeviceReport> {
        self.slots
            .iter()
            .map(|s| DeviceReport {
                name: s.device.name().to_owned(),
                endpoint: s.endpoint.describe(),
                messages: s.device.message_names().to_vec(),
                engine: s.device.counters().clone(),
                line: s.outbox.counters(),
                late_ticks: s.late_ticks,
                missing_inputs: s.missing_inputs,
            })
            .collect()
    }
}

/// Queues each frame the device's last call appended to `out` on its own (a datagram
/// endpoint sends one frame per datagram; a stream endpoint times each frame on the line).
fn queue(s: &mut Slot, out: &[u8], earliest: Instant, paced: bool) {
    let mut start = 0;
    for &end in s.device.frame_ends() {
        if let Some(frame) = out.get(start..end) {
            s.outbox.push(frame, earliest, paced);
        }
        start = end;
    }
    // Octets after the last frame end (none from a described device): as one frame.
    if let Some(rest) = out.get(start..).filter(|r| !r.is_empty()) {
        s.outbox.push(rest, earliest, paced);
    }
}

/// The engine's time of a tick, from the tick's time message (simulation time alone when it
/// was lost or the configuration has no epoch).
fn tick_time(tick: &Tick) -> TickTime {
    let h = tick.state.header;
    let mut t = TickTime {
        tick: h.tick,
        sim_time_ns: h.sim_time_ns,
        met_ns: h.sim_time_ns,
        ..TickTime::default()
    };
    if let Some(m) = tick.time.as_ref().filter(|m| m.header.tick == h.tick) {
        copy_time(m, &mut t);
    }
    t
}

fn copy_time(m: &TimeMsg, t: &mut TickTime) {
    t.met_ns = m.met_ns;
    t.has_epoch = m.flags & time_flags::EPOCH_VALID != 0;
    if !t.has_epoch {
        return;
    }
    t.tai_ns_1958 = m.tai_ns_1958;
    t.gps_week = m.gps_week;
    t.gps_ns_of_week = m.gps_ns_of_week;
    t.utc = Utc {
        year: m.utc.year,
        month: m.utc.month,
        day: m.utc.day,
        hour: m.utc.hour,
        minute: m.utc.minute,
        second: m.utc.second,
        nanosecond: m.utc.nanosecond,
    };
}
