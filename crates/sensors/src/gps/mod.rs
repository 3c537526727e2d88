//! A GPS receiver: the hub point B's position and velocity in ECEF and/or the inertial frame N,
//! with a bias and white noise, the GPS week and seconds of week, a fix flag, a rate and a
//! latency; published as `GpsMsg` on `flexdyn/<sc-id>/tlm/gps/<name>`.
//!
//! # Measurement model
//! At a measurement instant t (simulation time, from the frame's truth) with an `[epoch]`:
//!
//! ```text
//! times  = epoch.times(t)                         GPS week, seconds of week (GPS = TAI − 19 s)
//! [EN]   = EarthOrientation::at(times, t)         the environment's own rotation (IERS 2010 or uniform)
//! r_E    = [EN] r_BN_N                            ECEF position of B
//! v_E    = [EN] (v_BN_N − ω_E/N × r_BN_N)         velocity relative to E (transport theorem)
//! δr_E   = b_r + σ_r z_r,  δv_E = b_v + σ_v z_v   the receiver's solution error, ECEF
//! ECEF:  r̃_E = r_E + δr_E,  ṽ_E = v_E + δv_E
//! N:     r̃_N = r_BN_N + [EN]ᵀ δr_E,
//!        ṽ_N = v_BN_N + [EN]ᵀ δv_E + ω_E/N × [EN]ᵀ δr_E
//! ```
//!
//! z_r, z_v are three standard normals each. The N output is the ECEF solution carried to N
//! (r_N = \[EN\]ᵀ r_E, v_N = \[EN\]ᵀ v_E + ω × r_N, linear in the error), written as truth plus
//! the rotated error so that with every error term zero each frame's output is its truth bit
//! for bit: N straight from the state, ECEF from [`EarthOrientation`]. The antenna is at B (no
//! lever arm) and the receiver clock is perfect.
//!
//! # Fix
//! There is no fix (flags without `FIX`, every number 0) without an `[epoch]` (no GPS time and
//! no Earth rotation), for measurements valid before `acquisition_s`, and within the optional
//! outage `outage_s = [start, end)`.
//!
//! # Timing, latency and random numbers
//! The receiver measures at the frame boundaries whose tick is a multiple of `every_frames`
//! (`frame_hz / rate_hz`), starting at tick 0, and publishes each measurement `latency_frames`
//! (`latency_s · frame_hz`, a whole number) frames later: the message published at t carries the
//! measurement valid at t − latency. Pending measurements wait in a ring buffer of
//! `latency_frames / every_frames + 1` samples, allocated when the sensor is built; measurement
//! k (tick k·every_frames) sits in slot k mod n and is read back at tick k·every_frames + latency
//! frames, before any later measurement can reuse the slot. The sensor is due at measurement and
//! at publication ticks; it has a message only at publication ticks ([`Sensor::has_output`]).
//! Its normals come from the sensors' portable ChaCha8 + Marsaglia-polar generator
//! ([`super::rng`]) seeded with `seed`: six per measurement (z_r then z_v), drawn whether or not
//! there is a fix, so a seed reproduces the stream bit for bit in lockstep and offline.
//!
//! # Faults
//! A `[[faults]]` entry on `gps_receivers.<name>` acts on the published message (the measurement
//! leaving the latency ring, `flexdyn_faults`): the value modes on the channels `position_e`,
//! `velocity_e`, `position_n`, `velocity_n` (3 axes each; only the configured frames, only with a
//! fix), `dropout`, and `validity_off`, which makes the message a no-fix one (`FIX` cleared,
//! every number 0).

use nalgebra::Vector3;

use crate::{Sensor, SensorKind, Truth};
use flexdyn_environment::earth_rotation::{EarthOrientation, EarthOrientationModel};
use flexdyn_environment::epoch::SimEpoch;
use flexdyn_kernel::validate::{check_sensor_term, ParamError};
use flexdyn_proto::{encode_into, gps_flags, GpsMsg, Header};

use super::rng::NormalRng;

mod kind;
pub(crate) mod schema;

pub use kind::KIND;

