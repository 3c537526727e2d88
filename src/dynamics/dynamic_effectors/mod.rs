//! The external forces and torques, one folder per kind. Each is a
//! [`DynamicEffector`](super::DynamicEffector): it has no integrated state and is evaluated at
//! every RK4 stage from the stage's hub state and the held environment sample.

pub mod aero_drag;
pub mod gravity_gradient;
pub mod residual_dipole;
pub mod solar_pressure;
