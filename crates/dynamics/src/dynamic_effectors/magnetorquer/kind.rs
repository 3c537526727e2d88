//! The magnetorquer's entry in the kind registry ([`crate::kinds::KINDS`]): its
//! `[[magnetorquers]]` section, its telemetry names, and how a configured rod is checked and
//! built.

use super::{schema, Magnetorquer, MagnetorquerParams, KIND, OUTPUT_NAMES};
use crate::component::{
    read_boxed, BuiltComponent, ComponentKind, ComponentParams, ComponentReader, StepTiming,
};
use flexdyn_kernel::validate::ParamError;

/// The magnetorquer kind.
pub static COMPONENT: ComponentKind = ComponentKind {
    effector: KIND,
    section: "magnetorquers",
    noun: "magnetorquer",
    wire_names: |_, _| Some((&[], &OUTPUT_NAMES)),
    reader: Some(ComponentReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
    }),
    fault_modes: &["dead", "dipole_scale"],
};

impl ComponentParams for MagnetorquerParams {
    fn component_kind() -> &'static ComponentKind {
        &COMPONENT
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn validate(&self, path: &str, _timing: StepTiming) -> Result<(), ParamError> {
        MagnetorquerParams::validate(self, path)
    }
    fn wire_counts(&self) -> (usize, usize) {
        (0, OUTPUT_NAMES.len())
    }
    fn build(&self, path: &str, _timing: StepTiming) -> Result<BuiltComponent, ParamError> {
        Ok(BuiltComponent::Listed(Box::new(Magnetorquer::new(
            self.clone(),
            path,
        )?)))
    }
}
