//! NMEA 0183 sentences of a GPS receiver: writers for GGA, RMC and ZDA, and a sentence reader.
//!
//! A sentence is `$`, the address (talker id and sentence formatter, `GPGGA`), comma-separated
//! fields, `*`, the checksum as two upper-case hex digits, CR LF (the NMEA 0183 sentence
//! structure, also IEC 61162-1's; summarised in E. S. Raymond, "NMEA Revealed",
//! gpsd.gitlab.io/gpsd/NMEA.html). The checksum is the XOR of every character between `$` and
//! `*` ([`crate::checksum::sums::xor8`]).
//!
//! - [`style`]: the number formats of the fields (decimals, zero padding), [`NmeaStyle`];
//! - [`fields`]: the field writers (time, date, latitude, longitude, fixed-point numbers);
//! - [`sentence`]: the `$…*hh\r\n` envelope;
//! - [`gga`], [`rmc`], [`zda`]: the three sentences from typed inputs;
//! - [`reader`]: a parser and validator (checksum, field count), for tests and tools;
//! - [`error`] holds [`NmeaError`].
//!
//! # Formats and rounding
//! The standard fixes the field layout but not the number of decimals, and receivers differ
//! (the classic `4807.038` has 3 decimals of a minute, a survey receiver's `1813.38274046` 8).
//! [`NmeaStyle`] holds them; its default is `hhmmss.ss`, `ddmm.mmmm`/`dddmm.mmmm`, one decimal
//! for HDOP, altitude, geoid separation, speed, course and variation, two-digit satellite
//! count. Every number is rounded to its last decimal, half away from zero, in integer units
//! of that decimal, so that a carry propagates: 59.99996′ with 4 decimals is written as the
//! next whole degree's `00.0000`, never as `60.0000`. UTC is rounded likewise to the time
//! field's last decimal before it is split into calendar fields, so 23:59:59.996 with 2
//! decimals is the next day's 00:00:00.00 in the time and the date fields alike.

pub mod error;
pub mod fields;
pub mod gga;
pub mod reader;
pub mod rmc;
pub mod sentence;
pub mod style;
pub mod zda;

pub use error::NmeaError;
pub use gga::{Dgps, FixQuality, Gga};
pub use reader::Sentence;
pub use rmc::{Mode, Rmc};
pub use style::{Fixed, NmeaStyle, Talker};
pub use zda::{LocalZone, Zda};
