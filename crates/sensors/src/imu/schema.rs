//! The `[[imus]]` schema: location, platform frame, seed and the gyro and accelerometer error
//! terms. Keys are checked by the shared reader ([`flexdyn_kernel::schema`]); values are validated by
//! [`super::Imu::new`] and the configuration's magnitude bounds.

use super::{AccelErrors, GyroErrors, ImuConfig};
use crate::params::SensorContext;
use crate::params::{RawSensorConfig, SensorSpec};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::{mat3, vec3, SchemaError, TableReader};

/// The keys of one `[[imus]]` entry.
pub(crate) const KEYS: [&str; 6] = ["name", "r_sb_b_m", "dcm_pb", "seed", "gyro", "accel"];

pub(crate) struct RawImu {
    name: String,
    r_sb_b_m: [f64; 3],
    dcm_pb: [[f64; 3]; 3],
    seed: u64,
    gyro: RawTriad,
    accel: RawTriad,
}

/// `[imus.gyro]` or `[imus.accel]`: every key optional, zero by default (see [`GyroErrors`],
/// [`AccelErrors`]). The key names differ by unit; the values are read in this order:
/// white noise, bias-instability σ, its τ, random walk, bias, scale factor, misalignment,
/// range, output LSB, increment LSB.
#[derive(Default)]
struct RawTriad {
    white: f64,
    bias_instability_sigma: f64,
    bias_instability_tau_s: f64,
    random_walk: f64,
    bias: [f64; 3],
    scale_factor: [f64; 3],
    misalignment_rad: [[f64; 3]; 3],
    range: f64,
    lsb: f64,
    increment_lsb: f64,
}

/// The keys of a triad table, in [`RawTriad`]'s order.
pub(crate) const GYRO_KEYS: [&str; 10] = [
    "arw_rad_s_sqrt_hz",
    "bias_instability_sigma_rad_s",
    "bias_instability_tau_s",
    "rrw_rad_s2_sqrt_hz",
    "bias_rad_s",
    "scale_factor",
    "misalignment_rad",
    "range_rad_s",
    "lsb_rad_s",
    "dtheta_lsb_rad",
];
pub(crate) const ACCEL_KEYS: [&str; 10] = [
    "vrw_m_s2_sqrt_hz",
    "bias_instability_sigma_m_s2",
    "bias_instability_tau_s",
    "rrw_m_s3_sqrt_hz",
    "bias_m_s2",
    "scale_factor",
    "misalignment_rad",
    "range_m_s2",
    "lsb_m_s2",
    "dv_lsb_m_s",
];

impl RawTriad {
    pub(crate) fn read(
        t: Option<TableReader<'_, '_>>,
        keys: &[&str; 10],
    ) -> Result<Self, SchemaError> {
        let Some(t) = t else {
            return Ok(Self::default());
        };
        let f = |k: &str| t.opt_f64(k).map(Option::unwrap_or_default);
        Ok(RawTriad {
            white: f(keys[0])?,
            bias_instability_sigma: f(keys[1])?,
            bias_instability_tau_s: f(keys[2])?,
            random_walk: f(keys[3])?,
            bias: t.opt_floats(keys[4])?.unwrap_or_default(),
            scale_factor: t.opt_floats(keys[5])?.unwrap_or_default(),
            misalignment_rad: t.opt_mat3(keys[6])?.unwrap_or_default(),
            range: f(keys[7])?,
            lsb: f(keys[8])?,
            increment_lsb: f(keys[9])?,
        })
    }
}

impl RawImu {
    pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<Self, SchemaError> {
        Ok(RawImu {
            name: t.string("name")?,
            r_sb_b_m: t.floats("r_sb_b_m")?,
            dcm_pb: t.mat3("dcm_pb")?,
            // The documented range 0 ≤ seed ≤ 2⁶³ − 1 is TOML's non-negative integers.
            seed: t.int_in("seed", 0, i64::MAX)? as u64,
            gyro: RawTriad::read(t.opt_table("gyro", &GYRO_KEYS)?, &GYRO_KEYS)?,
            accel: RawTriad::read(t.opt_table("accel", &ACCEL_KEYS)?, &ACCEL_KEYS)?,
        })
    }

    pub(crate) fn into_config(self) -> ImuConfig {
        let g = self.gyro;
        let a = self.accel;
        ImuConfig {
            name: self.name,
            r_sb_b_m: vec3(&self.r_sb_b_m),
            dcm_pb: mat3(&self.dcm_pb),
            seed: self.seed,
            gyro: GyroErrors {
                arw_rad_s_sqrt_hz: g.white,
                bias_instability_sigma_rad_s: g.bias_instability_sigma,
                bias_instability_tau_s: g.bias_instability_tau_s,
                rrw_rad_s2_sqrt_hz: g.random_walk,
                bias_rad_s: vec3(&g.bias),
                scale_factor: vec3(&g.scale_factor),
                misalignment_rad: mat3(&g.misalignment_rad),
                range_rad_s: g.range,
                lsb_rad_s: g.lsb,
                dtheta_lsb_rad: g.increment_lsb,
            },
            accel: AccelErrors {
                vrw_m_s2_sqrt_hz: a.white,
                bias_instability_sigma_m_s2: a.bias_instability_sigma,
                bias_instability_tau_s: a.bias_instability_tau_s,
                rrw_m_s3_sqrt_hz: a.random_walk,
                bias_m_s2: vec3(&a.bias),
                scale_factor: vec3(&a.scale_factor),
                misalignment_rad: mat3(&a.misalignment_rad),
                range_m_s2: a.range,
                lsb_m_s2: a.lsb,
                dv_lsb_m_s: a.increment_lsb,
            },
        }
    }
}

impl RawSensorConfig for RawImu {
    /// Validates the terms ([`ImuConfig::validate`]), then the name's uniqueness.
    fn resolve(
        self: Box<Self>,
        ctx: &mut SensorContext<'_>,
        path: &str,
    ) -> Result<Box<dyn SensorSpec>, ConfigError> {
        let imu = self.into_config();
        imu.validate(path).map_err(|e| ctx.imu_error(e))?;
        ctx.unique_name(path, &imu.name, "IMU")?;
        Ok(Box::new(imu))
    }
}
