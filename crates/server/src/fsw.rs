//! The flight code's own telemetry: the callback of `flexdyn/<sc>/fsw/*` (`FswMsg`,
//! protocol 10).
//!
//! A sample is checked against its stream's declaration in the configuration's
//! `[[fsw_streams]]` ([`FswStreamDecl::check`]) and, when it passes, handed to the recorder
//! exactly as it arrived. Nothing on this key reaches the physics: the callback runs on the
//! Zenoh thread, touches only the recorder's queue and a few atomics, and the physics thread
//! never waits for it.
//!
//! Refusals count in `rejected.fsw_refused` and are logged with their reason (rate-limited per
//! reason, as commands are):
//! - `malformed`, `bad_version`, `non_finite`: the sample does not decode;
//! - `wrong_spacecraft`: another vehicle's `header.spacecraft_id`;
//! - `unknown_stream`: the key names no declared stream;
//! - `future_tick`: stamped with a tick the server has not reached;
//! - `wrong_time`: `header.sim_time_ns` is not its tick's time (tick × frame period);
//! - `rate_bound`: not after the stream's last recorded tick (a stream records at most one
//!   sample per tick, so the frame rate bounds every stream, and a flood records nothing more);
//! - the declaration's reasons (`FswRefusal::reason`): an undeclared mode or event, a value
//!   count other than the declaration's, a NaN or infinite f64 value, a bool other than 0/1,
//!   COVARIANCE without ESTIMATE.
//!
//! An accepted sample is published again, unchanged, on its key to the other sessions connected
//! to the server (remote only, dropped if a tool's link is full), so the tools that connect to
//! the server (the monitor, `flexdyn view`, `flexdyn record`) hear what the server accepted; a
//! refused sample goes nowhere.
//!
//! In lockstep the flight code answers tick k after the server published it, so a sample
//! stamped k that arrives before the answer is recorded with tick k, and the recording of a
//! lockstep run is the same whenever it is repeated. The run's last tick is published for the
//! record and no answer to it is awaited, so whether a sample for it arrives before the run
//! closes is a race: a lockstep server neither records nor checks a sample of its spacecraft
//! stamped with its last tick (so it is not counted as refused either), and two runs'
//! recordings and final counts stay identical.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use flexdyn_proto::client::transport::declared_key;
use flexdyn_proto::view::view_fsw;
use flexdyn_proto::view::ViewError;
use flexdyn_proto::{decode_fsw, Topics};
use flexdyn_sinks::recorder::{RecordItem, RecordTx};
use flexdyn_vehicle::config::fsw::FswStreamDecl;
use zenoh::pubsub::Subscriber;
use zenoh::{Session, Wait};

use super::error::ServerError;
use super::reject_log::RejectLog;
use super::shared::Shared;

/// What the callback checks a sample against (public for `tests/server_alloc.rs`, which runs
/// it beside the frame path).
pub struct FswIntake {
    /// The declared streams, in configuration order.
    streams: Vec<FswStreamDecl>,
    /// The full key of each stream (`flexdyn/<sc>/fsw/<name>`), shared with the recorder.
    keys: Vec<Arc<str>>,
    /// Per stream: the last recorded tick + 1 (0: none yet).
    next_tick: Vec<AtomicU64>,
    /// The server's numeric spacecraft id.
    spacecraft_id: u32,
    /// \[ns\] the frame period: a tick's time is tick × frame_ns.
    frame_ns: u64,
    /// Lockstep: the run's last tick, whose samples are not recorded (module docs).
    lockstep_last_tick: Option<u64>,
}

impl FswIntake {
    /// The intake of `streams` for the vehicle of `topics`; `lockstep_last_tick`: a lockstep
    /// run's last tick, if it has one. (The configuration validated the names, so their keys
    /// cannot fail.)
    pub fn new(
        topics: &Topics,
        streams: Vec<FswStreamDecl>,
        spacecraft_id: u32,
        frame_ns: u64,
        lockstep_last_tick: Option<u64>,
    ) -> Result<Self, ServerError> {
        let keys = streams
            .iter()
            .map(|s| flexdyn_proto::fsw_key(topics.sc_id(), &s.name).map(Arc::from))
            .collect::<Result<_, _>>()
            .map_err(|e| ServerError::Internal(format!("a [[fsw_streams]] key: {e}")))?;
        let next_tick = streams.iter().map(|_| AtomicU64::new(0)).collect();
        Ok(Self {
            streams,
            keys,
            next_tick,
            spacecraft_id,
            frame_ns,
            lockstep_last_tick,
        })
    }

