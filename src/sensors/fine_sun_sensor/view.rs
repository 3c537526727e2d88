//! The fine sun sensors' typed view of a [`Simulation`], for tests and tools that want the
//! sensor itself rather than the generic sensor bank.

use super::FineSunSensor;
use crate::sim::Simulation;

impl Simulation {
    /// The fine sun sensors, in config order (topic `flexdyn/<sc-id>/tlm/fss/<name>`).
    pub fn fine_sun_sensors(&self) -> Vec<&FineSunSensor> {
        self.sensors().of::<FineSunSensor>().collect()
    }
}
