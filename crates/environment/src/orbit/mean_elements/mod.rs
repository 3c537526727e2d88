//! SGP4 mean elements (TLE, CCSDS OMM) and their propagation to the simulation epoch.
//!
//! # Formats
//! [`parse_element_sets`] recognises, from the text itself:
//! - TLE / 3LE (parsed by the `sgp4` crate, which checks the columns and checksums);
//! - CCSDS OMM KVN (`CCSDS_OMM_VERS = …`), `kvn`;
//! - CCSDS OMM XML (NDM/XML, as CelesTrak and Space-Track serve it), `xml`;
//! - OMM JSON (CelesTrak numbers, Space-Track strings), `json`;
//! - OMM CSV (CelesTrak, Space-Track), `csv`.
//!
//! The `sgp4` crate reads TLEs and (with its `serde` feature) CelesTrak JSON only, with messages
//! that do not name the field; every OMM form is therefore read here into keyword fields and
//! built in one place (`fields`), which checks the metadata (centre EARTH, frame TEME, time
//! system UTC, theory SGP4, ephemeris type 0), the units, the ranges, and names the keyword
//! (and line) of any problem.
//!
//! # Propagation
//! [`Sgp4Propagator`] drives the `sgp4` crate as Vallado's reference SGP4 runs in its
//! "improved" mode (`opsmode = 'i'`, Vallado et al. 2006, AIAA 2006-6753): WGS-72 constants
//! (the constants the element sets are fitted with; the paper's §"Gravitational constants"
//! keeps WGS-72 for TLEs), the IAU 1982 GMST in the deep-space initialisation
//! (`iau_epoch_to_sidereal_time`), the corrected Lyddane choice (`Constants::propagate`), and the
//! element epoch as a Julian date in one `f64` as Vallado's `jday` forms it. That is the
//! configuration whose output is the published verification file `tcppver.out`, which
//! `crates/environment/tests/sgp4_orbit.rs` reproduces to 0.2 mm over all 33 cases. (The crate's
//! "AFSPC compatibility" mode differs from that file by 0.9 km for the Lyddane deep-space case
//! 23599 after 420 min; its default mode uses WGS-84 constants.) A position inside the Earth
//! is an error, as Vallado's error 6 ("decayed"), which the crate itself does not report.
//!
//! Time since the element epoch is the elapsed SI time (TAI difference) between the element
//! epoch (UTC) and `epoch + t_sim_ns`. The TEME result is rotated to N by
//! [`crate::earth_rotation::dcm_n_teme`].

mod csv;
mod fields;
mod json;
mod kvn;
mod tle;
mod xml;

use nalgebra::Vector3;

use crate::earth_rotation::{dcm_n_teme, CelestialPole};
use crate::epoch::{CalendarTime, SimEpoch, NS_PER_S};

/// The form an element set was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementFormat {
    /// Two-line element set.
    Tle,
    /// CCSDS OMM, keyword = value notation.
    OmmKvn,
    /// CCSDS OMM, XML.
    OmmXml,
    /// OMM keywords in JSON.
    OmmJson,
    /// OMM keywords in CSV.
    OmmCsv,
}

impl ElementFormat {
    /// A short name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Tle => "TLE",
            Self::OmmKvn => "OMM (KVN)",
            Self::OmmXml => "OMM (XML)",
            Self::OmmJson => "OMM (JSON)",
            Self::OmmCsv => "OMM (CSV)",
        }
    }
}

/// One SGP4 element set (TEME of date, Kozai mean motion), as read.
#[derive(Debug, Clone, PartialEq)]
pub struct MeanElements {
    /// `OBJECT_NAME` / the TLE's name line.
    pub object_name: Option<String>,
    /// `OBJECT_ID`, the international designator.
    pub object_id: Option<String>,
    /// `NORAD_CAT_ID`, the catalogue number.
    pub norad_cat_id: Option<u64>,
    /// `EPOCH`, UTC.
    pub epoch_utc: CalendarTime,
    /// \[rev/day\] `MEAN_MOTION` (Kozai).
    pub mean_motion_rev_per_day: f64,
    /// \[-\] `ECCENTRICITY`.
    pub eccentricity: f64,
    /// \[deg\] `INCLINATION`.
    pub inclination_deg: f64,
    /// \[deg\] `RA_OF_ASC_NODE`.
    pub raan_deg: f64,
    /// \[deg\] `ARG_OF_PERICENTER`.
    pub arg_perigee_deg: f64,
    /// \[deg\] `MEAN_ANOMALY`.
    pub mean_anomaly_deg: f64,
    /// \[1/Earth radii\] `BSTAR`, SGP4's drag term.
    pub bstar_per_earth_radius: f64,
    /// \[rev/day²\] `MEAN_MOTION_DOT` (informational; SGP4 does not use it).
    pub mean_motion_dot_rev_per_day2: f64,
    /// \[rev/day³\] `MEAN_MOTION_DDOT` (informational; SGP4 does not use it).
    pub mean_motion_ddot_rev_per_day3: f64,
    /// Where it was read from.
    pub format: ElementFormat,
}

