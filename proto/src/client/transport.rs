//! The one place that builds a Zenoh configuration, for the server, the tools, the tests and
//! the benchmarks.
//!
//! Rules, in order:
//! 1. Start from the JSON5 file of `--zenoh-config` if given (standard Zenoh format), else from
//!    Zenoh's defaults in **peer** mode.
//! 2. `--listen` / `--connect` (repeatable) replace the file's endpoints. Without them, and if
//!    the file does not set them either, the role's loopback defaults apply: the server listens
//!    on `tcp/127.0.0.1:7447` and connects nowhere (so does `flexdyn replay`, which stands in
//!    for it); a tool listens nowhere and connects to `tcp/127.0.0.1:7447`. (Zenoh's own peer
//!    default would listen on every interface.)
//! 3. The server's links queue 16 batches of data samples ([`SERVER_TX_QUEUE_BATCHES`]), not
//!    Zenoh's 2, unless the file sets it: real-time telemetry is dropped when a queue is full.
//! 4. Multicast scouting is **always** switched off (`scouting/multicast/enabled = false`),
//!    even if the file switches it on (a warning is logged): flexdyn never sends multicast, so
//!    nothing leaves this machine unless an endpoint says so.
//!
//! Every key a process publishes or receives every tick is declared to its session
//! ([`declared_key`]), so Zenoh routes it by a cached route rather than matching the key against
//! every subscription each time.
//!
//! A listening process logs where it listens ([`log_listening`]); `--listen tcp/127.0.0.1:0`
//! lets the OS pick a free port, and that line names it.

use std::path::PathBuf;

use zenoh::sample::Sample;

/// `key` declared to `session` as a key expression of its own (`Session::declare_keyexpr`),
/// for a key that is published or received every tick. The declaration lasts as long as the
/// returned value: publish with it (`declare_publisher(declared)`), or subscribe with it
/// (`declare_subscriber(declared)`: the subscriber keeps it).
///
/// # Why
/// Zenoh caches a data route per resource of its routing tables, and a key that nothing
/// declared exactly has no resource: flexdyn subscribes with wildcards (`flexdyn/<sc>/tlm/**`
/// in the recorder and viewers, `flexdyn/<sc>/cmd/*`), so each sample was matched against the whole tree, in every router it
/// crossed, and against each of the session's subscribers. In a lockstep run (`flexdyn run
/// --mode lockstep`, the reference spacecraft at 1 kHz, `flexdyn-acs-demo`), Zenoh's trace
/// showed `compute_data_route` three times per sample in each process, and declaring the
/// state, time and command keys on both sides took the run from 3668–4191 to 4303–4591 ticks
/// per second (five alternating pairs, docs/developer/benchmarks.md). A plain ping-pong
/// subscribes to its exact keys, so its routes were cached already.
pub fn declared_key(
    session: &zenoh::Session,
    key: impl Into<String>,
) -> zenoh::Result<zenoh::key_expr::KeyExpr<'static>> {
    use zenoh::Wait;
    session.declare_keyexpr(key.into()).wait()
}

/// The default Zenoh endpoint of the server (`flexdyn run` listens, the tools connect).
pub const DEFAULT_ENDPOINT: &str = "tcp/127.0.0.1:7447";

/// The Zenoh setting of a link's transmission queue for data samples, in batches.
pub const SERVER_TX_QUEUE_KEY: &str = "transport/link/tx/queue/size/data";
/// The server's transmission queue for data samples (Zenoh's default is 2, its maximum 16);
/// a `--zenoh-config` file that sets [`SERVER_TX_QUEUE_KEY`] keeps its own value.
pub const SERVER_TX_QUEUE_BATCHES: u32 = 16;

/// Zenoh connection options shared by `flexdyn run` and every tool (flattened with clap).
#[derive(Clone, Debug, Default, PartialEq, Eq, clap::Args)]
pub struct ZenohArgs {
    /// Zenoh endpoint to listen on, e.g. `tcp/127.0.0.1:7447` (repeatable). Default: the server
    /// and `flexdyn replay` (which stands in for it) listen on tcp/127.0.0.1:7447, the other
    /// tools listen nowhere.
    #[arg(long = "listen", value_name = "ENDPOINT")]
    pub listen: Vec<String>,
    /// Zenoh endpoint to connect to (repeatable). Default: the server and `flexdyn replay`
    /// connect nowhere, the other tools connect to tcp/127.0.0.1:7447.
    #[arg(long = "connect", value_name = "ENDPOINT")]
    pub connect: Vec<String>,
    /// Standard Zenoh JSON5 configuration file; `--listen`/`--connect` override its endpoints.
    /// Multicast scouting is forced off whatever the file says.
    #[arg(long = "zenoh-config", value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
}

