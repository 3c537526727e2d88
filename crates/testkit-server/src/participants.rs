//! Flight code in the loop, for the end-to-end suites: a recording lockstep participant living
//! in the test process, child processes (demo controllers, servers) killed on drop and waited
//! for with a bound, and the digest the lockstep hashes are pinned by.

use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use flexdyn_proto::Topics;

use super::server::endpoint;

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

/// Sends `signal` (e.g. `-STOP`) to `pid` with the `kill` utility.
pub fn signal(pid: u32, signal: &str) {
    let status = Command::new("kill")
        .arg(signal)
        .arg(pid.to_string())
        .status()
        .expect("run kill");
    assert!(status.success(), "kill {signal} {pid} failed");
}
