//! Sensor models, one folder per kind. Each folder owns the kind's parameters, its
//! configuration schema (`schema.rs`), its measurement model and its message mapping:
//! [`imu`] (gyro and accelerometer) and [`star_tracker`] (attitude).
//!
//! Every sensor is sampled at a frame boundary from the same truth: the state and the one
//! evaluation of the hub outputs that the frame's snapshot also uses
//! ([`crate::sim::Simulation`] caches it), so adding sensors adds no equation-of-motion
//! evaluations.

pub mod imu;
pub mod rng;
pub mod star_tracker;
