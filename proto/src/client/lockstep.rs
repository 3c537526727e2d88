//! Complete ticks for flight code that reads sensors.
//!
//! For each tick k the server publishes the sample of every IMU, of every star tracker,
//! magnetometer, coarse-sun-sensor array and fine sun sensor due at k, and of every GPS receiver
//! whose solution is published at k, then the StateMsg of k (proto/README.md, "Lockstep
//! protocol"). Flight code that answers
//! tick k from exactly those samples is as deterministic as the server; flight code that uses
//! whatever sample came last is not, because separate subscribers may be delivered on separate
//! threads and a state can overtake a sample of its own tick. So:
//!
//! - [`SensorSchedule`] says which samples are due at a tick, from the configuration the server
//!   serves ([`crate::client::vehicle`]), never from guessing;
//! - [`TickAssembler`] takes the telemetry samples as they come and hands out a [`Tick`] (the
//!   state and its due samples) once it is complete;
//! - [`TickReceiver`] is the Zenoh side: a callback subscriber on each key a tick is assembled
//!   from ([`SensorSchedule::keys`]), all feeding one assembler, with a time limit for a sample
//!   that never comes. Zenoh runs a callback subscriber's callback on the thread that reads the
//!   link, before it handles the next message, so the assembler sees the samples in publication
//!   order, whichever subscriber each came through. It hands each complete tick to the reader's
//!   thread
//!   ([`TickReceiver::declare`]), or runs a [`TickHandler`] on it right where it completes, on
//!   the Zenoh thread that delivered its last sample ([`TickReceiver::declare_with_handler`]):
//!   no thread hop between the state and the answer, as in a Zenoh ping-pong.
//!
//! A sensor in a `dropout` fault publishes nothing, by design, so its due samples will not
//! come: the assembler learns each dropout's interval from the fault events on
//! `flexdyn/<sc>/tlm/fault` (activation and clearance edges, [`crate::FaultEventMsg`]) and does
//! not wait for a sample the server withheld. The events of boundary k follow the state of k, so
//! a tick is released at most one message after its state, not after the time limit; the
//! withheld samples are still listed in [`Tick::missing`].

use std::collections::{BTreeMap, VecDeque};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use crate::{
    decode_css, decode_fault_event, decode_fss, decode_gps, decode_imu, decode_magnetometer,
    decode_star_tracker, decode_state, decode_time, CssMsg, DecodeError, FaultEventMsg, FssMsg,
    GpsMsg, ImuMsg, MagnetometerMsg, StarTrackerMsg, StateMsg, Telemetry, TimeMsg, Topics,
    FAULT_MODE_NAMES,
};
use zenoh::pubsub::Subscriber;
use zenoh::sample::Sample;
use zenoh::{Session, Wait};

use crate::client::transport::declared_key;
use crate::client::vehicle::{VehicleConfig, VehicleError};

/// A sensor that publishes on the ticks `offset + n · every` (n ≥ 0).
#[derive(Clone, Debug, PartialEq, Eq)]
struct Periodic {
    name: String,
    /// \[frames\] its period.
    every: u64,
    /// \[frames\] its first publication (a GPS receiver's latency; 0 for the others).
    offset: u64,
}

impl Periodic {
    fn due(&self, tick: u64) -> bool {
        tick >= self.offset && (tick - self.offset).is_multiple_of(self.every)
    }
}

/// Which sensor samples the server publishes at each tick: every IMU each tick; each star
/// tracker, magnetometer, coarse-sun-sensor array and fine sun sensor on the ticks that are
/// multiples of its period (from tick 0); each GPS receiver on the ticks `latency + n · period`
/// (its solutions, each published its latency after the instant it is valid).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SensorSchedule {
    /// Whether a tick carries the time service's message ([`Tick::time`]); see
    /// [`Self::without_time`].
    time: bool,
    imus: Vec<String>,
    star_trackers: Vec<Periodic>,
    magnetometers: Vec<Periodic>,
    coarse_sun_sensors: Vec<Periodic>,
    fine_sun_sensors: Vec<Periodic>,
    gps_receivers: Vec<Periodic>,
}

impl SensorSchedule {
    /// The schedule of a served configuration.
    pub fn from_config(cfg: &VehicleConfig) -> Result<Self, VehicleError> {
        let periodic = |what: &str, name: &str, rate_hz: f64| {
            Ok(Periodic {
                name: name.to_owned(),
                every: cfg.period_frames(what, name, rate_hz)?,
                offset: 0,
            })
        };
        Ok(Self {
            time: true,
            imus: cfg.imus.iter().map(|i| i.name.clone()).collect(),
            star_trackers: cfg
                .star_trackers
                .iter()
                .map(|st| periodic("star tracker", &st.name, st.rate_hz))
                .collect::<Result<_, VehicleError>>()?,
            magnetometers: cfg
                .magnetometers
                .iter()
                .map(|m| periodic("magnetometer", &m.name, m.rate_hz))
                .collect::<Result<_, VehicleError>>()?,
            coarse_sun_sensors: cfg
                .coarse_sun_sensors
                .iter()
                .map(|c| periodic("coarse sun sensor", &c.name, c.rate_hz))
                .collect::<Result<_, VehicleError>>()?,
            fine_sun_sensors: cfg
                .fine_sun_sensors
                .iter()
                .map(|f| periodic("fine sun sensor", &f.name, f.rate_hz))
                .collect::<Result<_, VehicleError>>()?,
            gps_receivers: cfg
                .gps_receivers
                .iter()
                .map(|g| {
                    Ok(Periodic {
                        offset: cfg.gps_latency_frames(g)?,
                        ..periodic("GPS receiver", &g.name, g.rate_hz)?
                    })
                })
                .collect::<Result<_, VehicleError>>()?,
        })
    }

    /// The same schedule, its ticks without the time service's message: a [`TickReceiver`]
    /// then does not subscribe to `flexdyn/<sc>/tlm/time` (so Zenoh does not send it to this
    /// session, unless another of its subscribers matches it), and [`Tick::time`] is `None`.
    /// For flight code that keeps no clock of its own from the time service (UTC, TAI, GPS
    /// time, CCSDS CUC): in a lockstep run at 1 kHz it shortened every tick by about 2 µs
    /// (`docs/developer/benchmarks.md`).
    pub fn without_time(self) -> Self {
        Self {
            time: false,
            ..self
        }
    }

    /// Whether its ticks carry the time service's message ([`Self::without_time`]).
    pub fn has_time(&self) -> bool {
        self.time
    }

    /// The IMU names, in configuration order.
    pub fn imus(&self) -> impl Iterator<Item = &str> {
        self.imus.iter().map(String::as_str)
    }

    /// The star trackers (name, period in frames), in configuration order.
    pub fn star_trackers(&self) -> impl Iterator<Item = (&str, u64)> {
        periods(&self.star_trackers)
    }

    /// The magnetometers (name, period in frames), in configuration order.
    pub fn magnetometers(&self) -> impl Iterator<Item = (&str, u64)> {
        periods(&self.magnetometers)
    }

    /// The coarse-sun-sensor arrays (name, period in frames), in configuration order.
    pub fn coarse_sun_sensors(&self) -> impl Iterator<Item = (&str, u64)> {
        periods(&self.coarse_sun_sensors)
    }

