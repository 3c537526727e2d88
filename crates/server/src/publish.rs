//! Publishing one frame's telemetry: its TimeMsg, then the messages of the sensors sampled at
//! its tick (in publication order: [`flexdyn_sensors::KINDS`], then config order), then its
//! StateMsg, then (when due) its EnvironmentMsg, then its fault events (FaultEventMsg), in that
//! order (a controller that waits for the state finds the sensor
//! samples of the same tick already delivered).
//!
//! Which thread calls [`FramePublisher::publish`] is the `server.handoff` setting:
//! - `direct` (what the default `auto` gives, except in real time with `--record`): the thread
//!   that finishes the frame. In real time that is the physics
//!   thread, at the frame boundary, with `CongestionControl::Drop`, so the put never waits for
//!   the network (a full Zenoh queue drops the sample, counted as a publish error); in lockstep
//!   it is the Zenoh thread that delivered the tick's last answer and stepped the frame
//!   ([`super::lockstep`]).
//! - `thread`: the telemetry thread, fed through the frame pool (the previous design; batch
//!   always uses it, since there it overlaps publishing with the next frames' physics).
//!
//! Each sample carries the 8-byte frame-boundary stamp as its attachment
//! ([`flexdyn_proto::client::transport::frame_stamp_ns`]).

use std::fmt;
use std::sync::atomic::Ordering;
use std::sync::Arc;

use flexdyn_proto::encode_into;
use zenoh::pubsub::Publisher;
use zenoh::Wait;

use super::shared::{Frame, Shared};
use flexdyn_sensors::SensorKind;
use flexdyn_sinks::recorder::{RecordItem, RecordTx};

/// Hands each sensor message of `frame` to `each` with the sensor's index in the bank, in
/// publication order.
fn for_each_sensor_payload(frame: &Frame, mut each: impl FnMut(usize, &[u8])) {
    for &i in &frame.sensors_sampled {
        if let Some(payload) = frame.sensor_payloads.get(i) {
            each(i, payload);
        }
    }
}

/// The recorder's queue and the keys it files payloads under.
#[derive(Clone)]
pub struct Recording {
    tx: RecordTx,
    time: Arc<str>,
    state: Arc<str>,
    /// `flexdyn/<sc>/tlm/env`, when the environment message is on.
    environment: Option<Arc<str>>,
    /// `flexdyn/<sc>/tlm/fault`, when fault events are published.
    fault_events: Option<Arc<str>>,
    /// `flexdyn/<sc>/status`.
    pub status: Arc<str>,
    /// Per sensor of the bank, its key.
    sensors: Vec<Arc<str>>,
}

impl Recording {
    /// Queues an already published `frame` (real time, `handoff = "direct"`: the physics thread
    /// published it; the telemetry thread files the sensor payloads as they are and encodes the
    /// state again for the file, in `buf`).
    pub fn record_frame(&self, frame: &Frame, buf: &mut Vec<u8>) {
        let stamp = Some(frame.boundary_unix_ns);
        encode_into(&frame.time, buf);
        self.submit(&self.time, buf, stamp);
        for_each_sensor_payload(frame, |i, payload| {
            if let Some(key) = self.sensors.get(i) {
                self.submit(key, payload, stamp);
            }
        });
        encode_into(&frame.state, buf);
        self.submit(&self.state, buf, stamp);
        if let (Some(env), Some(key)) = (&frame.environment, &self.environment) {
            encode_into(env, buf);
            self.submit(key, buf, stamp);
        }
        if let Some(key) = &self.fault_events {
            for ev in &frame.fault_events {
                encode_into(ev, buf);
                self.submit(key, buf, stamp);
            }
        }
    }

    /// Queues `payload` under `key` (see [`RecordTx::submit`] for lossless versus lossy).
    pub fn submit(&self, key: &Arc<str>, payload: &[u8], stamp_ns: Option<u64>) {
        self.tx.submit(RecordItem {
            key: key.clone(),
            payload: payload.to_vec(),
            publish_time_ns: stamp_ns,
        });
    }
}

/// "an IMU sample", without allocating.
struct SampleOf(&'static SensorKind);

impl fmt::Display for SampleOf {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} sample", self.0.a_noun)
    }
}

/// The publishers of one spacecraft's per-frame telemetry, with their encode buffer.
pub struct FramePublisher {
    /// `flexdyn/<sc>/tlm/time`.
    pub time_pub: Publisher<'static>,
    time_buf: Vec<u8>,
    /// `flexdyn/<sc>/tlm/state` (shared with the lockstep presence wait).
    pub state_pub: Arc<Publisher<'static>>,
    /// Per sensor of the bank: its kind and its publisher (`flexdyn/<sc>/tlm/<kind>/<name>`).
    pub sensor_pubs: Vec<(&'static SensorKind, Publisher<'static>)>,
    state_buf: Vec<u8>,
    /// `flexdyn/<sc>/tlm/env` (`[environment] telemetry_rate_hz` set), with its buffer.
    pub environment_pub: Option<Publisher<'static>>,
    environment_buf: Vec<u8>,
    /// `flexdyn/<sc>/tlm/fault` (fault activations and clearances), with its buffer.
    pub fault_pub: Option<Publisher<'static>>,
    fault_buf: Vec<u8>,
}

