//! The server's end-to-end tests, one executable: a real server (in process, or the `flexdyn`
//! binary as its own process) driven over loopback Zenoh as flight code and operators drive it:
//! lockstep commands and telemetry, bad input, live and link faults, operator control, the
//! environment and time messages, fleets, recording and the WebSocket view.
//!
//! The real-time suites, which measure pacing on the wall clock, are their own executable
//! (`realtime.rs` in this folder), so that nothing here runs beside them.

// The end-to-end harness, shared with the other suites (`crates/testkit-server`).
use flexdyn_testkit_server::server as server_support;

mod checkpoint_lockstep;
mod device_gateway;
mod environment_message;
mod faults_config;
mod faults_dropout_lockstep;
mod faults_links;
mod faults_live;
mod fleet_record_operator;
mod fleet_relative_state;
mod operator_control;
mod server_bad_input;
mod server_cli;
mod server_wheels;
mod tick_handler;
mod time_service;
mod view_ws;
