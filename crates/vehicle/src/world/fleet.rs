//! The fleet file: several spacecraft in one world, on one tick.
//!
//! ```toml
//! [[vehicles]]
//! id = "chief"                        # its keys: flexdyn/chief/…
//! spacecraft_file = "reference.toml"  # relative to the fleet file's folder
//! participants = [1]                  # lockstep sender ids that answer for it
//!
//! [[vehicles]]
//! id = "deputy"
//! spacecraft_id = 7                   # header.spacecraft_id (default: its position, from 1)
//! participants = [2]
//! [vehicles.spacecraft]               # or the spacecraft configuration inline
//! simulation = { step_s = 0.001, frame_hz = 100.0 }
//! # … every table of a spacecraft configuration …
//! [vehicles.relative]                 # its initial orbit relative to an earlier vehicle
//! chief = "chief"
//! hill_position_m = [0.0, -100.0, 0.0]    # radial, along-track, cross-track
//! hill_velocity_m_s = [0.0, 0.0, 0.0]     # rate seen in the chief's Hill frame
//! ```
//!
//! Every vehicle is a whole spacecraft configuration (the same file `flexdyn run` takes, so a
//! single-vehicle configuration stays valid as it is). A `relative` table replaces that
//! configuration's own position and velocity with the chief's centre-of-mass state plus the
//! Hill-frame offset ([`super::relative::deputy_state_n`]); the attitude stays the vehicle's.
//! The vehicles share one tick and one world, so their step, frame rate, epoch and gravity
//! must agree. Errors name the vehicle (`vehicles[1] ("deputy")`) and the field.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crate::config::{ConfigError, SimConfig};
use flexdyn_dynamics::InitialTranslation;

/// A fleet file that cannot be used. The message names the vehicle and the field.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FleetError {
    /// The fleet file could not be read.
    #[error("cannot read fleet file `{}`: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The fleet file is not valid TOML.
    #[error("fleet file: TOML syntax error: {0}")]
    Syntax(String),
    /// A bad field of the fleet file.
    #[error("{field}: {problem}")]
    Field {
        /// Its path, with the vehicle's id (`vehicles[1] ("deputy").relative.chief`).
        field: String,
        /// What is wrong.
        problem: String,
    },
    /// A vehicle's spacecraft configuration is invalid.
    #[error("{vehicle}.{what}: {source}")]
    Spacecraft {
        /// The vehicle (`vehicles[1] ("deputy")`).
        vehicle: String,
        /// `spacecraft` (inline) or ``spacecraft_file `path` ``.
        what: String,
        /// The configuration's own error (it names the field inside the spacecraft file).
        #[source]
        source: Box<ConfigError>,
    },
}

/// One vehicle, resolved.
#[derive(Debug, Clone)]
pub struct VehicleConfig {
    /// Its id: the `<sc-id>` of its keys `flexdyn/<sc-id>/…`.
    pub id: String,
    /// `header.spacecraft_id` of its messages.
    pub spacecraft_id: u32,
    /// Its spacecraft configuration (with the relative orbit applied).
    pub cfg: SimConfig,
    /// The lockstep sender ids that answer for it (a sender may be listed for several vehicles).
    pub participants: Vec<u32>,
    /// The vehicle whose Hill frame its initial orbit was given in (an index into the fleet).
    pub chief: Option<usize>,
}

/// A fleet: the vehicles of one world, in file order.
#[derive(Debug, Clone)]
pub struct FleetConfig {
    /// The vehicles.
    pub vehicles: Vec<VehicleConfig>,
}

/// Keys of one `[[vehicles]]` entry.
const VEHICLE_KEYS: [&str; 6] = [
    "id",
    "spacecraft_id",
    "spacecraft_file",
    "spacecraft",
    "participants",
    "relative",
];
/// Keys of `[vehicles.relative]`.
const RELATIVE_KEYS: [&str; 3] = ["chief", "hill_position_m", "hill_velocity_m_s"];

impl FleetConfig {
    /// One vehicle: what `flexdyn run` has without a fleet file.
    pub fn single(cfg: SimConfig, id: &str, spacecraft_id: u32, participants: Vec<u32>) -> Self {
        Self {
            vehicles: vec![VehicleConfig {
                id: id.to_string(),
                spacecraft_id,
                cfg,
                participants,
                chief: None,
            }],
        }
    }

