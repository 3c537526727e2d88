//! The library in safe Rust: a Zenoh session with the subscriptions, commands and lockstep
//! participant of `flexdyn_client.h`. [`crate::ffi`] only turns C pointers into these calls.
//!
//! Samples are queued by Zenoh's threads in ring channels and taken only when the caller asks
//! (poll or wait), so no user code ever runs on a Zenoh thread.

use std::ffi::CString;
use std::path::PathBuf;
use std::time::Duration;

use flexdyn_proto::client::lockstep::{SensorSchedule, Tick, TickReceiver};
use flexdyn_proto::client::transport::{zenoh_config, Role, ZenohArgs};
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

/// The spacecraft id of the keys when the options name none.
pub const DEFAULT_SC_ID: &str = "sc1";

/// How long a lockstep tick waits for a due sensor sample after its state before it is handed
/// out without it. In lockstep the server publishes a tick's samples before its state on one
/// subscriber, so this only matters when a sample is lost.
const SENSOR_TIMEOUT: Duration = Duration::from_secs(1);

/// Samples kept by the lockstep telemetry subscriber (at most one tick is in flight).
const LOCKSTEP_CAPACITY: usize = 256;

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
    imu_names: Vec<CString>,
    star_tracker_names: Vec<CString>,
    held: Option<Tick>,
    answered: bool,
}

/// An open session and what it declared.
pub struct Client {
    session: Session,
    topics: Topics,
    state: Option<Ring>,
    imu: Option<Ring>,
    star_tracker: Option<Ring>,
    status: Option<Ring>,
    time: Option<Ring>,
    /// The newest time message taken from the `time` subscription.
    last_time: Option<TimeMsg>,
    lockstep: Option<Lockstep>,
    /// The next command's `header.seq` (one counter for every command of this client).
    seq: u64,
}

/// Which subscription a poll or wait reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `flexdyn/<sc>/tlm/state`.
    State,
    /// `flexdyn/<sc>/tlm/imu/<name>`.
    Imu,
    /// `flexdyn/<sc>/tlm/st/<name>`.
    StarTracker,
    /// `flexdyn/<sc>/status`.
    Status,
    /// `flexdyn/<sc>/tlm/time`.
    Time,
}

