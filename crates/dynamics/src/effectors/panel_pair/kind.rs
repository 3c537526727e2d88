//! The panel pair's entry in the kind registry ([`crate::kinds::KINDS`]). Its section
//! `[[panel_pairs]]` is read into the typed `SimConfig::panel_pairs` (see
//! [`crate::component`] for why), so it has no generic reader.

use super::{KIND, STATE_NAMES};
use crate::component::ComponentKind;

/// The panel-pair kind.
pub static COMPONENT: ComponentKind = ComponentKind {
    effector: KIND,
    section: "panel_pairs",
    noun: "panel pair",
    wire_names: |_, _| Some((&STATE_NAMES, &[])),
    reader: None,
    fault_modes: &[],
};