/// A GPS receiver's configuration (`[[gps_receivers]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct GpsConfig {
    /// Name: the last chunk of its topic key.
    pub name: String,
    /// Measures every this many frames (from `rate_hz`; ≥ 1).
    pub every_frames: u64,
    /// Publishes each measurement this many frames later (from `latency_s`; ≥ 0).
    pub latency_frames: u64,
    /// Outputs the ECEF fields.
    pub ecef: bool,
    /// Outputs the inertial (N) fields.
    pub inertial: bool,
    /// \[ns\] no fix for measurements valid before this time (time to first fix).
    pub acquisition_ns: u64,
    /// \[ns\] no fix for measurements valid in `[start, end)`.
    pub outage_ns: Option<(u64, u64)>,
    /// \[m\] 1σ white noise of each position component, per measurement.
    pub position_sigma_m: f64,
    /// \[m/s\] 1σ white noise of each velocity component, per measurement.
    pub velocity_sigma_m_s: f64,
    /// \[m\] constant position bias, ECEF components.
    pub position_bias_e_m: Vector3<f64>,
    /// \[m/s\] constant velocity bias, ECEF components.
    pub velocity_bias_e_m_s: Vector3<f64>,
    /// RNG seed (0 ≤ seed ≤ 2⁶³ − 1 in the configuration).
    pub seed: u64,
}

impl GpsConfig {
    /// Validates the values (`path` is e.g. `gps_receivers[0]`).
    pub fn validate(&self, path: &str) -> Result<(), ParamError> {
        check_sensor_term(path, "position_sigma_m", &[self.position_sigma_m], true)?;
        check_sensor_term(path, "velocity_sigma_m_s", &[self.velocity_sigma_m_s], true)?;
        check_sensor_term(
            path,
            "position_bias_e_m",
            self.position_bias_e_m.as_slice(),
            false,
        )?;
        check_sensor_term(
            path,
            "velocity_bias_e_m_s",
            self.velocity_bias_e_m_s.as_slice(),
            false,
        )
    }

    /// Whether a measurement valid at `t_ns` has a fix (given an epoch).
    fn fix_at(&self, t_ns: u64) -> bool {
        t_ns >= self.acquisition_ns
            && !self
                .outage_ns
                .is_some_and(|(start, end)| (start..end).contains(&t_ns))
    }

    /// The frame bits of the flags.
    fn frame_flags(&self) -> u8 {
        (if self.ecef { gps_flags::ECEF } else { 0 })
            | (if self.inertial {
                gps_flags::INERTIAL
            } else {
                0
            })
    }
}

/// One GPS measurement.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GpsSample {
    /// \[ns\] the simulation time it is valid at.
    pub valid_sim_time_ns: u64,
    /// GPS week (0 without a fix).
    pub gps_week: u32,
    /// \[s\] GPS seconds of week (0 without a fix).
    pub gps_seconds_of_week: f64,
    /// \[m\] measured position of B, ECEF.
    pub r_be_e_m: Vector3<f64>,
    /// \[m/s\] measured velocity of B relative to E, ECEF.
    pub v_be_e_m_s: Vector3<f64>,
    /// \[m\] measured position of B, N.
    pub r_bn_n_m: Vector3<f64>,
    /// \[m/s\] measured inertial velocity of B, N.
    pub v_bn_n_m_s: Vector3<f64>,
    /// [`gps_flags`].
    pub flags: u8,
}

impl GpsSample {
    /// The wire message with `header`.
    pub fn to_msg(&self, header: Header) -> GpsMsg {
        GpsMsg {
            header,
            valid_sim_time_ns: self.valid_sim_time_ns,
            gps_week: self.gps_week,
            gps_seconds_of_week: self.gps_seconds_of_week,
            r_be_e_m: self.r_be_e_m.into(),
            v_be_e_m_s: self.v_be_e_m_s.into(),
            r_bn_n_m: self.r_bn_n_m.into(),
            v_bn_n_m_s: self.v_bn_n_m_s.into(),
            flags: self.flags,
        }
    }

    /// Whether the sample has a fix.
    pub fn fix(&self) -> bool {
        self.flags & gps_flags::FIX != 0
    }
}

/// A GPS receiver with its noise generator, its latency ring and its last published sample.
#[derive(Debug, Clone)]
pub struct Gps {
    cfg: GpsConfig,
    /// The epoch and the Earth's rotation (`None` without an `[epoch]`: never a fix).
    world: Option<(SimEpoch, EarthOrientation)>,
    /// \[ns\] the frame period (ticks from simulation time).
    frame_ns: u64,
    /// Whether any error term is non-zero (otherwise the outputs are the truths exactly).
    has_errors: bool,
    rng: NormalRng,
    /// Measurements awaiting publication (module docs); never resized after build.
    ring: Vec<GpsSample>,
    last: GpsSample,
    published: bool,
}

