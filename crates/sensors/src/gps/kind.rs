//! The GPS receiver's entry in the sensor registry ([`crate::KINDS`]): its key
//! (`flexdyn/<sc>/tlm/gps/<name>`), its wire message ([`GpsMsg`]), how it is built from
//! `[[gps_receivers]]` and how `flexdyn plot` draws it.

use flexdyn_proto::{decode_gps, GpsMsg, GPS_PREFIX};

use super::{schema, Gps, GpsConfig};
use crate::params::{read_boxed, SensorConfigReader, SensorParams};
use crate::{json_of, PanelSpec, Sensor, SensorBuild, SensorKind};
use flexdyn_kernel::schema::config_error::ConfigError;

/// The GPS receiver kind.
pub static KIND: SensorKind = SensorKind {
    noun: "GPS receiver",
    a_noun: "a GPS receiver",
    config_array: "gps_receivers",
    config: SensorConfigReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::read),
        error_terms: &[
            ("position_sigma_m", 1),
            ("velocity_sigma_m_s", 1),
            ("position_bias_e_m", 3),
            ("velocity_bias_e_m_s", 3),
        ],
    },
    key_prefix: GPS_PREFIX,
    column_prefix: "gps",
    message_name: "GpsMsg",
    key: |t, name| t.sensor(GPS_PREFIX, name),
    build,
    decode: |b| decode_gps(b).map(|m| json_of(m.header, &m)),
    default_json: || json_of(Default::default(), &GpsMsg::default()).1,
    json_schema: crate::message_json_schema::<GpsMsg>,
    plot: (
        "gps.png",
        "GPS receivers: measured ECEF position and velocity, and the fix flag",
        &[
            PanelSpec {
                y_label: "r ECEF (m)",
                lines: &[
                    ("r_be_e_m_1", "x"),
                    ("r_be_e_m_2", "y"),
                    ("r_be_e_m_3", "z"),
                ],
            },
            PanelSpec {
                y_label: "v rel. ECEF (m/s)",
                lines: &[
                    ("v_be_e_m_s_1", "x"),
                    ("v_be_e_m_s_2", "y"),
                    ("v_be_e_m_s_3", "z"),
                ],
            },
            PanelSpec {
                y_label: "flags (1 FIX, 2 ECEF, 4 N)",
                lines: &[("flags", "flags")],
            },
        ],
    ),
};

/// One [`Gps`] per `[[gps_receivers]]` entry (errors name `gps_receivers[i]…`).
fn build(ctx: &SensorBuild<'_>, out: &mut Vec<Box<dyn Sensor>>) -> Result<(), ConfigError> {
    for (i, g) in ctx.sensors.of::<GpsConfig>().enumerate() {
        let path = format!("gps_receivers[{i}]");
        out.push(Box::new(Gps::new(
            g.clone(),
            &path,
            ctx.frame_ns,
            ctx.epoch,
            ctx.earth_orientation,
        )?));
    }
    Ok(())
}

impl SensorParams for GpsConfig {
    fn sensor_kind() -> &'static SensorKind {
        &KIND
    }
    fn name(&self) -> &str {
        &self.name
    }
}
