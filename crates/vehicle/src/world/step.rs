//! The world: N vehicles on one tick.
//!
//! A [`Vehicle`] is one [`Simulation`] (spacecraft, sensors, environment, commands) with its id.
//! The [`World`] steps every vehicle over the same frame, in fleet order. The vehicles do not
//! act on one another (no contact or plume forces), so the order does not change any vehicle's
//! state: each vehicle's stream is what it would be alone, bit for bit.
//!
//! The environment is evaluated per vehicle, by each vehicle's own models (on its prefetch
//! worker where the server offloads them), for its own position. What does not depend on the
//! position, the Earth's orientation, the Sun and the Moon at an update instant (the fleet file
//! gives every vehicle the same epoch), is evaluated once for the world: the vehicles' models
//! share one [`CommonCache`], and the first vehicle to reach an instant fills it for the others
//! ([`flexdyn_environment::common`]; the samples are the same bits either way).

use std::sync::Arc;

use crate::sim::Simulation;
use flexdyn_environment::common::CommonCache;

use super::fleet::{FleetConfig, FleetError};
use super::relative::{com_state_n, relative_state_hill, RelativeState};

/// One spacecraft of the world.
#[derive(Debug)]
pub struct Vehicle {
    /// Its id (`flexdyn/<id>/…`).
    pub id: String,
    /// `header.spacecraft_id` of its messages.
    pub spacecraft_id: u32,
    /// Its lockstep participants (sender ids).
    pub participants: Vec<u32>,
    /// Its simulation.
    pub sim: Simulation,
}

/// N vehicles stepped on one tick.
#[derive(Debug)]
pub struct World {
    vehicles: Vec<Vehicle>,
    /// (chief, deputy) index pairs: every vehicle given relative to a chief.
    pairs: Vec<(usize, usize)>,
    /// RK4 steps per frame (the same for every vehicle: the fleet file checks it).
    steps_per_frame: u64,
    /// The environment's shared part, when two or more vehicles have an environment.
    common: Option<Arc<CommonCache>>,
}

impl World {
    /// Builds every vehicle at t = 0. An error names the vehicle.
    pub fn new(fleet: &FleetConfig) -> Result<Self, FleetError> {
        let mut vehicles = Vec::with_capacity(fleet.vehicles.len());
        let mut pairs = Vec::new();
        for (i, v) in fleet.vehicles.iter().enumerate() {
            let sim = Simulation::new(&v.cfg).map_err(|source| FleetError::Spacecraft {
                vehicle: format!("vehicles[{i}] ({:?})", v.id),
                what: "spacecraft".into(),
                source: Box::new(source),
            })?;
            if let Some(c) = v.chief {
                pairs.push((c, i));
            }
            vehicles.push(Vehicle {
                id: v.id.clone(),
                spacecraft_id: v.spacecraft_id,
                participants: v.participants.clone(),
                sim,
            });
        }
        let steps_per_frame = vehicles.first().map_or(0, |v| v.sim.steps_per_frame());
        let models: Vec<_> = vehicles
            .iter()
            .filter_map(|v| v.sim.environment())
            .collect();
        let common = (models.len() > 1).then(|| {
            let cache = Arc::new(CommonCache::new());
            for m in &models {
                m.share_common(cache.clone());
            }
            cache
        });
        Ok(Self {
            vehicles,
            pairs,
            steps_per_frame,
            common,
        })
    }

    /// A world of one spacecraft: `sim` under id `id`, its messages carrying `spacecraft_id`
    /// (what `flexdyn simulate` steps).
    pub fn of_one(id: String, spacecraft_id: u32, sim: Simulation) -> Self {
        let steps_per_frame = sim.steps_per_frame();
        Self {
            vehicles: vec![Vehicle {
                id,
                spacecraft_id,
                participants: Vec::new(),
                sim,
            }],
            pairs: Vec::new(),
            steps_per_frame,
            common: None,
        }
    }

