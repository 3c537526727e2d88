//! A fine (two-axis) sun sensor: the Sun's direction as two angles in the sensor's own frame F,
//! with a field of view, a bias, white noise, quantisation and a validity flag, published as
//! `FssMsg` on `flexdyn/<sc-id>/tlm/fss/<name>`.
//!
//! # Measurement model
//! The sensor is mounted with the fixed DCM \[FB\]; its boresight is F's axis 3. With ŝ_B the
//! unit Sun direction from the environment sample and ν its shadow factor,
//!
//! ```text
//! s   = [FB] ŝ_B                                   (s₁, s₂, s₃), unit
//! α   = atan2(s₁, s₃),   β = atan2(s₂, s₃)         tan α = s₁/s₃, tan β = s₂/s₃
//! IN_FOV = s₃ ≥ cos(fov_half_angle_rad)           the Sun within the cone about +3
//! SUNLIT = ν ≥ min_shadow_factor
//! VALID  = IN_FOV and SUNLIT:  (α, β) + bias + σ (z₁, z₂), each rounded to a multiple of
//!          lsb_rad (if > 0);  otherwise both angles are 0
//! ```
//!
//! The angles are the two-axis convention of slit and quadrant sun sensors: the Sun's angle from
//! the boresight projected on the sensor's 1–3 and 2–3 planes (Wertz (ed.), *Spacecraft Attitude
//! Determination and Control*, 1978, §6.1 and §7.1: a two-axis sensor is two single-axis heads
//! at right angles, each measuring atan of the in-plane component over the boresight
//! component). A flight unit calibrated to another convention (e.g. the angle from the boresight
//! and an azimuth) converts from these. With every error term zero the output is exactly
//! atan2(s₁, s₃), atan2(s₂, s₃) of \[FB\]\[BN\](r_sun/|r_sun|).
//!
//! # Neglected
//! Earth albedo (it shifts the sensed centroid when the Earth is in the field of view), the
//! penumbra's shift of the sensed centroid (the angles stay those of the Sun's centre until the
//! shadow factor drops below the threshold), field-of-view-dependent calibration errors, and
//! the Sun's finite disc. Without a Sun (no environment sample or no ephemeris) the sensor is
//! neither IN_FOV nor SUNLIT: set `sun = true` in `[environment]`.
//!
//! # Timing and random numbers
//! It updates every `frame_hz / rate_hz` frames, at the frame boundaries whose tick is a
//! multiple of it, starting at tick 0. Its normals come from the sensors' portable generator
//! ([`super::rng`]) seeded with `seed`, one pair (z₁, z₂) per update, drawn whether or not the
//! sample is valid or σ is zero, so a seed reproduces the stream bit for bit. (The angles use
//! the platform's `atan2`: bit-identical run to run on one machine, within an ulp across
//! platforms.)

use nalgebra::{Matrix3, Vector2, Vector3};

use crate::{Sensor, SensorKind, Truth};
use flexdyn_kernel::validate::{check_dcm, check_finite, check_sensor_term, ParamError};
use flexdyn_proto::{encode_into, fss_flags, FssMsg, Header};

use super::rng::NormalRng;

mod kind;
pub(crate) mod schema;

pub use kind::KIND;

/// A fine sun sensor's configuration (`[[fine_sun_sensors]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct FineSunSensorConfig {
    /// Name: the last chunk of its topic key.
    pub name: String,
    /// Mounting DCM \[FB\]: maps B components to sensor-frame F components (boresight +3).
    pub dcm_fb: Matrix3<f64>,
    /// \[rad\] field-of-view half-angle about the boresight, in (0, π/2).
    pub fov_half_angle_rad: f64,
    /// \[rad\] constant bias of (α, β).
    pub bias_rad: Vector2<f64>,
    /// \[rad\] 1σ white noise per angle and sample.
    pub noise_sigma_rad: f64,
    /// \[rad\] output LSB; 0 = not quantised.
    pub lsb_rad: f64,
    /// \[-\] the smallest shadow factor at which the sensor still measures, in (0, 1].
    pub min_shadow_factor: f64,
    /// Updates every this many frames (from `rate_hz`; ≥ 1).
    pub every_frames: u64,
    /// RNG seed (0 ≤ seed ≤ 2⁶³ − 1 in the configuration).
    pub seed: u64,
}

