//! Fault detection, isolation and recovery (FDIR) for the demo's fine-pointing loop
//! (`flexdyn-acs-demo --fdir`): a gyro monitor that checks every IMU's gyro against the star
//! tracker and switches the rate feedback to a healthy IMU (or to star-tracker-derived rates),
//! and a wheel monitor that checks every wheel's speed against its command and drops a failed
//! wheel from the torque allocation. Pure functions of the samples (no I/O), so a lockstep run
//! is reproducible bit for bit.
//!
//! # Gyro monitor: gyro-integrated versus star-tracker attitude change
//! At every valid star-tracker sample k the tracker gives [B_k N] = \[CB\]ᵀ [C̃N]. Each gyro is
//! integrated between frames (trapezoidal rate, frame rotation R(φ) = exp(−[φ̃]), exact through
//! the MRP tan(|φ|/4) φ̂) into G(t) = [B_t B_0]. Over a window of M tracker samples, W = M T_st
//! seconds from sample j to sample k, the tracker's attitude change is [B_k B_j] = [B_k N][B_j N]ᵀ
//! and the gyro's G_k G_jᵀ; their error E = [B_k B_j] (G_k G_jᵀ)ᵀ ≈ I − \[ẽ\] gives the residual
//! rotation e = vee((Eᵀ − E)/2) (B components), taken to the tracker's case frame, e_C = \[CB\] e.
//! Only the window's two end samples of the tracker enter (the tracker noise of the samples in
//! between cancels), while a fault's effect grows with W.
//!
//! Healthy, e_C is the sum of (the sensor models in `crates/sensors/src/`):
//! - the tracker noise of the two end samples: per sample σ_x about each axis across the
//!   boresight b̂ and σ_b about it, independent, so √2 σ per axis of the difference;
//! - the gyro's white noise integrated over W: the instantaneous samples carry N/√Δt (N the
//!   angle random walk, Δt the frame), the trapezoidal sum over W/Δt frames has variance
//!   ≤ (W/Δt) Δt² N²/Δt = N² W per axis;
//! - the gyro bias integrated over W: |b| ≤ |b_c| + 4 √3 σ_bi (the constant bias and four σ of
//!   the bias instability on every axis), a margin b_max W;
//! - scale-factor and misalignment errors (≲ 3.5e-4 |ω| W: 3.5e-6 rad at 1e-2 rad/s and W = 1 s,
//!   a tenth of the smallest σ below) and the trapezoid's error (∝ ω̇ Δt W), neglected.
//!
//! So along the boresight σ_∥² = 2 σ_b² + N² W, across it (a 2-D residual e_⊥) σ_⊥² = 2 σ_x² +
//! N² W, and the test statistic is
//!
//! ```text
//!     s = max( |e_∥| / (k σ_∥ + b_max W),  |e_⊥| / (k σ_⊥ + b_max W) ),   k = 5,
//! ```
//!
//! a gyro failing one test when s > 1. Healthy, the 1-D part exceeds 5σ with probability 5.7e-7
//! and the 2-D (Rayleigh) part with e^(−25/2) = 3.7e-6, so at most 4.3e-6 per test. A gyro is
//! declared failed after [`GYRO_PERSISTENCE`] consecutive failed tests; the windows overlap, so
//! persistence does not make the tests independent: the false-alarm rate is bounded by the
//! single test's, 4.3e-6 per tracker sample (one per 6.5 h at 10 Hz).
//!
//! A stuck gyro (held at ω_s) leaves e = ∫_W (ω − ω_s) dt: it is seen once the true rate has
//! moved from the held value by about (k σ + b_max W)/W, as soon as the control torque (which
//! the stuck rate no longer damps) turns the body.
//!
//! # Gyro monitor: a frozen output
//! A gyro stuck at its current value repeats its output exactly, while a healthy one never
//! does: its per-sample white noise σ = N/√Δt moves each axis between samples by d with
//! σ_d = √2 σ, so an axis repeats its quantised value (|d| < q/2, q the LSB) with probability
//! ≤ q / (√(2π) σ_d), and all three axes with its cube. The test runs when σ ≥ 10 q
//! (probability ≤ (1/(10 · 2 √π))³ = 2.3e-5 per sample; 1.2e-8 for the demo's gyro, σ/q = 138)
//! on samples without a saturation flag (a saturated output is held at the range), and a gyro
//! whose three axes repeat [`GYRO_PERSISTENCE`] samples in a row is declared failed: a stuck
//! gyro after exactly that many frames.
//!
//! **Isolation and recovery.** When the gyro in use is declared failed, the rate feedback moves
//! to the first other IMU whose monitor passed its last [`GYRO_PERSISTENCE`] tests; if none, to
//! the star-tracker-derived rate ω̄ = e_st / W, with e_st = vee(([B_k B_j]ᵀ − [B_k B_j])/2) the
//! tracker's rotation over the window (the mean rate over the last W seconds, noise √2 σ / W per
//! axis). A spare gyro that fails is only marked failed.
//!
//! # Wheel monitor: commanded versus measured wheel speed
//! The wheel equation (W3 of the wheel model) is J_s (Ω̇ + ĝᵀ ω̇) = u − τ_f(Ω): over a frame Δt
//! with the motor torque held at the clipped command ũ = clip(u, ±u_max) (lockstep: the command
//! that answers tick k acts over frame k), the residual torque
//!
//! ```text
//!     r = J_s (Ω_(k+1) − Ω_k) / Δt − ũ_k
//! ```
//!
//! is healthy −τ_f − J_s ĝᵀ ω̄̇, bounded by τ_c + c_v |Ω|max + J_s α_max, with τ_c and c_v the
//! Coulomb and viscous friction and α_max = Σ_j u_max,j / λ_min(\[I\]) the hub's largest angular
//! acceleration from the wheels. The threshold is twice that bound (the factor covers the
//! wings' coupling into ω̇, not in α_max). A wheel fails a frame when |r| exceeds it and is
//! declared failed after [`WHEEL_PERSISTENCE`] consecutive failed frames. Frames near the speed
//! limit (where the motor stops accelerating) are not tested. A seized bearing (the rotor braked
//! to rest at the motor's torque limit, then held) gives |r| ≈ u_max at once.
//!
//! **Recovery.** The failed wheel's column of \[G_s\] is set to zero and the allocation becomes
//! [G_s']⁺ = [G_s']ᵀ ([G_s']\[G_s'\]ᵀ)⁻¹: the failed wheel gets u = 0, and the three others (if
//! they still span three axes) give exactly the requested torque ([`WheelArray::without`]).
//!
//! In real time the command acts a frame later than in lockstep; the wheel residual then also
//! holds ũ_k − ũ_(k−1), small while pointing (keep the monitor to lockstep, or raise the
//! threshold).

