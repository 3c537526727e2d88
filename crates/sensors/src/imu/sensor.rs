//! One IMU on the sensor contract ([`crate::Sensor`]): its error model, where it sits,
//! its sample-interval bookkeeping (where the current interval started: time and σ_B/N), the Δv
//! it integrates over the interval, and its last sample.
//!
//! Δv is integrated by the IMU itself, through the integrator's stage hook: at every stage it
//! stores the specific force at its point (platform components), and at the end of the step adds
//! the integrator's combination of those stage values ([`StageCombine`]) — the same combination,
//! in the same operation order, as the state's, so Δv is exact to integrator precision and the
//! hub state holds nothing of the IMU.

use std::any::Any;

use flexdyn_proto::{encode_into, Header};
use nalgebra::Vector3;

use super::{attitude_increment_b, Imu, ImuConfig, ImuParamError, ImuSample, ImuTruth, KIND};
use crate::{Sensor, SensorKind, Truth};
use flexdyn_dynamics::stage_hook::{StageCombine, MAX_STAGES};
use flexdyn_dynamics::{specific_force_b, HubOutputs, SensorPoint, State};

/// One IMU and its current sample interval.
#[derive(Debug, Clone)]
pub struct ImuSensor {
    imu: Imu,
    /// Where it sits (r_S/B) and how its platform is turned ([PB]).
    point: SensorPoint,
    /// \[m/s\] Δv_P = ∫ [PB] f_B dt since the interval started.
    dv_p_m_s: Vector3<f64>,
    /// \[m/s²\] the specific force in P at each stage of the current step.
    stage_f_p_m_s2: [Vector3<f64>; MAX_STAGES],
    /// \[ns\] start of the current sample interval.
    interval_start_ns: u64,
    /// σ_B/N at the start of the current sample interval.
    sigma_bn_start: Vector3<f64>,
    /// The last sample (zero before the first).
    last: ImuSample,
}

impl ImuSensor {
    /// The IMU of `cfg` (errors name `path`, e.g. `imus[0]`) with a nominal sample interval of
    /// `sample_interval_s`, its first interval starting at `t_sim_ns` and state `x`.
    pub fn new(
        cfg: &ImuConfig,
        path: &str,
        sample_interval_s: f64,
        t_sim_ns: u64,
        x: &State,
    ) -> Result<Self, ImuParamError> {
        Ok(Self {
            imu: Imu::new(cfg, path, sample_interval_s)?,
            point: cfg.sensor_point(),
            dv_p_m_s: Vector3::zeros(),
            stage_f_p_m_s2: [Vector3::zeros(); MAX_STAGES],
            interval_start_ns: t_sim_ns,
            sigma_bn_start: x.sigma_bn,
            last: ImuSample::default(),
        })
    }

    /// The error model.
    pub fn imu(&self) -> &Imu {
        &self.imu
    }

    /// Where it sits and how its platform is turned.
    pub fn point(&self) -> &SensorPoint {
        &self.point
    }

    /// \[m/s\] the Δv integrated since the current interval started, P components.
    pub fn dv_p_m_s(&self) -> Vector3<f64> {
        self.dv_p_m_s
    }

    /// \[ns\] start of the current sample interval.
    pub fn interval_start_ns(&self) -> u64 {
        self.interval_start_ns
    }

    /// The last sample (zero before the first).
    pub fn last(&self) -> ImuSample {
        self.last
    }
}

