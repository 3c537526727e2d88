//! `flexdyn replay FILE.mcap`: republishes a recording's raw channels to Zenoh, byte for byte,
//! with the recorded spacing of their log times (simulation time) divided by `--speed`, or as
//! fast as Zenoh takes them. Each sample carries its recorded publish time as the 8-byte
//! attachment, like the server's. A monitor, ground tool or recorder can then be tested against
//! a real run with no server.

use std::collections::HashMap;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use flexdyn_proto::keys::{CONFIG_SUFFIX, KEY_ROOT};
use flexdyn_proto::validate_sc_id;
use zenoh::qos::CongestionControl;
use zenoh::Wait;

use super::error::SinkError;
use super::reader::read_recording;
use super::topics::classify;
use crate::transport::{zenoh_config, Role, ZenohArgs};

/// How long the replay stays connected after its last sample.
const LINGER: Duration = Duration::from_secs(1);

/// Arguments of `flexdyn replay`.
#[derive(Clone, Debug, PartialEq, clap::Args)]
pub struct ReplayArgs {
    /// The recording.
    #[arg(value_name = "FILE.mcap")]
    pub file: PathBuf,
    /// Playback speed: 2 plays twice as fast as recorded [default: 1].
    #[arg(long, value_name = "X", conflicts_with = "as_fast_as_possible")]
    pub speed: Option<f64>,
    /// Publish without pacing (Zenoh's congestion control still applies: nothing is dropped).
    #[arg(long)]
    pub as_fast_as_possible: bool,
    /// Replay only this spacecraft's keys (repeatable). Default: every recorded vehicle.
    #[arg(long = "sc-id", value_name = "ID")]
    pub sc_id: Vec<String>,
    /// Seconds to wait after connecting before the first sample, so subscribers can join
    /// [default: 1].
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub start_delay_s: f64,
    /// Zenoh endpoints and configuration file.
    #[command(flatten)]
    pub zenoh: ZenohArgs,
}

/// What a replay did.
#[derive(Clone, Debug, PartialEq)]
pub struct ReplayReport {
    /// Samples published.
    pub published: u64,
    /// \[s\] wall time of the playback.
    pub wall_s: f64,
    /// Why the file ended early, if it did (a recording cut by a crash).
    pub truncated: Option<String>,
}

/// Replays `args.file`.
pub fn replay(args: &ReplayArgs) -> Result<ReplayReport, SinkError> {
    let speed = match args.speed {
        None => 1.0,
        Some(x) if x.is_finite() && x > 0.0 => x,
        Some(x) => {
            return Err(SinkError::Arg {
                flag: "--speed",
                problem: format!("must be a positive number, got {x}"),
            })
        }
    };
    if !(args.start_delay_s.is_finite() && args.start_delay_s >= 0.0) {
        return Err(SinkError::Arg {
            flag: "--start-delay-s",
            problem: format!("must be a non-negative number, got {}", args.start_delay_s),
        });
    }
    for sc in &args.sc_id {
        validate_sc_id(sc).map_err(|e| SinkError::Arg {
            flag: "--sc-id",
            problem: e.to_string(),
        })?;
    }
    let rec = read_recording(&args.file)?;
    if let Some(why) = &rec.truncated {
        tracing::warn!(file = %args.file.display(), reason = %why, samples = rec.samples.len(), "the recording ends early (not closed cleanly); replaying what it holds");
    }
    let samples: Vec<_> = rec
        .samples
        .iter()
        .filter(|s| {
            args.sc_id.is_empty()
                || classify(&s.key).is_some_and(|t| args.sc_id.iter().any(|id| id == t.sc_id))
        })
        .collect();
    if samples.is_empty() {
        return Err(SinkError::Input {
            path: args.file.clone(),
            problem: if args.sc_id.is_empty() {
                "holds no flexdyn raw channel to replay".into()
            } else {
                format!("holds no raw channel of --sc-id {:?}", args.sc_id)
            },
        });
    }
    let zcfg = zenoh_config(&args.zenoh, Role::Tool)?;
    let runtime = super::error::runtime()?;
    let pace = !args.as_fast_as_possible;
    let start_delay = Duration::from_secs_f64(args.start_delay_s);
    let vehicles = rec.vehicles();
    let published = runtime.block_on(async move {
        let session = zenoh::open(zcfg)
            .await
            .map_err(|e| SinkError::zenoh("open the session", e))?;
        // Answer each recorded vehicle's configuration query as its server did, so a recorder
        // or viewer of the replay gets the same metadata and 3D geometry.
        let mut queryables = Vec::new();
        for v in vehicles {
            let reply = serde_json::to_string(&v)
                .map_err(|e| SinkError::Runtime(format!("vehicle description: {e}")))?;
            let key = format!("{KEY_ROOT}/{}/{CONFIG_SUFFIX}", v.sc_id);
            let q = session
                .declare_queryable(key.as_str())
                .callback(move |query| {
                    let key = query.key_expr().clone();
                    let _ = query.reply(key, reply.clone()).wait();
                })
                .await
                .map_err(|e| SinkError::zenoh("declare the configuration queryable", e))?;
            queryables.push(q);
        }
        tokio::time::sleep(start_delay).await;
        let mut publishers = HashMap::new();
        let t0_log = samples[0].log_time_ns;
        let started = Instant::now();
        let mut published = 0u64;
        for s in &samples {
            if pace {
                let offset_ns = s.log_time_ns.saturating_sub(t0_log) as f64 / speed;
                let due = started + Duration::from_nanos(offset_ns as u64);
                let now = Instant::now();
                if due > now {
                    tokio::time::sleep(due - now).await;
                }
            }
            if !publishers.contains_key(&s.key) {
                let p = session
                    .declare_publisher(s.key.clone())
                    .congestion_control(CongestionControl::Block)
                    .await
                    .map_err(|e| SinkError::zenoh("declare a publisher", e))?;
                publishers.insert(s.key.clone(), p);
            }
            if let Some(p) = publishers.get(&s.key) {
                p.put(s.payload.as_slice())
                    .attachment(s.publish_time_ns.to_le_bytes())
                    .await
                    .map_err(|e| SinkError::zenoh("publish", e))?;
                published += 1;
            }
        }
        let wall_s = started.elapsed().as_secs_f64();
        // Stay a moment so the last samples flush and late configuration queries (a recorder
        // asks when it first hears a vehicle) are answered.
        tokio::time::sleep(LINGER).await;
        drop(publishers);
        drop(queryables);
        let _ = session.close().await;
        Ok::<_, SinkError>((published, wall_s))
    })?;
    Ok(ReplayReport {
        published: published.0,
        wall_s: published.1,
        truncated: rec.truncated,
    })
}
