//! The whole ACS as flight code: one lockstep [`Tick`] of sensor samples in, one set of
//! actuator inputs out, the mode chosen by the [`ModeManager`]. No I/O (the binary's
//! `--mode-manager` loop does the Zenoh side), so it is tested and reproduced like any function.
//!
//! What each mode reads and commands (the laws are in [`crate::magnetic`], [`crate::sun`] and
//! [`crate::acs`]):
//!
//! | mode | sensors | actuators | law |
//! |---|---|---|---|
//! | Detumble | gyro, magnetometer | rods (wheels idle) | m = k_ω (ω × B)/\|B\|², each rod clipped |
//! | SunAcquisition | gyro, coarse sun sensors | wheels | τ = k_p (n̂ × ŝ) − k_d ω (+ gyroscopic term) |
//! | FinePointing | gyro, star tracker | wheels | L = −Kσ_BR − Pω + ω × (\[I\]ω + h_w) |
//! | MomentumManagement | + magnetometer | wheels + rods | fine pointing, m = (B × τ_d)/\|B\|², τ_d = −k_u h_w |
//!
//! **Detumble law and gain.** B-dot with the rate from the gyro instead of a finite difference
//! of the field: Ḃ_B = −ω × B_B + \[BN\] Ḃ_N, and a finite difference also sees the field's own
//! turning along the orbit (about twice the orbit rate, 0.13°/s here), so a magnetometer-only
//! B-dot settles the body at that rate, above the 0.1°/s the sequence asks for. With the gyro,
//! m = (k_ω/|B|) (ω × b̂) gives τ = m × B = −k_ω ω_⊥ (the rate across the field, which turns
//! through every direction over an orbit). The gain that minimises the orbit-averaged decay
//! time is k_ω = 2 n (1 + sin ξ_m) J_min (Avanzini & Giulietti, "Magnetic detumbling of a rigid
//! spacecraft", JGCD 35(4), 2012): n the orbit rate, ξ_m the orbit's inclination to the
//! geomagnetic equator, J_min the smallest principal inertia. For `scenarios/acs_full.toml`
//! (500 km, n = 2π/5677 s = 1.107e-3 rad/s; sun-synchronous, 97.4°, so ξ_m ≈ 80…90° and
//! sin ξ_m ≈ 1; J_min ≈ 1100 kg·m² about x through the centre of mass, see `acs::inertia_about_b`)
//! k_ω = 2 · 1.107e-3 · 2 · 1100 ≈ 4.9 N·m·s. At 3°/s in a 30 µT field that asks for
//! 4.9 · 0.052 / 3e-5 ≈ 8500 A·m², twenty times the 400 A·m² rods: the detumble runs saturated
//! (each rod clipped to its limit, which keeps ω·τ = −Σ m_j (ω × B)_j ≤ 0: still dissipative)
//! down to about 400 · 3e-5 / 4.9 = 2.5e-3 rad/s (0.14°/s), where it becomes linear.
//!
//! **Unloading gain.** τ_d = −k_u h_w asks the rods for |m| = k_u |h_w| / |B| (across the
//! field). It stays within the rods' m_max = 400 A·m² in the orbit-average field
//! B̄ ≈ 30 µT for |h_w| ≤ h_lin when k_u = m_max B̄ / h_lin; with h_lin = 10 N·m·s (the
//! scenario's initial wheel momentum), k_u = 400 · 3e-5 / 10 = 1.2e-3 s⁻¹. Only the part of τ_d
//! across the field is made: orbit-averaged, for a field that turns through every direction,
//! 2/3 of it (Camillo & Markley 1980), so h_w decays with a time constant
//! 1 / (⅔ k_u) ≈ 1250 s, about a quarter of an orbit; above h_lin the dipole is scaled down as
//! a whole and the drop is slower. The disturbance torques (gravity gradient ≲ 3 n² ΔI ≈ 3e-3
//! N·m) leave a residual of order τ / (⅔ k_u) ≈ 3 N·m·s.
//!
//! **Sun acquisition gains.** About one axis, I θ̈ + k_d θ̇ + k_p sin θ = 0. From far away the
//! slew runs at k_p / k_d (the torques balance); 0.3°/s = 5.2e-3 rad/s keeps the wheels within
//! their 0.2 N·m (k_p = 0.2 N·m at 90°). Critical damping on the largest inertia
//! (I ≈ 1800 kg·m²), k_d = 2 √(k_p I), with k_p = 5.2e-3 k_d gives k_d = 4 · 5.2e-3 · 1800 ≈
//! 38 N·m·s and k_p ≈ 0.2 N·m.
//!
//! **Fine pointing gains.** The linearised MRP loop (see the binary's docs): ω_n = √(K/(4I)),
//! ζ = P/√(K I). ω_n = 0.1 rad/s on I = 1812 kg·m² gives K = 4 I ω_n² ≈ 72 N·m, and ζ = 0.9 gives
//! P = 0.9 √(K I) ≈ 325 N·m·s; a 3e-3 N·m disturbance then leaves σ = τ/K = 4e-5 (0.01°).
//! The request is scaled down as a whole to the wheels' torque limit (direction kept).

