//! The `[[magnetometers]]` schema. Keys are checked by the shared reader ([`flexdyn_kernel::schema`]);
//! values by [`super::MagnetometerConfig::validate`] and the configuration (the rate must divide
//! the frame rate, the misalignment's diagonal must be zero).

use nalgebra::{Matrix3, Vector3};

use super::MagnetometerConfig;
use crate::params::SensorContext;
use crate::params::{RawSensorConfig, SensorSpec};
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::{mat3, vec3, SchemaError, TableReader};

/// The keys of one `[[magnetometers]]` entry (the first four are required).
pub(crate) const KEYS: [&str; 11] = [
    "name",
    "dcm_sb",
    "rate_hz",
    "seed",
    "scale_factor",
    "misalignment_rad",
    "bias_s_t",
    "noise_sigma_t",
    "range_t",
    "lsb_t",
    "r_sb_b_m",
];

/// One entry as written (the rate is converted to frames by the configuration).
pub(crate) struct RawMagnetometer {
    pub(crate) name: String,
    pub(crate) dcm_sb: Matrix3<f64>,
    pub(crate) rate_hz: f64,
    pub(crate) seed: u64,
    pub(crate) scale_factor: Vector3<f64>,
    pub(crate) misalignment_rad: Matrix3<f64>,
    pub(crate) bias_s_t: Vector3<f64>,
    pub(crate) noise_sigma_t: f64,
    pub(crate) range_t: f64,
    pub(crate) lsb_t: f64,
    pub(crate) r_sb_b_m: Option<Vector3<f64>>,
}

/// Reads one entry.
pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<RawMagnetometer, SchemaError> {
    let v3 = |a: [f64; 3]| vec3(&a);
    Ok(RawMagnetometer {
        name: t.string("name")?,
        dcm_sb: mat3(&t.mat3("dcm_sb")?),
        rate_hz: t.f64("rate_hz")?,
        seed: t.int_in("seed", 0, i64::MAX)? as u64,
        scale_factor: t.opt_floats("scale_factor")?.map_or(Vector3::zeros(), v3),
        misalignment_rad: t
            .opt_mat3("misalignment_rad")?
            .map_or(Matrix3::zeros(), |m| mat3(&m)),
        bias_s_t: t.opt_floats("bias_s_t")?.map_or(Vector3::zeros(), v3),
        noise_sigma_t: t.opt_f64("noise_sigma_t")?.unwrap_or(0.0),
        range_t: t.opt_f64("range_t")?.unwrap_or(0.0),
        lsb_t: t.opt_f64("lsb_t")?.unwrap_or(0.0),
        r_sb_b_m: t.opt_floats("r_sb_b_m")?.map(v3),
    })
}

impl RawSensorConfig for RawMagnetometer {
    /// Checks the name, converts the rate to frames, rejects a misalignment with a non-zero
    /// diagonal and validates the values ([`MagnetometerConfig::validate`]).
    fn resolve(
        self: Box<Self>,
        ctx: &mut SensorContext<'_>,
        path: &str,
    ) -> Result<Box<dyn SensorSpec>, ConfigError> {
        let raw = *self;
        ctx.unique_name(path, &raw.name, "magnetometer")?;
        ctx.sensor_name(path, &raw.name)?;
        let every_frames =
            ctx.every_frames(&format!("{path}.rate_hz"), raw.rate_hz, "magnetometer")?;
        if let Some(k) = (0..3).find(|&k| raw.misalignment_rad[(k, k)] != 0.0) {
            return Err(ctx.invalid(
                &format!("{path}.misalignment_rad"),
                format!(
                    "the diagonal must be zero (element [{k}][{k}] is {}): a scale error \
                     belongs in scale_factor",
                    Num(raw.misalignment_rad[(k, k)])
                ),
            ));
        }
        let cfg = MagnetometerConfig {
            name: raw.name,
            dcm_sb: raw.dcm_sb,
            scale_factor: raw.scale_factor,
            misalignment_rad: raw.misalignment_rad,
            bias_s_t: raw.bias_s_t,
            noise_sigma_t: raw.noise_sigma_t,
            range_t: raw.range_t,
            lsb_t: raw.lsb_t,
            every_frames,
            seed: raw.seed,
            r_sb_b_m: raw.r_sb_b_m,
        };
        cfg.validate(path).map_err(|e| ctx.param(e))?;
        Ok(Box::new(cfg))
    }
}