impl Kind {
    fn what(self) -> &'static str {
        match self {
            Kind::State => "state",
            Kind::Imu => "IMU",
            Kind::StarTracker => "star tracker",
            Kind::Status => "status",
            Kind::Time => "time",
        }
    }
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
        Ok(Self {
            session,
            topics,
            state: None,
            imu: None,
            star_tracker: None,
            status: None,
            time: None,
            last_time: None,
            lockstep: None,
            seq: 0,
        })
    }

    /// Undeclares everything and closes the session.
    pub fn close(self) -> Result<(), Error> {
        let Self {
            session,
            state,
            imu,
            star_tracker,
            status,
            time,
            lockstep,
            ..
        } = self;
        drop((state, imu, star_tracker, status, time, lockstep));
        session
            .close()
            .wait()
            .map_err(|e| Error::zenoh("cannot close the Zenoh session", e))
    }

    fn slot(&mut self, kind: Kind) -> &mut Option<Ring> {
        match kind {
            Kind::State => &mut self.state,
            Kind::Imu => &mut self.imu,
            Kind::StarTracker => &mut self.star_tracker,
            Kind::Status => &mut self.status,
            Kind::Time => &mut self.time,
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
        let bad_name = |e| Error::new(Code::Argument, format!("{} name: {e}", kind.what()));
        let key = match (kind, name) {
            (Kind::State, _) => self.topics.state().to_owned(),
            (Kind::Status, _) => self.topics.status().to_owned(),
            (Kind::Time, _) => self.topics.time(),
            (Kind::Imu, Some(n)) => self.topics.imu(n).map_err(bad_name)?,
            (Kind::Imu, None) => self.topics.imu_wildcard(),
            (Kind::StarTracker, Some(n)) => self.topics.star_tracker(n).map_err(bad_name)?,
            (Kind::StarTracker, None) => {
                flexdyn_proto::star_tracker_wildcard_key(self.topics.sc_id())
                    .map_err(|e| Error::new(Code::Argument, e.to_string()))?
            }
        };
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

    /// The next sample of `kind`: at once (`timeout` `None`: `Ok(None)` when there is none) or
    /// waiting up to `timeout` ([`Code::Timeout`]).
    pub fn receive(
        &mut self,
        kind: Kind,
        timeout: Option<Duration>,
    ) -> Result<Option<Received>, Error> {
        let Some(sub) = self.slot(kind).as_ref() else {
            return Err(Error::new(
                Code::Usage,
                format!(
                    "not subscribed to {} (call the subscribe function first)",
                    kind.what()
                ),
            ));
        };
        let closed = |e| {
            Error::new(
                Code::Closed,
                format!("the {} subscription ended: {e}", kind.what()),
            )
        };
        let sample = match timeout {
            None => sub.try_recv().map_err(closed)?,
            Some(t) => match sub.recv_timeout(t).map_err(closed)? {
                Some(s) => Some(s),
                None => {
                    return Err(Error::new(
                        Code::Timeout,
                        format!(
                            "no {} sample on {} within {} ms",
                            kind.what(),
                            sub.key_expr(),
                            t.as_millis()
                        ),
                    ))
                }
            },
        };
        Ok(sample.map(|s| Received {
            name: s
                .key_expr()
                .as_str()
                .rsplit('/')
                .next()
                .unwrap_or_default()
                .to_owned(),
            payload: s.payload().to_bytes().into_owned(),
        }))
    }

    /// The key of a received sample of `kind` named `name`, for messages.
    pub fn key_of(&self, kind: Kind, name: &str) -> String {
        match kind {
            Kind::State => self.topics.state().to_owned(),
            Kind::Status => self.topics.status().to_owned(),
            Kind::Time => self.topics.time(),
            Kind::Imu => self.topics.imu(name).unwrap_or_default(),
            Kind::StarTracker => self.topics.star_tracker(name).unwrap_or_default(),
        }
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
    /// `Ok(None)` when there is none); it becomes [`Self::now`].
    pub fn take_time(&mut self, timeout: Option<Duration>) -> Result<Option<TimeMsg>, Error> {
        let Some(r) = self.receive(Kind::Time, timeout)? else {
            return Ok(None);
        };
        let m = decode_as("time", &self.topics.time(), &r.payload, decode_time)?;
        self.last_time = Some(m);
        Ok(Some(m))
    }

    /// The newest time message received, after taking every one queued (`None` before the
    /// first). Never waits.
    pub fn now(&mut self) -> Result<Option<TimeMsg>, Error> {
        while self.take_time(None)?.is_some() {}
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

    /// Joins a lockstep run as `sender_id`: asks the server's configuration (up to `timeout`),
    /// subscribes to all telemetry, declares the command publisher, then the token.
    pub fn join(&mut self, sender_id: u32, timeout: Duration) -> Result<(), Error> {
        self.lockstep = None;
        let vehicle = Vehicle::query(&self.session, &self.topics, timeout).map_err(|e| {
            use flexdyn_proto::client::vehicle::VehicleError as V;
            let code = match e {
                V::NoAnswer { .. } => Code::Timeout,
                V::Zenoh { .. } => Code::Zenoh,
                _ => Code::Config,
            };
            Error::new(code, e.to_string())
        })?;
        let schedule = vehicle
            .config()
            .and_then(|cfg| SensorSchedule::from_config(&cfg))
            .map_err(|e| Error::new(Code::Config, e.to_string()))?;
        let c_names = |names: Vec<&str>| -> Vec<CString> {
            // Key chunks ([A-Za-z0-9_-]) hold no NUL.
            names
                .into_iter()
                .map(|n| CString::new(n).unwrap_or_default())
                .collect()
        };
        let imu_names = c_names(schedule.imus().collect());
        let star_tracker_names = c_names(schedule.star_trackers().map(|(n, _)| n).collect());
        let receiver = TickReceiver::declare(
            &self.session,
            &self.topics,
            schedule,
            LOCKSTEP_CAPACITY,
            SENSOR_TIMEOUT,
        )
        .map_err(|e| {
            Error::zenoh(
                &format!("cannot subscribe to {}", self.topics.telemetry_wildcard()),
                e,
            )
        })?;
        let cmd_key = self.topics.cmd(sender_id);
        let publisher = self
            .session
            .declare_publisher(cmd_key.clone())
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
            imu_names,
            star_tracker_names,
            held: None,
            answered: false,
        });
        Ok(())
    }

    /// Leaves the lockstep run (drops the token and the subscription).
    pub fn leave(&mut self) {
        self.lockstep = None;
    }

    fn lockstep(&mut self) -> Result<&mut Lockstep, Error> {
        self.lockstep.as_mut().ok_or_else(|| {
            Error::new(
                Code::Usage,
                "not a lockstep participant (call flexdyn_lockstep_join first)",
            )
        })
    }

    /// The next complete tick, waiting up to `timeout`; it is held until the next call.
    pub fn wait_tick(&mut self, timeout: Duration) -> Result<&Tick, Error> {
        let telemetry = self.topics.telemetry_wildcard();
        let ls = self.lockstep()?;
        ls.held = None;
        let tick = ls
            .receiver
            .recv_timeout(timeout)
            .map_err(|e| {
                Error::new(
                    Code::Closed,
                    format!("the telemetry subscription ended: {e}"),
                )
            })?
            .ok_or_else(|| {
                Error::new(
                    Code::Timeout,
                    format!("no tick on {telemetry} within {} ms", timeout.as_millis()),
                )
            })?;
        ls.answered = false;
        Ok(ls.held.insert(tick))
    }

    /// The sensor names of the joined run (IMUs, then star trackers).
    pub fn sensor_names(&self) -> (&[CString], &[CString]) {
        match &self.lockstep {
            Some(ls) => (&ls.imu_names, &ls.star_tracker_names),
            None => (&[], &[]),
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
