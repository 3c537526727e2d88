//! The demo's own telemetry (issue 37): what the flight code decided, published on its stream
//! `flexdyn/<sc>/fsw/<name>` (`--fsw-stream`, default `acs`) when the served configuration
//! declares that stream in `[[fsw_streams]]`, so the server records it beside the truth.
//!
//! The demo publishes, of what the stream declares:
//! - **mode**: the sequence's mode (`detumble`, `sun-acquisition`, `fine-pointing`,
//!   `momentum-management`), or `pointing` for the single controller;
//! - **events**: `target-chosen` (the fine-pointing target, chosen at run time), and the FDIR's
//!   `gyro-failure`, `wheel-failure`, `rate-source-switched`, `wheels-reconfigured`;
//! - **estimate** (q_BN from the star tracker, propagated with the gyro) and **target** (q_RN);
//! - **values**: `rate_b_rad_s` (f64 × 3, the rate it controls with), `wheel_momentum_b_nms`
//!   (f64 × 3, from the wheel speeds and that rate), `sun_visible` (bool, the sequence's coarse
//!   sun sensors see the Sun), `fdir_flags` (i64: bit 0 a gyro was declared failed, bit 1 a
//!   wheel).
//!
//! A mode, event or value the stream does not declare is left out; a value the stream declares
//! that the demo does not know makes the first sample fail with its name
//! (`scenarios/acs_full.toml` and `scenarios/fdir.toml` declare theirs). The sample of tick k goes out before
//! the answer to tick k, so in lockstep the server has it before it steps on.

use anyhow::Context as _;
use flexdyn_proto::attitude::mrp_to_quat;
use flexdyn_proto::client::fsw::{FswError, FswStream};
use flexdyn_proto::client::vehicle::Vehicle;
use flexdyn_proto::Topics;
use nalgebra::Vector3;
use zenoh::Session;

use crate::fdir::Event;
use crate::sequence::Output;

/// `fdir_flags` bit 0: a gyro was declared failed.
pub const FDIR_GYRO_FAILED: i64 = 1 << 0;
/// `fdir_flags` bit 1: a wheel was declared failed.
pub const FDIR_WHEEL_FAILED: i64 = 1 << 1;

/// What one tick of the single controller decided.
#[derive(Clone, Copy, Debug)]
pub struct ControllerTick<'a> {
    /// The attitude estimate σ_BN, once there is one.
    pub sigma_bn: Option<Vector3<f64>>,
    /// The target σ_RN.
    pub sigma_rn: Vector3<f64>,
    /// \[rad/s\] the rate it controls with, B components.
    pub rate_b_rad_s: Vector3<f64>,
    /// \[N·m·s\] the wheel momentum, B components (zero without wheels).
    pub wheel_momentum_b_nms: Vector3<f64>,
    /// The FDIR's events of this tick.
    pub fdir_events: &'a [Event],
}

/// The demo's stream, when the served configuration declares it.
pub struct Telemetry {
    stream: FswStream,
    fdir_flags: i64,
}

fn quat(sigma: &Vector3<f64>) -> [f64; 4] {
    let q = mrp_to_quat(sigma);
    [q[0], q[1], q[2], q[3]]
}

impl Telemetry {
    /// The stream `name` of `vehicle`'s configuration; `None` (said in the log) when it
    /// declares no such stream.
    pub fn declare(
        session: &Session,
        topics: &Topics,
        vehicle: &Vehicle,
        name: &str,
    ) -> anyhow::Result<Option<Self>> {
        match FswStream::declare(session, topics, vehicle, name) {
            Ok(stream) => {
                tracing::info!(key = stream.key(), "publishing the flight code's telemetry");
                Ok(Some(Self {
                    stream,
                    fdir_flags: 0,
                }))
            }
            Err(e @ FswError::NoStream { .. }) => {
                tracing::info!("{e}: the flight code's telemetry is off");
                Ok(None)
            }
            Err(e) => Err(e).context("the flight code's telemetry stream"),
        }
    }

    fn mode(&mut self, name: &str) -> Result<(), FswError> {
        if self.stream.declares_mode(name) {
            self.stream.mode(name)?;
        }
        Ok(())
    }

    fn event(&mut self, name: &str) -> Result<(), FswError> {
        if self.stream.declares_event(name) {
            self.stream.event(name)?;
        }
        Ok(())
    }

    fn f64s(&mut self, name: &str, v: &[f64]) -> Result<(), FswError> {
        if self.stream.declares_value(name) {
            self.stream.f64s(name, v)?;
        }
        Ok(())
    }

    fn fdir(&mut self, events: &[Event]) -> Result<(), FswError> {
        for e in events {
            match e {
                Event::Detected { what, .. } => {
                    let (flag, name) = if *what == "gyro" {
                        (FDIR_GYRO_FAILED, "gyro-failure")
                    } else {
                        (FDIR_WHEEL_FAILED, "wheel-failure")
                    };
                    self.fdir_flags |= flag;
                    self.event(name)?;
                }
                Event::RateSource { .. } => self.event("rate-source-switched")?,
                Event::Wheels { .. } => self.event("wheels-reconfigured")?,
            }
        }
        if self.stream.declares_value("fdir_flags") {
            self.stream.i64s("fdir_flags", &[self.fdir_flags])?;
        }
        Ok(())
    }

    /// Publishes what the ACS sequence decided at tick `tick` (time `t_ns`).
    pub fn sequence(&mut self, tick: u64, t_ns: u64, out: &Output) -> anyhow::Result<()> {
        self.stream.begin(tick, t_ns)?;
        self.mode(out.mode.name())?;
        if out.new_target_sigma_rn.is_some() {
            self.event("target-chosen")?;
        }
        if let Some(s) = &out.sigma_bn_estimate {
            self.stream.estimate(quat(s))?;
        }
        if let Some(r) = &out.target_sigma_rn {
            self.stream.target(quat(r))?;
        }
        self.f64s("rate_b_rad_s", out.observation.omega_bn_b_rad_s.as_slice())?;
        self.f64s("wheel_momentum_b_nms", out.wheel_momentum_b_nms.as_slice())?;
        if self.stream.declares_value("sun_visible") {
            self.stream.bools("sun_visible", &[out.sun_b.is_some()])?;
        }
        self.fdir(&[])?;
        self.stream.publish()?;
        Ok(())
    }

    /// Publishes what the single controller (and its FDIR) decided at tick `tick`.
    pub fn controller(&mut self, tick: u64, t_ns: u64, c: &ControllerTick) -> anyhow::Result<()> {
        self.stream.begin(tick, t_ns)?;
        self.mode("pointing")?;
        if let Some(s) = &c.sigma_bn {
            self.stream.estimate(quat(s))?;
        }
        self.stream.target(quat(&c.sigma_rn))?;
        self.f64s("rate_b_rad_s", c.rate_b_rad_s.as_slice())?;
        self.f64s("wheel_momentum_b_nms", c.wheel_momentum_b_nms.as_slice())?;
        if self.stream.declares_value("sun_visible") {
            // The single controller has no sun sensors.
            self.stream.bools("sun_visible", &[false])?;
        }
        self.fdir(c.fdir_events)?;
        self.stream.publish()?;
        Ok(())
    }
}
