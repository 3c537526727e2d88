//! The time service: the [`TimeMsg`] of a tick, computed from the tick, the `[epoch]` and the
//! run state. Allocation-free and without `Result`, so it runs on the stepping path.
//!
//! Definitions (the wire fields are documented in `proto/README.md`, "Time service"):
//! - **TAI** is counted in ns since 1958-01-01T00:00:00 TAI, the epoch of the CCSDS Level 1
//!   time code (CCSDS 301.0-B-4 §3.2.2), so the CUC coarse time is that count in seconds.
//! - **UTC** and the leap-second count ΔAT come from [`SimEpoch`], which reads hifitime's IERS
//!   table (no table is written here).
//! - **GPS** week and time of week: GPS time = TAI − 19 s from 1980-01-06T00:00:00 UTC
//!   (IS-GPS-200, §3.3.4), also from [`SimEpoch::times`].
//! - **MET** is the time since the epoch (simulation time zero).
//! - **Tone**: the frame whose time is the first at or after a whole second of the tone scale
//!   (TAI with an epoch — TAI, UTC and GPS whole seconds coincide since their offsets are whole
//!   seconds — simulation time without one).

use flexdyn_proto::{
    time_flags, Header, Mode, RunState, SysTime, TimeMsg, UtcTime, CUC_PFIELD_TAI_4_3,
};

use flexdyn_environment::epoch::SimEpoch;

const NS_PER_S: u64 = 1_000_000_000;

pub use flexdyn_environment::epoch::TAI_1958_COUNT_NS;

/// The per-run constants of the time message.
#[derive(Clone, Debug)]
pub struct TimeService {
    epoch: Option<SimEpoch>,
    spacecraft_id: u32,
    frame_ns: u64,
    mode: Mode,
    speed: f64,
}

/// `ns` (< 1 s) as cFE subseconds, units of 2⁻³² s, truncated.
fn subseconds(ns: u64) -> u32 {
    ((ns << 32) / NS_PER_S) as u32
}

/// A duration in ns as a cFE `CFE_TIME_SysTime_t` (seconds wrap at 2³², in 2094 for TAI 1958).
fn sys_time(ns: u64) -> SysTime {
    SysTime {
        seconds: (ns / NS_PER_S) as u32,
        subseconds: subseconds(ns % NS_PER_S),
    }
}

/// TAI since 1958 as CCSDS CUC, P-field [`CUC_PFIELD_TAI_4_3`], 4 coarse and 3 fine octets
/// (2⁻²⁴ s, truncated), big-endian (CCSDS 301.0-B-4 §3.2.1).
pub fn cuc_tai_4_3(tai_ns_1958: u64) -> [u8; 8] {
    let coarse = ((tai_ns_1958 / NS_PER_S) as u32).to_be_bytes();
    let fine = (((tai_ns_1958 % NS_PER_S) << 24) / NS_PER_S) as u32;
    let f = fine.to_be_bytes();
    [
        CUC_PFIELD_TAI_4_3,
        coarse[0],
        coarse[1],
        coarse[2],
        coarse[3],
        f[1],
        f[2],
        f[3],
    ]
}

impl TimeService {
    /// The time service of a run: `speed` is the real-time pacing factor (ignored, written
    /// 0.0, outside real time).
    pub fn new(
        epoch: Option<SimEpoch>,
        spacecraft_id: u32,
        frame_ns: u64,
        mode: Mode,
        speed: f64,
    ) -> Self {
        Self {
            epoch,
            spacecraft_id,
            frame_ns,
            mode,
            speed: if mode == Mode::RealTime { speed } else { 0.0 },
        }
    }

