//! The `[[star_trackers]]` schema. Keys are checked by the shared reader ([`flexdyn_kernel::schema`]);
//! values by [`super::StarTrackerConfig::validate`] and the configuration (the rate must divide
//! the frame rate).

use nalgebra::{Matrix3, Vector3};

use super::StarTrackerConfig;
use crate::params::SensorContext;
use crate::params::{RawSensorConfig, SensorSpec};
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::{mat3, vec3, SchemaError, TableReader};

/// The keys of one `[[star_trackers]]` entry (the first six are required).
pub(crate) const KEYS: [&str; 16] = [
    "name",
    "dcm_cb",
    "sigma_cross_boresight_rad",
    "sigma_about_boresight_rad",
    "rate_hz",
    "seed",
    "boresight_c",
    "bias_c_rad",
    "sun_direction_n",
    "sun_from_environment",
    "sun_exclusion_rad",
    "max_rate_rad_s",
    "earth_exclusion_rad",
    "earth_radius_m",
    "earth_atmosphere_m",
    "moon_exclusion_rad",
];

/// One entry as written (the rate is converted to frames by the configuration).
pub(crate) struct RawStarTracker {
    pub(crate) name: String,
    pub(crate) dcm_cb: Matrix3<f64>,
    pub(crate) sigma_cross_boresight_rad: f64,
    pub(crate) sigma_about_boresight_rad: f64,
    pub(crate) rate_hz: f64,
    pub(crate) seed: u64,
    pub(crate) boresight_c: Vector3<f64>,
    pub(crate) bias_c_rad: Vector3<f64>,
    pub(crate) sun_direction_n: Vector3<f64>,
    pub(crate) sun_from_environment: bool,
    pub(crate) sun_exclusion_rad: f64,
    pub(crate) max_rate_rad_s: f64,
    pub(crate) earth_exclusion_rad: f64,
    pub(crate) earth_radius_m: f64,
    pub(crate) earth_atmosphere_m: f64,
    pub(crate) moon_exclusion_rad: f64,
}

/// Reads one entry.
pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<RawStarTracker, SchemaError> {
    let v3 = |a: [f64; 3]| vec3(&a);
    let sun_from_environment = t.opt_bool("sun_from_environment")?.unwrap_or(false);
    if sun_from_environment && t.get("sun_direction_n").is_some() {
        return Err(SchemaError::InvalidValue {
            field: t.field("sun_direction_n"),
            message: format!(
                "give either sun_direction_n (a fixed Sun) or {} = true (the environment's \
                 Sun at each update), not both",
                t.field("sun_from_environment")
            ),
            at: flexdyn_kernel::schema::At(None),
        });
    }
    Ok(RawStarTracker {
        name: t.string("name")?,
        dcm_cb: mat3(&t.mat3("dcm_cb")?),
        sigma_cross_boresight_rad: t.f64("sigma_cross_boresight_rad")?,
        sigma_about_boresight_rad: t.f64("sigma_about_boresight_rad")?,
        rate_hz: t.f64("rate_hz")?,
        // The documented range 0 ≤ seed ≤ 2⁶³ − 1 is TOML's non-negative integers.
        seed: t.int_in("seed", 0, i64::MAX)? as u64,
        boresight_c: t.opt_floats("boresight_c")?.map_or(Vector3::z(), v3),
        bias_c_rad: t.opt_floats("bias_c_rad")?.map_or(Vector3::zeros(), v3),
        sun_direction_n: t.opt_floats("sun_direction_n")?.map_or(Vector3::x(), v3),
        sun_from_environment,
        sun_exclusion_rad: t.opt_f64("sun_exclusion_rad")?.unwrap_or(0.0),
        max_rate_rad_s: t.opt_f64("max_rate_rad_s")?.unwrap_or(f64::INFINITY),
        earth_exclusion_rad: t.opt_f64("earth_exclusion_rad")?.unwrap_or(0.0),
        earth_radius_m: t
            .opt_f64("earth_radius_m")?
            .unwrap_or(flexdyn_environment::geodetic::WGS84_A_M),
        earth_atmosphere_m: t.opt_f64("earth_atmosphere_m")?.unwrap_or(0.0),
        moon_exclusion_rad: t.opt_f64("moon_exclusion_rad")?.unwrap_or(0.0),
    })
}

impl RawSensorConfig for RawStarTracker {
    /// Checks the name, converts the rate to frames and validates the values
    /// ([`StarTrackerConfig::validate`]).
    fn resolve(
        self: Box<Self>,
        ctx: &mut SensorContext<'_>,
        path: &str,
    ) -> Result<Box<dyn SensorSpec>, ConfigError> {
        let raw = *self;
        ctx.unique_name(path, &raw.name, "star tracker")?;
        if let Err(e) = flexdyn_proto::validate_star_tracker_name(&raw.name) {
            return Err(ctx.invalid(&format!("{path}.name"), e.to_string()));
        }
        let every_frames = ctx.every_frames(&format!("{path}.rate_hz"), raw.rate_hz, "tracker")?;
        let cfg = StarTrackerConfig {
            name: raw.name,
            dcm_cb: raw.dcm_cb,
            boresight_c: raw.boresight_c,
            sigma_cross_boresight_rad: raw.sigma_cross_boresight_rad,
            sigma_about_boresight_rad: raw.sigma_about_boresight_rad,
            bias_c_rad: raw.bias_c_rad,
            every_frames,
            seed: raw.seed,
            sun_direction_n: raw.sun_direction_n,
            sun_from_environment: raw.sun_from_environment,
            sun_exclusion_rad: raw.sun_exclusion_rad,
            max_rate_rad_s: raw.max_rate_rad_s,
            earth_exclusion_rad: raw.earth_exclusion_rad,
            earth_radius_m: raw.earth_radius_m,
            earth_atmosphere_m: raw.earth_atmosphere_m,
            moon_exclusion_rad: raw.moon_exclusion_rad,
        };
        cfg.validate(path).map_err(|e| ctx.param(e))?;
        Ok(Box::new(cfg))
    }
}
