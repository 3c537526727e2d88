//! The devices at run time: each described device with its endpoint and its outbox, fed one
//! complete tick at a time, and the actuator inputs its driver set.
//!
//! Per tick, in this order:
//! 1. the tick's samples are copied into the channels ([`VehicleCatalog::fill`]);
//! 2. each device writes the outputs due at the tick (periodic, or on a fresh sample) into its
//!    outbox, to go at once in lockstep and its declared latency later in real time;
//! 3. **lockstep**: the gateway feeds each device the driver's bytes, one octet at a time, until
//!    every in-message the device declares due at this tick (`due_every_s`) has come, answering
//!    each request from this tick's values, or until the device's time-out passes; the octets
//!    after the last one owed wait for the next tick something is owed, so however the bytes
//!    were chunked on the way, each frame is taken at the same tick on every run. The tick is
//!    then done once every output is on its line (a driver slow to read holds the tick, up to
//!    the time-out). **Real time**: whatever the drivers wrote is taken at once;
//! 4. each device's behaviour runs ([`Device::drive`]: a wheel drive's speed loop);
//! 5. the inputs go to the server as one `Actuators` command ([`Gateway::commands`]).
//!
//! So drivers paced by their devices' outputs give the same commands at the same ticks on
//! every run; a time-out (counted, logged) is the one way two runs can differ.

use std::path::Path;
use std::time::{Duration, Instant};

use flexdyn_gateway::device::engine::Behaviour;
use flexdyn_gateway::device::{
    Device, DeviceCounters, DeviceSet, EndpointSpec, TickTime, Utc, MAX_READ_CHUNK,
};
use flexdyn_proto::client::lockstep::Tick;
use flexdyn_proto::{time_flags, TimeMsg};

use crate::catalog::VehicleCatalog;
use crate::endpoint::outbox::{Outbox, OutboxCounters};
use crate::endpoint::{poll_any, Endpoint, EndpointError};

/// Bytes an outbox holds at most before it drops frames (a driver that does not read).
const OUTBOX_BYTES: usize = 64 * 1024;
/// Bytes taken from a driver per read: a whole UDP datagram (the largest IPv4 payload), fed to
/// the engine in pieces of at most [`MAX_READ_CHUNK`].
const READ_BYTES: usize = 65_536;
/// How long a lockstep wait sleeps when no descriptor can wake it (an outbox draining, drivers
/// absent).
const NAP: Duration = Duration::from_micros(200);

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
    /// Whether its driver was there at the last look.
    present: bool,
    /// Lockstep: octets read from the driver and not yet taken (after the last frame owed).
    held: Vec<u8>,
    /// Lockstep: the messages owed at this tick, each with its count of frames in before it.
    owed: Vec<(usize, u64)>,
    /// Ticks at which the driver's due input did not all come within the time-out.
    late_ticks: u64,
    /// Due input frames that never came.
    missing_inputs: u64,
    /// Lockstep ticks whose outputs were not all on the line within the time-out.
    late_outputs: u64,
}

impl Slot {
    /// The owed messages that have not come yet.
    fn still_owed(&self) -> u64 {
        let frames_in = &self.device.counters().frames_in;
        self.owed
            .iter()
            .filter(|(m, before)| frames_in.get(*m).copied().unwrap_or(0) <= *before)
            .count() as u64
    }

    /// Takes octets in pieces the engine has room for; each piece's answers are queued at once.
    fn take(&mut self, bytes: &[u8], now: &TickTime, io: &mut Io<'_>, paced: bool) {
        for piece in bytes.chunks(MAX_READ_CHUNK) {
            io.out.clear();
            self.device
                .take_bytes(piece, now, io.values, io.commands, io.out);
            queue(self, io.out, Instant::now(), paced);
        }
    }
}

