//! flexdyn's device gateway at run time (issue 38): unmodified flight drivers open a
//! pseudo-terminal, a TCP stream or a UDP socket pair and speak their device's own protocol;
//! the gateway feeds those byte streams from a server's telemetry and turns what the drivers
//! send into the server's actuator commands.
//!
//! - [`catalog`]: the served vehicle's sensors as named channels and its actuators as named
//!   inputs, and the copy of each complete tick into them;
//! - [`endpoint`]: pseudo-terminals, TCP and UDP, non-blocking, and the outbox that times each
//!   frame (latency, baud rate);
//! - [`gateway`]: the devices at run time, one tick at a time, in lockstep or in real time;
//! - [`participant`]: `flexdyn gateway`, a Zenoh participant like any flight code;
//! - [`report`]: where the drivers find their devices, and the counters at the end.
//!
//! # Layer
//! Depends on the wire and its client library (`flexdyn-proto` with `client`: Zenoh) and on the
//! device descriptions and codecs (`flexdyn-gateway`), never on the simulator: it is flight
//! code to the server, whose frame loop it does not touch, so it cannot slow the physics
//! thread. `.ci/layers` holds it below the server and the campaigns.

pub mod catalog;
pub mod endpoint;
pub mod gateway;
pub mod participant;
pub mod report;
