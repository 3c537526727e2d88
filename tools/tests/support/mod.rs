//! The tools' test support: the end-to-end harness every suite shares
//! ([`flexdyn_testkit_server`]: an in-process server, loopback sessions, a recording lockstep
//! participant, child processes), and the ping-pong yardstick run against this package's own
//! `flexdyn-pingpong` binary.

// Each suite uses a different subset.
#[allow(unused_imports)]
pub use flexdyn_testkit_server::*;

/// Round-trip times of `count` StateMsg-sized pings after `warmup` ones, against a
/// `flexdyn-pingpong pong` child ([`flexdyn_tools::pingpong::round_trips`]).
#[allow(dead_code)]
pub fn pingpong_rtts(warmup: usize, count: usize, recv_loop: bool) -> Vec<std::time::Duration> {
    let pong = std::path::Path::new(env!("CARGO_BIN_EXE_flexdyn-pingpong"));
    flexdyn_tools::pingpong::round_trips(pong, warmup, count, recv_loop).expect("ping-pong")
}
