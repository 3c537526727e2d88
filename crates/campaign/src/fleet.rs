//! A campaign over a fleet: `fleet = "formation.toml"` in the campaign file in place of `base`.
//!
//! - [`FleetBase`]: the fleet file, read by [`flexdyn_vehicle::world::fleet`] (so it is exactly what
//!   `flexdyn run --fleet` accepts), and for each vehicle the document its dispersions write
//!   into: its spacecraft configuration (inline or by path) plus, for a vehicle given relative
//!   to a chief, a `relative` table with its Hill-frame offsets `hill_position_m` and
//!   `hill_velocity_m_s` (zeros when the fleet file leaves them out). A spacecraft
//!   configuration has no `relative` table of its own, so the two never collide.
//! - [`run_files`]: a run's `fleet.toml` and one `config-<id>.toml` per vehicle, written into
//!   the run's folder so that it stands alone (`flexdyn run --fleet run-0003/fleet.toml` replays
//!   it), and [`from_run`], the same run read back into a [`FleetConfig`] in memory.

use std::path::{Path, PathBuf};

use toml::{Table, Value};

use flexdyn_vehicle::world::{FleetConfig, FleetError};

/// The keys of a deputy's `relative` table a dispersion may name.
pub const RELATIVE_OFFSETS: [&str; 2] = ["hill_position_m", "hill_velocity_m_s"];

/// One vehicle of a campaign's fleet.
#[derive(Clone, Debug)]
pub struct FleetVehicle {
    /// Its id (`flexdyn/<id>/…`; letters, digits, `_` and `-`, so also a file name).
    pub id: String,
    /// Its `header.spacecraft_id`.
    pub spacecraft_id: u32,
    /// The lockstep sender ids the fleet file lists for it.
    pub participants: Vec<u32>,
    /// The id of the vehicle whose Hill frame its initial orbit is given in.
    pub chief: Option<String>,
    /// Its spacecraft configuration's text.
    pub base_toml: String,
    /// The folder relative paths inside it are resolved against (its file's; the fleet file's
    /// for an inline configuration).
    pub base_dir: PathBuf,
    /// Its Hill-frame offsets as the fleet file gives them (absent ones are zeros).
    pub offsets: [[f64; 3]; 2],
}

/// The fleet a campaign disperses.
#[derive(Clone, Debug)]
pub struct FleetBase {
    /// The fleet file.
    pub path: PathBuf,
    /// Its text.
    pub source: String,
    /// The fleet as the file builds it (each vehicle validated).
    pub config: FleetConfig,
    /// Its vehicles, in file order.
    pub vehicles: Vec<FleetVehicle>,
}

impl FleetBase {
    /// Reads the fleet file `path` whose text is `source`.
    pub fn new(path: &Path, source: &str) -> Result<Self, FleetError> {
        let dir = path.parent().unwrap_or(Path::new("."));
        let config = FleetConfig::from_toml_str_in(source, dir)?;
        // The file parsed as a fleet, so it is a table of `[[vehicles]]` tables.
        let raw: Table = source
            .parse()
            .map_err(|e: toml::de::Error| FleetError::Syntax(e.to_string()))?;
        let entries = raw.get("vehicles").and_then(Value::as_array);
        let mut vehicles = Vec::with_capacity(config.vehicles.len());
        for (i, v) in config.vehicles.iter().enumerate() {
            let entry = entries.and_then(|a| a.get(i)).and_then(Value::as_table);
            let base_dir = match entry.and_then(|t| t.get("spacecraft_file")) {
                Some(Value::String(p)) => dir
                    .join(p)
                    .parent()
                    .map_or_else(|| dir.to_path_buf(), Path::to_path_buf),
                _ => dir.to_path_buf(),
            };
            let rel = entry
                .and_then(|t| t.get("relative"))
                .and_then(Value::as_table);
            let offset = |key: &str| -> [f64; 3] {
                let mut out = [0.0; 3];
                if let Some(a) = rel.and_then(|r| r.get(key)).and_then(Value::as_array) {
                    for (o, x) in out.iter_mut().zip(a) {
                        *o = x
                            .as_float()
                            .or_else(|| x.as_integer().map(|n| n as f64))
                            .unwrap_or(0.0);
                    }
                }
                out
            };
            vehicles.push(FleetVehicle {
                id: v.id.clone(),
                spacecraft_id: v.spacecraft_id,
                participants: v.participants.clone(),
                chief: v.chief.map(|c| config.vehicles[c].id.clone()),
                base_toml: v.cfg.source_toml.clone(),
                base_dir,
                offsets: [offset(RELATIVE_OFFSETS[0]), offset(RELATIVE_OFFSETS[1])],
            });
        }
        Ok(Self {
            path: path.to_owned(),
            source: source.to_owned(),
            config,
            vehicles,
        })
    }

