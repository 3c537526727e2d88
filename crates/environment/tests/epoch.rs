//! The simulation epoch's time scales against published conversions.

use flexdyn_environment::epoch::{
    CalendarTime, EarthOrientationParams, EpochScale, SimEpoch, NS_PER_DAY, NS_PER_S,
};
use hifitime::{Duration, Epoch};

fn utc(s: &str) -> SimEpoch {
    SimEpoch::parse(
        s,
        EpochScale::Utc,
        EarthOrientationParams::default(),
        "epoch.utc",
    )
    .unwrap()
}

fn cal(y: i32, mo: u8, d: u8, h: u8, mi: u8, s: u8, ns: u32) -> CalendarTime {
    CalendarTime {
        year: y,
        month: mo,
        day: d,
        hour: h,
        minute: mi,
        second: s,
        nanosecond: ns,
    }
}

const HALF_S: u64 = 500_000_000;

/// IERS Bulletin C 52 (6 July 2016): a positive leap second at the end of 2016-12-31;
/// TAI − UTC = 36 s until then, 37 s from 2017-01-01T00:00:00 UTC. Simulation time runs on
/// through it; the UTC calendar must read 23:59:59, 23:59:60, then 00:00:00.
#[test]
fn validate_leap_second_2016_utc_fields() {
    let e = utc("2016-12-31T23:59:58.5Z");
    let expect = [
        (0, cal(2016, 12, 31, 23, 59, 58, 500_000_000), 36, false),
        (HALF_S, cal(2016, 12, 31, 23, 59, 59, 0), 36, false),
        (
            2 * HALF_S,
            cal(2016, 12, 31, 23, 59, 59, 500_000_000),
            36,
            false,
        ),
        (3 * HALF_S, cal(2016, 12, 31, 23, 59, 60, 0), 36, true),
        (
            4 * HALF_S,
            cal(2016, 12, 31, 23, 59, 60, 500_000_000),
            36,
            true,
        ),
        (
            5 * HALF_S - 1,
            cal(2016, 12, 31, 23, 59, 60, 999_999_999),
            36,
            true,
        ),
        (5 * HALF_S, cal(2017, 1, 1, 0, 0, 0, 0), 37, false),
        (6 * HALF_S, cal(2017, 1, 1, 0, 0, 0, 500_000_000), 37, false),
    ];
    for (t, want, dat, leap) in expect {
        assert_eq!(e.utc_calendar(t), want, "t = {t} ns");
        let times = e.times(t);
        assert_eq!(
            (times.tai_minus_utc_s, times.in_leap_second),
            (dat, leap),
            "t = {t} ns"
        );
    }
    // The leap second itself as the epoch: 2016-12-31T23:59:60Z = 2017-01-01T00:00:36 TAI.
    let at_leap = utc("2016-12-31T23:59:60Z");
    let tai = SimEpoch::parse(
        "2017-01-01T00:00:36",
        EpochScale::Tai,
        EarthOrientationParams::default(),
        "epoch.tai",
    )
    .unwrap();
    assert_eq!(at_leap.tai_ns(0), tai.tai_ns(0));
    assert_eq!(at_leap.tai_ns(0), e.tai_ns(3 * HALF_S));
    assert_eq!(tai.utc_iso(), "2016-12-31T23:59:60.000000000Z");
    // 2017-01-01T00:00:00Z is one SI second after 23:59:60Z.
    assert_eq!(
        utc("2017-01-01T00:00:00Z").tai_ns(0) - at_leap.tai_ns(0),
        NS_PER_S
    );
}

/// The 36 seconds before the leap second (23:59:24 to 23:59:60 UTC) are where hifitime 4.3's own
/// TAI → UTC conversion (`to_gregorian_utc`) is one second early, and at 23:59:60 it cannot
/// say 60 — the reason `SimEpoch` derives UTC itself from hifitime's table. This test pins
/// that behaviour of hifitime: if it fails, hifitime has changed and flexdyn's workaround
/// (`crates/environment/src/epoch/leap.rs`) can be revisited. flexdyn's calendar is checked beside it.
#[test]
fn hifitime_to_gregorian_utc_is_a_second_off_before_a_leap_second() {
    let e = utc("2016-12-31T23:59:30Z");
    assert_eq!(e.utc_calendar(0), cal(2016, 12, 31, 23, 59, 30, 0));
    let tai_duration = |t_ns: u64| {
        Epoch::from_tai_duration(Duration::from_total_nanoseconds(i128::from(e.tai_ns(t_ns))))
    };
    let (_, _, _, h, m, s, _) = tai_duration(0).to_gregorian_utc();
    assert_eq!(
        (h, m, s),
        (23, 59, 29),
        "hifitime's UTC 36 s before the leap second"
    );
    // 23:59:60.5 UTC.
    let t_leap = 30 * NS_PER_S as u64 + HALF_S;
    assert_eq!(
        e.utc_calendar(t_leap),
        cal(2016, 12, 31, 23, 59, 60, 500_000_000)
    );
    let (_, _, _, h, m, s, _) = tai_duration(t_leap).to_gregorian_utc();
    assert_eq!((h, m, s), (23, 59, 59), "hifitime's UTC in the leap second");
}

