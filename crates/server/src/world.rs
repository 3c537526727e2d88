//! The per-frame work of a world: every vehicle's [`Stepper`] (its simulation, command book and
//! held command) and the telemetry buffer it fills, stepped on one tick. One spacecraft is a
//! world of one; a fleet file is a world of many. Nothing here allocates after
//! [`WorldStepper::new`] (checked in `tests/server_alloc.rs`).
//!
//! The vehicles do not act on one another ([`flexdyn_vehicle::world::step`]), so each vehicle's
//! stream is the one it would have alone, bit for bit, whatever the world's order or size.
//!
//! Each (chief, deputy) pair of a fleet file ([`flexdyn_vehicle::world::World::relative_pairs`])
//! gets its [`RelativeStateMsg`] filled with the frames, from the two vehicles' states of the
//! same tick ([`flexdyn_vehicle::world::relative`]): a few dozen flops per pair, no allocation.

use flexdyn_proto::{CommandMsg, Header, RelativeStateMsg};

use super::commands::Offer;
use super::error::ServerError;
use super::settings::ServerSettings;
use super::shared::Frame;
use super::stepper::Stepper;
use flexdyn_vehicle::world::relative::{com_state_n, relative_state_hill};
use flexdyn_vehicle::world::Vehicle;

/// One vehicle of the running world.
pub struct WorldVehicle {
    /// Its id (`flexdyn/<id>/…`).
    pub id: String,
    /// Its simulation, command book and held command.
    pub stepper: Stepper,
    /// The telemetry buffer of its last tick filled. A vehicle that publishes in place (a
    /// fleet's) always has one; a vehicle whose buffers cycle through a telemetry thread (one
    /// spacecraft's server) has one between the fill and the frame boundary, and none when real
    /// time found no free buffer (that tick's telemetry is dropped and counted).
    pub frame: Option<Box<Frame>>,
}

/// A (chief, deputy) pair of the running world and its relative state of the last tick filled.
pub struct RelativePair {
    /// The chief's index in [`WorldStepper::vehicles`].
    pub chief: usize,
    /// The deputy's index (listed after its chief).
    pub deputy: usize,
    /// The deputy's state relative to the chief at the last tick filled (published on
    /// `flexdyn/<deputy>/tlm/rel/<chief>` after the deputy's frame).
    pub msg: RelativeStateMsg,
}

/// Every vehicle of the world, stepped together.
pub struct WorldStepper {
    /// The vehicles, in world order.
    pub vehicles: Vec<WorldVehicle>,
    /// The (chief, deputy) pairs, in the deputies' world order.
    pub pairs: Vec<RelativePair>,
}

/// A telemetry buffer shaped for `stepper`'s state, sensors and fault events.
pub fn frame_for(stepper: &Stepper) -> Box<Frame> {
    frame_for_sim(&stepper.sim)
}

/// A telemetry buffer shaped for `sim`'s state, sensors and fault events (room for the events
/// a frame can carry: its configured and live slots).
pub fn frame_for_sim(sim: &flexdyn_vehicle::sim::Simulation) -> Box<Frame> {
    Box::new(
        Frame::for_state(&sim.blank_state(), sim.sensors().len())
            .with_fault_events(sim.faults().event_capacity()),
    )
}

impl WorldStepper {
    /// Steppers at t = 0 (sensors sampled at tick 0), each with its own telemetry buffer;
    /// `settings[i]` are vehicle `i`'s (its participants and spacecraft id).
    pub fn new(vehicles: Vec<Vehicle>, settings: &[ServerSettings]) -> Self {
        let vehicles = vehicles
            .into_iter()
            .zip(settings)
            .map(|(v, s)| {
                let stepper = Stepper::new(v.sim, s);
                WorldVehicle {
                    id: v.id,
                    frame: Some(frame_for(&stepper)),
                    stepper,
                }
            })
            .collect();
        Self {
            vehicles,
            pairs: Vec::new(),
        }
    }

    /// A world of one spacecraft whose telemetry buffers come from a pool (the physics loop
    /// takes one before each fill).
    pub fn one(id: String, stepper: Stepper) -> Self {
        Self {
            vehicles: vec![WorldVehicle {
                id,
                stepper,
                frame: None,
            }],
            pairs: Vec::new(),
        }
    }

    /// With the relative states of these (chief, deputy) index pairs
    /// ([`flexdyn_vehicle::world::World::relative_pairs`]); a pair naming a vehicle out of
    /// range is left out.
    pub fn with_relative_pairs(mut self, pairs: &[(usize, usize)]) -> Self {
        let n = self.vehicles.len();
        self.pairs = pairs
            .iter()
            .filter(|&&(c, d)| c < n && d < n && c != d)
            .map(|&(chief, deputy)| RelativePair {
                chief,
                deputy,
                msg: RelativeStateMsg::default(),
            })
            .collect();
        self
    }

