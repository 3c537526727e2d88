//! A star tracker: the attitude of its case frame C relative to N, with noise, a bias and
//! validity conditions, published as `StarTrackerMsg` on `flexdyn/<sc-id>/tlm/st/<name>`.
//!
//! # Measurement model
//! The tracker is mounted with the fixed DCM \[CB\]; its boresight b̂ is a unit vector in C
//! (default +ẑ_C). At each update the true attitude is \[CN\] = \[CB\]\[BN\], and the measurement is
//!
//! [C̃N] = R(δθ) \[CN\],  δθ = β + σ_x n₁ ê₁ + σ_x n₂ ê₂ + σ_b n₃ b̂   (C components),
//!
//! where (ê₁, ê₂, b̂) is a right-handed orthonormal triad in C (ê₁ is the unit vector of b̂ × x̂_C,
//! or of b̂ × ŷ_C when b̂ ∥ x̂_C), n₁…n₃ are independent standard normals, σ_x is the
//! cross-boresight and σ_b the about-boresight noise (1σ, rad), β the constant bias (a small
//! rotation vector in C, rad), and R(δθ) the frame rotation by the rotation vector δθ, built
//! exactly through its MRP tan(|δθ|/4) δθ/|δθ|. The reported quaternion is that of [C̃N], scalar
//! first with q₀ ≥ 0. Star trackers are typically specified in arcseconds: 1″ = 4.8481e-6 rad.
//!
//! # Validity
//! A measurement is invalid (`valid = false`, the quaternion held at the last valid one, the
//! identity before the first) when
//! - the boresight in N, \[NC\] b̂, is within `sun_exclusion_rad` of the Sun direction (flag
//!   `SUN_EXCLUSION`): the configured `sun_direction_n`, or with `sun_from_environment = true`
//!   the direction of the environment sample's r_Sun/B at the update (no exclusion while the
//!   sample has no Sun), or
//! - |ω_B/N| exceeds `max_rate_rad_s` (flag `RATE_LIMIT`; the tracker cannot match smeared star
//!   images), or
//! - the boresight is within `earth_exclusion_rad` of the Earth's limb (flag `EARTH_EXCLUSION`),
//!   or within `moon_exclusion_rad` of the Moon's limb (flag `MOON_EXCLUSION`; the Moon of the
//!   environment sample, no exclusion while it has none).
//!
//! # Body exclusion (Earth, Moon)
//! A body of radius R whose centre is at d from point B (d = ‖r‖, r its position relative to B)
//! fills a disc of angular radius ρ = asin(R / d) about the direction r̂ (the Earth's angular
//! radius sin ρ = R_E / (R_E + H): Wertz and Larson, *Space Mission Analysis and Design*, 3rd
//! ed., 1999, §5.1, eq. 5-1).
//! The boresight's angle to the disc's edge, the limb, is
//!
//! η = acos(b̂_N · r̂) − ρ,
//!
//! negative while the boresight points into the disc. The tracker is excluded when η is below
//! the exclusion half-angle, and always when B is inside the body's sphere (d ≤ R). For the
//! Earth, r = −r_B/N (N is centred on the Earth) and R = `earth_radius_m` +
//! `earth_atmosphere_m`: the bright limb includes the lit atmosphere, whose height the user sets
//! (0 by default: the solid Earth). For the Moon, r = r_Moon/B of the environment sample and
//! R = 1737.4 km, the IAU mean radius (Archinal et al., *Celest. Mech. Dyn. Astr.* 130:22, 2018,
//! Table 5). An exclusion of 0 switches the check off, so a configuration without these keys
//! gives the streams it gave before.
//!
//! All use the true attitude, rate and position at the sample. The noise is drawn at every update, valid or
//! not, so the noise stream does not depend on the validity history.
//!
//! # Timing and random numbers
//! The tracker updates every `frame_hz / rate_hz` frames (a whole number), at the frame
//! boundaries whose tick is a multiple of it, starting at tick 0. Its normals come from the same
//! portable ChaCha8 + Marsaglia-polar generator as the IMU's, seeded with `seed`, three per update
//! (n₁, n₂, n₃, then one discarded to keep the pairs aligned), so a seed reproduces the stream
//! bit for bit on every platform.