use anyhow::Context as _;
use flexdyn_proto::attitude::{mrp_to_dcm, quat_to_dcm};
use flexdyn_proto::client::lockstep::{SensorSchedule, Tick};
use flexdyn_proto::client::vehicle::VehicleConfig;
use nalgebra::{Matrix3, SymmetricEigen, Vector3, Vector4};

use crate::acs::{inertia_about_b, mat3, WheelArray};

/// Consecutive failed tests before a gyro is declared failed.
pub const GYRO_PERSISTENCE: u32 = 3;
/// Consecutive failed frames before a wheel is declared failed.
pub const WHEEL_PERSISTENCE: u32 = 3;
/// The gyro test's threshold in standard deviations (k above).
pub const GYRO_K_SIGMA: f64 = 5.0;
/// The wheel threshold's factor on the healthy residual's bound.
pub const WHEEL_MARGIN: f64 = 2.0;

/// A detection or a reconfiguration, for the binary to print.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A unit declared failed: `unit` (the IMU or wheel name), by the test `test`, the
    /// statistic that crossed (`s` of the star-tracker test, the repeats of the frozen-output
    /// test, |r| / threshold for a wheel) and the threshold it was compared with (\[rad\]
    /// across the boresight, repeats, \[N·m\]).
    Detected {
        /// `gyro` or `wheel`.
        what: &'static str,
        /// `star-tracker`, `frozen` (gyros) or `speed` (wheels).
        test: &'static str,
        /// The IMU or wheel name.
        unit: String,
        /// The normalised statistic (> 1).
        statistic: f64,
        /// The threshold in the statistic's unit.
        threshold: f64,
    },
    /// The rate feedback now comes from `source` (an IMU name, or `star-tracker`).
    RateSource {
        /// The new source.
        source: String,
    },
    /// The wheels the allocation now uses.
    Wheels {
        /// Their names.
        active: Vec<String>,
    },
}

