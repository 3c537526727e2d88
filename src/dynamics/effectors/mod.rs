//! The appended bodies, one folder per kind. Each folder owns the kind's parameters, its
//! configuration schema (`schema.rs`), its [`StateEffector`](super::StateEffector)
//! implementation with its state, input and output names, and its tests.

pub mod panel_pair;
pub mod reaction_wheel;

use super::dynamic_effectors::{magnetorquer, thruster};
use super::EffectorKind;

/// How a tool that only has the telemetry names an effector's values (an appended body's, or a
/// listed actuator's, [`super::dynamic_effectors`]): its kind (CSV prefix),
/// state names and output names, from the wire tag and the value counts of an
/// [`flexdyn_proto::EffectorState`]. `None` for a kind this build does not know, or counts that
/// do not match the kind (then the values have no names here).
pub fn wire_names(
    kind: u16,
    n_states: usize,
    n_outputs: usize,
) -> Option<(
    EffectorKind,
    &'static [&'static str],
    &'static [&'static str],
)> {
    let (k, states, outputs): (
        EffectorKind,
        &'static [&'static str],
        &'static [&'static str],
    ) = if kind == panel_pair::KIND.wire_tag {
        (panel_pair::KIND, &panel_pair::STATE_NAMES, &[])
    } else if kind == reaction_wheel::KIND.wire_tag {
        let states: &'static [&'static str] = if n_states == 1 {
            &reaction_wheel::BALANCED_STATE_NAMES
        } else {
            &reaction_wheel::IMBALANCED_STATE_NAMES
        };
        (reaction_wheel::KIND, states, &reaction_wheel::OUTPUT_NAMES)
    } else if kind == magnetorquer::KIND.wire_tag {
        (magnetorquer::KIND, &[], &magnetorquer::OUTPUT_NAMES)
    } else if kind == thruster::KIND.wire_tag {
        (thruster::KIND, &[], &thruster::OUTPUT_NAMES)
    } else {
        return None;
    };
    (states.len() == n_states && outputs.len() == n_outputs).then_some((k, states, outputs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;

    #[test]
    fn wire_names_match_what_each_built_effector_says() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenarios/acs_full.toml"
        ))
        .unwrap();
        let sc = SimConfig::from_toml_str(&text)
            .unwrap()
            .build_spacecraft()
            .unwrap();
        assert!(sc.effector_count() >= 3);
        let mut kinds = std::collections::BTreeSet::new();
        for e in sc.effector_entries() {
            let (kind, states, outputs) =
                wire_names(e.kind.wire_tag, e.state_names.len(), e.output_names.len()).unwrap();
            assert_eq!(kind, e.kind);
            assert_eq!(states, e.state_names);
            assert_eq!(outputs, e.output_names);
            kinds.insert(kind.name);
        }
        // Every kind there is, bodies and actuators.
        assert_eq!(
            kinds.into_iter().collect::<Vec<_>>(),
            ["magnetorquer", "panel_pair", "reaction_wheel", "thruster"]
        );
        assert!(wire_names(999, 1, 0).is_none());
        assert!(wire_names(panel_pair::KIND.wire_tag, 3, 0).is_none());
    }
}
