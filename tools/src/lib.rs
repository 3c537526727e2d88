//! flexdyn-tools: companion binaries of the flexdyn server.
//!
//! # Layout
//! - `src/bin/flexdyn-acs-demo.rs`: demo MRP PD attitude controller, the template for flight
//!   code (works in real time and lockstep).
//! - `src/bin/flexdyn-monitor.rs`: live telemetry and status for operators: a terminal UI
//!   with sparklines ([`monitor_tui`]), or one summary line per interval (`--plain`).
//! - `src/bin/flexdyn-pingpong.rs`: plain Zenoh round trips, the yardstick of the lockstep
//!   benchmark.
//! - this library: [`CommonArgs`] (the connection options every tool shares) and [`pingpong`].
//!
//! Every tool builds its Zenoh configuration with [`flexdyn::transport::zenoh_config`]
//! ([`Role::Tool`]): peer mode, connect to `tcp/127.0.0.1:7447`, listen nowhere, multicast
//! scouting always off.

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use flexdyn::transport::{zenoh_config, Role, ZenohArgs};
use flexdyn_proto::Topics;
use zenoh::{Session, Wait};

pub mod acs;
pub mod monitor_tui;
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
        Topics::new(&self.sc_id).map_err(|e| usage(format!("--sc-id {:?}: {e}", self.sc_id)))
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
pub use flexdyn::logging::init_tracing;

/// Invalid input on the command line (a bad option value): the tool exits with code 2.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// A [`UsageError`] as an `anyhow::Error`.
pub fn usage(message: impl Into<String>) -> anyhow::Error {
    UsageError(message.into()).into()
}

/// Parses a tool's command line with the rules of `flexdyn` (see
/// [`flexdyn::logging::parse_args`]).
pub use flexdyn::logging::parse_args;

/// The exit code and one `error:` line for a tool's result: 0 on success; 2 for a
/// [`UsageError`] or an invalid Zenoh configuration; 1 for a failure while running. The error's
/// causes are joined on one line, with Zenoh's source paths removed.
pub fn exit_with(result: anyhow::Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let bad_input = e
                .chain()
                .any(|c| c.is::<UsageError>() || c.is::<flexdyn::transport::ZenohConfigError>());
            let line = format!("{e:#}").replace('\n', " ");
            flexdyn::logging::print_error(flexdyn::transport::clean_zenoh_message(&line));
            ExitCode::from(if bad_input { 2 } else { 1 })
        }
    }
}

/// A flag set on the first SIGINT or SIGTERM, for a tool's loop to check: the tool then
/// undeclares, closes its session and exits 0. A handler is installed even where the shell
/// started the tool with SIGINT ignored (a background job of a non-interactive shell).
pub fn stop_on_signals() -> anyhow::Result<Arc<AtomicBool>> {
    let flag = Arc::new(AtomicBool::new(false));
    let set = flag.clone();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_io()
        .build()
        .map_err(|e| anyhow::anyhow!("cannot start the signal listener: {e}"))?;
    #[cfg(unix)]
    let (mut int, mut term) = {
        use tokio::signal::unix::{signal, SignalKind};
        let _guard = runtime.enter();
        (
            signal(SignalKind::interrupt())
                .map_err(|e| anyhow::anyhow!("cannot handle SIGINT: {e}"))?,
            signal(SignalKind::terminate())
                .map_err(|e| anyhow::anyhow!("cannot handle SIGTERM: {e}"))?,
        )
    };
    std::thread::Builder::new()
        .name("flexdyn-signals".into())
        .spawn(move || {
            runtime.block_on(async move {
                #[cfg(unix)]
                tokio::select! {
                    _ = int.recv() => {}
                    _ = term.recv() => {}
                }
                #[cfg(not(unix))]
                let _ = tokio::signal::ctrl_c().await;
            });
            set.store(true, Ordering::Relaxed);
        })
        .map_err(|e| anyhow::anyhow!("cannot start the signal listener: {e}"))?;
    Ok(flag)
}

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