/// Which side of the link a configuration is for: decides the default endpoints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The server: listens on [`DEFAULT_ENDPOINT`], connects nowhere.
    Server,
    /// A tool or flight code: listens nowhere, connects to [`DEFAULT_ENDPOINT`].
    Tool,
}

impl Role {
    fn default_listen(self) -> &'static [&'static str] {
        match self {
            Role::Server => &[DEFAULT_ENDPOINT],
            Role::Tool => &[],
        }
    }

    fn default_connect(self) -> &'static [&'static str] {
        match self {
            Role::Server => &[],
            Role::Tool => &[DEFAULT_ENDPOINT],
        }
    }
}

fn json_list<S: AsRef<str>>(items: &[S]) -> String {
    let quoted: Vec<String> = items
        .iter()
        .map(|s| serde_json::Value::String(s.as_ref().to_owned()).to_string())
        .collect();
    format!("[{}]", quoted.join(","))
}

fn insert(
    config: &mut zenoh::Config,
    key: &str,
    value: &str,
    what: &str,
) -> Result<(), ZenohConfigError> {
    config
        .insert_json5(key, value)
        .map_err(|e| ZenohConfigError::Value {
            what: what.to_owned(),
            message: format!("{value}: {}", clean_zenoh_message(&e.to_string())),
        })
}

/// Zenoh's error text without its source locations (`… at /…/.cargo/registry/src/…/x.rs:61.`)
/// and serde wrappers (`Json5Err(Message { msg: "…", location: … })`), which mean nothing to a
/// user.
pub fn clean_zenoh_message(message: &str) -> String {
    let mut s = message.to_string();
    // Unwrap `Json5Err(Message { msg: "<inner>", … })` to `<inner>`.
    if let Some(i) = s.find("msg: \"") {
        let rest = &s[i + 6..];
        if let Some(j) = rest.find("\", location") {
            s = rest[..j].to_string();
        }
    }
    // Drop ` at <path>.rs:<line>` source locations.
    while let Some(i) = s.find(" at /") {
        let rest = &s[i..];
        let end = rest
            .find(".rs:")
            .map(|j| {
                let tail = &rest[j + 4..];
                j + 4
                    + tail
                        .find(|c: char| !c.is_ascii_digit())
                        .unwrap_or(tail.len())
            })
            .unwrap_or(rest.len());
        s.replace_range(i..i + end, "");
    }
    s.trim_end_matches('.').trim().to_string()
}

/// The endpoints `session` listens on, with the port the OS chose where the endpoint asked for
/// port 0 (`--listen tcp/127.0.0.1:0` → `tcp/127.0.0.1:41234`). Empty for a session that only
/// connects.
pub fn listening_on(session: &zenoh::Session) -> Vec<String> {
    use zenoh::Wait;
    session
        .info()
        .locators()
        .wait()
        .iter()
        .map(ToString::to_string)
        .collect()
}

/// The line a listening process logs once it is reachable: `Zenoh listening on <endpoint>, …`.
/// With `--listen tcp/127.0.0.1:0` it is how a user, a script or a test learns the port (the
/// tests read it back from stderr instead of guessing a free port).
pub const LISTENING_PREFIX: &str = "Zenoh listening on ";

/// Logs [`LISTENING_PREFIX`] and [`listening_on`] at `info` (nothing for a session that only
/// connects).
pub fn log_listening(session: &zenoh::Session) {
    let endpoints = listening_on(session);
    if !endpoints.is_empty() {
        tracing::info!("{LISTENING_PREFIX}{}", endpoints.join(", "));
    }
}

/// Checks a `--listen`/`--connect` endpoint before Zenoh sees it: `<protocol>/<address>`, and
/// the protocol must be one compiled in (only `tcp`).
fn check_endpoint(what: &str, endpoint: &str) -> Result<(), ZenohConfigError> {
    let bad = |problem: String| ZenohConfigError::Value {
        what: what.to_owned(),
        message: format!("`{endpoint}`: {problem}"),
    };
    let Some((proto, address)) = endpoint.split_once('/') else {
        return Err(bad(
            "not an endpoint: expected tcp/<host>:<port>, e.g. tcp/127.0.0.1:7447".into(),
        ));
    };
    if proto != "tcp" {
        return Err(bad(format!(
            "protocol `{proto}` is not built into flexdyn (only tcp): use tcp/<host>:<port>"
        )));
    }
    let address = address.split(['?', '#']).next().unwrap_or(address);
    let port_ok = address
        .rsplit_once(':')
        .is_some_and(|(host, port)| !host.is_empty() && port.parse::<u16>().is_ok());
    if !port_ok {
        return Err(bad(
            "expected tcp/<host>:<port> with a port from 0 to 65535, e.g. tcp/127.0.0.1:7447"
                .into(),
        ));
    }
    Ok(())
}

