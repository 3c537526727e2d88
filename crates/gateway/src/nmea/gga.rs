//! GGA, Global Positioning System Fix Data (NMEA 0183; the field list as in E. S.
//! Raymond, "NMEA Revealed", gpsd.gitlab.io/gpsd/NMEA.html, and D. DePriest, "NMEA data",
//! gpsinformation.org/dale/nmea.htm):
//!
//! ```text
//! $--GGA,hhmmss.ss,llll.ll,a,yyyyy.yy,a,x,xx,x.x,x.x,M,x.x,M,x.x,xxxx*hh
//!        1         2       3 4        5 6 7  8   9   10 11 12 13  14
//! ```
//! 1 UTC of fix, 2–3 latitude N/S, 4–5 longitude E/W, 6 fix quality, 7 satellites in use,
//! 8 HDOP, 9–10 altitude above mean sea level, metres, 11–12 geoid separation (geoid above
//! the WGS 84 ellipsoid), metres, 13 age of differential corrections, s, 14 differential
//! station id (13–14 empty without differential corrections).

use std::fmt::Write;

use hifitime::Epoch;

use super::fields::{fixed_value, in_range, write_fixed, Position, UtcFields};
use super::sentence::SentenceWriter;
use super::{NmeaError, NmeaStyle};

/// GGA's fix quality indicator (field 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FixQuality {
    /// 0: no fix.
    Invalid = 0,
    /// 1: GPS (SPS) fix.
    Gps = 1,
    /// 2: differential GPS fix.
    Differential = 2,
    /// 3: PPS fix.
    Pps = 3,
    /// 4: real-time kinematic, fixed integers.
    RtkFixed = 4,
    /// 5: real-time kinematic, float.
    RtkFloat = 5,
    /// 6: estimated (dead reckoning), NMEA 2.3.
    Estimated = 6,
    /// 7: manual input.
    Manual = 7,
    /// 8: simulation.
    Simulation = 8,
}

/// Differential corrections in use (fields 13–14).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dgps {
    /// Age of the corrections, seconds.
    pub age_s: f64,
    /// Reference station id, 0 to 1023, written with 4 digits.
    pub station_id: u16,
}

/// The inputs of a GGA sentence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gga {
    /// Time of the fix (any time scale; written in UTC).
    pub time: Epoch,
    /// Geodetic latitude, degrees, north positive, −90 to 90.
    pub latitude_deg: f64,
    /// Longitude, degrees, east positive, −180 to 180.
    pub longitude_deg: f64,
    /// Fix quality.
    pub fix_quality: FixQuality,
    /// Satellites in use.
    pub satellites: u8,
    /// Horizontal dilution of precision.
    pub hdop: f64,
    /// Altitude above mean sea level (the geoid), metres.
    pub altitude_msl_m: f64,
    /// Geoid separation: the geoid's height above the WGS 84 ellipsoid, metres.
    pub geoid_separation_m: f64,
    /// Differential corrections, if any.
    pub dgps: Option<Dgps>,
}

impl Gga {
    /// Appends the sentence to `out` (nothing is appended on error).
    pub fn write(&self, style: &NmeaStyle, out: &mut String) -> Result<(), NmeaError> {
        style.validate()?;
        let position = Position::checked(self.latitude_deg, self.longitude_deg)?;
        let hdop = fixed_value("hdop", self.hdop, false)?;
        let altitude_msl_m = fixed_value("altitude_msl_m", self.altitude_msl_m, true)?;
        let geoid_separation_m = fixed_value("geoid_separation_m", self.geoid_separation_m, true)?;
        let dgps_age_s = match self.dgps {
            Some(dgps) => {
                in_range(
                    "dgps.station_id",
                    f64::from(dgps.station_id),
                    0.0,
                    1023.0,
                    "0..=1023",
                )?;
                Some(fixed_value("dgps.age_s", dgps.age_s, false)?)
            }
            None => None,
        };
        let utc = UtcFields::of(self.time, style.time_decimals);

        let mut s = SentenceWriter::start(out, style.talker, "GGA");
        utc.write_time(s.field());
        position.write(&mut s, style.minute_decimals);
        let _ = write!(s.field(), "{}", self.fix_quality as u8);
        let _ = write!(
            s.field(),
            "{:0width$}",
            self.satellites,
            width = usize::from(style.satellites_digits)
        );
        write_fixed(s.field(), hdop, style.hdop);
        write_fixed(s.field(), altitude_msl_m, style.altitude_m);
        s.field().push('M');
        write_fixed(s.field(), geoid_separation_m, style.altitude_m);
        s.field().push('M');
        match (dgps_age_s, self.dgps) {
            (Some(age_s), Some(dgps)) => {
                write_fixed(s.field(), age_s, style.dgps_age_s);
                let _ = write!(s.field(), "{:04}", dgps.station_id);
            }
            _ => {
                s.field();
                s.field();
            }
        }
        s.finish();
        Ok(())
    }
}
