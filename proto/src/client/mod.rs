//! What every program that talks to a flexdyn server shares, without the simulator: the Zenoh
//! session rules, the command-line conventions, the served configuration, and lockstep ticks
//! assembled complete. Flight code (the template `flexdyn-acs-demo`), the tools and the server
//! itself use it. Behind the `client` feature (Zenoh, tokio, clap), so the wire crate alone
//! stays serde + bincode for programs that bring their own transport.
//!
//! # Layout
//! - [`transport`]: the one Zenoh configuration builder (peer, loopback defaults, multicast
//!   scouting always off), for the server and its clients alike.
//! - [`logging`]: stderr logging that survives a closed pipe, and the usage-error rule of every
//!   binary (one `error:` line, exit 2).
//! - [`cpu`]: the check every binary makes first, that the processor has the instructions the
//!   build uses (x86-64-v3 on x86-64).
//! - [`cli`]: the connection options every client shares ([`cli::CommonArgs`]), its exit codes
//!   and a clean stop on SIGINT/SIGTERM.
//! - [`vehicle`]: the vehicle a server runs, from its `flexdyn/<sc>/config` queryable: the
//!   geometry, wheels and sensors flight code reads.
//! - [`fsw`]: the flight code's own telemetry, a stream of the served `[[fsw_streams]]`
//!   published with names, not word offsets.
//! - [`run_end`]: the end of a run (the server's last status), so every client stops at once.
//! - [`participant`]: a lockstep participant's command publisher and liveliness token
//!   ([`participant::Participant`]).
//! - [`lockstep`]: complete ticks — the state of tick k with every sensor sample due at k —
//!   through a callback subscriber on each key a tick is assembled from
//!   ([`lockstep::TickReceiver`]).

pub mod cli;
pub mod cpu;
pub mod fsw;
pub mod lockstep;
pub mod logging;
pub mod participant;
pub mod run_end;
pub mod transport;
pub mod vehicle;
