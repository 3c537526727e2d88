//! The sensor models driven directly, without a vehicle: one test executable that links the
//! model crates only.
//!
//! - [`imu_statistics`]: the IMU error model's statistics with a static truth.

mod imu_statistics;
