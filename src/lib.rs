//! flexdyn: a real-time flight-software-in-the-loop dynamics server.
//!
//! # Layout
//! - [`attitude`]: MRP, DCM and quaternion kernels.
//! - [`dynamics`]: the physics core — rigid hub + dual-hinged panel pairs by back-substitution.
//! - [`environment`]: the world around the spacecraft — the epoch and its time scales, the
//!   Earth's rotation, initial orbits from elements, TLE and OMM, ephemerides, shadow, magnetic
//!   field, atmosphere, the facet (flat-plate) surface model, and the sample the dynamic
//!   effectors and sensors read.
//! - [`schema`]: the typed TOML reader the per-model schemas use.
//! - [`sensors`]: sensor models — [`sensors::imu`] (gyro and accelerometer).
//! - [`logging`]: the stderr log setup shared by `flexdyn`, the tools and the demo flight code
//!   (EPIPE-safe); `flexdyn_proto::client::logging`.
//! - [`transport`]: the one Zenoh configuration builder (loopback, multicast scouting off),
//!   shared by the server, the tools and flight code; `flexdyn_proto::client::transport`.
//! - [`sinks`]: recording (MCAP), replay, export, the live Foxglove view and plots.
//! - [`campaign`]: Monte Carlo campaigns with flight code in the loop.
//! - [`server`]: the Zenoh server (`flexdyn run`): real-time, lockstep and batch propagation.

#![warn(missing_docs)]

pub mod campaign;
pub mod cli;
pub mod config;
pub mod server;
pub mod signals;
pub mod sim;
pub mod sinks;
pub mod world;

pub use flexdyn_proto::client::{logging, transport};

// The model layers are crates of their own (`crates/`); their old paths stay re-exported here
// while the layers above them move into crates too.
pub use flexdyn_dynamics as dynamics;
pub use flexdyn_environment as environment;
pub use flexdyn_faults as faults;
pub use flexdyn_kernel::{attitude, numfmt, schema, validate};
pub use flexdyn_sensors as sensors;
