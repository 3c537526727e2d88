//! The recorder thread: an [`McapSink`] fed through a bounded queue, so whoever produces the
//! samples (the server's telemetry thread and command callback, or `flexdyn record`'s Zenoh
//! subscriber) never waits on the disk.
//!
//! Two queue policies:
//! - **lossless** (lockstep and batch, and `flexdyn record`): a full queue makes the producer
//!   wait, so nothing is dropped;
//! - **lossy** (real time): a full queue drops the sample and counts it. The count is logged,
//!   returned in the [`RecordReport`] and written into the file's `flexdyn.recorder` metadata.
//!
//! Either way the file's `flexdyn.recorder` metadata says what it misses: the telemetry messages
//! whose publishers' sequence numbers jump ([`super::gaps`]: `missing_samples`, in total and per
//! key), what the queue dropped, and whether the recording is `complete` (neither).
//!
//! Chunks are flushed at least every [`FLUSH_INTERVAL`], bounding what a crash can lose.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use flexdyn_proto::client::transport::unix_now_ns;

use super::mcap_file::{McapSink, RecordError, RecordingInfo, SinkStats, VehicleInfo};

/// Longest time a finished sample stays in an open chunk.
pub const FLUSH_INTERVAL: Duration = Duration::from_secs(1);

/// One sample for the recorder.
#[derive(Debug)]
pub struct RecordItem {
    /// The Zenoh key it was (or is) published on.
    pub key: Arc<str>,
    /// The exact payload bytes.
    pub payload: Vec<u8>,
    /// \[ns since the Unix epoch\] the sample's wall-clock stamp (its attachment), if any.
    pub publish_time_ns: Option<u64>,
}

enum Msg {
    Sample(RecordItem, u64),
    Vehicle(Box<VehicleInfo>),
    Stop,
}

/// The producers' end of the recorder queue; cheap to clone.
#[derive(Clone)]
pub struct RecordTx {
    tx: SyncSender<Msg>,
    dropped: Arc<AtomicU64>,
    lossless: bool,
}

impl RecordTx {
    /// Queues a sample: waits for room when lossless, drops and counts it when lossy and full.
    /// After the recorder has failed, samples are counted as dropped.
    pub fn submit(&self, item: RecordItem) {
        let msg = Msg::Sample(item, unix_now_ns());
        let sent = if self.lossless {
            self.tx.send(msg).is_ok()
        } else {
            match self.tx.try_send(msg) {
                Ok(()) => true,
                Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => false,
            }
        };
        if !sent {
            self.dropped.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Queues a vehicle description (metadata and 3D geometry); always waits for room.
    pub fn describe_vehicle(&self, info: VehicleInfo) {
        let _ = self.tx.send(Msg::Vehicle(Box::new(info)));
    }

    /// Samples dropped so far (queue full, or the recorder failed).
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }
}

/// What the recorder did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RecordReport {
    /// What the file holds.
    pub stats: SinkStats,
    /// Samples the recorder could not take (queue full in real time, or after a write error).
    pub dropped: u64,
}

impl RecordReport {
    /// Whether the file holds every sample the recorder was given and every telemetry message
    /// between the first and the last of each key (no sequence-number gap).
    pub fn complete(&self) -> bool {
        self.dropped == 0 && self.stats.missing.is_empty()
    }

    /// `complete`, or `INCOMPLETE: …` saying what is missing (per key) and what was dropped.
    pub fn completeness(&self) -> String {
        if self.complete() {
            return "complete".into();
        }
        let mut parts = Vec::new();
        if !self.stats.missing.is_empty() {
            let keys: Vec<String> = self
                .stats
                .missing
                .iter()
                .map(|(k, n)| format!("{k} {n}"))
                .collect();
            parts.push(format!(
                "{} telemetry messages missing (sequence-number gaps: {})",
                self.stats.missing_total(),
                keys.join(", ")
            ));
        }
        if self.dropped > 0 {
            parts.push(format!("{} samples dropped by the recorder", self.dropped));
        }
        format!("INCOMPLETE: {}", parts.join("; "))
    }
}

/// The running recorder thread.
pub struct Recorder {
    join: JoinHandle<Result<SinkStats, RecordError>>,
    dropped: Arc<AtomicU64>,
}

