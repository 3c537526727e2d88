//! The tools' and the demo flight code's end-to-end suites, one executable: a flexdyn server
//! (in this process, or the `flexdyn` binary) with `flexdyn-acs-demo` or
//! `flexdyn-formation-demo` in the loop over loopback Zenoh, in lockstep: the ACS sequence, FDIR,
//! faults, fleets, campaigns, recordings, the lab network's access rules, and the tools' error
//! rules. The lockstep streams here are the ones whose hashes must never move.
//!
//! `monitor_live.rs` watches a real-time server on the wall clock and is its own executable.

mod support;

mod acs_sequence;
mod campaign_e2e;
mod campaign_fleet_e2e;
mod campaign_fsw;
mod cli_errors;
mod demo_complete_ticks;
mod e2e_lockstep;
mod fault_determinism;
mod fdir;
mod fleet_faults;
mod fleet_formation;
mod fleet_lockstep;
mod recording_lockstep;
mod run_end;
mod secure_lockstep;