    /// The fine sun sensors (name, period in frames), in configuration order.
    pub fn fine_sun_sensors(&self) -> impl Iterator<Item = (&str, u64)> {
        periods(&self.fine_sun_sensors)
    }

    /// The GPS receivers (name, period in frames, latency in frames), in configuration order.
    pub fn gps_receivers(&self) -> impl Iterator<Item = (&str, u64, u64)> {
        self.gps_receivers
            .iter()
            .map(|p| (p.name.as_str(), p.every, p.offset))
    }
}

impl SensorSchedule {
    /// The telemetry keys of `topics` a tick of this schedule is assembled from: the state, the
    /// time message (unless [`Self::without_time`]), the fault events (which tell of withheld
    /// samples) and each scheduled sensor's key. Not the environment, relative or flight-code
    /// telemetry, which a tick does not carry.
    pub fn keys(&self, topics: &Topics) -> Vec<String> {
        let mut keys = vec![topics.state().to_owned(), topics.fault_events()];
        if self.time {
            keys.push(topics.time());
        }
        for (section, route) in SENSOR_SECTIONS {
            for name in self.names(section).unwrap_or_default() {
                // The schedule's names came from a configuration the server accepted; a name
                // that makes no key has no samples to route either.
                if let Ok(key) = topics.sensor(&format!("tlm/{route}"), name) {
                    keys.push(key);
                }
            }
        }
        keys
    }

    /// The names of a configuration section's sensors (`imus`, `star_trackers`,
    /// `magnetometers`, `coarse_sun_sensors`, `fine_sun_sensors`, `gps_receivers`), in
    /// configuration order; `None` for any other section.
    pub fn names(&self, section: &str) -> Option<Vec<&str>> {
        fn periodic(list: &[Periodic]) -> Vec<&str> {
            list.iter().map(|p| p.name.as_str()).collect()
        }
        Some(match section {
            "imus" => self.imus().collect(),
            "star_trackers" => periodic(&self.star_trackers),
            "magnetometers" => periodic(&self.magnetometers),
            "coarse_sun_sensors" => periodic(&self.coarse_sun_sensors),
            "fine_sun_sensors" => periodic(&self.fine_sun_sensors),
            "gps_receivers" => periodic(&self.gps_receivers),
            _ => return None,
        })
    }
}

/// (name, period) of each entry of a periodic list.
fn periods(list: &[Periodic]) -> impl Iterator<Item = (&str, u64)> {
    list.iter().map(|p| (p.name.as_str(), p.every))
}

/// The index of `name` in a periodic list.
fn position(list: &[Periodic], name: &str) -> Option<usize> {
    list.iter().position(|p| p.name == name)
}

/// `<prefix>/<name>` of each sensor of a periodic list due at `tick` whose sample `have` lacks.
fn missing_due<'a>(
    list: &'a [Periodic],
    prefix: &'a str,
    tick: u64,
    have: impl Fn(usize) -> bool + 'a,
) -> impl Iterator<Item = String> + 'a {
    list.iter()
        .enumerate()
        .filter(move |(i, p)| p.due(tick) && !have(*i))
        .map(move |(_, p)| format!("{prefix}/{}", p.name))
}

/// One tick's telemetry: its state and the sensor samples due at it.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    /// The StateMsg of the tick.
    pub state: StateMsg,
    /// The IMU samples of the tick, in configuration order (`None`: lost, see `missing`).
    pub imus: Vec<Option<ImuMsg>>,
    /// The star-tracker samples of the tick, in configuration order (`None`: not due at this
    /// tick, or lost).
    pub star_trackers: Vec<Option<StarTrackerMsg>>,
    /// The magnetometer samples of the tick, in configuration order (`None`: not due, or lost).
    pub magnetometers: Vec<Option<MagnetometerMsg>>,
    /// The coarse-sun-sensor array samples of the tick, in configuration order (`None`: not
    /// due, or lost).
    pub coarse_sun_sensors: Vec<Option<CssMsg>>,
    /// The fine-sun-sensor samples of the tick, in configuration order (`None`: not due, or
    /// lost).
    pub fine_sun_sensors: Vec<Option<FssMsg>>,
    /// The GPS solutions published at the tick, in configuration order (`None`: none published
    /// at this tick, or lost); each is valid its receiver's latency before the tick.
    pub gps_receivers: Vec<Option<GpsMsg>>,
    /// The time service's message of the tick (UTC, TAI, GPS time, CCSDS CUC), published
    /// before the tick's samples; `None` if it was lost, or if the schedule leaves it out
    /// ([`SensorSchedule::without_time`]). Not awaited: a tick is complete without it.
    pub time: Option<TimeMsg>,
    /// The due samples that never came, as `imu/<name>`, `st/<name>`, `mag/<name>`,
    /// `css/<name>`, `fss/<name>` or `gps/<name>`. Empty in lockstep unless a sample was lost
    /// or withheld by a `dropout` fault.
    pub missing: Vec<String>,
}

impl Tick {
    /// The tick (frame index).
    pub fn tick(&self) -> u64 {
        self.state.header.tick
    }

    /// The encoded sample of entry `index` of a configuration section (as
    /// [`SensorSchedule::names`]): `None` for an unknown section or an index past its end,
    /// `Some(None)` when the tick carries no sample of that sensor (not due, or lost).
    pub fn sample_bytes(&self, section: &str, index: usize) -> Option<Option<Vec<u8>>> {
        fn one<T: crate::WireMessage>(list: &[Option<T>], index: usize) -> Option<Option<Vec<u8>>> {
            list.get(index).map(|m| m.as_ref().map(crate::encode))
        }
        match section {
            "imus" => one(&self.imus, index),
            "star_trackers" => one(&self.star_trackers, index),
            "magnetometers" => one(&self.magnetometers, index),
            "coarse_sun_sensors" => one(&self.coarse_sun_sensors, index),
            "fine_sun_sensors" => one(&self.fine_sun_sensors, index),
            "gps_receivers" => one(&self.gps_receivers, index),
            _ => None,
        }
    }
}

/// The samples of one tick so far.
#[derive(Clone, Debug)]
struct Partial {
    imus: Vec<Option<ImuMsg>>,
    star_trackers: Vec<Option<StarTrackerMsg>>,
    magnetometers: Vec<Option<MagnetometerMsg>>,
    coarse_sun_sensors: Vec<Option<CssMsg>>,
    fine_sun_sensors: Vec<Option<FssMsg>>,
    gps_receivers: Vec<Option<GpsMsg>>,
}

impl Partial {
    fn empty(s: &SensorSchedule) -> Self {
        Self {
            imus: vec![None; s.imus.len()],
            star_trackers: vec![None; s.star_trackers.len()],
            magnetometers: vec![None; s.magnetometers.len()],
            coarse_sun_sensors: vec![None; s.coarse_sun_sensors.len()],
            fine_sun_sensors: vec![None; s.fine_sun_sensors.len()],
            gps_receivers: vec![None; s.gps_receivers.len()],
        }
    }
}

/// A sensor's samples withheld by a `dropout` fault over `[from_ns, until_ns)` (the fault
/// events' edges; `until_ns` is `u64::MAX` until its clearance comes).
#[derive(Clone, Debug, PartialEq, Eq)]
struct Withheld {
    fault_index: u32,
    /// `imu/<name>`, `st/<name>`, … (as in [`Tick::missing`]).
    route: String,
    from_ns: u64,
    until_ns: u64,
}