/// IS-GPS-200 §3.3.4: GPS time counts weeks from 1980-01-06T00:00:00 UTC and does not step with
/// leap seconds (GPS − UTC = ΔAT − 19 s). The 10-bit week counter rolled over at the start of
/// week 1024, 1999-08-22T00:00:00 GPST = 1999-08-21T23:59:47 UTC (GPS − UTC = 13 s), and of
/// week 2048, 2019-04-07T00:00:00 GPST = 2019-04-06T23:59:42 UTC (GPS − UTC = 18 s), as the
/// US Coast Guard NAVCEN rollover advisories and IERS Bulletin C give them.
#[test]
fn validate_gps_week_and_seconds() {
    let e = utc("1980-01-06T00:00:00Z");
    let t = e.times(0);
    assert_eq!(
        (t.gps_week, t.gps_ns_of_week, t.gps_minus_utc_s()),
        (0, 0, 0)
    );

    let e = utc("1999-08-21T23:59:46Z");
    let (before, at) = (e.times(0), e.times(NS_PER_S as u64));
    assert_eq!(
        (before.gps_week, before.gps_seconds_of_week()),
        (1023, 604799.0)
    );
    assert_eq!(
        (at.gps_week, at.gps_ns_of_week, at.gps_minus_utc_s()),
        (1024, 0, 13)
    );

    let e = utc("2019-04-06T23:59:41Z");
    let (before, at) = (e.times(0), e.times(NS_PER_S as u64));
    assert_eq!(
        (before.gps_week, before.gps_seconds_of_week()),
        (2047, 604799.0)
    );
    assert_eq!(
        (at.gps_week, at.gps_ns_of_week, at.gps_minus_utc_s()),
        (2048, 0, 18)
    );
    // Half a week later.
    let mid = e.times(NS_PER_S as u64 + 302_400 * NS_PER_S as u64 + 250_000_000);
    assert_eq!(
        (mid.gps_week, mid.gps_ns_of_week),
        (2048, 302_400_250_000_000)
    );
}

/// Vallado, Fundamentals of Astrodynamics and Applications (4th ed.), Example 3-14/3-15: on
/// 2004-04-06 07:51:28.386009 UTC with ΔAT = 32 s and UT1 − UTC = −0.4399619 s,
/// JD_UT1 = 2453101.827406783 and JD_TT = 2453101.828154745 (printed to 1e-9 day = 86 µs).
#[test]
fn validate_vallado_julian_dates() {
    let eop = EarthOrientationParams {
        ut1_minus_utc_s: -0.4399619,
        ..EarthOrientationParams::default()
    };
    let e = SimEpoch::parse(
        "2004-04-06T07:51:28.386009Z",
        EpochScale::Utc,
        eop,
        "epoch.utc",
    )
    .unwrap();
    let t = e.times(0);
    assert_eq!(t.tai_minus_utc_s, 32);
    let jd_ut1 = 2451545.0 + t.ut1_days_j2000();
    let jd_tt = 2451545.0 + t.tt_days_j2000();
    assert!(
        (jd_ut1 - 2453101.827406783).abs() <= 5e-10,
        "JD_UT1 {jd_ut1}"
    );
    assert!((jd_tt - 2453101.828154745).abs() <= 5e-10, "JD_TT {jd_tt}");
    // TT − UTC = 32.184 s + ΔAT.
    assert_eq!(t.tt_ns_j2000 - t.ut1_ns_j2000, 64_184_000_000 + 439_961_900);
}

/// UT1 is continuous through a leap second (UT1 − UTC jumps by +1 s), so UT1 − TAI stays at its
/// epoch value: the Earth keeps turning at its rate while UTC stops for a second.
#[test]
fn ut1_is_continuous_across_a_leap_second() {
    let eop = EarthOrientationParams {
        ut1_minus_utc_s: -0.4,
        ..EarthOrientationParams::default()
    };
    let e = SimEpoch::parse("2016-12-31T23:59:00Z", EpochScale::Utc, eop, "epoch.utc").unwrap();
    let t0 = e.times(0);
    let t1 = e.times(120 * NS_PER_S as u64);
    assert_eq!(t1.ut1_ns_j2000 - t0.ut1_ns_j2000, 120 * NS_PER_S);
    assert_eq!(t1.tai_minus_utc_s - t0.tai_minus_utc_s, 1);
}

#[test]
fn tt_centuries_and_decimal_year() {
    // 2026-03-20T12:00:00Z: TT − UTC = 69.184 s; days since J2000 = 9575 + 69.184/86400.
    let t = utc("2026-03-20T12:00:00Z").times(0);
    let days = 9575.0 + 69.184 / 86400.0;
    assert!((t.tt_days_j2000() - days).abs() < 1e-12);
    assert!((t.tt_centuries_j2000() - days / 36525.0).abs() < 1e-16);
    // Noon of 2 July 2026 is 182.5 days into a 365-day year.
    let c = utc("2026-07-02T12:00:00Z").utc_calendar(0);
    assert!((c.decimal_year() - (2026.0 + 182.5 / 365.0)).abs() < 1e-12);
    assert_eq!(NS_PER_DAY, 86_400 * NS_PER_S);
}

/// `times` and `utc_calendar` run on the stepping path: no heap allocation.
#[test]
fn per_step_calls_do_not_allocate() {
    let e = utc("2016-12-31T23:59:58Z");
    let n = crate::allocations_in(|| {
        for k in 0..5_000u64 {
            let t = k * 1_000_000;
            std::hint::black_box(e.times(t));
            std::hint::black_box(e.utc_calendar(t));
        }
    });
    assert_eq!(n, 0);
}