/// The frame rotation R(φ) for the rotation vector φ (maps components before the rotation to
/// components after it), through its MRP tan(|φ|/4) φ̂.
fn rotation(phi: &Vector3<f64>) -> Matrix3<f64> {
    let angle = phi.norm();
    if angle == 0.0 {
        return Matrix3::identity();
    }
    mrp_to_dcm(&(phi * ((angle / 4.0).tan() / angle)))
}

/// The small rotation of a DCM C ≈ I − [φ̃]: vee((Cᵀ − C)/2).
fn small_rotation(c: &Matrix3<f64>) -> Vector3<f64> {
    let a = (c.transpose() - c) * 0.5;
    Vector3::new(a[(2, 1)], a[(0, 2)], a[(1, 0)])
}

/// The gyro test's thresholds for one gyro, derived in the module docs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GyroThreshold {
    /// \[rad\] along the boresight: k σ_∥ + b_max W.
    pub along_rad: f64,
    /// \[rad\] across the boresight: k σ_⊥ + b_max W.
    pub across_rad: f64,
}

impl GyroThreshold {
    /// For a gyro of angle random walk `arw` \[rad/s/√Hz\] and bias bound `b_max` \[rad/s\],
    /// a tracker of noise `sigma_x` (across) and `sigma_b` (about the boresight) \[rad\], over
    /// a window of `w_s` seconds.
    pub fn new(arw: f64, b_max: f64, sigma_x: f64, sigma_b: f64, w_s: f64) -> Self {
        let gyro2 = arw * arw * w_s;
        Self {
            along_rad: GYRO_K_SIGMA * (2.0 * sigma_b * sigma_b + gyro2).sqrt() + b_max * w_s,
            across_rad: GYRO_K_SIGMA * (2.0 * sigma_x * sigma_x + gyro2).sqrt() + b_max * w_s,
        }
    }
}

/// One gyro under watch.
#[derive(Debug, Clone)]
struct GyroChannel {
    name: String,
    /// Its index in the tick's IMU samples.
    index: usize,
    /// [PB].
    dcm_pb: Matrix3<f64>,
    threshold: GyroThreshold,
    /// G = [B_t B_0] integrated from this gyro.
    g: Matrix3<f64>,
    /// Its last rate (B) and whether the last sample came.
    last_rate_b: Option<Vector3<f64>>,
    /// G at the last tracker samples of the window (oldest first).
    at_samples: Vec<Matrix3<f64>>,
    /// Consecutive failed tests.
    fails: u32,
    /// Tests passed in a row (a spare is eligible after GYRO_PERSISTENCE of them).
    passes: u32,
    failed: bool,
    /// Whether the frozen-output test runs (σ ≥ 10 q), the last raw output and its repeats.
    frozen_test: bool,
    last_raw: Option<[f64; 3]>,
    repeats: u32,
}

impl GyroChannel {
    /// Declares the gyro failed by `test` (once).
    fn declare(
        &mut self,
        test: &'static str,
        statistic: f64,
        threshold: f64,
        events: &mut Vec<Event>,
    ) {
        if !self.failed {
            self.failed = true;
            events.push(Event::Detected {
                what: "gyro",
                test,
                unit: self.name.clone(),
                statistic,
                threshold,
            });
        }
    }
}

/// Where the rate feedback comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum RateFrom {
    Gyro(usize),
    StarTracker,
}

/// The gyro monitor and the rate feedback it selects (module docs).
#[derive(Debug, Clone)]
pub struct GyroFdir {
    gyros: Vec<GyroChannel>,
    /// The tracker's index in the tick's samples, its [CB] and its boresight in B.
    tracker: usize,
    dcm_cb: Matrix3<f64>,
    boresight_b: Vector3<f64>,
    /// Tracker samples per window (M) and \[s\] the window W.
    window_samples: usize,
    window_s: f64,
    /// [B N] at the last tracker samples (oldest first), cleared by an invalid or lost one.
    tracker_dcm_bn: Vec<Matrix3<f64>>,
    frame_s: f64,
    from: RateFrom,
    /// The star-tracker-derived rate (B), once a window is full.
    st_rate_b: Option<Vector3<f64>>,
    /// The largest statistic of each gyro so far (a report of the margins).
    pub max_statistic: Vec<f64>,
}

