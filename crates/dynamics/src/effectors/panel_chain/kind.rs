//! The panel chain's entry in the kind registry ([`crate::kinds::KINDS`]): its
//! `[[panel_chains]]` section, its telemetry names by panel count, and how a configured chain is
//! checked and built. The first appended body configured through the generic list.

use super::{schema, PanelChain, PanelChainParams, KIND, MAX_WIRE_LINKS, STATE_NAMES};
use crate::component::{
    read_boxed, BuiltComponent, ComponentKind, ComponentParams, ComponentReader, StepTiming,
};
use flexdyn_kernel::validate::{join, ParamError};

/// The panel-chain kind.
pub static COMPONENT: ComponentKind = ComponentKind {
    effector: KIND,
    section: "panel_chains",
    noun: "panel chain",
    // Two states per panel, no outputs.
    wire_names: |n_states, n_outputs| {
        (n_outputs == 0 && n_states >= 2 && n_states % 2 == 0 && n_states <= STATE_NAMES.len())
            .then(|| (&STATE_NAMES[..n_states], &[][..]))
    },
    reader: Some(ComponentReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
    }),
    fault_modes: &[],
};

impl ComponentParams for PanelChainParams {
    fn component_kind() -> &'static ComponentKind {
        &COMPONENT
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn validate(&self, path: &str, _timing: StepTiming) -> Result<(), ParamError> {
        PanelChainParams::validate(self, path)?;
        if self.panels.len() > MAX_WIRE_LINKS {
            return Err(ParamError::Invalid {
                field: join(path, "panels"),
                problem: format!(
                    "has {} panels; a configured chain has at most {MAX_WIRE_LINKS} (a StateMsg \
                     effector entry carries at most {} states)",
                    self.panels.len(),
                    flexdyn_proto::MAX_EFFECTOR_VALUES
                ),
            });
        }
        Ok(())
    }
    fn wire_counts(&self) -> (usize, usize) {
        (2 * self.panels.len(), 0)
    }
    fn mass_kg(&self) -> f64 {
        self.panels.iter().map(|p| p.mass_kg).sum()
    }
    fn build(&self, path: &str, _timing: StepTiming) -> Result<BuiltComponent, ParamError> {
        Ok(BuiltComponent::Body(Box::new(PanelChain::new(
            self.clone(),
            path,
        )?)))
    }
}
