//! Number formatting for people and for files that must read back exactly.
//!
//! - [`Num`]: the shortest text that parses back to the same `f64`, in plain notation for
//!   magnitudes in [1e-4, 1e16) and in scientific notation outside it, so `1e300` prints as
//!   `1e300`, not as 301 digits, and `0.03` prints as `0.03`, not `2.9999999999999999e-2`.
//!   Used in CSV output and in every error message that quotes a value.
//! - [`Rounded`]: a value rounded to a few significant digits, for log lines and human
//!   messages (`2.001316387 s` prints as `2.001 s`).

use std::fmt;

/// Shortest round-trip form of an `f64` (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        if !x.is_finite() {
            // `NaN`, `inf`, `-inf`: the words TOML uses, lower case.
            if x.is_nan() {
                f.write_str("nan")
            } else if x > 0.0 {
                f.write_str("inf")
            } else {
                f.write_str("-inf")
            }
        } else if a == 0.0 || (1e-4..1e16).contains(&a) {
            // Rust's `{}` is the shortest representation that round-trips.
            write!(f, "{x}")
        } else {
            // `{:e}` is also the shortest round-trip digit string, with an exponent.
            write!(f, "{x:e}")
        }
    }
}

/// A value rounded to `digits` significant digits, for human messages (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rounded(pub f64, pub usize);

impl fmt::Display for Rounded {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Rounded(x, digits) = *self;
        let digits = digits.max(1);
        if !x.is_finite() || x == 0.0 {
            return Num(x).fmt(f);
        }
        let exp = x.abs().log10().floor() as i32;
        if !(-4..16).contains(&exp) {
            let s = format!("{:.*e}", digits - 1, x);
            let (mantissa, e) = s.split_once('e').unwrap_or((&s, "0"));
            let mantissa = if mantissa.contains('.') {
                mantissa.trim_end_matches('0').trim_end_matches('.')
            } else {
                mantissa
            };
            return write!(f, "{mantissa}e{e}");
        }
        let decimals = (digits as i32 - 1 - exp).max(0) as usize;
        let s = format!("{x:.decimals$}");
        // Drop trailing zeros after the point ("2.000" → "2", "0.1500" → "0.15").
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        f.write_str(&s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn num_is_short_and_round_trips() {
        for (x, want) in [
            (0.03, "0.03"),
            (1e300, "1e300"),
            (-4020338.689621511, "-4020338.689621511"),
            (1e-20, "1e-20"),
            (0.0, "0"),
            (-0.0, "-0"),
            (123.0, "123"),
            (2.5e16, "2.5e16"),
            (f64::NAN, "nan"),
            (f64::NEG_INFINITY, "-inf"),
        ] {
            assert_eq!(Num(x).to_string(), want, "{x:e}");
        }
        // Round trip on awkward values.
        for x in [
            0.1 + 0.2,
            1.0 / 3.0,
            f64::MIN_POSITIVE,
            f64::MAX,
            -7.0e-5,
            9.999e15,
        ] {
            let s = Num(x).to_string();
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
    }

    #[test]
    fn rounded_keeps_significant_digits() {
        assert_eq!(Rounded(2.001316387, 4).to_string(), "2.001");
        assert_eq!(Rounded(2.0, 4).to_string(), "2");
        assert_eq!(Rounded(1234.5678, 3).to_string(), "1235");
        assert_eq!(Rounded(0.00123456, 3).to_string(), "0.00123");
        assert_eq!(Rounded(1e300, 3).to_string(), "1e300");
        assert_eq!(Rounded(1.23456e-7, 3).to_string(), "1.23e-7");
    }
}
