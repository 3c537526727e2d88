//! The orbit table: an initial orbit as an alternative to r/v. Exactly one of three forms:
//!
//! ```toml
//! # Classical elements (osculating, referred to N = GCRF):
//! semi_major_axis_m = 6_878_137.0   # or altitude_m = 500e3 (a = equatorial radius + altitude)
//! eccentricity = 0.001
//! inclination_deg = 97.4
//! raan_deg = 30.0
//! arg_perigee_deg = 90.0
//! true_anomaly_deg = 0.0            # or mean_anomaly_deg
//!
//! # Or SGP4 mean elements, inline (a TLE, or an OMM as KVN, XML, JSON or CSV) …
//! elements = """
//! ISS (ZARYA)
//! 1 25544U 98067A   …
//! 2 25544  51.6416 …
//! """
//! # … or from a file (path relative to the configuration file):
//! elements_file = "iss_omm.xml"
//! norad_cat_id = 25544              # to pick one set from a file that holds several
//! max_element_age_days = 30         # optional (default 30): refuse older/newer sets
//! ```
//!
//! The configuration decides where the table lives and which point (centre of mass or B) the
//! state describes; [`RawOrbit::initial_state_n`] turns it into r/v in N at the epoch.

use std::path::Path;

use nalgebra::Vector3;

use super::keplerian::{Anomaly, ElementsError, KeplerianElements};
use super::mean_elements::{
    parse_element_sets, select_element_set, ElementSetError, MeanElements, Sgp4Propagator,
};
use crate::epoch::SimEpoch;
use flexdyn_kernel::schema::{At, SchemaError, TableReader};

/// The keys of the orbit table (the first eight are the classical elements).
pub const KEYS: [&str; 13] = [
    "semi_major_axis_m",
    "altitude_m",
    "eccentricity",
    "inclination_deg",
    "raan_deg",
    "arg_perigee_deg",
    "true_anomaly_deg",
    "mean_anomaly_deg",
    "elements",
    "elements_file",
    "norad_cat_id",
    "max_element_age_days",
    // Reserved so that a misspelt `tle` is pointed at `elements`.
    "tle",
];

/// Default `max_element_age_days`: SGP4's error grows by about 1–3 km per day from the element
/// epoch (Vallado et al. 2006), so a month-old set is already tens of kilometres off.
pub const DEFAULT_MAX_ELEMENT_AGE_DAYS: f64 = 30.0;

/// The size of a Keplerian orbit as written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrbitSize {
    /// \[m\] semi-major axis.
    SemiMajorAxisM(f64),
    /// \[m\] a − equatorial radius (the altitude of a circular orbit).
    AltitudeM(f64),
}

/// The orbit table as written.
#[derive(Debug, Clone, PartialEq)]
pub enum RawOrbit {
    /// Classical elements (angles in degrees as written).
    Keplerian {
        /// Size.
        size: OrbitSize,
        /// \[-\] eccentricity.
        eccentricity: f64,
        /// \[deg\] inclination.
        inclination_deg: f64,
        /// \[deg\] RAAN.
        raan_deg: f64,
        /// \[deg\] argument of perigee.
        arg_perigee_deg: f64,
        /// `true_anomaly_deg` or `mean_anomaly_deg`, in radians.
        anomaly: Anomaly,
    },
    /// Element sets, inline or from a file.
    Elements {
        /// The text (inline), or `None` for a file.
        text: Option<String>,
        /// The path as written (`elements_file`).
        file: Option<String>,
        /// `norad_cat_id`.
        norad_cat_id: Option<u64>,
        /// \[days\] `max_element_age_days`.
        max_age_days: f64,
    },
}

