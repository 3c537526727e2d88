//! Sensor models, one folder per kind, behind one contract ([`Sensor`]) and one registry
//! ([`KINDS`]). Each folder owns the kind's parameters, its configuration schema
//! (`schema.rs`), its measurement model, its message mapping and its [`SensorKind`]
//! descriptor: [`imu`] (gyro and accelerometer), [`star_tracker`] (attitude),
//! [`magnetometer`], [`coarse_sun_sensor`] (arrays of cosine detectors), [`fine_sun_sensor`]
//! (two-axis) and [`gps`] (a receiver with a latency).
//!
//! Every sensor is sampled at a frame boundary (or, for a sensor that integrates over an
//! interval, at each output instant) from the same truth, a [`Truth`]: the state and the one
//! evaluation of the hub outputs that the frame's snapshot also uses
//! (`flexdyn_vehicle::sim::Simulation` caches it), plus the environment sample when there is one, so
//! adding sensors adds no equation-of-motion evaluations. The [`SensorBank`] holds a spacecraft's
//! sensors in registry order, then config order, which is also their publication order.
//!
//! Everything that handles sensors generically — the bank, the server's publishers and its
//! recorder, `simulate`'s CSV columns, topic classification, export, plot, view and the campaign's
//! seed keys — iterates [`KINDS`]; a new kind is its folder, its line in [`KINDS`] and its wire
//! message (the codecs).
//!
//! # Layer
//! Above the kernel, the environment and the dynamics (a sensor samples the hub's truth and the
//! environment sample). Sensors are built from a small [`SensorBuild`] context, never from the
//! vehicle's whole configuration. This crate must never depend on the faults, the vehicle or
//! anything above them, nor on any I/O stack (`zenoh`, `tokio`, `foxglove`, `plotters`, `mcap`):
//! `.ci/layers` (run by `.ci/run`) checks the dependency graph.

#![warn(missing_docs)]

use std::any::Any;

use flexdyn_proto::keys::Topics;
use flexdyn_proto::{DecodeError, Header, KeyError};

use flexdyn_dynamics::stage_hook::StageCombine;
use flexdyn_dynamics::{DynamicEffector, HubOutputs, State};
use flexdyn_environment::epoch::SimEpoch;
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::schema::config_error::ConfigError;

pub mod bank;
pub mod coarse_sun_sensor;
pub mod fine_sun_sensor;
pub mod gps;
pub mod imu;
pub mod magnetometer;
pub mod params;
pub mod rng;
pub mod star_tracker;

pub use bank::SensorBank;

/// Every sensor kind, in publication order: the registry.
pub static KINDS: &[&SensorKind] = &[
    &imu::KIND,
    &star_tracker::KIND,
    &magnetometer::KIND,
    &coarse_sun_sensor::KIND,
    &fine_sun_sensor::KIND,
    &gps::KIND,
];

/// The truth one sample is taken from: one evaluation at the current instant.
#[derive(Debug, Clone, Copy)]
pub struct Truth<'a> {
    /// \[ns\] simulation time.
    pub t_sim_ns: u64,
    /// The integrated state.
    pub state: &'a State,
    /// The hub accelerations at `state` with the wrench and inputs that apply from now on.
    pub hub: &'a HubOutputs,
    /// The environment sample (`[environment]` with an `[epoch]`), if any.
    pub env: Option<&'a EnvironmentSample>,
    /// The spacecraft's dynamic effectors, with their inputs as they apply from now on (a
    /// magnetometer adds the field of the magnetorquer dipoles among them).
    pub dynamic_effectors: &'a [Box<dyn DynamicEffector>],
}

impl Truth<'_> {
    /// The unit Sun direction in B, \[BN\] (r_sun / |r_sun|) with r_sun the Sun's position from
    /// point B in the environment sample, and the sample's shadow factor; `None` without a Sun
    /// (no environment sample, or a zero Sun vector: no ephemeris). For the sun sensors.
    pub fn sun_b(&self) -> Option<(nalgebra::Vector3<f64>, f64)> {
        let sun_n = self.sun_n()?;
        Some((
            flexdyn_kernel::attitude::mrp_to_dcm(&self.state.sigma_bn) * sun_n,
            self.env?.shadow_factor,
        ))
    }

    /// The unit Sun direction from point B in N, r_sun / |r_sun|; `None` without a Sun (no
    /// environment sample, or a zero Sun vector). For the star tracker's Sun exclusion.
    pub fn sun_n(&self) -> Option<nalgebra::Vector3<f64>> {
        let r = self.env?.r_sun_b_n_m;
        let norm = r.norm();
        (norm > 0.0).then(|| r / norm)
    }
}

