//! The TOML configuration file: schema, parsing and validation.
//!
//! A configuration is parsed in four passes, and the first problem found is reported as one
//! [`ConfigError`] that names the offending field with its TOML path (e.g.
//! `panel_pairs[1].panel1.mass_kg`) and, where the file has it, its line and column:
//!
//! 1. TOML syntax ([`ConfigError::Syntax`]);
//! 2. structure: unknown keys, missing keys and wrong types, through `serde` with
//!    `deny_unknown_fields` ([`ConfigError::UnknownKey`], [`ConfigError::MissingKey`],
//!    [`ConfigError::InvalidValue`]);
//! 3. every float in the document must be finite — TOML accepts `nan` and `inf` literals
//!    ([`ConfigError::Param`] wrapping [`ParamError::NotFinite`]);
//! 4. physics and timing: the dynamics' own `validate` functions ([`ConfigError::Param`]) and the
//!    checks that only make sense for a file (step and frame in whole nanoseconds, which point the
//!    initial state describes, gravity model name, wrench schedule times), then the IMUs'
//!    ([`ImuConfig::validate`], unique names).
//!
//! The built-in default is [`DEFAULT_CONFIG_TOML`], the verbatim text of
//! `scenarios/reference.toml`. The README's "Configuration" section documents every key.

use std::collections::HashSet;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

use crate::dynamics::{
    GravityModel, HubInitial, HubParams, InitialTranslation, PanelPair, PanelPairInitial,
    PanelPairParams, PanelParams, ParamError, Spacecraft, StateEffector, WrenchSegment,
};
use crate::imu::{AccelErrors, GyroErrors, ImuConfig, ImuParamError};

/// The built-in default configuration (the text of `scenarios/reference.toml`).
pub const DEFAULT_CONFIG_TOML: &str = include_str!("../scenarios/reference.toml");

/// Largest allowed distance of `seconds · 1e9` from a whole number of nanoseconds.
pub const WHOLE_NS_TOL: f64 = 1e-6;

/// A position in the configuration text (1-based line and column, in characters).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Location {
    /// 1-based line.
    pub line: usize,
    /// 1-based column (characters).
    pub column: usize,
}

/// Where an error points to, if known; displays as ` (line L, column C)` or nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct At(pub Option<Location>);

impl fmt::Display for At {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(l) => write!(f, " (line {}, column {})", l.line, l.column),
            None => Ok(()),
        }
    }
}

/// A configuration that cannot be used. The message always starts with the TOML path of the
/// offending field (except for I/O and syntax errors, which name the file or the line).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read config file `{}`: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid TOML.
    #[error("TOML syntax error at line {line}, column {column}: {message}")]
    Syntax {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What the TOML parser reported.
        message: String,
    },
    /// A key that the schema does not have.
    #[error("{field}: unknown key ({message}){at}")]
    UnknownKey {
        /// TOML path of the unknown key.
        field: String,
        /// What the TOML parser reported (lists the expected keys).
        message: String,
        /// Position of the key.
        at: At,
    },
    /// A required key is absent.
    #[error("{field}: missing required key{}", in_table(at))]
    MissingKey {
        /// TOML path of the missing key.
        field: String,
        /// Position of the table that lacks it.
        at: At,
    },
    /// A value of the wrong type or shape (e.g. a string for a number, 2 elements for 3).
    #[error("{field}: invalid value: {message}{at}")]
    InvalidValue {
        /// TOML path of the value.
        field: String,
        /// What the TOML parser reported.
        message: String,
        /// Position of the value.
        at: At,
    },
    /// A parameter rejected by the dynamics' validation (non-finite, non-positive, inertia,
    /// DCM, panel geometry, …).
    #[error("{source}{at}")]
    Param {
        /// The validation error; it names the field.
        #[source]
        source: ParamError,
        /// Position of the value.
        at: At,
    },
    /// A duration that is not a whole number of nanoseconds or of RK4 steps, or a step that does
    /// not divide the frame period.
    #[error("{field}: {problem}{at}")]
    Timing {
        /// TOML path (`simulation.step_s`, `simulation.frame_hz`, `wrench_schedule[i].t_s`).
        field: String,
        /// What is wrong.
        problem: String,
        /// Position of the value.
        at: At,
    },
    /// The initial translational state does not name exactly one point (CoM or B).
    #[error("{field}: {problem}{at}")]
    InitialPoint {
        /// TOML path (`initial` or one of its keys).
        field: String,
        /// What is wrong.
        problem: String,
        /// Position.
        at: At,
    },
    /// Unknown gravity model name, or a parameter the chosen model does not take or needs.
    #[error("{field}: {problem}{at}")]
    Gravity {
        /// TOML path (`gravity.model`, `gravity.j2`, …).
        field: String,
        /// What is wrong.
        problem: String,
        /// Position.
        at: At,
    },
    /// Wrench schedule rows out of order.
    #[error("{field}: {problem}{at}")]
    WrenchSchedule {
        /// TOML path (`wrench_schedule[i].t_s`).
        field: String,
        /// What is wrong.
        problem: String,
        /// Position.
        at: At,
    },
    /// Any other invalid value (e.g. duplicate panel pair names).
    #[error("{field}: {problem}{at}")]
    Invalid {
        /// TOML path.
        field: String,
        /// What is wrong.
        problem: String,
        /// Position.
        at: At,
    },
}