/// A problem turning the orbit table into a state; names the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OrbitError {
    /// Bad classical elements.
    #[error(transparent)]
    Elements(#[from] ElementsError),
    /// A bad element set, file or propagation.
    #[error(transparent)]
    ElementSet(#[from] ElementSetError),
}

/// The initial orbit, resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialOrbit {
    /// \[m\] position in N at the epoch.
    pub r_n_m: Vector3<f64>,
    /// \[m/s\] velocity in N at the epoch.
    pub v_n_m_s: Vector3<f64>,
    /// The element set used, for SGP4 sources (for metadata and logs).
    pub mean_elements: Option<MeanElements>,
    /// \[days\] epoch − element epoch, for SGP4 sources.
    pub element_age_days: Option<f64>,
}

/// Reads the orbit table (opened with [`KEYS`]).
pub fn read(t: &TableReader<'_, '_>) -> Result<RawOrbit, SchemaError> {
    /// The value of exactly one of `a` and `b`, with `true` for `a`.
    fn one_of(
        t: &TableReader<'_, '_>,
        a: &str,
        b: &str,
    ) -> Result<Option<(bool, f64)>, SchemaError> {
        match (t.opt_f64(a)?, t.opt_f64(b)?) {
            (Some(x), None) => Ok(Some((true, x))),
            (None, Some(x)) => Ok(Some((false, x))),
            (None, None) => Ok(None),
            (Some(_), Some(_)) => Err(SchemaError::InvalidValue {
                field: t.field(b),
                message: format!(
                    "give one of `{}` and `{}`, not both",
                    t.field(a),
                    t.field(b)
                ),
                at: At(None),
            }),
        }
    }
    if t.get("tle").is_some() {
        return Err(SchemaError::InvalidValue {
            field: t.field("tle"),
            message: "write the TLE (or OMM) text as `elements`, or its file as `elements_file`"
                .to_string(),
            at: At(None),
        });
    }
    let kepler: Vec<&str> = KEYS[..8]
        .iter()
        .copied()
        .filter(|k| t.get(k).is_some())
        .collect();
    let sgp4_keys = [
        "elements",
        "elements_file",
        "norad_cat_id",
        "max_element_age_days",
    ];
    let sgp4: Vec<&str> = sgp4_keys
        .iter()
        .copied()
        .filter(|k| t.get(k).is_some())
        .collect();
    let conflict = |a: &str, b: &str| SchemaError::InvalidValue {
        field: t.field(b),
        message: format!(
            "`{}` and `{}` describe different orbits: give classical elements, `elements` or \
             `elements_file`",
            t.field(a),
            t.field(b)
        ),
        at: At(None),
    };
    if let (Some(a), Some(b)) = (kepler.first(), sgp4.first()) {
        return Err(conflict(a, b));
    }
    if !sgp4.is_empty() {
        let text = t
            .get("elements")
            .map(|_| t.string("elements"))
            .transpose()?;
        let file = t
            .get("elements_file")
            .map(|_| t.string("elements_file"))
            .transpose()?;
        let norad_cat_id = t
            .get("norad_cat_id")
            .map(|_| t.int_in("norad_cat_id", 0, 999_999_999).map(|v| v as u64))
            .transpose()?;
        let max_age_days = t
            .opt_f64("max_element_age_days")?
            .unwrap_or(DEFAULT_MAX_ELEMENT_AGE_DAYS);
        return match (&text, &file) {
            (Some(_), Some(_)) => Err(conflict("elements", "elements_file")),
            (None, None) => Err(SchemaError::MissingKey {
                field: format!("{} (or {})", t.field("elements"), t.field("elements_file")),
                at: At(None),
            }),
            _ => Ok(RawOrbit::Elements {
                text,
                file,
                norad_cat_id,
                max_age_days,
            }),
        };
    }
    let size = match one_of(t, "semi_major_axis_m", "altitude_m")? {
        Some((true, a)) => OrbitSize::SemiMajorAxisM(a),
        Some((false, h)) => OrbitSize::AltitudeM(h),
        None => {
            return Err(SchemaError::MissingKey {
                field: format!(
                    "{} (or {}, or `elements` / `elements_file`)",
                    t.field("semi_major_axis_m"),
                    t.field("altitude_m")
                ),
                at: At(None),
            })
        }
    };
    let anomaly = match one_of(t, "true_anomaly_deg", "mean_anomaly_deg")? {
        Some((true, v)) => Anomaly::TrueRad(v.to_radians()),
        Some((false, v)) => Anomaly::MeanRad(v.to_radians()),
        None => {
            return Err(SchemaError::MissingKey {
                field: format!(
                    "{} (or {})",
                    t.field("true_anomaly_deg"),
                    t.field("mean_anomaly_deg")
                ),
                at: At(None),
            })
        }
    };
    Ok(RawOrbit::Keplerian {
        size,
        eccentricity: t.f64("eccentricity")?,
        inclination_deg: t.f64("inclination_deg")?,
        raan_deg: t.f64("raan_deg")?,
        arg_perigee_deg: t.f64("arg_perigee_deg")?,
        anomaly,
    })
}

