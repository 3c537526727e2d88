//! The `[[gps_receivers]]` schema. Keys are checked by the shared reader ([`flexdyn_kernel::schema`]);
//! values by [`super::GpsConfig::validate`] and [`RawGps::resolve`] (the rate must divide the
//! frame rate, the latency and the times must be whole numbers of frames or nanoseconds).

use nalgebra::Vector3;

use super::GpsConfig;
use crate::params::SensorContext;
use crate::params::{RawSensorConfig, SensorSpec};
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::checks::whole_ns;
use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::{vec3, SchemaError, TableReader};
use flexdyn_kernel::validate::ParamError;

/// The keys of one `[[gps_receivers]]` entry (the first three are required).
pub(crate) const KEYS: [&str; 11] = [
    "name",
    "rate_hz",
    "seed",
    "frames",
    "latency_s",
    "acquisition_s",
    "outage_s",
    "position_sigma_m",
    "velocity_sigma_m_s",
    "position_bias_e_m",
    "velocity_bias_e_m_s",
];

/// The choices of `frames`.
const FRAMES: [&str; 3] = ["ecef", "n", "both"];

/// One entry as written (rates and times are converted by [`RawGps::resolve`]).
pub(crate) struct RawGps {
    name: String,
    rate_hz: f64,
    seed: u64,
    frames: usize,
    latency_s: f64,
    acquisition_s: f64,
    outage_s: Option<[f64; 2]>,
    position_sigma_m: f64,
    velocity_sigma_m_s: f64,
    position_bias_e_m: Vector3<f64>,
    velocity_bias_e_m_s: Vector3<f64>,
}

/// Reads one entry.
pub(crate) fn read(t: &TableReader<'_, '_>) -> Result<RawGps, SchemaError> {
    let v3 = |a: [f64; 3]| vec3(&a);
    Ok(RawGps {
        name: t.string("name")?,
        rate_hz: t.f64("rate_hz")?,
        seed: t.int_in("seed", 0, i64::MAX)? as u64,
        frames: t.opt_choice("frames", &FRAMES)?.unwrap_or(0),
        latency_s: t.opt_f64("latency_s")?.unwrap_or(0.0),
        acquisition_s: t.opt_f64("acquisition_s")?.unwrap_or(0.0),
        outage_s: t.opt_floats("outage_s")?,
        position_sigma_m: t.opt_f64("position_sigma_m")?.unwrap_or(0.0),
        velocity_sigma_m_s: t.opt_f64("velocity_sigma_m_s")?.unwrap_or(0.0),
        position_bias_e_m: t
            .opt_floats("position_bias_e_m")?
            .map_or(Vector3::zeros(), v3),
        velocity_bias_e_m_s: t
            .opt_floats("velocity_bias_e_m_s")?
            .map_or(Vector3::zeros(), v3),
    })
}

/// `seconds` at `field` as whole nanoseconds ≥ 0.
fn time_ns(ctx: &SensorContext<'_>, field: &str, seconds: f64) -> Result<u64, ConfigError> {
    if seconds < 0.0 {
        return Err(ctx.param(ParamError::Negative {
            field: field.to_string(),
            value: seconds,
        }));
    }
    whole_ns(seconds).ok_or_else(|| {
        ctx.invalid(
            field,
            format!("{} s is not a whole number of nanoseconds", Num(seconds)),
        )
    })
}

impl RawSensorConfig for RawGps {
    /// Checks the name, converts the rate and the latency to frames and the times to
    /// nanoseconds, and validates the values ([`GpsConfig::validate`]).
    fn resolve(
        self: Box<Self>,
        ctx: &mut SensorContext<'_>,
        path: &str,
    ) -> Result<Box<dyn SensorSpec>, ConfigError> {
        let raw = *self;
        ctx.unique_name(path, &raw.name, "GPS receiver")?;
        ctx.sensor_name(path, &raw.name)?;
        let every_frames = ctx.every_frames(&format!("{path}.rate_hz"), raw.rate_hz, "receiver")?;
        let field = format!("{path}.latency_s");
        time_ns(ctx, &field, raw.latency_s)?;
        let frames = raw.latency_s * ctx.frame_hz;
        if (frames - frames.round()).abs() > 1e-9 * frames.max(1.0) {
            return Err(ctx.invalid(
                &field,
                format!(
                    "{} s is not a whole number of frames (the frame is 1/{} Hz): the receiver \
                     publishes at frame boundaries",
                    Num(raw.latency_s),
                    Num(ctx.frame_hz)
                ),
            ));
        }
        let acquisition_ns = time_ns(ctx, &format!("{path}.acquisition_s"), raw.acquisition_s)?;
        let outage_ns = match raw.outage_s {
            None => None,
            Some([start, end]) => {
                let field = format!("{path}.outage_s");
                let (a, b) = (time_ns(ctx, &field, start)?, time_ns(ctx, &field, end)?);
                if b <= a {
                    return Err(ctx.invalid(
                        &field,
                        format!(
                            "the outage [{}, {}] s must end after it starts",
                            Num(start),
                            Num(end)
                        ),
                    ));
                }
                Some((a, b))
            }
        };
        let cfg = GpsConfig {
            name: raw.name,
            every_frames,
            latency_frames: frames.round() as u64,
            ecef: raw.frames != 1,
            inertial: raw.frames != 0,
            acquisition_ns,
            outage_ns,
            position_sigma_m: raw.position_sigma_m,
            velocity_sigma_m_s: raw.velocity_sigma_m_s,
            position_bias_e_m: raw.position_bias_e_m,
            velocity_bias_e_m_s: raw.velocity_bias_e_m_s,
            seed: raw.seed,
        };
        cfg.validate(path).map_err(|e| ctx.param(e))?;
        Ok(Box::new(cfg))
    }
}