impl GyroFdir {
    /// Watches every IMU of `cfg` with the tracker `star_tracker`, over windows of
    /// `window_s` seconds (a whole number of tracker periods, at least one); the rate feedback
    /// starts on `primary`.
    pub fn new(
        cfg: &VehicleConfig,
        schedule: &SensorSchedule,
        primary: &str,
        star_tracker: &str,
        window_s: f64,
    ) -> anyhow::Result<Self> {
        let st = cfg.star_tracker(star_tracker)?;
        let every = cfg.star_tracker_period_frames(st)?;
        let frame_s = (1e9 / cfg.simulation.frame_hz).round() * 1e-9;
        let t_st = every as f64 * frame_s;
        let window_samples = (window_s / t_st).round().max(1.0) as usize;
        let window_s = window_samples as f64 * t_st;
        let dcm_cb = mat3(&st.dcm_cb);
        let boresight_c = Vector3::from(st.boresight_c);
        anyhow::ensure!(
            boresight_c.norm() > 0.0,
            "star tracker `{star_tracker}`: zero boresight_c"
        );
        let boresight_b = dcm_cb.transpose() * boresight_c.normalize();
        let tracker = schedule
            .star_trackers()
            .position(|(n, _)| n == star_tracker)
            .context("the star tracker is in the configuration but not in its schedule")?;
        let mut gyros = Vec::new();
        for imu in &cfg.imus {
            let index = schedule
                .imus()
                .position(|n| n == imu.name)
                .context("an IMU is in the configuration but not in its schedule")?;
            let b = &imu.gyro;
            let b_max = Vector3::from(b.bias_rad_s).norm()
                + 4.0 * 3f64.sqrt() * b.bias_instability_sigma_rad_s;
            gyros.push(GyroChannel {
                name: imu.name.clone(),
                index,
                dcm_pb: mat3(&imu.dcm_pb),
                threshold: GyroThreshold::new(
                    b.arw_rad_s_sqrt_hz,
                    b_max,
                    st.sigma_cross_boresight_rad,
                    st.sigma_about_boresight_rad,
                    window_s,
                ),
                g: Matrix3::identity(),
                last_rate_b: None,
                at_samples: Vec::with_capacity(window_samples + 1),
                fails: 0,
                passes: 0,
                failed: false,
                frozen_test: b.arw_rad_s_sqrt_hz / frame_s.sqrt() >= 10.0 * b.lsb_rad_s
                    && b.arw_rad_s_sqrt_hz > 0.0,
                last_raw: None,
                repeats: 0,
            });
        }
        let first = gyros
            .iter()
            .position(|g| g.name == primary)
            .with_context(|| format!("--imu {primary}: no such IMU"))?;
        let n = gyros.len();
        Ok(Self {
            gyros,
            tracker,
            dcm_cb,
            boresight_b,
            window_samples,
            window_s,
            tracker_dcm_bn: Vec::with_capacity(window_samples + 1),
            frame_s,
            from: RateFrom::Gyro(first),
            st_rate_b: None,
            max_statistic: vec![0.0; n],
        })
    }

    /// \[s\] the window W.
    pub fn window_s(&self) -> f64 {
        self.window_s
    }

    /// The thresholds of the gyro `name`.
    pub fn threshold(&self, name: &str) -> Option<GyroThreshold> {
        self.gyros
            .iter()
            .find(|g| g.name == name)
            .map(|g| g.threshold)
    }

