//! The dynamics layer checked against invariants and independent references, in one test
//! executable that links the model crates only (no configuration file, server or I/O stack):
//!
//! - [`attitude`]: the attitude kernels and frame directions against nalgebra's own rotations;
//! - [`conservation`]: energy and angular momentum of the free spacecraft;
//! - [`analytic_limit`]: a pair on a near-fixed hub against the linearised eigenproblem;
//! - [`validate_dense_kane`]: back-substitution against a dense Kane formulation;
//! - [`validate_basilisk_nhinged`]: the panel chain against Basilisk's N-hinged effector;
//! - [`validate_dense_kane_chain`]: the N-link panel chain against its own dense Kane model;
//! - [`gravity_vs_sgp4`]: the point-mass and J2 gravity against SGP4's propagation;
//! - [`propellant_tank`]: mass depletion against ∫F/(I_sp g₀), hand-computed mass properties,
//!   invariants and the rocket equation;
//! - [`slosh`]: the fuel-slosh effectors against a dense Kane solve, invariants, closed-form
//!   frequencies and decay rates.
//!
//! [`common`] builds the reference spacecraft of `scenarios/reference.toml` in code.

// The reference spacecraft built in code, and the conservation measure.
use flexdyn_dynamics::reference as common;

mod analytic_limit;
mod attitude;
mod conservation;
mod gravity_vs_sgp4;
mod propellant_tank;
mod slosh;
mod validate_basilisk_nhinged;
mod validate_dense_kane;
mod validate_dense_kane_chain;