    /// The time message of tick `k` (at `k · frame_ns`) in `run_state`.
    pub fn message(&self, k: u64, run_state: RunState) -> TimeMsg {
        let t_ns = k.saturating_mul(self.frame_ns);
        let mut m = TimeMsg {
            header: Header::new(self.spacecraft_id, k, t_ns, k),
            run_state,
            mode: self.mode,
            frame_ns: self.frame_ns,
            speed: self.speed,
            met_ns: t_ns,
            ..TimeMsg::default()
        };
        // The tone scale's reading at this tick, in ns.
        let tone_scale_ns = match &self.epoch {
            Some(e) => {
                let tai = e.tai_ns_1958(t_ns);
                let times = e.times(t_ns);
                let c = e.utc_calendar(t_ns);
                m.flags |= time_flags::EPOCH_VALID;
                if times.in_leap_second {
                    m.flags |= time_flags::LEAP_SECOND;
                }
                m.tai_ns_1958 = tai;
                m.utc = UtcTime {
                    year: u16::try_from(c.year).unwrap_or(0),
                    month: c.month,
                    day: c.day,
                    hour: c.hour,
                    minute: c.minute,
                    second: c.second,
                    nanosecond: c.nanosecond,
                };
                m.tai_minus_utc_s = times.tai_minus_utc_s as i32;
                m.gps_week = times.gps_week;
                m.gps_ns_of_week = times.gps_ns_of_week;
                m.cuc_tai = cuc_tai_4_3(tai);
                tai
            }
            None => t_ns,
        };
        // Eq. tone: (T(k−1), T(k)] holds a whole second, T(k−1) = T(k) − frame_ns; tick 0 only
        // when T(0) is one.
        let since_tone_ns = tone_scale_ns % NS_PER_S;
        let tone = if k == 0 {
            since_tone_ns == 0
        } else {
            tone_scale_ns / NS_PER_S > (tone_scale_ns - self.frame_ns.min(tone_scale_ns)) / NS_PER_S
        };
        if tone {
            m.flags |= time_flags::TONE;
        }
        // The most recent tone at or before this tick; none yet (zero) before the run's first.
        if let Some(met_at_tone) = t_ns.checked_sub(since_tone_ns) {
            m.tone_met = sys_time(met_at_tone);
            if m.flags & time_flags::EPOCH_VALID != 0 {
                m.tone_tai = sys_time(tone_scale_ns - since_tone_ns);
            }
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_environment::epoch::{EarthOrientationParams, EpochScale};

    const S: u64 = NS_PER_S;

    fn utc(text: &str) -> SimEpoch {
        SimEpoch::parse(
            text,
            EpochScale::Utc,
            EarthOrientationParams::default(),
            "epoch.utc",
        )
        .unwrap()
    }

    fn service(epoch: Option<SimEpoch>, frame_ns: u64) -> TimeService {
        TimeService::new(epoch, 7, frame_ns, Mode::Lockstep, 2.0)
    }

    fn hms(m: &TimeMsg) -> (u16, u8, u8, u8, u8, u8, u32) {
        let u = m.utc;
        (
            u.year,
            u.month,
            u.day,
            u.hour,
            u.minute,
            u.second,
            u.nanosecond,
        )
    }

    #[test]
    fn tai_1958_reference_is_hifitimes() {
        let e = hifitime::Epoch::from_gregorian_tai(1958, 1, 1, 0, 0, 0, 0);
        assert_eq!(
            e.to_tai_duration().total_nanoseconds(),
            i128::from(TAI_1958_COUNT_NS)
        );
    }

    /// The UTC field right across the leap second at the end of 2016 (IERS Bulletin C 52:
    /// 2016-12-31T23:59:60 inserted, TAI − UTC 36 s → 37 s from 2017-01-01).
    #[test]
    fn utc_across_the_2016_leap_second() {
        let t = service(Some(utc("2016-12-31T23:59:59Z")), S / 2);
        let at = |k| t.message(k, RunState::Running);
        assert_eq!(hms(&at(0)), (2016, 12, 31, 23, 59, 59, 0));
        assert_eq!(hms(&at(1)), (2016, 12, 31, 23, 59, 59, 500_000_000));
        assert_eq!(hms(&at(2)), (2016, 12, 31, 23, 59, 60, 0));
        assert_eq!(hms(&at(3)), (2016, 12, 31, 23, 59, 60, 500_000_000));
        assert_eq!(hms(&at(4)), (2017, 1, 1, 0, 0, 0, 0));
        let delta: Vec<i32> = (0..5).map(|k| at(k).tai_minus_utc_s).collect();
        assert_eq!(delta, [36, 36, 36, 36, 37]);
        let leap: Vec<bool> = (0..5)
            .map(|k| at(k).flags & time_flags::LEAP_SECOND != 0)
            .collect();
        assert_eq!(leap, [false, false, true, true, false]);
        // TAI runs on through it: 2017-01-01T00:00:00 UTC = 00:00:37 TAI, and 1958-01-01 to
        // 2017-01-01 is 59 years with 15 leap days (1960 … 2016): 21,550 days.
        assert_eq!(at(4).tai_ns_1958, (21_550 * 86_400 + 37) * S);
        assert_eq!(at(2).tai_ns_1958, at(4).tai_ns_1958 - S);
    }

    /// GPS week and seconds against published conversions: GPS week 1930 began on Sunday
    /// 2017-01-01 (00:00:00 GPS time = 2016-12-31T23:59:42 UTC, GPS − UTC = 18 s from
    /// 2017-01-01; USNO / IS-GPS-200 §3.3.4), and the second week-number rollover, week 2048
    /// (10-bit week 0), began at 2019-04-06T23:59:42 UTC (published as the GPS week
    /// rollover date, e.g. US DHS/CISA "GPS Week Number Roll-Over", 2019).
    #[test]
    fn gps_week_and_seconds_against_published_conversions() {
        let t = service(Some(utc("2017-01-01T00:00:00Z")), S);
        let m = t.message(0, RunState::Running);
        assert_eq!((m.gps_week, m.gps_ns_of_week), (1930, 18 * S));
        let t = service(Some(utc("2019-04-06T23:59:41Z")), S);
        let before = t.message(0, RunState::Running);
        let at = t.message(1, RunState::Running);
        assert_eq!(
            (before.gps_week, before.gps_ns_of_week),
            (2047, 604_799 * S)
        );
        assert_eq!((at.gps_week, at.gps_ns_of_week), (2048, 0));
        // GPS time = TAI − 19 s, from 1980-01-06T00:00:19 TAI: 8,040 days after 1958-01-01.
        let gps_epoch_1958_ns = (8_040 * 86_400 + 19) * S;
        assert_eq!(
            u64::from(at.gps_week) * 604_800 * S + at.gps_ns_of_week,
            at.tai_ns_1958 - gps_epoch_1958_ns
        );
    }

    /// CUC octets by hand: 2017-01-01T00:00:00.5 UTC is TAI 1,861,920,037.5 s after 1958
    /// (0x6EFAA525 s), half a second is 0x800000 in 2⁻²⁴ s.
    #[test]
    fn cuc_and_tone_times() {
        let t = service(Some(utc("2017-01-01T00:00:00.5Z")), S / 4);
        let m = t.message(0, RunState::Running);
        assert_eq!(m.cuc_tai, [0x1F, 0x6E, 0xFA, 0xA5, 0x25, 0x80, 0x00, 0x00]);
        // TAI .5 at tick 0: no tone; the first whole TAI second is at t = 0.5 s, tick 2.
        let tones: Vec<u64> = (0..12)
            .filter(|&k| t.message(k, RunState::Running).flags & time_flags::TONE != 0)
            .collect();
        assert_eq!(tones, [2, 6, 10]);
        // Before the run's first tone: zero; at and after it, the tone's MET and TAI.
        assert_eq!(
            (m.tone_met, m.tone_tai),
            (SysTime::default(), SysTime::default())
        );
        let m3 = t.message(3, RunState::Running);
        assert_eq!(
            m3.tone_met,
            SysTime {
                seconds: 0,
                subseconds: 0x8000_0000
            }
        );
        assert_eq!(
            m3.tone_tai,
            SysTime {
                seconds: 1_861_920_038,
                subseconds: 0
            }
        );
        // A quarter second as cFE subseconds, and a nanosecond truncated to 4 (2³²/10⁹ = 4.29).
        assert_eq!(subseconds(250_000_000), 0x4000_0000);
        assert_eq!(subseconds(1), 4);
        assert_eq!(cuc_tai_4_3(S - 1)[5..], [0xFF, 0xFF, 0xFF]);
    }

    /// The service gives byte for byte the message of the hand-derived golden vector
    /// (`proto/tests/golden.rs`, `TIME_GOLDEN`, exported as `proto/golden/time.bin`).
    #[test]
    fn matches_the_hand_derived_golden_vector() {
        let t = TimeService::new(
            Some(utc("2016-12-31T23:59:59.5Z")),
            0x1122_3344,
            125_000_000,
            Mode::RealTime,
            0.5,
        );
        let golden = std::fs::read(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../proto/golden/time.bin"),
        )
        .unwrap();
        assert_eq!(
            flexdyn_proto::encode(&t.message(6, RunState::Paused)),
            golden
        );
    }

    /// Without an epoch: the calendar fields are zero, the valid bit clear, and the tone runs on
    /// simulation seconds.
    #[test]
    fn without_an_epoch_only_simulation_time() {
        let t = service(None, 300_000_000);
        let m = t.message(5, RunState::Paused);
        assert_eq!(m.flags & time_flags::EPOCH_VALID, 0);
        assert_eq!(
            (
                m.tai_ns_1958,
                m.utc,
                m.tai_minus_utc_s,
                m.gps_week,
                m.gps_ns_of_week
            ),
            (0, UtcTime::default(), 0, 0, 0)
        );
        assert_eq!(m.cuc_tai, [0; 8]);
        assert_eq!(m.tone_tai, SysTime::default());
        assert_eq!(
            (m.header.sim_time_ns, m.met_ns),
            (1_500_000_000, 1_500_000_000)
        );
        assert_eq!(
            (m.header.seq, m.run_state, m.speed),
            (5, RunState::Paused, 0.0)
        );
        let tones: Vec<u64> = (0..12)
            .filter(|&k| t.message(k, RunState::Running).flags & time_flags::TONE != 0)
            .collect();
        // t = 0, 1.2, 2.1, 3.0 s: the first frames at or after 0, 1, 2 and 3 s.
        assert_eq!(tones, [0, 4, 7, 10]);
        assert_eq!(
            t.message(8, RunState::Running).tone_met,
            SysTime {
                seconds: 2,
                subseconds: 0
            }
        );
        let rt = TimeService::new(None, 7, S, Mode::RealTime, 2.0);
        assert_eq!(rt.message(0, RunState::Running).speed, 2.0);
    }
}
