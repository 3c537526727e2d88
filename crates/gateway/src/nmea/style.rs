//! [`NmeaStyle`]: the talker id and the number formats of the written fields.

use super::NmeaError;

/// A two-character talker id (`GP` GPS, `GN` multi-constellation, `GL` GLONASS, …).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Talker([u8; 2]);

impl Talker {
    /// GPS.
    pub const GP: Talker = Talker(*b"GP");

    /// A talker id of two upper-case ASCII letters or digits.
    pub fn new(id: &str) -> Result<Self, NmeaError> {
        match id.as_bytes() {
            &[a, b]
                if [a, b]
                    .iter()
                    .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit()) =>
            {
                Ok(Talker([a, b]))
            }
            _ => Err(NmeaError::Talker(id.to_owned())),
        }
    }

    /// The two characters.
    pub fn as_str(&self) -> &str {
        // Both octets are ASCII (checked by `new`), so this never falls back.
        std::str::from_utf8(&self.0).unwrap_or("GP")
    }
}

impl Default for Talker {
    fn default() -> Self {
        Talker::GP
    }
}

/// A fixed-point number format: at least `int_digits` integer digits (zero-padded) and exactly
/// `decimals` decimals (no point when 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fixed {
    /// Minimum integer digits.
    pub int_digits: u8,
    /// Decimals (at most [`Fixed::MAX_DECIMALS`]).
    pub decimals: u8,
}

impl Fixed {
    /// The most decimals a field may have (integer units of 10⁻⁹ still fit in `u64` for any
    /// value a field holds).
    pub const MAX_DECIMALS: u8 = 9;

    /// `int_digits` integer digits, `decimals` decimals.
    pub const fn new(int_digits: u8, decimals: u8) -> Self {
        Self {
            int_digits,
            decimals,
        }
    }
}

/// The talker id and number formats of the sentences written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NmeaStyle {
    /// The talker id.
    pub talker: Talker,
    /// Decimals of the seconds in `hhmmss.ss` (0 to 9).
    pub time_decimals: u8,
    /// Decimals of the minutes in `ddmm.mmmm` and `dddmm.mmmm` (0 to 9).
    pub minute_decimals: u8,
    /// Digits of GGA's satellite count (zero-padded).
    pub satellites_digits: u8,
    /// GGA's HDOP.
    pub hdop: Fixed,
    /// GGA's altitude above mean sea level and geoid separation, metres.
    pub altitude_m: Fixed,
    /// GGA's age of differential corrections, seconds.
    pub dgps_age_s: Fixed,
    /// RMC's speed over ground, knots.
    pub speed_knots: Fixed,
    /// RMC's course over ground, degrees.
    pub course_deg: Fixed,
    /// RMC's magnetic variation, degrees.
    pub magnetic_variation_deg: Fixed,
}

impl Default for NmeaStyle {
    fn default() -> Self {
        Self {
            talker: Talker::GP,
            time_decimals: 2,
            minute_decimals: 4,
            satellites_digits: 2,
            hdop: Fixed::new(1, 1),
            altitude_m: Fixed::new(1, 1),
            dgps_age_s: Fixed::new(1, 1),
            speed_knots: Fixed::new(1, 1),
            course_deg: Fixed::new(1, 1),
            magnetic_variation_deg: Fixed::new(1, 1),
        }
    }
}

impl NmeaStyle {
    /// Checks every decimal count against [`Fixed::MAX_DECIMALS`].
    pub fn validate(&self) -> Result<(), NmeaError> {
        let counts = [
            ("time_decimals", self.time_decimals),
            ("minute_decimals", self.minute_decimals),
            ("hdop", self.hdop.decimals),
            ("altitude_m", self.altitude_m.decimals),
            ("dgps_age_s", self.dgps_age_s.decimals),
            ("speed_knots", self.speed_knots.decimals),
            ("course_deg", self.course_deg.decimals),
            (
                "magnetic_variation_deg",
                self.magnetic_variation_deg.decimals,
            ),
        ];
        match counts.iter().find(|(_, d)| *d > Fixed::MAX_DECIMALS) {
            Some(&(field, decimals)) => Err(NmeaError::Decimals {
                field,
                decimals,
                max: Fixed::MAX_DECIMALS,
            }),
            None => Ok(()),
        }
    }
}
