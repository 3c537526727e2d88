//! ZDA, Time & Date (NMEA 0183; field list as in "NMEA Revealed",
//! gpsd.gitlab.io/gpsd/NMEA.html):
//!
//! ```text
//! $--ZDA,hhmmss.ss,xx,xx,xxxx,xx,xx*hh
//!        1         2  3  4    5  6
//! ```
//! 1 UTC, 2 day, 3 month, 4 year, 5 local zone hours (−13 to 13), 6 local zone minutes (5–6
//! empty when not given).

use std::fmt::Write;

use hifitime::Epoch;

use super::fields::UtcFields;
use super::sentence::SentenceWriter;
use super::{NmeaError, NmeaStyle};

/// The local time zone of ZDA's fields 5–6: local time = UTC + hours + minutes (the
/// minutes carry the hours' sign).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LocalZone {
    /// Hours, −13 to 13.
    pub hours: i8,
    /// Minutes, 0 to 59.
    pub minutes: u8,
}

/// The inputs of a ZDA sentence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Zda {
    /// The time (any time scale; written in UTC).
    pub time: Epoch,
    /// The local zone, if written.
    pub local_zone: Option<LocalZone>,
}

impl Zda {
    /// Appends the sentence to `out` (nothing is appended on error).
    pub fn write(&self, style: &NmeaStyle, out: &mut String) -> Result<(), NmeaError> {
        style.validate()?;
        if let Some(zone) = self.local_zone {
            if !(-13..=13).contains(&zone.hours) {
                let value = f64::from(zone.hours);
                return Err(NmeaError::OutOfRange {
                    field: "local_zone.hours",
                    value,
                    range: "-13..=13",
                });
            }
            if zone.minutes > 59 {
                let value = f64::from(zone.minutes);
                return Err(NmeaError::OutOfRange {
                    field: "local_zone.minutes",
                    value,
                    range: "0..=59",
                });
            }
        }
        let utc = UtcFields::of(self.time, style.time_decimals);
        let year = utc.year_checked()?;

        let mut s = SentenceWriter::start(out, style.talker, "ZDA");
        utc.write_time(s.field());
        let _ = write!(s.field(), "{:02}", utc.day);
        let _ = write!(s.field(), "{:02}", utc.month);
        let _ = write!(s.field(), "{year:04}");
        match self.local_zone {
            Some(zone) => {
                let sign = if zone.hours < 0 { "-" } else { "" };
                let _ = write!(s.field(), "{sign}{:02}", zone.hours.unsigned_abs());
                let _ = write!(s.field(), "{:02}", zone.minutes);
            }
            None => {
                s.field();
                s.field();
            }
        }
        s.finish();
        Ok(())
    }
}
