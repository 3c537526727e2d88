//! flexdyn's vehicle layer: what turns a configuration file into vehicles that step.
//!
//! - [`config`]: the TOML configuration of one spacecraft, parsed in passes and validated, every
//!   error naming its field; it assembles each model's own schema and builds the spacecraft, its
//!   sensors ([`config::SimConfig::sensor_build`]) and its faults (`[[faults]]` and the live-fault
//!   resolver, checked against the vehicle it builds);
//! - [`sim`]: one vehicle, the [`sim::Simulation`]: the spacecraft, its schedules and commands, its
//!   sensor bank sampled from one truth per frame, its fault ports and its environment;
//! - [`checkpoint`]: a run's complete state at a frame boundary as a versioned, checksummed file's
//!   bytes, to resume or fork it bit for bit;
//! - [`world`]: several vehicles on one tick (the fleet file, the world that steps them, relative
//!   states in a chief's Hill frame).
//!
//! # Layer
//! Above every model crate (kernel, environment, dynamics, sensors, faults), which it assembles;
//! the server, the sinks, the campaigns and the command line sit above it. It must never depend on
//! them, nor on any I/O stack (`zenoh`, `tokio`, `foxglove`, `plotters`, `mcap`): `.ci/layers`
//! checks the dependency graph. Reading a configuration file is its only I/O (a checkpoint is bytes; the front ends write
//! and read its file).

#![warn(missing_docs)]

pub mod checkpoint;
pub mod config;
pub mod sim;
pub mod world;