use anyhow::{bail, Context as _};
use flexdyn_proto::attitude::{dcm_to_mrp, mrp_error, mrp_to_dcm};
use flexdyn_proto::client::lockstep::{SensorSchedule, Tick};
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_proto::EffectorInput;
use nalgebra::{Matrix3, Rotation3, Vector3};

use crate::acs::{inertia_about_b, mat3, wheel_control_torque, StarTrackerAttitude, WheelArray};
use crate::magnetic::{gyro_bdot_dipole_b_am2, unloading_dipole_b_am2, RodArray};
use crate::modes::{Mode, ModeManager, ModeSettings, Observation, Transition};
use crate::sun::{angle_to_sun_rad, sun_acquisition_torque_b_nm, sun_direction_b};

/// The control gains of every mode (module docs: their derivation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    /// \[N·m·s\] k_ω of the detumble law τ = −k_ω ω_⊥.
    pub detumble_nms: f64,
    /// \[N·m\] k_p of sun acquisition.
    pub sun_kp_nm: f64,
    /// \[N·m·s\] k_d of sun acquisition.
    pub sun_kd_nms: f64,
    /// \[N·m\] K of fine pointing.
    pub fine_k_nm: f64,
    /// \[N·m·s\] P of fine pointing.
    pub fine_p_nms: f64,
    /// \[1/s\] k_u of the unloading law.
    pub unload_per_s: f64,
}

impl Default for Gains {
    /// The values derived in the module docs for `scenarios/acs_full.toml`.
    fn default() -> Self {
        Self {
            detumble_nms: 4.9,
            sun_kp_nm: 0.2,
            sun_kd_nms: 38.0,
            fine_k_nm: 72.0,
            fine_p_nms: 325.0,
            unload_per_s: 1.2e-3,
        }
    }
}

/// Which sensors feed the sequence, and its geometry and settings.
#[derive(Clone, Debug, PartialEq)]
pub struct SequenceSetup {
    /// The `[[imus]]` whose gyro gives the rate.
    pub imu: String,
    /// The `[[star_trackers]]` giving the attitude.
    pub star_tracker: String,
    /// The `[[magnetometers]]` giving the field.
    pub magnetometer: String,
    /// The `[[coarse_sun_sensors]]` array giving the Sun direction.
    pub coarse_sun_sensor: String,
    /// The solar-panel normal in B, turned onto the Sun.
    pub panel_normal_b: Vector3<f64>,
    /// The fine-pointing target σ_RN; `None`: the Sun-pointing attitude nearest the one at
    /// entry to fine pointing (the panel normal exactly on the Sun, the rest of the attitude
    /// kept), held inertially.
    pub target_sigma_rn: Option<Vector3<f64>>,
    /// A coarse sun sensor reading above this sees the Sun (in the array's output unit).
    pub css_threshold: f64,
    /// The mode logic's thresholds and times.
    pub modes: ModeSettings,
    /// The gains.
    pub gains: Gains,
}

