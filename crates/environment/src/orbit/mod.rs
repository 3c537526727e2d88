//! Initial orbits, as alternatives to a position and velocity in N.
//!
//! - [`keplerian`]: classical elements (a, e, i, Ω, ω, true or mean anomaly) → r/v in N.
//! - [`mean_elements`]: SGP4 mean elements from a TLE or a CCSDS OMM (KVN, XML, CelesTrak /
//!   Space-Track JSON, CelesTrak CSV), propagated to the simulation epoch with SGP4 (the `sgp4`
//!   crate) and converted from TEME to N.
//! - [`schema`]: the configuration table that chooses one of them.
//!
//! # Mean elements are not an initial state
//! A TLE's (or OMM's) elements are SGP4 *mean* elements: fitted averages that only SGP4 turns
//! into positions. Read as osculating Keplerian elements they put a LEO spacecraft kilometres
//! off (15.4 km for CBERS 2 at 780 km: J2's short-period terms alone move a by ~9 km) — the
//! Basilisk trap the issue names. flexdyn never does that: it runs SGP4 to the simulation epoch
//! and takes SGP4's position and velocity there (which include SGP4's short-period terms, so
//! they are its estimate of the *osculating* state) as the initial condition. From then on
//! flexdyn's own gravity propagates the orbit, which differs from SGP4's theory (SGP4 has drag,
//! J3, J4 and first-order J2; flexdyn's J2 acts about N's z axis), so the two drift apart. For
//! CBERS 2 (`crates/dynamics/tests/gravity_vs_sgp4.rs`), started from SGP4's state: 0.21 km after one
//! orbit and 2.5 km after one day under flexdyn's J2 gravity; 32 km and 444 km under a point
//! mass. An element set is also only as good as its age: SGP4's own error grows by ~1–3 km
//! per day from the element epoch, so propagate from a recent set
//! ([`schema::DEFAULT_MAX_ELEMENT_AGE_DAYS`]).

pub mod keplerian;
pub mod mean_elements;
pub mod schema;
