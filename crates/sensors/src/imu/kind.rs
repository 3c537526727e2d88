//! The IMU's entry in the sensor registry ([`crate::KINDS`]): its key
//! (`flexdyn/<sc>/tlm/imu/<name>`), its wire message ([`ImuMsg`]), how it is built from
//! `[[imus]]` and how `flexdyn plot` draws it.

use flexdyn_proto::keys::{Topics, IMU_PREFIX};
use flexdyn_proto::{decode_imu, ImuMsg};

use super::{schema, ImuConfig, ImuSensor};
use crate::params::{read_boxed, SensorConfigReader, SensorParams};
use crate::{json_of, PanelSpec, Sensor, SensorBuild, SensorKind};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::plausible::Implausible;

/// The IMU kind.
pub static KIND: SensorKind = SensorKind {
    noun: "IMU",
    a_noun: "an IMU",
    config_array: "imus",
    config: SensorConfigReader {
        keys: &schema::KEYS,
        read: |t| read_boxed(t, schema::RawImu::read),
        error_terms: &[
            ("gyro.arw_rad_s_sqrt_hz", 1),
            ("gyro.bias_instability_sigma_rad_s", 1),
            ("gyro.rrw_rad_s2_sqrt_hz", 1),
            ("gyro.bias_rad_s", 3),
            ("gyro.range_rad_s", 1),
            ("gyro.lsb_rad_s", 1),
            ("gyro.dtheta_lsb_rad", 1),
            ("accel.vrw_m_s2_sqrt_hz", 1),
            ("accel.bias_instability_sigma_m_s2", 1),
            ("accel.rrw_m_s3_sqrt_hz", 1),
            ("accel.bias_m_s2", 3),
            ("accel.range_m_s2", 1),
            ("accel.lsb_m_s2", 1),
            ("accel.dv_lsb_m_s", 1),
        ],
    },
    key_prefix: IMU_PREFIX,
    column_prefix: "imu",
    message_name: "ImuMsg",
    key: Topics::imu,
    build,
    decode: |b| decode_imu(b).map(|m| json_of(m.header, &m)),
    default_json: || json_of(Default::default(), &ImuMsg::default()).1,
    json_schema: crate::message_json_schema::<ImuMsg>,
    plot: (
        "imu.png",
        "IMU measurements (sensor frame P)",
        &[
            PanelSpec {
                y_label: "rate, P (rad/s)",
                lines: &[
                    ("omega_p_rad_s_1", "ω1"),
                    ("omega_p_rad_s_2", "ω2"),
                    ("omega_p_rad_s_3", "ω3"),
                ],
            },
            PanelSpec {
                y_label: "specific force, P (m/s²)",
                lines: &[
                    ("accel_p_m_s2_1", "a1"),
                    ("accel_p_m_s2_2", "a2"),
                    ("accel_p_m_s2_3", "a3"),
                ],
            },
        ],
    ),
};

/// One [`ImuSensor`] per `[[imus]]` entry (errors name `imus[i]…`).
fn build(ctx: &SensorBuild<'_>, out: &mut Vec<Box<dyn Sensor>>) -> Result<(), ConfigError> {
    for (i, imu) in ctx.sensors.of::<ImuConfig>().enumerate() {
        let path = format!("imus[{i}]");
        out.push(Box::new(ImuSensor::new(
            imu,
            &path,
            ctx.sample_interval_s,
            ctx.t_sim_ns,
            ctx.x,
        )?));
    }
    Ok(())
}

impl SensorParams for ImuConfig {
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
