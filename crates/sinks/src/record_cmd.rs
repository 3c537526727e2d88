//! `flexdyn record`: subscribes to `flexdyn/<sc-id>/**` (every vehicle without `--sc-id`) and
//! writes every sample to an MCAP file until SIGINT/SIGTERM or `--duration-s` of wall time.
//! Each vehicle's configuration comes from its server's `flexdyn/<sc-id>/config` queryable, for
//! the file's metadata and the 3D transforms.

use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use flexdyn_proto::keys::{CONFIG_SUFFIX, KEY_ROOT};
use flexdyn_proto::validate_sc_id;
use zenoh::sample::SampleKind;
use zenoh::Session;

use super::error::SinkError;
use super::mcap_file::{RecordingInfo, VehicleInfo};
use super::recorder::{RecordItem, RecordReport, RecordTx, Recorder};
use super::topics::classify;
use flexdyn_proto::client::transport::{frame_stamp_ns, zenoh_config, Role, ZenohArgs};

/// Samples the recorder queue holds; the subscriber waits when it is full (nothing is lost).
const QUEUE: usize = 65_536;
/// How long to wait for a server's configuration reply.
const CONFIG_TIMEOUT: Duration = Duration::from_secs(2);

/// Arguments of `flexdyn record`.
#[derive(Clone, Debug, PartialEq, clap::Args)]
pub struct RecordArgs {
    /// The MCAP file to write (overwritten).
    #[arg(long, short, value_name = "FILE.mcap")]
    pub output: PathBuf,
    /// Record only this spacecraft (repeatable). Default: every vehicle heard.
    #[arg(long = "sc-id", value_name = "ID")]
    pub sc_id: Vec<String>,
    /// Stop after this many seconds of wall time. Default: until SIGINT/SIGTERM.
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration_s: Option<f64>,
    /// Zenoh endpoints and configuration file.
    #[command(flatten)]
    pub zenoh: ZenohArgs,
}

/// Asks `flexdyn/<sc>/config` (a key expression, `*` for every server) and returns the replies
/// that parse.
pub async fn query_vehicles(session: &Session, sc: &str) -> Vec<VehicleInfo> {
    let key = format!("{KEY_ROOT}/{sc}/{CONFIG_SUFFIX}");
    let Ok(replies) = session.get(key.as_str()).timeout(CONFIG_TIMEOUT).await else {
        return Vec::new();
    };
    let mut out = Vec::new();
    while let Ok(reply) = replies.recv_async().await {
        let Ok(sample) = reply.result() else { continue };
        let text = sample.payload().try_to_string().unwrap_or_default();
        match serde_json::from_str::<VehicleInfo>(&text) {
            Ok(info) => out.push(info),
            Err(e) => {
                tracing::warn!(key = %sample.key_expr(), error = %e, "a configuration reply does not parse")
            }
        }
    }
    out
}

fn check_args(args: &RecordArgs) -> Result<Option<Duration>, SinkError> {
    for sc in &args.sc_id {
        validate_sc_id(sc).map_err(|e| SinkError::Arg {
            flag: "--sc-id",
            problem: e.to_string(),
        })?;
    }
    match args.duration_s {
        None => Ok(None),
        Some(s) if s.is_finite() && s > 0.0 => Ok(Some(Duration::from_secs_f64(s))),
        Some(s) => Err(SinkError::Arg {
            flag: "--duration-s",
            problem: format!("must be a positive number of seconds, got {s}"),
        }),
    }
}

/// Records until the duration ends or a signal arrives; returns what was written.
pub fn record(args: &RecordArgs) -> Result<RecordReport, SinkError> {
    let duration = check_args(args)?;
    let zcfg = zenoh_config(&args.zenoh, Role::Tool)?;
    let runtime = super::error::runtime()?;
    runtime.block_on(async move {
        let shutdown = crate::signals::shutdown_signal()
            .await
            .map_err(|(s, e)| SinkError::Runtime(format!("cannot install the {s} handler: {e}")))?;
        let session = zenoh::open(zcfg)
            .await
            .map_err(|e| SinkError::zenoh("open the session", e))?;
        let result = record_on(&session, args, duration, shutdown).await;
        let _ = session.close().await;
        result
    })
}

async fn record_on(
    session: &Session,
    args: &RecordArgs,
    duration: Option<Duration>,
    shutdown: impl std::future::Future<Output = ()>,
) -> Result<RecordReport, SinkError> {
    let info = RecordingInfo {
        recorder: "flexdyn record".into(),
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
    };
    let (recorder, tx) = Recorder::start(&args.output, &info, QUEUE, true)?;
    let described: Arc<Mutex<HashSet<String>>> = Arc::default();
    // Vehicles already running: their configuration before their first sample.
    let patterns: Vec<String> = if args.sc_id.is_empty() {
        vec!["*".into()]
    } else {
        args.sc_id.clone()
    };
    for p in &patterns {
        for v in query_vehicles(session, p).await {
            if described
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .insert(v.sc_id.clone())
            {
                tx.describe_vehicle(v);
            }
        }
    }
    // A vehicle first heard later is described as soon as its server answers.
    let (new_tx, mut new_rx) = tokio::sync::mpsc::unbounded_channel::<String>();
    let mut subscribers = Vec::new();
    for p in &patterns {
        let key = format!("{KEY_ROOT}/{p}/**");
        let rec: RecordTx = tx.clone();
        let described = described.clone();
        let new_tx = new_tx.clone();
        let sub = session
            .declare_subscriber(key.as_str())
            .callback(move |sample| {
                if sample.kind() != SampleKind::Put {
                    return;
                }
                let key = sample.key_expr().as_str();
                if let Some(topic) = classify(key) {
                    let known = described
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .contains(topic.sc_id);
                    if !known {
                        let _ = new_tx.send(topic.sc_id.to_owned());
                    }
                }
                rec.submit(RecordItem {
                    key: Arc::from(key),
                    payload: sample.payload().to_bytes().into_owned(),
                    publish_time_ns: frame_stamp_ns(&sample),
                });
            })
            .await
            .map_err(|e| SinkError::zenoh("declare the subscriber", e))?;
        subscribers.push(sub);
    }
    tracing::info!(file = %args.output.display(), keys = ?patterns, "recording");
    let mut shutdown = std::pin::pin!(shutdown);
    let deadline = async {
        match duration {
            Some(d) => tokio::time::sleep(d).await,
            None => std::future::pending().await,
        }
    };
    let mut deadline = std::pin::pin!(deadline);
    loop {
        tokio::select! {
            () = &mut shutdown => break,
            () = &mut deadline => break,
            Some(sc) = new_rx.recv() => {
                if described.lock().unwrap_or_else(|e| e.into_inner()).contains(&sc) {
                    continue;
                }
                for v in query_vehicles(session, &sc).await {
                    if described.lock().unwrap_or_else(|e| e.into_inner()).insert(v.sc_id.clone()) {
                        tx.describe_vehicle(v);
                    }
                }
                // Asked once: a vehicle without a server answering keeps being recorded.
                described.lock().unwrap_or_else(|e| e.into_inner()).insert(sc);
            }
        }
    }
    for s in subscribers {
        let _ = s.undeclare().await;
    }
    let report = recorder.finish(&tx)?;
    Ok(report)
}