impl RawOrbit {
    /// The classical elements (validated), for `prefix` the table's path and `r_eq_m` the
    /// equatorial radius used by `altitude_m`.
    pub fn keplerian(
        &self,
        prefix: &str,
        r_eq_m: f64,
    ) -> Result<Option<KeplerianElements>, ElementsError> {
        let RawOrbit::Keplerian {
            size,
            eccentricity,
            inclination_deg,
            raan_deg,
            arg_perigee_deg,
            anomaly,
        } = self
        else {
            return Ok(None);
        };
        let (size_key, a) = match *size {
            OrbitSize::SemiMajorAxisM(a) => ("semi_major_axis_m", a),
            OrbitSize::AltitudeM(h) => ("altitude_m", r_eq_m + h),
        };
        let anomaly_key = match anomaly {
            Anomaly::TrueRad(_) => "true_anomaly_deg",
            Anomaly::MeanRad(_) => "mean_anomaly_deg",
        };
        let el = KeplerianElements {
            semi_major_axis_m: a,
            eccentricity: *eccentricity,
            inclination_rad: inclination_deg.to_radians(),
            raan_rad: raan_deg.to_radians(),
            arg_perigee_rad: arg_perigee_deg.to_radians(),
            anomaly: *anomaly,
        };
        el.validate(
            prefix,
            [
                size_key,
                "eccentricity",
                "inclination_deg",
                "raan_deg",
                "arg_perigee_deg",
                anomaly_key,
            ],
        )?;
        // A perigee below the equatorial radius is a trajectory into the Earth, not an orbit.
        let perigee_m = a * (1.0 - eccentricity);
        if perigee_m <= r_eq_m {
            let field = if prefix.is_empty() {
                size_key.to_string()
            } else {
                format!("{prefix}.{size_key}")
            };
            return Err(ElementsError {
                field,
                message: format!(
                    "the perigee radius a (1 − e) = {perigee_m} m is inside the Earth \
                     (equatorial radius {r_eq_m} m)"
                ),
            });
        }
        Ok(Some(el))
    }