/// What one tick produced.
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    /// The mode that commanded this tick.
    pub mode: Mode,
    /// The transition made at this tick, if any.
    pub transition: Option<Transition>,
    /// The fine-pointing target, when it was chosen at this tick.
    pub new_target_sigma_rn: Option<Vector3<f64>>,
    /// Every wheel's motor torque and every rod's dipole, for an `Actuators` command.
    pub inputs: Vec<EffectorInput>,
    /// \[N·m·s\] the wheel momentum h_w about B, B components, from this tick's wheel speeds.
    pub wheel_momentum_b_nms: Vector3<f64>,
    /// What the mode logic saw at this tick (the sensors' estimates: rate, Sun angle, pointing
    /// error).
    pub observation: Observation,
    /// The attitude estimate σ_BN (star tracker, propagated with the gyro), once there is one.
    pub sigma_bn_estimate: Option<Vector3<f64>>,
    /// The Sun direction the coarse sun sensors give, B components (`None` in eclipse).
    pub sun_b: Option<Vector3<f64>>,
    /// The fine-pointing target σ_RN in force, once chosen.
    pub target_sigma_rn: Option<Vector3<f64>>,
}

/// The flight software of the sequence (module docs).
#[derive(Debug)]
pub struct AcsSequence {
    setup: SequenceSetup,
    modes: ModeManager,
    wheels: WheelArray,
    wheel_max_torque_nm: Vec<f64>,
    rods: RodArray,
    inertia_b_kg_m2: Matrix3<f64>,
    frame_s: f64,
    imu_index: usize,
    dcm_pb: Matrix3<f64>,
    tracker: StarTrackerAttitude,
    tracker_index: usize,
    mag_index: usize,
    dcm_sb: Matrix3<f64>,
    css_index: usize,
    css_normals_b: Vec<Vector3<f64>>,
    last_rate_b: Option<Vector3<f64>>,
    last_b_b_t: Option<Vector3<f64>>,
    last_sun_b: Option<Vector3<f64>>,
    target_sigma_rn: Option<Vector3<f64>>,
    started: bool,
}

/// The index of `name` in a schedule's list, or an error naming it.
fn index_of<'a>(
    mut names: impl Iterator<Item = &'a str>,
    name: &str,
    what: &str,
) -> anyhow::Result<usize> {
    names
        .position(|n| n == name)
        .with_context(|| format!("the {what} `{name}` is not in the served configuration"))
}

impl AcsSequence {
    /// The sequence for a served configuration and its tick schedule.
    pub fn new(
        cfg: &VehicleConfig,
        schedule: &SensorSchedule,
        setup: SequenceSetup,
    ) -> anyhow::Result<Self> {
        let imu = cfg.imu(&setup.imu)?;
        let mag = cfg.magnetometer(&setup.magnetometer)?;
        let css = cfg.coarse_sun_sensor(&setup.coarse_sun_sensor)?;
        if setup.panel_normal_b.norm() == 0.0 || !setup.panel_normal_b.iter().all(|x| x.is_finite())
        {
            bail!("the panel normal must be a finite non-zero vector");
        }
        Ok(Self {
            wheels: WheelArray::from_config(cfg)?,
            wheel_max_torque_nm: cfg
                .reaction_wheels
                .iter()
                .map(|w| w.max_torque_nm)
                .collect(),
            rods: RodArray::from_config(cfg)?,
            inertia_b_kg_m2: inertia_about_b(cfg)?,
            frame_s: (1e9 / cfg.simulation.frame_hz).round() * 1e-9,
            imu_index: index_of(schedule.imus(), &setup.imu, "IMU")?,
            dcm_pb: mat3(&imu.dcm_pb),
            tracker: StarTrackerAttitude::from_config(cfg, &setup.star_tracker)?,
            tracker_index: index_of(
                schedule.star_trackers().map(|(n, _)| n),
                &setup.star_tracker,
                "star tracker",
            )?,
            mag_index: index_of(
                schedule.magnetometers().map(|(n, _)| n),
                &setup.magnetometer,
                "magnetometer",
            )?,
            dcm_sb: mat3(&mag.dcm_sb),
            css_index: index_of(
                schedule.coarse_sun_sensors().map(|(n, _)| n),
                &setup.coarse_sun_sensor,
                "coarse sun sensor",
            )?,
            css_normals_b: css
                .normals_b
                .iter()
                .map(|n| Vector3::from(*n).normalize())
                .collect(),
            modes: ModeManager::new(setup.modes, 0),
            target_sigma_rn: setup.target_sigma_rn,
            setup: SequenceSetup {
                panel_normal_b: setup.panel_normal_b.normalize(),
                ..setup
            },
            last_rate_b: None,
            last_b_b_t: None,
            last_sun_b: None,
            started: false,
        })
    }

