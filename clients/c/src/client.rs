//! The library in safe Rust: a Zenoh session with the subscriptions, commands, lockstep
//! participant and flight-code telemetry streams of `flexdyn_client.h`. `crate::ffi` only
//! turns C pointers into these calls.
//!
//! Samples are queued by Zenoh's threads in ring channels and taken only when the caller asks
//! (poll or wait), so no user code ever runs on a Zenoh thread.

use std::ffi::CString;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use flexdyn_proto::client::lockstep::{SensorSchedule, Tick, TickReceiver};
use flexdyn_proto::client::run_end::{Ended, RunEnd};
use flexdyn_proto::client::transport::{declared_key, zenoh_config, Role, ZenohArgs};
use flexdyn_proto::client::vehicle::Vehicle;
use flexdyn_proto::{
    decode_imu, decode_star_tracker, decode_state, decode_status, decode_time, encode, CommandMsg,
    DecodeError, Header, ImuMsg, OperatorAction, OperatorMsg, StarTrackerMsg, StateMsg, StatusMsg,
    TimeMsg, Topics,
};
use zenoh::handlers::{RingChannel, RingChannelHandler};
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::Sample;
use zenoh::{Session, Wait};

use crate::error::{Code, Error};
use crate::fsw::FswStream;
use crate::kinds::{self, KINDS};

/// The spacecraft id of the keys when the options name none.
pub const DEFAULT_SC_ID: &str = "sc1";

/// How long a lockstep tick waits for a due sensor sample after its state before it is handed
/// out without it. In lockstep the server publishes a tick's samples before its state on one
/// subscriber, so this only matters when a sample is lost.
const SENSOR_TIMEOUT: Duration = Duration::from_secs(1);

/// Samples kept by the lockstep telemetry subscriber (at most one tick is in flight).
const LOCKSTEP_CAPACITY: usize = 256;

/// How often a blocking wait looks whether the run has ended, and how long it still waits for
/// a sample once the end was heard before it says [`Taken::Ended`] (as the Rust demo does).
/// The server publishes its last status after its last frame, so by then every frame is
/// queued; the slice only covers delivery on another Zenoh thread.
const END_SLICE: Duration = Duration::from_millis(20);

/// What a poll or a wait found.
pub enum Taken<T> {
    /// A sample (or a tick).
    Got(T),
    /// Nothing: a poll found nothing queued ([`Code::Empty`]), or (inside a wait) nothing came
    /// within the timeout and no end of run was heard (the wait makes it [`Code::Timeout`]).
    Empty,
    /// The server said the run ended and nothing more is queued ([`Code::Ended`]; waits only).
    Ended,
}

impl<T> Taken<T> {
    /// `f` of the value, if any.
    pub fn map<U>(self, f: impl FnOnce(T) -> U) -> Taken<U> {
        match self {
            Taken::Got(x) => Taken::Got(f(x)),
            Taken::Empty => Taken::Empty,
            Taken::Ended => Taken::Ended,
        }
    }
}

/// How to reach the server (`flexdyn_options`).
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// The string spacecraft id; `None` = [`DEFAULT_SC_ID`].
    pub sc_id: Option<String>,
    /// Endpoints to connect to; empty = `tcp/127.0.0.1:7447`.
    pub connect: Vec<String>,
    /// Endpoints to listen on; empty = nowhere.
    pub listen: Vec<String>,
    /// A Zenoh JSON5 file.
    pub zenoh_config_file: Option<PathBuf>,
}

type Ring = Subscriber<RingChannelHandler<Sample>>;

/// A lockstep participant: its telemetry, token, command publisher and the tick it holds.
struct Lockstep {
    sender_id: u32,
    receiver: TickReceiver,
    publisher: Publisher<'static>,
    _token: LivelinessToken,
    /// Per message kind ([`KINDS`]), the names of the run's sensors of that kind (empty for a
    /// kind a tick does not carry).
    names: Vec<Vec<CString>>,
    held: Option<Tick>,
    answered: bool,
}

/// An open session and what it declared.
pub struct Client {
    session: Session,
    topics: Topics,
    /// The end of the run: subscribed to `flexdyn/<sc>/status` from open, before anything
    /// else, so the end cannot be heard before the frames it follows are subscribed to.
    run_end: RunEnd,
    /// One subscription per message kind ([`KINDS`]), by number.
    subs: Vec<Option<Ring>>,
    /// The newest time message taken from the `time` subscription.
    last_time: Option<TimeMsg>,
    lockstep: Option<Lockstep>,
    /// The next command's `header.seq` (one counter for every command of this client).
    seq: u64,
}

