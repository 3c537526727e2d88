//! The registry of effector kinds: one line per kind. Everything above the dynamics that must
//! know the kinds (configuration sections, the capacity check, the summary line, the campaign's
//! sections, the telemetry names of CSV and MCAP) loops over [`KINDS`].

use super::component::ComponentKind;
use super::dynamic_effectors::{magnetorquer, thruster};
use super::effectors::{panel_chain, panel_pair, propellant_tank, reaction_wheel};
use super::effectors::{slosh_linear, slosh_pendulum};
use super::EffectorKind;

/// Every kind, in effector-list order: the appended bodies first, then the listed actuators.
pub static KINDS: &[&ComponentKind] = &[
    &panel_pair::kind::COMPONENT,
    &reaction_wheel::kind::COMPONENT,
    &panel_chain::kind::COMPONENT,
    &slosh_linear::kind::COMPONENT,
    &slosh_pendulum::kind::COMPONENT,
    &propellant_tank::kind::COMPONENT,
    &magnetorquer::kind::COMPONENT,
    &thruster::kind::COMPONENT,
];

/// The registered kind with wire tag `wire_tag`.
pub fn by_wire_tag(wire_tag: u16) -> Option<&'static ComponentKind> {
    KINDS
        .iter()
        .copied()
        .find(|k| k.effector.wire_tag == wire_tag)
}

/// The registered kind named `name` (`panel_pair`).
pub fn by_name(name: &str) -> Option<&'static ComponentKind> {
    KINDS.iter().copied().find(|k| k.effector.name == name)
}

/// How a tool that only has the telemetry names an effector's values (an appended body's, or a
/// listed actuator's): its kind (CSV prefix), state names and output names, from the wire tag and
/// the value counts of an [`flexdyn_proto::EffectorState`]. `None` for a kind this build does not
/// know, or counts that do not match the kind (then the values have no names here).
pub fn wire_names(
    kind: u16,
    n_states: usize,
    n_outputs: usize,
) -> Option<(
    EffectorKind,
    &'static [&'static str],
    &'static [&'static str],
)> {
    let k = by_wire_tag(kind)?;
    let (states, outputs) = (k.wire_names)(n_states, n_outputs)?;
    (states.len() == n_states && outputs.len() == n_outputs)
        .then_some((k.effector, states, outputs))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Wire tags, names, sections and CSV prefixes are each unique across the registry.
    #[test]
    fn the_registry_has_no_duplicates() {
        let mut tags = std::collections::HashSet::new();
        let mut names = std::collections::HashSet::new();
        let mut sections = std::collections::HashSet::new();
        let mut prefixes = std::collections::HashSet::new();
        for &k in KINDS {
            assert!(tags.insert(k.effector.wire_tag), "{}", k.effector.name);
            assert!(names.insert(k.effector.name), "{}", k.effector.name);
            assert!(sections.insert(k.section), "{}", k.section);
            assert!(
                prefixes.insert(k.effector.column_prefix),
                "{}",
                k.effector.name
            );
            assert!(std::ptr::eq(by_name(k.effector.name).unwrap(), k));
        }
    }
}
