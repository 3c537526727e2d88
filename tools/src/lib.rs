//! flexdyn-tools: companion binaries of the flexdyn server.
//!
//! # Layout
//! - `src/bin/flexdyn-monitor.rs`: live telemetry and status for operators: a terminal UI
//!   with sparklines ([`monitor_tui`]), or one summary line per interval (`--plain`).
//! - `src/bin/flexdyn-pingpong.rs`: plain Zenoh round trips, the yardstick of the lockstep
//!   benchmark.
//! - this library: [`CommonArgs`] (the connection options every tool shares) and [`pingpong`].
//!
//! The demo flight code, `flexdyn-acs-demo`, is its own package (`clients/rust/acs-demo`): a
//! template to copy must not link the simulator.
//!
//! Every tool builds its Zenoh configuration with [`flexdyn_proto::client::transport::zenoh_config`]
//! (`Role::Tool`): peer mode, connect to `tcp/127.0.0.1:7447`, listen nowhere, multicast
//! scouting always off.

pub mod monitor_tui;
pub mod pingpong;

/// The connection options, error rules and signal handling every tool shares, from
/// `flexdyn_proto::client` (flight code such as `flexdyn-acs-demo` uses the same).
pub use flexdyn_proto::client::cli::{exit_with, stop_on_signals, usage, CommonArgs, UsageError};
/// Logs to stderr at `RUST_LOG` (default `info`): the server's own setup.
pub use flexdyn_proto::client::logging::init_tracing;
/// Parses a tool's command line with the rules of `flexdyn` (see
/// [`flexdyn_proto::client::logging::parse_args`]).
pub use flexdyn_proto::client::logging::parse_args;

/// Percentile `q` (0..=1) of sorted values (nearest rank); `None` if empty.
pub fn percentile<T: Copy>(sorted: &[T], q: f64) -> Option<T> {
    if sorted.is_empty() {
        return None;
    }
    let rank = (q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64).round() as usize;
    sorted.get(rank).copied()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles() {
        let v: Vec<u32> = (0..=100).collect();
        assert_eq!(percentile(&v, 0.5), Some(50));
        assert_eq!(percentile(&v, 0.99), Some(99));
        assert_eq!(percentile(&v, 1.0), Some(100));
        assert_eq!(percentile::<u32>(&[], 0.5), None);
    }
}