/// The configuration sections of the sensor kinds and their telemetry route prefixes.
const SENSOR_SECTIONS: [(&str, &str); 6] = [
    ("imus", "imu"),
    ("star_trackers", "st"),
    ("magnetometers", "mag"),
    ("coarse_sun_sensors", "css"),
    ("fine_sun_sensors", "fss"),
    ("gps_receivers", "gps"),
];

/// The route (`imu/hub`) of a sensor fault's target (`imus.hub` or `imus.hub.gyro`), `None` for
/// any other target.
fn sensor_route(target: &str) -> Option<String> {
    let mut parts = target.split('.');
    let (section, name) = (parts.next()?, parts.next()?);
    let prefix = SENSOR_SECTIONS
        .iter()
        .find(|(s, _)| *s == section)
        .map(|(_, p)| p)?;
    Some(format!("{prefix}/{name}"))
}

/// Assembles complete [`Tick`]s from telemetry samples given in any order (see the module
/// docs). A held state is released without its missing samples when a sample of a later tick
/// comes (real time, where the server drops samples under load), or when the caller gives up
/// on it ([`Self::give_up`], after its own time limit).
#[derive(Debug)]
pub struct TickAssembler {
    topics: Topics,
    /// `flexdyn/<sc>/tlm/fault`.
    fault_key: String,
    /// The dropout intervals the fault events told of, oldest first.
    withheld: Vec<Withheld>,
    schedule: SensorSchedule,
    /// The state waiting for its samples.
    held: Option<StateMsg>,
    /// Samples by tick, for ticks after the last one released.
    partial: BTreeMap<u64, Partial>,
    /// The latest time message: it comes first of its tick, and goes with that tick's release
    /// (kept apart from `partial`, so a tick of states alone costs no entry there).
    time: Option<TimeMsg>,
    /// The last tick released.
    last: Option<u64>,
}

impl TickAssembler {
    /// An assembler for the telemetry keys of `topics`.
    pub fn new(topics: Topics, schedule: SensorSchedule) -> Self {
        Self {
            fault_key: topics.fault_events(),
            topics,
            withheld: Vec::new(),
            schedule,
            held: None,
            partial: BTreeMap::new(),
            time: None,
            last: None,
        }
    }

    /// The schedule it follows.
    pub fn schedule(&self) -> &SensorSchedule {
        &self.schedule
    }

    /// Takes one sample (its key and payload) and calls `ready` with each tick it completes, in
    /// tick order: a key that is not telemetry of this spacecraft, a sensor not in the schedule
    /// and a sample of a tick already released are ignored. An undecodable payload is an
    /// error, and changes nothing.
    pub fn push(
        &mut self,
        key: &str,
        payload: &[u8],
        mut ready: impl FnMut(Tick),
    ) -> Result<(), DecodeError> {
        if key == self.fault_key {
            self.note_fault(&decode_fault_event(payload)?);
            if self.held.is_some() && self.awaited().is_empty() {
                if let Some(t) = self.release() {
                    ready(t);
                }
            }
            return Ok(());
        }
        let Some(topic) = self.topics.telemetry(key) else {
            return Ok(());
        };
        enum Msg {
            // Boxed: a state is twice the size of a sensor sample (clippy::large_enum_variant).
            State(Box<StateMsg>),
            Imu(usize, ImuMsg),
            Tracker(usize, StarTrackerMsg),
            Mag(usize, MagnetometerMsg),
            Css(usize, CssMsg),
            Fss(usize, FssMsg),
            Gps(usize, GpsMsg),
            Time(TimeMsg),
        }
        let s = &self.schedule;
        let msg = match topic {
            // The time service comes with its tick, but is never awaited.
            Telemetry::Time if s.time => Msg::Time(decode_time(payload)?),
            Telemetry::Time => return Ok(()),
            // Nor is the environment message (truth for operators, after the state).
            Telemetry::Environment => return Ok(()),
            // Nor is a fleet deputy's relative state (after the state; Client::subscribe).
            Telemetry::Relative(_) => return Ok(()),
            Telemetry::State => Msg::State(Box::new(decode_state(payload)?)),
            Telemetry::Imu(name) => match s.imus.iter().position(|n| n == name) {
                Some(i) => Msg::Imu(i, decode_imu(payload)?),
                None => return Ok(()),
            },
            Telemetry::StarTracker(name) => match position(&s.star_trackers, name) {
                Some(i) => Msg::Tracker(i, decode_star_tracker(payload)?),
                None => return Ok(()),
            },
            Telemetry::Magnetometer(name) => match position(&s.magnetometers, name) {
                Some(i) => Msg::Mag(i, decode_magnetometer(payload)?),
                None => return Ok(()),
            },
            Telemetry::Css(name) => match position(&s.coarse_sun_sensors, name) {
                Some(i) => Msg::Css(i, decode_css(payload)?),
                None => return Ok(()),
            },
            Telemetry::Fss(name) => match position(&s.fine_sun_sensors, name) {
                Some(i) => Msg::Fss(i, decode_fss(payload)?),
                None => return Ok(()),
            },
            Telemetry::Gps(name) => match position(&s.gps_receivers, name) {
                Some(i) => Msg::Gps(i, decode_gps(payload)?),
                None => return Ok(()),
            },
        };
        let tick = match &msg {
            Msg::State(m) => m.header.tick,
            Msg::Imu(_, m) => m.header.tick,
            Msg::Tracker(_, m) => m.header.tick,
            Msg::Mag(_, m) => m.header.tick,
            Msg::Css(_, m) => m.header.tick,
            Msg::Fss(_, m) => m.header.tick,
            Msg::Gps(_, m) => m.header.tick,
            Msg::Time(m) => m.header.tick,
        };
        if self.last.is_some_and(|last| tick <= last) {
            return Ok(()); // its tick was released already (it came after the time limit)
        }
        if self.held.as_ref().is_some_and(|h| tick > h.header.tick) {
            // The held tick's missing samples will not come any more.
            if let Some(t) = self.give_up() {
                ready(t);
            }
        }
        match msg {
            Msg::State(state) => {
                // Samples of ticks whose state never came (real time) are dropped.
                self.partial.retain(|t, _| *t >= tick);
                self.held = Some(*state);
            }
            Msg::Imu(i, m) => self.partial_mut(tick).imus[i] = Some(m),
            Msg::Tracker(i, m) => self.partial_mut(tick).star_trackers[i] = Some(m),
            Msg::Mag(i, m) => self.partial_mut(tick).magnetometers[i] = Some(m),
            Msg::Css(i, m) => self.partial_mut(tick).coarse_sun_sensors[i] = Some(m),
            Msg::Fss(i, m) => self.partial_mut(tick).fine_sun_sensors[i] = Some(m),
            Msg::Gps(i, m) => self.partial_mut(tick).gps_receivers[i] = Some(m),
            Msg::Time(m) => self.time = Some(m),
        }
        if self.held.is_some() && self.awaited().is_empty() {
            if let Some(t) = self.release() {
                ready(t);
            }
        }
        Ok(())
    }