/// Which subscription a poll or wait reads: a message kind's number ([`KINDS`],
/// `FLEXDYN_KIND_*` in C).
pub type Kind = usize;

/// The prose name of a kind (`IMU`).
fn what(kind: Kind) -> &'static str {
    KINDS.get(kind).map_or("unknown", |k| k.title)
}

/// Checks a kind number from C.
pub fn check_kind(kind: Kind) -> Result<&'static kinds::KindInfo, Error> {
    KINDS.get(kind).ok_or_else(|| {
        Error::new(
            Code::Argument,
            format!(
                "kind {kind} names no message (FLEXDYN_KIND_* is 0..{})",
                KINDS.len()
            ),
        )
    })
}

/// A received sample: the last chunk of its key (a sensor's name) and its payload.
pub struct Received {
    /// The key's last chunk.
    pub name: String,
    /// The payload bytes.
    pub payload: Vec<u8>,
}

fn decode_error(what: &str, key: &str, e: &DecodeError) -> Error {
    Error::new(
        Code::Decode,
        format!("an undecodable {what} sample on {key} (dropped): {e}"),
    )
}

/// Decodes a sample of `kind` from `key`.
pub fn decode_as<T>(
    what: &str,
    key: &str,
    bytes: &[u8],
    decode: impl Fn(&[u8]) -> Result<T, DecodeError>,
) -> Result<T, Error> {
    decode(bytes).map_err(|e| decode_error(what, key, &e))
}

impl Client {
    /// Opens a peer session with `options` (the flexdyn rules of
    /// `flexdyn_proto::client::transport`: loopback defaults, multicast scouting off).
    pub fn open(options: &Options) -> Result<Self, Error> {
        let sc = options.sc_id.as_deref().unwrap_or(DEFAULT_SC_ID);
        let topics = Topics::new(sc)
            .map_err(|e| Error::new(Code::Argument, format!("sc_id {sc:?}: {e}")))?;
        let args = ZenohArgs {
            listen: options.listen.clone(),
            connect: options.connect.clone(),
            zenoh_config: options.zenoh_config_file.clone(),
        };
        let config = zenoh_config(&args, Role::Tool).map_err(|e| {
            use flexdyn_proto::client::transport::ZenohConfigError as Z;
            let code = match e {
                Z::Value { .. } => Code::Argument,
                _ => Code::Config,
            };
            // The options' names, not the command-line flags the shared builder reports.
            let message = e
                .to_string()
                .replacen("--connect:", "connect:", 1)
                .replacen("--listen:", "listen:", 1);
            Error::new(code, message)
        })?;
        let session = zenoh::open(config)
            .wait()
            .map_err(|e| Error::zenoh("cannot open the Zenoh session", e))?;
        let run_end = RunEnd::declare(&session, &topics)
            .map_err(|e| Error::zenoh(&format!("cannot subscribe to {}", topics.status()), e))?;
        Ok(Self {
            session,
            topics,
            run_end,
            subs: KINDS.iter().map(|_| None).collect(),
            last_time: None,
            lockstep: None,
            seq: 0,
        })
    }

    /// Undeclares everything and closes the session.
    pub fn close(self) -> Result<(), Error> {
        let Self {
            session,
            run_end,
            subs,
            lockstep,
            ..
        } = self;
        drop((subs, lockstep, run_end));
        session
            .close()
            .wait()
            .map_err(|e| Error::zenoh("cannot close the Zenoh session", e))
    }

    fn slot(&mut self, kind: Kind) -> &mut Option<Ring> {
        &mut self.subs[kind]
    }

    /// The key of `kind` for one `name` (`Some`) or every one (`None`, a `*` chunk).
    fn key(&self, kind: Kind, name: Option<&str>) -> Result<String, Error> {
        let info = check_kind(kind)?;
        let base = format!("flexdyn/{}/{}", self.topics.sc_id(), info.key_tail);
        if !info.named {
            return Ok(base);
        }
        match name {
            None => Ok(format!("{base}/*")),
            Some(n) => {
                flexdyn_proto::validate_sensor_name(n).map_err(|e| {
                    Error::new(Code::Argument, format!("{} name {n:?}: {e}", info.title))
                })?;
                Ok(format!("{base}/{n}"))
            }
        }
    }

