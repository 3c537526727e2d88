//! The IMUs of one spacecraft and their sample-interval bookkeeping: where the current interval
//! started (time and σ_B/N), the Δv each IMU integrates over it, and the closing of an interval
//! into one [`ImuSample`] per IMU.
//!
//! Δv is integrated by the bank itself, as a [`StageHook`] of the spacecraft's integrator: at
//! every stage it stores the specific force at each IMU (platform components), and at the end of
//! the step adds the integrator's combination of those stage values ([`StageCombine`]) — the
//! same combination, in the same operation order, as the state's, so Δv is exact to integrator
//! precision and no other layer keeps IMU state.

use nalgebra::Vector3;

use super::{attitude_increment_b, Imu, ImuConfig, ImuParamError, ImuSample, ImuTruth};
use crate::dynamics::stage_hook::{StageCombine, StageHook, MAX_STAGES};
use crate::dynamics::{specific_force_b, HubOutputs, SensorPoint, Spacecraft, State};

/// The IMUs in config order and the current sample interval.
#[derive(Debug, Clone)]
pub struct ImuBank {
    imus: Vec<Imu>,
    names: Vec<String>,
    /// Where each IMU sits (r_S/B) and how its platform is turned ([PB]).
    points: Vec<SensorPoint>,
    /// \[m/s\] per IMU, Δv_P = ∫ [PB] f_B dt since the interval started.
    dv_p_m_s: Vec<Vector3<f64>>,
    /// \[m/s²\] per IMU, the specific force in P at each stage of the current step.
    stage_f_p_m_s2: Vec<[Vector3<f64>; MAX_STAGES]>,
    /// \[ns\] start of the current sample interval.
    interval_start_ns: u64,
    /// σ_B/N at the start of the current sample interval.
    sigma_bn_start: Vector3<f64>,
}

impl ImuBank {
    /// The IMUs of `cfgs` (errors name `imus[i]…`), with the first interval starting at `sc`'s
    /// current state and a nominal sample interval of `sample_interval_s`.
    pub fn new(
        cfgs: &[ImuConfig],
        sample_interval_s: f64,
        sc: &Spacecraft,
    ) -> Result<Self, ImuParamError> {
        let mut imus = Vec::with_capacity(cfgs.len());
        for (i, imu) in cfgs.iter().enumerate() {
            imus.push(Imu::new(imu, &format!("imus[{i}]"), sample_interval_s)?);
        }
        Ok(Self {
            imus,
            names: cfgs.iter().map(|c| c.name.clone()).collect(),
            points: cfgs.iter().map(ImuConfig::sensor_point).collect(),
            dv_p_m_s: vec![Vector3::zeros(); cfgs.len()],
            stage_f_p_m_s2: vec![[Vector3::zeros(); MAX_STAGES]; cfgs.len()],
            interval_start_ns: sc.t_sim_ns(),
            sigma_bn_start: sc.state().sigma_bn,
        })
    }

    /// The IMU names in config order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The IMU error models in config order.
    pub fn imus(&self) -> &[Imu] {
        &self.imus
    }

    /// Where each IMU sits and how its platform is turned, in config order.
    pub fn points(&self) -> &[SensorPoint] {
        &self.points
    }

    /// \[m/s\] the Δv each IMU has integrated since the current interval started, P components.
    pub fn dv_p_m_s(&self) -> &[Vector3<f64>] {
        &self.dv_p_m_s
    }

    /// \[ns\] start of the current sample interval.
    pub fn interval_start_ns(&self) -> u64 {
        self.interval_start_ns
    }

    /// Sets every IMU's nominal sample interval T_s \[s\] (finite, > 0).
    pub fn set_sample_interval_s(&mut self, t_s: f64) {
        for imu in &mut self.imus {
            // Cannot fail for a finite positive T_s (the caller's contract).
            let _ = imu.set_sample_interval_s(t_s);
        }
    }

    /// Closes the current interval at `sc`'s state with the frame's hub outputs `hub` (the one
    /// evaluation shared with the snapshot) and writes one sample per IMU into `out` (cleared
    /// first; allocation-free after the first call); then starts the next interval.
    pub fn sample_into(&mut self, sc: &Spacecraft, hub: &HubOutputs, out: &mut Vec<ImuSample>) {
        out.clear();
        if self.imus.is_empty() {
            return;
        }
        let t_ns = sc.t_sim_ns();
        let dt_s = t_ns.saturating_sub(self.interval_start_ns) as f64 * 1e-9;
        let dtheta_b = attitude_increment_b(&self.sigma_bn_start, &sc.state().sigma_bn);
        for ((imu, point), dv_p) in self.imus.iter_mut().zip(&self.points).zip(&self.dv_p_m_s) {
            let (omega_p, accel_p) = sensor_truth(point, sc.state(), hub);
            let truth = ImuTruth {
                omega_p_rad_s: omega_p,
                accel_p_m_s2: accel_p,
                dtheta_p_rad: imu.dcm_pb() * dtheta_b,
                dv_p_m_s: *dv_p,
            };
            out.push(imu.sample(&truth, dt_s));
        }
        self.restart(sc);
    }

    /// Starts a new interval at `sc`'s state without sampling (discards the accumulated Δv).
    pub fn restart(&mut self, sc: &Spacecraft) {
        self.dv_p_m_s.fill(Vector3::zeros());
        self.interval_start_ns = sc.t_sim_ns();
        self.sigma_bn_start = sc.state().sigma_bn;
    }
}

impl StageHook for ImuBank {
    /// Specific force at each IMU, in its platform frame:
    /// f = a_B,nongrav + ω̇ × r_S/B + ω × (ω × r_S/B) ([`specific_force_b`]).
    #[inline]
    fn stage(&mut self, stage: usize, x: &State, hub: &HubOutputs) {
        for (point, k) in self.points.iter().zip(&mut self.stage_f_p_m_s2) {
            if let Some(k) = k.get_mut(stage) {
                *k = point.dcm_pb
                    * specific_force_b(
                        &hub.nongrav_accel_bn_b,
                        &x.omega_bn_b,
                        &hub.omega_dot_bn_b,
                        &point.r_sb_b_m,
                    );
            }
        }
    }

    #[inline]
    fn end_step(&mut self, combine: &StageCombine) {
        for (dv, k) in self.dv_p_m_s.iter_mut().zip(&self.stage_f_p_m_s2) {
            *dv += combine.vec3(k);
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
