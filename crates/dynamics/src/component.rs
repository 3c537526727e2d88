//! The component contract: how a kind of effector describes itself to the layers above the
//! dynamics, so that adding a kind touches only its own folder plus one line in [`super::kinds`].
//!
//! A kind is a [`ComponentKind`] (a `static` in its folder): its [`EffectorKind`] (wire tag, CSV
//! prefix), its configuration section, the names of its telemetry values by wire tag, and — for
//! kinds configured through the generic list — the reader of one section entry. The entry's
//! parameters implement [`ComponentParams`]: they validate themselves, say how large their
//! state-record entry is, and build the effector (an appended body or an external, listed
//! dynamic effector). The configuration, the capacity check, the summary line, the campaign
//! read-back and the telemetry names loop over [`super::kinds::KINDS`]; none names a kind.
//!
//! The two original appended bodies (panel pairs, reaction wheels) are listed in the registry for
//! every generic use (telemetry names, campaign sections, CSV) but keep their typed fields in
//! `flexdyn_vehicle::config::SimConfig` (`panel_pairs`, `reaction_wheels`): every test of the
//! paper's system reads them by type. Their [`ComponentKind::reader`] is `None`. Plausibility
//! checks that need the hub or the step (the panel chain's hinge frequency,
//! [`crate::effectors::panel_chain::plausibility`]) are called with them from the
//! configuration's warnings, which reads generic kinds by type too.

use std::any::Any;
use std::fmt::Debug;

use super::dynamic_effector::DynamicEffector;
use super::effector::{EffectorKind, StateEffector};
use flexdyn_kernel::schema::kind_list::{list_entry, KindList};
use flexdyn_kernel::schema::{SchemaError, TableReader};
use flexdyn_kernel::validate::ParamError;

/// The names a tool gives an effector's telemetry values, from the value counts of an
/// [`flexdyn_proto::EffectorState`]: (state names, output names), or `None` when the counts do
/// not fit the kind.
pub type WireNames = fn(
    n_states: usize,
    n_outputs: usize,
) -> Option<(&'static [&'static str], &'static [&'static str])>;

/// One kind of component, registered once in [`super::kinds::KINDS`].
#[derive(Debug)]
pub struct ComponentKind {
    /// Wire tag, kind name and CSV prefix.
    pub effector: EffectorKind,
    /// The configuration section (`[[magnetorquers]]`), also the campaign's path prefix.
    pub section: &'static str,
    /// The singular used in messages (`magnetorquer`).
    pub noun: &'static str,
    /// Names of the telemetry values, by count.
    pub wire_names: WireNames,
    /// How one `[[section]]` entry is read, for kinds configured through the generic list.
    pub reader: Option<ComponentReader>,
    /// The `[[faults]]` modes it takes (`flexdyn_faults::modes`; none for a body without an
    /// input).
    pub fault_modes: &'static [&'static str],
}

/// The schema of one configuration entry of a kind.
#[derive(Debug)]
pub struct ComponentReader {
    /// The keys an entry may have (the shared reader rejects any other).
    pub keys: &'static [&'static str],
    /// Reads an entry's shape (values are checked by [`ComponentParams::validate`]).
    pub read: fn(&TableReader<'_, '_>) -> Result<Box<dyn ComponentSpec>, SchemaError>,
}

/// The simulation's timing, which some kinds validate against (a thruster's minimum on-time
/// within a frame) or build with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepTiming {
    /// \[ns\] integration step.
    pub step_ns: u64,
    /// \[ns\] frame period (a whole number of steps).
    pub frame_ns: u64,
}

/// A built component: an appended body (solved with the hub) or an external force listed in the
/// effector list after the bodies.
#[derive(Debug)]
pub enum BuiltComponent {
    /// A [`StateEffector`].
    Body(Box<dyn StateEffector>),
    /// A listed [`DynamicEffector`] (it must return `Some` from `listed_kind`).
    Listed(Box<dyn DynamicEffector>),
}