impl Gps {
    /// A receiver from a configuration (validated, errors name `path.<field>`), for frames of
    /// `frame_ns`, the run's `epoch` and the environment's Earth orientation model `earth` (the
    /// same `[E N]` as the magnetic field and the atmosphere).
    pub fn new(
        cfg: GpsConfig,
        path: &str,
        frame_ns: u64,
        epoch: Option<&SimEpoch>,
        earth: EarthOrientationModel,
    ) -> Result<Self, ParamError> {
        cfg.validate(path)?;
        let has_errors = cfg.position_sigma_m != 0.0
            || cfg.velocity_sigma_m_s != 0.0
            || cfg.position_bias_e_m != Vector3::zeros()
            || cfg.velocity_bias_e_m_s != Vector3::zeros();
        let slots = (cfg.latency_frames / cfg.every_frames.max(1) + 1) as usize;
        Ok(Self {
            world: epoch.map(|e| {
                (
                    e.clone(),
                    EarthOrientation::new(earth, e.earth_orientation()),
                )
            }),
            frame_ns: frame_ns.max(1),
            has_errors,
            rng: NormalRng::new(cfg.seed),
            ring: vec![GpsSample::default(); slots],
            last: GpsSample::default(),
            published: false,
            cfg,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &GpsConfig {
        &self.cfg
    }

    /// The last published sample (zero before the first).
    pub fn last(&self) -> GpsSample {
        self.last
    }

    fn measures_at(&self, tick: u64) -> bool {
        tick.is_multiple_of(self.cfg.every_frames)
    }

    fn publishes_at(&self, tick: u64) -> bool {
        tick >= self.cfg.latency_frames
            && (tick - self.cfg.latency_frames).is_multiple_of(self.cfg.every_frames)
    }

    /// One measurement from `truth` by the model of the module docs. Allocation-free.
    pub fn measure(&mut self, truth: &Truth<'_>) -> GpsSample {
        let [(z1, z2), (z3, z4), (z5, z6)] = self.rng.normal_pairs::<3>();
        let c = &self.cfg;
        let t_ns = truth.t_sim_ns;
        let mut s = GpsSample {
            valid_sim_time_ns: t_ns,
            flags: c.frame_flags(),
            ..GpsSample::default()
        };
        let Some((epoch, rotation)) = &self.world else {
            return s;
        };
        if !c.fix_at(t_ns) {
            return s;
        }
        let times = epoch.times(t_ns);
        let frame = rotation.at(&times, t_ns);
        let (r_n, v_n) = (&truth.state.r_bn_n, &truth.state.v_bn_n);
        s.flags |= gps_flags::FIX;
        s.gps_week = times.gps_week;
        s.gps_seconds_of_week = times.gps_seconds_of_week();
        let dr_e = c.position_bias_e_m + Vector3::new(z1, z2, z3) * c.position_sigma_m;
        let dv_e = c.velocity_bias_e_m_s + Vector3::new(z4, z5, z6) * c.velocity_sigma_m_s;
        if c.ecef {
            s.r_be_e_m = frame.r_e(r_n);
            s.v_be_e_m_s = frame.v_e(r_n, v_n);
            if self.has_errors {
                s.r_be_e_m += dr_e;
                s.v_be_e_m_s += dv_e;
            }
        }
        if c.inertial {
            s.r_bn_n_m = *r_n;
            s.v_bn_n_m_s = *v_n;
            if self.has_errors {
                let dr_n = frame.dcm_en.tr_mul(&dr_e);
                s.r_bn_n_m += dr_n;
                s.v_bn_n_m_s += frame.dcm_en.tr_mul(&dv_e) + frame.omega_en_n_rad_s.cross(&dr_n);
            }
        }
        s
    }
}

impl GpsSample {
    /// Every field, for a checkpoint.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            valid_sim_time_ns,
            gps_week,
            gps_seconds_of_week,
            r_be_e_m,
            v_be_e_m_s,
            r_bn_n_m,
            v_bn_n_m_s,
            flags,
        } = self;
        a.put(valid_sim_time_ns);
        a.put(gps_week);
        a.put(gps_seconds_of_week);
        a.put(r_be_e_m);
        a.put(v_be_e_m_s);
        a.put(r_bn_n_m);
        a.put(v_bn_n_m_s);
        a.put(flags);
    }
}

impl Sensor for Gps {
    fn kind(&self) -> &'static SensorKind {
        &KIND
    }

