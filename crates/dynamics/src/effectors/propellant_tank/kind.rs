//! The propellant tank's entry in the kind registry ([`crate::kinds::KINDS`]): its
//! `[[propellant_tanks]]` section, its telemetry names, and how a configured tank is checked
//! and built.

use super::{schema, PropellantTank, PropellantTankParams, KIND, OUTPUT_NAMES, STATE_NAMES};
use crate::component::{
    read_boxed, BuiltComponent, ComponentKind, ComponentParams, ComponentReader, StepTiming,
};
use flexdyn_kernel::validate::ParamError;

/// The propellant tank kind.
pub static COMPONENT: ComponentKind = ComponentKind {
    effector: KIND,
    section: "propellant_tanks",
    noun: "propellant tank",
    wire_names: |_, _| Some((&STATE_NAMES, &OUTPUT_NAMES)),
    reader: Some(ComponentReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
    }),
    fault_modes: &[],
};

impl ComponentParams for PropellantTankParams {
    fn component_kind() -> &'static ComponentKind {
        &COMPONENT
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn validate(&self, path: &str, _timing: StepTiming) -> Result<(), ParamError> {
        PropellantTankParams::validate(self, path)
    }
    fn wire_counts(&self) -> (usize, usize) {
        (STATE_NAMES.len(), OUTPUT_NAMES.len())
    }
    fn mass_kg(&self) -> f64 {
        self.propellant_mass_kg
    }
    fn build(&self, path: &str, _timing: StepTiming) -> Result<BuiltComponent, ParamError> {
        Ok(BuiltComponent::Body(Box::new(PropellantTank::new(
            self.clone(),
            path,
        )?)))
    }
}