use nalgebra::{Matrix3, Vector3, Vector4};

use crate::{Sensor, SensorKind, Truth};
use flexdyn_kernel::attitude::{dcm_to_quat, mrp_to_dcm};
use flexdyn_kernel::validate::{
    check_dcm, check_finite, check_non_negative, check_positive, check_sensor_term, join,
    ParamError,
};
use flexdyn_proto::{encode_into, star_tracker_flags, Header, StarTrackerMsg};

use super::rng::NormalRng;

mod kind;
pub(crate) mod plausibility;
pub(crate) mod schema;

pub use kind::KIND;

/// Tolerance on |‖v‖ − 1| for the boresight and the Sun direction.
pub const UNIT_TOL: f64 = 1e-6;

/// \[m\] the Moon's mean radius (IAU WG on Cartographic Coordinates and Rotational Elements,
/// Archinal et al. 2018, Table 5: 1737.4 km).
pub const MOON_RADIUS_M: f64 = 1_737_400.0;

/// A star tracker's configuration (`[[star_trackers]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct StarTrackerConfig {
    /// Name: the last chunk of its topic key.
    pub name: String,
    /// Mounting DCM \[CB\]: maps B components to case-frame C components.
    pub dcm_cb: Matrix3<f64>,
    /// Boresight b̂ in C components (unit).
    pub boresight_c: Vector3<f64>,
    /// \[rad\] 1σ noise about each cross-boresight axis.
    pub sigma_cross_boresight_rad: f64,
    /// \[rad\] 1σ noise about the boresight.
    pub sigma_about_boresight_rad: f64,
    /// \[rad\] constant bias, a small rotation vector in C components.
    pub bias_c_rad: Vector3<f64>,
    /// Updates every this many frames (from `rate_hz`; ≥ 1).
    pub every_frames: u64,
    /// RNG seed (0 ≤ seed ≤ 2⁶³ − 1 in the configuration).
    pub seed: u64,
    /// Unit Sun direction in N (used unless [`Self::sun_from_environment`]).
    pub sun_direction_n: Vector3<f64>,
    /// Whether the Sun exclusion takes the Sun's direction from the environment sample at
    /// each update (`sun_from_environment = true`: the ephemeris or the configured fixed Sun,
    /// seen from B) instead of [`Self::sun_direction_n`].
    pub sun_from_environment: bool,
    /// \[rad\] Sun exclusion half-angle about the boresight (0: no exclusion).
    pub sun_exclusion_rad: f64,
    /// [rad/s] largest |ω_B/N| at which the tracker still reports (∞: no limit).
    pub max_rate_rad_s: f64,
    /// \[rad\] exclusion half-angle about the Earth's limb (0: no Earth exclusion).
    pub earth_exclusion_rad: f64,
    /// \[m\] the Earth's radius for the limb (default WGS-84 a, 6378137 m).
    pub earth_radius_m: f64,
    /// \[m\] height of the bright atmosphere above `earth_radius_m`, counted as the Earth's disc.
    pub earth_atmosphere_m: f64,
    /// \[rad\] exclusion half-angle about the Moon's limb (0: no Moon exclusion).
    pub moon_exclusion_rad: f64,
}

impl StarTrackerConfig {
    /// Validates the values (`path` is e.g. `star_trackers[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_dcm(path, "dcm_cb", &self.dcm_cb)?;
        for (field, v) in [
            ("boresight_c", &self.boresight_c),
            ("sun_direction_n", &self.sun_direction_n),
        ] {
            check_finite(path, field, v.as_slice())?;
            if (v.norm() - 1.0).abs() > UNIT_TOL {
                return Err(ParamError::NotUnit {
                    field: join(path, field),
                    norm: v.norm(),
                });
            }
        }
        check_sensor_term(
            path,
            "sigma_cross_boresight_rad",
            &[self.sigma_cross_boresight_rad],
            true,
        )?;
        check_sensor_term(
            path,
            "sigma_about_boresight_rad",
            &[self.sigma_about_boresight_rad],
            true,
        )?;
        check_sensor_term(path, "bias_c_rad", self.bias_c_rad.as_slice(), false)?;
        check_non_negative(path, "sun_exclusion_rad", self.sun_exclusion_rad)?;
        check_non_negative(path, "earth_exclusion_rad", self.earth_exclusion_rad)?;
        check_positive(path, "earth_radius_m", self.earth_radius_m)?;
        check_non_negative(path, "earth_atmosphere_m", self.earth_atmosphere_m)?;
        check_non_negative(path, "moon_exclusion_rad", self.moon_exclusion_rad)?;
        if self.max_rate_rad_s.is_nan() {
            return Err(ParamError::NotFinite {
                field: join(path, "max_rate_rad_s"),
            });
        }
        check_positive(path, "max_rate_rad_s", self.max_rate_rad_s.min(f64::MAX))
    }
}