fn in_table(at: &At) -> String {
    match at.0 {
        Some(l) => format!(" (in the table at line {}, column {})", l.line, l.column),
        None => String::new(),
    }
}

impl ConfigError {
    /// The TOML path of the offending field, if the error is about one.
    pub fn field(&self) -> Option<&str> {
        match self {
            ConfigError::Io { .. } | ConfigError::Syntax { .. } => None,
            ConfigError::UnknownKey { field, .. }
            | ConfigError::MissingKey { field, .. }
            | ConfigError::InvalidValue { field, .. }
            | ConfigError::Timing { field, .. }
            | ConfigError::InitialPoint { field, .. }
            | ConfigError::Gravity { field, .. }
            | ConfigError::WrenchSchedule { field, .. }
            | ConfigError::Invalid { field, .. } => Some(field),
            ConfigError::Param { source, .. } => param_field(source),
        }
    }
}

impl From<ParamError> for ConfigError {
    fn from(source: ParamError) -> Self {
        ConfigError::Param {
            source,
            at: At(None),
        }
    }
}

impl From<ImuParamError> for ConfigError {
    fn from(e: ImuParamError) -> Self {
        match e {
            ImuParamError::Param(source) => source.into(),
            ImuParamError::Invalid { field, problem } => ConfigError::Invalid {
                field,
                problem,
                at: At(None),
            },
        }
    }
}

/// The field path a [`ParamError`] names, if any.
fn param_field(e: &ParamError) -> Option<&str> {
    match e {
        ParamError::NotFinite { field }
        | ParamError::NotPositive { field, .. }
        | ParamError::Negative { field, .. }
        | ParamError::NotSymmetric { field, .. }
        | ParamError::NotPositiveDefinite { field, .. }
        | ParamError::TriangleInequality { field, .. }
        | ParamError::NotOrthonormal { field, .. }
        | ParamError::DExceedsLength { field, .. } => Some(field),
        _ => None,
    }
}

/// A validated simulation configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// \[ns\] RK4 step.
    pub step_ns: u64,
    /// \[ns\] telemetry/command frame period (a whole multiple of `step_ns`).
    pub frame_ns: u64,
    /// \[Hz\] frame rate as configured.
    pub frame_hz: f64,
    /// Hub parameters.
    pub hub: HubParams,
    /// Gravity model.
    pub gravity: GravityModel,
    /// Hub initial state.
    pub initial: HubInitial,
    /// Panel pairs and their initial states, in file order.
    pub panel_pairs: Vec<(PanelPairParams, PanelPairInitial)>,
    /// Piecewise-constant external wrench on the hub, sorted by strictly increasing start time.
    pub wrench_schedule: Vec<WrenchSegment>,
    /// The `[server]` table, uninterpreted (empty if absent); the server validates it.
    pub server: toml::Table,
    /// The IMUs (`[[imus]]`), validated, in file order (empty if absent). IMU `i` is sensor
    /// point `i` of the spacecraft built by [`Self::build_spacecraft`].
    pub imus: Vec<ImuConfig>,
    /// The configuration text this was parsed from.
    pub source_toml: String,
}

impl SimConfig {
    /// Parses and validates a configuration. The error names the first offending field.
    pub fn from_toml_str(s: &str) -> Result<Self, ConfigError> {
        let doc = DeTable::parse(s).map_err(|e| {
            let loc = e
                .span()
                .map(|sp| location(s, sp.start))
                .unwrap_or(Location { line: 1, column: 1 });
            ConfigError::Syntax {
                line: loc.line,
                column: loc.column,
                message: e.message().to_string(),
            }
        })?;
        let map = SourceMap::new(s, doc.get_ref());
        let raw: RawConfig = toml::from_str(s).map_err(|e| map.serde_error(&e))?;
        map.check_all_finite(doc.get_ref())?;
        raw.into_config(s, &map)
    }

    /// Reads, parses and validates a configuration file. An I/O error names the path.
    pub fn from_file(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str(&text)
    }

