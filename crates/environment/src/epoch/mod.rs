//! The simulation epoch and the time scales at `epoch + t_sim_ns`.
//!
//! `[epoch]` names the instant at which simulation time is zero, as a UTC or a TAI calendar
//! date-time ([`schema`]). Simulation time stays what it is everywhere else in flexdyn: an
//! integer count of nanoseconds since that instant, in SI seconds — the rate of TAI and TT. The
//! other scales are derived from it, with integer arithmetic, by [`SimEpoch::times`] (scalars)
//! and [`SimEpoch::utc_calendar`] (the UTC date and time of day). Both are allocation-free and
//! return no `Result`, so they can run on the stepping path.
//!
//! # Time scales (and where each relation comes from)
//! - **TAI**: the count itself (hifitime's TAI duration since 1900-01-01T00:00:00 TAI).
//! - **TT** = TAI + 32.184 s exactly (IAU 1991 Resolution A4; IERS Conventions (2010),
//!   Ch. 10). Ephemerides take "Julian centuries TT since J2000.0", J2000.0 being
//!   2000-01-01T12:00:00 TT (JD 2451545.0 TT). TDB differs from TT by less than 1.7 ms
//!   (periodic, Fairhead & Bretagnon 1990), which is below every model's error here, so TT
//!   stands in for TDB.
//! - **UTC** = TAI − ΔAT, ΔAT from the IERS leap-second table (Bulletin C) shipped with
//!   hifitime — no table is typed here (`leap`). During an inserted leap second the UTC
//!   calendar reads 23:59:60.x. ΔAT after the table's last entry (37 s from 2017-01-01) is held
//!   at that value: a leap second announced after the hifitime release in use is missed until
//!   hifitime is updated.
//! - **GPS time** = TAI − 19 s, counted in weeks and seconds of week from the GPS epoch
//!   1980-01-06T00:00:00 UTC (IS-GPS-200, §3.3.4); the full week number, not the 10-bit one.
//! - **UT1**, the Earth's rotation angle as a time: UT1 = UTC + (UT1 − UTC). IERS Bulletin A
//!   publishes UT1 − UTC daily; leap seconds keep |UT1 − UTC| < 0.9 s. flexdyn holds
//!   UT1 − TAI at its epoch value ([`EarthOrientationParams::ut1_minus_utc_s`], 0 unless
//!   configured), which stays right across a leap second (UT1 is continuous, UTC jumps). Error:
//!   |UT1 − UTC| at the epoch (≤ 0.9 s when not configured: 13.5″ of Earth rotation, 0.45 km
//!   along the equator at 7,000 km radius) plus the drift of UT1 − TAI over the run, the excess
//!   length of day, ≤ 3 ms per day since 1962.
//!
//! # Span
//! Epochs from 1972-01-01T00:00:00 UTC (integer leap seconds began then) to
//! 2100-01-01T00:00:00 UTC (the span over which the IAU 2000B nutation of
//! [`super::earth_rotation`] is specified to 1 mas) are accepted; others are an error.

mod leap;
pub mod parse;
pub mod schema;

use std::fmt;

use hifitime::{Duration, Epoch, TimeScale};

use leap::LeapTable;
pub use leap::UtcOffset;
pub use parse::CalendarTime;

/// Nanoseconds per second.
pub const NS_PER_S: i64 = 1_000_000_000;
/// Nanoseconds per day (of 86,400 SI seconds).
pub const NS_PER_DAY: i64 = 86_400 * NS_PER_S;
/// \[ns\] TT − TAI (IAU 1991 Resolution A4).
pub const TT_MINUS_TAI_NS: i64 = 32_184_000_000;
/// Days per Julian century.
pub const DAYS_PER_JULIAN_CENTURY: f64 = 36_525.0;
const NS_PER_WEEK: i64 = 7 * NS_PER_DAY;
/// IERS keeps |UT1 − UTC| below this (IERS Conventions (2010), Ch. 5; the leap-second rule).
pub const MAX_ABS_UT1_MINUS_UTC_S: f64 = 0.9;
/// A bound on the polar-motion coordinates accepted from a configuration (the observed pole
/// has stayed within about 0.6″ of the IERS reference pole).
pub const MAX_ABS_POLAR_MOTION_ARCSEC: f64 = 1.0;
/// Radians per arcsecond.
pub const RAD_PER_ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// The time scale the epoch was written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EpochScale {
    /// `[epoch] utc = "…Z"`.
    Utc,
    /// `[epoch] tai = "…"`.
    Tai,
}

