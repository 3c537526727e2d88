//! flexdyn-tools: companion binaries of the flexdyn server.
//!
//! # Layout
//! - `src/bin/flexdyn-acs-demo.rs`: demo MRP PD attitude controller, the template for flight
//!   code (works in real time and lockstep).
//! - `src/bin/flexdyn-monitor.rs`: live one-line summaries of state and status for operators.
//! - `src/bin/flexdyn-pingpong.rs`: plain Zenoh round trips, the yardstick of the lockstep
//!   benchmark.
//! - this library: [`CommonArgs`] (the connection options every tool shares) and [`pingpong`].
//!
//! Every tool builds its Zenoh configuration with [`flexdyn::server::zenoh_config`]
//! ([`Role::Tool`]): peer mode, connect to `tcp/127.0.0.1:7447`, listen nowhere, multicast
//! scouting always off.

use anyhow::Context as _;
use flexdyn::server::{zenoh_config, Role, ZenohArgs};
use flexdyn_proto::Topics;
use zenoh::{Session, Wait};

pub mod pingpong;

/// Connection options shared by every tool (flatten into a binary's arguments with clap).
#[derive(Clone, Debug, PartialEq, Eq, clap::Args)]
pub struct CommonArgs {
    /// Zenoh endpoints and configuration file.
    #[command(flatten)]
    pub zenoh: ZenohArgs,
    /// String spacecraft id: the keys are flexdyn/<SC_ID>/...
    #[arg(long, value_name = "SC_ID", default_value = "sc1")]
    pub sc_id: String,
}

impl Default for CommonArgs {
    fn default() -> Self {
        Self {
            zenoh: ZenohArgs::default(),
            sc_id: "sc1".into(),
        }
    }
}

impl CommonArgs {
    /// The spacecraft's key expressions (validates `--sc-id`).
    pub fn topics(&self) -> anyhow::Result<Topics> {
        Topics::new(&self.sc_id).with_context(|| format!("--sc-id {:?}", self.sc_id))
    }

    /// The tool's Zenoh configuration.
    pub fn zenoh_config(&self) -> anyhow::Result<zenoh::Config> {
        Ok(zenoh_config(&self.zenoh, Role::Tool)?)
    }

    /// Opens the Zenoh session (blocking; usable without an async runtime).
    pub fn open_session(&self) -> anyhow::Result<Session> {
        zenoh::open(self.zenoh_config()?)
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot open the Zenoh session: {e}"))
    }
}

/// Logs to stderr at `RUST_LOG` (default `info`): the server's own setup.
pub use flexdyn::cli::init_tracing;

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
