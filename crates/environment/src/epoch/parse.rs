//! The date-time grammar of `[epoch]` and of CCSDS/TLE-derived epochs: ISO 8601 calendar
//! (`YYYY-MM-DDTHH:MM:SS[.f]`) or ordinal (`YYYY-DDDTHH:MM:SS[.f]`, CCSDS 301.0-B-4 ASCII time
//! code B) dates, with up to nine fractional digits. Only the *shape* is checked here; whether
//! the date exists (day 31 of April, second 60 of a day without a leap second) is checked by
//! hifitime when the instant is built ([`super::SimEpoch`]).

/// A calendar date-time as written, before any time-scale interpretation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CalendarTime {
    /// Gregorian year.
    pub year: i32,
    /// Month, 1–12.
    pub month: u8,
    /// Day of the month, 1–31.
    pub day: u8,
    /// Hour, 0–23.
    pub hour: u8,
    /// Minute, 0–59.
    pub minute: u8,
    /// Second, 0–60 (60 only during an inserted leap second).
    pub second: u8,
    /// \[ns\] fraction of the second, 0–999 999 999.
    pub nanosecond: u32,
}

/// What follows the seconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Zone {
    /// Nothing.
    None,
    /// `Z`, `z` or `+00:00`/`-00:00`: UTC.
    Utc,
}

/// Parses `text` as `date [T| ] HH:MM:SS[.fraction][zone]`, where `date` is `YYYY-MM-DD` or
/// `YYYY-DDD`. Returns the calendar time and the zone, or a message saying what is wrong.
pub fn parse_date_time(text: &str) -> Result<(CalendarTime, Zone), String> {
    let s = text.trim();
    let b = s.as_bytes();
    let mut p = Cursor { b, i: 0 };
    let year = p.digits(4, "a four-digit year")? as i32;
    p.expect(b'-', "`-` after the year")?;
    // Calendar (MM-DD) or ordinal (DDD) date.
    let (month, day) = if p.peek_digits() == 3 {
        let doy = p.digits(3, "a three-digit day of year")? as u16;
        month_day_of_ordinal(year, doy)?
    } else {
        let month = p.digits(2, "a two-digit month")? as u8;
        p.expect(b'-', "`-` after the month")?;
        let day = p.digits(2, "a two-digit day")? as u8;
        if !(1..=12).contains(&month) {
            return Err(format!("month {month} is out of range (1–12)"));
        }
        if !(1..=31).contains(&day) {
            return Err(format!("day {day} is out of range (1–31)"));
        }
        (month, day)
    };
    match p.next() {
        Some(b'T' | b't' | b' ') => {}
        _ => return Err("expected `T` between the date and the time".into()),
    }
    let hour = p.digits(2, "a two-digit hour")? as u8;
    p.expect(b':', "`:` after the hour")?;
    let minute = p.digits(2, "two-digit minutes")? as u8;
    p.expect(b':', "`:` after the minutes")?;
    let second = p.digits(2, "two-digit seconds")? as u8;
    if hour > 23 {
        return Err(format!("hour {hour} is out of range (0–23)"));
    }
    if minute > 59 {
        return Err(format!("minute {minute} is out of range (0–59)"));
    }
    if second > 60 {
        return Err(format!("second {second} is out of range (0–60)"));
    }
    let mut nanosecond = 0u32;
    if p.peek() == Some(b'.') {
        p.i += 1;
        let n = p.peek_digits();
        if n == 0 {
            return Err("expected digits after the decimal point".into());
        }
        if n > 9 {
            return Err(format!(
                "{n} fractional digits: at most 9 (nanoseconds) are accepted"
            ));
        }
        let frac = p.digits(n, "fractional seconds")? as u32;
        nanosecond = frac * 10u32.pow((9 - n) as u32);
    }
    let zone = match &s[p.i..] {
        "" => Zone::None,
        "Z" | "z" | "+00:00" | "-00:00" => Zone::Utc,
        rest => {
            return Err(format!(
                "unexpected `{rest}` after the seconds (only `Z` for UTC is accepted as a zone)"
            ))
        }
    };
    Ok((
        CalendarTime {
            year,
            month,
            day,
            hour,
            minute,
            second,
            nanosecond,
        },
        zone,
    ))
}

