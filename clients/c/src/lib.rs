//! flexdyn-client: the C ABI client library of the flexdyn server.
//!
//! C and C++ flight code includes `include/flexdyn_client.h` (which includes the wire header
//! `proto/c/include/flexdyn_proto.h`) and links `libflexdyn_client.a` or `.so`. The library
//! wraps the Rust `zenoh` crate, so the program needs no zenoh-c, and the Rust codec of
//! `flexdyn-proto`, so it decodes exactly as the server encodes; decoded messages are handed
//! over in the header's own structs (`fd_state_msg`, `fd_imu_msg`, ...).
//!
//! # Layout
//! - [`error`]: the return codes and the error that carries one with its message.
//! - [`ctypes`]: the `#[repr(C)]` mirrors of the `flexdyn_proto.h` structs and the conversions
//!   from the Rust messages (generated from the wire table).
//! - [`from_c`]: the checked conversions of what a C caller passes (effector inputs, wrenches)
//!   to Rust values.
//! - [`kinds`]: the message kinds of the wire table (generated): key, direction, lockstep
//!   section and the Rust decoder that checks each sample before it is handed out.
//! - [`client`]: the library in safe Rust: the session, subscriptions with ring queues, commands
//!   and the lockstep participant (built on `flexdyn_proto::client`).
//! - [`fsw`]: the flight code's own telemetry streams (FswMsg): the Rust client's
//!   `flexdyn_proto::client::fsw` with the library's return codes.
//! - `ffi`: the `extern "C"` functions. The only module with `unsafe` code: pointer checks,
//!   `catch_unwind` around every call, and the message of the last error in the handle.
//!
//! The header states the threading contract: a handle is used by one thread at a time, and no
//! callback ever runs user code on a library thread.
#![deny(unsafe_code)]
#![deny(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]

pub mod client;
// Written by flexdyn-wiregen from proto/schema/messages.toml.
pub mod ctypes;
#[cfg(test)]
mod ctypes_tests;
pub mod error;
mod ffi;
pub mod from_c;
pub mod fsw;
// Written by flexdyn-wiregen from proto/schema/messages.toml.
#[rustfmt::skip]
pub mod kinds;

pub use client::{Client, Options};
pub use error::{Code, Error};