    /// Subscribes to `kind` (one sensor `name`, or all of them), keeping `capacity` samples;
    /// replaces an earlier subscription of the same kind.
    pub fn subscribe(
        &mut self,
        kind: Kind,
        name: Option<&str>,
        capacity: usize,
    ) -> Result<(), Error> {
        if capacity == 0 {
            return Err(Error::new(Code::Argument, "capacity must be at least 1"));
        }
        let key = self.key(kind, name)?;
        // The old subscription goes first, so a sample is never queued twice.
        *self.slot(kind) = None;
        let sub = self
            .session
            .declare_subscriber(key.clone())
            .with(RingChannel::new(capacity))
            .wait()
            .map_err(|e| Error::zenoh(&format!("cannot subscribe to {key}"), e))?;
        *self.slot(kind) = Some(sub);
        Ok(())
    }

    /// How the run ended, once the server's last status said so (`Finished`, `Failed` or
    /// `Stopped`); remembered from open until close.
    pub fn ended(&self) -> Option<Ended> {
        self.run_end.ended()
    }

    /// Waits up to `timeout` with `once`, in slices of [`END_SLICE`], and stops early once the
    /// run has ended and a slice found nothing more (what was queued is still handed out
    /// first). The end is looked at before each slice, so the slice that says
    /// [`Taken::Ended`] began after the end was heard.
    fn wait_sliced<T>(
        run_end: &RunEnd,
        timeout: Duration,
        mut once: impl FnMut(Duration) -> Result<Option<T>, Error>,
    ) -> Result<Taken<T>, Error> {
        let deadline = Instant::now() + timeout;
        loop {
            let ended = run_end.ended().is_some();
            let left = deadline.saturating_duration_since(Instant::now());
            if let Some(x) = once(left.min(END_SLICE))? {
                return Ok(Taken::Got(x));
            }
            if ended {
                return Ok(Taken::Ended);
            }
            if Instant::now() >= deadline {
                return Ok(Taken::Empty);
            }
        }
    }

    fn not_subscribed(kind: Kind) -> Error {
        Error::new(
            Code::Usage,
            format!(
                "not subscribed to {} (call the subscribe function first)",
                what(kind)
            ),
        )
    }

    fn received(s: Sample) -> Received {
        Received {
            name: s
                .key_expr()
                .as_str()
                .rsplit('/')
                .next()
                .unwrap_or_default()
                .to_owned(),
            payload: s.payload().to_bytes().into_owned(),
        }
    }

    /// The next sample of `kind` at once (`Ok(None)` when there is none).
    pub fn poll(&mut self, kind: Kind) -> Result<Taken<Received>, Error> {
        check_kind(kind)?;
        let Some(sub) = self.slot(kind).as_ref() else {
            return Err(Self::not_subscribed(kind));
        };
        let sample = sub.try_recv().map_err(|e| {
            Error::new(
                Code::Closed,
                format!("the {} subscription ended: {e}", what(kind)),
            )
        })?;
        Ok(match sample {
            Some(s) => Taken::Got(Self::received(s)),
            None => Taken::Empty,
        })
    }

    /// The next sample of `kind`, waiting up to `timeout` ([`Code::Timeout`]); once the run
    /// has ended, [`Taken::Ended`] as soon as nothing more is queued.
    pub fn wait(&mut self, kind: Kind, timeout: Duration) -> Result<Taken<Received>, Error> {
        check_kind(kind)?;
        let Self { run_end, subs, .. } = self;
        let Some(sub) = subs[kind].as_ref() else {
            return Err(Self::not_subscribed(kind));
        };
        let waited = Self::wait_sliced(run_end, timeout, |slice| {
            sub.recv_timeout(slice).map_err(|e| {
                Error::new(
                    Code::Closed,
                    format!("the {} subscription ended: {e}", what(kind)),
                )
            })
        })?;
        match waited {
            Taken::Got(s) => Ok(Taken::Got(Self::received(s))),
            Taken::Ended => Ok(Taken::Ended),
            Taken::Empty => Err(Error::new(
                Code::Timeout,
                format!(
                    "no {} sample on {} within {} ms",
                    what(kind),
                    sub.key_expr(),
                    timeout.as_millis()
                ),
            )),
        }
    }

    /// [`Self::poll`] when `timeout` is `None`, else [`Self::wait`].
    pub fn receive(
        &mut self,
        kind: Kind,
        timeout: Option<Duration>,
    ) -> Result<Taken<Received>, Error> {
        match timeout {
            None => self.poll(kind),
            Some(t) => self.wait(kind, t),
        }
    }

