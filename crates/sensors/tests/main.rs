//! The sensor models driven directly, without a vehicle: one test executable that links the
//! model crates only.
//!
//! - [`css_albedo`]: the coarse sun sensors' Earth albedo against the environment's cap;
//! - [`imu_statistics`]: the IMU error model's statistics with a static truth;
//! - [`star_tracker_exclusion`]: the star tracker's Earth-limb and Moon exclusion against
//!   closed-form geometry.

mod css_albedo;
mod imu_statistics;
mod star_tracker_exclusion;
