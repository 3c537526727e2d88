//! Harness for the server tests: loopback sessions built with the one config builder
//! (multicast scouting off), an in-process server with a bounded join, and condition waits.

use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use flexdyn_proto::client::transport::{zenoh_config, Role, ZenohArgs};
use flexdyn_proto::{decode_state, decode_status, Mode, StateMsg, StatusMsg, Topics};
use flexdyn_server as server;
use flexdyn_vehicle::checkpoint::Source;
use flexdyn_vehicle::config::{SimConfig, DEFAULT_CONFIG_TOML};
use zenoh::{Session, Wait};

// Ports the OS gave a process, read back; shared with the test files without this harness.
pub use flexdyn_testkit::ports;
#[allow(unused_imports)]
pub use ports::{port_of, reporting, ws_port, zenoh_endpoint, ANY_PORT};

/// `tcp/127.0.0.1:<port>`.
pub fn endpoint(port: u16) -> String {
    format!("tcp/127.0.0.1:{port}")
}

/// A session listening on a port the OS chose, and that port.
pub fn listening_session() -> (Session, u16) {
    let args = ZenohArgs {
        listen: vec![ANY_PORT.into()],
        ..ZenohArgs::default()
    };
    let session = zenoh::open(zenoh_config(&args, Role::Server).unwrap())
        .wait()
        .unwrap();
    let port = session_port(&session);
    (session, port)
}

/// Waits until `server_session` routes `key` to a subscriber (one declared on a session
/// connected to it): a real-time run starts publishing at once, and a subscription that reaches
/// the server later misses the first frames (CI saw a stream start at tick 10 of 40). Zenoh's
/// matching status of a probe publisher on the server's own session says when it is there.
pub fn wait_for_subscriber(server_session: &Session, key: &str) {
    let probe = server_session
        .declare_publisher(key.to_owned())
        .wait()
        .unwrap();
    assert!(
        wait_until(Duration::from_secs(10), || probe
            .matching_status()
            .wait()
            .is_ok_and(|m| m.matching())),
        "no subscriber on {key} reached the server"
    );
}

/// The port `session` listens on (its first listen endpoint).
pub fn session_port(session: &Session) -> u16 {
    let endpoints = flexdyn_proto::client::transport::listening_on(session);
    port_of(endpoints.first().expect("the session listens nowhere"))
}

/// A session connecting to `port`.
pub fn connecting_session(port: u16) -> Session {
    let args = ZenohArgs {
        connect: vec![endpoint(port)],
        ..ZenohArgs::default()
    };
    zenoh::open(zenoh_config(&args, Role::Tool).unwrap())
        .wait()
        .unwrap()
}

/// The embedded reference spacecraft at `frame_hz`.
pub fn reference_config(frame_hz: f64) -> SimConfig {
    reference_config_with(frame_hz, "")
}

/// The embedded reference spacecraft at `frame_hz`, with the TOML `extra` appended (for
/// example a `[[fsw_streams]]` declaration).
pub fn reference_config_with(frame_hz: f64, extra: &str) -> SimConfig {
    let text =
        DEFAULT_CONFIG_TOML.replace("frame_hz = 100.0 ", &format!("frame_hz = {frame_hz:?} "));
    SimConfig::from_toml_str(&format!("{text}{extra}")).unwrap()
}