    /// Notes a `dropout` fault's activation or clearance (other faults change no schedule).
    fn note_fault(&mut self, ev: &FaultEventMsg) {
        if FAULT_MODE_NAMES.get(ev.mode as usize) != Some(&"dropout") {
            return;
        }
        let Some(route) = ev.target.as_str().and_then(sensor_route) else {
            return;
        };
        if ev.active {
            self.withheld.push(Withheld {
                fault_index: ev.fault_index,
                route,
                from_ns: ev.edge_ns,
                until_ns: u64::MAX,
            });
        } else if let Some(w) = self
            .withheld
            .iter_mut()
            .rev()
            .find(|w| w.fault_index == ev.fault_index && w.until_ns == u64::MAX)
        {
            w.until_ns = ev.edge_ns;
        }
    }

    /// The missing samples of the held tick still to wait for: those no dropout withheld.
    fn awaited(&self) -> Vec<String> {
        let Some(t_ns) = self.held.as_ref().map(|h| h.header.sim_time_ns) else {
            return Vec::new();
        };
        let mut missing = self.missing();
        missing.retain(|route| {
            !self
                .withheld
                .iter()
                .any(|w| w.route == *route && (w.from_ns..w.until_ns).contains(&t_ns))
        });
        missing
    }

    fn partial_mut(&mut self, tick: u64) -> &mut Partial {
        let s = &self.schedule;
        self.partial
            .entry(tick)
            .or_insert_with(|| Partial::empty(s))
    }

    /// The due samples of the held tick not received yet (`imu/<name>`, `st/<name>`,
    /// `mag/<name>`, `css/<name>`, `fss/<name>`, `gps/<name>`).
    fn missing(&self) -> Vec<String> {
        let Some(tick) = self.held.as_ref().map(|h| h.header.tick) else {
            return Vec::new();
        };
        let part = self.partial.get(&tick);
        let s = &self.schedule;
        let imus = s.imus.iter().enumerate().filter_map(|(i, name)| {
            let have = part.is_some_and(|p| p.imus[i].is_some());
            (!have).then(|| format!("imu/{name}"))
        });
        let sts = missing_due(&s.star_trackers, "st", tick, |i| {
            part.is_some_and(|p| p.star_trackers[i].is_some())
        });
        let mags = missing_due(&s.magnetometers, "mag", tick, |i| {
            part.is_some_and(|p| p.magnetometers[i].is_some())
        });
        let css = missing_due(&s.coarse_sun_sensors, "css", tick, |i| {
            part.is_some_and(|p| p.coarse_sun_sensors[i].is_some())
        });
        let fss = missing_due(&s.fine_sun_sensors, "fss", tick, |i| {
            part.is_some_and(|p| p.fine_sun_sensors[i].is_some())
        });
        let gps = missing_due(&s.gps_receivers, "gps", tick, |i| {
            part.is_some_and(|p| p.gps_receivers[i].is_some())
        });
        imus.chain(sts)
            .chain(mags)
            .chain(css)
            .chain(fss)
            .chain(gps)
            .collect()
    }

    /// The tick whose state is held, waiting for samples.
    pub fn waiting(&self) -> Option<u64> {
        self.held.as_ref().map(|h| h.header.tick)
    }

    /// Releases the held tick as it is, its missing samples listed in [`Tick::missing`].
    pub fn give_up(&mut self) -> Option<Tick> {
        self.release()
    }

    fn release(&mut self) -> Option<Tick> {
        let missing = self.missing();
        let state = self.held.take()?;
        let tick = state.header.tick;
        let t_ns = state.header.sim_time_ns;
        self.withheld.retain(|w| w.until_ns > t_ns);
        let part = self.partial.remove(&tick);
        self.partial.retain(|t, _| *t > tick);
        self.last = Some(tick);
        let p = part.unwrap_or_else(|| Partial::empty(&self.schedule));
        Some(Tick {
            state,
            imus: p.imus,
            star_trackers: p.star_trackers,
            magnetometers: p.magnetometers,
            coarse_sun_sensors: p.coarse_sun_sensors,
            fine_sun_sensors: p.fine_sun_sensors,
            gps_receivers: p.gps_receivers,
            time: self.time.filter(|t| t.header.tick == tick),
            missing,
        })
    }
}

/// Complete ticks from a server: a callback subscriber on each key of [`SensorSchedule::keys`],
/// all feeding one [`TickAssembler`] as the samples arrive, on Zenoh's receiving thread, and wakes the reader
/// only when a tick is complete. A tick whose samples have not all come `sensor_timeout` after
/// its state is handed out without them; one whose missing samples a `dropout` fault withheld is
/// handed out as soon as the fault event says so (module docs).
///
/// # Why the samples are assembled in the callback
/// A tick is several samples (its time message, its sensors, its state). Queued to the reader
/// one by one, each could wake the reader's thread, and on a virtual machine a wake-up is among
/// the dearest things a tick pays for: in a lockstep run on this project's 2-vCPU VM, the
/// server's first put of a frame, which wakes Zenoh's transmit thread, took 19–20 µs and its
/// second 1.3 µs. Assembled here, a tick wakes its reader once, whatever number of samples it
/// has. Measured on `scenarios/wheels_star_tracker.toml` in real time (100 Hz, an IMU every
/// tick and a star tracker at 10 Hz), `flexdyn-acs-demo`'s main thread went from 1037–1051
/// context switches and 20.8–30.5 ms of CPU per 5 s to 714–747 and 14.9–17.9 ms.
///
/// At most `capacity` complete ticks wait for the reader: in real time, a reader that falls
/// behind loses the oldest ticks ([`Self::lost`]) rather than queueing stale ones; in lockstep at
/// most one tick is in flight. With a handler no tick waits ([`TickHandler`]).
pub struct TickReceiver {
    /// One per key of [`SensorSchedule::keys`], each on its key declared to the session so
    /// that Zenoh routes its samples by a cached route
    /// ([`crate::client::transport::declared_key`]).
    _subscribers: Vec<Subscriber<()>>,
    shared: Arc<Shared>,
    schedule: SensorSchedule,
    sensor_timeout: Duration,
    /// When the held tick started waiting.
    waiting_since: Option<(u64, Instant)>,
    /// Undecodable samples received (as of the last [`Self::recv_timeout`]).
    pub undecodable: u64,
    /// Ticks handed out (or to the handler) with samples missing (as of the last
    /// [`Self::recv_timeout`]).
    pub incomplete: u64,
    /// Complete ticks dropped, oldest first, because more than `capacity` waited for the
    /// reader (as of the last [`Self::recv_timeout`]).
    pub lost: u64,
}

/// Flight code that answers each complete tick where it completes
/// ([`TickReceiver::declare_with_handler`]).
///
/// `on_tick` runs on the Zenoh thread that delivered the tick's last sample, or, for a tick
/// released without some of its samples after the sensor time limit, on the thread that calls
/// [`TickReceiver::recv_timeout`] (or on a Zenoh thread whose sample arrives while that call
/// hands it over); never two at once, and in tick order.
///
/// While it runs, that Zenoh thread delivers nothing else to the session, so:
/// - keep it to the flight code's own work (read, compute, publish the answer) and leave
///   blocking I/O to another thread;
/// - never wait on a Zenoh query inside it (its reply would come on the thread it blocks);
/// - in real time, a handler slower than a frame holds up the telemetry behind it, and the
///   server drops samples rather than wait (there is no queue of whole ticks to lose instead,
///   as [`TickReceiver::declare`]'s reader has);
/// - a panic in it unwinds into Zenoh's receiving task, which ends it: catch it in `on_tick`
///   (`std::panic::catch_unwind`) and report it to the owner.
///
/// Do not hold the handler's lock while calling [`TickReceiver::recv_timeout`]: it may take
/// that lock to hand over a released tick.
pub trait TickHandler: Send {
    /// Handles one complete tick (the state of its frame and its due sensor samples).
    fn on_tick(&mut self, tick: Tick);
}