/// The parameters of one configured component of a kind, implemented in the kind's folder.
pub trait ComponentParams: Debug + Clone + PartialEq + Send + Sync + 'static {
    /// The kind's registry entry.
    fn component_kind() -> &'static ComponentKind;
    /// The name from the configuration (unique within the kind).
    fn name(&self) -> &str;
    /// Checks every value; `path` (`thrusters[2]`) names the fields in errors.
    fn validate(&self, path: &str, timing: StepTiming) -> Result<(), ParamError>;
    /// (states, outputs) of its entry in the state record.
    fn wire_counts(&self) -> (usize, usize);
    /// Builds the effector; `path` names its fields in errors and in its parameters.
    fn build(&self, path: &str, timing: StepTiming) -> Result<BuiltComponent, ParamError>;
    /// \[kg\] the mass it adds to the vehicle (an appended body's; 0 for an actuator whose mass
    /// is the hub's).
    fn mass_kg(&self) -> f64 {
        0.0
    }
    /// Another entry this one names, which must exist: (its own field, the section the named
    /// entry is in, the name), e.g. a thruster's `tank` names a `propellant_tanks` entry.
    /// `None` (the default) for an entry that names none.
    fn refers_to(&self) -> Option<ComponentRef<'_>> {
        None
    }
}

/// A reference from one configured entry to another, by name ([`ComponentParams::refers_to`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ComponentRef<'a> {
    /// The referring entry's field (`tank`).
    pub field: &'static str,
    /// The section of the entry it names (`propellant_tanks`).
    pub section: &'static str,
    /// The name it gives.
    pub name: &'a str,
}

/// The object-safe face of [`ComponentParams`], implemented for every such type, so that a
/// configuration can hold the components of every kind in one list.
pub trait ComponentSpec: Debug + Send + Sync {
    /// The kind's registry entry.
    fn kind(&self) -> &'static ComponentKind;
    /// See [`ComponentParams::name`].
    fn name(&self) -> &str;
    /// See [`ComponentParams::validate`].
    fn validate(&self, path: &str, timing: StepTiming) -> Result<(), ParamError>;
    /// See [`ComponentParams::wire_counts`].
    fn wire_counts(&self) -> (usize, usize);
    /// See [`ComponentParams::build`].
    fn build(&self, path: &str, timing: StepTiming) -> Result<BuiltComponent, ParamError>;
    /// See [`ComponentParams::mass_kg`].
    fn mass_kg(&self) -> f64;
    /// See [`ComponentParams::refers_to`].
    fn refers_to(&self) -> Option<ComponentRef<'_>>;
    /// A boxed copy.
    fn box_clone(&self) -> Box<dyn ComponentSpec>;
    /// Whether `other` is the same kind with equal parameters.
    fn same_as(&self, other: &dyn ComponentSpec) -> bool;
    /// For typed access ([`KindList::of`]).
    fn as_any(&self) -> &dyn Any;
    /// For typed access ([`KindList::of_mut`]).
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

impl<P: ComponentParams> ComponentSpec for P {
    fn kind(&self) -> &'static ComponentKind {
        P::component_kind()
    }
    fn name(&self) -> &str {
        ComponentParams::name(self)
    }
    fn validate(&self, path: &str, timing: StepTiming) -> Result<(), ParamError> {
        ComponentParams::validate(self, path, timing)
    }
    fn wire_counts(&self) -> (usize, usize) {
        ComponentParams::wire_counts(self)
    }
    fn build(&self, path: &str, timing: StepTiming) -> Result<BuiltComponent, ParamError> {
        ComponentParams::build(self, path, timing)
    }
    fn mass_kg(&self) -> f64 {
        ComponentParams::mass_kg(self)
    }
    fn refers_to(&self) -> Option<ComponentRef<'_>> {
        ComponentParams::refers_to(self)
    }
    fn box_clone(&self) -> Box<dyn ComponentSpec> {
        Box::new(self.clone())
    }
    fn same_as(&self, other: &dyn ComponentSpec) -> bool {
        other.as_any().downcast_ref::<P>() == Some(self)
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// Reads one entry of kind `P` with `read` and boxes it: the usual [`ComponentReader::read`].
pub(crate) fn read_boxed<P: ComponentParams>(
    t: &TableReader<'_, '_>,
    read: fn(&TableReader<'_, '_>) -> Result<P, SchemaError>,
) -> Result<Box<dyn ComponentSpec>, SchemaError> {
    Ok(Box::new(read(t)?))
}

/// The components configured through the generic list, grouped by kind in registry order and in
/// file order within a kind (the order of the effector list after the typed bodies).
pub type Components = KindList<dyn ComponentSpec>;

list_entry!(dyn ComponentSpec, ComponentKind, section);