    /// Checks a sample that arrived on `key` while the server's last tick is `server_tick`:
    /// the index of its stream (`None`: a lockstep run's last tick, not recorded), or the
    /// refusal's reason and what was wrong.
    pub fn check(
        &self,
        key: &str,
        bytes: &[u8],
        server_tick: u64,
    ) -> Result<Option<usize>, (&'static str, String)> {
        // Read in place: an accepted sample allocates nothing. A refused one is decoded
        // again for the decoder's message (the refusal path may allocate).
        let msg = view_fsw(bytes).map_err(|e| {
            let reason = match e {
                ViewError::UnknownVersion { .. } => "bad_version",
                ViewError::NonFinite => "non_finite",
                ViewError::Malformed => "malformed",
            };
            let detail = decode_fsw(bytes)
                .err()
                .map_or_else(|| format!("{e:?}"), |d| d.to_string());
            (reason, format!("flight-code telemetry on {key}: {detail}"))
        })?;
        let header = msg.header();
        if header.spacecraft_id != self.spacecraft_id {
            return Err((
                "wrong_spacecraft",
                format!(
                    "flight-code telemetry on {key} for spacecraft_id {}, not this server's {}",
                    header.spacecraft_id, self.spacecraft_id
                ),
            ));
        }
        // A lockstep run's last tick: neither checked further nor recorded (module docs).
        if self.lockstep_last_tick == Some(header.tick) {
            return Ok(None);
        }
        let Some(i) = self.keys.iter().position(|k| &**k == key) else {
            return Err((
                "unknown_stream",
                format!(
                    "{key} names no stream of the configuration's [[fsw_streams]] (declared: {})",
                    self.declared()
                ),
            ));
        };
        let stream = &self.streams[i];
        let tick = header.tick;
        if tick > server_tick {
            return Err((
                "future_tick",
                format!(
                    "stream `{}` sample for tick {tick}, but the server is at tick {server_tick}",
                    stream.name
                ),
            ));
        }
        let due_ns = tick.saturating_mul(self.frame_ns);
        if header.sim_time_ns != due_ns {
            return Err((
                "wrong_time",
                format!(
                    "stream `{}` sample for tick {tick} says sim_time_ns {}, but that tick is at \
                     {due_ns} ns",
                    stream.name, header.sim_time_ns
                ),
            ));
        }
        stream.check_view(&msg).map_err(|why| {
            (
                why.reason(),
                format!("stream `{}` sample for tick {tick}: {why}", stream.name),
            )
        })?;

        // At most one sample per tick: claim the tick, or refuse a repeat (or an older one).
        let next = &self.next_tick[i];
        let mut seen = next.load(Ordering::Acquire);
        loop {
            if tick < seen {
                return Err((
                    "rate_bound",
                    format!(
                        "stream `{}` sample for tick {tick}, but tick {} is already recorded (at \
                         most one sample per tick per stream)",
                        stream.name,
                        seen - 1
                    ),
                ));
            }
            match next.compare_exchange_weak(seen, tick + 1, Ordering::AcqRel, Ordering::Acquire) {
                Ok(_) => return Ok(Some(i)),
                Err(now) => seen = now,
            }
        }
    }

