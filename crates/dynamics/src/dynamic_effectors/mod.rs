//! The external forces and torques, one folder per kind. Each is a
//! [`DynamicEffector`](super::DynamicEffector): it has no integrated state and is evaluated at
//! every RK4 stage from the stage's hub state and the held environment sample.

//!
//! The actuators among them (magnetorquers, thrusters) are also *listed*: they appear in the
//! state record's effector list after the appended bodies and take inputs from flight code
//! ([`DynamicEffector::listed_kind`](super::DynamicEffector::listed_kind)).

pub mod aero_drag;
pub mod cannonball_srp;
pub mod gravity_gradient;
pub mod magnetorquer;
pub mod residual_dipole;
pub mod solar_pressure;
pub mod thruster;