    /// The built-in default ([`DEFAULT_CONFIG_TOML`]).
    pub fn reference() -> Self {
        Self::from_toml_str(DEFAULT_CONFIG_TOML)
            .expect("the embedded default configuration is valid (see the unit test)")
    }

    /// RK4 steps per frame.
    pub fn steps_per_frame(&self) -> u64 {
        self.frame_ns / self.step_ns
    }

    /// \[kg\] total mass: hub plus every panel.
    pub fn total_mass_kg(&self) -> f64 {
        self.hub.mass_kg
            + self
                .panel_pairs
                .iter()
                .map(|(p, _)| p.panel1.mass_kg + p.panel2.mass_kg)
                .sum::<f64>()
    }

    /// Builds the spacecraft: one [`PanelPair`] per configured pair (errors name
    /// `panel_pairs[i]…`), then [`Spacecraft::new`], then one sensor point per IMU in file order
    /// (sensor point `i` is `imus[i]`).
    pub fn build_spacecraft(&self) -> Result<Spacecraft, ConfigError> {
        let mut effectors: Vec<Box<dyn StateEffector>> = Vec::with_capacity(self.panel_pairs.len());
        for (i, (params, initial)) in self.panel_pairs.iter().enumerate() {
            let pair = PanelPair::new(params.clone(), *initial, &format!("panel_pairs[{i}]"))?;
            effectors.push(Box::new(pair));
        }
        let mut sc = Spacecraft::new(
            self.hub.clone(),
            self.gravity,
            effectors,
            self.initial,
            self.step_ns,
        )?;
        for (i, imu) in self.imus.iter().enumerate() {
            sc.add_sensor_point(imu.sensor_point(), &format!("imus[{i}]"))?;
        }
        Ok(sc)
    }
}

/// Converts seconds to a whole number of nanoseconds: `None` unless `seconds` is finite, ≥ 0,
/// representable in `u64` nanoseconds and within [`WHOLE_NS_TOL`] (or 4 ulp of the product for
/// long durations) of a whole number.
pub fn whole_ns(seconds: f64) -> Option<u64> {
    round_ns(seconds * 1e9)
}

/// `ns` as a whole number of nanoseconds, with the tolerance of [`whole_ns`].
fn round_ns(ns: f64) -> Option<u64> {
    if !ns.is_finite() || ns < 0.0 || ns >= u64::MAX as f64 {
        return None;
    }
    let rounded = ns.round();
    let tol = WHOLE_NS_TOL.max(ns * 4.0 * f64::EPSILON);
    ((ns - rounded).abs() <= tol).then_some(rounded as u64)
}