    /// r/v in N at the epoch (`t_sim_ns = 0`). `prefix` is the table's path (`orbit`);
    /// `mu_m3_s2` and `r_eq_m` come from the gravity model (for classical elements); an
    /// `elements_file` path is resolved against `base_dir` (the configuration file's folder).
    pub fn initial_state_n(
        &self,
        prefix: &str,
        epoch: &SimEpoch,
        mu_m3_s2: f64,
        r_eq_m: f64,
        base_dir: &Path,
    ) -> Result<InitialOrbit, OrbitError> {
        if let Some(el) = self.keplerian(prefix, r_eq_m)? {
            let (r_n_m, v_n_m_s) = el.to_rv_n(mu_m3_s2);
            return Ok(InitialOrbit {
                r_n_m,
                v_n_m_s,
                mean_elements: None,
                element_age_days: None,
            });
        }
        let RawOrbit::Elements {
            text,
            file,
            norad_cat_id,
            max_age_days,
        } = self
        else {
            unreachable!("a RawOrbit is Keplerian or Elements");
        };
        let field = |k: &str| {
            if prefix.is_empty() {
                k.to_string()
            } else {
                format!("{prefix}.{k}")
            }
        };
        let (context, content) = match (text, file) {
            (Some(t), _) => (field("elements"), t.clone()),
            (None, Some(f)) => {
                let path = base_dir.join(f);
                let context = format!("{} ({})", field("elements_file"), path.display());
                let content = std::fs::read_to_string(&path).map_err(|e| ElementSetError {
                    context: context.clone(),
                    message: format!("cannot read the file: {e}"),
                })?;
                (context, content)
            }
            (None, None) => unreachable!("the reader requires one of them"),
        };
        let sets = parse_element_sets(&content, &context)?;
        let el = select_element_set(sets, *norad_cat_id, &context)?;
        let prop = Sgp4Propagator::new(&el, epoch, &context)?;
        let age_days = prop.minutes_since_element_epoch(epoch, 0) / 1440.0;
        if !max_age_days.is_finite() || *max_age_days <= 0.0 {
            return Err(ElementSetError {
                context: field("max_element_age_days"),
                message: format!("must be > 0 days (got {max_age_days})"),
            }
            .into());
        }
        if age_days.abs() > *max_age_days {
            return Err(ElementSetError {
                context,
                message: format!(
                    "{}: the element epoch is {:.1} days {} the simulation epoch, more than \
                     {} ({}): SGP4's error grows by about 1–3 km per day, so use a set nearer \
                     the epoch, or raise {}",
                    el.label(),
                    age_days.abs(),
                    if age_days >= 0.0 { "before" } else { "after" },
                    max_age_days,
                    field("max_element_age_days"),
                    field("max_element_age_days"),
                ),
            }
            .into());
        }
        let (r_n_m, v_n_m_s) = prop.state_n(epoch, 0, &context)?;
        Ok(InitialOrbit {
            r_n_m,
            v_n_m_s,
            mean_elements: Some(el),
            element_age_days: Some(age_days),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::epoch::{EarthOrientationParams, EpochScale};

    const MU: f64 = 3.986_004_418e14;
    const R_EQ: f64 = 6_378_137.0;

    fn read_str(body: &str) -> Result<RawOrbit, SchemaError> {
        let src = format!("[orbit]\n{body}");
        let doc = toml::de::DeTable::parse(&src).unwrap();
        let root = TableReader::root(&src, doc.get_ref(), &["orbit"]).unwrap();
        read(&root.table("orbit", &KEYS)?)
    }

    fn epoch(s: &str) -> SimEpoch {
        SimEpoch::parse(
            s,
            EpochScale::Utc,
            EarthOrientationParams::default(),
            "epoch.utc",
        )
        .unwrap()
    }

    fn state(raw: &RawOrbit, epoch_utc: &str) -> Result<InitialOrbit, OrbitError> {
        raw.initial_state_n("orbit", &epoch(epoch_utc), MU, R_EQ, &data_dir())
    }

    fn data_dir() -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/omm")
    }

    #[test]
    fn keplerian_with_altitude_and_mean_anomaly() {
        let raw = read_str(
            "altitude_m = 500e3\neccentricity = 0.0\ninclination_deg = 97.4\nraan_deg = 10\n\
             arg_perigee_deg = 0\nmean_anomaly_deg = 0\n",
        )
        .unwrap();
        let s = state(&raw, "2026-03-20T12:00:00Z").unwrap();
        // Circular: |r| = R + h, |v| = √(μ/r), at the ascending node (ν = 0 from it).
        assert!((s.r_n_m.norm() - (R_EQ + 500e3)).abs() < 1e-6);
        assert!((s.v_n_m_s.norm() - (MU / (R_EQ + 500e3)).sqrt()).abs() < 1e-9);
        assert!(s.r_n_m.z.abs() < 1e-6);
        assert!(s.mean_elements.is_none());
    }

    #[test]
    fn element_file_with_selection_and_age() {
        let raw = read_str("elements_file = \"mario.xml\"\nnorad_cat_id = 55123\n").unwrap();
        let s = state(&raw, "2023-04-25T12:00:00Z").unwrap();
        let age = s.element_age_days.unwrap();
        // 12:00:00 − 10:45:30.642912 = 4469.357088 s.
        assert!((age - 4_469.357_088 / 86_400.0).abs() < 1e-12, "{age}");
        assert!(
            (s.r_n_m.norm() / 1e3 - 6_600.0).abs() < 100.0,
            "{}",
            s.r_n_m.norm()
        );
        // Too old.
        let e = state(&raw, "2023-06-25T12:00:00Z").unwrap_err().to_string();
        assert!(
            e.contains("61.1 days before the simulation epoch")
                && e.contains("orbit.max_element_age_days"),
            "{e}"
        );
        // A missing file names the field and the path.
        let raw = read_str("elements_file = \"nope.tle\"\n").unwrap();
        let e = state(&raw, "2023-04-25T12:00:00Z").unwrap_err().to_string();
        assert!(
            e.starts_with("orbit.elements_file (") && e.contains("cannot read the file"),
            "{e}"
        );
    }

    #[test]
    fn inline_tle() {
        let tle = std::fs::read_to_string(data_dir().join("mario.tle")).unwrap();
        let raw = read_str(&format!("elements = \"\"\"\n{tle}\"\"\"\n")).unwrap();
        let s = state(&raw, "2023-04-25T10:45:30.642912Z").unwrap();
        assert!(s.element_age_days.unwrap().abs() < 1e-9);
        assert_eq!(s.mean_elements.unwrap().norad_cat_id, Some(55123));
    }

    #[test]
    fn one_form_only() {
        let e = read_str("altitude_m = 5e5\nelements_file = \"x\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("orbit.elements_file: ") && e.contains("different orbits"),
            "{e}"
        );
        let e = read_str("altitude_m = 5e5\nsemi_major_axis_m = 7e6\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("orbit.altitude_m: "), "{e}");
        let e = read_str("tle = \"1 …\"\n").unwrap_err().to_string();
        assert!(
            e.starts_with("orbit.tle: ") && e.contains("elements"),
            "{e}"
        );
        let e = read_str("norad_cat_id = 5\n").unwrap_err().to_string();
        assert!(e.contains("orbit.elements (or orbit.elements_file)"), "{e}");
        let e = read_str("altitude_m = 5e5\neccentricity = 0\ninclination_deg = 1\nraan_deg = 0\narg_perigee_deg = 0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("orbit.true_anomaly_deg (or orbit.mean_anomaly_deg)"),
            "{e}"
        );
        let raw = read_str(
            "altitude_m = 5e5\neccentricity = 1.5\ninclination_deg = 1\nraan_deg = 0\n\
             arg_perigee_deg = 0\ntrue_anomaly_deg = 0\n",
        )
        .unwrap();
        let e = state(&raw, "2026-03-20T12:00:00Z").unwrap_err().to_string();
        assert!(e.starts_with("orbit.eccentricity: "), "{e}");
        // a (1 − e) = 6,900 km × 0.05 = 345 km: inside the Earth.
        let raw = read_str(
            "semi_major_axis_m = 6.9e6\neccentricity = 0.95\ninclination_deg = 1\nraan_deg = 0\n\
             arg_perigee_deg = 0\ntrue_anomaly_deg = 0\n",
        )
        .unwrap();
        let e = state(&raw, "2026-03-20T12:00:00Z").unwrap_err().to_string();
        assert!(
            e.starts_with("orbit.semi_major_axis_m: ") && e.contains("inside the Earth"),
            "{e}"
        );
    }
}
