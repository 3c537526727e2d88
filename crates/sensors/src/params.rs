//! The sensors' side of the configuration, behind the registry: each kind's parameters implement
//! [`SensorParams`], a [`SensorConfigReader`] in its [`super::SensorKind`] reads and resolves
//! one `[[<config array>]]` entry, and [`SensorConfigs`] holds every kind's parameters in one
//! list (registry order, then file order) with typed access for the kind's own code
//! (`cfg.sensors.of::<MagnetometerConfig>()`). The configuration loops over
//! [`super::KINDS`]; none of it names a kind.
//!
//! This mirrors the effectors' [`flexdyn_dynamics::component`] contract.

use std::any::Any;
use std::collections::HashSet;
use std::fmt::Debug;

use super::imu::ImuParamError;
use super::SensorKind;
use flexdyn_kernel::schema::checks::{every_frames, unique_name};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::kind_list::{list_entry, KindList};
use flexdyn_kernel::schema::plausible::Implausible;
use flexdyn_kernel::schema::source_map::SourceMap;
use flexdyn_kernel::schema::{SchemaError, TableReader};
use flexdyn_kernel::validate::ParamError;

/// How one `[[<config array>]]` entry of a kind is read (pass 2: shape only) and resolved
/// (pass 4: values, names, rates).
#[derive(Debug)]
pub struct SensorConfigReader {
    /// The keys an entry may have (the shared reader rejects any other).
    pub keys: &'static [&'static str],
    /// Reads an entry's shape.
    pub read: fn(&TableReader<'_, '_>) -> Result<Box<dyn RawSensorConfig>, SchemaError>,
    /// Its error terms (noise σ, biases, ranges, LSBs) with their lengths (1 for a scalar):
    /// the keys bounded by [`flexdyn_kernel::validate::MAX_SENSOR_TERM_SI`] (checked by the
    /// kind's `validate` with [`flexdyn_kernel::validate::check_sensor_term`]; the list
    /// documents them and drives `tests/cli/sensor_bounds.rs`). A dotted key is in a sub-table.
    pub error_terms: &'static [(&'static str, usize)],
}

/// One entry as written, before its values are checked.
pub trait RawSensorConfig {
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

/// What a kind's resolver may ask of the configuration: the frame rate, the document's
/// positions for errors, and the names already taken within the kind.
pub struct SensorContext<'a> {
    map: &'a SourceMap<'a>,
    /// \[Hz\] the frame rate.
    pub(crate) frame_hz: f64,
    names: HashSet<String>,
}

impl<'a> SensorContext<'a> {
    /// A context for one kind's entries of the document mapped by `map`, at `frame_hz`.
    pub fn new(map: &'a SourceMap<'a>, frame_hz: f64) -> Self {
        Self {
            map,
            frame_hz,
            names: HashSet::new(),
        }
    }

    /// Checks that `<path>.name` is not blank and not taken by another sensor of the kind
    /// (`what` names the kind in the message).
    pub(crate) fn unique_name(
        &mut self,
        path: &str,
        name: &str,
        what: &str,
    ) -> Result<(), ConfigError> {
        unique_name(self.map, path, name, &mut self.names, what)
    }

    /// `frame_hz / rate_hz` as a whole number of frames ≥ 1, `rate_hz` read from `field`
    /// (`what` updates every whole number of frames).
    pub(crate) fn every_frames(
        &self,
        field: &str,
        rate_hz: f64,
        what: &str,
    ) -> Result<u64, ConfigError> {
        every_frames(self.map, field, rate_hz, self.frame_hz, what)
    }

    /// A value error, located.
    pub(crate) fn param(&self, e: ParamError) -> ConfigError {
        self.map.param_error(e)
    }

    /// An IMU value error, located: an absent key (e.g. a missing time constant) points at
    /// its table.
    pub(crate) fn imu_error(&self, e: ImuParamError) -> ConfigError {
        match e {
            ImuParamError::Param(p) => self.map.param_error(p),
            ImuParamError::Invalid { field, problem } => {
                let mut at = self.map.at(&field);
                let mut parent = field.as_str();
                while at.0.is_none() {
                    match parent.rfind('.') {
                        Some(i) => parent = &parent[..i],
                        None => break,
                    }
                    at = self.map.at(parent);
                }
                ConfigError::Invalid { field, problem, at }
            }
        }
    }

    /// `field` is invalid because of `problem`, located.
    pub(crate) fn invalid(&self, field: &str, problem: String) -> ConfigError {
        self.map.invalid(field, problem)
    }

    /// Checks that `<path>.name` may be a key segment.
    pub(crate) fn sensor_name(&self, path: &str, name: &str) -> Result<(), ConfigError> {
        flexdyn_proto::validate_sensor_name(name)
            .map_err(|e| self.invalid(&format!("{path}.name"), e.to_string()))
    }
}