    /// The vehicle with this id.
    pub fn vehicle(&self, id: &str) -> Option<&FleetVehicle> {
        self.vehicles.iter().find(|v| v.id == id)
    }

    /// `"chief", "deputy"`: the ids, for messages.
    pub fn ids(&self) -> String {
        self.vehicles
            .iter()
            .map(|v| format!("{:?}", v.id))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The `relative` table of a deputy's dispersible document: its two Hill-frame offsets.
pub fn offsets_table(offsets: &[[f64; 3]; 2]) -> Table {
    RELATIVE_OFFSETS
        .iter()
        .zip(offsets)
        .map(|(k, v)| {
            let a = v.iter().map(|x| Value::Float(*x)).collect();
            ((*k).to_owned(), Value::Array(a))
        })
        .collect()
}

/// The file a run writes vehicle `id`'s resolved configuration to.
pub fn vehicle_file(id: &str) -> String {
    format!("config-{id}.toml")
}

/// A run's fleet: its `fleet.toml` (each vehicle's `spacecraft_file` = [`vehicle_file`], its
/// ids, participants, chief and dispersed offsets) and each vehicle's configuration (id, TOML),
/// from the base and `docs`, the vehicles' dispersed documents (with `relative` for deputies).
pub fn run_files(
    base: &FleetBase,
    docs: &[Table],
) -> Result<(String, Vec<(String, String)>), String> {
    let mut entries = Vec::with_capacity(docs.len());
    let mut configs = Vec::with_capacity(docs.len());
    for (v, doc) in base.vehicles.iter().zip(docs) {
        let mut spacecraft = doc.clone();
        let offsets = spacecraft.remove("relative");
        let text = toml::to_string(&spacecraft)
            .map_err(|e| format!("vehicle {:?}: cannot write TOML: {e}", v.id))?;
        configs.push((v.id.clone(), text));
        let mut t = Table::new();
        t.insert("id".into(), Value::String(v.id.clone()));
        t.insert(
            "spacecraft_id".into(),
            Value::Integer(i64::from(v.spacecraft_id)),
        );
        t.insert("spacecraft_file".into(), Value::String(vehicle_file(&v.id)));
        t.insert(
            "participants".into(),
            Value::Array(
                v.participants
                    .iter()
                    .map(|p| Value::Integer(i64::from(*p)))
                    .collect(),
            ),
        );
        if let (Some(chief), Some(Value::Table(mut rel))) = (&v.chief, offsets) {
            rel.insert("chief".into(), Value::String(chief.clone()));
            t.insert("relative".into(), Value::Table(rel));
        }
        entries.push(Value::Table(t));
    }
    let mut fleet = Table::new();
    fleet.insert("vehicles".into(), Value::Array(entries));
    let text = toml::to_string(&fleet).map_err(|e| format!("fleet: cannot write TOML: {e}"))?;
    Ok((text, configs))
}

/// The fleet of a run from its [`run_files`]: each `spacecraft_file` replaced by that vehicle's
/// configuration, inline, so it is read in memory exactly as the run's folder would be.
pub fn from_run(fleet_toml: &str, configs: &[(String, String)]) -> Result<FleetConfig, String> {
    let mut doc: Table = fleet_toml
        .parse()
        .map_err(|e: toml::de::Error| format!("fleet: {e}"))?;
    if let Some(Value::Array(entries)) = doc.get_mut("vehicles") {
        for (entry, (id, text)) in entries.iter_mut().zip(configs) {
            let Value::Table(t) = entry else { continue };
            let spacecraft: Table = text
                .parse()
                .map_err(|e: toml::de::Error| format!("vehicle {id:?}: {e}"))?;
            t.remove("spacecraft_file");
            t.insert("spacecraft".into(), Value::Table(spacecraft));
        }
    }
    let inline = toml::to_string(&doc).map_err(|e| format!("fleet: cannot write TOML: {e}"))?;
    let fleet =
        FleetConfig::from_toml_str_in(&inline, Path::new(".")).map_err(|e| e.to_string())?;
    for (i, v) in fleet.vehicles.iter().enumerate() {
        v.cfg
            .build_spacecraft()
            .map_err(|e| format!("vehicles[{i}] ({:?}).spacecraft: {e}", v.id))?;
    }
    Ok(fleet)
}
