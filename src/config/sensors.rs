//! The sensor sections (`[[imus]]`, `[[star_trackers]]`, …): every kind in
//! [`crate::sensors::KINDS`], read through its [`crate::sensors::params::SensorConfigReader`].
//!
//! Each kind's reader and value checks live in its folder; this file reads the sections in
//! registry order (pass 2), then resolves every entry (pass 4) with a [`SensorContext`] that
//! checks names for uniqueness within a kind and converts rates to whole numbers of frames.

use std::collections::HashSet;

use crate::schema::TableReader;
use crate::sensors::imu::ImuParamError;
use crate::sensors::params::{RawSensorConfig, SensorConfigs};
use crate::sensors::KINDS;
use crate::validate::ParamError;

use super::{every_frames, unique_name, ConfigError, SourceMap};

/// The root keys of the sensor sections, in registry order.
pub(super) fn root_keys() -> impl Iterator<Item = &'static str> {
    KINDS.iter().map(|k| k.config_array)
}

/// Every section's entries as written, by kind (registry order), in file order.
pub(super) type RawSensors = Vec<Vec<Box<dyn RawSensorConfig>>>;

/// Reads every sensor section (each optional); shapes are checked, values not yet.
pub(super) fn read(root: &TableReader<'_, '_>) -> Result<RawSensors, ConfigError> {
    KINDS
        .iter()
        .map(|kind| {
            root.read_tables(kind.config_array, kind.config.keys, |t| {
                (kind.config.read)(t).map_err(ConfigError::from)
            })
        })
        .collect()
}

/// Resolves every entry, kind by kind; errors name the entry and the field.
pub(super) fn resolve(
    raw: RawSensors,
    map: &SourceMap,
    frame_hz: f64,
) -> Result<SensorConfigs, ConfigError> {
    let mut items = Vec::new();
    for (kind, entries) in KINDS.iter().zip(raw) {
        let mut ctx = SensorContext {
            map,
            frame_hz,
            names: HashSet::new(),
        };
        for (i, entry) in entries.into_iter().enumerate() {
            items.push(entry.resolve(&mut ctx, &format!("{}[{i}]", kind.config_array))?);
        }
    }
    Ok(SensorConfigs::new(items))
}

/// What a kind's resolver may ask of the configuration: the frame rate, the document's
/// positions for errors, and the names already taken within the kind.
pub(crate) struct SensorContext<'a> {
    map: &'a SourceMap<'a>,
    /// \[Hz\] the frame rate.
    pub(crate) frame_hz: f64,
    names: HashSet<String>,
}

impl SensorContext<'_> {
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

    /// An IMU value error, located.
    pub(crate) fn imu_error(&self, e: ImuParamError) -> ConfigError {
        self.map.imu_error(e)
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
