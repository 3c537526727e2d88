//! The magnetometers' typed view of a [`Simulation`], for tests and tools that want the sensor
//! itself rather than the generic sensor bank.

use super::Magnetometer;
use crate::sim::Simulation;

impl Simulation {
    /// The magnetometers, in config order (topic `flexdyn/<sc-id>/tlm/mag/<name>`).
    pub fn magnetometers(&self) -> Vec<&Magnetometer> {
        self.sensors().of::<Magnetometer>().collect()
    }
}
