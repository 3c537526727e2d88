//! The sensors of one spacecraft, in registry order ([`super::KINDS`]) then config order: built
//! from a [`SensorBuild`] through each kind's [`super::SensorKind::build`], sampled together
//! from one [`Truth`], and the integrator's stage hook for those that integrate over the stages.

use super::{Sensor, SensorBuild, Truth, KINDS};
use flexdyn_dynamics::stage_hook::{StageCombine, StageHook};
use flexdyn_dynamics::{HubOutputs, State};
use flexdyn_kernel::schema::config_error::ConfigError;

/// The sensors and which of them the last [`Self::sample`] sampled.
#[derive(Debug)]
pub struct SensorBank {
    sensors: Vec<Box<dyn Sensor>>,
    /// Indices of the sensors that use the stage hook.
    staged: Vec<usize>,
    /// Indices sampled by the last [`Self::sample`] (capacity: every sensor).
    sampled: Vec<usize>,
}

impl SensorBank {
    /// Lists every sensor's mutable state in its own section (named by kind and name), and
    /// which sensors the last sample took, for a checkpoint. Not on the stepping path.
    pub fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        a.section("sensors", |a| {
            a.expect_count("sensors", self.sensors.len());
            for s in &mut self.sensors {
                let name = format!("{} {}", s.kind().config_array, s.name());
                a.section(&name, |a| s.archive(a));
            }
            let mut n = self.sampled.len();
            a.length("sensors sampled last", &mut n, self.sensors.len());
            self.sampled.resize(n, 0);
            for i in &mut self.sampled {
                let mut v = *i as u64;
                a.put(&mut v);
                *i = (v as usize).min(self.sensors.len().saturating_sub(1));
            }
        });
    }

    /// Every registered kind's sensors of `ctx` ([`SensorBuild`]).
    pub fn new(ctx: &SensorBuild<'_>) -> Result<Self, ConfigError> {
        let mut sensors = Vec::new();
        for kind in KINDS {
            (kind.build)(ctx, &mut sensors)?;
        }
        let staged = (0..sensors.len())
            .filter(|&i| sensors[i].uses_stages())
            .collect();
        Ok(Self {
            sampled: Vec::with_capacity(sensors.len()),
            staged,
            sensors,
        })
    }

    /// Every sensor, in publication order.
    pub fn sensors(&self) -> &[Box<dyn Sensor>] {
        &self.sensors
    }

    /// Number of sensors.
    pub fn len(&self) -> usize {
        self.sensors.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.sensors.is_empty()
    }

    /// The sensors of concrete type `T` (one kind's typed view), in order.
    pub fn of<T: 'static>(&self) -> impl Iterator<Item = &T> {
        self.sensors
            .iter()
            .filter_map(|s| s.as_any().downcast_ref())
    }

    /// Whether any sensor is picked by `pick`.
    pub fn any(&self, pick: impl Fn(&dyn Sensor) -> bool) -> bool {
        self.sensors.iter().any(|s| pick(s.as_ref()))
    }

    /// Samples every sensor that `pick` selects from `truth` and notes which (see
    /// [`Self::sampled`]). Allocates nothing.
    pub fn sample(&mut self, truth: &Truth<'_>, pick: impl Fn(&dyn Sensor) -> bool) {
        self.sampled.clear();
        for (i, s) in self.sensors.iter_mut().enumerate() {
            if pick(s.as_ref()) {
                s.sample(truth);
                if s.has_output() {
                    self.sampled.push(i);
                }
            }
        }
    }

    /// Sensor `i`, mutably (the fault port, `flexdyn_faults`).
    pub fn sensor_mut(&mut self, i: usize) -> &mut dyn Sensor {
        self.sensors[i].as_mut()
    }

    /// Removes sensor `i` from the last sample's list: it publishes nothing this time (a
    /// `dropout` fault).
    pub fn unsample(&mut self, i: usize) {
        self.sampled.retain(|&k| k != i);
    }

    /// Notes that nothing was sampled.
    pub fn clear_sampled(&mut self) {
        self.sampled.clear();
    }

    /// Indices of the sensors the last [`Self::sample`] sampled and that have a message to
    /// publish ([`super::Sensor::has_output`]), in order.
    pub fn sampled(&self) -> &[usize] {
        &self.sampled
    }

    /// The first non-finite output among the last samples, as `(sensor, output)`.
    pub fn first_non_finite(&self) -> Option<(&dyn Sensor, &'static str)> {
        self.sampled.iter().find_map(|&i| {
            let s = self.sensors[i].as_ref();
            s.first_non_finite().map(|q| (s, q))
        })
    }

    /// Starts a new interval at the current instant on every sensor, without sampling.
    pub fn restart(&mut self, t_sim_ns: u64, x: &State) {
        for s in &mut self.sensors {
            s.restart(t_sim_ns, x);
        }
    }

    /// Sets every sensor's nominal sample interval \[s\] (finite, > 0).
    pub fn set_sample_interval_s(&mut self, t_s: f64) {
        for s in &mut self.sensors {
            s.set_sample_interval_s(t_s);
        }
    }
}

impl StageHook for SensorBank {
    #[inline]
    fn stage(&mut self, stage: usize, x: &State, hub: &HubOutputs) {
        for &i in &self.staged {
            self.sensors[i].stage(stage, x, hub);
        }
    }

    #[inline]
    fn end_step(&mut self, combine: &StageCombine) {
        for &i in &self.staged {
            self.sensors[i].end_step(combine);
        }
    }
}
