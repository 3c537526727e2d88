//! The fine sun sensor's entry in the sensor registry ([`crate::KINDS`]): its key
//! (`flexdyn/<sc>/tlm/fss/<name>`), its wire message ([`FssMsg`]), how it is built from
//! `[[fine_sun_sensors]]` and how `flexdyn plot` draws it.

use flexdyn_proto::keys::FSS_PREFIX;
use flexdyn_proto::{decode_fss, FssMsg};

use super::{schema, FineSunSensor, FineSunSensorConfig};
use crate::params::{read_boxed, SensorConfigReader, SensorParams};
use crate::{json_of, PanelSpec, Sensor, SensorBuild, SensorKind};
use flexdyn_kernel::schema::config_error::ConfigError;

/// The fine-sun-sensor kind.
pub static KIND: SensorKind = SensorKind {
    noun: "fine sun sensor",
    a_noun: "a fine sun sensor",
    config_array: "fine_sun_sensors",
    config: SensorConfigReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
        error_terms: &[("bias_rad", 2), ("noise_sigma_rad", 1), ("lsb_rad", 1)],
    },
    key_prefix: FSS_PREFIX,
    column_prefix: "fss",
    message_name: "FssMsg",
    key: |t, name| t.sensor(FSS_PREFIX, name),
    build,
    decode: |b| decode_fss(b).map(|m| json_of(m.header, &m)),
    default_json: || json_of(Default::default(), &FssMsg::default()).1,
    json_schema: crate::message_json_schema::<FssMsg>,
    plot: (
        "sun_sensors_fine.png",
        "Fine sun sensors: Sun angles in the sensor frame F (0 when not valid) and flags",
        &[
            PanelSpec {
                y_label: "angle (rad)",
                lines: &[
                    ("alpha_rad", "α = atan2(s1, s3)"),
                    ("beta_rad", "β = atan2(s2, s3)"),
                ],
            },
            PanelSpec {
                y_label: "flags (1 VALID, 2 IN_FOV, 4 SUNLIT)",
                lines: &[("flags", "flags")],
            },
        ],
    ),
};

/// One [`FineSunSensor`] per `[[fine_sun_sensors]]` entry (errors name
/// `fine_sun_sensors[i]…`).
fn build(ctx: &SensorBuild<'_>, out: &mut Vec<Box<dyn Sensor>>) -> Result<(), ConfigError> {
    for (i, c) in ctx.sensors.of::<FineSunSensorConfig>().enumerate() {
        let path = format!("fine_sun_sensors[{i}]");
        out.push(Box::new(FineSunSensor::new(c.clone(), &path)?));
    }
    Ok(())
}

impl SensorParams for FineSunSensorConfig {
    fn sensor_kind() -> &'static SensorKind {
        &KIND
    }
    fn name(&self) -> &str {
        &self.name
    }
}
