//! The `[[coarse_sun_sensors]]` schema. Keys are checked by the shared reader
//! ([`flexdyn_kernel::schema`]); values by [`super::CoarseSunSensorConfig::validate`] and the
//! configuration (the rate must divide the frame rate).

use super::CoarseSunSensorConfig;
use crate::params::SensorContext;
use crate::params::{RawSensorConfig, SensorSpec};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::{vec3, SchemaError, TableReader};
use nalgebra::Vector3;

/// The keys of one `[[coarse_sun_sensors]]` entry (the first four are required).
pub(crate) const KEYS: [&str; 9] = [
    "name",
    "normals_b",
    "rate_hz",
    "seed",
    "fov_half_angle_rad",
    "scale",
    "bias",
    "noise_sigma",
    "lsb",
];

/// One entry as written (the rate is converted to frames by the configuration).
pub(crate) struct RawCoarseSunSensor {
    pub(crate) name: String,
    pub(crate) normals_b: Vec<Vector3<f64>>,
    pub(crate) rate_hz: f64,
    pub(crate) seed: u64,
    pub(crate) fov_half_angle_rad: f64,
    pub(crate) scale: f64,
    pub(crate) bias: f64,
    pub(crate) noise_sigma: f64,
    pub(crate) lsb: f64,
}

/// Reads one entry. Defaults: a hemispherical field of view (π/2), `scale` 1 (readings are
/// cos θ times the shadow factor), no bias, noise or quantisation.
pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<RawCoarseSunSensor, SchemaError> {
    Ok(RawCoarseSunSensor {
        name: t.string("name")?,
        normals_b: t.vec3_list("normals_b")?.iter().map(vec3).collect(),
        rate_hz: t.f64("rate_hz")?,
        seed: t.int_in("seed", 0, i64::MAX)? as u64,
        fov_half_angle_rad: t
            .opt_f64("fov_half_angle_rad")?
            .unwrap_or(std::f64::consts::FRAC_PI_2),
        scale: t.opt_f64("scale")?.unwrap_or(1.0),
        bias: t.opt_f64("bias")?.unwrap_or(0.0),
        noise_sigma: t.opt_f64("noise_sigma")?.unwrap_or(0.0),
        lsb: t.opt_f64("lsb")?.unwrap_or(0.0),
    })
}

impl RawSensorConfig for RawCoarseSunSensor {
    /// Checks the name, converts the rate to frames and validates the values
    /// ([`CoarseSunSensorConfig::validate`]). Like a magnetometer without a field model, a sun
    /// sensor without `[environment] sun = true` sees no Sun (it reads 0).
    fn resolve(
        self: Box<Self>,
        ctx: &mut SensorContext<'_>,
        path: &str,
    ) -> Result<Box<dyn SensorSpec>, ConfigError> {
        let raw = *self;
        ctx.unique_name(path, &raw.name, "coarse sun sensor")?;
        ctx.sensor_name(path, &raw.name)?;
        let cfg = CoarseSunSensorConfig {
            every_frames: ctx.every_frames(&format!("{path}.rate_hz"), raw.rate_hz, "array")?,
            name: raw.name,
            normals_b: raw.normals_b,
            fov_half_angle_rad: raw.fov_half_angle_rad,
            scale: raw.scale,
            bias: raw.bias,
            noise_sigma: raw.noise_sigma,
            lsb: raw.lsb,
            seed: raw.seed,
        };
        cfg.validate(path).map_err(|e| ctx.param(e))?;
        Ok(Box::new(cfg))
    }
}
