//! The reaction wheel's entry in the kind registry ([`crate::kinds::KINDS`]). Its
//! section `[[reaction_wheels]]` is read into the typed `SimConfig::reaction_wheels` (see
//! [`crate::component`] for why), so it has no generic reader.

use super::{BALANCED_STATE_NAMES, IMBALANCED_STATE_NAMES, KIND, OUTPUT_NAMES};
use crate::component::ComponentKind;

/// The reaction-wheel kind. A balanced wheel has one state (its speed), an imbalanced one adds
/// its spin angle: the count tells them apart on the wire.
pub static COMPONENT: ComponentKind = ComponentKind {
    effector: KIND,
    section: "reaction_wheels",
    noun: "reaction wheel",
    wire_names: |n_states, _| {
        let states: &'static [&'static str] = if n_states == BALANCED_STATE_NAMES.len() {
            &BALANCED_STATE_NAMES
        } else {
            &IMBALANCED_STATE_NAMES
        };
        Some((states, &OUTPUT_NAMES))
    },
    reader: None,
    fault_modes: &[
        "friction_scale",
        "torque_limit",
        "seized",
        "command_ignored",
    ],
};
