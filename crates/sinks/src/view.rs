//! `flexdyn view`: a Foxglove WebSocket server (`foxglove.websocket.v1`, through the `foxglove`
//! SDK) with the decoded channels, the frame transforms and the 3D scene, live from Zenoh or
//! from a recording (`--file`, with the protocol's playback control: play, pause, speed, seek).
//! The same port serves a web page to a plain HTTP GET ([`super::web`]): a client of
//! that same protocol, so a browser shows a live run and a replay alike, with nothing installed.
//!
//! Topics and schemas are the recording's decoded ones (`/flexdyn/<sc>/tlm/state`,
//! `/flexdyn/<sc>/tf`, `/flexdyn/<sc>/scene`, …), so one Foxglove layout serves both. Message
//! times are simulation time, and the server announces the current simulation time
//! (`Capability::Time`) with the data that advances it, so Foxglove's clock runs on simulation
//! time and keeps up with the plots: live, right after a StateMsg of a later time (at most every
//! [`CLOCK_PERIOD`], the latest time once the stream pauses); from a recording, with each batch
//! of played messages.
//!
//! A slow or closed viewer never slows anything upstream: the SDK gives each client a queue of
//! `--backlog` messages that drops its oldest; the Zenoh subscriber only decodes and enqueues,
//! and the server publishes real-time telemetry with congestion control "drop".

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use foxglove::websocket::{
    Capability, ChannelView, Client, PlaybackCommand, PlaybackControlRequest, PlaybackState,
    PlaybackStatus, ServerListener,
};
use foxglove::{ChannelId, Context, PartialMetadata, RawChannel, Schema, WebSocketServer};
use zenoh::sample::SampleKind;

use super::error::SinkError;
use super::mcap_file::{
    actuator_topic, decoded_topic, environment_topic, scene_topic, tf_topic, VehicleInfo,
};
use super::reader::{read_recording, RawSample};
use super::scene::{
    actuator_scene, environment_scene, frame_transforms, frame_transforms_schema, scene_update,
    scene_update_schema, Geometry,
};
use super::topics::{classify, json_schema, Decoded};
use flexdyn_proto::client::transport::{zenoh_config, Role, ZenohArgs};

/// Default address of the viewer (Foxglove's default connection is `ws://localhost:8765`).
pub const DEFAULT_BIND: &str = "127.0.0.1:8765";
/// How often the scene is sent again while a replay plays or a live stream runs. A viewer
/// that subscribes in between gets the last one at once ([`Latched`]).
const SCENE_PERIOD: Duration = Duration::from_secs(1);
/// Shortest wall time between two live clock announcements. The SDK puts them on each viewer's
/// control queue (`--backlog` long), which, unlike the data queue, does not drop its oldest:
/// when full it disconnects the viewer. At most 100 a second keeps a viewer that stalls for
/// less than `backlog / 100` seconds connected, and Foxglove's clock within 10 ms of the data.
pub const CLOCK_PERIOD: Duration = Duration::from_millis(10);

/// Arguments of `flexdyn view`.
#[derive(Clone, Debug, PartialEq, clap::Args)]
pub struct ViewArgs {
    /// Address of the WebSocket server and the web page, one port (loopback by default).
    #[arg(long, value_name = "HOST:PORT", default_value = DEFAULT_BIND)]
    pub bind: String,
    /// Show only this spacecraft (repeatable). Default: every vehicle heard (or recorded).
    #[arg(long = "sc-id", value_name = "ID")]
    pub sc_id: Vec<String>,
    /// Serve this recording instead of the live stream, with playback control.
    #[arg(long, value_name = "FILE.mcap")]
    pub file: Option<PathBuf>,
    /// Messages each viewer's queue holds before it drops its oldest.
    #[arg(long, value_name = "N", default_value_t = 4096)]
    pub backlog: usize,
    /// Stop after this many seconds of wall time (for scripts and tests). Default: until
    /// SIGINT/SIGTERM.
    #[arg(long, value_name = "S")]
    pub duration_s: Option<f64>,
    /// Zenoh endpoints and configuration file (live mode).
    #[command(flatten)]
    pub zenoh: ZenohArgs,
}

