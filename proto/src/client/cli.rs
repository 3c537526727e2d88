//! The command-line conventions of every flexdyn program that connects to a server (the tools
//! and flight code such as `flexdyn-acs-demo`): the shared connection options, usage errors
//! (exit 2) against failures (exit 1) on one `error:` line, and a clean stop on SIGINT/SIGTERM.

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use crate::Topics;
use zenoh::{Session, Wait};

use crate::client::transport::{zenoh_config, Role, ZenohArgs, ZenohConfigError};

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

/// The exit code and one `error:` line for a tool's result: 0 on success; 2 for a
/// [`UsageError`] or an invalid Zenoh configuration; 1 for a failure while running. The error's
/// causes are joined on one line, with Zenoh's source paths removed.
pub fn exit_with(result: anyhow::Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let bad_input = e
                .chain()
                .any(|c| c.is::<UsageError>() || c.is::<ZenohConfigError>());
            let line = format!("{e:#}").replace('\n', " ");
            crate::client::logging::print_error(crate::client::transport::clean_zenoh_message(
                &line,
            ));
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