    /// The mode manager (its transitions, the time in each mode).
    pub fn modes(&self) -> &ModeManager {
        &self.modes
    }

    /// The fine-pointing target, once chosen.
    pub fn target_sigma_rn(&self) -> Option<Vector3<f64>> {
        self.target_sigma_rn
    }

    /// The Sun-pointing target nearest σ_BN: the smallest rotation that takes the panel normal
    /// onto the Sun, applied to the current attitude. With \[NB\] = \[BN\]ᵀ, n_N = \[NB\] n_B,
    /// s_N = \[NB\] s_B and C the rotation taking n_N to s_N, the target's axes in N are C \[NB\],
    /// so \[RN\] = \[BN\] Cᵀ.
    pub fn sun_pointing_target(
        sigma_bn: &Vector3<f64>,
        panel_normal_b: &Vector3<f64>,
        sun_b: &Vector3<f64>,
    ) -> Vector3<f64> {
        let dcm_bn = mrp_to_dcm(sigma_bn);
        let n_n = dcm_bn.transpose() * panel_normal_b.normalize();
        let s_n = dcm_bn.transpose() * sun_b.normalize();
        let c = Rotation3::rotation_between(&n_n, &s_n)
            .unwrap_or_else(Rotation3::identity)
            .into_inner();
        dcm_to_mrp(&(dcm_bn * c.transpose()))
    }