/// The arrays a device reads and writes while taking input.
struct Io<'a> {
    values: &'a [f64],
    commands: &'a mut [f64],
    out: &'a mut Vec<u8>,
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
    /// The endpoint's own tallies (connections, refused datagrams), by name.
    pub link: Vec<(&'static str, u64)>,
    /// Lockstep ticks whose due input did not all come within the time-out.
    pub late_ticks: u64,
    /// Due input frames that never came.
    pub missing_inputs: u64,
    /// Lockstep ticks whose outputs were not all on the line within the time-out.
    pub late_outputs: u64,
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
    /// Ticks whose time message was lost (their devices' time fields fell back to simulation
    /// time alone).
    ticks_without_time: u64,
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
            if device.has_undue_inputs() {
                tracing::warn!(
                    device = device.name(),
                    "its input messages declare no due_every_s: in lockstep the gateway never \
                     waits for them, so they are taken only at ticks where another of its \
                     messages is due (declare due_every_s for a deterministic tick)"
                );
            }
            out_len = out_len.max(device.max_output_len());
            slots.push(Slot {
                binary: matches!(device.behaviour(), Behaviour::Binary(_)),
                outbox: Outbox::new(OUTBOX_BYTES.max(4 * device.max_output_len()), baud),
                present: false,
                held: Vec::with_capacity(READ_BYTES),
                owed: Vec::with_capacity(device.message_names().len()),
                device,
                endpoint,
                late_ticks: 0,
                missing_inputs: 0,
                late_outputs: 0,
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
            read_buf: vec![0; READ_BYTES],
            now: TickTime::default(),
            ticks_without_time: 0,
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
        self.look_for_drivers();
        self.slots
            .iter()
            .filter(|s| !s.present)
            .map(|s| s.device.name().to_owned())
            .collect()
    }

    /// Notes which drivers are there (and takes a waiting TCP connection).
    fn look_for_drivers(&mut self) {
        for s in &mut self.slots {
            s.present = s.endpoint.driver_present(s.binary);
        }
    }

    /// Runs one tick's steps 1–4 (module note); the command is then [`Gateway::commands`].
    pub fn tick(&mut self, tick: &Tick, pacing: Pacing) -> std::io::Result<()> {
        self.now = tick_time(tick);
        if tick
            .time
            .as_ref()
            .is_none_or(|t| t.header.tick != tick.tick())
        {
            self.ticks_without_time += 1;
        }
        self.catalog.fill(tick, &mut self.values, &mut self.fresh);
        self.look_for_drivers();
        let arrived = Instant::now();
        for s in &mut self.slots {
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

    /// Lockstep step 3 (module note).
    fn collect_due(&mut self) -> std::io::Result<()> {
        let start = Instant::now();
        let tick = self.now.tick;
        for s in &mut self.slots {
            s.owed.clear();
            for m in 0..s.device.message_names().len() {
                if s.device.input_due(m, tick) {
                    let before = s.device.counters().frames_in.get(m).copied().unwrap_or(0);
                    s.owed.push((m, before));
                }
            }
        }
        let mut done = vec![false; self.slots.len()];
        loop {
            let mut io = Io {
                values: &self.values,
                commands: &mut self.commands,
                out: &mut self.out,
            };
            let mut wait_ms = i32::MAX;
            for (s, done) in self.slots.iter_mut().zip(done.iter_mut()) {
                if *done {
                    continue;
                }
                s.present = s.endpoint.driver_present(s.binary);
                take_owed(s, &self.now, &mut io, &mut self.read_buf)?;
                s.outbox.flush(Instant::now(), &mut s.endpoint)?;
                let owed = s.still_owed();
                // Outputs wait only for a driver that is there to read them.
                let unsent = s.present && !s.outbox.is_empty();
                if owed == 0 && !unsent {
                    *done = true;
                    continue;
                }
                let limit = s.device.timeout();
                let spent = start.elapsed();
                if spent >= limit {
                    if owed > 0 {
                        s.late_ticks += 1;
                        s.missing_inputs += owed;
                        tracing::warn!(
                            device = s.device.name(),
                            tick,
                            missing = owed,
                            timeout_ms = limit.as_millis() as u64,
                            "the driver's input due at this tick did not all come in time: the \
                             tick goes on without it"
                        );
                    }
                    if unsent {
                        s.late_outputs += 1;
                        tracing::warn!(
                            device = s.device.name(),
                            tick,
                            "the driver did not read this tick's output in time: the tick goes on"
                        );
                    }
                    *done = true;
                    continue;
                }
                wait_ms = wait_ms.min(ms_ceil(limit - spent));
            }
            if done.iter().all(|d| *d) {
                return Ok(());
            }
            // Wake on the owing drivers' bytes; outboxes draining and absent drivers have no
            // descriptor to wait on (an absent pty's master reports a hang-up at once), so nap.
            let fds: Vec<_> = self
                .slots
                .iter()
                .zip(&done)
                .filter(|(s, d)| !**d && s.present && s.still_owed() > 0)
                .filter_map(|(s, _)| s.endpoint.fd())
                .collect();
            let draining = self
                .slots
                .iter()
                .zip(&done)
                .any(|(s, d)| !*d && (!s.present || s.still_owed() == 0));
            if fds.is_empty() || draining {
                std::thread::sleep(NAP);
                if !fds.is_empty() {
                    poll_any(&fds, 0).map_err(std::io::Error::from)?;
                }
            } else {
                poll_any(&fds, wait_ms.clamp(1, 10)).map_err(std::io::Error::from)?;
            }
        }
    }

    /// Real time: takes whatever every driver wrote, answering requests at once.
    fn read_available(&mut self) -> std::io::Result<()> {
        let mut io = Io {
            values: &self.values,
            commands: &mut self.commands,
            out: &mut self.out,
        };
        for s in &mut self.slots {
            s.present = s.endpoint.driver_present(s.binary);
            if !s.held.is_empty() {
                let held = std::mem::take(&mut s.held);
                s.take(&held, &self.now, &mut io, true);
                s.held = held;
                s.held.clear();
            }
            loop {
                let n = s.endpoint.read(&mut self.read_buf)?;
                if n == 0 {
                    break;
                }
                s.take(&self.read_buf[..n], &self.now, &mut io, true);
            }
            s.outbox.flush(Instant::now(), &mut s.endpoint)?;
        }
        Ok(())
    }

    /// Real time, between ticks: waits up to `limit` for a driver's bytes or an outbox's next
    /// frame, then reads and writes what is due.
    pub fn service(&mut self, limit: Duration) -> std::io::Result<()> {
        let now = Instant::now();
        let wait = self
            .slots
            .iter()
            .filter_map(|s| s.outbox.next_due())
            .min()
            .map_or(limit, |t| t.saturating_duration_since(now).min(limit));
        let fds: Vec<_> = self
            .slots
            .iter()
            .filter(|s| s.present)
            .filter_map(|s| s.endpoint.fd())
            .collect();
        if fds.is_empty() {
            std::thread::sleep(wait.max(NAP));
        } else {
            poll_any(&fds, ms_ceil(wait).max(1)).map_err(std::io::Error::from)?;
        }
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

    /// Ticks whose time message was lost.
    pub fn ticks_without_time(&self) -> u64 {
        self.ticks_without_time
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
                link: s.endpoint.counters(),
                late_ticks: s.late_ticks,
                missing_inputs: s.missing_inputs,
                late_outputs: s.late_outputs,
            })
            .collect()
    }
}

/// Lockstep: feeds the driver's octets to the device one at a time until nothing it owes at
/// this tick is missing; the octets after the last one owed stay in `held`.
fn take_owed(
    s: &mut Slot,
    now: &TickTime,
    io: &mut Io<'_>,
    read_buf: &mut [u8],
) -> std::io::Result<()> {
    let mut next = 0;
    while s.still_owed() > 0 {
        if next == s.held.len() {
            s.held.clear();
            next = 0;
            let n = s.endpoint.read(read_buf)?;
            if n == 0 {
                break;
            }
            s.held.extend_from_slice(&read_buf[..n]);
        }
        let octet = [s.held[next]];
        next += 1;
        s.take(&octet, now, io, false);
    }
    s.held.drain(..next);
    Ok(())
}

/// Milliseconds, rounded up, for poll(2).
fn ms_ceil(d: Duration) -> i32 {
    i32::try_from(d.as_micros().div_ceil(1000)).unwrap_or(i32::MAX)
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
