//! [`TickTime`]: the time of one tick as the runtime copies it from the server's `TimeMsg`
//! (`proto/src/messages.rs`), the only clock a device reads, so that a lockstep run repeats
//! byte for byte.

/// A UTC calendar reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Utc {
    /// Year.
    pub year: u16,
    /// Month, 1 to 12 (0 without an epoch).
    pub month: u8,
    /// Day of the month, 1 to 31 (0 without an epoch).
    pub day: u8,
    /// Hour, 0 to 23.
    pub hour: u8,
    /// Minute, 0 to 59.
    pub minute: u8,
    /// Second, 0 to 59, 60 inside a leap second.
    pub second: u8,
    /// Nanoseconds of the second.
    pub nanosecond: u32,
}

/// The time of a tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TickTime {
    /// The tick (frame) number.
    pub tick: u64,
    /// \[ns\] simulation time, tick · frame period.
    pub sim_time_ns: u64,
    /// The scenario has an epoch: the fields below are meaningful (zero otherwise).
    pub has_epoch: bool,
    /// \[ns\] TAI since 1958-01-01T00:00:00 TAI (the CCSDS level-1 epoch).
    pub tai_ns_1958: u64,
    /// UTC calendar reading.
    pub utc: Utc,
    /// Weeks since 1980-01-06 (GPS), not modulo 1024.
    pub gps_week: u32,
    /// \[ns\] since the start of the GPS week.
    pub gps_ns_of_week: u64,
    /// \[ns\] mission elapsed time.
    pub met_ns: u64,
}

/// A time value a field may carry (`source = "time.…"`), with its unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeSource {
    /// `time.tick`.
    Tick,
    /// `time.sim_time_s`.
    SimTimeS,
    /// `time.gps_week`.
    GpsWeek,
    /// `time.gps_seconds_of_week`.
    GpsSecondsOfWeek,
    /// `time.met_s`.
    MetS,
    /// `time.tai_s`: seconds since 1958-01-01 TAI.
    TaiS,
    /// `time.utc.year`.
    UtcYear,
    /// `time.utc.month`.
    UtcMonth,
    /// `time.utc.day`.
    UtcDay,
    /// `time.utc.hour`.
    UtcHour,
    /// `time.utc.minute`.
    UtcMinute,
    /// `time.utc.second` (60 in a leap second).
    UtcSecond,
    /// `time.utc.nanosecond`: the fraction of the UTC second, in seconds (its SI unit); a
    /// field with `unit = "ns"` carries the nanoseconds.
    UtcNanosecond,
}

impl TimeSource {
    /// Every time source with its name and SI unit.
    pub const ALL: [(&'static str, TimeSource, &'static str); 13] = [
        ("time.tick", TimeSource::Tick, "1"),
        ("time.sim_time_s", TimeSource::SimTimeS, "s"),
        ("time.gps_week", TimeSource::GpsWeek, "1"),
        (
            "time.gps_seconds_of_week",
            TimeSource::GpsSecondsOfWeek,
            "s",
        ),
        ("time.met_s", TimeSource::MetS, "s"),
        ("time.tai_s", TimeSource::TaiS, "s"),
        ("time.utc.year", TimeSource::UtcYear, "1"),
        ("time.utc.month", TimeSource::UtcMonth, "1"),
        ("time.utc.day", TimeSource::UtcDay, "1"),
        ("time.utc.hour", TimeSource::UtcHour, "1"),
        ("time.utc.minute", TimeSource::UtcMinute, "1"),
        ("time.utc.second", TimeSource::UtcSecond, "1"),
        ("time.utc.nanosecond", TimeSource::UtcNanosecond, "s"),
    ];

    /// The source of this name and its SI unit.
    pub fn by_name(name: &str) -> Option<(TimeSource, &'static str)> {
        Self::ALL
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|&(_, s, u)| (s, u))
    }

    /// The value at `now`, in the source's SI unit. Integer counts above 2⁵³ lose their
    /// low bits in `f64` (no tick count or calendar field comes near).
    pub fn value(self, now: &TickTime) -> f64 {
        const NS: f64 = 1e9;
        match self {
            TimeSource::Tick => now.tick as f64,
            TimeSource::SimTimeS => now.sim_time_ns as f64 / NS,
            TimeSource::GpsWeek => f64::from(now.gps_week),
            TimeSource::GpsSecondsOfWeek => now.gps_ns_of_week as f64 / NS,
            TimeSource::MetS => now.met_ns as f64 / NS,
            TimeSource::TaiS => now.tai_ns_1958 as f64 / NS,
            TimeSource::UtcYear => f64::from(now.utc.year),
            TimeSource::UtcMonth => f64::from(now.utc.month),
            TimeSource::UtcDay => f64::from(now.utc.day),
            TimeSource::UtcHour => f64::from(now.utc.hour),
            TimeSource::UtcMinute => f64::from(now.utc.minute),
            TimeSource::UtcSecond => f64::from(now.utc.second),
            TimeSource::UtcNanosecond => f64::from(now.utc.nanosecond) * 1e-9,
        }
    }
}
