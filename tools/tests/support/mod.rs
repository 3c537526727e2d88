//! Test harness for end-to-end runs: an in-process flexdyn server on its own loopback port, a
//! recording lockstep participant, and child processes with bounded waits.
#![allow(dead_code)]

use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use flexdyn_proto::Topics;

// The server harness (sessions on the test's own loopback port, the reference config with
// another frame rate, `server::run` in a background thread) is the root package's.
#[path = "../../../tests/server/server_support.rs"]
mod server_support;
// Each test or bench that includes this module uses a different subset.
#[allow(unused_imports)]
pub use server_support::{
    connecting_session, endpoint, listening_session, ports, reference_config, FleetServerHandle,
    ServerHandle,
};

/// Every StateMsg payload seen, with its tick.
pub type Recorded = flexdyn_campaign::execute::Received;

/// A passive lockstep participant living in the test process: records every state payload and
/// answers it with `NoCommand` as `sender_id` (the campaign's observer). Keep it alive.
pub struct Recorder {
    pub states: Recorded,
    _observer: flexdyn_campaign::execute::Observer,
}

impl Recorder {
    pub fn start(port: u16, topics: &Topics, sender_id: u32) -> Self {
        let observer =
            flexdyn_campaign::execute::Observer::start(&endpoint(port), topics, sender_id).unwrap();
        Self {
            states: observer.states.clone(),
            _observer: observer,
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

/// Waits (20 s at most) for a demo whose standard output is piped to exit after its run,
/// checks it succeeded, and returns that output.
pub fn finish_demo(demo: &mut ChildGuard) -> String {
    use std::io::Read as _;
    let status = demo
        .wait_timeout(Duration::from_secs(20))
        .expect("the demo did not exit after the run");
    assert!(status.success(), "the demo failed: {status}");
    let mut transcript = String::new();
    demo.0
        .stdout
        .take()
        .expect("the demo's stdout is piped")
        .read_to_string(&mut transcript)
        .unwrap();
    transcript
}

/// The sha256 (hex) of a run's StateMsg payloads in tick order, checked contiguous from 0.
pub fn digest(states: &[(u64, Vec<u8>)]) -> String {
    use sha2::{Digest as _, Sha256};
    let mut h = Sha256::new();
    for (i, (tick, bytes)) in states.iter().enumerate() {
        assert_eq!(*tick, i as u64, "ticks are not contiguous from 0");
        h.update(bytes);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Round-trip times of `count` StateMsg-sized pings (after `warmup` unmeasured ones) from a
/// session listening on a port the OS chose to a `flexdyn-pingpong pong` child (reply CommandMsg-sized),
/// which answers inside its Zenoh callback or, with `recv_loop`, from a receive loop (the demo
/// controller's structure). The benchmarks' yardstick.
pub fn pingpong_rtts(warmup: usize, count: usize, recv_loop: bool) -> Vec<Duration> {
    use flexdyn_proto::{EFFECTOR_STATE_FIXED_LEN, STATE_FIXED_LEN};
    let topics = Topics::new("bench").unwrap();
    let (session, port) = listening_session();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_flexdyn-pingpong"));
    cmd.args(["--connect", &endpoint(port), "--sc-id", "bench"])
        .args(["pong", "--duration-s", "300"]);
    if recv_loop {
        cmd.arg("--recv-loop");
    }
    let _pong = ChildGuard::spawn(&mut cmd);
    flexdyn_tools::pingpong::ping(
        &session,
        &topics,
        STATE_FIXED_LEN + 2 * (EFFECTOR_STATE_FIXED_LEN + 32),
        warmup,
        count,
        Duration::from_secs(30),
    )
    .expect("ping-pong")
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
