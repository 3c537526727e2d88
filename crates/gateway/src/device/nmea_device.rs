//! [`NmeaDevice`]: a GPS receiver speaking NMEA 0183 (`protocol = "nmea0183"`), built on the
//! crate's sentence writers ([`crate::nmea`]). Bound to a catalog group `gps.<name>` with the
//! fields `gps_week`, `gps_seconds_of_week`, `r_be_e_m[0..2]` (ECEF position, m),
//! `v_be_e_m_s[0..2]` (ECEF velocity, m/s) and `valid` (1/0):
//!
//! - when: with the receiver's solutions, as a receiver sends its sentences: a sentence goes out
//!   at a tick the GPS group publishes, if its `every_s` has passed since it last went (the
//!   first solution always);
//! - time and date: the solution's own, from its GPS week and seconds of week (GPS time,
//!   IS-GPS-200 §3.3.4, turned to UTC by hifitime's leap-second table), as a receiver stamps its
//!   fix; without a fix (week 0) the tick's UTC ([`TickTime::utc`]); without an epoch nothing
//!   is sent (counted unsendable);
//! - latitude, longitude and height: WGS-84 geodetic from the ECEF position
//!   ([`flexdyn_environment::geodetic::geodetic_from_ecef`], Bowring 1976);
//! - GGA altitude: the height above the ellipsoid, with a geoid separation of 0 (the
//!   simulated receiver carries no geoid model, as a receiver may report, NMEA Revealed §GGA);
//! - GGA fix quality 1 (GPS) when `valid` ≥ 0.5, else 0; RMC status `A`/`V` and mode `A`/`N`
//!   likewise;
//! - RMC speed and course over ground: the ECEF velocity turned to local north-east-down
//!   ([`flexdyn_environment::geodetic::dcm_ned_ecef`]); speed = √(v_N² + v_E²) in knots
//!   (1 kn = 1852 m / 3600 s, exactly), course = atan2(v_E, v_N) in degrees, 0 to 360.
//!
//! Lines the driver sends are delimited and counted (unknown request): the receiver takes
//! no commands.

use hifitime::{Duration, Epoch, TimeScale};
use nalgebra::Vector3;

use flexdyn_environment::geodetic::{dcm_ned_ecef, geodetic_from_ecef};

use super::counters::DeviceCounters;
use super::time::TickTime;
use crate::framing::lines::LineDecoder;
use crate::framing::StreamDecoder;
use crate::nmea::{FixQuality, Gga, Mode, NmeaStyle, Rmc, Zda};

/// \[m/s\] one knot: 1852 m per hour.
const KNOT_M_S: f64 = 1852.0 / 3600.0;
/// \[ns\] from 1900-01-01 TAI (hifitime's reference) to 1958-01-01 TAI: 58 years with 14
/// leap days (1904 … 1956) = 21 184 days.
const TAI_1900_TO_1958_NS: i128 = 21_184 * 86_400 * 1_000_000_000;
/// The longest sentence written (NMEA 0183 allows 82 characters; the style's decimals may
/// make it longer): the text buffer's capacity.
pub const MAX_SENTENCE_BYTES: usize = 160;
/// The longest line read from the driver.
const MAX_LINE_BYTES: usize = 120;

/// A sentence type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SentenceKind {
    /// GGA.
    Gga,
    /// RMC.
    Rmc,
    /// ZDA.
    Zda,
}

impl SentenceKind {
    /// The sentence of a formatter name (`GGA`, `RMC`, `ZDA`), case-insensitive.
    pub fn by_name(name: &str) -> Option<Self> {
        [
            ("GGA", SentenceKind::Gga),
            ("RMC", SentenceKind::Rmc),
            ("ZDA", SentenceKind::Zda),
        ]
        .into_iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, k)| k)
    }
}

/// The GPS group's channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GpsChannels {
    /// The group (its freshness says a solution was published at the tick).
    pub group: usize,
    /// `gps_week`.
    pub gps_week: usize,
    /// `gps_seconds_of_week`.
    pub gps_seconds_of_week: usize,
    /// `r_be_e_m[0..2]`.
    pub r_be_e_m: [usize; 3],
    /// `v_be_e_m_s[0..2]`.
    pub v_be_e_m_s: [usize; 3],
    /// `valid`.
    pub valid: usize,
}

/// A GPS receiver's NMEA stream.
#[derive(Debug, Clone)]
pub struct NmeaDevice {
    gps: GpsChannels,
    style: NmeaStyle,
    satellites: u8,
    hdop: f64,
    sentences: Vec<(SentenceKind, u64)>,
    /// The tick each sentence last went out.
    last_sent: Vec<Option<u64>>,
    /// Where each sentence appended by the last `emit_due` ends in its `out`.
    frame_ends: Vec<usize>,
    text: String,
    lines: LineDecoder,
}

impl NmeaDevice {
    /// A receiver sending `sentences` (each with its period in frames).
    pub fn new(
        gps: GpsChannels,
        style: NmeaStyle,
        satellites: u8,
        hdop: f64,
        sentences: Vec<(SentenceKind, u64)>,
    ) -> Self {
        Self {
            gps,
            style,
            satellites,
            hdop,
            last_sent: vec![None; sentences.len()],
            frame_ends: Vec::with_capacity(sentences.len()),
            sentences,
            text: String::with_capacity(MAX_SENTENCE_BYTES),
            lines: LineDecoder::new(MAX_LINE_BYTES),
        }
    }

    /// The sentences and their periods in frames.
    pub fn sentences(&self) -> &[(SentenceKind, u64)] {
        &self.sentences
    }

