//! Several spacecraft in one world, on one tick.
//!
//! - [`fleet`]: the fleet file (vehicles, their spacecraft configurations, initial orbits
//!   absolute or relative to a chief, participants).
//! - [`step`]: the [`World`] that steps N [`Vehicle`]s (each a [`crate::sim::Simulation`]).
//! - [`offline`]: the offline stepping loop of `flexdyn simulate` (a world of one) and
//!   `flexdyn fleet`: rows at whole log intervals, optional stops at the frame boundaries.
//! - [`relative`]: a deputy's position and velocity in its chief's Hill frame, range, range rate.

pub mod fleet;
pub mod offline;
pub mod relative;
pub mod step;

pub use fleet::{FleetConfig, FleetError, VehicleConfig};
pub use offline::{walk, RowPlan, RowSink};
pub use relative::{relative_state_hill, RelativeState};
pub use step::{Vehicle, World};
