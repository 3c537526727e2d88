//! Logging setup shared by `flexdyn` and the tools, an error line that never panics, and the
//! command-line parsing that gives every binary the same usage-error rule.
//!
//! - Logs go to stderr at `RUST_LOG` (default `info`).
//! - Colour only when stderr is a terminal: a file or a pipe gets plain text.
//! - A closed or broken stderr (`flexdyn 2>&1 | tee log`, then Ctrl-C kills `tee` first) never
//!   takes the process down: the writer drops what it cannot write (EPIPE included), so neither
//!   `tracing-subscriber` nor its internal error printing ever sees a failed write.
//! - Zenoh's `Scouting delay elapsed before start conditions are met` warning is filtered out.
//!   Zenoh logs it at every session open that has `connect` endpoints and waits for its start
//!   conditions; with multicast scouting off (always, here) nothing is being scouted, so the
//!   warning reports nothing a user can act on. Raising that one module to `error` hides it;
//!   `RUST_LOG=zenoh::net::runtime::orchestrator=warn` brings it back.

use std::io::{self, IsTerminal, Write};

/// The filter directive that hides Zenoh's scouting-delay warning (see the module docs).
pub const QUIET_SCOUTING: &str = "zenoh::net::runtime::orchestrator=error";

/// stderr, with every write error swallowed (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct LossyStderr;

impl Write for LossyStderr {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        // A log line that cannot be written is dropped, never an error.
        let _ = io::stderr().write_all(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        let _ = io::stderr().flush();
        Ok(())
    }
}

/// Logs to stderr at `RUST_LOG` (default `info`), shared by `flexdyn` and the tools. Does
/// nothing if a subscriber is already installed.
pub fn init_tracing() {
    init_tracing_at("info");
}

/// [`init_tracing`] with `default` (e.g. `warn`) as the level when `RUST_LOG` is unset: for
/// commands whose own output would drown in the servers' info lines (`campaign run`).
pub fn init_tracing_at(default: &str) {
    let env = std::env::var("RUST_LOG").unwrap_or_default();
    let mut directives = if env.trim().is_empty() {
        default.to_string()
    } else {
        env.clone()
    };
    // A user who names the orchestrator module decides for themselves.
    if !env.contains("zenoh::net::runtime::orchestrator") {
        directives.push(',');
        directives.push_str(QUIET_SCOUTING);
    }
    let filter = tracing_subscriber::EnvFilter::try_new(&directives)
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(format!("info,{QUIET_SCOUTING}")));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_ansi(io::stderr().is_terminal())
        .with_writer(|| LossyStderr)
        .try_init();
}

/// Prints `error: <message>` on stderr, ignoring a closed stderr (unlike `eprintln!`, which
/// panics on EPIPE).
pub fn print_error(message: impl std::fmt::Display) {
    let _ = writeln!(io::stderr(), "error: {message}");
}

/// clap's usage error as one line: its first line without the `error: ` prefix, plus the
/// `--help` hint (clap prints usage and tips on further lines).
pub fn usage_line(clap_message: &str) -> String {
    let first = clap_message
        .lines()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("invalid command line");
    let first = first.strip_prefix("error: ").unwrap_or(first).trim();
    format!("{first} (see --help)")
}

/// Parses a binary's command line with the rule every flexdyn binary follows: a usage error is
/// one `error:` line ([`usage_line`]) with exit code 2; `--help` and `--version` print and
/// exit 0. `Err` carries the exit code to return.
///
/// First of all it checks that the processor has the instructions this build uses
/// ([`super::cpu::check`]): if not, one `error:` line naming them, and exit code 1.
pub fn parse_args<A: clap::Parser>() -> Result<A, std::process::ExitCode> {
    if let Err(message) = super::cpu::check() {
        print_error(message);
        return Err(std::process::ExitCode::FAILURE);
    }
    match A::try_parse() {
        Ok(a) => Ok(a),
        Err(e) => match e.kind() {
            clap::error::ErrorKind::DisplayHelp
            | clap::error::ErrorKind::DisplayVersion
            | clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                let _ = e.print();
                Err(std::process::ExitCode::SUCCESS)
            }
            _ => {
                print_error(usage_line(&e.to_string()));
                Err(std::process::ExitCode::from(2))
            }
        },
    }
}
