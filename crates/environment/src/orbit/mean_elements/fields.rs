//! The one place where OMM keywords become [`MeanElements`]: every format (KVN, XML, JSON, CSV)
//! is first read into a list of `KEYWORD = value [unit]` fields, then built here, so the checks
//! and their messages are the same whatever the file.
//!
//! Keywords and units are those of CCSDS 502.0-B-3, *Orbit Data Messages* (2023), §4 (OMM),
//! Tables 4-1 to 4-4; CelesTrak's and Space-Track's JSON/CSV use the same keywords.

use super::{ElementFormat, MeanElements};
use crate::epoch::parse::parse_date_time;

/// One `KEYWORD = value` of an element set, with its unit and line when the format has them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawField {
    pub key: String,
    pub value: String,
    pub unit: Option<String>,
    /// 1-based line in the file (0 when the format has no lines, e.g. JSON).
    pub line: usize,
}

/// The fields of one element set.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct RawSet {
    pub fields: Vec<RawField>,
}

/// Every OMM keyword of CCSDS 502.0-B-3 (versions 2.0 and 3.0), plus the `USER_DEFINED_`
/// prefix. KVN and XML files are checked against it; JSON and CSV are not (CelesTrak and
/// Space-Track add their own columns, e.g. `TLE_LINE1`, `DECAY_DATE`).
const OMM_KEYWORDS: &[&str] = &[
    "CCSDS_OMM_VERS",
    "COMMENT",
    "CLASSIFICATION",
    "CREATION_DATE",
    "ORIGINATOR",
    "MESSAGE_ID",
    "OBJECT_NAME",
    "OBJECT_ID",
    "CENTER_NAME",
    "REF_FRAME",
    "REF_FRAME_EPOCH",
    "TIME_SYSTEM",
    "MEAN_ELEMENT_THEORY",
    "EPOCH",
    "SEMI_MAJOR_AXIS",
    "MEAN_MOTION",
    "ECCENTRICITY",
    "INCLINATION",
    "RA_OF_ASC_NODE",
    "ARG_OF_PERICENTER",
    "MEAN_ANOMALY",
    "GM",
    "MASS",
    "SOLAR_RAD_AREA",
    "SOLAR_RAD_COEFF",
    "DRAG_AREA",
    "DRAG_COEFF",
    "EPHEMERIS_TYPE",
    "CLASSIFICATION_TYPE",
    "NORAD_CAT_ID",
    "ELEMENT_SET_NO",
    "REV_AT_EPOCH",
    "BSTAR",
    "BTERM",
    "MEAN_MOTION_DOT",
    "MEAN_MOTION_DDOT",
    "AGOM",
    "COV_REF_FRAME",
    "CX_X",
    "CY_X",
    "CY_Y",
    "CZ_X",
    "CZ_Y",
    "CZ_Z",
    "CX_DOT_X",
    "CX_DOT_Y",
    "CX_DOT_Z",
    "CX_DOT_X_DOT",
    "CY_DOT_X",
    "CY_DOT_Y",
    "CY_DOT_Z",
    "CY_DOT_X_DOT",
    "CY_DOT_Y_DOT",
    "CZ_DOT_X",
    "CZ_DOT_Y",
    "CZ_DOT_Z",
    "CZ_DOT_X_DOT",
    "CZ_DOT_Y_DOT",
    "CZ_DOT_Z_DOT",
];

/// Whether `key` is a CCSDS OMM keyword.
pub(crate) fn is_omm_keyword(key: &str) -> bool {
    OMM_KEYWORDS.contains(&key) || key.starts_with("USER_DEFINED_")
}

/// `KEY (line N)`, or `KEY` when the line is unknown.
pub(crate) fn at(key: &str, line: usize) -> String {
    if line == 0 {
        key.to_string()
    } else {
        format!("{key} (line {line})")
    }
}

impl RawSet {
    fn get(&self, key: &str) -> Option<&RawField> {
        self.fields
            .iter()
            .find(|f| f.key == key && !f.value.trim().is_empty())
    }

    fn required(&self, key: &str, why: &str) -> Result<&RawField, String> {
        self.get(key)
            .ok_or_else(|| format!("{key}: missing ({why})"))
    }

    /// A number with an optional expected unit (compared ignoring case and spaces).
    fn number(f: &RawField, unit: Option<&str>) -> Result<f64, String> {
        if let (Some(given), Some(want)) = (&f.unit, unit) {
            let norm = |s: &str| s.replace(' ', "").to_ascii_lowercase();
            if norm(given) != norm(want) {
                return Err(format!(
                    "{}: unit [{given}] where SGP4 takes [{want}]",
                    at(&f.key, f.line)
                ));
            }
        }
        let v = f.value.trim();
        match v.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(format!(
                "{}: expected a finite number, got {v:?}",
                at(&f.key, f.line)
            )),
        }
    }

    fn opt_number(&self, key: &str, unit: Option<&str>) -> Result<Option<f64>, String> {
        self.get(key).map(|f| Self::number(f, unit)).transpose()
    }

    fn req_number(&self, key: &str, unit: &str, why: &str) -> Result<f64, String> {
        Self::number(self.required(key, why)?, Some(unit))
    }

    fn text(&self, key: &str) -> Option<String> {
        self.get(key).map(|f| f.value.trim().to_string())
    }

    /// The value of metadata `key` must be one of `allowed` when present.
    fn expect_one_of(&self, key: &str, allowed: &[&str], why: &str) -> Result<(), String> {
        match self.get(key) {
            Some(f)
                if !allowed
                    .iter()
                    .any(|a| a.eq_ignore_ascii_case(f.value.trim())) =>
            {
                Err(format!(
                    "{}: {:?} is not supported ({why}; expected {})",
                    at(key, f.line),
                    f.value.trim(),
                    allowed.join(" or ")
                ))
            }
            _ => Ok(()),
        }
    }
}

