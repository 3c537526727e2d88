//! The `flexdyn` command-line entry point: parses arguments, initialises logging and calls the
//! library. Every error is reported as one `error: …` line on stderr with a non-zero exit code
//! (2 for invalid input, 1 for a failure while running; `flexdyn record` exits 3 when the file
//! it wrote is incomplete); nothing here panics on bad input.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use flexdyn::cli::{self, CliError, SimulateArgs};
use flexdyn_proto::client::logging::print_error;
use flexdyn_server::cli::{run_from_args, RunArgs};
use flexdyn_sinks::{self as sinks, SinkError};
use flexdyn_vehicle::config::DEFAULT_CONFIG_TOML;

/// Real-time flight-software-in-the-loop spacecraft dynamics: rigid hub + dual-hinged panels.
///
/// Without a subcommand, `flexdyn [OPTIONS]` is `flexdyn run [OPTIONS]`.
#[derive(Debug, Parser)]
#[command(
    name = "flexdyn",
    version,
    about,
    long_about = None,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// The `run` options, accepted without the subcommand.
    #[command(flatten)]
    run: Box<RunArgs>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run the server (the default without a subcommand): propagate the spacecraft and talk to
    /// flight code over Zenoh, in real time, lockstep or batch.
    Run(Box<RunArgs>),
    /// Propagate a configuration offline and write the state history as CSV.
    Simulate(SimulateArgs),
    /// Propagate a fleet file (several spacecraft, one tick) offline: states and relative
    /// states as CSV.
    Fleet(flexdyn::world::run::FleetArgs),
    /// Validate a configuration file and print a one-line summary (exit 2 if invalid).
    CheckConfig {
        /// The configuration file (TOML).
        file: PathBuf,
    },
    /// Print the embedded default configuration (scenarios/reference.toml) verbatim.
    PrintDefaultConfig,
    /// Record every sample of flexdyn/<sc-id>/** (all vehicles by default) to an MCAP file.
    Record(sinks::record_cmd::RecordArgs),
    /// Republish a recording's raw channels to Zenoh with the recorded spacing.
    Replay(sinks::replay::ReplayArgs),
    /// Write one CSV per topic of a recording.
    Export(sinks::export::ExportArgs),
    /// Serve the live stream (or a recording) to Foxglove over its WebSocket protocol.
    View(sinks::view::ViewArgs),
    /// Draw PNG figures of a recording or a simulate/export CSV.
    Plot(sinks::plot::PlotArgs),
    /// Monte Carlo campaigns: plan, run (locally or one index at a time), summarize.
    #[command(subcommand)]
    Campaign(flexdyn_campaign::CampaignCommand),
}

/// Runs a sink subcommand and prints its one-line summary on stderr.
fn run_sink<T>(result: Result<T, SinkError>, summary: impl FnOnce(&T) -> String) -> ExitCode {
    match result {
        Ok(r) => {
            let _ = writeln!(std::io::stderr(), "{}", summary(&r));
            ExitCode::SUCCESS
        }
        Err(e) => {
            print_error(&e);
            ExitCode::from(e.exit_code())
        }
    }
}

fn print_default_config() -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_all(DEFAULT_CONFIG_TOML.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|source| CliError::Output {
            target: "stdout".into(),
            source,
        })
}

/// `flexdyn run`: the server until its duration, a signal or an error. Exit code 0 on success,
/// 2 for invalid settings or configuration, 1 for a failure while running.
fn run_server(args: &RunArgs) -> ExitCode {
    if let Some(fleet) = &args.fleet {
        return match flexdyn_server::fleet::run_from_args(args, fleet) {
            Ok(_report) => ExitCode::SUCCESS,
            Err(e) => {
                print_error(&e);
                ExitCode::from(e.exit_code())
            }
        };
    }
    match run_from_args(args) {
        Ok(_report) => ExitCode::SUCCESS,
        Err(e) => {
            print_error(&e);
            ExitCode::from(e.exit_code())
        }
    }
}