impl<F: FnMut(Tick) + Send> TickHandler for F {
    fn on_tick(&mut self, tick: Tick) {
        self(tick);
    }
}

/// A handler shared between the receiver and its owner, who keeps a clone to read its state.
pub type SharedHandler = Arc<Mutex<dyn TickHandler>>;

/// What the subscriber's callback and the reader share.
struct Shared {
    inner: Mutex<Inner>,
    /// Signalled when `ready` stops being empty (without a handler), or, with one, when a tick
    /// starts waiting for an overdue sample, so that the reader starts its time limit then.
    ready: Condvar,
    /// With a handler, the ticks go to it instead of `ready`'s reader. Locked before `inner`
    /// and held while the ticks it takes are handled, so they are handled in order.
    handler: Option<SharedHandler>,
}

struct Inner {
    assembler: TickAssembler,
    ready: VecDeque<Tick>,
    capacity: usize,
    undecodable: u64,
    lost: u64,
    /// Times the callback signalled the reader (once per tick that found `ready` empty).
    signals: u64,
    /// Ticks taken from `ready` with samples missing ([`Inner::pop_ready`]).
    incomplete: u64,
    /// With a handler: the held tick whose wait the callback last signalled to the reader.
    held_signalled: Option<u64>,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Inner> {
        // A panic while holding the lock cannot leave the assembler half-updated in a way that
        // matters more than losing the sample: go on with it.
        self.inner.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The subscriber's callback: one sample into the assembler.
    fn take(&self, sample: &Sample) {
        let payload = sample.payload().to_bytes();
        let mut handler = self
            .handler
            .as_ref()
            .map(|h| h.lock().unwrap_or_else(PoisonError::into_inner));
        let mut g = self.lock();
        let was_empty = g.ready.is_empty();
        let Inner {
            assembler, ready, ..
        } = &mut *g;
        if let Err(e) = assembler.push(sample.key_expr().as_str(), &payload, |t| ready.push_back(t))
        {
            g.undecodable += 1;
            if g.undecodable == 1 || g.undecodable.is_multiple_of(100) {
                tracing::warn!(key = %sample.key_expr(), error = %e, undecodable = g.undecodable, "an undecodable sample");
            }
        }
        if let Some(h) = handler.as_deref_mut() {
            g.hand_over(h);
            // A tick that now waits for an overdue sample: wake the reader once, so that its
            // time limit runs from now, not from the reader's next look.
            let held = g.assembler.waiting();
            let signal = held.is_some() && held != g.held_signalled;
            if signal {
                g.held_signalled = held;
            }
            drop(g);
            drop(handler);
            if signal {
                self.ready.notify_one();
            }
            return;
        }
        while g.ready.len() > g.capacity {
            g.ready.pop_front();
            g.lost += 1;
        }
        let wake = was_empty && !g.ready.is_empty();
        g.signals += u64::from(wake);
        drop(g);
        if wake {
            self.ready.notify_one();
        }
    }
}

impl Inner {
    /// The oldest ready tick; one without all its samples is counted in `incomplete` and
    /// warned of (the first, then every 100th).
    fn pop_ready(&mut self) -> Option<Tick> {
        let t = self.ready.pop_front()?;
        if !t.missing.is_empty() {
            self.incomplete += 1;
            if self.incomplete == 1 || self.incomplete.is_multiple_of(100) {
                tracing::warn!(
                    tick = t.tick(),
                    missing = ?t.missing,
                    incomplete = self.incomplete,
                    "a tick without all its sensor samples"
                );
            }
        }
        Some(t)
    }

    /// Hands the ready ticks to the handler, in order (the caller holds the handler's lock).
    fn hand_over(&mut self, handler: &mut dyn TickHandler) {
        while let Some(t) = self.pop_ready() {
            handler.on_tick(t);
        }
    }
}

impl TickReceiver {
    /// Subscribes to the telemetry of `topics` (do it before declaring a lockstep
    /// participant's liveliness token, so tick 0 cannot be missed); the reader takes the
    /// complete ticks with [`Self::recv_timeout`].
    pub fn declare(
        session: &Session,
        topics: &Topics,
        schedule: SensorSchedule,
        capacity: usize,
        sensor_timeout: Duration,
    ) -> zenoh::Result<Self> {
        Self::declare_inner(session, topics, schedule, capacity, sensor_timeout, None)
    }

    /// Like [`Self::declare`], but each complete tick goes to `handler` on the Zenoh thread
    /// that completed it ([`TickHandler`]), instead of waking a reader: the answer leaves
    /// without a hop between threads. Keep calling [`Self::recv_timeout`] (it returns `None`):
    /// it releases a tick whose samples are overdue to the handler, and is where the owner
    /// notices the end of the run. The owner keeps a clone of `handler` to read its state.
    pub fn declare_with_handler(
        session: &Session,
        topics: &Topics,
        schedule: SensorSchedule,
        sensor_timeout: Duration,
        handler: SharedHandler,
    ) -> zenoh::Result<Self> {
        Self::declare_inner(session, topics, schedule, 1, sensor_timeout, Some(handler))
    }

    fn declare_inner(
        session: &Session,
        topics: &Topics,
        schedule: SensorSchedule,
        capacity: usize,
        sensor_timeout: Duration,
        handler: Option<SharedHandler>,
    ) -> zenoh::Result<Self> {
        let shared = Arc::new(Shared {
            inner: Mutex::new(Inner {
                assembler: TickAssembler::new(topics.clone(), schedule.clone()),
                ready: VecDeque::new(),
                capacity: capacity.max(1),
                undecodable: 0,
                lost: 0,
                signals: 0,
                incomplete: 0,
                held_signalled: None,
            }),
            ready: Condvar::new(),
            handler,
        });
        // One callback subscriber per key rather than one on `tlm/**`: Zenoh then sends this
        // session only what a tick is assembled from (not the time message when the schedule
        // leaves it out, nor the environment or another process's telemetry), and the
        // callbacks still run in arrival order on the thread that reads the link (module docs).
        let subscribers = schedule
            .keys(topics)
            .into_iter()
            .map(|key| {
                let feed = shared.clone();
                session
                    .declare_subscriber(declared_key(session, key)?)
                    .callback(move |sample| feed.take(&sample))
                    .wait()
            })
            .collect::<zenoh::Result<_>>()?;
        Ok(Self {
            _subscribers: subscribers,
            shared,
            schedule,
            sensor_timeout,
            waiting_since: None,
            undecodable: 0,
            incomplete: 0,
            lost: 0,
        })
    }

    /// The schedule it follows.
    pub fn schedule(&self) -> &SensorSchedule {
        &self.schedule
    }