    /// One tick: the sensor estimates, the mode, the commands.
    pub fn step(&mut self, tick: &Tick) -> anyhow::Result<Output> {
        let state = &tick.state;
        let (tick_no, t_ns) = (state.header.tick, state.header.sim_time_ns);
        if !self.started {
            self.modes = ModeManager::new(self.setup.modes, t_ns);
            self.started = true;
        }
        // The gyro (a lost sample holds the last rate).
        if let Some(m) = tick.imus.get(self.imu_index).and_then(Option::as_ref) {
            self.last_rate_b = Some(self.dcm_pb.transpose() * Vector3::from(m.omega_p_rad_s));
        }
        let rate_b = self
            .last_rate_b
            .with_context(|| format!("no gyro sample from `{}` yet", self.setup.imu))?;
        // The field, B components (held between samples).
        if let Some(m) = tick
            .magnetometers
            .get(self.mag_index)
            .and_then(Option::as_ref)
        {
            self.last_b_b_t = Some(self.dcm_sb.transpose() * Vector3::from(m.b_s_t));
        }
        // The Sun direction (none in eclipse); held between samples.
        if let Some(m) = tick
            .coarse_sun_sensors
            .get(self.css_index)
            .and_then(Option::as_ref)
        {
            let n = usize::from(m.detector_count).min(self.css_normals_b.len());
            self.last_sun_b = sun_direction_b(
                &self.css_normals_b[..n],
                &m.readings[..n],
                self.setup.css_threshold,
            );
        }
        let sun_b = self.last_sun_b;
        // The attitude (star tracker, propagated with the gyro between its updates).
        let sigma_bn = self.tracker.update(
            tick.star_trackers
                .get(self.tracker_index)
                .and_then(Option::as_ref),
            &rate_b,
            self.frame_s,
        );
        let sigma_br = match (sigma_bn, self.target_sigma_rn) {
            (Some(s), Some(r)) => Some(mrp_error(&s, &r)),
            _ => None,
        };
        let n_b = self.setup.panel_normal_b;
        let obs = Observation {
            tick: tick_no,
            t_ns,
            omega_bn_b_rad_s: rate_b,
            sun_angle_rad: sun_b.map(|s| angle_to_sun_rad(&n_b, &s)),
            // Principal angle of σ_BR: 4 atan |σ|.
            pointing_error_rad: sigma_br.map(|s| 4.0 * s.norm().atan()),
        };
        let before = self.transitions_len();
        let mode = self.modes.update(&obs);
        let transition = (self.transitions_len() > before)
            .then(|| *self.modes.transitions().last().expect("just pushed"));
        // The fine-pointing target: chosen once, on the first tick of fine pointing with an
        // attitude and a Sun direction.
        let mut new_target = None;
        if matches!(mode, Mode::FinePointing | Mode::MomentumManagement)
            && self.target_sigma_rn.is_none()
        {
            if let (Some(s), Some(sun)) = (sigma_bn, sun_b) {
                let t = Self::sun_pointing_target(&s, &n_b, &sun);
                self.target_sigma_rn = Some(t);
                new_target = Some(t);
            }
        }

        let speeds = self.wheels.speeds(state)?;
        let h_w = self.wheels.momentum_b(&rate_b, &speeds);
        let gyroscopic = rate_b.cross(&(self.inertia_b_kg_m2 * rate_b + h_w));
        let g = self.setup.gains;
        let sun_torque = |sun: Option<&Vector3<f64>>| {
            sun_acquisition_torque_b_nm(g.sun_kp_nm, g.sun_kd_nms, &n_b, sun, &rate_b) + gyroscopic
        };
        let (wheel_torque_b, dipole) = match mode {
            Mode::Detumble => (None, self.detumble_dipoles(&rate_b)),
            Mode::SunAcquisition => (Some(sun_torque(sun_b.as_ref())), self.rods_off()),
            Mode::FinePointing | Mode::MomentumManagement => {
                let l = match (sigma_bn, self.target_sigma_rn) {
                    (Some(s), Some(r)) => wheel_control_torque(
                        g.fine_k_nm,
                        g.fine_p_nms,
                        &mrp_error(&s, &r),
                        &rate_b,
                        &self.inertia_b_kg_m2,
                        &h_w,
                    ),
                    // No attitude yet: keep the Sun on the panel meanwhile.
                    _ => sun_torque(sun_b.as_ref()),
                };
                let rods = match (mode, self.last_b_b_t) {
                    (Mode::MomentumManagement, Some(b)) => self.rods.dipoles(
                        &unloading_dipole_b_am2(g.unload_per_s, &h_w, &Vector3::zeros(), &b),
                    ),
                    _ => self.rods_off(),
                };
                (Some(l), rods)
            }
        };
        let u = match wheel_torque_b {
            Some(l) => self.limited_motor_torques(&l),
            None => vec![0.0; self.wheels.effector_index.len()],
        };
        let mut inputs = self.wheels.inputs(&u);
        inputs.extend(self.rods.inputs(&dipole));
        Ok(Output {
            mode,
            transition,
            new_target_sigma_rn: new_target,
            inputs,
            wheel_momentum_b_nms: h_w,
            observation: obs,
            sigma_bn_estimate: sigma_bn,
            sun_b,
            target_sigma_rn: self.target_sigma_rn,
        })
    }

    fn transitions_len(&self) -> usize {
        self.modes.transitions().len()
    }