fn run(
    mut sink: McapSink,
    rx: Receiver<Msg>,
    dropped: Arc<AtomicU64>,
) -> Result<SinkStats, RecordError> {
    let mut last_flush = Instant::now();
    let mut failed: Option<RecordError> = None;
    loop {
        let msg = match rx.recv_timeout(FLUSH_INTERVAL) {
            Ok(Msg::Stop) => break,
            Ok(m) => Some(m),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        if failed.is_some() {
            if matches!(msg, Some(Msg::Sample(..))) {
                dropped.fetch_add(1, Ordering::Relaxed);
            }
            continue;
        }
        let result = match msg {
            Some(Msg::Sample(item, received)) => {
                sink.write(&item.key, &item.payload, item.publish_time_ns, received)
            }
            Some(Msg::Vehicle(info)) => sink.describe_vehicle(&info),
            Some(Msg::Stop) | None => Ok(()),
        };
        let result = result.and_then(|()| {
            if last_flush.elapsed() >= FLUSH_INTERVAL {
                last_flush = Instant::now();
                sink.flush_chunk()
            } else {
                Ok(())
            }
        });
        if let Err(e) = result {
            tracing::error!(error = %e, "the recorder stopped writing; further samples are counted as dropped");
            failed = Some(e);
        }
    }
    if let Some(e) = failed {
        return Err(e);
    }
    let mut meta = BTreeMap::new();
    meta.insert(
        "dropped_samples".to_owned(),
        dropped.load(Ordering::Relaxed).to_string(),
    );
    meta.insert("samples".to_owned(), sink.stats().samples.to_string());
    meta.insert(
        "undecodable".to_owned(),
        sink.stats().undecodable.to_string(),
    );
    let missing = sink.stats().missing.clone();
    meta.insert(
        "missing_samples".to_owned(),
        missing.values().sum::<u64>().to_string(),
    );
    for (key, n) in &missing {
        meta.insert(format!("missing_samples.{key}"), n.to_string());
    }
    let complete = missing.is_empty() && dropped.load(Ordering::Relaxed) == 0;
    meta.insert("complete".to_owned(), complete.to_string());
    sink.write_metadata("flexdyn.recorder", meta)?;
    sink.finish()
}

/// Real time: the recorder yields the CPU to everything else (SCHED_BATCH at nice 19 on Linux),
/// so on a machine with few cores it does not preempt the physics thread; what it cannot keep
/// up with is dropped and counted. Needs no privilege (lowering is always allowed).
fn lower_priority() {
    #[cfg(target_os = "linux")]
    {
        use thread_priority::{
            set_thread_priority_and_policy, thread_native_id, NormalThreadSchedulePolicy,
            ThreadPriority, ThreadSchedulePolicy,
        };
        if let Err(e) = set_thread_priority_and_policy(
            thread_native_id(),
            ThreadPriority::Min,
            ThreadSchedulePolicy::Normal(NormalThreadSchedulePolicy::Batch),
        ) {
            tracing::debug!(error = ?e, "cannot lower the recorder thread's priority");
        }
    }
}

impl Recorder {
    /// Creates the file and starts the recorder thread with a queue of `capacity` samples. A
    /// lossy recorder (real time) also runs at the lowest CPU priority.
    pub fn start(
        path: &Path,
        info: &RecordingInfo,
        capacity: usize,
        lossless: bool,
    ) -> Result<(Recorder, RecordTx), RecordError> {
        let sink = McapSink::create(path, info)?;
        let (tx, rx) = sync_channel(capacity.max(1));
        let dropped = Arc::new(AtomicU64::new(0));
        let d = dropped.clone();
        let join = std::thread::Builder::new()
            .name("flexdyn-recorder".into())
            .spawn(move || {
                if !lossless {
                    lower_priority();
                }
                run(sink, rx, d)
            })
            .map_err(|source| RecordError::Create {
                path: path.to_owned(),
                source,
            })?;
        Ok((
            Recorder {
                join,
                dropped: dropped.clone(),
            },
            RecordTx {
                tx,
                dropped,
                lossless,
            },
        ))
    }

    /// Writes everything queued before this call, closes the file and ends the thread. `tx` is
    /// any of the queue's senders; samples submitted later by other clones are counted as
    /// dropped.
    pub fn finish(self, tx: &RecordTx) -> Result<RecordReport, RecordError> {
        let _ = tx.tx.send(Msg::Stop);
        let stats = match self.join.join() {
            Ok(r) => r?,
            Err(_) => {
                return Err(RecordError::Write {
                    path: "recording".into(),
                    source: mcap::McapError::Io(std::io::Error::other(
                        "the recorder thread panicked",
                    )),
                })
            }
        };
        let dropped = self.dropped.load(Ordering::Relaxed);
        if dropped > 0 {
            tracing::warn!(
                dropped,
                "the recorder could not keep up and dropped samples (real-time mode drops rather than delay telemetry)"
            );
        }
        if !stats.missing.is_empty() {
            tracing::warn!(
                missing = stats.missing_total(),
                by_key = ?stats.missing,
                "the recording misses telemetry messages: their publishers' sequence numbers jump"
            );
        }
        Ok(RecordReport { stats, dropped })
    }
}
