//! Field writers: UTC time and date, latitude and longitude, fixed-point numbers. Each checks
//! its input (finite, in range) and rounds half away from zero in integer units of its last
//! decimal (see the module documentation of [`crate::nmea`]).

use std::fmt::Write;

use hifitime::{Duration, Epoch, TimeScale};

use super::sentence::SentenceWriter;
use super::{Fixed, NmeaError};

/// UTC calendar fields, the seconds rounded to the time field's decimals.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UtcFields {
    /// Year.
    pub year: i32,
    /// Month, 1 to 12.
    pub month: u8,
    /// Day, 1 to 31.
    pub day: u8,
    /// Hour.
    pub hour: u8,
    /// Minute.
    pub minute: u8,
    /// Second (60 during a leap second).
    pub second: u8,
    /// Fraction of the second in units of 10^−decimals.
    pub fraction: u64,
    /// Decimals of the fraction.
    pub decimals: u8,
}

impl UtcFields {
    /// The UTC fields of `epoch` (any time scale), the second rounded to `decimals` (0 to 9).
    pub fn of(epoch: Epoch, decimals: u8) -> Self {
        let decimals = decimals.min(Fixed::MAX_DECIMALS);
        let utc = epoch.to_time_scale(TimeScale::UTC);
        let (_, _, _, _, _, _, nanos) = utc.to_gregorian_utc();
        let unit_ns = 10u64.pow(u32::from(Fixed::MAX_DECIMALS - decimals));
        let mut fraction = (u64::from(nanos) + unit_ns / 2) / unit_ns;
        let mut rounded = utc;
        if fraction == 10u64.pow(u32::from(decimals)) {
            // Rounds up to the next whole second: let the calendar carry it.
            rounded = utc + Duration::from_total_nanoseconds(i128::from(1_000_000_000 - nanos));
            fraction = 0;
        }
        let (year, month, day, hour, minute, second, _) = rounded.to_gregorian_utc();
        Self {
            year,
            month,
            day,
            hour,
            minute,
            second,
            fraction,
            decimals,
        }
    }

    /// `hhmmss` and, with decimals, `.s…`.
    pub fn write_time(&self, out: &mut String) {
        let _ = write!(out, "{:02}{:02}{:02}", self.hour, self.minute, self.second);
        if self.decimals > 0 {
            let _ = write!(
                out,
                ".{:0width$}",
                self.fraction,
                width = usize::from(self.decimals)
            );
        }
    }

    /// The year, checked to fit 4 digits.
    pub fn year_checked(&self) -> Result<i32, NmeaError> {
        if (0..=9999).contains(&self.year) {
            Ok(self.year)
        } else {
            Err(NmeaError::Year { year: self.year })
        }
    }
}

/// `value` if finite.
pub fn finite(field: &'static str, value: f64) -> Result<f64, NmeaError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(NmeaError::NotFinite { field, value })
    }
}

/// `value` if finite and within `min..=max`.
pub fn in_range(
    field: &'static str,
    value: f64,
    min: f64,
    max: f64,
    range: &'static str,
) -> Result<f64, NmeaError> {
    let value = finite(field, value)?;
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(NmeaError::OutOfRange {
            field,
            value,
            range,
        })
    }
}

/// `|value|` in integer units of 10^−decimals, rounded half away from zero.
fn units(value: f64, decimals: u8) -> u64 {
    (value.abs() * 10f64.powi(i32::from(decimals))).round() as u64
}

/// Writes `units` (of 10^−decimals) as `int.frac`, the integer part zero-padded to `int_digits`.
fn write_units(out: &mut String, units: u64, int_digits: u8, decimals: u8) {
    let scale = 10u64.pow(u32::from(decimals));
    let _ = write!(
        out,
        "{:0width$}",
        units / scale,
        width = usize::from(int_digits)
    );
    if decimals > 0 {
        let _ = write!(
            out,
            ".{:0width$}",
            units % scale,
            width = usize::from(decimals)
        );
    }
}

/// The largest magnitude a fixed-point field accepts: its integer units stay below 2⁶³.
const MAX_MAGNITUDE: f64 = 1e9;

/// A checked fixed-point value: finite, of magnitude below 10⁹, not negative unless allowed.
pub fn fixed_value(
    field: &'static str,
    value: f64,
    allow_negative: bool,
) -> Result<f64, NmeaError> {
    let min = if allow_negative { -MAX_MAGNITUDE } else { 0.0 };
    let range = if allow_negative {
        "-1e9..=1e9"
    } else {
        "0..=1e9"
    };
    in_range(field, value, min, MAX_MAGNITUDE, range)
}

/// Writes a value checked by [`fixed_value`] in `format`, with a `-` if it rounds to a
/// negative number.
pub fn write_fixed(out: &mut String, value: f64, format: Fixed) {
    let units = units(value, format.decimals);
    if value < 0.0 && units > 0 {
        out.push('-');
    }
    write_units(out, units, format.int_digits, format.decimals);
}

/// Writes latitude (`deg_digits` = 2) or longitude (3) as `d…dmm.m…,H`: whole degrees, minutes
/// with `minute_decimals` decimals, and the hemisphere letter (`positive`/`negative`). The
/// value must have been checked by [`in_range`].
pub fn write_angle(
    out: &mut String,
    value_deg: f64,
    deg_digits: usize,
    minute_decimals: u8,
    hemispheres: [char; 2],
) {
    let per_minute = 10u64.pow(u32::from(minute_decimals));
    let total = units(value_deg * 60.0, minute_decimals);
    let degrees = total / (60 * per_minute);
    let minutes = total % (60 * per_minute);
    let _ = write!(out, "{degrees:0deg_digits$}");
    write_units(out, minutes, 2, minute_decimals);
    out.push(',');
    out.push(if value_deg < 0.0 && total > 0 {
        hemispheres[1]
    } else {
        hemispheres[0]
    });
}

/// A latitude and longitude checked for a sentence (finite, within ±90° and ±180°).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Position {
    latitude_deg: f64,
    longitude_deg: f64,
}

impl Position {
    /// Checks a geodetic latitude and a longitude, degrees, north and east positive.
    pub fn checked(latitude_deg: f64, longitude_deg: f64) -> Result<Self, NmeaError> {
        Ok(Self {
            latitude_deg: in_range("latitude_deg", latitude_deg, -90.0, 90.0, "-90..=90")?,
            longitude_deg: in_range("longitude_deg", longitude_deg, -180.0, 180.0, "-180..=180")?,
        })
    }

    /// Writes the four fields `ddmm.m…,N|S,dddmm.m…,E|W`.
    pub fn write(&self, sentence: &mut SentenceWriter<'_>, minute_decimals: u8) {
        write_angle(
            sentence.field(),
            self.latitude_deg,
            2,
            minute_decimals,
            ['N', 'S'],
        );
        write_angle(
            sentence.field(),
            self.longitude_deg,
            3,
            minute_decimals,
            ['E', 'W'],
        );
    }
}
