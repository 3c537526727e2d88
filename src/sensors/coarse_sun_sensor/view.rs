//! The coarse-sun-sensor arrays' typed view of a [`Simulation`], for tests and tools that want
//! the sensor itself rather than the generic sensor bank.

use super::CoarseSunSensor;
use crate::sim::Simulation;

impl Simulation {
    /// The coarse-sun-sensor arrays, in config order (topic `flexdyn/<sc-id>/tlm/css/<name>`).
    pub fn coarse_sun_sensors(&self) -> Vec<&CoarseSunSensor> {
        self.sensors().of::<CoarseSunSensor>().collect()
    }
}
