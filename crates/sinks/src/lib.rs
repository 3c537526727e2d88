//! Output sinks: everything that turns the telemetry stream into something to keep or look at.
//! None of it runs on the physics thread.
//!
//! - [`topics`]: which message a key carries, decoded, as JSON and its JSON Schema.
//! - [`scene`]: Foxglove frame transforms and the spacecraft's 3D boxes.
//! - [`mcap_file`]: the MCAP recording layout (raw + decoded + 3D channels, metadata).
//! - [`recorder`]: the recorder thread behind a bounded queue (lossless or counted drops).
//! - [`gaps`]: what a recording misses, from the publishers' sequence numbers.
//! - [`reader`]: reading a recording back, crash-truncated files included.
//! - [`table`]: decoded messages as named columns (CSV export, plots); [`fsw_columns`]: the
//!   flight code's telemetry by its declared names.
//! - [`record_cmd`], [`replay`], [`export`]: the `flexdyn record`, `replay` and `export`
//!   subcommands.
//! - [`plot`]: `flexdyn plot`, PNG figures of a recording or a CSV; [`fault_spans`]: the
//!   intervals its figures shade where a fault was active; [`prior_faults`]: the faults already
//!   active when a recording began.
//! - [`view`]: `flexdyn view`, the live (or recorded) Foxglove WebSocket view.
//!
//! A crate of its own (`flexdyn-sinks`) above the vehicle layer: it depends on the wire
//! (`flexdyn-proto` with its client transport), the model crates and `flexdyn-vehicle` (a
//! recording's scene and a CSV's columns are built from the configuration), and on the I/O
//! stacks it exists for (Zenoh, tokio, MCAP, Foxglove, plotters). It must never depend on the
//! server, the campaigns or the command line: they use it, and `.ci/layers` checks the order.
//! [`signals`] (SIGINT and SIGTERM for the long-running commands) lives here, the lowest crate
//! with tokio, so the server shares it.

#![warn(missing_docs)]

pub mod columns;
pub mod error;
pub mod export;
pub mod fault_spans;
pub mod fsw_columns;
pub mod gaps;
#[cfg(test)]
mod kind_round_trip;
pub mod mcap_file;
pub mod plot;
pub mod prior_faults;
pub mod reader;
pub mod record_cmd;
pub mod recorder;
pub mod replay;
pub mod scene;
pub mod signals;
pub mod table;
pub mod topics;
pub mod view;
pub mod web;
pub mod ws_names;

pub use error::SinkError;
