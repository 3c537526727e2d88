//! Test harness for end-to-end runs: an in-process flexdyn server on its own loopback port, a
//! recording lockstep participant, and child processes with bounded waits.
#![allow(dead_code)]

use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use flexdyn::config::{SimConfig, DEFAULT_CONFIG_TOML};
use flexdyn::server::{self, zenoh_config, Role, ZenohArgs};
use flexdyn_proto::{decode_state, encode, CommandMsg, Header, Topics};
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

/// `tcp/127.0.0.1:<port>`.
pub fn endpoint(port: u16) -> String {
    format!("tcp/127.0.0.1:{port}")
}

/// A session listening on `port` (loopback, multicast scouting off: the one config builder).
pub fn listening_session(port: u16) -> Session {
    let args = ZenohArgs {
        listen: vec![endpoint(port)],
        ..ZenohArgs::default()
    };
    zenoh::open(zenoh_config(&args, Role::Server).unwrap())
        .wait()
        .unwrap()
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

/// The embedded reference spacecraft with its frame rate replaced.
pub fn reference_config(frame_hz: f64) -> SimConfig {
    let text =
        DEFAULT_CONFIG_TOML.replace("frame_hz = 100.0 ", &format!("frame_hz = {frame_hz:?} "));
    assert!(
        frame_hz == 100.0 || text != DEFAULT_CONFIG_TOML,
        "frame_hz line not found"
    );
    SimConfig::from_toml_str(&text).unwrap()
}

/// Every StateMsg payload seen, with its tick.
pub type Recorded = Arc<Mutex<Vec<(u64, Vec<u8>)>>>;

/// A passive lockstep participant living in the test process: records every state payload and
/// answers it with `NoCommand` as `sender_id`. Keep the returned handles alive.
pub struct Recorder {
    pub states: Recorded,
    _session: Session,
    _sub: zenoh::pubsub::Subscriber<()>,
    _token: zenoh::liveliness::LivelinessToken,
}

impl Recorder {
    pub fn start(port: u16, topics: &Topics, sender_id: u32) -> Self {
        let session = connecting_session(port);
        let states: Recorded = Arc::default();
        let publisher = session
            .declare_publisher(topics.cmd_wrench().to_owned())
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .unwrap();
        let rec = states.clone();
        let mut seq = 0u64;
        let sub = session
            .declare_subscriber(topics.state().to_owned())
            .callback_mut(move |sample| {
                let bytes = sample.payload().to_bytes().into_owned();
                let Ok(state) = decode_state(&bytes) else {
                    return;
                };
                let h = state.header;
                rec.lock().unwrap().push((h.tick, bytes));
                let cmd = CommandMsg::no_command(
                    Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, seq),
                    sender_id,
                );
                seq += 1;
                let _ = publisher.put(encode(&cmd)).wait();
            })
            .wait()
            .unwrap();
        let token = session
            .liveliness()
            .declare_token(topics.participant(sender_id))
            .wait()
            .unwrap();
        Self {
            states,
            _session: session,
            _sub: sub,
            _token: token,
        }
    }

    /// The highest tick recorded so far.
    pub fn last_tick(&self) -> Option<u64> {
        self.states.lock().unwrap().last().map(|(t, _)| *t)
    }

    /// Waits (bounded) until a tick ≥ `tick` is recorded.
    pub fn wait_for_tick(&self, tick: u64, timeout: Duration) -> bool {
        let give_up = Instant::now() + timeout;
        while Instant::now() < give_up {
            if self.last_tick().is_some_and(|t| t >= tick) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        false
    }
}

/// Runs `server::run` on a fresh runtime in a background thread; returns a handle whose `join`
/// is bounded. Dropping the stop sender (or calling `stop`) shuts the server down.
pub struct ServerHandle {
    pub done: std::sync::mpsc::Receiver<Result<server::RunReport, server::ServerError>>,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
}

impl ServerHandle {
    pub fn start(port: u16, settings: server::ServerSettings, cfg: SimConfig) -> Self {
        let (done_tx, done) = std::sync::mpsc::channel();
        let (stop_tx, stop_rx) = tokio::sync::oneshot::channel::<()>();
        let session = listening_session(port);
        std::thread::spawn(move || {
            let rt = tokio::runtime::Builder::new_multi_thread()
                .worker_threads(2)
                .enable_all()
                .build()
                .unwrap();
            let result = rt.block_on(async {
                let shutdown = async {
                    let _ = stop_rx.await;
                };
                let r = server::run(session.clone(), settings, cfg, shutdown).await;
                let _ = session.close().await;
                r
            });
            let _ = done_tx.send(result);
        });
        Self {
            done,
            stop: Some(stop_tx),
        }
    }

    pub fn stop(&mut self) {
        if let Some(s) = self.stop.take() {
            let _ = s.send(());
        }
    }

    /// The run's result, waiting at most `timeout`.
    pub fn join(&self, timeout: Duration) -> Result<server::RunReport, server::ServerError> {
        self.done
            .recv_timeout(timeout)
            .expect("the server did not finish in time")
    }
}

/// A child process that is killed when dropped.
pub struct ChildGuard(pub Child);

impl ChildGuard {
    pub fn spawn(cmd: &mut Command) -> Self {
        Self(
            cmd.stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("spawn child"),
        )
    }

    pub fn id(&self) -> u32 {
        self.0.id()
    }

    /// Waits at most `timeout` for the child to exit.
    pub fn wait_timeout(&mut self, timeout: Duration) -> Option<ExitStatus> {
        let give_up = Instant::now() + timeout;
        loop {
            if let Some(s) = self.0.try_wait().unwrap() {
                return Some(s);
            }
            if Instant::now() >= give_up {
                return None;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Sends `signal` (e.g. `-STOP`) to `pid` with the `kill` utility.
pub fn signal(pid: u32, signal: &str) {
    let status = Command::new("kill")
        .arg(signal)
        .arg(pid.to_string())
        .status()
        .expect("run kill");
    assert!(status.success(), "kill {signal} {pid} failed");
}
