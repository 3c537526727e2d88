//! The sections of the kinds configured through the generic component list
//! ([`flexdyn_dynamics::component`]): every kind in [`flexdyn_dynamics::kinds::KINDS`] that has a
//! reader (`[[magnetorquers]]`, `[[thrusters]]`, …).
//!
//! Each kind's reader and validation live in its folder; this file reads the sections in
//! registry order, checks names for uniqueness within a kind, validates every entry against the
//! step and frame, and gives the capacity check their count and wire size. These components are
//! listed after the typed appended bodies in the effector list (registry order, then file order)
//! and take their inputs from `Actuators` commands by that index.

use std::collections::HashSet;

use flexdyn_dynamics::component::{ComponentSpec, Components, StepTiming};
use flexdyn_dynamics::kinds::KINDS;
use flexdyn_kernel::schema::TableReader;

use super::{unique_name, ConfigError, SourceMap};

/// The root keys of the generic sections, in registry order.
pub(super) fn root_keys() -> impl Iterator<Item = &'static str> {
    KINDS
        .iter()
        .filter(|k| k.reader.is_some())
        .map(|k| k.section)
}

/// Reads every generic section (each optional); shapes are checked, values not yet.
pub(super) fn read(root: &TableReader<'_, '_>) -> Result<Vec<Box<dyn ComponentSpec>>, ConfigError> {
    let mut items = Vec::new();
    for kind in KINDS {
        let Some(reader) = &kind.reader else {
            continue;
        };
        for t in root.tables(kind.section, reader.keys)?.unwrap_or_default() {
            items.push((reader.read)(&t)?);
        }
    }
    Ok(items)
}

/// Validates every component for `timing`; errors name the entry and the field. `pair_names`
/// are the `[[panel_pairs]]` names, which a chain may not take.
pub(super) fn resolve(
    items: Vec<Box<dyn ComponentSpec>>,
    map: &SourceMap,
    timing: StepTiming,
    pair_names: &HashSet<String>,
) -> Result<Components, ConfigError> {
    let components = Components::new(items);
    let mut names = HashSet::new();
    let mut section = "";
    for (path, c) in components.with_paths() {
        if c.kind().section != section {
            section = c.kind().section;
            names.clear();
        }
        unique_name(map, &path, c.name(), &mut names, c.kind().noun)?;
        c.validate(&path, timing).map_err(|e| map.param_error(e))?;
    }
    // Pairs and chains share the 3D scene's frame ids (`<name>/panel<k>`): one name each.
    for (path, c) in components
        .with_paths()
        .filter(|(_, c)| c.kind().section == "panel_chains")
    {
        if pair_names.contains(c.name()) {
            return Err(map.invalid(
                &format!("{path}.name"),
                format!(
                    "`{}` is also a panel pair's name: pairs and chains share the view's \
                     frame ids (`<name>/panel<k>`), so each needs its own name",
                    c.name()
                ),
            ));
        }
    }
    // Every entry another names (a thruster's `tank`) exists.
    for (path, c) in components.with_paths() {
        let Some(r) = c.refers_to() else {
            continue;
        };
        if !components
            .iter()
            .any(|o| o.kind().section == r.section && o.name() == r.name)
        {
            return Err(map.invalid(
                &format!("{path}.{}", r.field),
                format!("no [[{}]] entry is named `{}`", r.section, r.name),
            ));
        }
    }
    Ok(components)
}

/// \[bytes\] their entries in the state record: the fixed part and 8 bytes per state and output.
pub(super) fn wire_bytes(components: &Components) -> usize {
    components
        .iter()
        .map(|c| {
            let (states, outputs) = c.wire_counts();
            flexdyn_proto::EFFECTOR_STATE_FIXED_LEN + 8 * (states + outputs)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use crate::config::SimConfig;
    use flexdyn_dynamics::kinds;

    /// The effector registry's wire names agree with what each effector built from a
    /// configuration says of itself (a test of the configuration, which builds them).
    #[test]
    fn wire_names_match_what_each_built_effector_says() {
        let mut kinds = std::collections::BTreeSet::new();
        for scenario in ["acs_full", "slosh", "panel_chain", "depletion"] {
            let text = std::fs::read_to_string(format!(
                "{}/../../scenarios/{scenario}.toml",
                env!("CARGO_MANIFEST_DIR")
            ))
            .unwrap();
            let sc = SimConfig::from_toml_str(&text)
                .unwrap()
                .build_spacecraft()
                .unwrap();
            assert!(sc.effector_count() >= 2);
            check_wire_names(&sc, &mut kinds);
        }
        // Between them, acs_full, slosh, panel_chain and depletion have every registered kind,
        // bodies and actuators.
        let registered: std::collections::BTreeSet<_> =
            kinds::KINDS.iter().map(|k| k.effector.name).collect();
        assert_eq!(kinds, registered);
        assert!(kinds::wire_names(999, 1, 0).is_none());
        assert!(
            kinds::wire_names(flexdyn_dynamics::effectors::panel_pair::KIND.wire_tag, 3, 0)
                .is_none()
        );
    }

    fn check_wire_names(
        sc: &flexdyn_dynamics::Spacecraft,
        kinds: &mut std::collections::BTreeSet<&'static str>,
    ) {
        for e in sc.effector_entries() {
            let (kind, states, outputs) =
                kinds::wire_names(e.kind.wire_tag, e.state_names.len(), e.output_names.len())
                    .unwrap();
            assert_eq!(kind, e.kind);
            assert_eq!(states, e.state_names);
            assert_eq!(outputs, e.output_names);
            kinds.insert(kind.name);
        }
    }
}
