//! The sensor sections (`[[imus]]`, `[[star_trackers]]`, …): every kind in
//! [`flexdyn_sensors::KINDS`], read through its [`flexdyn_sensors::params::SensorConfigReader`].
//!
//! Each kind's reader and value checks live in its folder; this file reads the sections in
//! registry order (pass 2), then resolves every entry (pass 4) with a [`SensorContext`] that
//! checks names for uniqueness within a kind and converts rates to whole numbers of frames.

use flexdyn_kernel::schema::TableReader;
use flexdyn_sensors::params::{RawSensorConfig, SensorConfigs, SensorContext};
use flexdyn_sensors::KINDS;

use super::{ConfigError, SourceMap};

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
        let mut ctx = SensorContext::new(map, frame_hz);
        for (i, entry) in entries.into_iter().enumerate() {
            items.push(entry.resolve(&mut ctx, &format!("{}[{i}]", kind.config_array))?);
        }
    }
    Ok(SensorConfigs::new(items))
}
