//! The per-frame work of a fleet: every vehicle's [`Stepper`] (its simulation, command book and
//! held command) and its telemetry buffer, stepped on one tick. Nothing here allocates after
//! [`FleetStepper::new`] (checked in `tests/server_alloc.rs`).
//!
//! The vehicles do not act on one another ([`flexdyn_vehicle::world::step`]), so each vehicle's stream
//! is the one it would have alone, bit for bit, whatever the fleet's order or size.
//!
//! Each (chief, deputy) pair of the fleet file ([`flexdyn_vehicle::world::World::relative_pairs`]) gets
//! its [`RelativeStateMsg`] filled with the frames, from the two vehicles' states of the same
//! tick ([`flexdyn_vehicle::world::relative`]): a few dozen flops per pair, no allocation.

use flexdyn_proto::{CommandMsg, Header, RelativeStateMsg};

use super::super::commands::Offer;
use super::super::error::ServerError;
use super::super::physics::Stepper;
use super::super::settings::ServerSettings;
use super::super::shared::Frame;
use flexdyn_vehicle::world::relative::{com_state_n, relative_state_hill};
use flexdyn_vehicle::world::Vehicle;

/// One vehicle of the running fleet.
pub struct FleetVehicle {
    /// Its id (`flexdyn/<id>/…`).
    pub id: String,
    /// Its simulation, command book and held command.
    pub stepper: Stepper,
    /// The telemetry of its last tick filled.
    pub frame: Box<Frame>,
}

/// A (chief, deputy) pair of the running fleet and its relative state of the last tick filled.
pub struct RelativePair {
    /// The chief's index in [`FleetStepper::vehicles`].
    pub chief: usize,
    /// The deputy's index (listed after its chief).
    pub deputy: usize,
    /// The deputy's state relative to the chief at the last tick filled (published on
    /// `flexdyn/<deputy>/tlm/rel/<chief>` after the deputy's frame).
    pub msg: RelativeStateMsg,
}

/// Every vehicle of the fleet, stepped together.
pub struct FleetStepper {
    /// The vehicles, in fleet order.
    pub vehicles: Vec<FleetVehicle>,
    /// The (chief, deputy) pairs, in the deputies' fleet order.
    pub pairs: Vec<RelativePair>,
}

impl FleetStepper {
    /// Steppers at t = 0 (sensors sampled at tick 0); `settings[i]` are vehicle `i`'s (its
    /// participants and spacecraft id).
    pub fn new(vehicles: Vec<Vehicle>, settings: &[ServerSettings]) -> Self {
        let vehicles = vehicles
            .into_iter()
            .zip(settings)
            .map(|(v, s)| {
                // Room for the fault events a frame can carry (its configured and live slots).
                let frame = Box::new(
                    Frame::for_state(&v.sim.blank_state(), v.sim.sensors().len())
                        .with_fault_events(v.sim.faults().event_capacity()),
                );
                FleetVehicle {
                    id: v.id,
                    stepper: Stepper::new(v.sim, s),
                    frame,
                }
            })
            .collect();
        Self {
            vehicles,
            pairs: Vec::new(),
        }
    }

    /// With the relative states of these (chief, deputy) index pairs
    /// ([`flexdyn_vehicle::world::World::relative_pairs`]); a pair naming a vehicle out of range is left
    /// out.
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

    /// Fills every vehicle's telemetry of tick `k` and checks it finite; an error names the
    /// vehicle.
    pub fn fill(&mut self, k: u64) -> Result<(), ServerError> {
        for v in &mut self.vehicles {
            v.stepper.fill(&mut v.frame, k);
            if let Err(e) = v.stepper.check_finite(k, true) {
                return Err(ServerError::Vehicle {
                    vehicle: v.id.clone(),
                    source: Box::new(e),
                });
            }
        }
        for p in &mut self.pairs {
            let (Some(c), Some(d)) = (self.vehicles.get(p.chief), self.vehicles.get(p.deputy))
            else {
                continue;
            };
            p.msg = relative_msg(c, d, k);
        }
        Ok(())
    }

    /// \[ns\] the frame period (every vehicle's: the fleet file checks it).
    pub fn frame_ns(&self) -> u64 {
        self.vehicles
            .first()
            .map_or(1, |v| v.stepper.sim.frame_ns())
    }
}

/// The deputy `d`'s state relative to the chief `c` at tick `k` (both just filled), with the
/// deputy's header (`seq` = `k`: one message per frame). A chief without an orbit plane (its
/// position and velocity parallel) has no Hill frame: the H fields are then 0, the range and
/// its rate still computed.
fn relative_msg(c: &FleetVehicle, d: &FleetVehicle, k: u64) -> RelativeStateMsg {
    let (r_c, v_c) = com_state_n(c.stepper.sim.spacecraft());
    let (r_d, v_d) = com_state_n(d.stepper.sim.spacecraft());
    let header = &d.frame.state.header;
    let mut msg = RelativeStateMsg {
        header: Header::new(header.spacecraft_id, k, header.sim_time_ns, k),
        chief_spacecraft_id: c.frame.state.header.spacecraft_id,
        deputy_spacecraft_id: header.spacecraft_id,
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
