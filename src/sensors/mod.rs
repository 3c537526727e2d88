//! Sensor models, one folder per kind. Each folder owns the kind's parameters, its
//! configuration schema (`schema.rs`), its measurement model and its message mapping.

pub mod imu;