impl FramePublisher {
    /// Publishers for a frame; the buffer is sized once here.
    pub fn new(
        time_pub: Publisher<'static>,
        state_pub: Arc<Publisher<'static>>,
        sensor_pubs: Vec<(&'static SensorKind, Publisher<'static>)>,
    ) -> Self {
        Self {
            time_pub,
            time_buf: Vec::with_capacity(flexdyn_proto::TIME_LEN),
            state_pub,
            sensor_pubs,
            state_buf: Vec::with_capacity(4096),
            environment_pub: None,
            environment_buf: Vec::with_capacity(flexdyn_proto::ENVIRONMENT_LEN),
            fault_pub: None,
            fault_buf: Vec::with_capacity(flexdyn_proto::FAULT_EVENT_LEN),
        }
    }

    /// The recorder's view of these publishers' keys.
    pub fn recording(&self, tx: RecordTx, status: &Publisher<'static>) -> Recording {
        let key = |p: &Publisher<'static>| -> Arc<str> { p.key_expr().as_str().into() };
        Recording {
            tx,
            time: key(&self.time_pub),
            state: key(&self.state_pub),
            environment: self.environment_pub.as_ref().map(key),
            fault_events: self.fault_pub.as_ref().map(key),
            status: key(status),
            sensors: self.sensor_pubs.iter().map(|(_, p)| key(p)).collect(),
        }
    }

    fn count_error(shared: &Shared, what: &dyn fmt::Display, e: &dyn fmt::Display) {
        let n = shared.publish_errors.fetch_add(1, Ordering::Relaxed) + 1;
        if n.is_power_of_two() {
            tracing::warn!(error = %e, errors = n, "cannot publish {what}");
        }
    }

    /// Encodes and publishes `frame` (its time message, its sensors, then the state), queueing
    /// each payload
    /// for `rec` too. Counts the state in `shared.published`, failures in
    /// `shared.publish_errors`, and notes the frame's command bookkeeping, its active faults
    /// and its fault events (for the log: [`super::fault_log`]).
    pub fn publish(&mut self, frame: &Frame, shared: &Shared, rec: Option<&Recording>) {
        let stamp = frame.boundary_unix_ns.to_le_bytes();
        encode_into(&frame.time, &mut self.time_buf);
        if let Some(r) = rec {
            r.submit(&r.time, &self.time_buf, Some(frame.boundary_unix_ns));
        }
        if let Err(e) = self
            .time_pub
            .put(self.time_buf.as_slice())
            .attachment(stamp)
            .wait()
        {
            Self::count_error(shared, &"time", &e);
        }
        let sensor_pubs = &self.sensor_pubs;
        for_each_sensor_payload(frame, |i, payload| {
            let Some((kind, publisher)) = sensor_pubs.get(i) else {
                return;
            };
            if let Some((r, key)) = rec.and_then(|r| Some((r, r.sensors.get(i)?))) {
                r.submit(key, payload, Some(frame.boundary_unix_ns));
            }
            if let Err(e) = publisher.put(payload).attachment(stamp).wait() {
                Self::count_error(shared, &SampleOf(kind), &e);
            }
        });
        encode_into(&frame.state, &mut self.state_buf);
        shared.set_last_command(&frame.command);
        shared.set_faults_active(frame.faults_active.0, &frame.faults_active.1);
        shared.fault_edges.note(&frame.fault_events);
        match self
            .state_pub
            .put(self.state_buf.as_slice())
            .attachment(stamp)
            .wait()
        {
            Ok(()) => {
                shared.published.fetch_add(1, Ordering::Relaxed);
            }
            Err(e) => Self::count_error(shared, &"state", &e),
        }
        // Queued for the recorder after the state is out: the subscriber first.
        if let Some(r) = rec {
            r.submit(&r.state, &self.state_buf, Some(frame.boundary_unix_ns));
        }
        if let (Some(env), Some(publisher)) = (&frame.environment, &self.environment_pub) {
            encode_into(env, &mut self.environment_buf);
            if let Err(e) = publisher
                .put(self.environment_buf.as_slice())
                .attachment(stamp)
                .wait()
            {
                Self::count_error(shared, &"environment", &e);
            }
            if let Some((r, key)) = rec.and_then(|r| Some((r, r.environment.as_ref()?))) {
                r.submit(key, &self.environment_buf, Some(frame.boundary_unix_ns));
            }
        }
        if let Some(publisher) = &self.fault_pub {
            for ev in &frame.fault_events {
                encode_into(ev, &mut self.fault_buf);
                if let Err(e) = publisher
                    .put(self.fault_buf.as_slice())
                    .attachment(stamp)
                    .wait()
                {
                    Self::count_error(shared, &"fault event", &e);
                }
                if let Some((r, key)) = rec.and_then(|r| Some((r, r.fault_events.as_ref()?))) {
                    r.submit(key, &self.fault_buf, Some(frame.boundary_unix_ns));
                }
            }
        }
    }
}