    /// Reads a fleet file; `spacecraft_file` paths are relative to its folder.
    pub fn from_file(path: &Path) -> Result<Self, FleetError> {
        let text = std::fs::read_to_string(path).map_err(|source| FleetError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str_in(&text, path.parent().unwrap_or(Path::new(".")))
    }

    /// Parses a fleet file's text; `spacecraft_file` paths are relative to `base_dir`.
    pub fn from_toml_str_in(text: &str, base_dir: &Path) -> Result<Self, FleetError> {
        let doc: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| FleetError::Syntax(e.to_string()))?;
        if let Some(key) = doc.keys().find(|k| *k != "vehicles") {
            return Err(field_err(
                key,
                "unknown key (a fleet file holds only [[vehicles]])",
            ));
        }
        let list = match doc.get("vehicles") {
            Some(toml::Value::Array(a)) if !a.is_empty() => a,
            Some(toml::Value::Array(_)) | None => {
                return Err(field_err(
                    "vehicles",
                    "give at least one [[vehicles]] entry",
                ))
            }
            Some(_) => return Err(field_err("vehicles", "must be an array of tables")),
        };
        let mut vehicles: Vec<VehicleConfig> = Vec::with_capacity(list.len());
        for (i, v) in list.iter().enumerate() {
            let vehicle = read_vehicle(i, v, base_dir, &vehicles)?;
            vehicles.push(vehicle);
        }
        let fleet = Self { vehicles };
        fleet.check_shared()?;
        Ok(fleet)
    }

    /// The vehicle with this id.
    pub fn index_of(&self, id: &str) -> Option<usize> {
        self.vehicles.iter().position(|v| v.id == id)
    }

    /// The vehicles share one tick and one world: step, frame, epoch and gravity must agree
    /// with the first vehicle's.
    fn check_shared(&self) -> Result<(), FleetError> {
        let first = &self.vehicles[0];
        for (i, v) in self.vehicles.iter().enumerate().skip(1) {
            let differs = |field: &str, what: &str| {
                Err(field_err(
                    &format!("{}.spacecraft.{field}", name(i, &v.id)),
                    &format!(
                        "{what} differs from {}'s: the vehicles of a fleet run on one tick in \
                         one world",
                        name(0, &first.id)
                    ),
                ))
            };
            if v.cfg.step_ns != first.cfg.step_ns {
                return differs("simulation.step_s", "the step");
            }
            if v.cfg.frame_ns != first.cfg.frame_ns {
                return differs("simulation.frame_hz", "the frame period");
            }
            if v.cfg.epoch != first.cfg.epoch {
                return differs("epoch", "the epoch");
            }
            if v.cfg.gravity != first.cfg.gravity {
                return differs("gravity", "the gravity model");
            }
        }
        Ok(())
    }
}

/// `vehicles[i] ("id")`.
fn name(i: usize, id: &str) -> String {
    format!("vehicles[{i}] ({id:?})")
}

fn field_err(field: &str, problem: &str) -> FleetError {
    FleetError::Field {
        field: field.to_string(),
        problem: problem.to_string(),
    }
}

/// A 3-vector of finite numbers (integers allowed).
fn vec3(field: &str, v: Option<&toml::Value>) -> Result<Vector3<f64>, FleetError> {
    let Some(v) = v else {
        return Ok(Vector3::zeros());
    };
    let bad = || field_err(field, "must be an array of 3 finite numbers");
    let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
    let mut out = Vector3::zeros();
    for (o, x) in out.iter_mut().zip(a) {
        *o = match x {
            toml::Value::Float(f) if f.is_finite() => *f,
            toml::Value::Integer(n) => *n as f64,
            _ => return Err(bad()),
        };
    }
    Ok(out)
}

