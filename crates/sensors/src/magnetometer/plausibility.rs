//! Magnetometer values that are legal but almost surely a unit slip ([`flexdyn_kernel::schema::plausible`]).
//!
//! The keys are in tesla; datasheets give nanotesla, microtesla or gauss (1 G = 1e-4 T), so the
//! typical slip is a datasheet number typed as it stands (`50` for 50 nT of noise, `60` for a
//! ±60 µT range). What flight magnetometers span, and where a warning starts:
//! - noise (1σ): from tens of picotesla for fluxgates to about 0.2 µT for AMR parts such as
//!   Honeywell's HMC5883L (2 mG resolution; datasheet, 2013). Above 1e-5 T (10 µT, a quarter of
//!   the LEO field) no sensor is specified: a warning.
//! - bias: up to some microtesla after calibration; above 1e-4 T (100 µT, more than the field
//!   at the Earth's surface) it is a slip.
//! - range: ±60 µT (fluxgates built for LEO) to ±800 µT (the HMC5883L's ±8 G); above 2e-3 T a
//!   warning.
//! - LSB: picotesla to about 0.5 µT; above 1e-5 T a warning.

use super::MagnetometerConfig;
use flexdyn_kernel::schema::plausible::{Implausible, Range, Unit};

const FIELD_UNITS: &[Unit] = &[("nT", 1e-9), ("µT", 1e-6), ("mG", 1e-7), ("G", 1e-4)];

/// The implausible values of `m` (at `path`, e.g. `magnetometers[0]`).
pub(crate) fn check(m: &MagnetometerConfig, path: &str, out: &mut Vec<Implausible>) {
    let range = |what, plausible| Range {
        what,
        si: "T",
        plausible,
        units: FIELD_UNITS,
    };
    let rows = [
        (
            "noise_sigma_t",
            m.noise_sigma_t,
            range("a magnetometer's noise (1σ)", (1e-11, 1e-5)),
        ),
        (
            "bias_s_t",
            m.bias_s_t.norm(),
            range("a magnetometer's bias", (1e-10, 1e-4)),
        ),
        (
            "range_t",
            m.range_t,
            range("a magnetometer's range", (1e-5, 2e-3)),
        ),
        (
            "lsb_t",
            m.lsb_t,
            range("a magnetometer's LSB", (1e-12, 1e-5)),
        ),
    ];
    for (key, value, range) in rows {
        out.extend(range.above(format!("{path}.{key}"), value));
    }
}