/// Earth orientation parameters at the epoch, held constant over a run (IERS Bulletin A gives
/// them daily; over days they change by milliseconds of UT1 and milliarcseconds of pole).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EarthOrientationParams {
    /// \[s\] UT1 − UTC at the epoch, |·| < 0.9 s. Zero when unknown (UT1 ≈ UTC).
    pub ut1_minus_utc_s: f64,
    /// \[rad\] pole coordinate x_p (IERS Conventions (2010) Eq. (5.3)). Zero when unknown.
    pub polar_motion_x_rad: f64,
    /// \[rad\] pole coordinate y_p. Zero when unknown.
    pub polar_motion_y_rad: f64,
}

/// A bad epoch; every variant names the configuration field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EpochError {
    /// The text is not a date-time of the accepted shape.
    #[error("{field}: {value:?} is not a date-time: {message} (write e.g. {example})")]
    Syntax {
        /// Field path.
        field: String,
        /// The text given.
        value: String,
        /// What is wrong.
        message: String,
        /// A valid example for this field.
        example: &'static str,
    },
    /// The date does not exist (30 February, second 60 without a leap second, …).
    #[error("{field}: {value:?} is not a valid {scale} date-time: {message}")]
    InvalidDate {
        /// Field path.
        field: String,
        /// The text given.
        value: String,
        /// `UTC` or `TAI`.
        scale: &'static str,
        /// What is wrong.
        message: String,
    },
    /// Outside 1972-01-01T00:00:00Z ..< 2100-01-01T00:00:00Z.
    #[error(
        "{field}: {value:?} is outside the supported span 1972-01-01T00:00:00Z to \
         2100-01-01T00:00:00Z (integer leap seconds start in 1972; the IAU 2000B nutation is \
         specified to 1 mas until 2100)"
    )]
    OutOfSpan {
        /// Field path.
        field: String,
        /// The text given.
        value: String,
    },
    /// `offset_s` not finite, too large, or moving the epoch out of the span.
    #[error("{field}: {message} (got {value})")]
    Offset {
        /// Field path.
        field: String,
        /// \[s\] the offset given.
        value: f64,
        /// The allowed range and why.
        message: String,
    },
    /// An Earth orientation parameter out of range or not finite.
    #[error("{field}: {message} (got {value})")]
    EarthOrientation {
        /// Field path.
        field: String,
        /// The value given.
        value: f64,
        /// The allowed range and why.
        message: String,
    },
}

/// \[ns\] 1958-01-01T00:00:00 TAI as a TAI count since 1900-01-01T00:00:00 TAI (hifitime's and
/// [`SimEpoch::tai_ns`]'s reference): 58 years of which 14 leap years (1904 … 1956), so
/// 58·365 + 14 = 21,184 days = 1,830,297,600 s. Checked against hifitime in the server clock's
/// tests.
pub const TAI_1958_COUNT_NS: i64 = 1_830_297_600 * 1_000_000_000;

/// The simulation epoch: the instant where `t_sim_ns = 0`, with everything needed to derive
/// the time scales at `epoch + t_sim_ns` without allocating.
#[derive(Debug, Clone, PartialEq)]
pub struct SimEpoch {
    epoch: Epoch,
    scale: EpochScale,
    /// \[ns\] TAI count (since 1900-01-01T00:00:00 TAI) at the epoch.
    tai_ns: i64,
    /// \[ns\] TT − J2000.0 at the epoch.
    tt_ns_j2000: i64,
    /// \[ns\] GPS time since the GPS epoch, at the epoch.
    gpst_ns: i64,
    /// \[ns\] UT1 − TAI, held at its epoch value.
    ut1_minus_tai_ns: i64,
    /// \[ns\] the calendar count of 2000-01-01T12:00:00 (the J2000 reading of any scale).
    j2000_count_ns: i64,
    eop: EarthOrientationParams,
    leap: LeapTable,
    /// \[ns\] the shift `[epoch] offset_s` applied to the date-time written (0 without).
    offset_ns: i64,
}