    /// The key of a received sample of `kind` named `name`, for messages.
    pub fn key_of(&self, kind: Kind, name: &str) -> String {
        self.key(kind, Some(name)).unwrap_or_default()
    }

    /// The next sample of `kind` (a poll when `timeout` is `None`), checked with the Rust
    /// decoder of its kind: a sample that does not decode is dropped and is [`Code::Decode`].
    pub fn receive_checked(
        &mut self,
        kind: Kind,
        timeout: Option<Duration>,
    ) -> Result<Taken<Received>, Error> {
        let info = check_kind(kind)?;
        let r = match self.receive(kind, timeout)? {
            Taken::Got(r) => r,
            other => return Ok(other),
        };
        (info.check)(&r.payload)
            .map_err(|e| decode_error(info.title, &self.key_of(kind, &r.name), &e))?;
        Ok(Taken::Got(r))
    }

    /// Puts the encoded message `bytes` of `kind` (one flight code or an operator sends) on
    /// its key, after checking them with the Rust decoder. A command goes on the key of its
    /// `sender_id`; a flight-code telemetry sample is refused (its key names its stream: see
    /// [`Self::declare_fsw`]).
    pub fn publish(&self, kind: Kind, bytes: &[u8]) -> Result<(), Error> {
        let info = check_kind(kind)?;
        if info.from_server {
            return Err(Error::new(
                Code::Usage,
                format!(
                    "the server publishes {} messages ({}); flight code does not",
                    info.title, info.key
                ),
            ));
        }
        if kind == kinds::FSW {
            return Err(Error::new(
                Code::Usage,
                format!(
                    "{} samples go on their stream's key ({}): publish them with \
                     flexdyn_fsw_declare and flexdyn_fsw_publish",
                    info.title, info.key
                ),
            ));
        }
        let invalid = |e: DecodeError| {
            Error::new(
                Code::Argument,
                format!("not a valid {} message (nothing sent): {e}", info.title),
            )
        };
        // The check is the decode; a command's key needs its decoded sender id.
        let key = if kind == kinds::COMMAND {
            let cmd = flexdyn_proto::decode_command(bytes).map_err(invalid)?;
            self.topics.cmd(cmd.sender_id)
        } else {
            (info.check)(bytes).map_err(invalid)?;
            self.key(kind, None)?
        };
        self.put(key, bytes.to_vec())
    }

    /// A header for this client's next command, stamped from `stamp`.
    fn header(&mut self, stamp: &Header) -> Header {
        let seq = self.seq;
        self.seq += 1;
        Header::new(stamp.spacecraft_id, stamp.tick, stamp.sim_time_ns, seq)
    }

    /// Publishes `kind` for `sender_id`, stamped from `stamp`.
    pub fn send(
        &mut self,
        sender_id: u32,
        stamp: &Header,
        kind: flexdyn_proto::CommandKind,
    ) -> Result<(), Error> {
        let cmd = CommandMsg {
            header: self.header(stamp),
            sender_id,
            kind,
        };
        self.put(self.topics.cmd(sender_id), encode(&cmd))
    }

    /// Puts `payload` on `key` (blocking under congestion: a command is never dropped here).
    fn put(&self, key: String, payload: Vec<u8>) -> Result<(), Error> {
        self.session
            .put(key.clone(), payload)
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(|e| Error::zenoh(&format!("cannot put on {key}"), e))
    }

    /// The next time message (the next tick), waiting up to `timeout` (`None`: at once,
    /// [`Taken::Empty`] when there is none; a wait says [`Taken::Ended`] once the run has
    /// ended and none is queued); it becomes [`Self::now`].
    pub fn take_time(&mut self, timeout: Option<Duration>) -> Result<Taken<TimeMsg>, Error> {
        let r = match self.receive(kinds::TIME, timeout)? {
            Taken::Got(r) => r,
            Taken::Empty => return Ok(Taken::Empty),
            Taken::Ended => return Ok(Taken::Ended),
        };
        let m = decode_as("time", &self.topics.time(), &r.payload, decode_time)?;
        self.last_time = Some(m);
        Ok(Taken::Got(m))
    }

    /// The newest time message received, after taking every one queued (`None` before the
    /// first). Never waits.
    pub fn now(&mut self) -> Result<Option<TimeMsg>, Error> {
        while let Taken::Got(_) = self.take_time(None)? {}
        Ok(self.last_time)
    }