    fn rods_off(&self) -> Vec<f64> {
        vec![0.0; self.rods.effector_index.len()]
    }

    /// The detumble dipoles m = k_ω (ω × B)/|B|², each rod clipped to its limit; zero before
    /// the first field sample or in a zero field.
    fn detumble_dipoles(&self, rate_b: &Vector3<f64>) -> Vec<f64> {
        let Some(b) = self.last_b_b_t.filter(|b| b.norm_squared() > 0.0) else {
            return self.rods_off();
        };
        self.rods.dipoles_clipped(&gyro_bdot_dipole_b_am2(
            self.setup.gains.detumble_nms,
            rate_b,
            &b,
        ))
    }

    /// u = −[G_s]⁺ L, scaled down as a whole so that no wheel exceeds its torque limit.
    fn limited_motor_torques(&self, torque_b_nm: &Vector3<f64>) -> Vec<f64> {
        scaled_to_limits(
            &self.wheels.motor_torques(torque_b_nm),
            &self.wheel_max_torque_nm,
        )
    }
}

/// `u` scaled down as a whole (direction kept) so that no |u_j| exceeds `max[j]`; unchanged
/// when it fits.
pub fn scaled_to_limits(u: &[f64], max: &[f64]) -> Vec<f64> {
    let over = u
        .iter()
        .zip(max)
        .fold(1.0_f64, |s, (u, max)| s.max(u.abs() / max));
    u.iter().map(|x| x / over).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The target puts the panel normal exactly on the Sun: in R the Sun's components are the
    /// panel normal's, s_R = [RN] [NB] s_B = n̂. And it is the nearest such attitude: the
    /// rotation from B to R is the angle between n̂ and ŝ, not more.
    #[test]
    fn the_sun_pointing_target_puts_the_panel_normal_on_the_sun_by_the_smallest_turn() {
        let cases = [
            (
                Vector3::new(0.1, -0.2, 0.3),
                Vector3::z(),
                Vector3::new(0.3, 0.4, 0.5),
            ),
            (
                Vector3::new(-0.4, 0.05, 0.2),
                Vector3::new(1.0, 1.0, 0.0),
                Vector3::new(0.0, -1.0, 0.2),
            ),
            (Vector3::zeros(), Vector3::z(), Vector3::z()),
        ];
        for (sigma_bn, n_b, sun_b) in cases {
            let sigma_rn = AcsSequence::sun_pointing_target(&sigma_bn, &n_b, &sun_b);
            let dcm_bn = mrp_to_dcm(&sigma_bn);
            let sun_r = mrp_to_dcm(&sigma_rn) * dcm_bn.transpose() * sun_b.normalize();
            assert!(
                (sun_r - n_b.normalize()).norm() < 1e-12,
                "{sun_r:?} vs {n_b:?}"
            );
            let turn_rad = 4.0 * mrp_error(&sigma_bn, &sigma_rn).norm().atan();
            assert!((turn_rad - n_b.angle(&sun_b)).abs() < 1e-12, "{turn_rad}");
        }
    }

    /// Too large a request is scaled as a whole: the largest wheel sits at its limit and the
    /// ratios (so the body torque's direction) are kept; a request within the limits is kept.
    #[test]
    fn motor_torques_are_scaled_as_a_whole_to_the_limits() {
        let max = [0.2, 0.2, 0.1];
        let u = [0.3, -0.1, 0.1];
        let s = scaled_to_limits(&u, &max);
        // The worst ratio is 0.3/0.2 = 1.5 (wheel 0): it ends at its limit, the rest in
        // proportion.
        for (x, want) in s.iter().zip([0.2, -0.1 / 1.5, 0.1 / 1.5]) {
            assert!((x - want).abs() < 1e-15, "{s:?}");
        }
        let fits = [0.1, -0.2, 0.05];
        assert_eq!(scaled_to_limits(&fits, &max), fits);
    }
}