/// The last message of each channel that describes the vehicles rather than streams them (the
/// scene and the flight code's names), by channel. The SDK sends a channel's messages only to
/// the viewers subscribed at the time, so each viewer gets these again as it subscribes
/// ([`Listener::on_subscribe`]): one that subscribes between two sends of [`SCENE_PERIOD`],
/// or after a replay ended, sees them at once instead of never.
#[derive(Default)]
struct Latched(Mutex<HashMap<ChannelId, Kept>>);

/// A latched message: its channel, its JSON and its simulation time.
type Kept = (Arc<RawChannel>, Vec<u8>, u64);

impl Latched {
    /// Sends `json` on `channel` at simulation time `t_ns`, and keeps it for later subscribers.
    fn log(&self, channel: &Arc<RawChannel>, json: &[u8], t_ns: u64) {
        channel.log_with_meta(
            json,
            PartialMetadata {
                log_time: Some(t_ns),
            },
        );
        self.0
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(channel.id(), (channel.clone(), json.to_vec(), t_ns));
    }

    /// Sends the kept message of `channel`, if any, to the viewer behind `client` alone.
    fn resend(&self, client: &Client, channel: ChannelId) {
        let kept = self
            .0
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&channel)
            .cloned();
        if let Some((c, json, t_ns)) = kept {
            c.log_with_meta_to_sink(
                &json,
                PartialMetadata {
                    log_time: Some(t_ns),
                },
                client.sink_id(),
            );
        }
    }
}

/// Turns flexdyn samples into Foxglove channel messages.
struct Translator {
    ctx: Arc<Context>,
    latched: Arc<Latched>,
    channels: HashMap<String, Arc<RawChannel>>,
    geometry: HashMap<String, Geometry>,
    /// Per vehicle, its `[[fsw_streams]]` as the JSON of `/flexdyn/<sc>/fsw_streams` (only
    /// vehicles that declare any).
    fsw_streams: HashMap<String, String>,
    filter: Vec<String>,
    latest_time_ns: u64,
    /// The last simulation time announced to the viewers, and when.
    announced: Option<(u64, Instant)>,
}

impl Translator {
    fn new(ctx: Arc<Context>, latched: Arc<Latched>, filter: Vec<String>) -> Self {
        Self {
            ctx,
            latched,
            channels: HashMap::new(),
            geometry: HashMap::new(),
            fsw_streams: HashMap::new(),
            filter,
            latest_time_ns: 0,
            announced: None,
        }
    }

    /// The simulation time to announce now, if the data has moved it since the last
    /// announcement and [`CLOCK_PERIOD`] has passed (or `now_anyway`).
    fn clock_due(&mut self, now_anyway: bool) -> Option<u64> {
        let t = self.latest_time_ns;
        let due = match self.announced {
            None => true,
            Some((last, at)) => t > last && (now_anyway || at.elapsed() >= CLOCK_PERIOD),
        };
        due.then(|| {
            self.announced = Some((t, Instant::now()));
            t
        })
    }

    fn channel(&mut self, topic: &str, schema: impl FnOnce() -> Schema) -> Option<Arc<RawChannel>> {
        if let Some(c) = self.channels.get(topic) {
            return Some(c.clone());
        }
        match self
            .ctx
            .channel_builder(topic)
            .message_encoding("json")
            .schema(schema())
            .build_raw()
        {
            Ok(c) => {
                self.channels.insert(topic.to_owned(), c.clone());
                Some(c)
            }
            Err(e) => {
                tracing::warn!(topic, error = %e, "cannot open a viewer channel");
                None
            }
        }
    }