    fn name(&self) -> &str {
        &self.cfg.name
    }

    /// The error terms (a campaign disperses them); the rate, latency and acquisition shape the
    /// latency ring and the timing, so they are not dispersed.
    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        let c = &self.cfg;
        out.push(("position_sigma_m".into(), c.position_sigma_m));
        out.push(("velocity_sigma_m_s".into(), c.velocity_sigma_m_s));
        for i in 0..3 {
            out.push((format!("position_bias_e_m[{i}]"), c.position_bias_e_m[i]));
            out.push((
                format!("velocity_bias_e_m_s[{i}]"),
                c.velocity_bias_e_m_s[i],
            ));
        }
    }

    fn due(&self, tick: u64) -> bool {
        self.measures_at(tick) || self.publishes_at(tick)
    }

    /// Measures (at a measurement tick, into the ring), then publishes (at a publication tick,
    /// the measurement `latency_frames` old) — the tick from the truth's time.
    fn sample(&mut self, truth: &Truth<'_>) {
        let tick = truth.t_sim_ns / self.frame_ns;
        let n = self.ring.len() as u64;
        if self.measures_at(tick) {
            let s = self.measure(truth);
            self.ring[((tick / self.cfg.every_frames) % n) as usize] = s;
        }
        self.published = self.publishes_at(tick);
        if self.published {
            let k = (tick - self.cfg.latency_frames) / self.cfg.every_frames;
            self.last = self.ring[(k % n) as usize];
        }
    }

    fn has_output(&self) -> bool {
        self.published
    }

    /// `seq` counts the messages: (tick − latency frames) / every_frames.
    fn encode(&self, header: Header, buf: &mut Vec<u8>) {
        let header = Header {
            seq: header.tick.saturating_sub(self.cfg.latency_frames) / self.cfg.every_frames,
            ..header
        };
        encode_into(&self.last.to_msg(header), buf);
    }

    fn first_non_finite(&self) -> Option<&'static str> {
        let s = &self.last;
        [
            ("r_be_e_m", &s.r_be_e_m),
            ("v_be_e_m_s", &s.v_be_e_m_s),
            ("r_bn_n_m", &s.r_bn_n_m),
            ("v_bn_n_m_s", &s.v_bn_n_m_s),
        ]
        .into_iter()
        .find(|(_, v)| !v.iter().all(|x| x.is_finite()))
        .map(|(name, _)| name)
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    /// The generator, the latency ring (its slots are indexed by tick), the last sample and
    /// whether it was published.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            cfg: _,
            world: _,
            frame_ns: _,
            has_errors: _,
            rng,
            ring,
            last,
            published,
        } = self;
        a.put(rng);
        a.expect_count("latency slots", ring.len());
        for s in ring.iter_mut() {
            s.archive(a);
        }
        last.archive(a);
        a.put(published);
    }

    /// The solution's vectors, each in the frame its name ends with; a channel whose frame is
    /// not configured output, or a sample without a fix, exposes no axes (there is no solution
    /// to corrupt, and a message without `FIX` keeps every number 0).
    fn fault_channels(&self) -> &'static [&'static str] {
        &["position_e", "velocity_e", "position_n", "velocity_n"]
    }

    fn fault_axes(&self, channel: usize) -> usize {
        if channel < 4 {
            3
        } else {
            0
        }
    }

    fn fault_channel(&mut self, channel: usize) -> &mut [f64] {
        let (c, s) = (&self.cfg, &mut self.last);
        if !s.fix() {
            return &mut [];
        }
        match channel {
            0 if c.ecef => s.r_be_e_m.as_mut_slice(),
            1 if c.ecef => s.v_be_e_m_s.as_mut_slice(),
            2 if c.inertial => s.r_bn_n_m.as_mut_slice(),
            3 if c.inertial => s.v_bn_n_m_s.as_mut_slice(),
            _ => &mut [],
        }
    }

    /// `FIX` is the validity flag.
    fn has_validity(&self) -> bool {
        true
    }

    fn is_valid(&self) -> bool {
        self.last.flags & gps_flags::FIX != 0
    }

    /// The receiver reports no solution: `FIX` cleared and, as in any message without it,
    /// every number 0 (the valid time and the frame flags stay).
    fn force_invalid(&mut self) {
        self.last = GpsSample {
            valid_sim_time_ns: self.last.valid_sim_time_ns,
            flags: self.last.flags & !gps_flags::FIX,
            ..GpsSample::default()
        };
    }
}
