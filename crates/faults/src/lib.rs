//! Fault injection at the ports: a fault wraps a sensor's output as it leaves the
//! [`flexdyn_sensors::SensorBank`], or an actuator's input as it enters the spacecraft; the
//! physics models are untouched.
//!
//! - [`schema`]: the `[[faults]]` entries as written;
//! - [`targets`]: their load-time resolution (unknown targets, modes a kind does not take,
//!   parameters out of range are configuration errors naming the field);
//! - [`modes`]: the modes and the documented transform of each;
//! - [`window`]: when a fault is active (start, duration or open-ended, period); a random
//!   fault (`mtbf_s`) starts at a time to failure drawn from its seed at load
//!   ([`failure_delay_ns`]);
//! - [`ports`]: the per-vehicle runtime ([`Faults`]) that `flexdyn_vehicle::sim::Simulation` calls at its
//!   two ports; it allocates nothing, locks nothing and cannot fail. It also notes each fault's
//!   activation and clearance at the frame boundaries (the server's FaultEventMsg);
//! - [`live`]: live faults (`flexdyn/<sc>/fault`), checked off the physics thread by the same
//!   resolution as `[[faults]]` and handed over ready-made;
//! - [`link`]: command-link faults (`links.<sender id>`), applied where the server takes a
//!   participant's commands in (`flexdyn_server::commands::CommandBook`).
//!
//! Which modes apply is stated by each kind: a sensor through
//! [`flexdyn_sensors::Sensor::fault_channels`] and [`flexdyn_sensors::Sensor::has_validity`], an
//! effector kind through [`flexdyn_dynamics::component::ComponentKind::fault_modes`].
//!
//! # Layer
//! Above the kernel, the dynamics and the sensors: a fault wraps their ports. Resolution against a
//! configuration (`[[faults]]`, the live-fault resolver a configuration builds) lives in the
//! vehicle layer above; this crate resolves against a built spacecraft and sensor bank only. It
//! must never depend on the vehicle, the server or the sinks, nor on any I/O stack (`zenoh`,
//! `tokio`, `foxglove`, `plotters`, `mcap`): `.ci/layers` (run by `.ci/run`) checks the dependency
//! graph.

#![warn(missing_docs)]

pub mod link;
pub mod live;
pub mod modes;
pub mod ports;
pub mod schema;
pub mod targets;
pub mod window;

pub use modes::FaultMode;
pub use ports::Faults;
pub use targets::failure_delay_ns;
pub use window::FaultWindow;

/// Most axes a sensor channel may expose to faults (a coarse-sun-sensor array's detectors).
pub const MAX_AXES: usize = flexdyn_proto::MAX_CSS_DETECTORS;
/// Most fault channels a sensor may expose.
pub const MAX_CHANNELS: usize = 4;
/// Most live faults one run accepts ([`live`]): their slots are reserved when the server
/// starts, so the physics thread never allocates one.
pub const MAX_LIVE_FAULTS: usize = 64;

/// A resolved fault: what, how and when.
#[derive(Debug, Clone, PartialEq)]
pub struct FaultSpec {
    /// The target as written (`imus.hub.gyro`).
    pub target: String,
    /// The mode and its parameters.
    pub mode: FaultMode,
    /// When it is active.
    pub window: FaultWindow,
    /// Selected axes, bit `a` for 1-based axis `a + 1`; 0: every axis.
    pub axes: u32,
    /// Seed of its generator (`noise`, `spikes`).
    pub seed: u64,
    /// Where it sits.
    pub port: Port,
    /// Where it came from: a schedule, a random failure (`mtbf_s`) or a live command.
    pub source: flexdyn_proto::FaultSource,
}

/// Where a fault sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Port {
    /// A sensor's output: index in the sensor bank, and one of its channels (all if `None`).
    Sensor {
        /// Index in [`flexdyn_sensors::SensorBank::sensors`].
        sensor: usize,
        /// Index in the sensor's [`flexdyn_sensors::Sensor::fault_channels`].
        channel: Option<usize>,
    },
    /// An actuator's input: its index in the effector list.
    Actuator {
        /// Index in [`flexdyn_dynamics::Spacecraft::effector_entries`].
        effector: usize,
    },
    /// A participant's command link: its sender id (one of `server.participants`).
    Link {
        /// The participant's sender id.
        sender_id: u32,
    },
}