    fn describe(&mut self, info: &VehicleInfo) {
        if let Some(json) = fsw_streams_json(&info.config_toml) {
            self.fsw_streams.insert(info.sc_id.clone(), json);
        }
        match info.geometry() {
            Ok(g) => {
                self.geometry.insert(info.sc_id.clone(), g);
                self.send_scenes();
            }
            Err(e) => {
                tracing::warn!(sc_id = %info.sc_id, error = %e, "the vehicle's configuration does not parse here; no 3D view for it")
            }
        }
    }

    fn send_scenes(&mut self) {
        let t = self.latest_time_ns;
        let scenes: Vec<(String, String)> = self
            .geometry
            .iter()
            .map(|(sc, g)| {
                (
                    scene_topic(sc),
                    scene_update(g, &format!("{sc}/"), t).to_string(),
                )
            })
            .collect();
        for (topic, json) in scenes {
            if let Some(c) = self.channel(&topic, scene_update_channel_schema) {
                self.latched.log(&c, json.as_bytes(), t);
            }
        }
        let dictionaries: Vec<(String, String)> = self
            .fsw_streams
            .iter()
            .map(|(sc, json)| (fsw_streams_topic(sc), json.clone()))
            .collect();
        for (topic, json) in dictionaries {
            if let Some(c) = self.channel(&topic, fsw_streams_schema) {
                self.latched.log(&c, json.as_bytes(), t);
            }
        }
    }

    /// Opens the decoded channel of `key` before its first message: a replay knows its keys up
    /// front, and a viewer subscribes to a channel only once it is advertised, so a channel
    /// opened by its first message would lose that message (a one-off status or fault event).
    fn advertise(&mut self, key: &str) {
        let Some(topic) = classify(key) else { return };
        if !self.filter.is_empty() && !self.filter.iter().any(|s| s == topic.sc_id) {
            return;
        }
        let kind = topic.kind;
        self.channel(&decoded_topic(key), || decoded_schema(kind));
    }

    fn sample(&mut self, key: &str, payload: &[u8]) {
        let Some(topic) = classify(key) else { return };
        if !self.filter.is_empty() && !self.filter.iter().any(|s| s == topic.sc_id) {
            return;
        }
        let Ok(decoded) = Decoded::decode(topic.kind, payload) else {
            return;
        };
        let t = decoded.header().sim_time_ns;
        let kind = topic.kind;
        let sc_id = topic.sc_id.to_owned();
        let json_topic = decoded_topic(key);
        if let Some(c) = self.channel(&json_topic, || decoded_schema(kind)) {
            let json = decoded.to_json_bytes();
            c.log_with_meta(&json, PartialMetadata { log_time: Some(t) });
        }
        if let Decoded::Environment(env) = &decoded {
            let json = environment_scene(env, &format!("{sc_id}/"), t).to_string();
            if let Some(c) = self.channel(&environment_topic(&sc_id), scene_update_channel_schema) {
                c.log_with_meta(json.as_bytes(), PartialMetadata { log_time: Some(t) });
            }
        }
        if let Decoded::State(state) = &decoded {
            self.latest_time_ns = self.latest_time_ns.max(t);
            let prefix = format!("{sc_id}/");
            let (tf, arrows) = match self.geometry.get(&sc_id) {
                Some(g) => (
                    Some(frame_transforms(state, g, &prefix).to_string()),
                    actuator_scene(g, state, &prefix, t).map(|v| v.to_string()),
                ),
                None => (None, None),
            };
            if let Some(json) = arrows {
                if let Some(c) = self.channel(&actuator_topic(&sc_id), scene_update_channel_schema)
                {
                    c.log_with_meta(json.as_bytes(), PartialMetadata { log_time: Some(t) });
                }
            }
            if let Some(json) = tf {
                if let Some(c) = self.channel(&tf_topic(&sc_id), || {
                    Schema::new(
                        "foxglove.FrameTransforms",
                        "jsonschema",
                        frame_transforms_schema().to_string().into_bytes(),
                    )
                }) {
                    c.log_with_meta(json.as_bytes(), PartialMetadata { log_time: Some(t) });
                }
            }
        }
    }
}

