//! Each sensor kind's typed view of a [`Simulation`], for tests, benchmarks and tools that want
//! the sensor itself (an IMU's error model, a star tracker's last sample) rather than the generic
//! sensor bank. The vehicle owns these views: the sensor kinds know nothing of it.

use std::num::NonZeroU64;

use flexdyn_dynamics::SensorPoint;
use flexdyn_sensors::coarse_sun_sensor::CoarseSunSensor;
use flexdyn_sensors::fine_sun_sensor::FineSunSensor;
use flexdyn_sensors::gps::Gps;
use flexdyn_sensors::imu::{Imu, ImuSample, ImuSensor};
use flexdyn_sensors::magnetometer::Magnetometer;
use flexdyn_sensors::star_tracker::{StarTracker, StarTrackerSample};
use flexdyn_sensors::Sensor;

use super::Simulation;

// `flexdyn_sensors::imu`
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

    /// Where each IMU sits (r_S/B) and how its platform is turned (\[PB\]), in config order.
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

// `flexdyn_sensors::star_tracker`
impl Simulation {
    /// The star trackers, in config order (topic `flexdyn/<sc-id>/tlm/st/<name>`).
    pub fn star_trackers(&self) -> Vec<&StarTracker> {
        self.sensors().of::<StarTracker>().collect()
    }

    /// Samples every star tracker due at frame boundary `tick` (see [`StarTracker::due`]) at the
    /// current state, writing `(tracker index, sample)` pairs into `out` (cleared first; after
    /// the first call this allocates nothing).
    pub fn star_tracker_samples_into(
        &mut self,
        tick: u64,
        out: &mut Vec<(usize, StarTrackerSample)>,
    ) {
        out.clear();
        self.sample_sensors(|s| s.as_any().is::<StarTracker>() && s.due(tick));
        let bank = self.sensors();
        let first = bank
            .sensors()
            .iter()
            .position(|s| s.as_any().is::<StarTracker>())
            .unwrap_or(0);
        for &i in bank.sampled() {
            if let Some(st) = bank.sensors()[i].as_any().downcast_ref::<StarTracker>() {
                out.push((i - first, st.last()));
            }
        }
    }
}

// `flexdyn_sensors::magnetometer`
impl Simulation {
    /// The magnetometers, in config order (topic `flexdyn/<sc-id>/tlm/mag/<name>`).
    pub fn magnetometers(&self) -> Vec<&Magnetometer> {
        self.sensors().of::<Magnetometer>().collect()
    }
}

// `flexdyn_sensors::coarse_sun_sensor`
impl Simulation {
    /// The coarse-sun-sensor arrays, in config order (topic `flexdyn/<sc-id>/tlm/css/<name>`).
    pub fn coarse_sun_sensors(&self) -> Vec<&CoarseSunSensor> {
        self.sensors().of::<CoarseSunSensor>().collect()
    }
}

// `flexdyn_sensors::fine_sun_sensor`
impl Simulation {
    /// The fine sun sensors, in config order (topic `flexdyn/<sc-id>/tlm/fss/<name>`).
    pub fn fine_sun_sensors(&self) -> Vec<&FineSunSensor> {
        self.sensors().of::<FineSunSensor>().collect()
    }
}

// `flexdyn_sensors::gps`
impl Simulation {
    /// The GPS receivers, in config order (topic `flexdyn/<sc-id>/tlm/gps/<name>`).
    pub fn gps_receivers(&self) -> Vec<&Gps> {
        self.sensors().of::<Gps>().collect()
    }
}