    /// Lockstep: tick `k` begins; every participant of every vehicle owes an answer (a
    /// participant whose command link is faulted `dropped` counts as answered with nothing).
    pub fn begin_tick(&mut self, k: u64) {
        for v in &mut self.vehicles {
            v.stepper.book.begin_tick(k);
        }
    }

    /// Whether every participant of every vehicle has answered the current tick.
    pub fn all_answered(&self) -> bool {
        self.vehicles.iter().all(|v| v.stepper.book.all_answered())
    }

    /// The first vehicle (index) with a participant that has not answered, and that
    /// participant's sender id.
    pub fn first_unanswered(&self) -> Option<(usize, u32)> {
        self.vehicles
            .iter()
            .enumerate()
            .find_map(|(i, v)| v.stepper.book.first_unanswered().map(|p| (i, p)))
    }

    /// Lockstep: offers `cmd` to vehicle `vehicle`'s book as its answer to tick `k`.
    pub fn offer_lockstep(&mut self, vehicle: usize, cmd: &CommandMsg, k: u64) -> Offer {
        match self.vehicles.get_mut(vehicle) {
            Some(v) => v.stepper.book.offer_lockstep(cmd, k),
            None => Offer::UnknownSender,
        }
    }

    /// Real time / batch: offers `cmd` to vehicle `vehicle`'s book as its latest command.
    pub fn offer_latest(&mut self, vehicle: usize, cmd: &CommandMsg, k: u64) -> Offer {
        match self.vehicles.get_mut(vehicle) {
            Some(v) => v.stepper.book.offer_latest(cmd, k),
            None => Offer::UnknownSender,
        }
    }

    /// Frame `k → k + 1` of every vehicle (each holds its own book's commands for tick `k`).
    pub fn step(&mut self, k: u64) {
        for v in &mut self.vehicles {
            v.stepper.step(k);
        }
    }

    /// Fills every vehicle's telemetry buffer (those that have one) with tick `k`, checks every
    /// vehicle's state and sensors finite, and fills the pairs' relative states. An error
    /// comes with the index of the vehicle it is about.
    pub fn fill(&mut self, k: u64) -> Result<(), (usize, ServerError)> {
        for (i, v) in self.vehicles.iter_mut().enumerate() {
            let filled = match v.frame.as_mut() {
                Some(f) => {
                    v.stepper.fill(f, k);
                    true
                }
                None => false,
            };
            v.stepper.check_finite(k, filled).map_err(|e| (i, e))?;
        }
        for p in &mut self.pairs {
            let (Some(c), Some(d)) = (self.vehicles.get(p.chief), self.vehicles.get(p.deputy))
            else {
                continue;
            };
            p.msg = relative_msg(&c.stepper, &d.stepper, k);
        }
        Ok(())
    }

    /// \[ns\] the frame period (every vehicle's: the fleet file checks it).
    pub fn frame_ns(&self) -> u64 {
        self.vehicles
            .first()
            .map_or(1, |v| v.stepper.sim.frame_ns())
    }

    /// \[ns\] the simulation time reached (every vehicle's).
    pub fn sim_time_ns(&self) -> u64 {
        self.vehicles
            .first()
            .map_or(0, |v| v.stepper.sim.t_sim_ns())
    }
}

/// The deputy `d`'s state relative to the chief `c` at tick `k` (both just filled), with the
/// deputy's header (`seq` = `k`: one message per frame). A chief without an orbit plane (its
/// position and velocity parallel) has no Hill frame: the H fields are then 0, the range and
/// its rate still computed.
fn relative_msg(c: &Stepper, d: &Stepper, k: u64) -> RelativeStateMsg {
    let (r_c, v_c) = com_state_n(c.sim.spacecraft());
    let (r_d, v_d) = com_state_n(d.sim.spacecraft());
    let mut msg = RelativeStateMsg {
        header: Header::new(d.spacecraft_id(), k, d.filled_sim_time_ns(), k),
        chief_spacecraft_id: c.spacecraft_id(),
        deputy_spacecraft_id: d.spacecraft_id(),
        ..RelativeStateMsg::default()
    };
    match relative_state_hill(&r_c, &v_c, &r_d, &v_d) {
        Some(rel) => {
            msg.r_dc_h_m = rel.r_dc_h_m.into();
            msg.v_dc_h_m_s = rel.v_dc_h_m_s.into();
            msg.range_m = rel.range_m;
            msg.range_rate_m_s = rel.range_rate_m_s;
        }
        None => {
            let (dr, dv) = (r_d - r_c, v_d - v_c);
            msg.range_m = dr.norm();
            if msg.range_m > 0.0 {
                msg.range_rate_m_s = dr.dot(&dv) / msg.range_m;
            }
        }
    }
    msg
}
