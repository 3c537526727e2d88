//! A three-axis magnetometer: the planet's magnetic field in the sensor's own frame S, with
//! scale-factor and misalignment errors, a bias, white noise, saturation and quantisation,
//! published as `MagnetometerMsg` on `flexdyn/<sc-id>/tlm/mag/<name>`.
//!
//! # Measurement model
//! The sensor is mounted with the fixed DCM \[SB\]. At each update, from the environment sample
//! (IGRF via [`flexdyn_environment`]; a zero field when no magnetic model is configured),
//!
//! ```text
//! B_B   = [BN] B_N (+ the spacecraft's own field at the sensor, see below)
//! y_S   = (I + diag(s) + M) [SB] B_B + b + σ z          z: three standard normals
//! ```
//!
//! with s the scale-factor errors (fractions), M the misalignment (zero diagonal, M_ij the small
//! angle by which sense axis i leans toward true axis j, the IMU's convention), b the constant
//! bias and σ the 1σ white noise per axis and sample. Then, per axis: saturation (y clipped to
//! ±`range_t`, setting that axis's [`flexdyn_proto::magnetometer_flags`] bit; 0 = unlimited),
//! then quantisation (y rounded to the nearest multiple of `lsb_t`; 0 = not quantised). With
//! every error term zero, y_S = \[SB\]\[BN\] B_N exactly (the same floating-point products).
//!
//! # The spacecraft's own field
//! Flight magnetometers also see the field of the spacecraft's magnetorquers (issue 20 §3). When
//! the sensor's position `r_sb_b_m` is configured, [`Magnetometer::truth_b_t`] (the one place
//! that forms B_B) adds the field of every dipole a dynamic effector carries (each magnetorquer
//! rod, with the dipole it applies from now on) as a point dipole at the rod's centre:
//! B = (μ0/4π) [3 (m·r̂) r̂ − m] / r³ with r from the rod to the sensor
//! ([`flexdyn_environment::magnetic::dipole_field_t`]). The point-dipole (far-field) form is
//! accurate a few rod lengths away; nearer, a real rod's field differs and the sensor should be
//! placed farther (as flight magnetometers are, often on a boom). A 100 A·m² rod 1 m away adds
//! up to 20 µT, comparable to the Earth's field in LEO: B-dot laws either stop the rods while
//! the magnetometer samples or subtract a calibrated model. Without `r_sb_b_m` the sensor sees
//! the Earth's field alone. The residual dipole of `[environment]` has no position and is not
//! added.
//!
//! # Timing and random numbers
//! The magnetometer updates every `frame_hz / rate_hz` frames (a whole number), at the frame
//! boundaries whose tick is a multiple of it, starting at tick 0. Its normals come from the
//! sensors' portable ChaCha8 + Marsaglia-polar generator ([`super::rng`]) seeded with `seed`,
//! four per update (z₁, z₂, z₃, then one discarded to keep the pairs aligned), drawn whether or
//! not σ is zero, so a seed reproduces the stream bit for bit on every platform.

use nalgebra::{Matrix3, Vector3};

use crate::{Sensor, SensorKind, Truth};
use flexdyn_environment::magnetic::dipole_field_t;
use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_kernel::validate::{check_dcm, check_finite, check_sensor_term, ParamError};
use flexdyn_proto::{encode_into, magnetometer_flags, Header, MagnetometerMsg};

use super::rng::NormalRng;

mod kind;
pub(crate) mod plausibility;
pub(crate) mod schema;

pub use kind::KIND;

/// A magnetometer's configuration (`[[magnetometers]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct MagnetometerConfig {
    /// Name: the last chunk of its topic key.
    pub name: String,
    /// Mounting DCM \[SB\]: maps B components to sensor-frame S components.
    pub dcm_sb: Matrix3<f64>,
    /// \[–\] scale-factor error per axis, a fraction.
    pub scale_factor: Vector3<f64>,
    /// \[rad\] misalignment M (zero diagonal).
    pub misalignment_rad: Matrix3<f64>,
    /// \[T\] constant bias, S components.
    pub bias_s_t: Vector3<f64>,
    /// \[T\] 1σ white noise per axis and sample.
    pub noise_sigma_t: f64,
    /// \[T\] per-axis range; 0 = unlimited.
    pub range_t: f64,
    /// \[T\] output LSB; 0 = not quantised.
    pub lsb_t: f64,
    /// Updates every this many frames (from `rate_hz`; ≥ 1).
    pub every_frames: u64,
    /// \[m\] the sensor's position relative to B, B components; when given, the field of the
    /// spacecraft's magnetorquer dipoles at this point adds to the Earth's (module docs).
    pub r_sb_b_m: Option<Vector3<f64>>,
    /// RNG seed (0 ≤ seed ≤ 2⁶³ − 1 in the configuration).
    pub seed: u64,
}

impl MagnetometerConfig {
    /// Validates the values (`path` is e.g. `magnetometers[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_dcm(path, "dcm_sb", &self.dcm_sb)?;
        check_finite(path, "scale_factor", self.scale_factor.as_slice())?;
        check_finite(path, "misalignment_rad", self.misalignment_rad.as_slice())?;
        check_sensor_term(path, "bias_s_t", self.bias_s_t.as_slice(), false)?;
        if let Some(r) = &self.r_sb_b_m {
            check_finite(path, "r_sb_b_m", r.as_slice())?;
        }
        check_sensor_term(path, "noise_sigma_t", &[self.noise_sigma_t], true)?;
        check_sensor_term(path, "range_t", &[self.range_t], true)?;
        check_sensor_term(path, "lsb_t", &[self.lsb_t], true)
    }
}