    /// The next tick, waiting at most `timeout` for it; `Ok(None)` if none is complete by then.
    /// With a handler ([`Self::declare_with_handler`]) it hands a tick released after the
    /// sensor time limit to the handler, and returns `Ok(None)` at `timeout`.
    /// (It never fails today; the `Result` is kept for the callers written against the
    /// channel-backed receiver.)
    pub fn recv_timeout(&mut self, timeout: Duration) -> zenoh::Result<Option<Tick>> {
        let deadline = Instant::now() + timeout;
        let shared = self.shared.clone();
        // With a handler, its lock comes first (the callback's order); it is taken only for a
        // release, so the callbacks run freely while this waits.
        let mut g = shared.lock();
        loop {
            self.undecodable = g.undecodable;
            self.lost = g.lost;
            if let Some(handler) = &shared.handler {
                if !g.ready.is_empty() {
                    drop(g);
                    let mut h = handler.lock().unwrap_or_else(PoisonError::into_inner);
                    g = shared.lock();
                    g.hand_over(&mut *h);
                    continue;
                }
            } else if let Some(t) = g.pop_ready() {
                self.incomplete = g.incomplete;
                return Ok(Some(t));
            }
            self.incomplete = g.incomplete;
            // Give up on a held tick once its samples are overdue.
            let mut wake = deadline;
            match (g.assembler.waiting(), self.waiting_since) {
                (Some(t), Some((since_tick, since))) if t == since_tick => {
                    let give_up_at = since + self.sensor_timeout;
                    if Instant::now() >= give_up_at {
                        let released = g.assembler.give_up();
                        g.ready.extend(released);
                        continue;
                    }
                    wake = wake.min(give_up_at);
                }
                (Some(t), _) => {
                    self.waiting_since = Some((t, Instant::now()));
                    continue;
                }
                (None, _) => self.waiting_since = None,
            }
            let now = Instant::now();
            if now >= wake {
                if now >= deadline {
                    return Ok(None);
                }
                continue; // time to give up on the held tick
            }
            g = shared
                .ready
                .wait_timeout(g, wake - now)
                .unwrap_or_else(PoisonError::into_inner)
                .0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{encode, Header};

    fn schedule() -> SensorSchedule {
        let every = |name: &str, every| Periodic {
            name: name.into(),
            every,
            offset: 0,
        };
        SensorSchedule {
            time: true,
            imus: vec!["hub".into(), "bracket".into()],
            star_trackers: vec![every("st1", 10), every("st2", 4)],
            magnetometers: vec![every("mag1", 2)],
            coarse_sun_sensors: vec![every("css", 5)],
            fine_sun_sensors: vec![],
            gps_receivers: vec![],
        }
    }

    /// The keys a receiver subscribes to are the keys its assembler reads: the state, the
    /// fault events, the time message unless the schedule leaves it out, and each scheduled
    /// sample's key, one each; never the environment message, which a tick does not carry.
    #[test]
    fn the_subscribed_keys_are_the_keys_a_tick_is_assembled_from() {
        let topics = Topics::new("sc1").unwrap();
        let keys = schedule().keys(&topics);
        assert_eq!(keys[1], topics.fault_events());
        let read: Vec<Telemetry> = keys.iter().filter_map(|k| topics.telemetry(k)).collect();
        use Telemetry::*;
        let sensors = [
            Imu("hub"),
            Imu("bracket"),
            StarTracker("st1"),
            StarTracker("st2"),
            Magnetometer("mag1"),
            Css("css"),
        ];
        assert_eq!(read[..2], [State, Time]);
        assert_eq!(read[2..], sensors);
        assert_eq!(keys.len(), read.len() + 1);
        let keys = schedule().without_time().keys(&topics);
        let read: Vec<Telemetry> = keys.iter().filter_map(|k| topics.telemetry(k)).collect();
        assert_eq!(read[..1], [State]);
        assert_eq!(read[1..], sensors);
        assert_eq!(keys.len(), read.len() + 1);
        let keys = sun_and_gps_schedule().keys(&topics);
        let read: Vec<Telemetry> = keys
            .iter()
            .skip(3)
            .filter_map(|k| topics.telemetry(k))
            .collect();
        assert_eq!(read, [Fss("fss"), Gps("gps1")]);
    }

    /// A schedule without the time message ignores one pushed to its assembler: the tick comes
    /// without it, as it does when the receiver never subscribed to it.
    #[test]
    fn a_schedule_without_time_hands_out_ticks_without_it() {
        let mut f = Feed::with(sun_and_gps_schedule().without_time());
        let time = TimeMsg {
            header: header(1),
            met_ns: 10_000_000,
            ..TimeMsg::default()
        };
        f.push("flexdyn/sc1/tlm/time", encode(&time));
        f.state(1);
        assert_eq!(f.out.len(), 1);
        assert_eq!(f.out[0].time, None);
        assert!(!f.a.schedule().has_time());
        // The same samples with the time message kept: the tick carries it.
        let mut f = Feed::with(sun_and_gps_schedule());
        f.push("flexdyn/sc1/tlm/time", encode(&time));
        f.state(1);
        assert_eq!(f.out[0].time, Some(time));
    }

    /// A fine sun sensor every 5 frames and a GPS receiver every 10 frames with a latency of 3:
    /// its solutions are due at ticks 3, 13, 23, …, never at 0.
    fn sun_and_gps_schedule() -> SensorSchedule {
        SensorSchedule {
            time: true,
            imus: vec![],
            star_trackers: vec![],
            magnetometers: vec![],
            coarse_sun_sensors: vec![],
            fine_sun_sensors: vec![Periodic {
                name: "fss".into(),
                every: 5,
                offset: 0,
            }],
            gps_receivers: vec![Periodic {
                name: "gps1".into(),
                every: 10,
                offset: 3,
            }],
        }
    }

    fn header(tick: u64) -> Header {
        Header::new(1, tick, tick * 10_000_000, tick)
    }

    struct Feed {
        a: TickAssembler,
        out: Vec<Tick>,
    }

    impl Feed {
        fn new() -> Self {
            Self::with(schedule())
        }
        fn with(schedule: SensorSchedule) -> Self {
            Self {
                a: TickAssembler::new(Topics::new("sc1").unwrap(), schedule),
                out: Vec::new(),
            }
        }
        fn push(&mut self, key: &str, payload: Vec<u8>) {
            let out = &mut self.out;
            self.a.push(key, &payload, |t| out.push(t)).unwrap();
        }
        fn state(&mut self, tick: u64) {
            let m = StateMsg {
                header: header(tick),
                ..StateMsg::default()
            };
            self.push("flexdyn/sc1/tlm/state", encode(&m));
        }
        fn imu(&mut self, name: &str, tick: u64) {
            let m = ImuMsg {
                header: header(tick),
                omega_p_rad_s: [tick as f64, 0.0, 0.0],
                ..ImuMsg::default()
            };
            self.push(&format!("flexdyn/sc1/tlm/imu/{name}"), encode(&m));
        }
        fn st(&mut self, name: &str, tick: u64) {
            let m = StarTrackerMsg {
                header: header(tick),
                valid: true,
                ..StarTrackerMsg::default()
            };
            self.push(&format!("flexdyn/sc1/tlm/st/{name}"), encode(&m));
        }
        fn mag(&mut self, tick: u64) {
            let m = MagnetometerMsg {
                header: header(tick),
                b_s_t: [tick as f64, 0.0, 0.0],
                ..MagnetometerMsg::default()
            };
            self.push("flexdyn/sc1/tlm/mag/mag1", encode(&m));
        }
        fn css(&mut self, tick: u64) {
            let m = CssMsg {
                header: header(tick),
                detector_count: 1,
                ..CssMsg::default()
            };
            self.push("flexdyn/sc1/tlm/css/css", encode(&m));
        }
        fn fss(&mut self, tick: u64) {
            let m = FssMsg {
                header: header(tick),
                alpha_rad: tick as f64,
                ..FssMsg::default()
            };
            self.push("flexdyn/sc1/tlm/fss/fss", encode(&m));
        }
        fn gps(&mut self, tick: u64, latency: u64) {
            let m = GpsMsg {
                header: header(tick),
                valid_sim_time_ns: (tick - latency) * 10_000_000,
                ..GpsMsg::default()
            };
            self.push("flexdyn/sc1/tlm/gps/gps1", encode(&m));
        }
        /// A fault event of fault `index` (`mode` by name) on `target` with its edge at
        /// tick-time `edge_tick`, reported at boundary `tick`.
        fn fault(&mut self, index: u32, mode: &str, target: &str, active: bool, at: (u64, u64)) {
            let (tick, edge_tick) = at;
            let m = FaultEventMsg {
                header: header(tick),
                fault_index: index,
                mode: FAULT_MODE_NAMES.iter().position(|n| *n == mode).unwrap() as u32,
                active,
                edge_ns: edge_tick * 10_000_000,
                target: crate::FaultTarget::new(target).unwrap(),
                ..FaultEventMsg::default()
            };
            self.push("flexdyn/sc1/tlm/fault", encode(&m));
        }
        fn ticks(&self) -> Vec<(u64, Vec<String>)> {
            self.out
                .iter()
                .map(|t| (t.tick(), t.missing.clone()))
                .collect()
        }
    }

    /// In publication order (samples, state, then the boundary's fault events): a dropout's
    /// activation event releases the tick its state is waiting with, the next ticks go with
    /// their states, and after its clearance the sensor is waited for again. Other faults, and
    /// dropouts of sensors not in the schedule, change nothing.
    #[test]
    fn a_dropout_fault_event_stops_the_wait_for_the_samples_it_withholds() {
        // Only the IMUs are due at odd ticks that are not multiples of 5 (schedule()).
        let mut f = Feed::new();
        f.imu("hub", 1);
        f.imu("bracket", 1);
        f.state(1);
        assert_eq!(f.ticks(), [(1, vec![])]);
        // Tick 3: imus.bracket drops out from tick 3; a bias on imus.hub is no dropout.
        f.imu("hub", 3);
        f.state(3);
        f.fault(0, "bias_step", "imus.hub.gyro", true, (3, 3));
        assert_eq!(f.a.waiting(), Some(3), "a bias withholds nothing");
        f.fault(1, "dropout", "imus.nowhere", true, (3, 3));
        assert_eq!(f.a.waiting(), Some(3), "not a sensor of the schedule");
        f.fault(2, "dropout", "imus.bracket", true, (3, 3));
        let bracket = || vec!["imu/bracket".to_owned()];
        assert_eq!(f.ticks()[1..], [(3, bracket())]);
        // Tick 7: released with its state.
        f.imu("hub", 7);
        f.state(7);
        assert_eq!(f.ticks()[2..], [(7, bracket())]);
        // Cleared at tick 9 (reported at boundary 9, after its state): tick 9's sample is
        // published again and awaited.
        f.imu("hub", 9);
        f.imu("bracket", 9);
        f.state(9);
        f.fault(2, "dropout", "imus.bracket", false, (9, 9));
        assert_eq!(f.ticks()[3..], [(9, vec![])]);
        f.imu("hub", 11);
        f.state(11);
        assert_eq!(
            f.a.waiting(),
            Some(11),
            "no dropout any more: wait for imu/bracket"
        );
        f.imu("bracket", 11);
        assert_eq!(f.ticks()[4..], [(11, vec![])]);
        // A dropout that began and ended inside frame 12 → 13 withheld no sample (the IMUs
        // publish at boundaries): it is reported after tick 13, and tick 17 waits as before.
        f.imu("hub", 13);
        f.imu("bracket", 13);
        f.state(13);
        f.fault(3, "dropout", "imus.bracket", true, (13, 12));
        f.fault(3, "dropout", "imus.bracket", false, (13, 12));
        assert_eq!(f.ticks()[5..], [(13, vec![])]);
        f.imu("hub", 17);
        f.state(17);
        assert_eq!(f.a.waiting(), Some(17));
    }

    #[test]
    fn each_tick_carries_its_own_time_message_and_no_other() {
        let mut f = Feed::new();
        let time = |tick| TimeMsg {
            header: header(tick),
            met_ns: tick * 10_000_000,
            ..TimeMsg::default()
        };
        // Tick 1 (no star tracker, magnetometer or CSS due): its time first, as the server
        // publishes it, then the IMUs and the state.
        f.push("flexdyn/sc1/tlm/time", encode(&time(1)));
        f.imu("hub", 1);
        f.imu("bracket", 1);
        f.state(1);
        assert_eq!(f.out.len(), 1);
        assert_eq!(f.out[0].time, Some(time(1)));
        // Tick 3 whose time message was lost: the tick comes without one, not with tick 1's.
        f.imu("hub", 3);
        f.imu("bracket", 3);
        f.state(3);
        assert_eq!(f.out.len(), 2);
        assert_eq!(f.out[1].time, None);
    }

    #[test]
    fn a_state_that_overtakes_its_samples_waits_for_them() {
        let mut f = Feed::new();
        f.state(0);
        f.imu("hub", 0);
        f.st("st1", 0);
        f.imu("bracket", 0);
        assert!(f.out.is_empty(), "tick 0 released without st/st2");
        assert_eq!(f.a.waiting(), Some(0));
        f.st("st2", 0);
        assert!(
            f.out.is_empty(),
            "tick 0 released without mag/mag1 and css/css"
        );
        f.mag(0);
        f.css(0);
        assert_eq!(f.ticks(), [(0, vec![])]);
        let t = &f.out[0];
        assert!(t.imus.iter().all(Option::is_some) && t.star_trackers.iter().all(Option::is_some));
        assert!(t.magnetometers[0].is_some() && t.coarse_sun_sensors[0].is_some());
        // Tick 1: no tracker is due; in publication order it is released with its state.
        f.imu("hub", 1);
        f.imu("bracket", 1);
        f.state(1);
        assert_eq!(f.ticks(), [(0, vec![]), (1, vec![])]);
        assert_eq!(f.out[1].imus[0].as_ref().unwrap().omega_p_rad_s[0], 1.0);
        assert_eq!(f.out[1].star_trackers, [None, None]);
        assert_eq!(
            (f.out[1].magnetometers[0], f.out[1].coarse_sun_sensors[0]),
            (None, None)
        );
        // Tick 4: st2 (period 4) and mag1 (period 2) are due, st1 (period 10) and css (5) are
        // not.
        f.imu("hub", 4);
        f.imu("bracket", 4);
        f.state(4);
        assert_eq!(f.a.waiting(), Some(4));
        f.st("st2", 4);
        assert_eq!(f.a.waiting(), Some(4));
        f.mag(4);
        assert_eq!(f.ticks().last(), Some(&(4, vec![])));
        assert_eq!(f.out[2].magnetometers[0].unwrap().b_s_t[0], 4.0);
    }

    #[test]
    fn lost_samples_release_the_tick_when_given_up_or_overtaken() {
        let mut f = Feed::new();
        f.imu("hub", 3);
        f.state(3); // imu/bracket of tick 3 never comes
        assert!(f.out.is_empty());
        assert_eq!(
            f.a.give_up().map(|t| t.missing),
            Some(vec!["imu/bracket".to_string()])
        );
        f.imu("bracket", 3); // too late: ignored
        assert_eq!(f.a.waiting(), None);
        // Real time: a sample of tick 6 gives up on tick 5 at once.
        f.imu("hub", 5);
        f.state(5);
        f.imu("hub", 6);
        assert_eq!(
            f.ticks(),
            [(5, vec!["imu/bracket".to_string(), "css/css".to_string()])]
        );
        f.imu("bracket", 6);
        f.mag(6);
        f.state(6);
        assert_eq!(f.ticks().last(), Some(&(6, vec![])));
        // Keys of other spacecraft, unknown sensors and non-telemetry are ignored; garbage
        // under a known key is an error.
        let mut out = Vec::new();
        let a = &mut f.a;
        for key in [
            "flexdyn/sc2/tlm/state",
            "flexdyn/sc1/tlm/imu/other",
            "flexdyn/sc1/status",
        ] {
            a.push(key, &[1, 2, 3], |t| out.push(t)).unwrap();
        }
        assert!(a
            .push("flexdyn/sc1/tlm/state", &[4, 0, 1], |t| out.push(t))
            .is_err());
        assert!(out.is_empty());
    }

    #[test]
    fn fine_sun_and_gps_samples_are_awaited_at_their_own_ticks() {
        let mut f = Feed::new();
        f.a = TickAssembler::new(Topics::new("sc1").unwrap(), sun_and_gps_schedule());
        // Tick 0: the sun sensor is due, the GPS receiver (latency 3) is not.
        f.state(0);
        assert_eq!(f.a.waiting(), Some(0));
        f.fss(0);
        assert_eq!(f.ticks(), [(0, vec![])]);
        assert_eq!(f.out[0].fine_sun_sensors[0].unwrap().alpha_rad, 0.0);
        assert_eq!(f.out[0].gps_receivers, [None]);
        // Ticks 1, 2: nothing due.
        f.state(1);
        f.state(2);
        assert_eq!(f.ticks().len(), 3);
        // Tick 3: the first solution (valid at tick 0) is due.
        f.state(3);
        assert_eq!(f.a.waiting(), Some(3), "tick 3 released without gps/gps1");
        f.gps(3, 3);
        assert_eq!(f.ticks().last(), Some(&(3, vec![])));
        assert_eq!(f.out[3].gps_receivers[0].unwrap().valid_sim_time_ns, 0);
        // Tick 5: the sun sensor again; tick 13: the GPS again, lost, then given up.
        f.state(5);
        f.fss(5);
        f.state(13);
        assert_eq!(
            f.a.give_up().map(|t| t.missing),
            Some(vec!["gps/gps1".to_string()])
        );
    }

    /// [`TickReceiver`] on a real Zenoh session: the server's samples are published on the same
    /// session (local delivery runs the subscriber's callback inside the put, so the order and
    /// the timing are the test's).
    mod receiver {
        use super::*;

        fn session() -> Session {
            let mut c = zenoh::Config::default();
            for (key, value) in [
                ("mode", r#""peer""#),
                ("listen/endpoints", "[]"),
                ("connect/endpoints", "[]"),
                ("scouting/multicast/enabled", "false"),
                ("scouting/gossip/enabled", "false"),
            ] {
                c.insert_json5(key, value).unwrap();
            }
            zenoh::open(c).wait().unwrap()
        }

        fn put(session: &Session, key: &str, payload: Vec<u8>) {
            session.put(key, payload).wait().unwrap();
        }

        /// Tick `k` as the server publishes it for [`schedule`] at a tick where only the IMUs
        /// are due (k odd and not a multiple of 5): its time, both IMUs, then its state.
        fn publish_tick(session: &Session, k: u64) {
            let time = TimeMsg {
                header: header(k),
                ..TimeMsg::default()
            };
            put(session, "flexdyn/sc1/tlm/time", encode(&time));
            for name in ["hub", "bracket"] {
                let m = ImuMsg {
                    header: header(k),
                    ..ImuMsg::default()
                };
                put(session, &format!("flexdyn/sc1/tlm/imu/{name}"), encode(&m));
            }
            let m = StateMsg {
                header: header(k),
                ..StateMsg::default()
            };
            put(session, "flexdyn/sc1/tlm/state", encode(&m));
        }

        fn receiver(session: &Session, capacity: usize, sensor_timeout: Duration) -> TickReceiver {
            let topics = Topics::new("sc1").unwrap();
            TickReceiver::declare(session, &topics, schedule(), capacity, sensor_timeout).unwrap()
        }

        /// Four samples a tick, and the reader is signalled once per tick: the samples are
        /// assembled in the callback, and only a complete tick wakes the reader.
        #[test]
        fn a_tick_signals_its_reader_once_whatever_its_samples() {
            let session = session();
            let mut rx = receiver(&session, 8, Duration::from_secs(60));
            let ticks = [1, 3, 7, 9, 11];
            for k in ticks {
                publish_tick(&session, k);
                let t = rx.recv_timeout(Duration::from_secs(5)).unwrap().unwrap();
                assert_eq!(t.tick(), k);
                assert_eq!(t.imus.len(), 2);
                assert_eq!(t.time.map(|m| m.header.tick), Some(k));
                assert!(t.missing.is_empty());
            }
            assert_eq!(rx.shared.lock().signals, ticks.len() as u64);
            assert_eq!((rx.undecodable, rx.incomplete, rx.lost), (0, 0, 0));
            assert!(rx
                .recv_timeout(Duration::from_millis(10))
                .unwrap()
                .is_none());
        }

        /// A reader that falls behind keeps the newest `capacity` ticks and counts the others.
        #[test]
        fn a_reader_behind_loses_the_oldest_ticks() {
            let session = session();
            let mut rx = receiver(&session, 2, Duration::from_secs(60));
            for k in [1, 3, 7, 9, 11] {
                publish_tick(&session, k);
            }
            let got: Vec<u64> = std::iter::from_fn(|| {
                rx.recv_timeout(Duration::from_millis(10))
                    .unwrap()
                    .map(|t| t.tick())
            })
            .collect();
            assert_eq!(got, [9, 11]);
            assert_eq!(rx.lost, 3);
            // One signal: the queue never became empty between the first tick and the reads.
            assert_eq!(rx.shared.lock().signals, 1);
        }

        /// A state whose IMU samples never come is handed out after the sensor time limit,
        /// with the missing samples listed; an undecodable sample is counted, not fatal.
        #[test]
        fn a_tick_missing_samples_is_released_after_the_time_limit() {
            let session = session();
            let limit = Duration::from_millis(80);
            let mut rx = receiver(&session, 8, limit);
            put(&session, "flexdyn/sc1/tlm/imu/hub", vec![1, 2, 3]);
            let m = StateMsg {
                header: header(1),
                ..StateMsg::default()
            };
            let sent = Instant::now();
            put(&session, "flexdyn/sc1/tlm/state", encode(&m));
            let t = rx.recv_timeout(Duration::from_secs(5)).unwrap().unwrap();
            assert!(
                sent.elapsed() >= limit,
                "released after {:?}",
                sent.elapsed()
            );
            assert_eq!(t.tick(), 1);
            assert_eq!(t.missing, ["imu/hub", "imu/bracket"]);
            assert_eq!((rx.incomplete, rx.undecodable), (1, 1));
        }
    }
}