impl FineSunSensorConfig {
    /// Validates the values (`path` is e.g. `fine_sun_sensors[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_dcm(path, "dcm_fb", &self.dcm_fb)?;
        check_finite(path, "fov_half_angle_rad", &[self.fov_half_angle_rad])?;
        if !(self.fov_half_angle_rad > 0.0 && self.fov_half_angle_rad < std::f64::consts::FRAC_PI_2)
        {
            return Err(ParamError::Invalid {
                field: format!("{path}.fov_half_angle_rad"),
                problem: format!(
                    "must be in (0, π/2) rad (the angles atan2(s1, s3), atan2(s2, s3) need the \
                     Sun in front of the sensor), got {}",
                    self.fov_half_angle_rad
                ),
            });
        }
        check_sensor_term(path, "bias_rad", self.bias_rad.as_slice(), false)?;
        check_sensor_term(path, "noise_sigma_rad", &[self.noise_sigma_rad], true)?;
        check_sensor_term(path, "lsb_rad", &[self.lsb_rad], true)?;
        check_finite(path, "min_shadow_factor", &[self.min_shadow_factor])?;
        if !(self.min_shadow_factor > 0.0 && self.min_shadow_factor <= 1.0) {
            return Err(ParamError::Invalid {
                field: format!("{path}.min_shadow_factor"),
                problem: format!(
                    "must be in (0, 1] (the visible fraction of the solar disc below which the \
                     sensor reports no Sun), got {}",
                    self.min_shadow_factor
                ),
            });
        }
        Ok(())
    }
}

/// One fine-sun-sensor output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FineSunSensorSample {
    /// \[rad\] α (0 unless valid).
    pub alpha_rad: f64,
    /// \[rad\] β (0 unless valid).
    pub beta_rad: f64,
    /// [`fss_flags`].
    pub flags: u8,
}

impl FineSunSensorSample {
    /// Whether the angles are a measurement.
    pub fn valid(&self) -> bool {
        self.flags & fss_flags::VALID != 0
    }

    /// The wire message with `header`.
    pub fn to_msg(&self, header: Header) -> FssMsg {
        FssMsg {
            header,
            alpha_rad: self.alpha_rad,
            beta_rad: self.beta_rad,
            flags: self.flags,
        }
    }
}

/// A fine sun sensor with its noise generator and last output.
#[derive(Debug, Clone)]
pub struct FineSunSensor {
    cfg: FineSunSensorConfig,
    /// cos(fov_half_angle_rad), formed once.
    cos_fov: f64,
    rng: NormalRng,
    last: FineSunSensorSample,
}