impl Sensor for ImuSensor {
    fn kind(&self) -> &'static SensorKind {
        &KIND
    }

    fn name(&self) -> &str {
        self.imu.name()
    }

    /// The error terms ([`Imu::parameters`]) and the position `r_sb_b_m[i]`.
    fn parameters(&self, out: &mut Vec<(String, f64)>) {
        self.imu.parameters(out);
        for i in 0..3 {
            out.push((format!("r_sb_b_m[{i}]"), self.point.r_sb_b_m[i]));
        }
    }

    /// Every frame (it closes its interval whenever it is sampled).
    fn due(&self, _tick: u64) -> bool {
        true
    }

    fn every_output(&self) -> bool {
        true
    }

    /// Closes the current interval at `truth` and starts the next: rate and specific force at
    /// the instant, Δθ from σ_B/N at the interval's start and now, Δv from the stage hook; the
    /// error model is stepped with dt = the interval's length (0 for a first call at the
    /// interval's start, whose Δθ and Δv are exactly zero).
    fn sample(&mut self, truth: &Truth<'_>) {
        let dt_s = truth.t_sim_ns.saturating_sub(self.interval_start_ns) as f64 * 1e-9;
        let dtheta_b = attitude_increment_b(&self.sigma_bn_start, &truth.state.sigma_bn);
        let (omega_p, accel_p) = sensor_truth(&self.point, truth.state, truth.hub);
        let imu_truth = ImuTruth {
            omega_p_rad_s: omega_p,
            accel_p_m_s2: accel_p,
            dtheta_p_rad: self.imu.dcm_pb() * dtheta_b,
            dv_p_m_s: self.dv_p_m_s,
        };
        self.last = self.imu.sample(&imu_truth, dt_s);
        self.restart(truth.t_sim_ns, truth.state);
    }

    fn encode(&self, header: Header, buf: &mut Vec<u8>) {
        encode_into(&self.last.to_msg(header), buf);
    }

    fn first_non_finite(&self) -> Option<&'static str> {
        self.last.first_non_finite()
    }

    fn uses_stages(&self) -> bool {
        true
    }

    /// Specific force at the IMU, in its platform frame:
    /// f = a_B,nongrav + ω̇ × r_S/B + ω × (ω × r_S/B) ([`specific_force_b`]).
    #[inline]
    fn stage(&mut self, stage: usize, x: &State, hub: &HubOutputs) {
        if let Some(k) = self.stage_f_p_m_s2.get_mut(stage) {
            *k = self.point.dcm_pb
                * specific_force_b(
                    &hub.nongrav_accel_bn_b,
                    &x.omega_bn_b,
                    &hub.omega_dot_bn_b,
                    &self.point.r_sb_b_m,
                );
        }
    }

    #[inline]
    fn end_step(&mut self, combine: &StageCombine) {
        self.dv_p_m_s += combine.vec3(&self.stage_f_p_m_s2);
    }

    /// Discards the accumulated Δv and starts the interval here.
    fn restart(&mut self, t_sim_ns: u64, x: &State) {
        self.dv_p_m_s = Vector3::zeros();
        self.interval_start_ns = t_sim_ns;
        self.sigma_bn_start = x.sigma_bn;
    }

    fn set_sample_interval_s(&mut self, t_s: f64) {
        // Cannot fail for a finite positive T_s (the caller's contract).
        let _ = self.imu.set_sample_interval_s(t_s);
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    /// The error model, the Δv and the stage values of the interval under way, where the
    /// interval started, and the last sample.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            imu,
            point: _,
            dv_p_m_s,
            stage_f_p_m_s2,
            interval_start_ns,
            sigma_bn_start,
            last,
        } = self;
        imu.archive(a);
        a.put(dv_p_m_s);
        a.put(stage_f_p_m_s2);
        a.put(interval_start_ns);
        a.put(sigma_bn_start);
        last.archive(a);
    }

    /// `gyro` (ω, rad/s), `accel` (specific force, m/s²), `dtheta` (Δθ, rad), `dv` (Δv, m/s),
    /// each in P.
    fn fault_channels(&self) -> &'static [&'static str] {
        &["gyro", "accel", "dtheta", "dv"]
    }

    fn fault_axes(&self, channel: usize) -> usize {
        if channel < 4 {
            3
        } else {
            0
        }
    }

    fn fault_channel(&mut self, channel: usize) -> &mut [f64] {
        let s = &mut self.last;
        match channel {
            0 => s.omega_p_rad_s.as_mut_slice(),
            1 => s.accel_p_m_s2.as_mut_slice(),
            2 => s.dtheta_p_rad.as_mut_slice(),
            3 => s.dv_p_m_s.as_mut_slice(),
            _ => &mut [],
        }
    }
}

/// Truth at the IMU at `point` given the state `x` and its hub outputs `hub`: (\[rad/s\] ω_B/N
/// in P, \[m/s²\] specific force in P).
pub fn sensor_truth(
    point: &SensorPoint,
    x: &State,
    hub: &HubOutputs,
) -> (Vector3<f64>, Vector3<f64>) {
    let w = &x.omega_bn_b;
    (
        point.dcm_pb * w,
        point.dcm_pb
            * specific_force_b(
                &hub.nongrav_accel_bn_b,
                w,
                &hub.omega_dot_bn_b,
                &point.r_sb_b_m,
            ),
    )
}