/// One star-tracker output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StarTrackerSample {
    /// Measured q_CN, scalar first, q₀ ≥ 0 (held while invalid).
    pub q_cn: Vector4<f64>,
    /// Whether `q_cn` is a fresh measurement.
    pub valid: bool,
    /// Why not (`flexdyn_proto::star_tracker_flags`), 0 when valid.
    pub status_flags: u8,
}

impl StarTrackerSample {
    /// The wire message with `header`.
    pub fn to_msg(&self, header: Header) -> StarTrackerMsg {
        StarTrackerMsg {
            header,
            q_cn: self.q_cn.into(),
            valid: self.valid,
            status_flags: self.status_flags,
        }
    }

    /// The first non-finite component's name, if any.
    pub fn first_non_finite(&self) -> Option<&'static str> {
        (!self.q_cn.iter().all(|v| v.is_finite())).then_some("q_cn")
    }
}

/// A star tracker with its noise generator and held output.
#[derive(Debug, Clone)]
pub struct StarTracker {
    cfg: StarTrackerConfig,
    /// ê₁, ê₂ of the module docs (C components).
    e1_c: Vector3<f64>,
    e2_c: Vector3<f64>,
    rng: NormalRng,
    held_q_cn: Vector4<f64>,
    /// The last update (invalid, the identity, before the first).
    last: StarTrackerSample,
}

