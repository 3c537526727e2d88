//! The appended bodies, one folder per kind. Each folder owns the kind's parameters, its
//! configuration schema (`schema.rs`), its [`StateEffector`](super::StateEffector)
//! implementation with its state, input and output names, and its tests.

pub mod panel_chain;
pub mod panel_pair;
pub mod propellant_tank;
pub mod reaction_wheel;
pub mod slosh_linear;
pub mod slosh_pendulum;