/// \[s\] the largest `[epoch] offset_s` magnitude: about a century, far inside i64 ns.
pub const MAX_ABS_OFFSET_S: f64 = 3.2e9;

/// The time scales at one instant, as [`SimEpoch::times`] derives them (integer where exact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochTimes {
    /// \[ns\] simulation time, elapsed SI time since the epoch.
    pub t_sim_ns: u64,
    /// \[ns\] TT − J2000.0 (JD_TT − 2451545.0, in ns).
    pub tt_ns_j2000: i64,
    /// \[ns\] UT1 − 2000-01-01T12:00:00 UT1 (JD_UT1 − 2451545.0, in ns): the Earth rotation
    /// angle's argument (IERS Conventions (2010) Eq. (5.15)).
    pub ut1_ns_j2000: i64,
    /// \[s\] TAI − UTC (the leap-second count ΔAT).
    pub tai_minus_utc_s: i64,
    /// The instant lies within an inserted leap second (UTC reads 23:59:60.x).
    pub in_leap_second: bool,
    /// GPS week number since 1980-01-06 (not modulo 1024).
    pub gps_week: u32,
    /// \[ns\] GPS time of week (from Sunday 00:00:00 GPS time).
    pub gps_ns_of_week: u64,
}

impl EpochTimes {
    /// \[days\] TT − J2000.0.
    pub fn tt_days_j2000(&self) -> f64 {
        self.tt_ns_j2000 as f64 / NS_PER_DAY as f64
    }
    /// \[Julian centuries\] TT − J2000.0: the argument of the precession-nutation, Sun and Moon
    /// series (TT for TDB, see the module docs).
    pub fn tt_centuries_j2000(&self) -> f64 {
        self.tt_days_j2000() / DAYS_PER_JULIAN_CENTURY
    }
    /// \[days\] UT1 − J2000.0 UT1 (D_U of the Earth rotation angle).
    pub fn ut1_days_j2000(&self) -> f64 {
        self.ut1_ns_j2000 as f64 / NS_PER_DAY as f64
    }
    /// \[s\] GPS seconds of week.
    pub fn gps_seconds_of_week(&self) -> f64 {
        self.gps_ns_of_week as f64 * 1e-9
    }
    /// \[s\] GPS time − UTC (ΔAT − 19 s).
    pub fn gps_minus_utc_s(&self) -> i64 {
        self.tai_minus_utc_s - 19
    }
}

impl CalendarTime {
    /// \[years\] the year plus the elapsed fraction of it (days of 86,400 s; a leap second
    /// counts as the last second of its day), as field models such as IGRF take it.
    pub fn decimal_year(&self) -> f64 {
        let leap = (self.year % 4 == 0 && self.year % 100 != 0) || self.year % 400 == 0;
        const CUM: [u16; 12] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];
        let doy0 = CUM[usize::from(self.month.clamp(1, 12)) - 1]
            + u16::from(leap && self.month > 2)
            + u16::from(self.day)
            - 1;
        let sec = f64::from(self.hour) * 3600.0
            + f64::from(self.minute) * 60.0
            + f64::from(self.second.min(59))
            + f64::from(self.nanosecond) * 1e-9;
        let days_in_year = if leap { 366.0 } else { 365.0 };
        f64::from(self.year) + (f64::from(doy0) + sec / 86_400.0) / days_in_year
    }
}

/// ISO 8601 with nanoseconds, e.g. `2016-12-31T23:59:60.500000000` (no zone: the scale is the
/// caller's; [`SimEpoch::utc_iso`] appends `Z`).
impl fmt::Display for CalendarTime {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:09}",
            self.year, self.month, self.day, self.hour, self.minute, self.second, self.nanosecond
        )
    }
}

