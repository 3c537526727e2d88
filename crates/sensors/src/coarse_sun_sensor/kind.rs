//! The coarse-sun-sensor array's entry in the sensor registry ([`crate::KINDS`]): its
//! key (`flexdyn/<sc>/tlm/css/<name>`), its wire message ([`CssMsg`]), how it is built from
//! `[[coarse_sun_sensors]]` and how `flexdyn plot` draws it.

use flexdyn_proto::keys::CSS_PREFIX;
use flexdyn_proto::{decode_css, CssMsg};

use super::{schema, CoarseSunSensor, CoarseSunSensorConfig};
use crate::params::{read_boxed, SensorConfigReader, SensorParams};
use crate::{json_of, PanelSpec, Sensor, SensorBuild, SensorKind};
use flexdyn_kernel::schema::config_error::ConfigError;

/// The coarse-sun-sensor array kind.
pub static KIND: SensorKind = SensorKind {
    noun: "coarse sun sensor",
    a_noun: "a coarse sun sensor",
    config_array: "coarse_sun_sensors",
    config: SensorConfigReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
        error_terms: &[("scale", 1), ("bias", 1), ("noise_sigma", 1), ("lsb", 1)],
    },
    key_prefix: CSS_PREFIX,
    column_prefix: "css",
    message_name: "CssMsg",
    key: |t, name| t.sensor(CSS_PREFIX, name),
    build,
    decode: |b| decode_css(b).map(|m| json_of(m.header, &m)),
    default_json: || json_of(Default::default(), &CssMsg::default()).1,
    json_schema: crate::message_json_schema::<CssMsg>,
    plot: (
        "sun_sensors_coarse.png",
        "Coarse sun sensors: each detector's reading (0 outside its field of view and in umbra)",
        &[
            PanelSpec {
                y_label: "reading (output unit)",
                lines: &[
                    ("readings_1", "1"),
                    ("readings_2", "2"),
                    ("readings_3", "3"),
                    ("readings_4", "4"),
                    ("readings_5", "5"),
                    ("readings_6", "6"),
                ],
            },
            PanelSpec {
                y_label: "reading, detectors 7-16",
                lines: &[
                    ("readings_7", "7"),
                    ("readings_8", "8"),
                    ("readings_9", "9"),
                    ("readings_10", "10"),
                    ("readings_11", "11"),
                    ("readings_12", "12"),
                    ("readings_13", "13"),
                    ("readings_14", "14"),
                    ("readings_15", "15"),
                    ("readings_16", "16"),
                ],
            },
        ],
    ),
};

/// One [`CoarseSunSensor`] per `[[coarse_sun_sensors]]` entry (errors name
/// `coarse_sun_sensors[i]…`).
fn build(ctx: &SensorBuild<'_>, out: &mut Vec<Box<dyn Sensor>>) -> Result<(), ConfigError> {
    for (i, c) in ctx.sensors.of::<CoarseSunSensorConfig>().enumerate() {
        let path = format!("coarse_sun_sensors[{i}]");
        out.push(Box::new(CoarseSunSensor::new(c.clone(), &path)?));
    }
    Ok(())
}

impl SensorParams for CoarseSunSensorConfig {
    fn sensor_kind() -> &'static SensorKind {
        &KIND
    }
    fn name(&self) -> &str {
        &self.name
    }
}