    /// The most octets one [`NmeaDevice::emit_due`] appends.
    pub fn max_emit_len(&self) -> usize {
        self.sentences.len() * MAX_SENTENCE_BYTES
    }

    /// The UTC epoch of `now`, from its calendar reading; in a leap second (which the
    /// calendar constructor refuses) from its TAI.
    fn epoch(now: &TickTime) -> Option<Epoch> {
        if !now.has_epoch {
            return None;
        }
        let u = now.utc;
        Epoch::maybe_from_gregorian_utc(
            i32::from(u.year),
            u.month,
            u.day,
            u.hour,
            u.minute,
            u.second,
            u.nanosecond,
        )
        .ok()
        .or_else(|| {
            Some(Epoch::from_tai_duration(Duration::from_total_nanoseconds(
                TAI_1900_TO_1958_NS + i128::from(now.tai_ns_1958),
            )))
        })
    }

    /// Writes one sentence into the text buffer.
    fn write(&mut self, kind: SentenceKind, time: Epoch, values: &[f64]) -> bool {
        let get = |c: usize| values.get(c).copied().unwrap_or(f64::NAN);
        let r = Vector3::new(
            get(self.gps.r_be_e_m[0]),
            get(self.gps.r_be_e_m[1]),
            get(self.gps.r_be_e_m[2]),
        );
        let v = Vector3::new(
            get(self.gps.v_be_e_m_s[0]),
            get(self.gps.v_be_e_m_s[1]),
            get(self.gps.v_be_e_m_s[2]),
        );
        let valid = get(self.gps.valid) >= 0.5;
        let geodetic = geodetic_from_ecef(&r);
        let latitude_deg = geodetic.lat_rad.to_degrees();
        let longitude_deg = geodetic.lon_rad.to_degrees();
        self.text.clear();
        let written = match kind {
            SentenceKind::Gga => Gga {
                time,
                latitude_deg,
                longitude_deg,
                fix_quality: if valid {
                    FixQuality::Gps
                } else {
                    FixQuality::Invalid
                },
                satellites: self.satellites,
                hdop: self.hdop,
                altitude_msl_m: geodetic.height_m,
                geoid_separation_m: 0.0,
                dgps: None,
            }
            .write(&self.style, &mut self.text),
            SentenceKind::Rmc => {
                let v_ned = dcm_ned_ecef(geodetic.lat_rad, geodetic.lon_rad) * v;
                let speed_knots = v_ned.x.hypot(v_ned.y) / KNOT_M_S;
                let course_deg = v_ned.y.atan2(v_ned.x).to_degrees().rem_euclid(360.0);
                Rmc {
                    time,
                    valid,
                    latitude_deg,
                    longitude_deg,
                    speed_knots,
                    // rem_euclid can give exactly 360.0 for a tiny negative angle.
                    course_deg: if course_deg >= 360.0 { 0.0 } else { course_deg },
                    magnetic_variation_deg: None,
                    mode: Some(if valid {
                        Mode::Autonomous
                    } else {
                        Mode::NotValid
                    }),
                }
                .write(&self.style, &mut self.text)
            }
            SentenceKind::Zda => Zda {
                time,
                local_zone: None,
            }
            .write(&self.style, &mut self.text),
        };
        written.is_ok()
    }

    /// The time of the solution in `values`: its GPS week and seconds of week when it has a
    /// fix, else the tick's.
    fn solution_epoch(&self, now: &TickTime, values: &[f64]) -> Option<Epoch> {
        let tick = Self::epoch(now)?;
        let week = values.get(self.gps.gps_week).copied().unwrap_or(0.0);
        let sow = values
            .get(self.gps.gps_seconds_of_week)
            .copied()
            .unwrap_or(0.0);
        if !(week >= 1.0 && week < f64::from(u32::MAX) && (0.0..604_800.0).contains(&sow)) {
            return Some(tick);
        }
        let ns = (sow * 1e9).round() as u64;
        Some(Epoch::from_time_of_week(week as u32, ns, TimeScale::GPST))
    }

    /// Appends every sentence due at `now` (module note); returns the sentences written.
    pub fn emit_due(
        &mut self,
        now: &TickTime,
        values: &[f64],
        fresh: &[bool],
        counters: &mut DeviceCounters,
        out: &mut Vec<u8>,
    ) -> usize {
        let mut frames = 0;
        self.frame_ends.clear();
        if !fresh.get(self.gps.group).copied().unwrap_or(false) {
            return 0;
        }
        let time = self.solution_epoch(now, values);
        for i in 0..self.sentences.len() {
            let (kind, period) = self.sentences[i];
            if self.last_sent[i].is_some_and(|t| now.tick < t.saturating_add(period)) {
                continue;
            }
            self.last_sent[i] = Some(now.tick);
            match time {
                Some(time) if self.write(kind, time, values) => {
                    out.extend_from_slice(self.text.as_bytes());
                    self.frame_ends.push(out.len());
                    counters.frames_out += 1;
                    frames += 1;
                }
                _ => counters.unsendable += 1,
            }
        }
        frames
    }

    /// Where each sentence the last `emit_due` appended ends in its `out` (none after
    /// `take_bytes`: the receiver answers nothing).
    pub fn frame_ends(&self) -> &[usize] {
        &self.frame_ends
    }

    /// Delimits and counts the driver's lines.
    pub fn take_bytes(&mut self, bytes: &[u8], counters: &mut DeviceCounters) {
        self.frame_ends.clear();
        let mut lines = 0;
        self.lines.feed(bytes, &mut |_| lines += 1);
        counters.unknown_request += lines;
        counters.framing = *self.lines.counters();
    }
}
