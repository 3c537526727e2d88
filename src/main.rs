//! The `flexdyn` command-line entry point: parses the arguments, sets up logging and calls the
//! subcommand's `main` (one file per subcommand under `src/commands/`), which prints its summary
//! or its one `error: …` line and returns the exit code (2 for invalid input, 1 for a failure
//! while running; `flexdyn record` exits 3 when the file it wrote is incomplete). Nothing here
//! panics on bad input.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use flexdyn::commands;
use flexdyn_server::cli::RunArgs;
use flexdyn_sinks::{export, plot, record_cmd, replay, view};

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
    Simulate(commands::simulate::SimulateArgs),
    /// Propagate a fleet file (several spacecraft, one tick) offline: states and relative
    /// states as CSV.
    Fleet(commands::fleet::FleetArgs),
    /// Validate a configuration file and print a one-line summary (exit 2 if invalid).
    CheckConfig {
        /// The configuration file (TOML).
        file: PathBuf,
    },
    /// Print the embedded default configuration (scenarios/reference.toml) verbatim.
    PrintDefaultConfig,
    /// Record every sample of flexdyn/<sc-id>/** (all vehicles by default) to an MCAP file.
    Record(record_cmd::RecordArgs),
    /// Republish a recording's raw channels to Zenoh with the recorded spacing.
    Replay(replay::ReplayArgs),
    /// Write one CSV per topic of a recording.
    Export(export::ExportArgs),
    /// Serve the live stream (or a recording) to Foxglove over its WebSocket protocol.
    View(view::ViewArgs),
    /// Draw PNG figures of a recording or a simulate/export CSV.
    Plot(plot::PlotArgs),
    /// The device gateway: the served vehicle's sensors and actuators as byte-stream devices
    /// (pseudo-terminals, TCP, UDP) that unmodified flight drivers open, described by TOML
    /// files; a lockstep participant like any flight code.
    Gateway(Box<flexdyn_devices::participant::GatewayArgs>),
    /// Monte Carlo campaigns: plan, run (locally or one index at a time), summarize.
    #[command(subcommand)]
    Campaign(flexdyn_campaign::CampaignCommand),
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
        flexdyn_proto::client::logging::init_tracing();
    }
    match args.command {
        Some(Command::Run(a)) => commands::run::main(&a),
        // No subcommand: `flexdyn run` with the options given.
        None => commands::run::main(&args.run),
        Some(Command::Simulate(a)) => commands::simulate::main(&a),
        Some(Command::Fleet(a)) => commands::fleet::main(&a),
        Some(Command::CheckConfig { file }) => commands::check_config::main(&file),
        Some(Command::PrintDefaultConfig) => commands::print_default_config::main(),
        Some(Command::Record(a)) => commands::record::main(&a),
        Some(Command::Replay(a)) => commands::replay::main(&a),
        Some(Command::Export(a)) => commands::export::main(&a),
        Some(Command::View(a)) => commands::view::main(&a),
        Some(Command::Plot(a)) => commands::plot::main(&a),
        Some(Command::Gateway(a)) => commands::gateway::main(&a),
        Some(Command::Campaign(c)) => commands::campaign::main(&c),
    }
}