// ---------------------------------------------------------------------------------------------
// Raw (file-shaped) schema.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    simulation: RawSimulation,
    gravity: RawGravity,
    hub: RawHub,
    initial: RawInitial,
    panel_pairs: Vec<RawPanelPair>,
    #[serde(default)]
    wrench_schedule: Vec<RawWrench>,
    #[serde(default)]
    server: toml::Table,
    #[serde(default)]
    imus: Vec<RawImu>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSimulation {
    step_s: f64,
    frame_hz: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGravity {
    model: String,
    mu_m3_s2: Option<f64>,
    j2: Option<f64>,
    r_eq_m: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHub {
    mass_kg: f64,
    inertia_bc_b_kg_m2: [[f64; 3]; 3],
    r_bcb_b_m: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInitial {
    r_cn_n_m: Option<[f64; 3]>,
    v_cn_n_m_s: Option<[f64; 3]>,
    r_bn_n_m: Option<[f64; 3]>,
    v_bn_n_m_s: Option<[f64; 3]>,
    sigma_bn: [f64; 3],
    omega_bn_b_rad_s: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPanelPair {
    name: String,
    r_h1b_b_m: [f64; 3],
    dcm_h1b: [[f64; 3]; 3],
    theta_h2s1_rad: f64,
    motor_torque_nm: Option<[f64; 2]>,
    panel1: RawPanel1,
    panel2: RawPanel2,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPanel1 {
    mass_kg: f64,
    inertia_s_kg_m2: [f64; 3],
    d_m: f64,
    l_m: f64,
    k_n_m_rad: f64,
    c_n_m_s_rad: f64,
    theta_rad: f64,
    theta_dot_rad_s: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPanel2 {
    mass_kg: f64,
    inertia_s_kg_m2: [f64; 3],
    d_m: f64,
    k_n_m_rad: f64,
    c_n_m_s_rad: f64,
    theta_rad: f64,
    theta_dot_rad_s: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawImu {
    name: String,
    r_sb_b_m: [f64; 3],
    dcm_pb: [[f64; 3]; 3],
    seed: u64,
    #[serde(default)]
    gyro: RawGyro,
    #[serde(default)]
    accel: RawAccel,
}

/// `[imus.gyro]`: every key optional, zero by default (see [`GyroErrors`]).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
struct RawGyro {
    arw_rad_s_sqrt_hz: f64,
    bias_instability_sigma_rad_s: f64,
    bias_instability_tau_s: f64,
    rrw_rad_s2_sqrt_hz: f64,
    bias_rad_s: [f64; 3],
    scale_factor: [f64; 3],
    misalignment_rad: [[f64; 3]; 3],
    range_rad_s: f64,
    lsb_rad_s: f64,
    dtheta_lsb_rad: f64,
}

/// `[imus.accel]`: every key optional, zero by default (see [`AccelErrors`]).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
struct RawAccel {
    vrw_m_s2_sqrt_hz: f64,
    bias_instability_sigma_m_s2: f64,
    bias_instability_tau_s: f64,
    rrw_m_s3_sqrt_hz: f64,
    bias_m_s2: [f64; 3],
    scale_factor: [f64; 3],
    misalignment_rad: [[f64; 3]; 3],
    range_m_s2: f64,
    lsb_m_s2: f64,
    dv_lsb_m_s: f64,
}

impl RawImu {
    fn into_config(self) -> ImuConfig {
        let g = self.gyro;
        let a = self.accel;
        ImuConfig {
            name: self.name,
            r_sb_b_m: vec3(&self.r_sb_b_m),
            dcm_pb: mat3(&self.dcm_pb),
            seed: self.seed,
            gyro: GyroErrors {
                arw_rad_s_sqrt_hz: g.arw_rad_s_sqrt_hz,
                bias_instability_sigma_rad_s: g.bias_instability_sigma_rad_s,
                bias_instability_tau_s: g.bias_instability_tau_s,
                rrw_rad_s2_sqrt_hz: g.rrw_rad_s2_sqrt_hz,
                bias_rad_s: vec3(&g.bias_rad_s),
                scale_factor: vec3(&g.scale_factor),
                misalignment_rad: mat3(&g.misalignment_rad),
                range_rad_s: g.range_rad_s,
                lsb_rad_s: g.lsb_rad_s,
                dtheta_lsb_rad: g.dtheta_lsb_rad,
            },
            accel: AccelErrors {
                vrw_m_s2_sqrt_hz: a.vrw_m_s2_sqrt_hz,
                bias_instability_sigma_m_s2: a.bias_instability_sigma_m_s2,
                bias_instability_tau_s: a.bias_instability_tau_s,
                rrw_m_s3_sqrt_hz: a.rrw_m_s3_sqrt_hz,
                bias_m_s2: vec3(&a.bias_m_s2),
                scale_factor: vec3(&a.scale_factor),
                misalignment_rad: mat3(&a.misalignment_rad),
                range_m_s2: a.range_m_s2,
                lsb_m_s2: a.lsb_m_s2,
                dv_lsb_m_s: a.dv_lsb_m_s,
            },
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWrench {
    t_s: f64,
    force_b_n: [f64; 3],
    torque_b_nm: [f64; 3],
}

fn mat3(rows: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| rows[i][j])
}

fn vec3(v: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

impl RawConfig {
    fn into_config(self, source: &str, map: &SourceMap) -> Result<SimConfig, ConfigError> {
        let param = |e: ParamError| map.param_error(e);

        // [simulation]
        let sim = &self.simulation;
        if sim.step_s <= 0.0 {
            return Err(param(ParamError::NotPositive {
                field: "simulation.step_s".into(),
                value: sim.step_s,
            }));
        }
        let step_ns = match whole_ns(sim.step_s) {
            Some(ns) if ns > 0 => ns,
            _ => {
                return Err(map.timing(
                    "simulation.step_s",
                    format!("step {} s is not a whole number of nanoseconds", sim.step_s),
                ))
            }
        };
        if sim.frame_hz <= 0.0 {
            return Err(param(ParamError::NotPositive {
                field: "simulation.frame_hz".into(),
                value: sim.frame_hz,
            }));
        }
        let frame_ns = match round_ns(1e9 / sim.frame_hz) {
            Some(ns) if ns > 0 => ns,
            _ => {
                return Err(map.timing(
                    "simulation.frame_hz",
                    format!(
                        "frame period 1/{} Hz = {} ns is not a whole number of nanoseconds",
                        sim.frame_hz,
                        1e9 / sim.frame_hz
                    ),
                ))
            }
        };
        if frame_ns % step_ns != 0 {
            return Err(map.timing(
                "simulation.frame_hz",
                format!(
                    "the step ({step_ns} ns, simulation.step_s) does not divide the frame period \
                     ({frame_ns} ns = 1/{} Hz): the frame must be a whole number of steps",
                    sim.frame_hz
                ),
            ));
        }

        // [gravity]
        let gravity = self.gravity.to_model(map)?;
        gravity.validate("gravity").map_err(param)?;

        // [hub]
        let hub = HubParams {
            mass_kg: self.hub.mass_kg,
            inertia_bc_b_kg_m2: mat3(&self.hub.inertia_bc_b_kg_m2),
            r_bcb_b_m: vec3(&self.hub.r_bcb_b_m),
        };
        hub.validate("hub").map_err(param)?;

        // [initial]
        let initial = self.initial.to_initial(map)?;

        // [[panel_pairs]]
        let mut panel_pairs = Vec::with_capacity(self.panel_pairs.len());
        let mut names = HashSet::new();
        for (i, raw) in self.panel_pairs.into_iter().enumerate() {
            let path = format!("panel_pairs[{i}]");
            if raw.name.trim().is_empty() {
                return Err(map.invalid(&format!("{path}.name"), "must not be empty".into()));
            }
            if !names.insert(raw.name.clone()) {
                return Err(map.invalid(
                    &format!("{path}.name"),
                    format!(
                        "duplicate panel pair name `{}` (names must be unique)",
                        raw.name
                    ),
                ));
            }
            let (params, init) = raw.into_params();
            params.validate(&path).map_err(param)?;
            init.validate(&path).map_err(param)?;
            panel_pairs.push((params, init));
        }

        // [[wrench_schedule]]
        let mut wrench_schedule = Vec::with_capacity(self.wrench_schedule.len());
        for (i, row) in self.wrench_schedule.iter().enumerate() {
            let path = format!("wrench_schedule[{i}]");
            let t_field = format!("{path}.t_s");
            if row.t_s < 0.0 {
                return Err(param(ParamError::Negative {
                    field: t_field,
                    value: row.t_s,
                }));
            }
            let t_start_ns = match whole_ns(row.t_s) {
                Some(ns) if ns % step_ns == 0 => ns,
                _ => {
                    return Err(map.timing(
                        &t_field,
                        format!(
                            "t_s = {} s is not a whole number of steps (step = {step_ns} ns)",
                            row.t_s
                        ),
                    ))
                }
            };
            if let Some(prev) = wrench_schedule.last().map(|w: &WrenchSegment| w.t_start_ns) {
                if t_start_ns <= prev {
                    return Err(map.wrench_order(
                        &t_field,
                        format!(
                            "t_s = {} s is not after the previous row's ({} s): t_s must be strictly increasing",
                            row.t_s,
                            prev as f64 * 1e-9
                        ),
                    ));
                }
            }
            let seg = WrenchSegment {
                t_start_ns,
                force_b_n: vec3(&row.force_b_n),
                torque_b_nm: vec3(&row.torque_b_nm),
            };
            seg.validate(&path).map_err(param)?;
            wrench_schedule.push(seg);
        }

        // [[imus]]
        let mut imus = Vec::with_capacity(self.imus.len());
        let mut imu_names = HashSet::new();
        for (i, raw) in self.imus.into_iter().enumerate() {
            let path = format!("imus[{i}]");
            let imu = raw.into_config();
            imu.validate(&path).map_err(|e| map.imu_error(e))?;
            if !imu_names.insert(imu.name.clone()) {
                return Err(map.invalid(
                    &format!("{path}.name"),
                    format!("duplicate IMU name `{}` (names must be unique)", imu.name),
                ));
            }
            imus.push(imu);
        }

        Ok(SimConfig {
            step_ns,
            frame_ns,
            frame_hz: sim.frame_hz,
            hub,
            gravity,
            initial,
            panel_pairs,
            wrench_schedule,
            server: self.server,
            imus,
            source_toml: source.to_string(),
        })
    }
}

impl RawGravity {
    fn to_model(&self, map: &SourceMap) -> Result<GravityModel, ConfigError> {
        let needs = |key: &str, v: Option<f64>| -> Result<f64, ConfigError> {
            v.ok_or_else(|| ConfigError::MissingKey {
                field: format!("gravity.{key}"),
                at: map.at("gravity"),
            })
        };
        let forbid = |key: &str, v: Option<f64>| -> Result<(), ConfigError> {
            match v {
                Some(_) => Err(map.gravity(
                    &format!("gravity.{key}"),
                    format!("not used by model \"{}\"; remove it", self.model),
                )),
                None => Ok(()),
            }
        };
        match self.model.as_str() {
            "none" => {
                forbid("mu_m3_s2", self.mu_m3_s2)?;
                forbid("j2", self.j2)?;
                forbid("r_eq_m", self.r_eq_m)?;
                Ok(GravityModel::None)
            }
            "point_mass" => {
                let mu_m3_s2 = needs("mu_m3_s2", self.mu_m3_s2)?;
                forbid("j2", self.j2)?;
                forbid("r_eq_m", self.r_eq_m)?;
                Ok(GravityModel::PointMass { mu_m3_s2 })
            }
            "j2" => Ok(GravityModel::J2 {
                mu_m3_s2: needs("mu_m3_s2", self.mu_m3_s2)?,
                j2: needs("j2", self.j2)?,
                r_eq_m: needs("r_eq_m", self.r_eq_m)?,
            }),
            other => Err(map.gravity(
                "gravity.model",
                format!("unknown gravity model \"{other}\" (expected \"none\", \"point_mass\" or \"j2\")"),
            )),
        }
    }
}

impl RawInitial {
    fn to_initial(&self, map: &SourceMap) -> Result<HubInitial, ConfigError> {
        let err = |field: &str, problem: String| {
            let at = map.at(field);
            ConfigError::InitialPoint {
                field: field.to_string(),
                problem,
                at: if at.0.is_some() {
                    at
                } else {
                    map.at("initial")
                },
            }
        };
        let both = |what: &str, a: &str, b: &str| {
            err(
                &format!("initial.{b}"),
                format!(
                    "both initial.{a} and initial.{b} are given: give the {what} of exactly one \
                     point (system centre of mass: {a}; point B: {b})"
                ),
            )
        };
        if self.r_cn_n_m.is_some() && self.r_bn_n_m.is_some() {
            return Err(both("position", "r_cn_n_m", "r_bn_n_m"));
        }
        if self.v_cn_n_m_s.is_some() && self.v_bn_n_m_s.is_some() {
            return Err(both("velocity", "v_cn_n_m_s", "v_bn_n_m_s"));
        }
        let translation = match (
            self.r_cn_n_m,
            self.r_bn_n_m,
            self.v_cn_n_m_s,
            self.v_bn_n_m_s,
        ) {
            (Some(r), None, Some(v), None) => InitialTranslation::CenterOfMass {
                r_cn_n_m: vec3(&r),
                v_cn_n_m_s: vec3(&v),
            },
            (None, Some(r), None, Some(v)) => InitialTranslation::PointB {
                r_bn_n_m: vec3(&r),
                v_bn_n_m_s: vec3(&v),
            },
            (None, None, _, _) => {
                return Err(err(
                    "initial.r_cn_n_m",
                    "missing initial position: give exactly one of initial.r_cn_n_m (system \
                     centre of mass) or initial.r_bn_n_m (point B)"
                        .into(),
                ))
            }
            (_, _, None, None) => {
                let (r, v) = if self.r_cn_n_m.is_some() {
                    ("r_cn_n_m", "v_cn_n_m_s")
                } else {
                    ("r_bn_n_m", "v_bn_n_m_s")
                };
                return Err(err(
                    &format!("initial.{v}"),
                    format!("missing initial velocity: initial.{r} needs initial.{v}"),
                ));
            }
            _ => {
                let field = if self.r_cn_n_m.is_some() {
                    "initial.v_bn_n_m_s"
                } else {
                    "initial.v_cn_n_m_s"
                };
                return Err(err(
                    field,
                    "position and velocity must be of the same point: use r_cn_n_m with \
                     v_cn_n_m_s (system centre of mass) or r_bn_n_m with v_bn_n_m_s (point B)"
                        .into(),
                ));
            }
        };
        Ok(HubInitial {
            translation,
            sigma_bn: vec3(&self.sigma_bn),
            omega_bn_b_rad_s: vec3(&self.omega_bn_b_rad_s),
        })
    }
}

impl RawPanelPair {
    fn into_params(self) -> (PanelPairParams, PanelPairInitial) {
        let p1 = &self.panel1;
        let p2 = &self.panel2;
        let params = PanelPairParams {
            name: self.name,
            r_h1b_b_m: vec3(&self.r_h1b_b_m),
            dcm_h1b: mat3(&self.dcm_h1b),
            theta_h2s1_rad: self.theta_h2s1_rad,
            l1_m: p1.l_m,
            panel1: PanelParams {
                mass_kg: p1.mass_kg,
                inertia_s_kg_m2: vec3(&p1.inertia_s_kg_m2),
                d_m: p1.d_m,
                k_n_m_rad: p1.k_n_m_rad,
                c_n_m_s_rad: p1.c_n_m_s_rad,
            },
            panel2: PanelParams {
                mass_kg: p2.mass_kg,
                inertia_s_kg_m2: vec3(&p2.inertia_s_kg_m2),
                d_m: p2.d_m,
                k_n_m_rad: p2.k_n_m_rad,
                c_n_m_s_rad: p2.c_n_m_s_rad,
            },
            motor_torque_nm: self.motor_torque_nm.unwrap_or([0.0, 0.0]),
        };
        let initial = PanelPairInitial {
            theta1_rad: p1.theta_rad,
            theta1_dot_rad_s: p1.theta_dot_rad_s,
            theta2_rad: p2.theta_rad,
            theta2_dot_rad_s: p2.theta_dot_rad_s,
        };
        (params, initial)
    }
}

// ---------------------------------------------------------------------------------------------
// Source map: TOML paths ↔ text positions.

/// 1-based line and column of byte `offset` in `s`.
fn location(s: &str, offset: usize) -> Location {
    let offset = offset.min(s.len());
    let before = s.get(..offset).unwrap_or(s);
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    Location {
        line: before.matches('\n').count() + 1,
        column: before[line_start..].chars().count() + 1,
    }
}

fn is_bare_key(k: &str) -> bool {
    !k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

fn join_key(path: &str, key: &str) -> String {
    let key = if is_bare_key(key) {
        key.to_string()
    } else {
        format!("{key:?}")
    };
    if path.is_empty() {
        key
    } else {
        format!("{path}.{key}")
    }
}

struct SpanEntry {
    span: Range<usize>,
    path: String,
    is_key: bool,
}

/// Every key and value of the document with its TOML path and byte span.
struct SourceMap<'s> {
    source: &'s str,
    entries: Vec<SpanEntry>,
}

impl<'s> SourceMap<'s> {
    fn new(source: &'s str, doc: &DeTable<'_>) -> Self {
        let mut map = Self {
            source,
            entries: Vec::new(),
        };
        map.index_table(doc, "");
        map
    }

    fn index_table(&mut self, t: &DeTable<'_>, path: &str) {
        for (k, v) in t.iter() {
            let p = join_key(path, k.get_ref());
            self.entries.push(SpanEntry {
                span: k.span(),
                path: p.clone(),
                is_key: true,
            });
            self.index_value(v, p);
        }
    }

    fn index_value(&mut self, v: &Spanned<DeValue<'_>>, path: String) {
        self.entries.push(SpanEntry {
            span: v.span(),
            path: path.clone(),
            is_key: false,
        });
        match v.get_ref() {
            DeValue::Table(t) => self.index_table(t, &path),
            DeValue::Array(a) => {
                for (i, e) in a.iter().enumerate() {
                    self.index_value(e, format!("{path}[{i}]"));
                }
            }
            _ => {}
        }
    }

    /// The deepest path whose key or value span equals `span`, else the smallest that contains it.
    fn path_at(&self, span: &Range<usize>) -> Option<&str> {
        let exact = self
            .entries
            .iter()
            .filter(|e| e.span == *span)
            .max_by_key(|e| e.path.len());
        let best = exact.or_else(|| {
            self.entries
                .iter()
                .filter(|e| e.span.start <= span.start && span.end <= e.span.end)
                .min_by_key(|e| (e.span.len(), usize::MAX - e.path.len()))
        });
        best.map(|e| e.path.as_str())
    }

    /// Position of the value at `path` (or of its key), if the document has it.
    fn at(&self, path: &str) -> At {
        let entry = self
            .entries
            .iter()
            .find(|e| !e.is_key && e.path == path)
            .or_else(|| self.entries.iter().find(|e| e.path == path));
        At(entry.map(|e| location(self.source, e.span.start)))
    }

    fn at_span(&self, span: &Range<usize>) -> At {
        if span.is_empty() && span.start == 0 {
            At(None)
        } else {
            At(Some(location(self.source, span.start)))
        }
    }

    /// Maps a structural error from `toml`/`serde` to a [`ConfigError`] naming the field.
    fn serde_error(&self, e: &toml::de::Error) -> ConfigError {
        let message = e.message().trim().to_string();
        let span = e.span().unwrap_or(0..0);
        // An empty span at the start means the document itself (e.g. a missing top-level table).
        let path = if span == (0..0) {
            ""
        } else {
            self.path_at(&span).unwrap_or("")
        }
        .to_string();
        let at = self.at_span(&span);
        let quoted = |prefix: &str| -> Option<String> {
            let rest = message.strip_prefix(prefix)?;
            let rest = rest.strip_prefix('`')?;
            Some(rest[..rest.find('`')?].to_string())
        };
        if let Some(key) = quoted("missing field ") {
            return ConfigError::MissingKey {
                field: join_key(&path, &key),
                at,
            };
        }
        if let Some(key) = quoted("unknown field ") {
            // The span is the key's, so `path` already ends with it.
            let field = if path.is_empty() { key } else { path };
            return ConfigError::UnknownKey { field, message, at };
        }
        let field = if path.is_empty() {
            "(document)".to_string()
        } else {
            path
        };
        ConfigError::InvalidValue { field, message, at }
    }

    /// Rejects NaN and ±Inf anywhere in the document (including `[server]` and `[[imus]]`).
    fn check_all_finite(&self, doc: &DeTable<'_>) -> Result<(), ConfigError> {
        fn walk_table(t: &DeTable<'_>, path: &str, out: &mut Option<(String, usize)>) {
            for (k, v) in t.iter() {
                if out.is_some() {
                    return;
                }
                walk_value(v, join_key(path, k.get_ref()), out);
            }
        }
        fn walk_value(v: &Spanned<DeValue<'_>>, path: String, out: &mut Option<(String, usize)>) {
            match v.get_ref() {
                DeValue::Float(f) => {
                    let s = f.as_str().to_ascii_lowercase();
                    let finite = !s.contains("nan")
                        && !s.contains("inf")
                        && s.replace('_', "").parse::<f64>().is_ok_and(f64::is_finite);
                    if !finite && out.is_none() {
                        *out = Some((path, v.span().start));
                    }
                }
                DeValue::Table(t) => walk_table(t, &path, out),
                DeValue::Array(a) => {
                    for (i, e) in a.iter().enumerate() {
                        if out.is_some() {
                            return;
                        }
                        walk_value(e, format!("{path}[{i}]"), out);
                    }
                }
                _ => {}
            }
        }
        let mut found = None;
        walk_table(doc, "", &mut found);
        match found {
            None => Ok(()),
            Some((field, offset)) => Err(ConfigError::Param {
                source: ParamError::NotFinite { field },
                at: At(Some(location(self.source, offset))),
            }),
        }
    }

    fn param_error(&self, source: ParamError) -> ConfigError {
        let at = param_field(&source).map(|f| self.at(f)).unwrap_or_default();
        ConfigError::Param { source, at }
    }

    fn timing(&self, field: &str, problem: String) -> ConfigError {
        ConfigError::Timing {
            field: field.to_string(),
            problem,
            at: self.at(field),
        }
    }

    fn gravity(&self, field: &str, problem: String) -> ConfigError {
        ConfigError::Gravity {
            field: field.to_string(),
            problem,
            at: self.at(field),
        }
    }

    fn wrench_order(&self, field: &str, problem: String) -> ConfigError {
        ConfigError::WrenchSchedule {
            field: field.to_string(),
            problem,
            at: self.at(field),
        }
    }

    fn imu_error(&self, e: ImuParamError) -> ConfigError {
        match e {
            ImuParamError::Param(p) => self.param_error(p),
            ImuParamError::Invalid { field, problem } => {
                // An absent key (e.g. a missing time constant) points at its table.
                let mut at = self.at(&field);
                let mut parent = field.as_str();
                while at.0.is_none() {
                    match parent.rfind('.') {
                        Some(i) => parent = &parent[..i],
                        None => break,
                    }
                    at = self.at(parent);
                }
                ConfigError::Invalid { field, problem, at }
            }
        }
    }

    fn invalid(&self, field: &str, problem: String) -> ConfigError {
        ConfigError::Invalid {
            field: field.to_string(),
            problem,
            at: self.at(field),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_parses() {
        let cfg = SimConfig::from_toml_str(DEFAULT_CONFIG_TOML).expect("reference parses");
        assert_eq!(cfg.step_ns, 1_000_000);
        assert_eq!(cfg.frame_ns, 10_000_000);
        assert_eq!(cfg.steps_per_frame(), 10);
        assert_eq!(cfg.panel_pairs.len(), 2);
        assert_eq!(cfg.source_toml, DEFAULT_CONFIG_TOML);
        assert_eq!(SimConfig::reference(), cfg);
        cfg.build_spacecraft().expect("reference spacecraft builds");
    }

    #[test]
    fn whole_ns_tolerance() {
        assert_eq!(whole_ns(0.001), Some(1_000_000));
        assert_eq!(whole_ns(1e-9), Some(1));
        assert_eq!(whole_ns(0.01), Some(10_000_000));
        assert_eq!(whole_ns(1.5e-9), None);
        assert_eq!(whole_ns(-1.0), None);
        assert_eq!(whole_ns(f64::NAN), None);
        assert_eq!(whole_ns(86_400.0 * 365.0), Some(31_536_000_000_000_000));
    }

    #[test]
    fn locations() {
        let s = "a = 1\nbb = 2\n";
        assert_eq!(location(s, 0), Location { line: 1, column: 1 });
        assert_eq!(location(s, 6), Location { line: 2, column: 1 });
        assert_eq!(location(s, 11), Location { line: 2, column: 6 });
    }

    #[test]
    fn quoted_keys_in_paths() {
        assert_eq!(join_key("", "hub"), "hub");
        assert_eq!(join_key("server", "a.b"), "server.\"a.b\"");
    }
}
