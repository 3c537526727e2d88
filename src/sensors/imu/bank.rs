//! The IMUs of one spacecraft and their sample-interval bookkeeping: where the current interval
//! started (time and σ_B/N) and the closing of an interval into one [`ImuSample`] per IMU.
//!
//! IMU `i` is the spacecraft's sensor point `i`, whose Δv the RK4 integration accumulates
//! ([`Spacecraft::sensor_dv_p`]); the bank reads and resets those accumulators when it closes an
//! interval, so no other layer keeps IMU state.

use nalgebra::Vector3;

use super::{attitude_increment_b, Imu, ImuConfig, ImuParamError, ImuSample, ImuTruth};
use crate::dynamics::{HubOutputs, Spacecraft};

/// The IMUs in config order and the current sample interval.
#[derive(Debug, Clone)]
pub struct ImuBank {
    imus: Vec<Imu>,
    names: Vec<String>,
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
    pub fn sample_into(&mut self, sc: &mut Spacecraft, hub: &HubOutputs, out: &mut Vec<ImuSample>) {
        out.clear();
        if self.imus.is_empty() {
            return;
        }
        let t_ns = sc.t_sim_ns();
        let dt_s = t_ns.saturating_sub(self.interval_start_ns) as f64 * 1e-9;
        let dtheta_b = attitude_increment_b(&self.sigma_bn_start, &sc.state().sigma_bn);
        for (i, imu) in self.imus.iter_mut().enumerate() {
            let (omega_p, accel_p) = sc.sensor_truth(i, hub);
            let truth = ImuTruth {
                omega_p_rad_s: omega_p,
                accel_p_m_s2: accel_p,
                dtheta_p_rad: imu.dcm_pb() * dtheta_b,
                dv_p_m_s: sc.sensor_dv_p()[i],
            };
            out.push(imu.sample(&truth, dt_s));
        }
        self.restart(sc);
    }

    /// Starts a new interval at `sc`'s state without sampling (discards the accumulated Δv).
    pub fn restart(&mut self, sc: &mut Spacecraft) {
        sc.reset_sensor_dv();
        self.interval_start_ns = sc.t_sim_ns();
        self.sigma_bn_start = sc.state().sigma_bn;
    }
}
