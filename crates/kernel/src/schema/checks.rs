//! Checks every configuration schema shares: durations in whole nanoseconds, rates that divide
//! the frame rate, and names unique within a kind. Errors are located through the document's
//! [`SourceMap`].

use std::collections::HashSet;

use super::config_error::ConfigError;
use super::source_map::SourceMap;
use crate::numfmt::Num;
use crate::validate::ParamError;

/// Largest allowed distance of `seconds · 1e9` from a whole number of nanoseconds.
pub const WHOLE_NS_TOL: f64 = 1e-6;

/// Converts seconds to a whole number of nanoseconds: `None` unless `seconds` is finite, ≥ 0,
/// representable in `u64` nanoseconds and within [`WHOLE_NS_TOL`] (or 4 ulp of the product for
/// long durations) of a whole number.
pub fn whole_ns(seconds: f64) -> Option<u64> {
    round_ns(seconds * 1e9)
}

/// `ns` as a whole number of nanoseconds, with the tolerance of [`whole_ns`].
pub fn round_ns(ns: f64) -> Option<u64> {
    if !ns.is_finite() || ns < 0.0 || ns >= u64::MAX as f64 {
        return None;
    }
    let rounded = ns.round();
    let tol = WHOLE_NS_TOL.max(ns * 4.0 * f64::EPSILON);
    ((ns - rounded).abs() <= tol).then_some(rounded as u64)
}

/// `frame_hz / rate_hz` as a whole number of frames ≥ 1 (`rate_hz` read from `field`): a
/// sensor that updates at `rate_hz` does so every that many frames (`what` updates …).
pub fn every_frames(
    map: &SourceMap,
    field: &str,
    rate_hz: f64,
    frame_hz: f64,
    what: &str,
) -> Result<u64, ConfigError> {
    let field = field.to_string();
    if !rate_hz.is_finite() || rate_hz <= 0.0 {
        return Err(map.param_error(ParamError::NotPositive {
            field,
            value: rate_hz,
        }));
    }
    let ratio = frame_hz / rate_hz;
    let every_frames = ratio.round();
    if every_frames < 1.0 || (ratio - every_frames).abs() > 1e-9 * ratio {
        return Err(map.invalid(
            &field,
            format!(
                "{} Hz is not the frame rate ({} Hz) divided by a whole number: the {what} \
                 updates every whole number of frames",
                Num(rate_hz),
                Num(frame_hz)
            ),
        ));
    }
    Ok(every_frames as u64)
}

/// Checks that `<path>.name` is not blank and not already in `seen` (then adds it).
pub fn unique_name(
    map: &SourceMap,
    path: &str,
    name: &str,
    seen: &mut HashSet<String>,
    what: &str,
) -> Result<(), ConfigError> {
    let field = format!("{path}.name");
    if name.trim().is_empty() {
        return Err(map.invalid(&field, "must not be empty".into()));
    }
    if !seen.insert(name.to_string()) {
        return Err(map.invalid(
            &field,
            format!("duplicate {what} name `{name}` (names must be unique)"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_ns_tolerance() {
        assert_eq!(whole_ns(0.001), Some(1_000_000));
        assert_eq!(whole_ns(1e-9), Some(1));
        assert_eq!(whole_ns(0.01), Some(10_000_000));
        assert_eq!(whole_ns(1.5e-9), None);
        assert_eq!(whole_ns(-1.0), None);
        assert_eq!(whole_ns(f64::NAN), None);
        assert_eq!(whole_ns(86_400.0 * 365.0), Some(31_536_000_000_000_000));
    }
}
