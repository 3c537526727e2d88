//! What flexdyn's tests and benchmarks share, in place of modules each test used to include by
//! path:
//! - [`ports`]: free loopback ports without a race, read back from the process that listens;
//! - [`demo_bin`]: where the demo flight code binaries are, checked built after their sources;
//! - [`cli_errors`]: the error rules every flexdyn binary follows on bad input;
//! - [`fleets`]: fleet files the tests fly (text only: the tests parse them);
//! - [`c_program`]: C programs built from source as strictly as a user's CI would;
//! - [`python`]: a virtual environment for the checks against independent Python readers;
//! - [`alloc_counter`]: a counting global allocator, for the tests that prove a hot path
//!   allocates nothing;
//! - [`median`] and [`median_mut`]: the figure the benchmarks print.
//!
//! It depends on the standard library only, so a model crate's tests link no layer through it,
//! and it must never depend on a flexdyn crate: helpers that need the simulator stay with the
//! crate whose tests use them.

pub mod alloc_counter;
pub mod c_program;
pub mod cargo_build;
pub mod cli_errors;
pub mod demo_bin;
pub mod fleets;
pub mod ports;
pub mod python;

/// The median of `v` as the benchmarks print it: the upper median (`v[len / 2]` once sorted by
/// `f64::total_cmp`) for an even count. Panics on an empty `v`.
pub fn median(mut v: Vec<f64>) -> f64 {
    median_mut(&mut v)
}

/// [`median`], sorting `v` in place.
pub fn median_mut(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