/// `/flexdyn/<sc>/fsw_streams`: the names behind the indices of the vehicle's flight-code
/// telemetry (`/flexdyn/<sc>/fsw/<stream>`), sent with the scene.
pub fn fsw_streams_topic(sc_id: &str) -> String {
    format!("/flexdyn/{sc_id}/fsw_streams")
}

/// The JSON of `/flexdyn/<sc>/fsw_streams` for a vehicle configured by `config_toml`:
/// `{"streams": [{"name", "modes": [...], "events": [{"name", "severity"}], "values": [{"name",
/// "type", "len", "unit"}]}]}`; `None` when it declares no stream (or does not parse here).
pub fn fsw_streams_json(config_toml: &str) -> Option<String> {
    let declared = flexdyn_vehicle::config::fsw::read_streams(config_toml).ok()?;
    if declared.is_empty() {
        return None;
    }
    let streams: Vec<serde_json::Value> = declared
        .iter()
        .map(|d| {
            serde_json::json!({
                "name": d.name,
                "modes": d.modes,
                "events": d.events.iter().map(|e| serde_json::json!({
                    "name": e.name, "severity": e.severity.name(),
                })).collect::<Vec<_>>(),
                "values": d.values.iter().map(|v| serde_json::json!({
                    "name": v.name, "type": v.ty.name(), "len": v.len, "unit": v.unit,
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    Some(serde_json::json!({ "streams": streams }).to_string())
}

/// The schema of `/flexdyn/<sc>/fsw_streams` ([`fsw_streams_json`]).
fn fsw_streams_schema() -> Schema {
    let names = serde_json::json!({"type": "array", "items": {"type": "string"}});
    let schema = serde_json::json!({
        "type": "object",
        "required": ["streams"],
        "properties": {"streams": {"type": "array", "items": {
            "type": "object",
            "required": ["name", "modes", "events", "values"],
            "properties": {
                "name": {"type": "string"},
                "modes": names,
                "events": {"type": "array", "items": {"type": "object", "properties": {
                    "name": {"type": "string"}, "severity": {"type": "string"}}}},
                "values": {"type": "array", "items": {"type": "object", "properties": {
                    "name": {"type": "string"}, "type": {"type": "string"},
                    "len": {"type": "integer"}, "unit": {"type": "string"}}}},
            },
        }}},
    });
    Schema::new(
        "flexdyn.FswStreams",
        "jsonschema",
        schema.to_string().into_bytes(),
    )
}

/// The schema of the decoded channel of a message kind (`flexdyn.<Message>`).
fn decoded_schema(kind: super::topics::TopicKind) -> Schema {
    Schema::new(
        format!("flexdyn.{}", kind.message_name()),
        "jsonschema",
        json_schema(kind).to_string().into_bytes(),
    )
}

/// The schema of every `foxglove.SceneUpdate` channel (the scenes and the arrows).
fn scene_update_channel_schema() -> Schema {
    Schema::new(
        "foxglove.SceneUpdate",
        "jsonschema",
        scene_update_schema().to_string().into_bytes(),
    )
}

fn split_bind(bind: &str) -> Result<(String, u16), SinkError> {
    let bad = |problem: String| SinkError::Arg {
        flag: "--bind",
        problem,
    };
    let (host, port) = bind
        .rsplit_once(':')
        .ok_or_else(|| bad(format!("expected HOST:PORT, got {bind:?}")))?;
    let port = port
        .parse::<u16>()
        .map_err(|e| bad(format!("port {port:?}: {e}")))?;
    if host.is_empty() {
        return Err(bad(format!("no host in {bind:?}")));
    }
    Ok((host.trim_matches(['[', ']']).to_owned(), port))
}

/// Playback of a recording, shared between the player loop and the protocol listener.
struct Player {
    playing: bool,
    speed: f32,
    seek_to: Option<u64>,
    current_ns: u64,
}

/// The protocol's callbacks: playback control of a recording, and the latched messages sent
/// to each new subscriber.
struct Listener {
    player: Arc<Mutex<Player>>,
    latched: Arc<Latched>,
}

impl ServerListener for Listener {
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        self.latched.resend(&client, channel.id());
    }

    fn on_playback_control_request(&self, req: PlaybackControlRequest) -> Option<PlaybackState> {
        let mut p = self.player.lock().unwrap_or_else(|e| e.into_inner());
        p.playing = req.playback_command == PlaybackCommand::Play;
        if req.playback_speed.is_finite() && req.playback_speed > 0.0 {
            p.speed = req.playback_speed;
        }
        if let Some(t) = req.seek_time {
            p.seek_to = Some(t);
            p.current_ns = t;
        }
        Some(PlaybackState {
            status: if p.playing {
                PlaybackStatus::Playing
            } else {
                PlaybackStatus::Paused
            },
            current_time: p.current_ns,
            playback_speed: p.speed,
            did_seek: req.seek_time.is_some(),
            request_id: Some(req.request_id),
        })
    }
}

/// What the viewer did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ViewReport {
    /// The port it listened on.
    pub port: u16,
    /// Samples it translated.
    pub samples: u64,
}

/// Serves until a signal or `--duration-s`.
pub fn view(args: &ViewArgs) -> Result<ViewReport, SinkError> {
    let (host, port) = split_bind(&args.bind)?;
    if args.backlog == 0 {
        return Err(SinkError::Arg {
            flag: "--backlog",
            problem: "must be at least 1".into(),
        });
    }
    let duration = match args.duration_s {
        None => None,
        Some(s) if s.is_finite() && s > 0.0 => Some(Duration::from_secs_f64(s)),
        Some(s) => {
            return Err(SinkError::Arg {
                flag: "--duration-s",
                problem: format!("must be a positive number of seconds, got {s}"),
            })
        }
    };
    let recording = match &args.file {
        Some(path) => Some(read_recording(path)?),
        None => None,
    };
    let runtime = super::error::runtime()?;
    runtime.block_on(async move {
        let shutdown = crate::signals::shutdown_signal()
            .await
            .map_err(|(s, e)| SinkError::Runtime(format!("cannot install the {s} handler: {e}")))?;
        let ctx = Context::new();
        let player = Arc::new(Mutex::new(Player {
            playing: true,
            speed: 1.0,
            seek_to: None,
            current_ns: 0,
        }));
        // The public socket accepts both names of the protocol (see `ws_names`) and relays to
        // the SDK server on an ephemeral loopback port.
        let public = tokio::net::TcpListener::bind((host.as_str(), port))
            .await
            .map_err(|e| SinkError::Runtime(format!("cannot listen on {host}:{port}: {e}")))?;
        let bound = public
            .local_addr()
            .map_err(|e| SinkError::Runtime(format!("{host}:{port}: {e}")))?
            .port();
        let latched = Arc::new(Latched::default());
        let mut server = WebSocketServer::new()
            .name(format!("flexdyn {}", super::mcap_file::flexdyn_version()))
            .bind("127.0.0.1", 0)
            .context(&ctx)
            .message_backlog_size(args.backlog)
            .capabilities([Capability::Time])
            .listener(Arc::new(Listener {
                player: player.clone(),
                latched: latched.clone(),
            }));
        if let Some(rec) = &recording {
            let first = rec.samples.iter().map(|s| s.log_time_ns).min().unwrap_or(0);
            let last = rec.samples.iter().map(|s| s.log_time_ns).max().unwrap_or(0);
            player.lock().unwrap_or_else(|e| e.into_inner()).current_ns = first;
            server = server
                .capabilities([Capability::Time, Capability::PlaybackControl])
                .playback_time_range(first, last);
        }
        let handle = Arc::new(
            server
                .start()
                .await
                .map_err(|e| SinkError::Runtime(format!("cannot serve on {host}:{port}: {e}")))?,
        );
        let upstream = std::net::SocketAddr::from(([127, 0, 0, 1], handle.port()));
        let relay = tokio::spawn(super::ws_names::serve(public, upstream));
        // Once, with the port in use (`--bind HOST:0` picks one): the page and the protocol
        // share it (`ws_names`).
        let url_host = if host.contains(':') {
            format!("[{host}]")
        } else {
            host.clone()
        };
        tracing::info!(
            "view: open http://{url_host}:{bound}/ in a browser, or connect Foxglove to ws://{url_host}:{bound}"
        );
        let translator = Arc::new(Mutex::new(Translator::new(
            ctx.clone(),
            latched,
            args.sc_id.clone(),
        )));
        let samples = Arc::new(std::sync::atomic::AtomicU64::new(0));
        let stop = async {
            let mut shutdown = std::pin::pin!(shutdown);
            match duration {
                Some(d) => {
                    tokio::select! {
                        () = tokio::time::sleep(d) => {},
                        () = &mut shutdown => {},
                    }
                }
                None => shutdown.await,
            }
        };
        match recording {
            Some(rec) => {
                {
                    let mut t = translator.lock().unwrap_or_else(|e| e.into_inner());
                    for v in rec.vehicles() {
                        t.describe(&v);
                    }
                    let keys: std::collections::BTreeSet<&str> =
                        rec.samples.iter().map(|s| s.key.as_str()).collect();
                    for key in keys {
                        t.advertise(key);
                    }
                }
                let mut samples_sorted = rec.samples;
                samples_sorted.sort_by_key(|s| s.log_time_ns);
                let player_task = play(
                    samples_sorted,
                    translator.clone(),
                    player,
                    handle_time_sink(&handle),
                    samples.clone(),
                );
                tokio::select! {
                    () = stop => {},
                    () = player_task => {},
                }
            }
            None => {
                let zcfg = zenoh_config(&args.zenoh, Role::Tool)?;
                let session = zenoh::open(zcfg)
                    .await
                    .map_err(|e| SinkError::zenoh("open the session", e))?;
                let patterns: Vec<String> = if args.sc_id.is_empty() {
                    vec!["*".into()]
                } else {
                    args.sc_id.clone()
                };
                for p in &patterns {
                    for v in super::record_cmd::query_vehicles(&session, p).await {
                        translator.lock().unwrap_or_else(|e| e.into_inner()).describe(&v);
                    }
                }
                let (new_tx, mut new_rx) = tokio::sync::mpsc::unbounded_channel::<String>();
                let mut subs = Vec::new();
                for p in &patterns {
                    let t = translator.clone();
                    let n = samples.clone();
                    let new_tx = new_tx.clone();
                    let clock = handle.clone();
                    let sub = session
                        .declare_subscriber(format!("flexdyn/{p}/**"))
                        .callback(move |sample| {
                            if sample.kind() != SampleKind::Put {
                                return;
                            }
                            let key = sample.key_expr().as_str();
                            let mut t = t.lock().unwrap_or_else(|e| e.into_inner());
                            if let Some(topic) = classify(key) {
                                if !t.geometry.contains_key(topic.sc_id) {
                                    let _ = new_tx.send(topic.sc_id.to_owned());
                                }
                            }
                            t.sample(key, &sample.payload().to_bytes());
                            let announce = t.clock_due(false);
                            drop(t);
                            n.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            // The clock moves with the data, not once a second behind it.
                            if let Some(time) = announce {
                                clock.broadcast_time(time);
                            }
                        })
                        .await
                        .map_err(|e| SinkError::zenoh("declare the subscriber", e))?;
                    subs.push(sub);
                }
                let mut asked = std::collections::HashSet::new();
                let mut stop = std::pin::pin!(stop);
                let mut tick = tokio::time::interval(SCENE_PERIOD);
                loop {
                    tokio::select! {
                        () = &mut stop => break,
                        _ = tick.tick() => {
                            let mut t = translator.lock().unwrap_or_else(|e| e.into_inner());
                            t.send_scenes();
                            // The latest time, if the stream paused within CLOCK_PERIOD of it.
                            if let Some(time) = t.clock_due(true) {
                                handle.broadcast_time(time);
                            }
                        }
                        Some(sc) = new_rx.recv() => {
                            if asked.insert(sc.clone()) {
                                for v in super::record_cmd::query_vehicles(&session, &sc).await {
                                    translator.lock().unwrap_or_else(|e| e.into_inner()).describe(&v);
                                }
                            }
                        }
                    }
                }
                drop(subs);
                let _ = session.close().await;
            }
        }
        relay.abort();
        if let Ok(h) = Arc::try_unwrap(handle) {
            let _ = h.stop();
        }
        Ok(ViewReport {
            port: bound,
            samples: samples.load(std::sync::atomic::Ordering::Relaxed),
        })
    })
}

/// Announces playback time and state to the viewers.
type TimeSink = Arc<dyn Fn(u64, Option<PlaybackState>) + Send + Sync>;

fn handle_time_sink(handle: &Arc<foxglove::WebSocketServerHandle>) -> TimeSink {
    let h = handle.clone();
    Arc::new(move |t, state| {
        h.broadcast_time(t);
        if let Some(s) = state {
            h.broadcast_playback_state(s);
        }
    })
}

/// Plays `samples` (sorted by log time) at the player's speed from its current time, honouring
/// pause and seek; at the end it reports `Ended` and waits for a seek.
async fn play(
    samples: Vec<RawSample>,
    translator: Arc<Mutex<Translator>>,
    player: Arc<Mutex<Player>>,
    time_sink: TimeSink,
    count: Arc<std::sync::atomic::AtomicU64>,
) {
    let mut index = 0usize;
    let mut anchor: Option<(Instant, u64)> = None;
    let mut ended = false;
    let mut scene_at = Instant::now();
    loop {
        let (playing, speed, seek) = {
            let mut p = player.lock().unwrap_or_else(|e| e.into_inner());
            (p.playing, p.speed, p.seek_to.take())
        };
        if let Some(t) = seek {
            index = samples.partition_point(|s| s.log_time_ns < t);
            anchor = None;
            ended = false;
        }
        if !playing {
            anchor = None;
        } else if index < samples.len() {
            let (wall0, sim0) = *anchor.get_or_insert((Instant::now(), samples[index].log_time_ns));
            let now_sim = sim0 + (wall0.elapsed().as_secs_f64() * 1e9 * f64::from(speed)) as u64;
            {
                let mut t = translator.lock().unwrap_or_else(|e| e.into_inner());
                while index < samples.len() && samples[index].log_time_ns <= now_sim {
                    t.sample(&samples[index].key, &samples[index].payload);
                    count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    index += 1;
                }
                if scene_at.elapsed() >= SCENE_PERIOD {
                    t.send_scenes();
                    scene_at = Instant::now();
                }
            }
            player.lock().unwrap_or_else(|e| e.into_inner()).current_ns = now_sim;
            time_sink(now_sim, None);
        } else if !ended {
            ended = true;
            let p = player.lock().unwrap_or_else(|e| e.into_inner());
            time_sink(
                p.current_ns,
                Some(PlaybackState {
                    status: PlaybackStatus::Ended,
                    current_time: p.current_ns,
                    playback_speed: p.speed,
                    did_seek: false,
                    request_id: None,
                }),
            );
        }
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bind_addresses_name_the_problem() {
        assert_eq!(
            split_bind("127.0.0.1:8765").unwrap(),
            ("127.0.0.1".into(), 8765)
        );
        assert_eq!(split_bind("[::1]:0").unwrap(), ("::1".into(), 0));
        for bad in ["8765", "127.0.0.1:x", ":8765", "127.0.0.1:70000"] {
            let e = split_bind(bad).unwrap_err().to_string();
            assert!(e.starts_with("--bind: "), "{bad}: {e}");
        }
    }
}
