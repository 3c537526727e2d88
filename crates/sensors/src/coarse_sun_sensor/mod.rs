//! A coarse-sun-sensor array: K cosine detectors (K ≤ 16) fixed in the body, sampled together
//! and published as one `CssMsg` on `flexdyn/<sc-id>/tlm/css/<name>`.
//!
//! # Measurement model
//! Each detector k is a flat photodiode or solar cell with outward unit normal n̂ₖ (B
//! components). Its short-circuit current is proportional to the projected area it shows the
//! Sun, the cosine law (Wertz, *Spacecraft Attitude Determination and Control*, 1978, §6.1,
//! "analog sun sensors": I(θ) = I(0) cos θ). With ŝ_B the unit Sun direction from the
//! environment sample and ν its shadow factor (1 sunlit, 0 umbra, between in penumbra):
//!
//! ```text
//! (C1) ŝ_B  = [BN] (r_sun / |r_sun|)               r_sun: Sun from point B, N components
//! (C2) cₖ   = n̂ₖ · ŝ_B                               cos θₖ
//! (C3) dₖ   = scale · cₖ · ν   if cₖ > 0 and cₖ ≥ cos(fov_half_angle_rad), else 0
//! (C4) αₖ   = Σᵢ wᵢ max(0, n̂ₖ,N · ûᵢ)  over the cap's elements i with n̂ₖ,N · ûᵢ ≥ cos(fov)
//! (C5) tₖ   = dₖ + scale · αₖ           (albedo off: tₖ = dₖ, the same bits as before it)
//! (C6) yₖ   = max(0, tₖ + bias + σ zₖ), then rounded to a multiple of lsb (if lsb > 0)
//! ```
//!
//! `scale` is the output at normal incidence in full sunlight, in the array's own output unit
//! (a normalised 1, or e.g. milliamperes); bias, σ and lsb are in the same unit. The clip at 0
//! is physical (a photocurrent is not negative) and is applied before quantisation. With every
//! error term and albedo off, yₖ = scale · (n̂ₖ · ŝ_B) · ν exactly (the same floating-point
//! products).
//!
//! # Earth albedo
//! With `[environment] albedo = "lambertian"` the environment sample carries the Earth's
//! visible cap ([`flexdyn_environment::albedo`]): 128 directions ûᵢ from B (N components) with
//! weights wᵢ = (a/π) max(0, n̂_P·ŝ) ΔΩᵢ, the albedo irradiance per unit solar irradiance S (its
//! (A6)). αₖ (C4) is then the albedo irradiance on detector k divided by S, the same
//! normalisation as the direct term's cₖ ν (the direct irradiance over S), so in the output
//! unit albedo adds scale · αₖ (C5): a detector facing the nadir under a fully lit cap at 500 km
//! reads about 0.26 scale with a = 0.3. The field of view applies per element direction: an
//! element outside the detector's cone adds nothing. n̂ₖ,N = \[BN\]ᵀ n̂ₖ is formed once per
//! detector and sample; (C4) is 2 multiply-adds per element and allocates nothing. Albedo is
//! not scaled by the spacecraft's shadow factor ν: it is light from the lit Earth, and a
//! detector facing it reads it in penumbra at its full value (in the umbra of a spherical Earth
//! no lit ground is in view, so αₖ is 0 there by geometry). Off (the default), the sample has
//! no cap and tₖ = dₖ bit for bit.
//!
//! # Neglected
//! - The albedo model's own simplifications (a uniform coefficient, a Lambertian sphere, no
//!   atmosphere): [`flexdyn_environment::albedo`], "Neglected". Its 8 × 16 grid is within 1.2 %
//!   of the exact cap integral at 500 km (within 0.3 % on detectors tilted up to 45° from the
//!   nadir).
//! - The Sun's distance: the irradiance's ±3.3 % annual variation (1/r²) is not applied; the
//!   reading at normal incidence is always `scale`.
//! - The detector's departure from the cosine law near grazing incidence (Fresnel reflection of
//!   the cover glass), temperature effects and per-detector scale errors.
//!
//! Without a Sun (no environment sample, or no ephemeris: `[environment] sun = true` is off, a zero Sun
//! vector) every tₖ is 0, as a magnetometer without a field model reads zero field.
//!
//! # Timing and random numbers
//! The array updates every `frame_hz / rate_hz` frames, at the frame boundaries whose tick is a
//! multiple of it, starting at tick 0. Its normals come from the sensors' portable ChaCha8 +
//! Marsaglia-polar generator ([`super::rng`]) seeded with `seed`, ⌈K/2⌉ pairs per update (z₀, z₁
//! from the first pair, …; the second of the last pair is discarded when K is odd), drawn
//! whether or not σ is zero, so a seed reproduces the stream bit for bit.