/// Whether the parsed JSON5 document sets `path` (a `/`-separated key) to anything.
fn json_has(doc: &serde_json::Value, path: &str) -> Option<serde_json::Value> {
    let mut v = doc;
    for part in path.split('/') {
        v = v.get(part)?;
    }
    Some(v.clone())
}

/// Builds the Zenoh configuration for `role` from `args` (see the module docs for the rules).
pub fn zenoh_config(args: &ZenohArgs, role: Role) -> Result<zenoh::Config, ZenohConfigError> {
    for e in &args.listen {
        check_endpoint("--listen", e)?;
    }
    for e in &args.connect {
        check_endpoint("--connect", e)?;
    }
    let (mut config, doc) = match &args.zenoh_config {
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|source| ZenohConfigError::Read {
                path: path.clone(),
                source,
            })?;
            let doc: serde_json::Value =
                json5::from_str(&text).map_err(|e| ZenohConfigError::Parse {
                    path: path.clone(),
                    message: e.to_string(),
                })?;
            let config = zenoh::Config::from_json5(&text).map_err(|e| ZenohConfigError::Parse {
                path: path.clone(),
                message: e.to_string(),
            })?;
            (config, Some(doc))
        }
        None => {
            let mut config = zenoh::Config::default();
            insert(&mut config, "mode", "\"peer\"", "mode")?;
            // Tools may start before the server: retry the connection quickly.
            insert(
                &mut config,
                "connect/retry",
                "{ period_init_ms: 100, period_max_ms: 1000, period_increase_factor: 2 }",
                "connect/retry",
            )?;
            (config, None)
        }
    };
    let file_sets = |key: &str| doc.as_ref().and_then(|d| json_has(d, key)).is_some();

    // A relative usrpwd dictionary path is relative to the JSON5 file, not to the working
    // directory, so a shipped file works from anywhere.
    if let (Some(path), Some(doc)) = (&args.zenoh_config, &doc) {
        if let Some(serde_json::Value::String(dict)) =
            json_has(doc, "transport/auth/usrpwd/dictionary_file")
        {
            let dict_path = std::path::Path::new(&dict);
            if dict_path.is_relative() {
                let base = path.parent().unwrap_or(std::path::Path::new("."));
                let resolved = base.join(dict_path);
                insert(
                    &mut config,
                    "transport/auth/usrpwd/dictionary_file",
                    &serde_json::Value::String(resolved.to_string_lossy().into_owned()).to_string(),
                    "transport/auth/usrpwd/dictionary_file",
                )?;
            }
        }
    }

    if !args.listen.is_empty() {
        insert(
            &mut config,
            "listen/endpoints",
            &json_list(&args.listen),
            "--listen",
        )?;
    } else if !file_sets("listen/endpoints") {
        insert(
            &mut config,
            "listen/endpoints",
            &json_list(role.default_listen()),
            "listen",
        )?;
    }
    if !args.connect.is_empty() {
        insert(
            &mut config,
            "connect/endpoints",
            &json_list(&args.connect),
            "--connect",
        )?;
    } else if !file_sets("connect/endpoints") {
        insert(
            &mut config,
            "connect/endpoints",
            &json_list(role.default_connect()),
            "connect",
        )?;
    }

    // Real-time telemetry goes out with congestion control "drop": a sample that finds its
    // link's transmission queue full for 1 ms is dropped. Zenoh's default queue holds 2
    // batches per priority and an express sample takes a batch of its own, so a subscriber
    // whose link was not served for two samples lost them: a `flexdyn record` next to a 1 kHz
    // server with three CPU hogs on two cores missed 2.9–7.8 % of the states. 16 batches, Zenoh's
    // most, lost none in the same test (docs/guides/recording.md). The batches
    // are allocated as needed, up to 16 × 64 KiB per peer.
    if role == Role::Server && !file_sets(SERVER_TX_QUEUE_KEY) {
        insert(
            &mut config,
            SERVER_TX_QUEUE_KEY,
            &SERVER_TX_QUEUE_BATCHES.to_string(),
            SERVER_TX_QUEUE_KEY,
        )?;
    }

    if let (Some(path), Some(doc)) = (&args.zenoh_config, &doc) {
        if json_has(doc, "scouting/multicast/enabled") == Some(serde_json::Value::Bool(true)) {
            tracing::warn!(
                file = %path.display(),
                "the Zenoh config enables multicast scouting; flexdyn forces \
                 scouting/multicast/enabled = false (loopback/explicit endpoints only)"
            );
        }
    }
    insert(
        &mut config,
        "scouting/multicast/enabled",
        "false",
        "scouting/multicast/enabled",
    )?;
    Ok(config)
}

