//! The environment models against published references, in one test executable that links the
//! model crates only: leap seconds and GPS weeks ([`epoch`]), the IAU SOFA validation values and
//! Vallado's worked examples for the Earth's rotation and TEME ([`earth_rotation`]), Kepler's
//! equation and the element conversions ([`kepler`]), Vallado's SGP4 verification vectors and
//! the TLE / OMM readers ([`sgp4_orbit`]), the atmospheres ([`atmosphere`]), the Sun and Moon
//! ephemerides ([`ephemeris`]), the facet surface model ([`facets`]), geodetic coordinates
//! ([`geodetic`]), the magnetic field models ([`magnetic`]) and the shadow ([`shadow`]). The
//! reference data sit under this crate's `tests/data/` with their provenance.

// The references' digits are kept as published (SOFA prints 19 significant digits).
#![allow(clippy::excessive_precision)]

mod albedo;
mod atmosphere;
mod earth_rotation;
mod ephemeris;
mod epoch;
mod facets;
mod geodetic;
mod kepler;
mod magnetic;
mod sgp4_orbit;
mod shadow;

use assert_no_alloc::{assert_no_alloc, reset_violation_count, violation_count, AllocDisabler};

/// Counts heap (de)allocations inside `assert_no_alloc` (features `warn_debug`/`warn_release`:
/// count and warn, do not abort), to check that the per-step calls allocate nothing.
#[global_allocator]
static ALLOC: AllocDisabler = AllocDisabler;

/// The number of heap allocations `f` makes.
pub fn allocations_in(f: impl FnOnce()) -> usize {
    reset_violation_count();
    assert_no_alloc(f);
    violation_count() as usize
}

/// The path of a file under this crate's `tests/data/`.
pub fn data(path: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(path)
}