/// One magnetometer output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MagnetometerSample {
    /// \[T\] measured field, S components.
    pub b_s_t: Vector3<f64>,
    /// Saturated axes ([`magnetometer_flags`]).
    pub saturation_flags: u8,
}

impl MagnetometerSample {
    /// The wire message with `header`.
    pub fn to_msg(&self, header: Header) -> MagnetometerMsg {
        MagnetometerMsg {
            header,
            b_s_t: self.b_s_t.into(),
            saturation_flags: self.saturation_flags,
        }
    }
}

/// A magnetometer with its noise generator and last output.
#[derive(Debug, Clone)]
pub struct Magnetometer {
    cfg: MagnetometerConfig,
    /// (I + diag(s) + M) [SB], formed once.
    gain_sb: Matrix3<f64>,
    rng: NormalRng,
    last: MagnetometerSample,
}

impl Magnetometer {
    /// A magnetometer from a configuration, validated (errors name `path.<field>`).
    pub fn new(cfg: MagnetometerConfig, path: &str) -> Result<Self, ParamError> {
        cfg.validate(path)?;
        let g =
            Matrix3::identity() + Matrix3::from_diagonal(&cfg.scale_factor) + cfg.misalignment_rad;
        // With no scale or misalignment error G = I exactly; skip the product so that the
        // zero-error output is [SB] B_B with no extra rounding.
        let gain_sb = if g == Matrix3::identity() {
            cfg.dcm_sb
        } else {
            g * cfg.dcm_sb
        };
        Ok(Self {
            rng: NormalRng::new(cfg.seed),
            gain_sb,
            last: MagnetometerSample {
                b_s_t: Vector3::zeros(),
                saturation_flags: 0,
            },
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &MagnetometerConfig {
        &self.cfg
    }

    /// The last output (zero before the first).
    pub fn last(&self) -> MagnetometerSample {
        self.last
    }

    /// The field at the sensor, B components: \[BN\] B_N from the environment sample (zero
    /// without one), plus, when the sensor's position is configured, the field of every
    /// magnetic dipole the spacecraft's dynamic effectors carry (module docs).
    pub fn truth_b_t(&self, truth: &Truth<'_>) -> Vector3<f64> {
        let mut b_b_t = match truth.env {
            Some(env) => mrp_to_dcm(&truth.state.sigma_bn) * env.b_field_n_t,
            None => Vector3::zeros(),
        };
        if let Some(r_sb_b_m) = &self.cfg.r_sb_b_m {
            for (r_mb_b_m, m_b_am2) in truth
                .dynamic_effectors
                .iter()
                .filter_map(|e| e.magnetic_dipole_b())
            {
                b_b_t += dipole_field_t(&m_b_am2, &(r_sb_b_m - r_mb_b_m));
            }
        }
        b_b_t
    }

    /// One measurement of the field `b_b_t` (B components) by the model of the module docs.
    pub fn measure(&mut self, b_b_t: &Vector3<f64>) -> MagnetometerSample {
        let [(z1, z2), (z3, _)] = self.rng.normal_pairs::<2>();
        let c = &self.cfg;
        let mut y = self.gain_sb * b_b_t + c.bias_s_t + Vector3::new(z1, z2, z3) * c.noise_sigma_t;
        let mut flags = 0;
        for (i, bit) in [
            magnetometer_flags::AXIS_1,
            magnetometer_flags::AXIS_2,
            magnetometer_flags::AXIS_3,
        ]
        .into_iter()
        .enumerate()
        {
            if c.range_t > 0.0 && y[i].abs() > c.range_t {
                y[i] = c.range_t.copysign(y[i]);
                flags |= bit;
            }
            if c.lsb_t > 0.0 {
                y[i] = (y[i] / c.lsb_t).round() * c.lsb_t;
            }
        }
        MagnetometerSample {
            b_s_t: y,
            saturation_flags: flags,
        }
    }
}

impl Sensor for Magnetometer {
    fn kind(&self) -> &'static SensorKind {
        &KIND
    }

    fn name(&self) -> &str {
        &self.cfg.name
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        let c = &self.cfg;
        for i in 0..3 {
            out.push((format!("scale_factor[{i}]"), c.scale_factor[i]));
            out.push((format!("bias_s_t[{i}]"), c.bias_s_t[i]));
            for j in 0..3 {
                out.push((
                    format!("misalignment_rad[{i}][{j}]"),
                    c.misalignment_rad[(i, j)],
                ));
            }
        }
        out.push(("noise_sigma_t".into(), c.noise_sigma_t));
        out.push(("range_t".into(), c.range_t));
        out.push(("lsb_t".into(), c.lsb_t));
    }

    fn due(&self, tick: u64) -> bool {
        tick.is_multiple_of(self.cfg.every_frames)
    }

    fn sample(&mut self, truth: &Truth<'_>) {
        let b_b_t = self.truth_b_t(truth);
        self.last = self.measure(&b_b_t);
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
        (!self.last.b_s_t.iter().all(|v| v.is_finite())).then_some("b_s_t")
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            cfg: _,
            gain_sb: _,
            rng,
            last:
                MagnetometerSample {
                    b_s_t,
                    saturation_flags,
                },
        } = self;
        a.put(rng);
        a.put(b_s_t);
        a.put(saturation_flags);
    }

    /// `field` (B in S, T).
    fn fault_channels(&self) -> &'static [&'static str] {
        &["field"]
    }

    fn fault_axes(&self, channel: usize) -> usize {
        if channel == 0 {
            3
        } else {
            0
        }
    }

    fn fault_channel(&mut self, channel: usize) -> &mut [f64] {
        match channel {
            0 => self.last.b_s_t.as_mut_slice(),
            _ => &mut [],
        }
    }
}
