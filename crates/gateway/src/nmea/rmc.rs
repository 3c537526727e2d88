//! RMC, Recommended Minimum Specific GNSS Data (NMEA 0183 v2.3; field list as in E. S. Raymond,
//! "NMEA Revealed", gpsd.gitlab.io/gpsd/NMEA.html, and receiver manuals such as Garmin's GPS 18):
//!
//! ```text
//! $--RMC,hhmmss.ss,A,llll.ll,a,yyyyy.yy,a,x.x,x.x,ddmmyy,x.x,a,m*hh
//!        1         2 3       4 5        6 7   8   9      10  11 12
//! ```
//! 1 UTC of position, 2 status (A valid, V warning), 3–4 latitude, 5–6 longitude, 7 speed over
//! ground, knots, 8 course over ground, degrees true, 9 date, 10–11 magnetic variation,
//! degrees, E/W (both empty when unknown), 12 mode indicator (NMEA 2.3 and later; absent
//! before). The variation is east positive: magnetic course = true course − variation (an
//! easterly variation subtracts from the true course, a westerly one, written `W`, adds).

use std::fmt::Write;

use hifitime::Epoch;

use super::fields::{fixed_value, in_range, write_fixed, Position, UtcFields};
use super::sentence::SentenceWriter;
use super::{NmeaError, NmeaStyle};

/// RMC's mode indicator (field 12, NMEA 2.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// `A`: autonomous.
    Autonomous,
    /// `D`: differential.
    Differential,
    /// `E`: estimated (dead reckoning).
    Estimated,
    /// `M`: manual input.
    Manual,
    /// `S`: simulator.
    Simulator,
    /// `N`: data not valid.
    NotValid,
}

impl Mode {
    /// The field's letter.
    pub fn letter(self) -> char {
        match self {
            Mode::Autonomous => 'A',
            Mode::Differential => 'D',
            Mode::Estimated => 'E',
            Mode::Manual => 'M',
            Mode::Simulator => 'S',
            Mode::NotValid => 'N',
        }
    }
}

/// The inputs of an RMC sentence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rmc {
    /// Time of the position (any time scale; written in UTC), also the date field.
    pub time: Epoch,
    /// Status: `true` writes `A` (valid), `false` `V` (navigation receiver warning).
    pub valid: bool,
    /// Geodetic latitude, degrees, north positive, −90 to 90.
    pub latitude_deg: f64,
    /// Longitude, degrees, east positive, −180 to 180.
    pub longitude_deg: f64,
    /// Speed over ground, knots.
    pub speed_knots: f64,
    /// Course over ground, degrees true, 0 to 360.
    pub course_deg: f64,
    /// Magnetic variation, degrees, east positive (fields 10–11 empty when `None`).
    pub magnetic_variation_deg: Option<f64>,
    /// Mode indicator; `None` writes the pre-2.3 sentence without field 12.
    pub mode: Option<Mode>,
}

impl Rmc {
    /// Appends the sentence to `out` (nothing is appended on error).
    pub fn write(&self, style: &NmeaStyle, out: &mut String) -> Result<(), NmeaError> {
        style.validate()?;
        let position = Position::checked(self.latitude_deg, self.longitude_deg)?;
        let speed_knots = fixed_value("speed_knots", self.speed_knots, false)?;
        let course_deg = in_range("course_deg", self.course_deg, 0.0, 360.0, "0..=360")?;
        let variation = match self.magnetic_variation_deg {
            Some(v) => Some(in_range(
                "magnetic_variation_deg",
                v,
                -180.0,
                180.0,
                "-180..=180",
            )?),
            None => None,
        };
        let utc = UtcFields::of(self.time, style.time_decimals);
        let year = utc.year_checked()?;

        let mut s = SentenceWriter::start(out, style.talker, "RMC");
        utc.write_time(s.field());
        s.field().push(if self.valid { 'A' } else { 'V' });
        position.write(&mut s, style.minute_decimals);
        write_fixed(s.field(), speed_knots, style.speed_knots);
        write_fixed(s.field(), course_deg, style.course_deg);
        let _ = write!(s.field(), "{:02}{:02}{:02}", utc.day, utc.month, year % 100);
        match variation {
            Some(v) => {
                write_fixed(s.field(), v.abs(), style.magnetic_variation_deg);
                s.field().push(if v < 0.0 { 'W' } else { 'E' });
            }
            None => {
                s.field();
                s.field();
            }
        }
        if let Some(mode) = self.mode {
            s.field().push(mode.letter());
        }
        s.finish();
        Ok(())
    }
}