/// One sensor: what the bank, the server and the sinks need of it. Every method called per
/// frame or per stage allocates nothing, locks nothing and cannot fail.
pub trait Sensor: std::fmt::Debug + Send {
    /// Its kind (an entry of [`KINDS`]).
    fn kind(&self) -> &'static SensorKind;

    /// Its configured name (the last segment of its key).
    fn name(&self) -> &str;

    /// Whether it samples at frame boundary `tick`.
    fn due(&self, tick: u64) -> bool;

    /// Whether it closes an integration interval at every output instant (every frame in the
    /// server, every row in `simulate`) rather than at the frame boundaries where it is due.
    fn every_output(&self) -> bool {
        false
    }

    /// Takes one sample from `truth`, kept until the next (see [`Self::encode`]).
    fn sample(&mut self, truth: &Truth<'_>);

    /// Whether the last [`Self::sample`] left a message to publish (a sensor with a latency
    /// also samples at instants where it only stores a measurement; default: always).
    fn has_output(&self) -> bool {
        true
    }

    /// Encodes the last sample as its wire message into `buf` (cleared first), with the frame's
    /// `header` (the sensor may set its own `seq`).
    fn encode(&self, header: Header, buf: &mut Vec<u8>);

    /// The first non-finite output of the last sample, if any.
    fn first_non_finite(&self) -> Option<&'static str>;

    /// Whether it integrates over the stages of every step ([`Self::stage`], [`Self::end_step`]).
    fn uses_stages(&self) -> bool {
        false
    }

    /// Stage `stage` of the current step was evaluated at `x` with hub accelerations `hub`
    /// ([`flexdyn_dynamics::stage_hook`]).
    fn stage(&mut self, _stage: usize, _x: &State, _hub: &HubOutputs) {}

    /// The step is complete: combine the stage values with `combine`.
    fn end_step(&mut self, _combine: &StageCombine) {}

    /// Starts a new interval at the current instant without sampling (e.g. after a state
    /// restore).
    fn restart(&mut self, _t_sim_ns: u64, _x: &State) {}

    /// Sets the nominal sample interval \[s\] (finite, > 0) of a sensor whose noise depends on
    /// it; others ignore it.
    fn set_sample_interval_s(&mut self, _t_s: f64) {}

    /// Its numeric parameters as built, by key relative to its configuration entry
    /// (`noise_sigma_t`, `bias_s_t[0]`), for a campaign's read-back of dispersed values
    /// (`flexdyn_campaign::plan::readback`). Not on the stepping path. None by default: a
    /// kind that lists none cannot be dispersed (the campaign rejects its keys at load time).
    fn parameters(&self, _out: &mut Vec<(String, f64)>) {}

    /// For the kind's own typed views ([`SensorBank::of`]).
    fn as_any(&self) -> &dyn Any;

    /// Lists its mutable state for a checkpoint ([`flexdyn_kernel::archive`]): its random
    /// generator, its error states, what it holds between samples and its last sample.
    /// Required, so a new kind says what it holds. Not on the stepping path.
    fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>);

    /// The output channels a fault can transform (`flexdyn_faults`), by name (`gyro`): the
    /// kind's statement of where its value modes apply. None by default (then only `dropout`,
    /// and `validity_off` with [`Self::has_validity`], apply).
    fn fault_channels(&self) -> &'static [&'static str] {
        &[]
    }

    /// The number of axes of fault channel `channel` (0 for none).
    fn fault_axes(&self, _channel: usize) -> usize {
        0
    }

    /// Fault channel `channel` of the last sample, mutably (empty for none).
    fn fault_channel(&mut self, _channel: usize) -> &mut [f64] {
        &mut []
    }

    /// Whether its message carries a validity flag (`validity_off` applies).
    fn has_validity(&self) -> bool {
        false
    }

    /// Marks the last sample invalid (a `validity_off` fault).
    fn force_invalid(&mut self) {}

    /// Whether the last sample carries a measurement: its validity flag set (a GPS fix, a valid
    /// star-tracker attitude or sun-sensor angle pair); always, for a kind without one. A
    /// `stuck_current` fault holds the first valid sample of its activation.
    fn is_valid(&self) -> bool {
        true
    }
}

/// A figure panel of a sensor kind's plot: `(column, legend)` pairs of its message's columns.
#[derive(Debug)]
pub struct PanelSpec {
    /// The y-axis label.
    pub y_label: &'static str,
    /// `(column of the decoded message, legend entry)`.
    pub lines: &'static [(&'static str, &'static str)],
}

