//! `flexdyn replay FILE.mcap`: republishes a recording's raw channels to Zenoh, byte for byte,
//! with the recorded spacing of their log times (simulation time) divided by `--speed`, or as
//! fast as Zenoh takes them. Each sample carries its recorded publish time as the 8-byte
//! attachment, like the server's. A monitor, ground tool or recorder can then be tested against
//! a real run with no server.
//!
//! The replay stands in for the server, so it takes the server's endpoints: it listens on
//! `tcp/127.0.0.1:7447` by default, where the tools connect. Before the first sample it waits
//! until a subscriber matches one of the recorded keys (Zenoh's matching status), at most
//! `--wait-subscriber-s`; with none, it replays nothing and fails. Samples published while their
//! key had no subscriber are counted and reported.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use flexdyn_proto::keys::{CONFIG_SUFFIX, KEY_ROOT};
use flexdyn_proto::validate_sc_id;
use zenoh::pubsub::Publisher;
use zenoh::qos::CongestionControl;
use zenoh::Wait;

use super::error::SinkError;
use super::reader::read_recording;
use super::topics::classify;
use flexdyn_proto::client::transport::{zenoh_config, Role, ZenohArgs};

/// How long the replay stays connected after its last sample.
const LINGER: Duration = Duration::from_secs(1);
/// How often the wait for a subscriber looks at the matching status.
const MATCH_POLL: Duration = Duration::from_millis(20);

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
    /// Seconds to wait for the first subscriber of a recorded key; with none by then, nothing
    /// is replayed and the replay fails. 0: do not wait (publish whoever listens).
    #[arg(long, value_name = "S", default_value_t = 10.0)]
    pub wait_subscriber_s: f64,
    /// Seconds to wait after the first subscriber appears, before the first sample, so other
    /// subscribers can join too.
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub start_delay_s: f64,
    /// Zenoh endpoints and configuration file. Like the server, the replay listens on
    /// tcp/127.0.0.1:7447 by default and connects nowhere.
    #[command(flatten)]
    pub zenoh: ZenohArgs,
}