/// Polls `cond` every millisecond until it holds or `timeout` passes.
pub fn wait_until(timeout: Duration, mut cond: impl FnMut() -> bool) -> bool {
    let give_up = Instant::now() + timeout;
    loop {
        if cond() {
            return true;
        }
        if Instant::now() >= give_up {
            return false;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// Everything a test observer saw: decoded states (with the attachment stamp) and statuses.
#[derive(Default)]
pub struct Seen {
    pub states: Vec<(StateMsg, Option<u64>)>,
    pub statuses: Vec<StatusMsg>,
}

/// Subscribes to a spacecraft's state and status topics.
pub struct Observer {
    pub seen: Arc<Mutex<Seen>>,
    pub session: Session,
    _subs: Vec<zenoh::pubsub::Subscriber<()>>,
}

impl Observer {
    pub fn start(port: u16, topics: &Topics) -> Self {
        let session = connecting_session(port);
        let seen: Arc<Mutex<Seen>> = Arc::default();
        let s = seen.clone();
        let states = session
            .declare_subscriber(topics.state().to_owned())
            .callback(move |sample| {
                if let Ok(st) = decode_state(&sample.payload().to_bytes()) {
                    let stamp = server::frame_stamp_ns(&sample);
                    s.lock().unwrap().states.push((st, stamp));
                }
            })
            .wait()
            .unwrap();
        let s = seen.clone();
        let statuses = session
            .declare_subscriber(topics.status().to_owned())
            .callback(move |sample| {
                if let Ok(st) = decode_status(&sample.payload().to_bytes()) {
                    s.lock().unwrap().statuses.push(st);
                }
            })
            .wait()
            .unwrap();
        Self {
            seen,
            session,
            _subs: vec![states, statuses],
        }
    }

    pub fn last_tick(&self) -> Option<u64> {
        self.seen
            .lock()
            .unwrap()
            .states
            .last()
            .map(|(s, _)| s.header.tick)
    }

    pub fn last_status(&self) -> Option<StatusMsg> {
        self.seen.lock().unwrap().statuses.last().copied()
    }
}

/// A server run on its own runtime in a background thread, with a bounded join: `R` is its
/// report ([`ServerHandle`]: `server::run`; [`FleetServerHandle`]: `server::fleet::run`).
pub struct Handle<R> {
    /// The port the server's session listens on.
    pub port: u16,
    done: std::sync::mpsc::Receiver<Result<R, server::ServerError>>,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
}

/// `server::run` in the background.
pub type ServerHandle = Handle<server::RunReport>;
/// `server::fleet::run` in the background.
pub type FleetServerHandle = Handle<server::fleet::FleetReport>;

/// The shutdown future a [`Handle`] hands its server.
pub type Shutdown = std::pin::Pin<Box<dyn std::future::Future<Output = ()> + Send>>;

impl<R: Send + 'static> Handle<R> {
    /// Runs `run(session, shutdown)` on a runtime of its own, then closes the session.
    fn spawn<F, Fut>(session: Session, run: F) -> Self
    where
        F: FnOnce(Session, Shutdown) -> Fut + Send + 'static,
        Fut: std::future::Future<Output = Result<R, server::ServerError>>,
    {
        let port = session_port(&session);
        let (done_tx, done) = std::sync::mpsc::channel();
        let (stop_tx, stop_rx) = tokio::sync::oneshot::channel::<()>();
        std::thread::spawn(move || {
            let rt = tokio::runtime::Builder::new_multi_thread()
                .worker_threads(2)
                .enable_all()
                .build()
                .unwrap();
            let result = rt.block_on(async {
                let shutdown: Shutdown = Box::pin(async {
                    let _ = stop_rx.await;
                });
                let r = run(session.clone(), shutdown).await;
                let _ = session.close().await;
                r
            });
            let _ = done_tx.send(result);
        });
        Self {
            port,
            done,
            stop: Some(stop_tx),
        }
    }

    /// Completes the shutdown future (like SIGINT).
    pub fn stop(&mut self) {
        if let Some(s) = self.stop.take() {
            let _ = s.send(());
        }
    }

    /// The run's result, waiting at most `timeout`.
    pub fn join(&self, timeout: Duration) -> Result<R, server::ServerError> {
        self.done
            .recv_timeout(timeout)
            .expect("the server did not finish in time")
    }
}

impl ServerHandle {
    /// On a session listening on a port the OS chose ([`Self::port`]).
    pub fn start(settings: server::ServerSettings, cfg: SimConfig) -> Self {
        Self::start_with_session(listening_session().0, settings, cfg)
    }

    /// [`Self::start`] on a session the caller opened (e.g. with an authenticating config).
    pub fn start_with_session(
        session: Session,
        settings: server::ServerSettings,
        cfg: SimConfig,
    ) -> Self {
        Self::spawn(session, move |session, shutdown| {
            server::run(session, settings, cfg, shutdown)
        })
    }

    /// A lockstep server ([`Self::start`]) on the scenario file `scenario`, waiting for
    /// `participants` (60 s for an answer, 120 s for their tokens), for `duration_ns` of
    /// simulated time.
    pub fn lockstep_on(scenario: &Path, participants: Vec<u32>, duration_ns: u64) -> Self {
        let cfg = Source::of(Some(scenario)).unwrap().config().unwrap();
        Self::start(
            server::ServerSettings {
                mode: Mode::Lockstep,
                participants,
                participant_timeout: Duration::from_secs(60),
                presence_timeout: Duration::from_secs(120),
                duration_ns: Some(duration_ns),
                ..server::ServerSettings::default()
            },
            cfg,
        )
    }
}

impl FleetServerHandle {
    /// On a session listening on a port the OS chose ([`Self::port`]).
    pub fn start(
        settings: server::ServerSettings,
        fleet: flexdyn_vehicle::world::FleetConfig,
    ) -> Self {
        Self::spawn(listening_session().0, move |session, shutdown| {
            server::fleet::run(session, settings, fleet, shutdown)
        })
    }
}
