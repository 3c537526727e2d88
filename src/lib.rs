//! flexdyn: a real-time flight-software-in-the-loop dynamics server.
//!
//! # Layout
//! - [`attitude`]: MRP, DCM and quaternion kernels.
//! - [`dynamics`]: the physics core — rigid hub + dual-hinged panel pairs by back-substitution.
//! - [`imu`]: gyro and accelerometer measurement models (truth at the sensor, error model, RNG).
//! - [`logging`]: the stderr log setup shared by `flexdyn` and the tools (EPIPE-safe).
//! - [`server`]: the Zenoh server (`flexdyn run`): real-time, lockstep and batch propagation.

#![warn(missing_docs)]

pub mod attitude;
pub mod cli;
pub mod config;
pub mod dynamics;
pub mod imu;
pub mod logging;
pub mod numfmt;
pub mod server;
pub mod sim;
