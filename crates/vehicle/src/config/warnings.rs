//! Plausibility warnings of a valid configuration: values that are legal but almost surely a
//! unit slip (arcseconds typed as radians, rpm as rad/s). Each model judges its own values
//! against the hardware it stands for (`plausibility.rs` beside the star tracker, the IMU and
//! the reaction wheel, with their datasheet ranges); this module gathers them with their
//! positions in the file. A warning never rejects a configuration: `check-config` lists them,
//! and `run`, `simulate` and `campaign` log them at WARN.

use std::fmt;
use std::path::Path;

use toml::de::DeTable;

use super::{At, SimConfig, SourceMap};
use flexdyn_dynamics::effectors::reaction_wheel;
use flexdyn_kernel::schema::plausible::Implausible;

/// One implausible value: its field, what is implausible and the likely intended unit, and its
/// position in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigWarning {
    /// TOML path of the value.
    pub field: String,
    /// What is implausible, and the likely intended unit.
    pub message: String,
    /// Where the value is.
    pub at: At,
}

impl fmt::Display for ConfigWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}{}", self.field, self.message, self.at)
    }
}

impl SimConfig {
    /// The plausibility warnings (module docs): the reaction wheels', then every sensor kind's
    /// ([`flexdyn_sensors::params::SensorParams::implausible`], registry order), in file order
    /// within each.
    pub fn warnings(&self) -> Vec<ConfigWarning> {
        let mut found: Vec<Implausible> = Vec::new();
        for (i, x) in self.reaction_wheels.iter().enumerate() {
            reaction_wheel::plausibility::check(x, &format!("reaction_wheels[{i}]"), &mut found);
        }
        for (path, x) in self.sensors.with_paths() {
            x.implausible(&path, &mut found);
        }
        if found.is_empty() {
            return Vec::new();
        }
        let doc = DeTable::parse(&self.source_toml);
        let map = doc
            .as_ref()
            .ok()
            .map(|d| SourceMap::new(&self.source_toml, d.get_ref()));
        found
            .into_iter()
            .map(|Implausible { field, message }| ConfigWarning {
                at: map.as_ref().map(|m| m.at(&field)).unwrap_or_default(),
                field,
                message,
            })
            .collect()
    }
}

/// `FILE: field: message (line L, column C)` for a configuration read from `file` (`None`:
/// the embedded default).
pub fn warning_message(file: Option<&Path>, w: &ConfigWarning) -> String {
    match file {
        Some(f) => format!("{}: {w}", f.display()),
        None => w.to_string(),
    }
}

/// Logs every warning of `cfg`, read from `file`, at WARN.
pub fn log_warnings(cfg: &SimConfig, file: Option<&Path>) {
    for w in cfg.warnings() {
        tracing::warn!("implausible value: {}", warning_message(file, &w));
    }
}