/// What a replay did.
#[derive(Clone, Debug, PartialEq)]
pub struct ReplayReport {
    /// Samples published.
    pub published: u64,
    /// Of those, samples published while no subscriber matched their key (nobody got them).
    pub unheard: u64,
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
    for (flag, value) in [
        ("--start-delay-s", args.start_delay_s),
        ("--wait-subscriber-s", args.wait_subscriber_s),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(SinkError::Arg {
                flag,
                problem: format!("must be a non-negative number of seconds, got {value}"),
            });
        }
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
    let zcfg = replay_config(&args.zenoh)?;
    let runtime = super::error::runtime()?;
    let pace = !args.as_fast_as_possible;
    let start_delay = Duration::from_secs_f64(args.start_delay_s);
    let wait_subscriber = Duration::from_secs_f64(args.wait_subscriber_s);
    let vehicles = rec.vehicles();
    let (published, unheard, wall_s) = runtime.block_on(async move {
        let session = zenoh::open(zcfg)
            .await
            .map_err(|e| SinkError::zenoh("open the session", e))?;
        flexdyn_proto::client::transport::log_listening(&session);
        let listening = flexdyn_proto::client::transport::listening_on(&session);
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
        // Every recorded key's publisher, declared up front so their matching status can be
        // watched before the first sample.
        let mut publishers = BTreeMap::new();
        for s in &samples {
            if !publishers.contains_key(s.key.as_str()) {
                let p = session
                    .declare_publisher(s.key.clone())
                    .congestion_control(CongestionControl::Block)
                    .await
                    .map_err(|e| SinkError::zenoh("declare a publisher", e))?;
                publishers.insert(s.key.as_str(), p);
            }
        }
        if !wait_subscriber.is_zero() {
            let waited_from = Instant::now();
            while !any_matched(publishers.values()).await {
                if waited_from.elapsed() >= wait_subscriber {
                    return Err(SinkError::NoSubscriber {
                        keys: publishers.len(),
                        waited_s: args.wait_subscriber_s,
                        endpoints: endpoints_text(&args.zenoh, &listening),
                    });
                }
                tokio::time::sleep(MATCH_POLL).await;
            }
            tracing::info!(
                waited_s = format!("{:.3}", waited_from.elapsed().as_secs_f64()),
                "a subscriber is here; replaying after --start-delay-s"
            );
        }
        tokio::time::sleep(start_delay).await;
        let t0_log = samples[0].log_time_ns;
        let started = Instant::now();
        let (mut published, mut unheard) = (0u64, 0u64);
        for s in &samples {
            if pace {
                let offset_ns = s.log_time_ns.saturating_sub(t0_log) as f64 / speed;
                let due = started + Duration::from_nanos(offset_ns as u64);
                let now = Instant::now();
                if due > now {
                    tokio::time::sleep(due - now).await;
                }
            }
            if let Some(p) = publishers.get(s.key.as_str()) {
                if !any_matched([p]).await {
                    unheard += 1;
                }
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
        Ok::<_, SinkError>((published, unheard, wall_s))
    })?;
    if unheard > 0 {
        tracing::warn!(
            unheard,
            published,
            "samples were published while no subscriber matched their key: nobody received them"
        );
    }
    Ok(ReplayReport {
        published,
        unheard,
        wall_s,
        truncated: rec.truncated,
    })
}

/// The replay's Zenoh configuration: the server's defaults (it stands in for the server).
fn replay_config(z: &ZenohArgs) -> Result<zenoh::Config, SinkError> {
    Ok(zenoh_config(z, Role::Server)?)
}

/// Whether a subscriber matches any of `publishers`' keys now.
async fn any_matched<'a>(publishers: impl IntoIterator<Item = &'a Publisher<'a>>) -> bool {
    for p in publishers {
        if p.matching_status().await.is_ok_and(|m| m.matching()) {
            return true;
        }
    }
    false
}

/// Where the replay listens or connects, in words (`listens on tcp/127.0.0.1:7447`).
/// `listening`: where its session really listens (the port the OS gave for `:0`), if known.
fn endpoints_text(z: &ZenohArgs, listening: &[String]) -> String {
    let list = |v: &[String]| v.join(", ");
    let listen = if listening.is_empty() {
        &z.listen
    } else {
        listening
    };
    match (listen.is_empty(), z.connect.is_empty(), &z.zenoh_config) {
        (true, true, Some(file)) => format!("uses the endpoints of {}", file.display()),
        (true, true, None) => format!(
            "listens on {}",
            flexdyn_proto::client::transport::DEFAULT_ENDPOINT
        ),
        (false, true, _) => format!("listens on {}", list(listen)),
        (true, false, _) => format!("connects to {}", list(&z.connect)),
        (false, false, _) => format!(
            "listens on {} and connects to {}",
            list(listen),
            list(&z.connect)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A configuration value as JSON.
    fn get(c: &zenoh::Config, key: &str) -> serde_json::Value {
        serde_json::from_str(&c.get_json(key).expect("a known key")).expect("JSON")
    }

    /// On its defaults the replay takes the server's place: it listens where the tools connect.
    #[test]
    fn the_replay_listens_where_the_tools_connect_by_default() {
        let replay = replay_config(&ZenohArgs::default()).unwrap();
        let tool = zenoh_config(&ZenohArgs::default(), Role::Tool).unwrap();
        assert_eq!(
            get(&replay, "listen/endpoints"),
            get(&tool, "connect/endpoints")
        );
        assert_eq!(
            get(&replay, "connect/endpoints"),
            serde_json::json!([]),
            "the replay connects nowhere by default"
        );
        assert_eq!(
            endpoints_text(&ZenohArgs::default(), &[]),
            "listens on tcp/127.0.0.1:7447"
        );
    }
}