impl StarTracker {
    /// A tracker from a validated configuration.
    pub fn new(cfg: StarTrackerConfig, path: &str) -> Result<Self, ParamError> {
        cfg.validate(path)?;
        let b = cfg.boresight_c;
        let helper = if b.cross(&Vector3::x()).norm() > 0.5 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let e1_c = b.cross(&helper).normalize();
        let e2_c = b.cross(&e1_c);
        Ok(Self {
            rng: NormalRng::new(cfg.seed),
            e1_c,
            e2_c,
            held_q_cn: Vector4::new(1.0, 0.0, 0.0, 0.0),
            last: StarTrackerSample {
                q_cn: Vector4::new(1.0, 0.0, 0.0, 0.0),
                valid: false,
                status_flags: 0,
            },
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &StarTrackerConfig {
        &self.cfg
    }

    /// The name.
    pub fn name(&self) -> &str {
        &self.cfg.name
    }

    /// Whether the tracker updates at frame boundary `tick`.
    pub fn due(&self, tick: u64) -> bool {
        tick.is_multiple_of(self.cfg.every_frames)
    }

    /// The last update (see [`Sensor::sample`]).
    pub fn last(&self) -> StarTrackerSample {
        self.last
    }

    /// The cross-boresight axes (ê₁, ê₂) in C, for tests that project errors on them.
    pub fn cross_axes_c(&self) -> (Vector3<f64>, Vector3<f64>) {
        (self.e1_c, self.e2_c)
    }

    /// One update at the true attitude `sigma_bn` and rate `omega_bn_b`, with the configured
    /// Sun direction (allocates nothing).
    pub fn sample(
        &mut self,
        sigma_bn: &Vector3<f64>,
        omega_bn_b: &Vector3<f64>,
    ) -> StarTrackerSample {
        let sun_n = self.cfg.sun_direction_n;
        self.sample_with_sun(sigma_bn, omega_bn_b, Some(&sun_n))
    }

    /// One update with the unit Sun direction `sun_n` in N for the exclusion (`None`: no Sun,
    /// no exclusion), and no Earth or Moon. Allocates nothing.
    pub fn sample_with_sun(
        &mut self,
        sigma_bn: &Vector3<f64>,
        omega_bn_b: &Vector3<f64>,
        sun_n: Option<&Vector3<f64>>,
    ) -> StarTrackerSample {
        self.sample_in_sky(
            sigma_bn,
            omega_bn_b,
            &Sky {
                sun_n: sun_n.copied(),
                ..Sky::default()
            },
        )
    }

    /// One update at the true attitude and rate with the bodies of `sky` (module docs,
    /// "Validity" and "Body exclusion"). Allocates nothing.
    pub fn sample_in_sky(
        &mut self,
        sigma_bn: &Vector3<f64>,
        omega_bn_b: &Vector3<f64>,
        sky: &Sky,
    ) -> StarTrackerSample {
        let [(n1, n2), (n3, _)] = self.rng.normal_pairs::<2>();
        let c = &self.cfg;
        let dcm_cn = c.dcm_cb * mrp_to_dcm(sigma_bn);
        let mut flags = 0;
        let boresight_n = dcm_cn.transpose() * c.boresight_c;
        if let Some(sun_n) = sky.sun_n.filter(|_| c.sun_exclusion_rad > 0.0) {
            if boresight_n.dot(&sun_n).clamp(-1.0, 1.0).acos() < c.sun_exclusion_rad {
                flags |= star_tracker_flags::SUN_EXCLUSION;
            }
        }
        if let Some(r_bn_n) = sky.r_bn_n.filter(|_| c.earth_exclusion_rad > 0.0) {
            let radius = c.earth_radius_m + c.earth_atmosphere_m;
            if limb_angle_rad(&boresight_n, &-r_bn_n, radius) < c.earth_exclusion_rad {
                flags |= star_tracker_flags::EARTH_EXCLUSION;
            }
        }
        if let Some(r_moon_b_n) = sky.r_moon_b_n.filter(|_| c.moon_exclusion_rad > 0.0) {
            if limb_angle_rad(&boresight_n, &r_moon_b_n, MOON_RADIUS_M) < c.moon_exclusion_rad {
                flags |= star_tracker_flags::MOON_EXCLUSION;
            }
        }
        if omega_bn_b.norm() > c.max_rate_rad_s {
            flags |= star_tracker_flags::RATE_LIMIT;
        }
        if flags != 0 {
            return StarTrackerSample {
                q_cn: self.held_q_cn,
                valid: false,
                status_flags: flags,
            };
        }
        let dtheta_c = c.bias_c_rad
            + self.e1_c * (c.sigma_cross_boresight_rad * n1)
            + self.e2_c * (c.sigma_cross_boresight_rad * n2)
            + c.boresight_c * (c.sigma_about_boresight_rad * n3);
        let q = dcm_to_quat(&(rotation(&dtheta_c) * dcm_cn));
        let q = if q[0] < 0.0 { -q } else { q };
        self.held_q_cn = q;
        StarTrackerSample {
            q_cn: q,
            valid: true,
            status_flags: 0,
        }
    }
}

impl Sensor for StarTracker {
    fn kind(&self) -> &'static SensorKind {
        &KIND
    }

    fn name(&self) -> &str {
        &self.cfg.name
    }

    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        let c = &self.cfg;
        out.push((
            "sigma_cross_boresight_rad".into(),
            c.sigma_cross_boresight_rad,
        ));
        out.push((
            "sigma_about_boresight_rad".into(),
            c.sigma_about_boresight_rad,
        ));
        for i in 0..3 {
            out.push((format!("bias_c_rad[{i}]"), c.bias_c_rad[i]));
        }
        out.push(("sun_exclusion_rad".into(), c.sun_exclusion_rad));
        out.push(("max_rate_rad_s".into(), c.max_rate_rad_s));
        out.push(("earth_exclusion_rad".into(), c.earth_exclusion_rad));
        out.push(("earth_radius_m".into(), c.earth_radius_m));
        out.push(("earth_atmosphere_m".into(), c.earth_atmosphere_m));
        out.push(("moon_exclusion_rad".into(), c.moon_exclusion_rad));
    }

    fn due(&self, tick: u64) -> bool {
        StarTracker::due(self, tick)
    }

    /// One update at the true attitude and rate ([`StarTracker::sample_in_sky`]), with the
    /// configured Sun direction or the environment's, the Earth at the origin of N and the
    /// environment's Moon.
    fn sample(&mut self, truth: &Truth<'_>) {
        let sun_n = if self.cfg.sun_from_environment {
            truth.sun_n()
        } else {
            Some(self.cfg.sun_direction_n)
        };
        let sky = Sky {
            sun_n,
            r_bn_n: Some(truth.state.r_bn_n),
            r_moon_b_n: truth.env.map(|e| e.r_moon_b_n_m).filter(|r| r.norm() > 0.0),
        };
        self.last =
            StarTracker::sample_in_sky(self, &truth.state.sigma_bn, &truth.state.omega_bn_b, &sky);
    }

    /// `seq` counts the tracker's updates: the frame's tick / `every_frames`.
    fn encode(&self, header: Header, buf: &mut Vec<u8>) {
        let header = Header {
            seq: header.tick / self.cfg.every_frames,
            ..header
        };
        encode_into(&self.last.to_msg(header), buf);
    }

    fn first_non_finite(&self) -> Option<&'static str> {
        self.last.first_non_finite()
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            cfg: _,
            e1_c: _,
            e2_c: _,
            rng,
            held_q_cn,
            last:
                StarTrackerSample {
                    q_cn,
                    valid,
                    status_flags,
                },
        } = self;
        a.put(rng);
        a.put(held_q_cn);
        a.put(q_cn);
        a.put(valid);
        a.put(status_flags);
    }

    /// `q` (q_CN, scalar first; a fault's transform is not renormalised).
    fn fault_channels(&self) -> &'static [&'static str] {
        &["q"]
    }

    fn fault_axes(&self, channel: usize) -> usize {
        if channel == 0 {
            4
        } else {
            0
        }
    }

    fn fault_channel(&mut self, channel: usize) -> &mut [f64] {
        match channel {
            0 => self.last.q_cn.as_mut_slice(),
            _ => &mut [],
        }
    }

    fn has_validity(&self) -> bool {
        true
    }

    fn is_valid(&self) -> bool {
        self.last.valid
    }

    /// `valid = false` (the quaternion and the status flags as measured).
    fn force_invalid(&mut self) {
        self.last.valid = false;
    }
}

