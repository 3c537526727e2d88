//! Star-tracker values that are legal but almost surely a unit slip ([`flexdyn_kernel::schema::plausible`]).
//!
//! Star trackers are specified in arcseconds and degrees; the keys are in radians, so the
//! typical slip is a datasheet number typed as it stands (`5` for 5″, `30` for a 30° Sun
//! exclusion). What flight trackers' datasheets give, and where a warning starts:
//! - noise (1σ): from 0.2″ (Ball's High Accuracy Star Tracker; Michaels, IEEE Aerospace
//!   Conference 2005, doi:10.1109/AERO.2005.1559572) to some tens of arcseconds across the
//!   boresight for CubeSat trackers, and several times that about the boresight. Above 5e-3 rad
//!   (≈ 1000″ ≈ 0.29°) no tracker is specified: a warning.
//! - bias: a calibration residual or thermal distortion of arcseconds to arcminutes. Above
//!   0.05 rad (2.9°) it is a mounting error, which belongs in `dcm_cb`.
//! - Sun exclusion half-angle: 25°–45° for baffled trackers. Above 90° (π/2 rad) the tracker
//!   would be blind over more than a hemisphere.
//! - rate limit: trackers keep tracking up to a few °/s (the HAST above: 4°/s). Above 1 rad/s
//!   (57°/s) is a warning.
//! - Earth and Moon exclusion half-angles (from the limb): some degrees to about 30° on
//!   datasheets. The blind cone about the body is its angular radius plus the half-angle (the
//!   Earth's is 66° from a 7000 km orbit), so above 60° (π/3 rad) the Earth alone would hide
//!   nearly the whole sky in LEO.
//! - the atmosphere counted as the Earth's limb: tens of kilometres (the bright airglow and
//!   scattering layer is below about 100 km). Above 1000 km is a warning.

use super::StarTrackerConfig;
use flexdyn_kernel::schema::plausible::{Implausible, Range, ARCSEC, DEG};

const ANGLES: &[(&str, f64)] = &[("arcsec", ARCSEC), ("deg", DEG)];

/// The implausible values of `st` (at `path`, e.g. `star_trackers[0]`).
pub(crate) fn check(st: &StarTrackerConfig, path: &str, out: &mut Vec<Implausible>) {
    let rows = [
        (
            "sigma_cross_boresight_rad",
            st.sigma_cross_boresight_rad,
            Range {
                what: "a star tracker's noise (1σ)",
                si: "rad",
                plausible: (1e-7, 5e-3),
                units: ANGLES,
            },
        ),
        (
            "sigma_about_boresight_rad",
            st.sigma_about_boresight_rad,
            Range {
                what: "a star tracker's noise (1σ)",
                si: "rad",
                plausible: (1e-7, 5e-3),
                units: ANGLES,
            },
        ),
        (
            "bias_c_rad",
            st.bias_c_rad.norm(),
            Range {
                what: "a star tracker's alignment bias",
                si: "rad",
                plausible: (1e-7, 0.05),
                units: ANGLES,
            },
        ),
        (
            "sun_exclusion_rad",
            st.sun_exclusion_rad,
            Range {
                what: "a star tracker's Sun exclusion half-angle",
                si: "rad",
                plausible: (0.1, std::f64::consts::FRAC_PI_2),
                units: &[("deg", DEG)],
            },
        ),
        (
            "earth_exclusion_rad",
            st.earth_exclusion_rad,
            Range {
                what: "a star tracker's Earth-limb exclusion half-angle",
                si: "rad",
                plausible: (0.01, std::f64::consts::FRAC_PI_3),
                units: &[("deg", DEG)],
            },
        ),
        (
            "moon_exclusion_rad",
            st.moon_exclusion_rad,
            Range {
                what: "a star tracker's Moon exclusion half-angle",
                si: "rad",
                plausible: (0.01, std::f64::consts::FRAC_PI_3),
                units: &[("deg", DEG)],
            },
        ),
        (
            "earth_atmosphere_m",
            st.earth_atmosphere_m,
            Range {
                what: "the atmosphere height of a star tracker's Earth limb",
                si: "m",
                plausible: (1.0, 1e6),
                units: &[("km", 1e3)],
            },
        ),
        (
            "max_rate_rad_s",
            // ∞ (no limit, the default) is not a slip.
            if st.max_rate_rad_s.is_finite() {
                st.max_rate_rad_s
            } else {
                0.0
            },
            Range {
                what: "a star tracker's tracking-rate limit",
                si: "rad/s",
                plausible: (1e-3, 1.0),
                units: &[("deg/s", DEG)],
            },
        ),
    ];
    for (key, value, range) in rows {
        out.extend(range.above(format!("{path}.{key}"), value));
    }
}