use nalgebra::{Matrix3, Vector3};

use crate::{Sensor, SensorKind, Truth};
use flexdyn_environment::albedo::AlbedoCap;
use flexdyn_kernel::validate::{check_finite, check_sensor_term, check_unit_axis, ParamError};
use flexdyn_proto::{encode_into, CssMsg, Header, MAX_CSS_DETECTORS};

use super::rng::NormalRng;

mod kind;
pub(crate) mod schema;

pub use kind::KIND;

/// A coarse-sun-sensor array's configuration (`[[coarse_sun_sensors]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct CoarseSunSensorConfig {
    /// Name: the last chunk of its topic key.
    pub name: String,
    /// Each detector's outward unit normal, B components (1..=16 detectors).
    pub normals_b: Vec<Vector3<f64>>,
    /// \[rad\] field-of-view half-angle from the normal, in (0, π/2]; a detector reads 0 beyond.
    pub fov_half_angle_rad: f64,
    /// Output at normal incidence in full sunlight (the array's output unit; > 0).
    pub scale: f64,
    /// Constant offset added to every detector (output unit).
    pub bias: f64,
    /// 1σ white noise per detector and sample (output unit).
    pub noise_sigma: f64,
    /// Output LSB; 0 = not quantised.
    pub lsb: f64,
    /// Updates every this many frames (from `rate_hz`; ≥ 1).
    pub every_frames: u64,
    /// RNG seed (0 ≤ seed ≤ 2⁶³ − 1 in the configuration).
    pub seed: u64,
}

impl CoarseSunSensorConfig {
    /// Validates the values (`path` is e.g. `coarse_sun_sensors[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        let k = self.normals_b.len();
        if k == 0 || k > MAX_CSS_DETECTORS {
            return Err(ParamError::Invalid {
                field: format!("{path}.normals_b"),
                problem: format!(
                    "an array has 1 to {MAX_CSS_DETECTORS} detectors (one CssMsg carries at \
                     most {MAX_CSS_DETECTORS}), got {k}"
                ),
            });
        }
        for (i, n) in self.normals_b.iter().enumerate() {
            check_unit_axis(path, &format!("normals_b[{i}]"), n)?;
        }
        check_finite(path, "fov_half_angle_rad", &[self.fov_half_angle_rad])?;
        if !(self.fov_half_angle_rad > 0.0
            && self.fov_half_angle_rad <= std::f64::consts::FRAC_PI_2)
        {
            return Err(ParamError::Invalid {
                field: format!("{path}.fov_half_angle_rad"),
                problem: format!(
                    "must be in (0, π/2] rad (a cosine detector sees nothing beyond 90°), got {}",
                    self.fov_half_angle_rad
                ),
            });
        }
        flexdyn_kernel::validate::check_positive(path, "scale", self.scale)?;
        check_sensor_term(path, "scale", &[self.scale], true)?;
        check_sensor_term(path, "bias", &[self.bias], false)?;
        check_sensor_term(path, "noise_sigma", &[self.noise_sigma], true)?;
        check_sensor_term(path, "lsb", &[self.lsb], true)
    }
}

/// One array output: K readings in configuration order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoarseSunSensorSample {
    /// The number of detectors K.
    pub detector_count: u8,
    /// Detector k's reading (output unit) for k < K; 0 beyond.
    pub readings: [f64; MAX_CSS_DETECTORS],
}

impl CoarseSunSensorSample {
    /// The first K readings.
    pub fn detectors(&self) -> &[f64] {
        &self.readings[..usize::from(self.detector_count)]
    }

    /// The wire message with `header`.
    pub fn to_msg(&self, header: Header) -> CssMsg {
        CssMsg {
            header,
            detector_count: self.detector_count,
            readings: self.readings,
        }
    }
}

/// A coarse-sun-sensor array with its noise generator and last output.
#[derive(Debug, Clone)]
pub struct CoarseSunSensor {
    cfg: CoarseSunSensorConfig,
    /// cos(fov_half_angle_rad), formed once.
    cos_fov: f64,
    rng: NormalRng,
    last: CoarseSunSensorSample,
}