    /// Publishes an operator command (pause, resume, run `ticks` ticks) on
    /// `flexdyn/<sc>/operator`, stamped from `stamp` (its spacecraft id must be the server's).
    pub fn send_operator(
        &mut self,
        stamp: &Header,
        action: OperatorAction,
        ticks: u64,
    ) -> Result<(), Error> {
        let msg = OperatorMsg::new(self.header(stamp), action, ticks);
        self.put(self.topics.operator(), encode(&msg))
    }

    /// What the server runs: the reply of `flexdyn/<sc>/config`, waiting up to `timeout`.
    fn vehicle(&self, timeout: Duration) -> Result<Vehicle, Error> {
        Vehicle::query(&self.session, &self.topics, timeout).map_err(|e| {
            use flexdyn_proto::client::vehicle::VehicleError as V;
            let code = match e {
                V::NoAnswer { .. } => Code::Timeout,
                V::Zenoh { .. } => Code::Zenoh,
                _ => Code::Config,
            };
            Error::new(code, e.to_string())
        })
    }

    /// Declares the flight code's telemetry stream `stream`: asks the server's configuration (up
    /// to `timeout`) for its `[[fsw_streams]]` entry and declares the publisher of
    /// `flexdyn/<sc>/fsw/<stream>`. The stream is independent of this client afterwards.
    pub fn declare_fsw(&self, stream: &str, timeout: Duration) -> Result<FswStream, Error> {
        let vehicle = self.vehicle(timeout)?;
        Ok(FswStream::declare(
            &self.session,
            &self.topics,
            &vehicle,
            stream,
        )?)
    }

    /// Joins a lockstep run as `sender_id`: asks the server's configuration (up to `timeout`),
    /// subscribes to the telemetry its ticks are assembled from, declares the command
    /// publisher, then the token.
    pub fn join(&mut self, sender_id: u32, timeout: Duration) -> Result<(), Error> {
        self.lockstep = None;
        let vehicle = self.vehicle(timeout)?;
        let schedule = vehicle
            .config()
            .and_then(|cfg| SensorSchedule::from_config(&cfg))
            .map_err(|e| Error::new(Code::Config, e.to_string()))?;
        let names = KINDS
            .iter()
            .map(|k| {
                k.lockstep
                    .and_then(|section| schedule.names(section))
                    .unwrap_or_default()
                    .into_iter()
                    // Key chunks ([A-Za-z0-9_-]) hold no NUL.
                    .map(|n| CString::new(n).unwrap_or_default())
                    .collect()
            })
            .collect();
        let receiver = TickReceiver::declare(
            &self.session,
            &self.topics,
            schedule,
            LOCKSTEP_CAPACITY,
            SENSOR_TIMEOUT,
        )
        .map_err(|e| {
            Error::zenoh(
                &format!(
                    "cannot subscribe to the tick's telemetry under {}",
                    self.topics.telemetry_wildcard()
                ),
                e,
            )
        })?;
        let cmd_key = self.topics.cmd(sender_id);
        let declared = declared_key(&self.session, cmd_key.clone())
            .map_err(|e| Error::zenoh(&format!("cannot declare {cmd_key}"), e))?;
        let publisher = self
            .session
            .declare_publisher(declared)
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(|e| Error::zenoh(&format!("cannot declare {cmd_key}"), e))?;
        let token_key = self.topics.participant(sender_id);
        let token = self
            .session
            .liveliness()
            .declare_token(token_key.clone())
            .wait()
            .map_err(|e| Error::zenoh(&format!("cannot declare the token {token_key}"), e))?;
        self.lockstep = Some(Lockstep {
            sender_id,
            receiver,
            publisher,
            _token: token,
            names,
            held: None,
            answered: false,
        });
        Ok(())
    }

    /// Leaves the lockstep run (drops the token and the subscription).
    pub fn leave(&mut self) {
        self.lockstep = None;
    }

    fn not_participant() -> Error {
        Error::new(
            Code::Usage,
            "not a lockstep participant (call flexdyn_lockstep_join first)",
        )
    }

    fn lockstep(&mut self) -> Result<&mut Lockstep, Error> {
        self.lockstep.as_mut().ok_or_else(Self::not_participant)
    }

