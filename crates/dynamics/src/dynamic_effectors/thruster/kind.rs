//! The thruster's entry in the kind registry ([`crate::kinds::KINDS`]): its
//! `[[thrusters]]` section, its telemetry names, and how a configured thruster is checked
//! (against the frame: its valve opens once per frame) and built.

use super::{schema, Thruster, ThrusterParams, KIND, OUTPUT_NAMES};
use crate::component::{
    read_boxed, BuiltComponent, ComponentKind, ComponentParams, ComponentReader, ComponentRef,
    StepTiming,
};
use flexdyn_kernel::validate::ParamError;

/// The thruster kind.
pub static COMPONENT: ComponentKind = ComponentKind {
    effector: KIND,
    section: "thrusters",
    noun: "thruster",
    wire_names: |_, _| Some((&[], &OUTPUT_NAMES)),
    reader: Some(ComponentReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
    }),
    fault_modes: &["stuck_on", "stuck_off", "thrust_scale"],
};

impl ComponentParams for ThrusterParams {
    fn component_kind() -> &'static ComponentKind {
        &COMPONENT
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn validate(&self, path: &str, timing: StepTiming) -> Result<(), ParamError> {
        ThrusterParams::validate(self, path, timing.frame_ns)
    }
    fn wire_counts(&self) -> (usize, usize) {
        (0, OUTPUT_NAMES.len())
    }
    fn refers_to(&self) -> Option<ComponentRef<'_>> {
        self.tank.as_deref().map(|name| ComponentRef {
            field: "tank",
            section: crate::effectors::propellant_tank::kind::COMPONENT.section,
            name,
        })
    }
    fn build(&self, path: &str, timing: StepTiming) -> Result<BuiltComponent, ParamError> {
        let thruster = Thruster::new(self.clone(), path, timing.frame_ns, timing.step_ns)?;
        Ok(BuiltComponent::Listed(Box::new(thruster)))
    }
}
