//! Process signals shared by the server and the sink commands.

/// Installs the handlers, then completes on the first SIGINT or SIGTERM (Ctrl-C only on
/// non-Unix platforms). The error names the signal whose handler could not be installed.
pub async fn shutdown_signal(
) -> Result<impl std::future::Future<Output = ()>, (&'static str, std::io::Error)> {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{signal, SignalKind};
        let mut int = signal(SignalKind::interrupt()).map_err(|e| ("SIGINT", e))?;
        let mut term = signal(SignalKind::terminate()).map_err(|e| ("SIGTERM", e))?;
        Ok(async move {
            let which = tokio::select! {
                _ = int.recv() => "SIGINT",
                _ = term.recv() => "SIGTERM",
            };
            tracing::info!(signal = which, "shutdown signal received");
        })
    }
    #[cfg(not(unix))]
    {
        Ok(async {
            let _ = tokio::signal::ctrl_c().await;
            tracing::info!("Ctrl-C received");
        })
    }
}