/// Where the bodies a tracker must not look at are, at one update (N components).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sky {
    /// Unit direction from B to the Sun (`None`: no Sun, no Sun exclusion).
    pub sun_n: Option<Vector3<f64>>,
    /// \[m\] position of B relative to the Earth's centre, the origin of N (`None`: no Earth
    /// exclusion).
    pub r_bn_n: Option<Vector3<f64>>,
    /// \[m\] position of the Moon's centre relative to B (`None`: no Moon exclusion).
    pub r_moon_b_n: Option<Vector3<f64>>,
}

/// \[rad\] the angle from the unit `boresight_n` to the limb of a sphere of `radius_m` whose
/// centre is at `r_n` from B: acos(b̂ · r̂) − asin(R / ‖r‖), negative inside the disc; −∞ when B
/// is inside the sphere (module docs, "Body exclusion").
pub fn limb_angle_rad(boresight_n: &Vector3<f64>, r_n: &Vector3<f64>, radius_m: f64) -> f64 {
    let d = r_n.norm();
    if d <= radius_m {
        return f64::NEG_INFINITY;
    }
    let to_centre = boresight_n.dot(r_n) / d;
    to_centre.clamp(-1.0, 1.0).acos() - (radius_m / d).asin()
}

/// The frame rotation [C̃C] by the rotation vector `theta` (through its MRP, exact).
fn rotation(theta: &Vector3<f64>) -> Matrix3<f64> {
    let angle = theta.norm();
    if angle == 0.0 {
        return Matrix3::identity();
    }
    mrp_to_dcm(&(theta * ((angle / 4.0).tan() / angle)))
}

/// The rotation vector of a proper DCM (the inverse of the frame rotation used for the noise),
/// for tests and tools that compare a measurement with the truth: [C̃C] = R(δθ) ⇒ δθ.
pub fn rotation_vector(dcm: &Matrix3<f64>) -> Vector3<f64> {
    let sigma = flexdyn_kernel::attitude::dcm_to_mrp(dcm);
    let s = sigma.norm();
    if s == 0.0 {
        return Vector3::zeros();
    }
    sigma * (4.0 * s.atan() / s)
}
