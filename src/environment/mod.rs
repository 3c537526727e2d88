//! The world around the spacecraft: the epoch and the environment models (fields, ephemerides,
//! atmosphere), each in its own folder, and the [`EnvironmentSample`] they fill for the dynamic
//! effectors ([`crate::dynamics::DynamicEffector`]) and the sensors.

pub mod sample;

pub use sample::EnvironmentSample;