/// The TAI calendar count (ns since 1900-01-01T00:00:00) of a calendar reading, through
/// hifitime (its TAI scale has no leap seconds, so this is pure calendar arithmetic).
fn calendar_count_ns(c: &CalendarTime) -> Result<i64, String> {
    let e = Epoch::maybe_from_gregorian(
        c.year,
        c.month,
        c.day,
        c.hour,
        c.minute,
        c.second,
        c.nanosecond,
        TimeScale::TAI,
    )
    .map_err(|e| e.to_string())?;
    i64::try_from(e.to_tai_duration().total_nanoseconds()).map_err(|e| e.to_string())
}

/// The calendar reading of a TAI calendar count (inverse of [`calendar_count_ns`]).
fn calendar_of_count(count_ns: i64) -> CalendarTime {
    let (year, month, day, hour, minute, second, nanosecond) =
        Epoch::from_tai_duration(Duration::from_total_nanoseconds(i128::from(count_ns)))
            .to_gregorian_tai();
    CalendarTime {
        year,
        month,
        day,
        hour,
        minute,
        second,
        nanosecond,
    }
}

/// \[ns\] the TAI count of a UTC calendar reading: `u + ΔAT(u)`, where a leap second
/// 23:59:60.x is one SI second after 23:59:59.x and exists only where the table has one.
fn tai_of_utc(leap: &LeapTable, cal: &CalendarTime) -> Result<i64, String> {
    let (c, extra) = if cal.second == 60 {
        (CalendarTime { second: 59, ..*cal }, NS_PER_S)
    } else {
        (*cal, 0)
    };
    let u = calendar_count_ns(&c)?;
    if cal.second == 60 && leap.delta_at_utc(u + NS_PER_S) != leap.delta_at_utc(u) + 1 {
        return Err("second 60 exists only at the end of a day with a leap second".to_string());
    }
    Ok(u + leap.delta_at_utc(u) * NS_PER_S + extra)
}

const UTC_EXAMPLE: &str = "utc = \"2026-03-20T12:00:00Z\"";
const TAI_EXAMPLE: &str = "tai = \"2026-03-20T12:00:37\"";

impl SimEpoch {
    /// The epoch from its text as written in `[epoch]` (`utc` or `tai`), with Earth orientation
    /// parameters. `field` is the configuration path used in errors (`epoch.utc`).
    pub fn parse(
        text: &str,
        scale: EpochScale,
        eop: EarthOrientationParams,
        field: &str,
    ) -> Result<Self, EpochError> {
        let example = match scale {
            EpochScale::Utc => UTC_EXAMPLE,
            EpochScale::Tai => TAI_EXAMPLE,
        };
        let syntax = |message: String| EpochError::Syntax {
            field: field.to_string(),
            value: text.to_string(),
            message,
            example,
        };
        let (cal, zone) = parse::parse_date_time(text).map_err(syntax)?;
        match (scale, zone) {
            (EpochScale::Utc, parse::Zone::None) => {
                return Err(syntax(
                    "a UTC date-time ends with `Z` (no local times)".to_string(),
                ))
            }
            (EpochScale::Tai, parse::Zone::Utc) => {
                return Err(syntax(
                    "a TAI date-time has no zone designator; drop the `Z` (or use `utc`)"
                        .to_string(),
                ))
            }
            _ => {}
        }
        Self::from_calendar(&cal, scale, eop, field, text)
    }

    /// The epoch from a calendar reading in `scale`. `field` and `text` name the source in
    /// errors.
    pub fn from_calendar(
        cal: &CalendarTime,
        scale: EpochScale,
        eop: EarthOrientationParams,
        field: &str,
        text: &str,
    ) -> Result<Self, EpochError> {
        let leap = LeapTable::from_hifitime();
        let (scale_name, hifi_scale) = match scale {
            EpochScale::Utc => ("UTC", TimeScale::UTC),
            EpochScale::Tai => ("TAI", TimeScale::TAI),
        };
        let invalid = |message: String| EpochError::InvalidDate {
            field: field.to_string(),
            value: text.to_string(),
            scale: scale_name,
            message,
        };
        // hifitime validates the calendar (month lengths, leap years, and second 60 only at
        // the end of a day that has a leap second).
        Epoch::maybe_from_gregorian(
            cal.year,
            cal.month,
            cal.day,
            cal.hour,
            cal.minute,
            cal.second,
            cal.nanosecond,
            hifi_scale,
        )
        .map_err(|e| invalid(e.to_string()))?;
        let tai_ns = match scale {
            EpochScale::Tai => calendar_count_ns(cal).map_err(invalid)?,
            EpochScale::Utc => tai_of_utc(&leap, cal).map_err(invalid)?,
        };
        if !in_span(&leap, tai_ns).map_err(invalid)? {
            return Err(EpochError::OutOfSpan {
                field: field.to_string(),
                value: text.to_string(),
            });
        }
        Self::from_tai_count(tai_ns, scale, eop, leap, field)
    }