impl FineSunSensor {
    /// A sensor from a configuration, validated (errors name `path.<field>`).
    pub fn new(cfg: FineSunSensorConfig, path: &str) -> Result<Self, ParamError> {
        cfg.validate(path)?;
        Ok(Self {
            rng: NormalRng::new(cfg.seed),
            cos_fov: cfg.fov_half_angle_rad.cos(),
            last: FineSunSensorSample {
                alpha_rad: 0.0,
                beta_rad: 0.0,
                flags: 0,
            },
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &FineSunSensorConfig {
        &self.cfg
    }

    /// The last output (invalid before the first).
    pub fn last(&self) -> FineSunSensorSample {
        self.last
    }

    /// One measurement by the model of the module docs: `sun` is the unit Sun direction in B
    /// and the shadow factor, or `None` for no Sun.
    pub fn measure(&mut self, sun: Option<(Vector3<f64>, f64)>) -> FineSunSensorSample {
        let (z1, z2) = self.rng.normal_pair();
        let c = &self.cfg;
        let Some((s_b, shadow)) = sun else {
            return FineSunSensorSample {
                alpha_rad: 0.0,
                beta_rad: 0.0,
                flags: 0,
            };
        };
        let s = c.dcm_fb * s_b;
        let mut flags = 0;
        if s[2] >= self.cos_fov {
            flags |= fss_flags::IN_FOV;
        }
        if shadow >= c.min_shadow_factor {
            flags |= fss_flags::SUNLIT;
        }
        if flags != fss_flags::IN_FOV | fss_flags::SUNLIT {
            return FineSunSensorSample {
                alpha_rad: 0.0,
                beta_rad: 0.0,
                flags,
            };
        }
        let quantise = |x: f64| {
            if c.lsb_rad > 0.0 {
                (x / c.lsb_rad).round() * c.lsb_rad
            } else {
                x
            }
        };
        FineSunSensorSample {
            alpha_rad: quantise(s[0].atan2(s[2]) + c.bias_rad[0] + c.noise_sigma_rad * z1),
            beta_rad: quantise(s[1].atan2(s[2]) + c.bias_rad[1] + c.noise_sigma_rad * z2),
            flags: flags | fss_flags::VALID,
        }
    }
}

impl Sensor for FineSunSensor {
    fn kind(&self) -> &'static SensorKind {
        &KIND
    }

    fn name(&self) -> &str {
        &self.cfg.name
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        let c = &self.cfg;
        out.push(("fov_half_angle_rad".into(), c.fov_half_angle_rad));
        for i in 0..2 {
            out.push((format!("bias_rad[{i}]"), c.bias_rad[i]));
        }
        out.push(("noise_sigma_rad".into(), c.noise_sigma_rad));
        out.push(("lsb_rad".into(), c.lsb_rad));
        out.push(("min_shadow_factor".into(), c.min_shadow_factor));
    }

    fn due(&self, tick: u64) -> bool {
        tick.is_multiple_of(self.cfg.every_frames)
    }

    fn sample(&mut self, truth: &Truth<'_>) {
        self.last = self.measure(truth.sun_b());
    }

    /// `seq` counts the updates: the frame's tick / `every_frames`.
    fn encode(&self, header: Header, buf: &mut Vec<u8>) {
        let header = Header {
            seq: header.tick / self.cfg.every_frames,
            ..header
        };
        encode_into(&self.last.to_msg(header), buf);
    }

    fn first_non_finite(&self) -> Option<&'static str> {
        if !self.last.alpha_rad.is_finite() {
            Some("alpha_rad")
        } else if !self.last.beta_rad.is_finite() {
            Some("beta_rad")
        } else {
            None
        }
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            cfg: _,
            cos_fov: _,
            rng,
            last:
                FineSunSensorSample {
                    alpha_rad,
                    beta_rad,
                    flags,
                },
        } = self;
        a.put(rng);
        a.put(alpha_rad);
        a.put(beta_rad);
        a.put(flags);
    }

    /// `alpha` and `beta` (rad).
    fn fault_channels(&self) -> &'static [&'static str] {
        &["alpha", "beta"]
    }

    fn fault_axes(&self, channel: usize) -> usize {
        usize::from(channel < 2)
    }

    fn fault_channel(&mut self, channel: usize) -> &mut [f64] {
        match channel {
            0 => std::slice::from_mut(&mut self.last.alpha_rad),
            1 => std::slice::from_mut(&mut self.last.beta_rad),
            _ => &mut [],
        }
    }

    fn has_validity(&self) -> bool {
        true
    }

    fn is_valid(&self) -> bool {
        self.last.flags & fss_flags::VALID != 0
    }

    /// Clears the `VALID` flag (the angles as measured).
    fn force_invalid(&mut self) {
        self.last.flags &= !fss_flags::VALID;
    }
}
