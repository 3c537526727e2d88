//! Publishing one frame's telemetry: its IMU samples, the star-tracker samples due at its tick,
//! then its StateMsg, in that order (a controller that waits for the state finds the sensor
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
//! ([`crate::transport::frame_stamp_ns`]).

use std::sync::atomic::Ordering;
use std::sync::Arc;

use flexdyn_proto::encode_into;
use zenoh::pubsub::Publisher;
use zenoh::Wait;

use super::shared::{Frame, Shared};
use crate::sinks::recorder::{RecordItem, RecordTx};

/// Which sensor a payload comes from: its index among the IMUs or the star trackers (config
/// order).
#[derive(Clone, Copy)]
enum Sensor {
    Imu(usize),
    StarTracker(usize),
}

/// Encodes each sensor sample of `frame` into `buf`, in publication order (the IMUs, then the
/// star trackers due at its tick), and hands it to `each`. `st_every` gives a tracker's update
/// period in frames (`None`: no such tracker, skipped); a tracker's `seq` counts its messages,
/// +1 per update.
fn for_each_sensor_payload(
    frame: &Frame,
    st_every: impl Fn(usize) -> Option<u64>,
    buf: &mut Vec<u8>,
    mut each: impl FnMut(Sensor, &[u8]),
) {
    let header = frame.state.header;
    for (i, sample) in frame.imu.iter().enumerate() {
        encode_into(&sample.to_msg(header), buf);
        each(Sensor::Imu(i), buf);
    }
    for (i, sample) in &frame.star_trackers {
        let Some(every) = st_every(*i) else {
            continue;
        };
        let h = flexdyn_proto::Header {
            seq: header.tick / every,
            ..header
        };
        encode_into(&sample.to_msg(h), buf);
        each(Sensor::StarTracker(*i), buf);
    }
}

/// The recorder's queue and the keys it files payloads under.
#[derive(Clone)]
pub struct Recording {
    tx: RecordTx,
    state: Arc<str>,
    /// `flexdyn/<sc>/status`.
    pub status: Arc<str>,
    imus: Vec<Arc<str>>,
    sts: Vec<Arc<str>>,
    st_every: Vec<u64>,
}

impl Recording {
    /// The key a sensor's payloads are filed under (`None`: no such sensor).
    fn sensor_key(&self, sensor: Sensor) -> Option<&Arc<str>> {
        match sensor {
            Sensor::Imu(i) => self.imus.get(i),
            Sensor::StarTracker(i) => self.sts.get(i),
        }
    }

    /// Queues an already published `frame` (real time, `handoff = "direct"`: the physics thread
    /// published it; the telemetry thread encodes it again for the file, in `buf`).
    pub fn record_frame(&self, frame: &Frame, buf: &mut Vec<u8>) {
        let stamp = Some(frame.boundary_unix_ns);
        let st_every = |i: usize| self.st_every.get(i).copied();
        for_each_sensor_payload(frame, st_every, buf, |sensor, payload| {
            if let Some(key) = self.sensor_key(sensor) {
                self.submit(key, payload, stamp);
            }
        });
        encode_into(&frame.state, buf);
        self.submit(&self.state, buf, stamp);
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

/// The publishers of one spacecraft's per-frame telemetry, with their encode buffers.
pub struct FramePublisher {
    /// `flexdyn/<sc>/tlm/state` (shared with the lockstep presence wait).
    pub state_pub: Arc<Publisher<'static>>,
    /// `flexdyn/<sc>/tlm/imu/<name>`, in IMU config order.
    pub imu_pubs: Vec<Publisher<'static>>,
    /// `flexdyn/<sc>/tlm/st/<name>` with the tracker's update period in frames, in
    /// star-tracker config order.
    pub st_pubs: Vec<(Publisher<'static>, u64)>,
    state_buf: Vec<u8>,
    sensor_buf: Vec<u8>,
}

impl FramePublisher {
    /// Publishers for a frame; the buffers are sized once here.
    pub fn new(
        state_pub: Arc<Publisher<'static>>,
        imu_pubs: Vec<Publisher<'static>>,
        st_pubs: Vec<(Publisher<'static>, u64)>,
    ) -> Self {
        Self {
            state_pub,
            imu_pubs,
            st_pubs,
            state_buf: Vec::with_capacity(4096),
            sensor_buf: Vec::with_capacity(256),
        }
    }

    /// The recorder's view of these publishers' keys.
    pub fn recording(&self, tx: RecordTx, status: &Publisher<'static>) -> Recording {
        let key = |p: &Publisher<'static>| -> Arc<str> { p.key_expr().as_str().into() };
        Recording {
            tx,
            state: key(&self.state_pub),
            status: key(status),
            imus: self.imu_pubs.iter().map(key).collect(),
            sts: self.st_pubs.iter().map(|(p, _)| key(p)).collect(),
            st_every: self.st_pubs.iter().map(|(_, every)| *every).collect(),
        }
    }

    fn count_error(shared: &Shared, what: &str, e: &dyn std::fmt::Display) {
        let n = shared.publish_errors.fetch_add(1, Ordering::Relaxed) + 1;
        if n.is_power_of_two() {
            tracing::warn!(error = %e, errors = n, "cannot publish {what}");
        }
    }

    /// Encodes and publishes `frame` (sensors first, then the state), queueing each payload
    /// for `rec` too. Counts the state in `shared.published`, failures in
    /// `shared.publish_errors`, and notes the frame's command bookkeeping.
    pub fn publish(&mut self, frame: &Frame, shared: &Shared, rec: Option<&Recording>) {
        let stamp = frame.boundary_unix_ns.to_le_bytes();
        let (imu_pubs, st_pubs) = (&self.imu_pubs, &self.st_pubs);
        let st_every = |i: usize| st_pubs.get(i).map(|(_, every)| *every);
        for_each_sensor_payload(frame, st_every, &mut self.sensor_buf, |sensor, payload| {
            let (publisher, what) = match sensor {
                Sensor::Imu(i) => (imu_pubs.get(i), "an IMU sample"),
                Sensor::StarTracker(i) => (st_pubs.get(i).map(|(p, _)| p), "a star-tracker sample"),
            };
            let Some(publisher) = publisher else {
                return;
            };
            if let Some((r, key)) = rec.and_then(|r| Some((r, r.sensor_key(sensor)?))) {
                r.submit(key, payload, Some(frame.boundary_unix_ns));
            }
            if let Err(e) = publisher.put(payload).attachment(stamp).wait() {
                Self::count_error(shared, what, &e);
            }
        });
        encode_into(&frame.state, &mut self.state_buf);
        shared.set_last_command(&frame.command);
        match self
            .state_pub
            .put(self.state_buf.as_slice())
            .attachment(stamp)
            .wait()
        {
            Ok(()) => {
                shared.published.fetch_add(1, Ordering::Relaxed);
            }
            Err(e) => Self::count_error(shared, "state", &e),
        }
        // Queued for the recorder after the state is out: the subscriber first.
        if let Some(r) = rec {
            r.submit(&r.state, &self.state_buf, Some(frame.boundary_unix_ns));
        }
    }
}