    /// The epoch moved by `offset_s` seconds (SI, along TAI), as `[epoch] offset_s` asks (a
    /// campaign disperses it to move a run through the year: Sun angle, eclipse season). The
    /// Earth orientation parameters are kept. `field` is the offset's configuration path.
    pub fn offset_by(&self, offset_s: f64, field: &str) -> Result<Self, EpochError> {
        let bad = |message: String| EpochError::Offset {
            field: field.to_string(),
            value: offset_s,
            message,
        };
        if !offset_s.is_finite() || offset_s.abs() > MAX_ABS_OFFSET_S {
            return Err(bad(format!(
                "must be finite and within ±{MAX_ABS_OFFSET_S:e} s (about a century)"
            )));
        }
        let offset_ns = (offset_s * 1e9).round() as i64;
        let tai_ns = self.tai_ns - self.offset_ns + offset_ns;
        if !in_span(&self.leap, tai_ns).map_err(bad)? {
            return Err(bad(
                "moves the epoch outside 1972-01-01T00:00:00Z to 2100-01-01T00:00:00Z".to_string(),
            ));
        }
        let mut shifted =
            Self::from_tai_count(tai_ns, self.scale, self.eop, self.leap.clone(), field)?;
        shifted.offset_ns = offset_ns;
        Ok(shifted)
    }

    /// \[s\] the `[epoch] offset_s` this epoch was moved by (0 without).
    pub fn offset_s(&self) -> f64 {
        self.offset_ns as f64 * 1e-9
    }
}

/// Whether the TAI count `tai_ns` lies in the supported span 1972-01-01T00:00:00Z ..<
/// 2100-01-01T00:00:00Z.
fn in_span(leap: &LeapTable, tai_ns: i64) -> Result<bool, String> {
    let first = leap.first_utc_count_ns() + 10 * NS_PER_S;
    let end_utc = calendar_count_ns(&CalendarTime {
        year: 2100,
        month: 1,
        day: 1,
        hour: 0,
        minute: 0,
        second: 0,
        nanosecond: 0,
    })?;
    let end = end_utc + leap.delta_at_utc(end_utc) * NS_PER_S;
    Ok(tai_ns >= first && tai_ns < end)
}