    /// The declared stream names, for an error message.
    fn declared(&self) -> String {
        if self.streams.is_empty() {
            return "none".to_owned();
        }
        self.streams
            .iter()
            .map(|s| format!("`{}`", s.name))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The recorder's key of stream `i`.
    pub fn key(&self, i: usize) -> &Arc<str> {
        &self.keys[i]
    }
}

/// Subscribes the telemetry callback to `flexdyn/<sc>/fsw/*`; dropping the subscriber stops it.
/// Accepted samples go to `record` (when recording) and count in `shared`'s `fsw_recorded`.
pub(super) async fn declare(
    session: &Session,
    topics: &Topics,
    intake: FswIntake,
    shared: Arc<Shared>,
    record: Option<RecordTx>,
) -> Result<Subscriber<()>, ServerError> {
    let log = Mutex::new(RejectLog::counted_in(
        "flight-code telemetry",
        "fsw_refused",
    ));
    let key = flexdyn_proto::fsw_wildcard_key(topics.sc_id())
        .map_err(|e| ServerError::Internal(format!("the fsw key: {e}")))?;
    // Each accepted sample goes out again to the other sessions connected to this one (the
    // monitor, `flexdyn view`, `flexdyn record`): peers do not route between the clients of a
    // server, so without this only the server would hear the flight code. Remote only (this
    // session's own subscriber must not hear it twice), and dropped rather than waited for
    // when a tool's link is full: a slow tool never holds this thread.
    // Each stream's key is declared, so Zenoh routes the samples that come in on it, and the
    // ones that go out again, by cached routes (`transport::declared_key`); the declarations
    // live in the publishers, which live in the callback.
    let mut republish = Vec::with_capacity(intake.streams.len());
    for k in &intake.keys {
        let declared = declared_key(session, k.to_string())
            .map_err(|e| ServerError::zenoh("declare the flight-code telemetry publisher", e))?;
        republish.push(
            session
                .declare_publisher(declared)
                .allowed_destination(zenoh::sample::Locality::Remote)
                .congestion_control(zenoh::qos::CongestionControl::Drop)
                .await
                .map_err(|e| {
                    ServerError::zenoh("declare the flight-code telemetry publisher", e)
                })?,
        );
    }
    let callback = move |sample: zenoh::sample::Sample| {
        let bytes = sample.payload().to_bytes();
        let server_tick = shared.tick.load(Ordering::Acquire);
        match intake.check(sample.key_expr().as_str(), &bytes, server_tick) {
            Ok(None) => {}
            Ok(Some(i)) => {
                shared.fsw_recorded.fetch_add(1, Ordering::Relaxed);
                // The payload's buffer is shared, not copied.
                let _ = republish[i].put(sample.payload().clone()).wait();
                if let Some(rec) = &record {
                    rec.submit(RecordItem {
                        key: intake.key(i).clone(),
                        payload: bytes.to_vec(),
                        publish_time_ns: flexdyn_proto::client::transport::frame_stamp_ns(&sample),
                    });
                }
            }
            Err((reason, detail)) => {
                shared.reject_fsw();
                log.lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .record(reason, None, 1, &detail);
            }
        }
    };
    session
        .declare_subscriber(key)
        .callback(callback)
        .await
        .map_err(|e| ServerError::zenoh("declare the flight-code telemetry subscriber", e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::{encode, fsw_flags, FswMsg, Header};
    use flexdyn_vehicle::config::SimConfig;

    const FRAME_NS: u64 = 10_000_000;

    fn intake() -> FswIntake {
        let toml = format!(
            "{}\n[[fsw_streams]]\nname = \"acs\"\nmodes = [\"detumble\", \"point\"]\n\
             events = [{{ name = \"gyro_fault\", severity = \"error\" }}]\n\
             values = [{{ name = \"h_b_nms\", type = \"f64\", len = 3 }}, \
             {{ name = \"ok\", type = \"bool\" }}]\n",
            flexdyn_vehicle::config::DEFAULT_CONFIG_TOML
        );
        let cfg = SimConfig::from_toml_str(&toml).expect("the test dictionary");
        let topics = Topics::new("sc1").unwrap();
        FswIntake::new(&topics, cfg.fsw_streams.clone(), 1, FRAME_NS, Some(100)).unwrap()
    }

    fn sample(tick: u64) -> FswMsg {
        FswMsg {
            header: Header::new(1, tick, tick * FRAME_NS, tick),
            flags: fsw_flags::MODE,
            mode: 1,
            values: vec![0.5f64.to_bits(), 0, (-1.0f64).to_bits(), 1],
            ..FswMsg::default()
        }
    }

    fn reason(r: Result<Option<usize>, (&'static str, String)>) -> &'static str {
        match r {
            Ok(Some(_)) => "accepted",
            Ok(None) => "last_tick",
            Err((why, _)) => why,
        }
    }

    #[test]
    fn one_sample_per_tick_per_stream_and_never_ahead_of_the_server() {
        let t = intake();
        let key = "flexdyn/sc1/fsw/acs";
        assert_eq!(reason(t.check(key, &encode(&sample(3)), 5)), "accepted");
        // The same tick again, and an older one: the rate bound.
        assert_eq!(reason(t.check(key, &encode(&sample(3)), 5)), "rate_bound");
        assert_eq!(reason(t.check(key, &encode(&sample(2)), 5)), "rate_bound");
        assert_eq!(reason(t.check(key, &encode(&sample(4)), 5)), "accepted");
        // Ahead of the server.
        assert_eq!(reason(t.check(key, &encode(&sample(6)), 5)), "future_tick");
        assert_eq!(reason(t.check(key, &encode(&sample(5)), 5)), "accepted");
        // A lockstep run's last tick (100 here) is not recorded, and not refused either.
        assert_eq!(
            reason(t.check(key, &encode(&sample(100)), 100)),
            "last_tick"
        );
    }

    #[test]
    fn every_refusal_is_named() {
        let t = intake();
        let key = "flexdyn/sc1/fsw/acs";
        let mut wrong_sc = sample(1);
        wrong_sc.header.spacecraft_id = 2;
        assert_eq!(
            reason(t.check(key, &encode(&wrong_sc), 9)),
            "wrong_spacecraft"
        );
        assert_eq!(
            reason(t.check("flexdyn/sc1/fsw/nav", &encode(&sample(1)), 9)),
            "unknown_stream"
        );
        let mut late = sample(1);
        late.header.sim_time_ns += 1;
        assert_eq!(reason(t.check(key, &encode(&late), 9)), "wrong_time");
        let mut mode = sample(1);
        mode.mode = 2;
        assert_eq!(reason(t.check(key, &encode(&mode), 9)), "unknown_mode");
        let mut count = sample(1);
        count.values.pop();
        assert_eq!(reason(t.check(key, &encode(&count), 9)), "wrong_count");
        let mut nan = sample(1);
        nan.values[1] = f64::NAN.to_bits();
        assert_eq!(reason(t.check(key, &encode(&nan), 9)), "non_finite");
        let mut bool2 = sample(1);
        bool2.values[3] = 2;
        assert_eq!(reason(t.check(key, &encode(&bool2), 9)), "not_bool");
        let mut bytes = encode(&sample(1));
        bytes[0] = 9;
        assert_eq!(reason(t.check(key, &bytes, 9)), "bad_version");
        assert_eq!(
            reason(t.check(key, &encode(&sample(1))[..40], 9)),
            "malformed"
        );
        // None of the refusals claimed tick 1: a good sample for it is still recorded.
        assert_eq!(reason(t.check(key, &encode(&sample(1)), 9)), "accepted");
    }
}
