//! flexdyn: a real-time flight-software-in-the-loop dynamics server.
//!
//! # Layout
//! The workspace is cut into crates along its layers, bottom up (each depends only on those below
//! it; `.ci/layers` checks it from cargo's dependency graph):
//! - `flexdyn-proto` (`proto/`): the wire;
//! - `flexdyn-kernel`: `attitude`, `numfmt`, `validate` and the typed TOML `schema`
//!   reader;
//! - `flexdyn-environment` (`environment`): the epoch and its time scales, the Earth's
//!   rotation, orbits from elements, TLE and OMM, ephemerides, shadow, magnetic field,
//!   atmosphere, facets, and the sample the dynamic effectors and sensors read;
//! - `flexdyn-dynamics` (`dynamics`): the hub, state effectors by back-substitution, dynamic
//!   effectors, integrators;
//! - `flexdyn-sensors` (`sensors`) and `flexdyn-faults` (`faults`);
//! - `flexdyn-vehicle`: the `config`uration file, one vehicle (`sim`) and the world of
//!   vehicles (`world`);
//! - `flexdyn-sinks` (`sinks`, and `signals`): recording (MCAP), replay, export, the live
//!   Foxglove view and plots; the first layer with an I/O stack;
//! - `flexdyn-server` (`server`): the Zenoh server (`flexdyn run`): real-time, lockstep and
//!   batch propagation;
//! - `flexdyn-campaign` (`campaign`): Monte Carlo campaigns with flight code in the loop.
//!
//! This crate is the `flexdyn` binary's library half: [`commands`], one file per subcommand
//! (`run`, `simulate`, `fleet`, `check-config`, `record`, `replay`, `export`, `view`, `plot`,
//! `campaign`, …), each a thin front end over the layer that does the work. `simulate` and
//! `fleet` step through the vehicle layer's one offline loop
//! (`flexdyn_vehicle::world::offline::walk`) and only format rows.
//!
//! Use the layers by their own crate names (`flexdyn_server::run`,
//! `flexdyn_vehicle::config::SimConfig`, …): the old `flexdyn::<layer>` paths were re-exports
//! while the crates were cut, and are gone.

#![warn(missing_docs)]

pub mod commands;
