//! The `[[fine_sun_sensors]]` schema. Keys are checked by the shared reader ([`flexdyn_kernel::schema`]);
//! values by [`super::FineSunSensorConfig::validate`] and the configuration (the rate must
//! divide the frame rate).

use nalgebra::{Matrix3, Vector2};

use super::FineSunSensorConfig;
use crate::params::SensorContext;
use crate::params::{RawSensorConfig, SensorSpec};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::{mat3, SchemaError, TableReader};

/// The keys of one `[[fine_sun_sensors]]` entry (the first five are required).
pub(crate) const KEYS: [&str; 9] = [
    "name",
    "dcm_fb",
    "rate_hz",
    "seed",
    "fov_half_angle_rad",
    "bias_rad",
    "noise_sigma_rad",
    "lsb_rad",
    "min_shadow_factor",
];

/// One entry as written (the rate is converted to frames by the configuration).
pub(crate) struct RawFineSunSensor {
    pub(crate) name: String,
    pub(crate) dcm_fb: Matrix3<f64>,
    pub(crate) rate_hz: f64,
    pub(crate) seed: u64,
    pub(crate) fov_half_angle_rad: f64,
    pub(crate) bias_rad: Vector2<f64>,
    pub(crate) noise_sigma_rad: f64,
    pub(crate) lsb_rad: f64,
    pub(crate) min_shadow_factor: f64,
}

/// Reads one entry. Defaults: no bias, noise or quantisation; valid down to half the solar
/// disc (`min_shadow_factor` 0.5).
pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<RawFineSunSensor, SchemaError> {
    Ok(RawFineSunSensor {
        name: t.string("name")?,
        dcm_fb: mat3(&t.mat3("dcm_fb")?),
        rate_hz: t.f64("rate_hz")?,
        seed: t.int_in("seed", 0, i64::MAX)? as u64,
        fov_half_angle_rad: t.f64("fov_half_angle_rad")?,
        bias_rad: t
            .opt_floats::<2>("bias_rad")?
            .map_or(Vector2::zeros(), |b| Vector2::new(b[0], b[1])),
        noise_sigma_rad: t.opt_f64("noise_sigma_rad")?.unwrap_or(0.0),
        lsb_rad: t.opt_f64("lsb_rad")?.unwrap_or(0.0),
        min_shadow_factor: t.opt_f64("min_shadow_factor")?.unwrap_or(0.5),
    })
}

impl RawSensorConfig for RawFineSunSensor {
    /// Checks the name, converts the rate to frames and validates the values
    /// ([`FineSunSensorConfig::validate`]).
    fn resolve(
        self: Box<Self>,
        ctx: &mut SensorContext<'_>,
        path: &str,
    ) -> Result<Box<dyn SensorSpec>, ConfigError> {
        let raw = *self;
        ctx.unique_name(path, &raw.name, "fine sun sensor")?;
        ctx.sensor_name(path, &raw.name)?;
        let cfg = FineSunSensorConfig {
            every_frames: ctx.every_frames(&format!("{path}.rate_hz"), raw.rate_hz, "sensor")?,
            name: raw.name,
            dcm_fb: raw.dcm_fb,
            fov_half_angle_rad: raw.fov_half_angle_rad,
            bias_rad: raw.bias_rad,
            noise_sigma_rad: raw.noise_sigma_rad,
            lsb_rad: raw.lsb_rad,
            min_shadow_factor: raw.min_shadow_factor,
            seed: raw.seed,
        };
        cfg.validate(path).map_err(|e| ctx.param(e))?;
        Ok(Box::new(cfg))
    }
}