impl SimEpoch {
    fn from_tai_count(
        tai_ns: i64,
        scale: EpochScale,
        eop: EarthOrientationParams,
        leap: LeapTable,
        field: &str,
    ) -> Result<Self, EpochError> {
        let prefix = field.rsplit_once('.').map_or("", |(p, _)| p);
        let eop_field = |k: &str| {
            if prefix.is_empty() {
                k.to_string()
            } else {
                format!("{prefix}.{k}")
            }
        };
        let check = |k: &str, v: f64, max: f64, unit_scale: f64, unit: &str, why: &str| {
            if !v.is_finite() || v.abs() > max {
                Err(EpochError::EarthOrientation {
                    field: eop_field(k),
                    value: v / unit_scale,
                    message: format!("must be within ±{} {unit} ({why})", max / unit_scale),
                })
            } else {
                Ok(())
            }
        };
        check(
            "ut1_minus_utc_s",
            eop.ut1_minus_utc_s,
            MAX_ABS_UT1_MINUS_UTC_S,
            1.0,
            "s",
            "the IERS keeps |UT1 − UTC| below 0.9 s",
        )?;
        let pm_max = MAX_ABS_POLAR_MOTION_ARCSEC * RAD_PER_ARCSEC;
        let why = "the pole has stayed within about 0.6″ of the IERS reference pole";
        check(
            "polar_motion_x_arcsec",
            eop.polar_motion_x_rad,
            pm_max,
            RAD_PER_ARCSEC,
            "arcsec",
            why,
        )?;
        check(
            "polar_motion_y_arcsec",
            eop.polar_motion_y_rad,
            pm_max,
            RAD_PER_ARCSEC,
            "arcsec",
            why,
        )?;
        let epoch_tai =
            Epoch::from_tai_duration(Duration::from_total_nanoseconds(i128::from(tai_ns)));
        let j2000_count_ns = calendar_count_ns(&CalendarTime {
            year: 2000,
            month: 1,
            day: 1,
            hour: 12,
            minute: 0,
            second: 0,
            nanosecond: 0,
        })
        .unwrap_or(0);
        // hifitime's GPST reference is 1980-01-06T00:00:19 TAI (= 00:00:00 UTC).
        let gpst_ns = epoch_tai.to_gpst_duration().total_nanoseconds() as i64;
        let delta_at = leap.offset_at_tai(tai_ns).delta_at_s;
        let ut1_minus_tai_ns = (eop.ut1_minus_utc_s * 1e9).round() as i64 - delta_at * NS_PER_S;
        let epoch = match scale {
            EpochScale::Tai => epoch_tai,
            EpochScale::Utc => epoch_tai.to_time_scale(TimeScale::UTC),
        };
        Ok(Self {
            epoch,
            scale,
            tai_ns,
            tt_ns_j2000: tai_ns + TT_MINUS_TAI_NS - j2000_count_ns,
            gpst_ns,
            ut1_minus_tai_ns,
            j2000_count_ns,
            eop,
            leap,
            offset_ns: 0,
        })
    }

    /// The epoch as a hifitime [`Epoch`] (in the scale it was written in).
    pub fn hifitime(&self) -> Epoch {
        self.epoch
    }

    /// The scale the epoch was written in.
    pub fn scale(&self) -> EpochScale {
        self.scale
    }

    /// The Earth orientation parameters given with the epoch.
    pub fn earth_orientation(&self) -> &EarthOrientationParams {
        &self.eop
    }

    /// \[ns\] TAI since 1958-01-01T00:00:00 TAI (the CCSDS Level 1 epoch) at `t_sim_ns`, as
    /// the time and environment messages carry it (0 before 1958, outside any accepted epoch).
    pub fn tai_ns_1958(&self, t_sim_ns: u64) -> u64 {
        u64::try_from(self.tai_ns(t_sim_ns) - TAI_1958_COUNT_NS).unwrap_or(0)
    }

    /// \[ns\] the TAI count (since 1900-01-01T00:00:00 TAI) at `t_sim_ns`; saturates past
    /// about the year 2192 (i64 nanoseconds), far beyond the accepted span.
    pub fn tai_ns(&self, t_sim_ns: u64) -> i64 {
        self.tai_ns
            .saturating_add(i64::try_from(t_sim_ns).unwrap_or(i64::MAX))
    }

    /// The time scales at `epoch + t_sim_ns`. Allocation-free, no `Result`.
    pub fn times(&self, t_sim_ns: u64) -> EpochTimes {
        let dt = i64::try_from(t_sim_ns).unwrap_or(i64::MAX);
        let tai = self.tai_ns.saturating_add(dt);
        let off = self.leap.offset_at_tai(tai);
        let gps = self.gpst_ns.saturating_add(dt);
        EpochTimes {
            t_sim_ns,
            tt_ns_j2000: self.tt_ns_j2000.saturating_add(dt),
            ut1_ns_j2000: (tai + self.ut1_minus_tai_ns).saturating_sub(self.j2000_count_ns),
            tai_minus_utc_s: off.delta_at_s,
            in_leap_second: off.in_leap_second,
            gps_week: gps.div_euclid(NS_PER_WEEK) as u32,
            gps_ns_of_week: gps.rem_euclid(NS_PER_WEEK) as u64,
        }
    }

