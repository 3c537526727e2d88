//! The GPS receivers' typed view of a [`Simulation`], for tests and tools that want the sensor
//! itself rather than the generic sensor bank.

use super::Gps;
use crate::sim::Simulation;

impl Simulation {
    /// The GPS receivers, in config order (topic `flexdyn/<sc-id>/tlm/gps/<name>`).
    pub fn gps_receivers(&self) -> Vec<&Gps> {
        self.sensors().of::<Gps>().collect()
    }
}