    /// The next complete tick, waiting up to `timeout`; it is held until the next call.
    /// [`Taken::Ended`] (nothing held) once the run has ended and no tick is queued; never
    /// [`Taken::Empty`] (a timeout is [`Code::Timeout`]).
    pub fn wait_tick(&mut self, timeout: Duration) -> Result<Taken<&Tick>, Error> {
        let telemetry = self.topics.telemetry_wildcard();
        let Self {
            run_end, lockstep, ..
        } = self;
        let ls = lockstep.as_mut().ok_or_else(Self::not_participant)?;
        ls.held = None;
        let receiver = &mut ls.receiver;
        let waited = Self::wait_sliced(run_end, timeout, |slice| {
            receiver.recv_timeout(slice).map_err(|e| {
                Error::new(
                    Code::Closed,
                    format!("the telemetry subscription ended: {e}"),
                )
            })
        })?;
        match waited {
            Taken::Got(tick) => {
                ls.answered = false;
                Ok(Taken::Got(ls.held.insert(tick)))
            }
            Taken::Ended => Ok(Taken::Ended),
            Taken::Empty => Err(Error::new(
                Code::Timeout,
                format!("no tick on {telemetry} within {} ms", timeout.as_millis()),
            )),
        }
    }

    /// The names of the joined run's sensors of `kind`, in configuration order (none before a
    /// join, or for a kind a tick does not carry).
    pub fn sensor_names(&self, kind: Kind) -> &[CString] {
        match &self.lockstep {
            Some(ls) => ls.names.get(kind).map_or(&[], Vec::as_slice),
            None => &[],
        }
    }

    /// The held tick's encoded sample of sensor `index` of `kind`.
    pub fn held_sample(&mut self, kind: Kind, index: usize) -> Result<Vec<u8>, Error> {
        let info = check_kind(kind)?;
        let Some(section) = info.lockstep else {
            return Err(Error::new(
                Code::Argument,
                format!("a lockstep tick carries no {} messages", info.title),
            ));
        };
        let tick = self.held()?;
        match tick.sample_bytes(section, index) {
            Some(Some(bytes)) => Ok(bytes),
            Some(None) => Err(Error::new(
                Code::Absent,
                format!(
                    "{} {index} has no sample at tick {} (not due, or lost)",
                    info.title,
                    tick.tick()
                ),
            )),
            None => Err(Error::new(
                Code::Argument,
                format!(
                    "{} index {index}: the run has {} of them ([[{section}]])",
                    info.title,
                    self.sensor_names(kind).len()
                ),
            )),
        }
    }

    /// The held tick.
    pub fn held(&mut self) -> Result<&Tick, Error> {
        self.lockstep()?.held.as_ref().ok_or_else(|| {
            Error::new(
                Code::Usage,
                "no tick held (call flexdyn_lockstep_wait first)",
            )
        })
    }

    /// The one answer to the held tick.
    pub fn answer(&mut self, kind: flexdyn_proto::CommandKind) -> Result<(), Error> {
        let stamp = {
            let ls = self.lockstep()?;
            let Some(tick) = ls.held.as_ref() else {
                return Err(Error::new(
                    Code::Usage,
                    "no tick held to answer (call flexdyn_lockstep_wait first)",
                ));
            };
            if ls.answered {
                return Err(Error::new(
                    Code::Usage,
                    format!(
                        "tick {} was answered already (one answer per tick)",
                        tick.tick()
                    ),
                ));
            }
            tick.state.header
        };
        let header = self.header(&stamp);
        let ls = self.lockstep()?;
        let cmd = CommandMsg {
            header,
            sender_id: ls.sender_id,
            kind,
        };
        ls.publisher
            .put(encode(&cmd))
            .wait()
            .map_err(|e| Error::zenoh(&format!("cannot put on {}", ls.publisher.key_expr()), e))?;
        ls.answered = true;
        Ok(())
    }
}

/// The decoders of the messages a C program receives, by kind.
pub fn decode_state_bytes(key: &str, b: &[u8]) -> Result<StateMsg, Error> {
    decode_as("state", key, b, decode_state)
}

/// See [`decode_state_bytes`].
pub fn decode_imu_bytes(key: &str, b: &[u8]) -> Result<ImuMsg, Error> {
    decode_as("IMU", key, b, decode_imu)
}

/// See [`decode_state_bytes`].
pub fn decode_star_tracker_bytes(key: &str, b: &[u8]) -> Result<StarTrackerMsg, Error> {
    decode_as("star tracker", key, b, decode_star_tracker)
}

/// See [`decode_state_bytes`].
pub fn decode_status_bytes(key: &str, b: &[u8]) -> Result<StatusMsg, Error> {
    decode_as("status", key, b, decode_status)
}
