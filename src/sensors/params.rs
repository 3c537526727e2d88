//! The sensors' side of the configuration, behind the registry: each kind's parameters implement
//! [`SensorParams`], a [`SensorConfigReader`] in its [`super::SensorKind`] reads and resolves
//! one `[[<config array>]]` entry, and [`SensorConfigs`] holds every kind's parameters in one
//! list (registry order, then file order) with typed access for the kind's own code
//! (`cfg.sensors.of::<MagnetometerConfig>()`). The configuration loops over
//! [`super::KINDS`]; none of it names a kind.
//!
//! This mirrors the effectors' [`crate::dynamics::component`] contract.

use std::any::Any;
use std::fmt::Debug;

use super::SensorKind;
use crate::config::{ConfigError, SensorContext};
use crate::schema::kind_list::{list_entry, KindList};
use crate::schema::plausible::Implausible;
use crate::schema::{SchemaError, TableReader};

/// How one `[[<config array>]]` entry of a kind is read (pass 2: shape only) and resolved
/// (pass 4: values, names, rates).
#[derive(Debug)]
pub struct SensorConfigReader {
    /// The keys an entry may have (the shared reader rejects any other).
    pub keys: &'static [&'static str],
    /// Reads an entry's shape.
    pub(crate) read: fn(&TableReader<'_, '_>) -> Result<Box<dyn RawSensorConfig>, SchemaError>,
}

/// One entry as written, before its values are checked.
pub(crate) trait RawSensorConfig {
    /// Checks the values of the entry at `path` (`magnetometers[0]`) and converts it (rates to
    /// frames); errors name the field. `ctx` checks names for uniqueness within the kind.
    fn resolve(
        self: Box<Self>,
        ctx: &mut SensorContext<'_>,
        path: &str,
    ) -> Result<Box<dyn SensorSpec>, ConfigError>;
}

/// Reads one entry with `read` and boxes it: the usual [`SensorConfigReader::read`].
pub(crate) fn read_boxed<R: RawSensorConfig + 'static>(
    t: &TableReader<'_, '_>,
    read: fn(&TableReader<'_, '_>) -> Result<R, SchemaError>,
) -> Result<Box<dyn RawSensorConfig>, SchemaError> {
    Ok(Box::new(read(t)?))
}

/// The validated parameters of one configured sensor of a kind, implemented in its folder.
pub trait SensorParams: Debug + Clone + PartialEq + Send + Sync + 'static {
    /// The kind's registry entry.
    fn sensor_kind() -> &'static SensorKind;
    /// The name from the configuration (unique within the kind).
    fn name(&self) -> &str;
    /// Its legal but implausible values (`path` is `imus[0]`); none by default.
    fn implausible(&self, _path: &str, _out: &mut Vec<Implausible>) {}
}

/// The object-safe face of [`SensorParams`], so that a configuration holds every kind's sensors
/// in one list.
pub trait SensorSpec: Debug + Send + Sync {
    /// The kind's registry entry.
    fn kind(&self) -> &'static SensorKind;
    /// See [`SensorParams::name`].
    fn name(&self) -> &str;
    /// See [`SensorParams::implausible`].
    fn implausible(&self, path: &str, out: &mut Vec<Implausible>);
    /// A boxed copy.
    fn box_clone(&self) -> Box<dyn SensorSpec>;
    /// Whether `other` is the same kind with equal parameters.
    fn same_as(&self, other: &dyn SensorSpec) -> bool;
    /// For typed access ([`KindList::of`]).
    fn as_any(&self) -> &dyn Any;
    /// For typed access ([`KindList::of_mut`]).
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

impl<P: SensorParams> SensorSpec for P {
    fn kind(&self) -> &'static SensorKind {
        P::sensor_kind()
    }
    fn name(&self) -> &str {
        SensorParams::name(self)
    }
    fn implausible(&self, path: &str, out: &mut Vec<Implausible>) {
        SensorParams::implausible(self, path, out)
    }
    fn box_clone(&self) -> Box<dyn SensorSpec> {
        Box::new(self.clone())
    }
    fn same_as(&self, other: &dyn SensorSpec) -> bool {
        other.as_any().downcast_ref::<P>() == Some(self)
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// Every configured sensor's parameters, in registry order then file order (the bank's order).
pub type SensorConfigs = KindList<dyn SensorSpec>;

list_entry!(dyn SensorSpec, SensorKind, config_array);