    /// The rate feedback (B) for this tick, and what changed. `None` before any rate is known.
    pub fn update(&mut self, tick: &Tick, events: &mut Vec<Event>) -> Option<Vector3<f64>> {
        // 1. Integrate every gyro over the frame that ended at this tick (trapezoid), and the
        //    frozen-output test.
        for g in &mut self.gyros {
            let Some(m) = tick.imus.get(g.index).and_then(Option::as_ref) else {
                continue; // lost: its last rate is held in the integration below next time
            };
            let raw = m.omega_p_rad_s;
            g.repeats = if g.frozen_test && m.saturation_flags == 0 && g.last_raw == Some(raw) {
                g.repeats + 1
            } else {
                0
            };
            g.last_raw = Some(raw);
            if g.repeats >= GYRO_PERSISTENCE {
                let repeats = f64::from(g.repeats);
                g.declare("frozen", repeats, f64::from(GYRO_PERSISTENCE), events);
            }
            let w = g.dcm_pb.transpose() * Vector3::from(raw);
            if let Some(prev) = g.last_rate_b {
                g.g = rotation(&((prev + w) * (0.5 * self.frame_s))) * g.g;
            }
            g.last_rate_b = Some(w);
        }
        // 2. At a tracker sample, the tests.
        if let Some(st) = tick
            .star_trackers
            .get(self.tracker)
            .and_then(Option::as_ref)
        {
            if st.valid {
                let dcm_bn = self.dcm_cb.transpose() * quat_to_dcm(&Vector4::from(st.q_cn));
                push_window(&mut self.tracker_dcm_bn, dcm_bn, self.window_samples);
                for g in &mut self.gyros {
                    push_window(&mut g.at_samples, g.g, self.window_samples);
                }
                if self.tracker_dcm_bn.len() == self.window_samples + 1 {
                    self.test(events);
                }
            } else {
                self.tracker_dcm_bn.clear();
                for g in &mut self.gyros {
                    g.at_samples.clear();
                }
            }
        }
        self.isolate(events);
        match self.from {
            RateFrom::Gyro(i) => self.gyros[i].last_rate_b,
            RateFrom::StarTracker => self.st_rate_b,
        }
    }

    /// The tests over the full window.
    fn test(&mut self, events: &mut Vec<Event>) {
        let (first, last) = (
            &self.tracker_dcm_bn[0],
            &self.tracker_dcm_bn[self.window_samples],
        );
        let st_change = last * first.transpose();
        self.st_rate_b = Some(small_rotation(&st_change) / self.window_s);
        for (i, g) in self.gyros.iter_mut().enumerate() {
            if g.at_samples.len() != self.window_samples + 1 {
                continue; // a gyro whose samples started later than the tracker's
            }
            let gyro_change = g.at_samples[self.window_samples] * g.at_samples[0].transpose();
            let e_b = small_rotation(&(st_change * gyro_change.transpose()));
            let along = e_b.dot(&self.boresight_b);
            let across = (e_b - self.boresight_b * along).norm();
            let s = (along.abs() / g.threshold.along_rad).max(across / g.threshold.across_rad);
            self.max_statistic[i] = self.max_statistic[i].max(s);
            if s > 1.0 {
                g.fails += 1;
                g.passes = 0;
            } else {
                g.fails = 0;
                g.passes += 1;
            }
            if g.fails >= GYRO_PERSISTENCE {
                let threshold = g.threshold.across_rad;
                g.declare("star-tracker", s, threshold, events);
            }
        }
    }

    /// Isolation and recovery: leaves a failed gyro for a healthy one, or for the tracker.
    fn isolate(&mut self, events: &mut Vec<Event>) {
        if let RateFrom::Gyro(i) = self.from {
            if self.gyros[i].failed {
                let spare = self
                    .gyros
                    .iter()
                    .position(|g| !g.failed && g.passes >= GYRO_PERSISTENCE);
                self.from = spare.map_or(RateFrom::StarTracker, RateFrom::Gyro);
                events.push(Event::RateSource {
                    source: spare.map_or("star-tracker".to_owned(), |j| self.gyros[j].name.clone()),
                });
            }
        }
    }

    /// The names of the gyros, in the order of [`Self::max_statistic`].
    pub fn names(&self) -> Vec<&str> {
        self.gyros.iter().map(|g| g.name.as_str()).collect()
    }
}

/// Appends `x` to a window of at most `samples + 1` entries (oldest dropped).
fn push_window(v: &mut Vec<Matrix3<f64>>, x: Matrix3<f64>, samples: usize) {
    if v.len() == samples + 1 {
        v.remove(0);
    }
    v.push(x);
}