fn main() -> ExitCode {
    let args = match flexdyn_proto::client::logging::parse_args::<Cli>() {
        Ok(a) => a,
        Err(code) => return code,
    };
    if matches!(args.command, Some(Command::Campaign(_))) {
        // Each run's server would log its start and end at info: keep the progress bar readable.
        flexdyn_proto::client::logging::init_tracing_at("warn");
    } else {
        flexdyn::cli::init_tracing();
    }
    let result = match args.command {
        Some(Command::Simulate(a)) => cli::simulate(&a).map(|report| {
            let _ = writeln!(std::io::stderr(), "{report}");
        }),
        Some(Command::CheckConfig { file }) => cli::check_config(&file).and_then(|summary| {
            let mut out = std::io::stdout().lock();
            writeln!(out, "{summary}")
                .and_then(|()| out.flush())
                .map_err(|source| CliError::Output {
                    target: "stdout".into(),
                    source,
                })
        }),
        Some(Command::PrintDefaultConfig) => print_default_config(),
        Some(Command::Record(a)) => {
            let result = sinks::record_cmd::record(&a);
            let incomplete = result.as_ref().is_ok_and(|r| !r.complete());
            let code = run_sink(result, |r| {
                format!(
                    "recorded {} samples ({} payload bytes, {} undecodable) to {}; dropped {}; {}",
                    r.stats.samples,
                    r.stats.payload_bytes,
                    r.stats.undecodable,
                    a.output.display(),
                    r.dropped,
                    r.completeness()
                )
            });
            // The file is written and readable, but it is not the whole stream.
            return if incomplete { ExitCode::from(3) } else { code };
        }
        Some(Command::Replay(a)) => {
            return run_sink(sinks::replay::replay(&a), |r| {
                format!(
                    "replayed {} samples in {:.3} s{}{}",
                    r.published,
                    r.wall_s,
                    if r.unheard > 0 {
                        format!(
                            "; {} of them while no subscriber matched their key (nobody \
                             received those)",
                            r.unheard
                        )
                    } else {
                        String::new()
                    },
                    r.truncated
                        .as_ref()
                        .map_or(String::new(), |why| format!(" (file ends early: {why})"))
                )
            })
        }
        Some(Command::Campaign(c)) => {
            return match flexdyn_campaign::main(&c) {
                Ok(report) => {
                    let _ = writeln!(std::io::stderr(), "{}", report.text);
                    ExitCode::from(report.exit_code)
                }
                Err((code, message)) => {
                    let _ = writeln!(std::io::stderr(), "error: {message}");
                    ExitCode::from(code)
                }
            }
        }
        Some(Command::Plot(a)) => {
            return run_sink(sinks::plot::plot(&a), |r| {
                let mut lines: Vec<String> = r
                    .written
                    .iter()
                    .map(|p| format!("wrote {}", p.display()))
                    .collect();
                lines.extend(
                    r.skipped
                        .iter()
                        .map(|(f, why)| format!("skipped {f}: {why}")),
                );
                lines.join("\n")
            })
        }
        Some(Command::View(a)) => {
            return run_sink(sinks::view::view(&a), |r| {
                format!(
                    "viewer on port {} stopped after {} samples",
                    r.port, r.samples
                )
            })
        }
        Some(Command::Export(a)) => {
            return run_sink(sinks::export::export(&a), |r| {
                r.iter()
                    .map(|(p, n)| format!("{}: {n} rows", p.display()))
                    .collect::<Vec<_>>()
                    .join("\n")
            })
        }
        Some(Command::Fleet(a)) => {
            return match flexdyn::world::run::fleet(&a) {
                Ok(r) => {
                    let _ = writeln!(
                        std::io::stderr(),
                        "propagated {} vehicles for {} steps; wrote {} rows",
                        r.vehicles,
                        r.steps,
                        r.rows
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    print_error(&e);
                    ExitCode::from(e.exit_code())
                }
            }
        }
        Some(Command::Run(a)) => return run_server(&a),
        // No subcommand: `flexdyn run` with the options given.
        None => return run_server(&args.run),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            print_error(&e);
            ExitCode::from(e.exit_code())
        }
    }
}
