//! The control laws of `flexdyn-acs-demo` (the binary in `src/main.rs`), the template for Rust
//! flight code: [`acs`], the reaction-wheel MRP law and the star-tracker attitude estimate;
//! [`magnetic`], B-dot detumbling and magnetic momentum unloading with the rods; [`sun`], sun
//! acquisition from coarse sun sensors; [`modes`], the ACS mode manager (detumble, sun
//! acquisition, fine pointing, momentum management); [`sequence`], the whole ACS per tick
//! (sensors in, actuator inputs out) that the binary runs with `--mode-manager`; [`fdir`], the
//! gyro and wheel fault detection, isolation and recovery of `--fdir`; [`telemetry`], what the
//! flight code decided, published on its `[[fsw_streams]]` stream for the server to record.
//! The binary's module docs say how it talks to the server and what to keep when you copy it.

#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod acs;
pub mod fdir;
pub mod formation;
pub mod magnetic;
pub mod modes;
pub mod sequence;
pub mod sun;
pub mod telemetry;
