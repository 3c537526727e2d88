//! Free loopback TCP ports, asked of the OS: bind `127.0.0.1:0`, read the port the kernel chose,
//! release it. Every test that needs a Zenoh endpoint or a WebSocket port takes one here, so test
//! binaries can run side by side and never collide with a user's server on a hand-picked port
//! (7447, 8765).
//!
//! The kernel picks from its ephemeral range, and a port handed out once is never handed out
//! again by this process, so parallel tests in one binary do not collide either. Between the
//! release and the test's own bind another process could take the port; the kernel spreads its
//! choices over some 28 000 ports, which makes that a rare event rather than a recurring one.
#![allow(dead_code)]

use std::net::TcpListener;
use std::sync::Mutex;

/// Every port this process has handed out.
static GIVEN: Mutex<Vec<u16>> = Mutex::new(Vec::new());

fn bind(port: u16) -> Option<TcpListener> {
    TcpListener::bind(("127.0.0.1", port)).ok()
}

/// `n` consecutive loopback ports, all free now, none handed out before; returns the first.
/// (A campaign's run `i` listens on `base_port + i`.)
pub fn free_port_range(n: u16) -> u16 {
    assert!(n >= 1);
    let mut given = GIVEN.lock().unwrap_or_else(|e| e.into_inner());
    for _ in 0..1000 {
        let first = bind(0)
            .expect("cannot bind 127.0.0.1:0")
            .local_addr()
            .expect("a bound socket has an address")
            .port();
        let Some(last) = first.checked_add(n - 1) else {
            continue;
        };
        if given.iter().any(|p| (first..=last).contains(p)) {
            continue;
        }
        // Held together, so each one is checked while the others are taken.
        let held: Option<Vec<TcpListener>> = (first..=last).map(bind).collect();
        if held.is_some() {
            given.extend(first..=last);
            return first;
        }
    }
    panic!("no {n} consecutive free loopback ports in 1000 tries");
}

/// A loopback port that is free now and that this process has not handed out before.
pub fn free_port() -> u16 {
    free_port_range(1)
}

/// `tcp/127.0.0.1:<a free port>`.
pub fn free_endpoint() -> String {
    format!("tcp/127.0.0.1:{}", free_port())
}
