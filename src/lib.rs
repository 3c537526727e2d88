//! flexdyn: a real-time flight-software-in-the-loop dynamics server.
//!
//! # Layout
//! The workspace is cut into crates along its layers, bottom up (each depends only on those below
//! it; `.ci/layers` checks it from cargo's dependency graph):
//! - `flexdyn-proto` (`proto/`): the wire;
//! - `flexdyn-kernel`: [`attitude`], [`numfmt`], [`validate`] and the typed TOML [`schema`]
//!   reader;
//! - `flexdyn-environment` ([`environment`]): the epoch and its time scales, the Earth's
//!   rotation, orbits from elements, TLE and OMM, ephemerides, shadow, magnetic field,
//!   atmosphere, facets, and the sample the dynamic effectors and sensors read;
//! - `flexdyn-dynamics` ([`dynamics`]): the hub, state effectors by back-substitution, dynamic
//!   effectors, integrators;
//! - `flexdyn-sensors` ([`sensors`]) and `flexdyn-faults` ([`faults`]);
//! - `flexdyn-vehicle`: the [`config`]uration file, one vehicle ([`sim`]) and the world of
//!   vehicles ([`world`]);
//! - `flexdyn-sinks` ([`sinks`], and [`signals`]): recording (MCAP), replay, export, the live
//!   Foxglove view and plots; the first layer with an I/O stack;
//! - `flexdyn-server` ([`server`]): the Zenoh server (`flexdyn run`): real-time, lockstep and
//!   batch propagation;
//! - `flexdyn-campaign` ([`campaign`]): Monte Carlo campaigns with flight code in the loop.
//!
//! This crate re-exports them under their old paths and holds what sits above them, for now:
//! - [`logging`], [`transport`]: the stderr log setup and the one Zenoh configuration builder
//!   (loopback, multicast scouting off), shared with the tools and flight code
//!   (`flexdyn_proto::client`);
//! - [`cli`] and [`world::run`]: the offline front ends `flexdyn simulate` and `flexdyn fleet`.

#![warn(missing_docs)]

pub mod cli;
pub mod world;

pub use flexdyn_proto::client::{logging, transport};

// The model and vehicle layers are crates of their own (`crates/`); their old paths stay
// re-exported here while the layers above them move into crates too.
pub use flexdyn_campaign as campaign;
pub use flexdyn_dynamics as dynamics;
pub use flexdyn_environment as environment;
pub use flexdyn_faults as faults;
pub use flexdyn_kernel::{attitude, numfmt, schema, validate};
pub use flexdyn_sensors as sensors;
pub use flexdyn_server as server;
pub use flexdyn_sinks as sinks;
pub use flexdyn_sinks::signals;
pub use flexdyn_vehicle::{config, sim};