/// A configuration value as JSON, for the tests that check what [`zenoh_config`] built.
#[cfg(test)]
pub(crate) fn config_value(c: &zenoh::Config, key: &str) -> serde_json::Value {
    serde_json::from_str(&c.get_json(key).expect("a known key")).expect("JSON")
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::config_value as get;

    #[test]
    fn defaults_are_loopback_peer_without_multicast() {
        let c = zenoh_config(&ZenohArgs::default(), Role::Server).unwrap();
        assert_eq!(get(&c, "mode"), serde_json::json!("peer"));
        assert_eq!(
            get(&c, "scouting/multicast/enabled"),
            serde_json::json!(false)
        );
        assert_eq!(
            get(&c, "listen/endpoints"),
            serde_json::json!(["tcp/127.0.0.1:7447"])
        );
        assert_eq!(get(&c, "connect/endpoints"), serde_json::json!([]));
        let t = zenoh_config(&ZenohArgs::default(), Role::Tool).unwrap();
        assert_eq!(get(&t, "listen/endpoints"), serde_json::json!([]));
        assert_eq!(
            get(&t, "connect/endpoints"),
            serde_json::json!(["tcp/127.0.0.1:7447"])
        );
        assert_eq!(
            get(&t, "scouting/multicast/enabled"),
            serde_json::json!(false)
        );
    }

    #[test]
    fn the_server_queues_16_batches_per_link_unless_its_file_says_otherwise() {
        let server = zenoh_config(&ZenohArgs::default(), Role::Server).unwrap();
        let tool = zenoh_config(&ZenohArgs::default(), Role::Tool).unwrap();
        assert_eq!(get(&server, SERVER_TX_QUEUE_KEY), serde_json::json!(16));
        assert_eq!(
            get(&tool, SERVER_TX_QUEUE_KEY),
            serde_json::json!(2),
            "Zenoh's default"
        );
        let file = std::env::temp_dir().join(format!("flexdyn-txq-{}.json5", std::process::id()));
        std::fs::write(
            &file,
            r#"{ transport: { link: { tx: { queue: { size: { data: 4 } } } } } }"#,
        )
        .unwrap();
        let args = ZenohArgs {
            zenoh_config: Some(file.clone()),
            ..ZenohArgs::default()
        };
        let own = zenoh_config(&args, Role::Server).unwrap();
        std::fs::remove_file(&file).ok();
        assert_eq!(get(&own, SERVER_TX_QUEUE_KEY), serde_json::json!(4));
    }

    #[test]
    fn flags_override_and_file_cannot_enable_multicast() {
        let dir = std::env::temp_dir().join(format!("flexdyn-zcfg-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("z.json5");
        std::fs::write(
            &file,
            r#"{ mode: "peer", scouting: { multicast: { enabled: true } },
                 listen: { endpoints: ["tcp/127.0.0.1:17999"] } }"#,
        )
        .unwrap();
        let args = ZenohArgs {
            listen: vec![],
            connect: vec!["tcp/127.0.0.1:17998".into()],
            zenoh_config: Some(file.clone()),
        };
        let c = zenoh_config(&args, Role::Server).unwrap();
        assert_eq!(
            get(&c, "scouting/multicast/enabled"),
            serde_json::json!(false)
        );
        // The file's listen endpoints are kept, the flag's connect endpoint applies.
        assert_eq!(
            get(&c, "listen/endpoints"),
            serde_json::json!(["tcp/127.0.0.1:17999"])
        );
        assert_eq!(
            get(&c, "connect/endpoints"),
            serde_json::json!(["tcp/127.0.0.1:17998"])
        );
        let args = ZenohArgs {
            listen: vec!["tcp/127.0.0.1:17997".into()],
            ..args
        };
        let c = zenoh_config(&args, Role::Tool).unwrap();
        assert_eq!(
            get(&c, "listen/endpoints"),
            serde_json::json!(["tcp/127.0.0.1:17997"])
        );

        std::fs::write(&file, "{ mode: ").unwrap();
        let e = zenoh_config(&args, Role::Server).unwrap_err();
        assert!(
            e.to_string().starts_with("invalid Zenoh config file"),
            "{e}"
        );
        let missing = ZenohArgs {
            zenoh_config: Some(dir.join("missing.json5")),
            ..ZenohArgs::default()
        };
        let e = zenoh_config(&missing, Role::Server).unwrap_err();
        assert!(
            e.to_string().starts_with("cannot read Zenoh config file"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn bad_endpoint_is_an_error() {
        let args = ZenohArgs {
            listen: vec!["not an endpoint".into()],
            ..ZenohArgs::default()
        };
        let e = zenoh_config(&args, Role::Server).unwrap_err();
        assert!(e.to_string().starts_with("--listen:"), "{e}");
        for (bad, want) in [
            ("garbage", "not an endpoint"),
            (
                "udp/127.0.0.1:7447",
                "protocol `udp` is not built into flexdyn",
            ),
            ("tcp/127.0.0.1", "expected tcp/<host>:<port> with a port"),
            (
                "tcp/127.0.0.1:99999",
                "expected tcp/<host>:<port> with a port",
            ),
        ] {
            let args = ZenohArgs {
                connect: vec![bad.into()],
                ..ZenohArgs::default()
            };
            let msg = zenoh_config(&args, Role::Tool).unwrap_err().to_string();
            assert!(
                msg.starts_with(&format!("--connect: `{bad}`: {want}")),
                "{msg}"
            );
            assert!(!msg.contains(".rs:") && !msg.contains("Json5Err"), "{msg}");
        }
    }

    #[test]
    fn zenoh_messages_lose_their_source_paths() {
        let raw = "Json5Err(Message { msg: \"Endpoints must be of the form <protocol>/<address>: \
                   garbage at /root/.cargo/registry/src/x/zenoh-protocol-1.10.2/src/core/endpoint.rs:615.\", \
                   location: Some(Location { line: 1, column: 1 }) }) at /root/.cargo/registry/src/x/zenoh-1.10.2/src/api/config.rs:86.";
        assert_eq!(
            clean_zenoh_message(raw),
            "Endpoints must be of the form <protocol>/<address>: garbage"
        );
        assert_eq!(
            clean_zenoh_message("Can not create a new TCP listener bound to tcp/127.0.0.1:1: Permission denied at /r/.cargo/registry/src/tcp.rs:61."),
            "Can not create a new TCP listener bound to tcp/127.0.0.1:1: Permission denied"
        );
    }
}

/// A Zenoh configuration that cannot be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ZenohConfigError {
    /// The JSON5 file given with `--zenoh-config` cannot be read.
    #[error("cannot read Zenoh config file `{}`: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The JSON5 file is not a valid Zenoh configuration.
    #[error("invalid Zenoh config file `{}`: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// What JSON5 or Zenoh reported.
        message: String,
    },
    /// An endpoint or other value that Zenoh rejects.
    #[error("{what}: {message}")]
    Value {
        /// The option (`--listen`, `--connect`, or a Zenoh config key).
        what: String,
        /// What Zenoh reported.
        message: String,
    },
}

/// Now, in ns since the Unix epoch: the clock of the frame-boundary stamps (0 before 1970,
/// saturating after 2554).
pub fn unix_now_ns() -> u64 {
    use std::time::{SystemTime, UNIX_EPOCH};
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
}

/// The frame-boundary wall-clock stamp of a StateMsg sample (ns since the Unix epoch), from its
/// 8-byte little-endian attachment; `None` if absent or malformed.
pub fn frame_stamp_ns(sample: &Sample) -> Option<u64> {
    let bytes = sample.attachment()?.to_bytes();
    let arr: [u8; 8] = bytes.as_ref().try_into().ok()?;
    Some(u64::from_le_bytes(arr))
}

/// The spelling of a [`crate::Mode`] in settings and logs.
pub fn mode_name(mode: crate::Mode) -> &'static str {
    match mode {
        crate::Mode::RealTime => "realtime",
        crate::Mode::Lockstep => "lockstep",
        crate::Mode::Batch => "batch",
    }
}