/// Builds one element set from its fields. `strict_keys`: reject keywords that are not
/// CCSDS OMM keywords (KVN, XML) and repeated keywords.
pub(crate) fn build(
    set: &RawSet,
    format: ElementFormat,
    strict_keys: bool,
) -> Result<MeanElements, String> {
    for (i, f) in set.fields.iter().enumerate() {
        if strict_keys && !is_omm_keyword(&f.key) {
            return Err(format!(
                "{}: not a CCSDS OMM keyword (CCSDS 502.0-B-3 Tables 4-1 to 4-4)",
                at(&f.key, f.line)
            ));
        }
        if f.key != "COMMENT" && set.fields[..i].iter().any(|g| g.key == f.key) {
            return Err(format!(
                "{}: given twice in one element set",
                at(&f.key, f.line)
            ));
        }
    }
    set.expect_one_of("CENTER_NAME", &["EARTH"], "SGP4 orbits the Earth")?;
    set.expect_one_of("REF_FRAME", &["TEME"], "SGP4 elements are TEME of date")?;
    set.expect_one_of("TIME_SYSTEM", &["UTC"], "SGP4 element epochs are UTC")?;
    set.expect_one_of(
        "MEAN_ELEMENT_THEORY",
        &["SGP4", "SGP/SGP4"],
        "flexdyn propagates SGP4 element sets; SGP4-XP, DSST, Brouwer and other theories need \
         their own propagator",
    )?;
    set.expect_one_of(
        "EPHEMERIS_TYPE",
        &["0"],
        "type 0 is SGP4; other types (e.g. 4, SGP4-XP) need another propagator",
    )?;
    if set.get("MEAN_MOTION").is_none() && set.get("SEMI_MAJOR_AXIS").is_some() {
        return Err(
            "SEMI_MAJOR_AXIS is given instead of MEAN_MOTION: SGP4 takes the Kozai mean motion \
             [rev/day] (is this OMM for another theory?)"
                .to_string(),
        );
    }
    let epoch_field = set.required("EPOCH", "the UTC epoch of the elements")?;
    // The epoch is UTC whether or not it ends with `Z` (TIME_SYSTEM = UTC).
    let (epoch_utc, _zone) = parse_date_time(&epoch_field.value).map_err(|m| {
        format!(
            "{}: {:?} is not a date-time: {m}",
            at("EPOCH", epoch_field.line),
            epoch_field.value.trim()
        )
    })?;
    let why = "SGP4 needs it";
    let n = set.req_number("MEAN_MOTION", "rev/day", why)?;
    // Dimensionless: no unit to check.
    let e = RawSet::number(set.required("ECCENTRICITY", why)?, None)?;
    let inc = set.req_number("INCLINATION", "deg", why)?;
    let raan = set.req_number("RA_OF_ASC_NODE", "deg", why)?;
    let argp = set.req_number("ARG_OF_PERICENTER", "deg", why)?;
    let ma = set.req_number("MEAN_ANOMALY", "deg", why)?;
    let bstar = set.req_number(
        "BSTAR",
        "1/ER",
        "SGP4 needs the drag term B*; write 0 for none",
    )?;
    let ndot = set
        .opt_number("MEAN_MOTION_DOT", Some("rev/day**2"))?
        .unwrap_or(0.0);
    let nddot = set
        .opt_number("MEAN_MOTION_DDOT", Some("rev/day**3"))?
        .unwrap_or(0.0);
    let norad = match set.get("NORAD_CAT_ID") {
        None => None,
        Some(f) => Some(f.value.trim().parse::<u64>().map_err(|_| {
            format!(
                "{}: expected a catalogue number (a non-negative integer), got {:?}",
                at("NORAD_CAT_ID", f.line),
                f.value.trim()
            )
        })?),
    };
    let range = |key: &str, v: f64, ok: bool, what: &str| -> Result<(), String> {
        if ok {
            Ok(())
        } else {
            let line = set.get(key).map_or(0, |f| f.line);
            Err(format!("{}: {what} (got {v})", at(key, line)))
        }
    };
    range("MEAN_MOTION", n, n > 0.0, "must be > 0 rev/day")?;
    range(
        "ECCENTRICITY",
        e,
        (0.0..1.0).contains(&e),
        "must be in [0, 1)",
    )?;
    range(
        "INCLINATION",
        inc,
        (0.0..=180.0).contains(&inc),
        "must be in [0, 180] deg",
    )?;
    Ok(MeanElements {
        object_name: set.text("OBJECT_NAME"),
        object_id: set.text("OBJECT_ID"),
        norad_cat_id: norad,
        epoch_utc,
        mean_motion_rev_per_day: n,
        eccentricity: e,
        inclination_deg: inc,
        raan_deg: raan,
        arg_perigee_deg: argp,
        mean_anomaly_deg: ma,
        bstar_per_earth_radius: bstar,
        mean_motion_dot_rev_per_day2: ndot,
        mean_motion_ddot_rev_per_day3: nddot,
        format,
    })
}