impl CoarseSunSensor {
    /// An array from a configuration, validated (errors name `path.<field>`).
    pub fn new(cfg: CoarseSunSensorConfig, path: &str) -> Result<Self, ParamError> {
        cfg.validate(path)?;
        Ok(Self {
            rng: NormalRng::new(cfg.seed),
            cos_fov: cfg.fov_half_angle_rad.cos(),
            last: CoarseSunSensorSample {
                detector_count: cfg.normals_b.len() as u8,
                readings: [0.0; MAX_CSS_DETECTORS],
            },
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &CoarseSunSensorConfig {
        &self.cfg
    }

    /// The last output (zeros before the first).
    pub fn last(&self) -> CoarseSunSensorSample {
        self.last
    }

    /// One measurement by the model of the module docs without albedo: `sun` is the unit Sun
    /// direction in B and the shadow factor, or `None` for no Sun.
    pub fn measure(&mut self, sun: Option<(Vector3<f64>, f64)>) -> CoarseSunSensorSample {
        self.measure_with_albedo(sun, None)
    }

    /// One measurement by the model of the module docs: `sun` as for [`Self::measure`];
    /// `albedo` the environment sample's cap and the attitude `[NB]` (B → N) that turns the
    /// detectors' normals into the cap's frame, or `None` for no albedo. Allocation-free.
    pub fn measure_with_albedo(
        &mut self,
        sun: Option<(Vector3<f64>, f64)>,
        albedo: Option<(&AlbedoCap, &Matrix3<f64>)>,
    ) -> CoarseSunSensorSample {
        let c = &self.cfg;
        let mut out = CoarseSunSensorSample {
            detector_count: self.last.detector_count,
            readings: [0.0; MAX_CSS_DETECTORS],
        };
        let mut z = (0.0, 0.0);
        for (k, n) in c.normals_b.iter().enumerate() {
            if k % 2 == 0 {
                z = self.rng.normal_pair();
            }
            let zk = if k % 2 == 0 { z.0 } else { z.1 };
            // (C3)
            let direct = match sun {
                Some((s_b, shadow)) => {
                    let cos = n.dot(&s_b);
                    if cos > 0.0 && cos >= self.cos_fov {
                        c.scale * cos * shadow
                    } else {
                        0.0
                    }
                }
                None => 0.0,
            };
            // (C4), (C5)
            let truth = match albedo {
                Some((cap, dcm_nb)) => {
                    direct + c.scale * cap.irradiance_fraction(&(dcm_nb * n), self.cos_fov)
                }
                None => direct,
            };
            let mut y = (truth + c.bias + c.noise_sigma * zk).max(0.0);
            if c.lsb > 0.0 {
                y = (y / c.lsb).round() * c.lsb;
            }
            out.readings[k] = y;
        }
        out
    }
}

impl Sensor for CoarseSunSensor {
    fn kind(&self) -> &'static SensorKind {
        &KIND
    }

    fn name(&self) -> &str {
        &self.cfg.name
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        let c = &self.cfg;
        out.push(("fov_half_angle_rad".into(), c.fov_half_angle_rad));
        out.push(("scale".into(), c.scale));
        out.push(("bias".into(), c.bias));
        out.push(("noise_sigma".into(), c.noise_sigma));
        out.push(("lsb".into(), c.lsb));
    }

    fn due(&self, tick: u64) -> bool {
        tick.is_multiple_of(self.cfg.every_frames)
    }

    fn sample(&mut self, truth: &Truth<'_>) {
        let cap = truth.env.and_then(|e| e.albedo.as_ref());
        let dcm_nb =
            cap.map(|_| flexdyn_kernel::attitude::mrp_to_dcm(&truth.state.sigma_bn).transpose());
        let albedo = cap.zip(dcm_nb.as_ref());
        self.last = self.measure_with_albedo(truth.sun_b(), albedo);
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
        (!self.last.readings.iter().all(|v| v.is_finite())).then_some("readings")
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
                CoarseSunSensorSample {
                    // The configuration's (the number of normals), not state.
                    detector_count: _,
                    readings,
                },
        } = self;
        a.put(rng);
        a.put(readings);
    }

    /// `readings` (one axis per detector, in the output unit).
    fn fault_channels(&self) -> &'static [&'static str] {
        &["readings"]
    }

    fn fault_axes(&self, channel: usize) -> usize {
        if channel == 0 {
            usize::from(self.last.detector_count)
        } else {
            0
        }
    }

    fn fault_channel(&mut self, channel: usize) -> &mut [f64] {
        let k = usize::from(self.last.detector_count);
        match channel {
            0 => &mut self.last.readings[..k],
            _ => &mut [],
        }
    }
}
