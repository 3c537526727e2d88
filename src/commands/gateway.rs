//! `flexdyn gateway`: the device gateway, a participant that exposes the served vehicle's
//! sensors and actuators as byte-stream devices (pseudo-terminals, TCP, UDP) for unmodified
//! flight drivers (`flexdyn_devices::participant`; book: "Device gateway").

use std::process::ExitCode;

use flexdyn_devices::participant::{run, GatewayArgs};
use flexdyn_proto::client::cli::exit_with;

/// Runs the gateway until the server ends the run; 2 for a bad device list or option, 1 for a
/// failure while running.
pub fn main(args: &GatewayArgs) -> ExitCode {
    exit_with(run(args))
}
