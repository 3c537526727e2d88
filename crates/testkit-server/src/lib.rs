//! What flexdyn's end-to-end tests and benchmarks share, above the server:
//! - [`server`]: loopback sessions built with the one configuration builder (multicast scouting
//!   off, ports the OS chose), an in-process server (one spacecraft or a fleet) with a bounded
//!   join, an observer of its state and status, and condition waits;
//! - [`participants`]: a recording lockstep participant in the test process, child processes
//!   killed on drop and waited for with a bound, and the digest the lockstep hashes are pinned by.
//!
//! It depends on the server and the campaigns (and on `flexdyn-testkit` below them); only test
//! and benchmark targets depend on it, so no layer ever links it. It replaces the `#[path]`
//! includes the suites used to share this code with.

// Test support: helpers panic on a broken setup, as a test would.

pub mod participants;
pub mod server;

pub use participants::*;
pub use server::*;
