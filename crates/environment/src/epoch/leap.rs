//! TAI − UTC from hifitime's IERS leap-second table, in integer nanoseconds.
//!
//! hifitime ships the IERS table (Bulletin C) as `hifitime::leap_seconds::LatestLeapSeconds`:
//! each entry gives ΔAT = TAI − UTC from a UTC instant on, written as a count of seconds since
//! 1900-01-01T00:00:00 (the same calendar count hifitime's TAI durations use). This module copies
//! the IERS-announced entries (1972 on; the pre-1972 rubber-second offsets are not integers and
//! are out of flexdyn's span) into integer nanoseconds once, and answers two questions exactly:
//!
//! - UTC → TAI: ΔAT at a UTC count `u` is the entry in force at `u` (`TAI = u + ΔAT`);
//! - TAI → UTC: ΔAT at a TAI count `T` is the `L` with `ΔAT(T − L) = L`. When no entry is
//!   consistent, `T` lies in an inserted leap second (23:59:60.x UTC) and ΔAT is the value before
//!   it.
//!
//! The second question is why flexdyn does not call `Epoch::to_gregorian_utc`: hifitime 4.3
//! looks ΔAT up with the TAI count itself, so for the ΔAT seconds before each leap second
//! (2016-12-31T23:59:24–23:59:60 UTC, for the last one) it returns a UTC one second early, and it
//! cannot show 23:59:60 (`crates/environment/tests/epoch.rs` shows both).

use hifitime::leap_seconds::LatestLeapSeconds;

const NS_PER_S: i64 = 1_000_000_000;

/// The integer leap-second table: `(utc_count_ns, delta_at_s)`, ascending.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LeapTable {
    entries: Vec<(i64, i64)>,
}

/// ΔAT at a TAI instant, and whether the instant is inside an inserted leap second.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UtcOffset {
    /// \[s\] TAI − UTC.
    pub delta_at_s: i64,
    /// The instant is within 23:59:60 of a day that ends with a leap second.
    pub in_leap_second: bool,
}

impl LeapTable {
    /// The IERS entries of hifitime's table.
    pub fn from_hifitime() -> Self {
        let entries = LatestLeapSeconds::default()
            .filter(|l| l.announced_by_iers)
            // Whole seconds (the IERS entries are integers in hifitime's table).
            .map(|l| {
                (
                    l.timestamp_tai_s.round() as i64 * NS_PER_S,
                    l.delta_at.round() as i64,
                )
            })
            .collect();
        Self { entries }
    }

    /// \[ns\] the UTC count from which the first entry (10 s, 1972-01-01) applies.
    pub fn first_utc_count_ns(&self) -> i64 {
        self.entries.first().map_or(i64::MAX, |e| e.0)
    }

    /// The last entry, `(utc_count_ns, delta_at_s)`.
    pub fn last(&self) -> (i64, i64) {
        self.entries.last().copied().unwrap_or((0, 0))
    }

    /// \[s\] ΔAT in force at UTC count `utc_ns` (0 before 1972).
    pub fn delta_at_utc(&self, utc_ns: i64) -> i64 {
        self.entries
            .iter()
            .rev()
            .find(|e| utc_ns >= e.0)
            .map_or(0, |e| e.1)
    }

    /// ΔAT at TAI count `tai_ns` (allocation-free; a reverse scan that stops at the first entry
    /// in force, so recent dates cost one or two comparisons).
    pub fn offset_at_tai(&self, tai_ns: i64) -> UtcOffset {
        // An upper bound: the table looked up at the TAI count (TAI ≥ UTC).
        let hi = self.delta_at_utc(tai_ns);
        if self.delta_at_utc(tai_ns - hi * NS_PER_S) == hi {
            return UtcOffset {
                delta_at_s: hi,
                in_leap_second: false,
            };
        }
        let lo = self.delta_at_utc(tai_ns - hi * NS_PER_S);
        UtcOffset {
            delta_at_s: lo,
            in_leap_second: self.delta_at_utc(tai_ns - lo * NS_PER_S) != lo,
        }
    }
}
