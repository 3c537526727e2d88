//! The IMUs' typed view of a [`Simulation`]: their names, error models and points, and their
//! samples as [`ImuSample`]s, for tests, benchmarks and tools that want the IMU itself rather
//! than the generic sensor bank.

use std::num::NonZeroU64;

use super::{Imu, ImuSample, ImuSensor};
use crate::dynamics::SensorPoint;
use crate::sensors::Sensor;
use crate::sim::Simulation;

impl Simulation {
    /// The IMUs, in config order.
    pub fn imu_sensors(&self) -> impl Iterator<Item = &ImuSensor> {
        self.sensors().of::<ImuSensor>()
    }

    /// The IMU names in config order (topic `flexdyn/<sc-id>/tlm/imu/<name>`).
    pub fn imu_names(&self) -> Vec<&str> {
        self.imu_sensors().map(|s| s.name()).collect()
    }

    /// Number of IMUs.
    pub fn n_imus(&self) -> usize {
        self.imu_sensors().count()
    }

    /// The IMU error models, in config order.
    pub fn imus(&self) -> Vec<&Imu> {
        self.imu_sensors().map(ImuSensor::imu).collect()
    }

    /// Where each IMU sits (r_S/B) and how its platform is turned ([PB]), in config order.
    pub fn imu_points(&self) -> Vec<SensorPoint> {
        self.imu_sensors().map(|s| *s.point()).collect()
    }

    /// Sets every sensor's nominal sample interval T_s (default: the frame period); for an IMU,
    /// the instantaneous outputs carry white noise of standard deviation N/√T_s. `simulate` sets
    /// it to the log interval. It does not change where intervals end: that is when
    /// [`Self::imu_samples_into`] is called.
    pub fn set_imu_sample_interval_ns(&mut self, interval_ns: NonZeroU64) {
        self.set_sensor_sample_interval_ns(interval_ns);
    }

    /// Closes the current IMU sample interval at the current time and writes one measurement per
    /// IMU (config order) into `out` (cleared first; after the first call this allocates
    /// nothing). Then starts the next interval here. See [`ImuSensor`] for the truth.
    pub fn imu_samples_into(&mut self, out: &mut Vec<ImuSample>) {
        out.clear();
        self.sample_sensors(|s| s.as_any().is::<ImuSensor>());
        out.extend(self.imu_sensors().map(ImuSensor::last));
    }
}
