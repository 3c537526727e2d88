//! The magnetometer's entry in the sensor registry ([`crate::KINDS`]): its key
//! (`flexdyn/<sc>/tlm/mag/<name>`), its wire message ([`MagnetometerMsg`]), how it is built
//! from `[[magnetometers]]` and how `flexdyn plot` draws it.

use flexdyn_proto::keys::MAGNETOMETER_PREFIX;
use flexdyn_proto::{decode_magnetometer, MagnetometerMsg};

use super::{schema, Magnetometer, MagnetometerConfig};
use crate::params::{read_boxed, SensorConfigReader, SensorParams};
use crate::{json_of, PanelSpec, Sensor, SensorBuild, SensorKind};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::plausible::Implausible;

/// The magnetometer kind.
pub static KIND: SensorKind = SensorKind {
    noun: "magnetometer",
    a_noun: "a magnetometer",
    config_array: "magnetometers",
    config: SensorConfigReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
        error_terms: &[
            ("bias_s_t", 3),
            ("noise_sigma_t", 1),
            ("range_t", 1),
            ("lsb_t", 1),
        ],
    },
    key_prefix: MAGNETOMETER_PREFIX,
    column_prefix: "mag",
    message_name: "MagnetometerMsg",
    key: |t, name| t.sensor(MAGNETOMETER_PREFIX, name),
    build,
    decode: |b| decode_magnetometer(b).map(|m| json_of(m.header, &m)),
    default_json: || json_of(Default::default(), &MagnetometerMsg::default()).1,
    json_schema: crate::message_json_schema::<MagnetometerMsg>,
    plot: (
        "magnetometer.png",
        "Magnetometers: measured field (sensor frame S) and saturated axes",
        &[
            PanelSpec {
                y_label: "B, S (T)",
                lines: &[("b_s_t_1", "B1"), ("b_s_t_2", "B2"), ("b_s_t_3", "B3")],
            },
            PanelSpec {
                y_label: "saturated axes (bits 1, 2, 4)",
                lines: &[("saturation_flags", "flags")],
            },
        ],
    ),
};

/// One [`Magnetometer`] per `[[magnetometers]]` entry (errors name `magnetometers[i]…`).
fn build(ctx: &SensorBuild<'_>, out: &mut Vec<Box<dyn Sensor>>) -> Result<(), ConfigError> {
    for (i, m) in ctx.sensors.of::<MagnetometerConfig>().enumerate() {
        let path = format!("magnetometers[{i}]");
        out.push(Box::new(Magnetometer::new(m.clone(), &path)?));
    }
    Ok(())
}

impl SensorParams for MagnetometerConfig {
    fn sensor_kind() -> &'static SensorKind {
        &KIND
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn implausible(&self, path: &str, out: &mut Vec<Implausible>) {
        super::plausibility::check(self, path, out);
    }
}
