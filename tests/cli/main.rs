//! The root package's offline end-to-end tests, one executable: the `flexdyn` binary's offline
//! subcommands run as a user runs them (`simulate`, `check-config`, `campaign`, `plot`,
//! `export`, recordings written and replayed), checked against independent readers (Python's
//! `mcap` and pandas, a PNG decoder) and the sensors' documented models; the goldens of the
//! sensor outputs; and the Markdown documents (every link resolves, every block of the README and the book runs).
//!
//! The vehicle layer's own tests are in `crates/vehicle/tests/`; those that need a server are in
//! `tests/server/`.

// Shared by the files below.
#[allow(dead_code)]
mod campaign_support;
#[allow(dead_code)]
mod mcap_support;
#[allow(dead_code)]
mod py_support;

mod campaign_cli;
mod campaign_faults;
mod campaign_fleet_plan;
mod campaign_fork;
mod campaign_plan;
mod campaign_slurm;
mod checkpoint;
mod cli_simulate;
mod config_errors;
mod config_fuzz;
mod csv_dialect;
mod doc_links;
mod epoch_metadata;
mod fsw_plots;
mod gps;
mod imu_seeds;
mod magnetometer;
mod model_pages;
mod plots;
mod python_sdk;
mod readme_snippets;
mod recording_faults;
mod recording_files;
mod regress_sensor_outputs;
mod sensor_bounds;
mod served_config;
mod sun_sensors;
mod web_view;
