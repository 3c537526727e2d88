//! The linear slosh particle's entry in the kind registry ([`crate::kinds::KINDS`]): its
//! `[[slosh_linear]]` section, its telemetry names, and how a configured particle is checked and
//! built.

use super::{schema, SloshLinear, SloshLinearEntry, KIND, STATE_NAMES};
use crate::component::{
    read_boxed, BuiltComponent, ComponentKind, ComponentParams, ComponentReader, StepTiming,
};
use flexdyn_kernel::validate::ParamError;

/// The linear slosh kind.
pub static COMPONENT: ComponentKind = ComponentKind {
    effector: KIND,
    section: "slosh_linear",
    noun: "linear slosh particle",
    wire_names: |_, _| Some((&STATE_NAMES, &[])),
    reader: Some(ComponentReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
    }),
    fault_modes: &[],
};

impl ComponentParams for SloshLinearEntry {
    fn component_kind() -> &'static ComponentKind {
        &COMPONENT
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn validate(&self, path: &str, _timing: StepTiming) -> Result<(), ParamError> {
        self.resolve(path)?.validate(path)
    }
    fn wire_counts(&self) -> (usize, usize) {
        (STATE_NAMES.len(), 0)
    }
    fn added_mass_kg(&self) -> f64 {
        // Validated before this is asked; an invalid entry adds nothing.
        self.resolve("").map_or(0.0, |p| p.mass_kg)
    }
    fn build(&self, path: &str, _timing: StepTiming) -> Result<BuiltComponent, ParamError> {
        Ok(BuiltComponent::Body(Box::new(SloshLinear::new(
            self.resolve(path)?,
            path,
        )?)))
    }
}