    /// The UTC calendar reading at `epoch + t_sim_ns` (23:59:60.x during a leap second).
    /// Allocation-free, no `Result`.
    pub fn utc_calendar(&self, t_sim_ns: u64) -> CalendarTime {
        let tai = self.tai_ns(t_sim_ns);
        let off = self.leap.offset_at_tai(tai);
        let utc_count = tai - off.delta_at_s * NS_PER_S;
        if off.in_leap_second {
            // The count reads 00:00:00.x of the next day; the calendar says 23:59:60.x.
            let mut c = calendar_of_count(utc_count - NS_PER_S);
            c.second = 60;
            c
        } else {
            calendar_of_count(utc_count)
        }
    }

    /// The epoch in UTC, ISO 8601 with nanoseconds (`2026-03-20T12:00:00.000000000Z`), for
    /// metadata and file headers.
    pub fn utc_iso(&self) -> String {
        format!("{}Z", self.utc_calendar(0))
    }

    /// \[ns\] the TAI count of a UTC calendar reading (leap-second aware), e.g. an element
    /// set's epoch; `None` before 1972 or for an invalid date.
    pub fn utc_calendar_to_tai_ns(&self, cal: &CalendarTime) -> Option<i64> {
        let tai = tai_of_utc(&self.leap, cal).ok()?;
        (tai >= self.leap.first_utc_count_ns() + 10 * NS_PER_S).then_some(tai)
    }

    /// The last entry of the leap-second table in use: the UTC calendar date from which its ΔAT
    /// \[s\] applies (after it, ΔAT is held).
    pub fn last_leap_second(&self) -> (CalendarTime, i64) {
        let (u, d) = self.leap.last();
        (calendar_of_count(u), d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn utc(s: &str) -> SimEpoch {
        SimEpoch::parse(
            s,
            EpochScale::Utc,
            EarthOrientationParams::default(),
            "epoch.utc",
        )
        .unwrap()
    }

    #[test]
    fn tai_and_utc_forms_agree() {
        // ΔAT = 37 s since 2017 (IERS Bulletin C 52).
        let a = utc("2026-03-20T12:00:00Z");
        let b = SimEpoch::parse(
            "2026-03-20T12:00:37",
            EpochScale::Tai,
            EarthOrientationParams::default(),
            "epoch.tai",
        )
        .unwrap();
        assert_eq!(a.tai_ns(0), b.tai_ns(0));
        assert_eq!(a.times(0).tai_minus_utc_s, 37);
        assert_eq!(b.utc_iso(), "2026-03-20T12:00:00.000000000Z");
    }

    #[test]
    fn j2000_is_noon_tt() {
        // J2000.0 = 2000-01-01T12:00:00 TT = 11:58:55.816 UTC (ΔAT = 32 s).
        let e = utc("2000-01-01T11:58:55.816Z");
        assert_eq!(e.times(0).tt_ns_j2000, 0);
    }

    #[test]
    fn errors_name_the_field() {
        let eop = EarthOrientationParams::default();
        let e =
            SimEpoch::parse("2026-02-30T00:00:00Z", EpochScale::Utc, eop, "epoch.utc").unwrap_err();
        assert!(e.to_string().starts_with("epoch.utc: "), "{e}");
        let e =
            SimEpoch::parse("1969-07-20T20:17:40Z", EpochScale::Utc, eop, "epoch.utc").unwrap_err();
        assert!(matches!(e, EpochError::OutOfSpan { .. }), "{e}");
        let e =
            SimEpoch::parse("2026-03-20T12:00:00", EpochScale::Utc, eop, "epoch.utc").unwrap_err();
        assert!(e.to_string().contains("ends with `Z`"), "{e}");
        let bad = EarthOrientationParams {
            ut1_minus_utc_s: 1.2,
            ..eop
        };
        let e =
            SimEpoch::parse("2026-03-20T12:00:00Z", EpochScale::Utc, bad, "epoch.utc").unwrap_err();
        assert!(e.to_string().starts_with("epoch.ut1_minus_utc_s: "), "{e}");
        // 2015-12-31 had no leap second.
        let e =
            SimEpoch::parse("2015-12-31T23:59:60Z", EpochScale::Utc, eop, "epoch.utc").unwrap_err();
        assert!(matches!(e, EpochError::InvalidDate { .. }), "{e}");
    }
}
