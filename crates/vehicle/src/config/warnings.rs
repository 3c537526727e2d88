//! Plausibility warnings of a valid configuration: values that are legal but almost surely a
//! unit slip (arcseconds typed as radians, rpm as rad/s) or a mistake (a panel chain's hinge
//! mode faster than the step can follow). Each model judges its own values against the
//! hardware it stands for (`plausibility.rs` beside the star tracker, the IMU and the reaction
//! wheel, with their datasheet ranges, and beside the panel chain, against the hub and the
//! step); this module gathers them with their positions in the file. A warning never rejects a
//! configuration: `check-config` lists them, and `run`, `simulate` and `campaign` log them at
//! WARN.

use std::fmt;
use std::path::Path;

use toml::de::DeTable;

use super::{At, SimConfig, SourceMap};
use flexdyn_dynamics::effectors::{panel_chain, reaction_wheel};
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
    /// The plausibility warnings (module docs): the reaction wheels', the panel chains', then
    /// every sensor kind's ([`flexdyn_sensors::params::SensorParams::implausible`], registry
    /// order), in file order within each.
    pub fn warnings(&self) -> Vec<ConfigWarning> {
        let mut found: Vec<Implausible> = Vec::new();
        for (i, x) in self.reaction_wheels.iter().enumerate() {
            reaction_wheel::plausibility::check(x, &format!("reaction_wheels[{i}]"), &mut found);
        }
        let step_s = self.step_ns as f64 * 1e-9;
        let chains = self.components.of::<panel_chain::PanelChainParams>();
        for (i, x) in chains.enumerate() {
            let path = format!("panel_chains[{i}]");
            panel_chain::plausibility::check(x, &path, &self.hub, step_s, &mut found);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The panel chains' warnings reach the configuration's list at the value's line: none for
    /// the shipped chain scenario; a stiff tip hinge (60 → 6e7 N·m/rad: its panel alone on a
    /// fixed base has I_2 + m d² = 6 + 18·0.55² = 11.445 kg·m², so ω ≥ √(6e7/11.445) ≈ 2290
    /// rad/s and ω·h ≥ 2.29 at the scenario's 1 ms) and an angle typed in degrees.
    #[test]
    fn panel_chain_warnings_name_the_value_and_its_line() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenarios/panel_chain.toml");
        let text = std::fs::read_to_string(path).unwrap();
        assert!(SimConfig::from_toml_str(&text)
            .unwrap()
            .warnings()
            .is_empty());
        for (from, to, field) in [
            (
                "k_nm_rad = 60.0",
                "k_nm_rad = 6.0e7",
                "panel_chains[0].panels[3].k_nm_rad",
            ),
            (
                "theta_rad = -0.03",
                "theta_rad = -30.0",
                "panel_chains[0].panels[2].theta_rad",
            ),
        ] {
            assert_eq!(text.matches(from).count(), 1, "{from}");
            let slipped = text.replacen(from, to, 1);
            let w = SimConfig::from_toml_str(&slipped).unwrap().warnings();
            assert_eq!(w.len(), 1, "{to}: {w:?}");
            assert_eq!(w[0].field, field);
            let line = 1 + slipped.lines().position(|l| l == to).unwrap();
            assert!(
                w[0].to_string().ends_with(&format!(
                    "(line {line}, column {})",
                    to.find('=').unwrap() + 3
                )),
                "{}",
                w[0]
            );
        }
    }
}