/// The wheel monitor and the allocation it keeps (module docs).
#[derive(Debug, Clone)]
pub struct WheelFdir {
    names: Vec<String>,
    j_s_kg_m2: Vec<f64>,
    max_torque_nm: Vec<f64>,
    max_speed_rad_s: Vec<f64>,
    /// \[N·m\] the threshold of each wheel at the speed bound `speed_bound_rad_s`.
    coulomb_nm: Vec<f64>,
    viscous_nm_s_rad: Vec<f64>,
    /// \[N·m\] J_s α_max of each wheel.
    hub_coupling_nm: Vec<f64>,
    frame_s: f64,
    /// The last speeds and the clipped commands that act over the frame after them.
    last: Option<(Vec<f64>, Vec<f64>)>,
    fails: Vec<u32>,
    failed: Vec<bool>,
    /// The largest |r| / threshold of each wheel so far.
    pub max_statistic: Vec<f64>,
}

impl WheelFdir {
    /// Watches the wheels of `cfg`.
    pub fn new(cfg: &VehicleConfig) -> anyhow::Result<Self> {
        let inertia = inertia_about_b(cfg)?;
        let lambda_min = SymmetricEigen::new(inertia).eigenvalues.min();
        anyhow::ensure!(lambda_min > 0.0, "the inertia is not positive definite");
        let wheels = &cfg.reaction_wheels;
        let alpha_max = wheels.iter().map(|w| w.max_torque_nm).sum::<f64>() / lambda_min;
        let n = wheels.len();
        Ok(Self {
            names: wheels.iter().map(|w| w.name.clone()).collect(),
            j_s_kg_m2: wheels.iter().map(|w| w.j_s_kg_m2).collect(),
            max_torque_nm: wheels.iter().map(|w| w.max_torque_nm).collect(),
            max_speed_rad_s: wheels.iter().map(|w| w.max_speed_rad_s).collect(),
            coulomb_nm: wheels.iter().map(|w| w.coulomb_friction_nm).collect(),
            viscous_nm_s_rad: wheels.iter().map(|w| w.viscous_friction_nm_s_rad).collect(),
            hub_coupling_nm: wheels.iter().map(|w| w.j_s_kg_m2 * alpha_max).collect(),
            frame_s: (1e9 / cfg.simulation.frame_hz).round() * 1e-9,
            last: None,
            fails: vec![0; n],
            failed: vec![false; n],
            max_statistic: vec![0.0; n],
        })
    }

    /// \[N·m\] wheel `j`'s threshold over a frame between speeds `a` and `b` \[rad/s\].
    pub fn threshold_nm(&self, j: usize, a: f64, b: f64) -> f64 {
        WHEEL_MARGIN
            * (self.coulomb_nm[j]
                + self.viscous_nm_s_rad[j] * a.abs().max(b.abs())
                + self.hub_coupling_nm[j])
    }

    /// The wheel names.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Whether wheel `j` is declared failed.
    pub fn failed(&self, j: usize) -> bool {
        self.failed[j]
    }

    /// Tests the frame that ended with the wheel speeds `speeds` \[rad/s\] (the tachometers);
    /// returns the wheel newly declared failed, if any.
    pub fn check(&mut self, speeds: &[f64], events: &mut Vec<Event>) -> Option<usize> {
        let (prev, u) = self.last.as_ref()?;
        let mut newly = None;
        for j in 0..self.names.len() {
            let (a, b) = (prev[j], speeds[j]);
            let limit = 0.99 * self.max_speed_rad_s[j];
            if self.failed[j] || a.abs() >= limit || b.abs() >= limit {
                self.fails[j] = 0;
                continue;
            }
            let r = self.j_s_kg_m2[j] * (b - a) / self.frame_s - u[j];
            let threshold = self.threshold_nm(j, a, b);
            let s = r.abs() / threshold;
            self.max_statistic[j] = self.max_statistic[j].max(s);
            self.fails[j] = if s > 1.0 { self.fails[j] + 1 } else { 0 };
            if self.fails[j] >= WHEEL_PERSISTENCE && newly.is_none() {
                self.failed[j] = true;
                newly = Some(j);
                events.push(Event::Detected {
                    what: "wheel",
                    test: "speed",
                    unit: self.names[j].clone(),
                    statistic: s,
                    threshold,
                });
            }
        }
        newly
    }

    /// The failed flags, in wheel order.
    pub fn failed_list(&self) -> Vec<bool> {
        self.failed.clone()
    }

    /// The names of the wheels not declared failed.
    pub fn active_names(&self) -> Vec<String> {
        self.names
            .iter()
            .zip(&self.failed)
            .filter(|(_, f)| !**f)
            .map(|(n, _)| n.clone())
            .collect()
    }

