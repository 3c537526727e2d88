//! The star trackers' typed view of a [`Simulation`], for tests, benchmarks and tools that want
//! the tracker itself rather than the generic sensor bank.

use super::{StarTracker, StarTrackerSample};
use crate::sim::Simulation;

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
