//! Several spacecraft in one world: the vehicle layer's [`flexdyn_vehicle::world`], and
//! [`run`], the `flexdyn fleet` command that propagates a fleet file offline to CSV.

pub use flexdyn_vehicle::world::*;

pub mod run;