/// Reads `[[vehicles]]` entry `i`; `earlier` are the entries before it (for ids and chiefs).
fn read_vehicle(
    i: usize,
    v: &toml::Value,
    base_dir: &Path,
    earlier: &[VehicleConfig],
) -> Result<VehicleConfig, FleetError> {
    let at = format!("vehicles[{i}]");
    let t = v
        .as_table()
        .ok_or_else(|| field_err(&at, "must be a table ([[vehicles]])"))?;
    let id = match t.get("id") {
        Some(toml::Value::String(s)) => s.clone(),
        Some(_) => return Err(field_err(&format!("{at}.id"), "must be a string")),
        None => return Err(field_err(&format!("{at}.id"), "missing required key")),
    };
    let who = name(i, &id);
    let f = |key: &str| format!("{who}.{key}");
    if let Some(key) = t.keys().find(|k| !VEHICLE_KEYS.contains(&k.as_str())) {
        return Err(field_err(
            &f(key),
            &format!("unknown key (expected one of {})", VEHICLE_KEYS.join(", ")),
        ));
    }
    if let Err(e) = flexdyn_proto::Topics::new(&id) {
        return Err(field_err(&f("id"), &e.to_string()));
    }
    if let Some(j) = earlier.iter().position(|e| e.id == id) {
        return Err(field_err(
            &f("id"),
            &format!("{id:?} is already the id of vehicles[{j}]"),
        ));
    }
    let spacecraft_id = match t.get("spacecraft_id") {
        None => u32::try_from(i + 1).unwrap_or(u32::MAX),
        Some(toml::Value::Integer(n)) => u32::try_from(*n).map_err(|_| {
            field_err(
                &f("spacecraft_id"),
                "must be a whole number from 0 to 4294967295",
            )
        })?,
        Some(_) => return Err(field_err(&f("spacecraft_id"), "must be an integer")),
    };
    if let Some(j) = earlier
        .iter()
        .position(|e| e.spacecraft_id == spacecraft_id)
    {
        return Err(field_err(
            &f("spacecraft_id"),
            &format!("{spacecraft_id} is already the spacecraft_id of vehicles[{j}]"),
        ));
    }
    let participants = match t.get("participants") {
        None => Vec::new(),
        Some(toml::Value::Array(a)) => {
            let mut out = Vec::with_capacity(a.len());
            for x in a {
                let id = x
                    .as_integer()
                    .and_then(|n| u32::try_from(n).ok())
                    .ok_or_else(|| {
                        field_err(
                            &f("participants"),
                            "must be a list of sender ids (whole numbers from 0 to 4294967295)",
                        )
                    })?;
                if out.contains(&id) {
                    return Err(field_err(
                        &f("participants"),
                        &format!("sender id {id} is listed twice"),
                    ));
                }
                out.push(id);
            }
            out
        }
        Some(_) => return Err(field_err(&f("participants"), "must be an array")),
    };
    let mut cfg =
        match (t.get("spacecraft_file"), t.get("spacecraft")) {
            (Some(_), Some(_)) => {
                return Err(field_err(
                    &f("spacecraft"),
                    "give the spacecraft either inline (spacecraft) or by path (spacecraft_file), \
                 not both",
                ))
            }
            (None, None) => return Err(field_err(
                &f("spacecraft_file"),
                "missing: give spacecraft_file = \"path.toml\" or an inline [vehicles.spacecraft]",
            )),
            (Some(toml::Value::String(p)), None) => {
                let path = base_dir.join(p);
                SimConfig::from_file(&path).map_err(|source| FleetError::Spacecraft {
                    vehicle: who.clone(),
                    what: format!("spacecraft_file `{}`", path.display()),
                    source: Box::new(source),
                })?
            }
            (Some(_), None) => return Err(field_err(&f("spacecraft_file"), "must be a string")),
            (None, Some(toml::Value::Table(inline))) => {
                let text = toml::to_string(inline).map_err(|e| {
                    field_err(&f("spacecraft"), &format!("cannot be re-read as TOML: {e}"))
                })?;
                SimConfig::from_toml_str_in(&text, base_dir).map_err(|source| {
                    FleetError::Spacecraft {
                        vehicle: who.clone(),
                        what: "spacecraft".into(),
                        source: Box::new(source),
                    }
                })?
            }
            (None, Some(_)) => return Err(field_err(&f("spacecraft"), "must be a table")),
        };
    let mut chief = None;
    if let Some(rel) = t.get("relative") {
        let rel = rel
            .as_table()
            .ok_or_else(|| field_err(&f("relative"), "must be a table"))?;
        let g = |key: &str| format!("{who}.relative.{key}");
        if let Some(key) = rel.keys().find(|k| !RELATIVE_KEYS.contains(&k.as_str())) {
            return Err(field_err(
                &g(key),
                &format!("unknown key (expected one of {})", RELATIVE_KEYS.join(", ")),
            ));
        }
        let chief_id = rel
            .get("chief")
            .and_then(|c| c.as_str())
            .ok_or_else(|| field_err(&g("chief"), "missing: the id of an earlier vehicle"))?;
        let c = earlier
            .iter()
            .position(|e| e.id == chief_id)
            .ok_or_else(|| {
                field_err(
                    &g("chief"),
                    &format!(
                        "{chief_id:?} is not the id of an earlier vehicle (a chief is listed \
                         before its deputies)"
                    ),
                )
            })?;
        let rho_h = vec3(&g("hill_position_m"), rel.get("hill_position_m"))?;
        let rho_dot_h = vec3(&g("hill_velocity_m_s"), rel.get("hill_velocity_m_s"))?;
        let chief_sc =
            earlier[c]
                .cfg
                .build_spacecraft()
                .map_err(|source| FleetError::Spacecraft {
                    vehicle: name(c, chief_id),
                    what: "spacecraft".into(),
                    source: Box::new(source),
                })?;
        let (r_c, v_c) = super::relative::com_state_n(&chief_sc);
        let (r_d, v_d) = super::relative::deputy_state_n(&r_c, &v_c, &rho_h, &rho_dot_h)
            .ok_or_else(|| {
                field_err(
                    &g("chief"),
                    &format!(
                        "{chief_id:?} has no orbit plane (its position and velocity are \
                         parallel or zero), so it has no Hill frame"
                    ),
                )
            })?;
        cfg.initial.translation = InitialTranslation::CenterOfMass {
            r_cn_n_m: r_d,
            v_cn_n_m_s: v_d,
        };
        chief = Some(c);
    }
    Ok(VehicleConfig {
        id,
        spacecraft_id,
        cfg,
        participants,
        chief,
    })
}