    /// RK4 steps per frame (every vehicle's).
    pub fn steps_per_frame(&self) -> u64 {
        self.steps_per_frame
    }

    /// (hits, misses) of the shared environment part ([`CommonCache::counts`]); `None` when
    /// fewer than two vehicles have an environment.
    pub fn common_environment_counts(&self) -> Option<(u64, u64)> {
        self.common.as_ref().map(|c| c.counts())
    }

    /// The vehicles, in fleet order.
    pub fn vehicles(&self) -> &[Vehicle] {
        &self.vehicles
    }

    /// The vehicles, taken out of the world (the server steps each with its own command book
    /// and telemetry, on one physics thread: `flexdyn_server::fleet`).
    pub fn into_vehicles(self) -> Vec<Vehicle> {
        self.vehicles
    }

    /// The vehicles, mutably (to command them).
    pub fn vehicles_mut(&mut self) -> &mut [Vehicle] {
        &mut self.vehicles
    }

    /// Moves each vehicle's environment updates to a worker thread of its own
    /// ([`Simulation::offload_environment`]), so the models never run on the stepping thread. The
    /// samples are the same bits either way, so a vehicle whose worker cannot be spawned keeps
    /// its updates on the stepping thread, with a warning, and only runs slower.
    pub fn offload_environments(&mut self) {
        for v in &mut self.vehicles {
            if let Err(e) = v.sim.offload_environment() {
                tracing::warn!(vehicle = %v.id, error = %e, "environment updates stay on the stepping thread");
            }
        }
    }

    /// \[ns\] simulation time (every vehicle's).
    pub fn t_sim_ns(&self) -> u64 {
        self.vehicles.first().map_or(0, |v| v.sim.t_sim_ns())
    }

    /// One frame of every vehicle. Allocates nothing.
    pub fn step_frame(&mut self) {
        for _ in 0..self.steps_per_frame {
            self.step();
        }
    }

    /// One RK4 step of every vehicle. Allocates nothing.
    pub fn step(&mut self) {
        for v in &mut self.vehicles {
            v.sim.step();
        }
    }

    /// `n` RK4 steps of every vehicle, in step with one another (so the vehicles reach each
    /// environment update instant together, and the shared part is computed once for them).
    /// Allocates nothing.
    pub fn step_n(&mut self, n: u64) {
        // A world of one steps its simulation straight: the same bits, and measured 7 % faster
        // on `scenarios/acs_full.toml` than going through the per-step loop below.
        if let [v] = self.vehicles.as_mut_slice() {
            v.sim.step_n(n);
            return;
        }
        for _ in 0..n {
            self.step();
        }
    }

    /// Lists every vehicle's mutable state, each in a section named by its id, for a
    /// checkpoint ([`crate::checkpoint`]). The shared environment part is a cache (the same bits
    /// whoever fills it) and is not listed. Not on the stepping path.
    pub fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        a.section("world", |a| {
            a.expect_count("vehicles", self.vehicles.len());
            for v in &mut self.vehicles {
                let name = format!("vehicle {}", v.id);
                a.section(&name, |a| v.sim.archive(a));
            }
        });
    }

    /// The (chief, deputy) pairs of the fleet file's `relative` tables.
    pub fn relative_pairs(&self) -> &[(usize, usize)] {
        &self.pairs
    }

    /// Vehicle `deputy`'s centre of mass relative to vehicle `chief`'s, in the chief's Hill
    /// frame. `None` for an index out of range, or a chief without an orbit plane.
    pub fn relative_state(&self, chief: usize, deputy: usize) -> Option<RelativeState> {
        let c = self.vehicles.get(chief)?;
        let d = self.vehicles.get(deputy)?;
        let (r_c, v_c) = com_state_n(c.sim.spacecraft());
        let (r_d, v_d) = com_state_n(d.sim.spacecraft());
        relative_state_hill(&r_c, &v_c, &r_d, &v_d)
    }
}
