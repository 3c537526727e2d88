//! flexdyn's device-gateway codecs: the byte-level protocols that the gateway's device
//! descriptions are built from (issue 38), with no I/O of their own.
//!
//! - [`checksum`]: CRCs of any width in the Rocksoft™ model with the RevEng catalogue's
//!   presets, XOR, 8-bit sum, Fletcher-16 and -32;
//! - [`framing`]: encoders and incremental stream decoders for sync-and-length frames, SLIP
//!   (RFC 1055), COBS (Cheshire & Baker 1999), HDLC-like byte stuffing (RFC 1662 §4.2) and
//!   text lines; the decoders take bytes in any chunks, resynchronise, bound a frame's length,
//!   count malformed input by reason, and allocate nothing after construction;
//! - [`nmea`]: NMEA 0183 GGA, RMC and ZDA sentence writers and a sentence reader;
//! - [`ccsds`]: the CCSDS Space Packet primary header (CCSDS 133.0-B-2) and the CUC time code
//!   (CCSDS 301.0-B-4 §3.2);
//! - [`ByteOrder`]: the octet order of multi-octet integers;
//! - [`device`]: described devices: the catalog of channels, the TOML device list and
//!   descriptions, and the engine that encodes outputs, decodes the driver's frames, applies
//!   commands, answers requests and runs a wheel's speed loop.
//!
//! # Layer
//! Above the model crates (it sits after `flexdyn-vehicle` in `.ci/layers`, so that a device
//! description may later read the models' types) and below the sinks, the server and the
//! campaigns. It depends on `thiserror`, `hifitime` (UTC calendar fields for NMEA), `serde` and
//! `toml` (device descriptions), and `flexdyn-environment` (WGS-84 geodetic coordinates). It must never depend on an I/O stack (`zenoh`, `tokio`,
//! `foxglove`, `plotters`, `mcap`) nor on a flexdyn crate above it (`flexdyn-sinks`,
//! `flexdyn-server`, `flexdyn-campaign`, the root package): `.ci/layers` checks both. The
//! gateway's runtime (ptys, sockets, lockstep) belongs above it and calls it.

#![warn(missing_docs)]

pub mod byte_order;
pub mod ccsds;
pub mod checksum;
pub mod device;
pub mod framing;
pub mod nmea;

pub use byte_order::ByteOrder;
