//! The server's real-time suites, one executable of their own: they pace frames on the wall
//! clock and check the rate and the lateness, so they run only beside each other, never beside
//! the heavier lockstep suites of `main.rs`. The hard real-time settings
//! (`server_hard_realtime.rs`) are a third executable: `mlockall` is process-wide.

use flexdyn_testkit_server::server as server_support;

mod device_gateway_realtime;
mod fleet_realtime;
mod server_realtime;
