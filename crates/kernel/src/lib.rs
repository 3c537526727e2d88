//! flexdyn's kernel: what every layer above it shares and nothing of the physics.
//!
//! - [`archive`]: a run's mutable state as bytes, listed once per component for both the save
//!   and the restore of a checkpoint;
//! - [`attitude`]: the MRP, DCM and quaternion kernels (those of `flexdyn_proto::attitude`, which
//!   flight code uses without linking the simulator);
//! - [`numfmt`]: numbers formatted for messages and files;
//! - [`validate`]: parameter checks and their error, [`validate::ParamError`];
//! - [`schema`]: the typed TOML reader every model's schema uses, the configuration's error
//!   ([`schema::config_error::ConfigError`]), the source map that locates a TOML path in the
//!   text, and the checks every schema shares (whole nanoseconds, rates, unique names).
//!
//! # Layer
//! The bottom of the workspace. It depends on the wire crate (`flexdyn-proto`, for its attitude
//! kernels), `nalgebra`, `toml` and `thiserror` only. It must never depend on a flexdyn crate but
//! `flexdyn-proto`, nor on any I/O stack (`zenoh`, `tokio`, `foxglove`, `plotters`, `mcap`):
//! `.ci/layers` (run by `.ci/run`) checks the dependency graph.

#![warn(missing_docs)]

pub mod archive;
pub mod attitude;
pub mod numfmt;
pub mod schema;
pub mod validate;
