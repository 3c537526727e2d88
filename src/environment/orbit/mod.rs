//! Initial orbits, as alternatives to a position and velocity in N.
//!
//! - [`keplerian`]: classical elements (a, e, i, Ω, ω, true or mean anomaly) → r/v in N.

pub mod keplerian;
