//! Attitude kinematics: the MRP, DCM and quaternion kernels of `flexdyn_proto::attitude`, which
//! flight code (the demo controller) uses too without linking the simulator.

pub use flexdyn_proto::attitude::*;