/// The calendar time of day-of-year `doy` (1-based) of `year` plus `ns_of_day` nanoseconds
/// (< one day), e.g. a TLE epoch `YYDDD.DDDDDDDD` converted exactly.
pub fn calendar_of_ordinal(year: i32, doy: u16, ns_of_day: u64) -> Result<CalendarTime, String> {
    const NS_PER_S: u64 = 1_000_000_000;
    if ns_of_day >= 86_400 * NS_PER_S {
        return Err(format!("{ns_of_day} ns is not within a day"));
    }
    let (month, day) = month_day_of_ordinal(year, doy)?;
    let s = ns_of_day / NS_PER_S;
    Ok(CalendarTime {
        year,
        month,
        day,
        hour: (s / 3600) as u8,
        minute: (s / 60 % 60) as u8,
        second: (s % 60) as u8,
        nanosecond: (ns_of_day % NS_PER_S) as u32,
    })
}

/// Month and day of day-of-year `doy` (1-based) of `year`.
fn month_day_of_ordinal(year: i32, doy: u16) -> Result<(u8, u8), String> {
    let leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    let lengths: [u16; 12] = [
        31,
        if leap { 29 } else { 28 },
        31,
        30,
        31,
        30,
        31,
        31,
        30,
        31,
        30,
        31,
    ];
    let days_in_year: u16 = lengths.iter().sum();
    if !(1..=days_in_year).contains(&doy) {
        return Err(format!(
            "day of year {doy} is out of range (1–{days_in_year} in {year})"
        ));
    }
    let mut rest = doy;
    for (m, len) in lengths.iter().enumerate() {
        if rest <= *len {
            return Ok((m as u8 + 1, rest as u8));
        }
        rest -= len;
    }
    unreachable!("doy ≤ days_in_year was checked")
}

struct Cursor<'a> {
    b: &'a [u8],
    i: usize,
}

impl Cursor<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }
    fn next(&mut self) -> Option<u8> {
        let c = self.peek();
        self.i += 1;
        c
    }
    fn peek_digits(&self) -> usize {
        self.b[self.i.min(self.b.len())..]
            .iter()
            .take_while(|c| c.is_ascii_digit())
            .count()
    }
    fn expect(&mut self, c: u8, what: &str) -> Result<(), String> {
        if self.peek() == Some(c) {
            self.i += 1;
            Ok(())
        } else {
            Err(format!("expected {what}"))
        }
    }
    fn digits(&mut self, n: usize, what: &str) -> Result<u64, String> {
        if self.peek_digits() < n {
            return Err(format!("expected {what}"));
        }
        let mut v = 0u64;
        for _ in 0..n {
            v = v * 10 + u64::from(self.b[self.i] - b'0');
            self.i += 1;
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calendar_and_ordinal_forms() {
        let (t, z) = parse_date_time("2026-03-20T12:00:00Z").unwrap();
        assert_eq!(
            (t.year, t.month, t.day, t.hour, t.second),
            (2026, 3, 20, 12, 0)
        );
        assert_eq!(z, Zone::Utc);
        // CCSDS ordinal date: day 64 of 2007 is 5 March.
        let (t, z) = parse_date_time("2007-064T10:34:41.4264").unwrap();
        assert_eq!((t.month, t.day, t.nanosecond), (3, 5, 426_400_000));
        assert_eq!(z, Zone::None);
        // Day 60 of a leap year is 29 February.
        let (t, _) = parse_date_time("2024-060T00:00:00").unwrap();
        assert_eq!((t.month, t.day), (2, 29));
        let (t, _) = parse_date_time("2016-12-31 23:59:60.5").unwrap();
        assert_eq!((t.second, t.nanosecond), (60, 500_000_000));
    }

    #[test]
    fn rejects_with_reasons() {
        for (s, want) in [
            ("2026-13-01T00:00:00Z", "month 13"),
            ("2026-03-20", "`T`"),
            ("2026-03-20T12:00Z", "`:` after the minutes"),
            ("2026-03-20T12:00:00.1234567891Z", "10 fractional digits"),
            ("2026-03-20T12:00:00+01:00", "unexpected `+01:00`"),
            ("2023-366T00:00:00", "day of year 366"),
            ("26-03-20T12:00:00Z", "four-digit year"),
            ("2026-03-20T24:00:00Z", "hour 24"),
        ] {
            let e = parse_date_time(s).unwrap_err();
            assert!(e.contains(want), "{s}: {e}");
        }
    }
}
