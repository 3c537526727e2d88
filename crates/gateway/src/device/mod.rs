//! Devices: the described byte-stream devices of the gateway (issue 38), pure (no I/O).
//!
//! The runtime builds a [`Catalog`] of what the served vehicle offers, loads a [`DeviceSet`]
//! from the device list (each device a description file: no code per device), then every
//! tick calls [`Device::emit_due`], feeds the driver's bytes to [`Device::take_bytes`], and
//! calls [`Device::drive`] before sending the commands.
//!
//! # Layout
//! - [`catalog`]: channels, groups and inputs on offer, with their SI units;
//! - [`time`]: [`TickTime`], the tick's clock, and the `time.…` sources;
//! - [`units`]: unit conversion between a field's unit and the catalog's SI unit;
//! - [`endpoint`]: where a device's stream is exposed, [`EndpointSpec`];
//! - [`description`]: the TOML device list and descriptions, their checks, [`DeviceSet`];
//! - [`field`], [`message`]: fields and messages, their encoding and decoding;
//! - [`wire`], [`ccsds_framing`]: a device's framing (the crate's framings, and Space Packets);
//! - [`binary`]: the engine of described binary devices; [`speed_loop`]: a wheel drive's loop;
//! - [`nmea_device`]: the NMEA 0183 GPS receiver;
//! - [`engine`]: [`Device`], the runtime's handle on one device; [`counters`]: its tallies.

pub mod binary;
pub mod catalog;
pub mod ccsds_framing;
pub mod counters;
pub mod description;
pub mod endpoint;
pub mod engine;
pub mod field;
pub mod message;
pub mod nmea_device;
pub mod speed_loop;
pub mod time;
pub mod units;
pub mod wire;

pub use catalog::Catalog;
pub use counters::DeviceCounters;
pub use description::{DescriptionError, DeviceSet};
pub use endpoint::EndpointSpec;
pub use engine::{Device, Taken, MAX_READ_CHUNK};
pub use time::{TickTime, Utc};