impl MeanElements {
    /// `NAME (NORAD 25544)`, or what is known of it.
    pub fn label(&self) -> String {
        match (&self.object_name, self.norad_cat_id) {
            (Some(n), Some(id)) => format!("{n} (NORAD {id})"),
            (Some(n), None) => n.clone(),
            (None, Some(id)) => format!("NORAD {id}"),
            (None, None) => "an unnamed element set".to_string(),
        }
    }
}

/// A problem with an element set or its propagation; `context` names the configuration field
/// (and file), `message` the keyword or line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{context}: {message}")]
pub struct ElementSetError {
    /// The configuration field and file, e.g. `orbit.elements_file (iss.xml)`.
    pub context: String,
    /// What is wrong, naming the OMM keyword or TLE line.
    pub message: String,
}

/// Every element set in `text` (TLE, OMM KVN/XML/JSON/CSV, recognised from the text).
/// `context` prefixes errors.
pub fn parse_element_sets(text: &str, context: &str) -> Result<Vec<MeanElements>, ElementSetError> {
    let err = |message: String| ElementSetError {
        context: context.to_string(),
        message,
    };
    let t = text.trim_start_matches('\u{feff}').trim();
    let (format, sets) = if t.starts_with('<') {
        (ElementFormat::OmmXml, xml::read(t).map_err(err)?)
    } else if t.starts_with('{') || t.starts_with('[') {
        (ElementFormat::OmmJson, json::read(t).map_err(err)?)
    } else if tle::looks_like(t) {
        return tle::read(t).map_err(|m| err(format!("TLE {m}")));
    } else if t
        .lines()
        .next()
        .is_some_and(|l| l.contains(',') && !l.contains('='))
    {
        (ElementFormat::OmmCsv, csv::read(t).map_err(err)?)
    } else if t.lines().any(|l| l.contains('=')) {
        (ElementFormat::OmmKvn, kvn::read(t).map_err(err)?)
    } else {
        return Err(err(
            "not a recognised element set: expected a TLE (lines `1 …`, `2 …`), or a CCSDS OMM \
             as KVN (`CCSDS_OMM_VERS = …`), XML (`<omm>`), JSON or CSV"
                .to_string(),
        ));
    };
    let strict = matches!(format, ElementFormat::OmmKvn | ElementFormat::OmmXml);
    let n = sets.len();
    sets.iter()
        .enumerate()
        .map(|(i, s)| {
            fields::build(s, format, strict).map_err(|m| {
                err(if n > 1 {
                    format!("{} element set {}: {m}", format.name(), i + 1)
                } else {
                    format!("{}: {m}", format.name())
                })
            })
        })
        .collect()
}

/// The one element set of `sets` to use: the one with catalogue number `norad_cat_id` if given,
/// else the only one.
pub fn select_element_set(
    sets: Vec<MeanElements>,
    norad_cat_id: Option<u64>,
    context: &str,
) -> Result<MeanElements, ElementSetError> {
    let err = |message: String| ElementSetError {
        context: context.to_string(),
        message,
    };
    let names = |sets: &[MeanElements]| {
        let mut l: Vec<String> = sets.iter().take(8).map(MeanElements::label).collect();
        if sets.len() > 8 {
            l.push(format!("… {} more", sets.len() - 8));
        }
        l.join(", ")
    };
    match norad_cat_id {
        Some(id) => {
            let mut hits: Vec<MeanElements> = sets
                .iter()
                .filter(|s| s.norad_cat_id == Some(id))
                .cloned()
                .collect();
            match hits.len() {
                1 => Ok(hits.remove(0)),
                0 => Err(err(format!(
                    "no element set has NORAD_CAT_ID {id} (the file has: {})",
                    names(&sets)
                ))),
                k => Err(err(format!(
                    "{k} element sets have NORAD_CAT_ID {id}; keep one in the file"
                ))),
            }
        }
        None if sets.len() == 1 => Ok(sets.into_iter().next().expect("one element")),
        None => Err(err(format!(
            "the file holds {} element sets ({}): choose one with norad_cat_id",
            sets.len(),
            names(&sets)
        ))),
    }
}

/// The element epoch in Julian years UTC since J2000 as Vallado's code forms it (`jday`: a
/// Julian date in one `f64`, then (JD − 2451545)/365.25), through the crate's function for it:
/// the deep-space terms (lunar–solar, resonance) take it, and the 40 µs quantum of that `f64`
/// shows in the reference output (`tcppver.out`) at the millimetre level (case 23333).
fn afspc_epoch_years(c: &CalendarTime) -> Option<f64> {
    let dt = sgp4::chrono::NaiveDate::from_ymd_opt(c.year, u32::from(c.month), u32::from(c.day))?
        .and_hms_nano_opt(
        u32::from(c.hour),
        u32::from(c.minute),
        u32::from(c.second.min(59)),
        c.nanosecond,
    )?;
    Some(sgp4::julian_years_since_j2000_afspc_compatibility_mode(&dt))
}

