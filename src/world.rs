//! Several spacecraft in one world: [`run`], the `flexdyn fleet` command that propagates a fleet
//! file offline to CSV (the world itself is the vehicle layer's [`flexdyn_vehicle::world`]).

pub mod run;