    /// No wheel command for the frame after this tick: the next frame is not tested.
    pub fn uncommanded(&mut self) {
        self.last = None;
    }

    /// Records the speeds of this tick and the motor torques commanded for the frame after it.
    pub fn commanded(&mut self, speeds: &[f64], u_nm: &[f64]) {
        let clipped = u_nm
            .iter()
            .zip(&self.max_torque_nm)
            .map(|(u, m)| u.clamp(-m, *m))
            .collect();
        self.last = Some((speeds.to_vec(), clipped));
    }
}

/// The gyro test's statistic s for a window in which the tracker saw the body turn by the
/// rotation vector `st_rotation_b` and the gyro by `gyro_rotation_b` (B components), with the
/// boresight `boresight_b`: the arithmetic of [`GyroFdir`]'s test on its own.
pub fn gyro_statistic(
    threshold: &GyroThreshold,
    boresight_b: &Vector3<f64>,
    st_rotation_b: &Vector3<f64>,
    gyro_rotation_b: &Vector3<f64>,
) -> f64 {
    let e_b = small_rotation(&(rotation(st_rotation_b) * rotation(gyro_rotation_b).transpose()));
    let b = boresight_b.normalize();
    let along = e_b.dot(&b);
    let across = (e_b - b * along).norm();
    (along.abs() / threshold.along_rad).max(across / threshold.across_rad)
}

impl WheelArray {
    /// The same array without wheel `failed`: its column of \[G_s\] set to zero, so the
    /// minimum-norm allocation gives it u = 0 and the others the requested torque exactly
    /// (an error if they no longer span three axes).
    pub fn without(&self, failed: &[bool]) -> anyhow::Result<Self> {
        let mut out = self.clone();
        out.set_allocation(failed)?;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> VehicleConfig {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../scenarios/fdir.toml");
        VehicleConfig::from_toml(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// Without rw2 the allocation gives it nothing and the three others still make the
    /// requested torque exactly: −Σ ĝ_j u_j = L.
    #[test]
    fn three_wheels_make_the_torque_and_the_failed_one_gets_none() {
        let all = WheelArray::from_config(&cfg()).unwrap();
        let three = all.without(&[false, true, false, false]).unwrap();
        let l = Vector3::new(0.03, -0.05, 0.02);
        let u = three.motor_torques(&l);
        assert_eq!(u[1], 0.0);
        let back: Vector3<f64> = three.spin_axis_b.iter().zip(&u).map(|(g, u)| -g * *u).sum();
        assert!((back - l).norm() < 1e-15, "{back} vs {l}");
        // Two wheels cannot span three axes.
        assert!(all.without(&[true, true, false, false]).is_err());
    }

    /// The scenario's thresholds (the numbers the lockstep test re-derives), and the statistic:
    /// 0 when gyro and tracker agree, 1 on the threshold across the boresight.
    #[test]
    fn gyro_thresholds_and_statistic() {
        let c = cfg();
        let imu = c.imu("imu_a").unwrap();
        let st = c.star_tracker("st1").unwrap();
        let b_max = Vector3::from(imu.gyro.bias_rad_s).norm()
            + 4.0 * 3f64.sqrt() * imu.gyro.bias_instability_sigma_rad_s;
        let t = GyroThreshold::new(
            imu.gyro.arw_rad_s_sqrt_hz,
            b_max,
            st.sigma_cross_boresight_rad,
            st.sigma_about_boresight_rad,
            1.0,
        );
        assert!((t.across_rad - 3.4999e-4).abs() < 1e-8, "{t:?}");
        assert!((t.along_rad - 1.4611e-3).abs() < 1e-7, "{t:?}");
        let boresight_b = Vector3::new(0.0, -1.0, 0.0);
        let phi = Vector3::new(1e-3, -2e-3, 5e-4);
        assert!(gyro_statistic(&t, &boresight_b, &phi, &phi) < 1e-12);
        let across = gyro_statistic(&t, &boresight_b, &(phi + Vector3::x() * t.across_rad), &phi);
        assert!((across - 1.0).abs() < 1e-5, "{across}");
        let along = gyro_statistic(&t, &boresight_b, &(phi + boresight_b * t.along_rad), &phi);
        assert!((along - 1.0).abs() < 1e-5, "{along}");
    }
}