/// SGP4 for one element set, tied to a simulation epoch's leap-second table.
#[derive(Debug, Clone)]
pub struct Sgp4Propagator {
    constants: sgp4::Constants,
    /// \[ns\] the element epoch as a TAI count.
    element_epoch_tai_ns: i64,
    label: String,
}

impl Sgp4Propagator {
    /// Initialises SGP4 (Vallado's improved mode, WGS-72, see the module docs) for `el`.
    pub fn new(
        el: &MeanElements,
        epoch: &SimEpoch,
        context: &str,
    ) -> Result<Self, ElementSetError> {
        let err = |message: String| ElementSetError {
            context: context.to_string(),
            message: format!("{}: {message}", el.label()),
        };
        let element_epoch_tai_ns =
            epoch.utc_calendar_to_tai_ns(&el.epoch_utc).ok_or_else(|| {
                err("the element epoch is before 1972 (no leap-second-exact UTC)".to_string())
            })?;
        let deg = std::f64::consts::PI / 180.0;
        let epoch_years = afspc_epoch_years(&el.epoch_utc)
            .ok_or_else(|| err("the element epoch is not a calendar date".to_string()))?;
        let orbit = sgp4::Orbit::from_kozai_elements(
            &sgp4::WGS72,
            el.inclination_deg * deg,
            el.raan_deg * deg,
            el.eccentricity,
            el.arg_perigee_deg * deg,
            el.mean_anomaly_deg * deg,
            // rev/day → rad/min
            el.mean_motion_rev_per_day * (std::f64::consts::PI / 720.0),
        )
        .map_err(|e| err(format!("SGP4 rejects the elements: {e}")))?;
        let constants = sgp4::Constants::new(
            sgp4::WGS72,
            sgp4::iau_epoch_to_sidereal_time,
            epoch_years,
            el.bstar_per_earth_radius,
            orbit,
        )
        .map_err(|e| err(format!("SGP4 rejects the elements: {e}")))?;
        Ok(Self {
            constants,
            element_epoch_tai_ns,
            label: el.label(),
        })
    }

    /// \[min\] time from the element epoch to `epoch + t_sim_ns` (elapsed SI time).
    pub fn minutes_since_element_epoch(&self, epoch: &SimEpoch, t_sim_ns: u64) -> f64 {
        (epoch.tai_ns(t_sim_ns) - self.element_epoch_tai_ns) as f64 / (60.0 * NS_PER_S as f64)
    }

    /// \[km, km/s\] SGP4's position and velocity in TEME, `minutes` after the element epoch.
    /// Besides the crate's errors, a position inside the Earth (|r| below WGS-72's equatorial
    /// radius) is an error, as in Vallado's SGP4 (error 6, "satellite has decayed"), which the
    /// crate does not report.
    pub fn teme_km(&self, minutes: f64) -> Result<([f64; 3], [f64; 3]), String> {
        let p = self
            .constants
            .propagate(sgp4::MinutesSinceEpoch(minutes))
            .map_err(|e| e.to_string())?;
        let r_km = Vector3::from(p.position).norm();
        if r_km.is_nan() || r_km < sgp4::WGS72.ae {
            return Err(format!(
                "the satellite has decayed: SGP4 places it {:.1} km below the Earth's \
                 equatorial radius",
                sgp4::WGS72.ae - r_km
            ));
        }
        Ok((p.position, p.velocity))
    }

    /// \[m, m/s\] position and velocity in N at `epoch + t_sim_ns`: SGP4 in TEME, rotated by
    /// `[N TEME]` (velocity with the same rotation: TEME turns with precession–nutation only,
    /// < 1e-11 rad/s, a µm/s effect at LEO). Not for the stepping path (it allocates on error).
    pub fn state_n(
        &self,
        epoch: &SimEpoch,
        t_sim_ns: u64,
        context: &str,
    ) -> Result<(Vector3<f64>, Vector3<f64>), ElementSetError> {
        let minutes = self.minutes_since_element_epoch(epoch, t_sim_ns);
        let (r, v) = self.teme_km(minutes).map_err(|m| ElementSetError {
            context: context.to_string(),
            message: format!(
                "{}: SGP4 fails {:.3} days after the element epoch: {m}",
                self.label,
                minutes / 1440.0
            ),
        })?;
        let times = epoch.times(t_sim_ns);
        let dcm = dcm_n_teme(&CelestialPole::at(times.tt_centuries_j2000()), &times);
        let r_n_m = dcm * Vector3::from(r) * 1e3;
        let v_n_m_s = dcm * Vector3::from(v) * 1e3;
        Ok((r_n_m, v_n_m_s))
    }
}