/// What a vehicle's sensors are built from: their validated parameters and the little of the
/// vehicle they depend on. Never the whole configuration, so that the sensors sit below it.
#[derive(Debug, Clone, Copy)]
pub struct SensorBuild<'a> {
    /// Every configured sensor's parameters (registry order, then file order).
    pub sensors: &'a params::SensorConfigs,
    /// \[ns\] the frame period (a GPS receiver's latency ring counts frames).
    pub frame_ns: u64,
    /// The `[epoch]` (t = 0), if any (a GPS receiver's week and time of week).
    pub epoch: Option<&'a SimEpoch>,
    /// The environment's model of the Earth's orientation (a GPS receiver's Earth-fixed
    /// outputs rotate with it; the IAU 2006 chain without `[environment]`).
    pub earth_orientation: flexdyn_environment::earth_rotation::EarthOrientationModel,
    /// \[s\] the nominal sample interval (finite, > 0) of a sensor whose noise depends on it.
    pub sample_interval_s: f64,
    /// \[ns\] where the first integration interval starts.
    pub t_sim_ns: u64,
    /// The state at `t_sim_ns`.
    pub x: &'a State,
}

/// Builds a kind's sensors of `ctx.sensors` (config order) into `out`; errors name the entry's
/// field (`imus[0]…`).
pub type BuildFn =
    fn(ctx: &SensorBuild<'_>, out: &mut Vec<Box<dyn Sensor>>) -> Result<(), ConfigError>;

/// Decodes a kind's payload into its header and its JSON.
pub type DecodeFn = fn(&[u8]) -> Result<(Header, serde_json::Value), DecodeError>;

/// A sensor kind: how it is built, keyed, decoded, and plotted. One `static` per folder.
#[derive(Debug)]
pub struct SensorKind {
    /// Its name in messages and captions (`IMU`, `star tracker`).
    pub noun: &'static str,
    /// The same with its article (`an IMU`, `a star tracker`).
    pub a_noun: &'static str,
    /// The configuration array (`imus`, `star_trackers`): error paths and campaign seed keys.
    pub config_array: &'static str,
    /// How one `[[<config_array>]]` entry is read and validated.
    pub config: params::SensorConfigReader,
    /// The key prefix below `flexdyn/<sc>/` (`tlm/imu`); the key is `<prefix>/<name>`.
    pub key_prefix: &'static str,
    /// The prefix of its `simulate` CSV columns and the last segment of its key prefix
    /// (`imu`, `st`).
    pub column_prefix: &'static str,
    /// The wire message's name, as in `proto/README.md` (`ImuMsg`).
    pub message_name: &'static str,
    /// Its key for spacecraft `topics` and a sensor name (validates the name).
    pub key: fn(&Topics, &str) -> Result<String, KeyError>,
    /// Builds the kind's sensors of a vehicle.
    pub build: BuildFn,
    /// Decodes a payload into its header and its JSON (fields named as in the wire struct).
    pub decode: DecodeFn,
    /// The JSON of a default message (its column set).
    pub default_json: fn() -> serde_json::Value,
    /// The JSON Schema (draft 2020-12) of the decoded JSON.
    pub json_schema: fn() -> serde_json::Value,
    /// `flexdyn plot`: the figure's file, its title and the panels drawn per sensor.
    pub plot: (&'static str, &'static str, &'static [PanelSpec]),
}

impl SensorKind {
    /// Its index in [`KINDS`] (`None` for a kind not registered).
    pub fn index(&'static self) -> Option<usize> {
        KINDS.iter().position(|k| std::ptr::eq(*k, self))
    }
}

/// The JSON Schema of message `M`'s JSON, from the wire table
/// ([`flexdyn_proto::json_schema_text`]), for [`SensorKind::json_schema`].
pub fn message_json_schema<M: flexdyn_proto::WireMessage>() -> serde_json::Value {
    flexdyn_proto::json_schema_text(M::NAME)
        .and_then(|text| serde_json::from_str(text).ok())
        .unwrap_or(serde_json::Value::Null)
}

/// The message `msg` as `(header, JSON)`, for [`SensorKind::decode`].
pub fn json_of<M: serde::Serialize>(header: Header, msg: &M) -> (Header, serde_json::Value) {
    (
        header,
        // Wire structs hold only numbers, bools and arrays: always representable.
        serde_json::to_value(msg).unwrap_or(serde_json::Value::Null),
    )
}
