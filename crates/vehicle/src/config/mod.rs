//! The TOML configuration file: schema, parsing and validation.
//!
//! A configuration is parsed in four passes, and the first problem found is reported as one
//! [`ConfigError`] that names the offending field with its TOML path (e.g.
//! `panel_pairs[1].panel1.mass_kg`) and, where the file has it, its line and column:
//!
//! 1. TOML syntax ([`ConfigError::Syntax`]);
//! 2. structure: unknown keys, missing keys, wrong types and wrong array lengths, by the typed
//!    reader of `crates/kernel/src/schema/reader.rs` ([`ConfigError::Schema`]: an unknown or missing key, a value
//!    of the wrong type), whose messages speak TOML (tables, keys, numbers,
//!    datetimes), never Rust types;
//! 3. every float in the document must be finite — TOML accepts `nan` and `inf` literals
//!    ([`ConfigError::Param`] wrapping [`ParamError::NotFinite`]);
//! 4. physics and timing: the dynamics' own `validate` functions ([`ConfigError::Param`]) and the
//!    checks that only make sense for a file (step and frame in whole nanoseconds, which point the
//!    initial state describes, gravity model name, wrench schedule times), then the IMUs'
//!    ([`ImuConfig::validate`], unique names).
//!
//! The built-in default is [`DEFAULT_CONFIG_TOML`], the verbatim text of
//! `scenarios/reference.toml`. docs/guides/configuration.md documents every key.

mod components;
mod faults;
mod file;
pub mod fsw;
mod schedule;
mod sensors;
mod warnings;
mod world;

use std::collections::HashSet;
use std::path::Path;

use toml::de::DeTable;

pub use file::{config_message, load_config};
pub use flexdyn_dynamics::component::Components;
use flexdyn_environment::earth_rotation::EarthOrientationModel;
use flexdyn_kernel::numfmt::{Num, Rounded};
use flexdyn_kernel::schema::checks::{every_frames, round_ns, unique_name};
pub use flexdyn_kernel::schema::checks::{whole_ns, WHOLE_NS_TOL};
pub use flexdyn_kernel::schema::config_error::ConfigError;
use flexdyn_kernel::schema::location;
pub use flexdyn_kernel::schema::source_map::SourceMap;
use flexdyn_kernel::schema::{mat3, vec3, SchemaError, TableReader};
pub use flexdyn_kernel::schema::{At, Location};
use flexdyn_proto::MAX_PANEL_PAIRS;
pub use fsw::{
    word_as_f64, FswEventDecl, FswRefusal, FswSeverity, FswStreamDecl, FswValueDecl, FswValueType,
    FswValues, MAX_FSW_DECLARED_EVENTS, MAX_FSW_DECLARED_MODES, MAX_FSW_NAME_LEN, MAX_FSW_STREAMS,
};
pub use schedule::EffectorInputSegment;
pub use warnings::{log_warnings, warning_message, ConfigWarning};

use flexdyn_dynamics::component::{BuiltComponent, StepTiming};
use flexdyn_dynamics::effectors::panel_pair::{self, schema::RawPanelPair};
use flexdyn_dynamics::effectors::reaction_wheel;
use flexdyn_dynamics::integrator::{self, ButcherTableau, RK4};
use flexdyn_dynamics::{
    GravityModel, HubInitial, HubParams, InitialTranslation, PanelPair, PanelPairInitial,
    PanelPairParams, ParamError, ReactionWheel, ReactionWheelParams, Spacecraft, StateEffector,
    WrenchSegment,
};
use flexdyn_sensors::imu::ImuConfig;
use flexdyn_sensors::magnetometer::MagnetometerConfig;
pub use flexdyn_sensors::params::SensorConfigs;
use flexdyn_sensors::star_tracker::StarTrackerConfig;
use flexdyn_sensors::{SensorBank, SensorBuild};

/// The built-in default configuration (the text of `scenarios/reference.toml`).
pub const DEFAULT_CONFIG_TOML: &str = include_str!("../../../../scenarios/reference.toml");

/// A validated simulation configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// \[ns\] integration step.
    pub step_ns: u64,
    /// The fixed-step Runge–Kutta method (`simulation.integrator`; RK4 if absent).
    pub integrator: &'static ButcherTableau,
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
    /// Reaction wheels (`[[reaction_wheels]]`), validated, in file order (empty if absent).
    /// They follow the panel pairs in the effector order.
    pub reaction_wheels: Vec<ReactionWheelParams>,
    /// The components of every registered kind configured through the generic list
    /// ([`flexdyn_dynamics::kinds::KINDS`]: `[[magnetorquers]]`, `[[thrusters]]`, …), validated,
    /// in registry order then file order; they follow the reaction wheels in the effector order
    /// (appended bodies among them before listed actuators).
    pub components: Components,
    /// Piecewise-constant external wrench on the hub, sorted by strictly increasing start time.
    pub wrench_schedule: Vec<WrenchSegment>,
    /// Piecewise-constant effector inputs (`[[effector_input_schedule]]`), sorted by start
    /// time (rows of equal time in file order); each row holds until the same effector's next.
    pub effector_input_schedule: Vec<EffectorInputSegment>,
    /// The `[server]` table, uninterpreted (empty if absent); the server validates it.
    pub server: toml::Table,
    /// The sensors of every registered kind ([`flexdyn_sensors::KINDS`]: `[[imus]]`,
    /// `[[star_trackers]]`, …), validated, in registry order then file order; typed access by
    /// kind: `cfg.sensors.of::<ImuConfig>()`.
    pub sensors: SensorConfigs,
    /// The simulation epoch (`[epoch]`), if given: t = 0 is this instant.
    pub epoch: Option<flexdyn_environment::epoch::SimEpoch>,
    /// The environment (`[environment]`), if given: models and dynamic effectors.
    pub environment: Option<flexdyn_environment::model::EnvironmentSettings>,
    /// The faults (`[[faults]]`), resolved against the spacecraft and its sensors, in file
    /// order (empty if absent).
    pub faults: Vec<flexdyn_faults::FaultSpec>,
    /// The flight code's telemetry streams (`[[fsw_streams]]`), validated, in file order (empty
    /// if absent): what each [`flexdyn_proto::FswMsg`] on `flexdyn/<sc-id>/fsw/<name>` is
    /// checked against ([`FswStreamDecl::check`]) and decoded by.
    pub fsw_streams: Vec<FswStreamDecl>,
    /// The configuration text this was parsed from.
    pub source_toml: String,
}

impl SimConfig {
    /// Parses and validates a configuration. The error names the first offending field.
    pub fn from_toml_str(s: &str) -> Result<Self, ConfigError> {
        Self::from_toml_str_in(s, Path::new("."))
    }

    /// Like [`Self::from_toml_str`], with relative paths in the file (`orbit.elements_file`)
    /// resolved against `base_dir`.
    pub fn from_toml_str_in(s: &str, base_dir: &Path) -> Result<Self, ConfigError> {
        let doc = parse_document(s)?;
        let map = SourceMap::new(s, doc.get_ref());
        let raw = RawConfig::read(s, doc.get_ref(), &map)?;
        map.check_all_finite(doc.get_ref())?;
        raw.into_config(s, &map, base_dir)
    }

    /// Reads, parses and validates a configuration file. An I/O error names the path.
    pub fn from_file(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str_in(&text, path.parent().unwrap_or(Path::new(".")))
    }

    /// The built-in default ([`DEFAULT_CONFIG_TOML`]).
    pub fn reference() -> Self {
        Self::from_toml_str(DEFAULT_CONFIG_TOML)
            .expect("the embedded default configuration is valid (see the unit test)")
    }

    /// The declared flight-code telemetry stream named `name` (`[[fsw_streams]]`), if any.
    pub fn fsw_stream(&self, name: &str) -> Option<&FswStreamDecl> {
        self.fsw_streams.iter().find(|s| s.name == name)
    }

    /// One-line summary, as `check-config` prints it after `ok: FILE: `.
    pub fn summary(&self) -> String {
        config_summary(self)
    }

    /// Integration steps per frame.
    pub fn steps_per_frame(&self) -> u64 {
        self.frame_ns / self.step_ns
    }

    /// \[kg\] total mass: hub plus every panel, wheel rotor, chain panel and appended body of the
    /// generic list (slosh masses).
    pub fn total_mass_kg(&self) -> f64 {
        self.hub.mass_kg
            + self
                .panel_pairs
                .iter()
                .map(|(p, _)| p.panel1.mass_kg + p.panel2.mass_kg)
                .sum::<f64>()
            + self.reaction_wheels.iter().map(|w| w.mass_kg).sum::<f64>()
            + self.components.iter().map(|c| c.mass_kg()).sum::<f64>()
    }

    /// What the vehicle's sensors are built from ([`SensorBank::new`]): their parameters, the
    /// frame period and the epoch of this configuration, with a nominal sample interval of
    /// `sample_interval_s` \[s\] and the first interval starting at `t_sim_ns` in state `x`.
    pub fn sensor_build<'a>(
        &'a self,
        sample_interval_s: f64,
        t_sim_ns: u64,
        x: &'a flexdyn_dynamics::State,
    ) -> SensorBuild<'a> {
        SensorBuild {
            sensors: &self.sensors,
            frame_ns: self.frame_ns,
            epoch: self.epoch.as_ref(),
            earth_orientation: self
                .environment
                .as_ref()
                .map_or(EarthOrientationModel::Iau2006, |e| e.earth_rotation),
            sample_interval_s,
            t_sim_ns,
            x,
        }
    }

    /// The sensor bank of this configuration at t = 0 in state `x`, sampled at the frame period:
    /// what `[[faults]]` targets and live faults are checked against.
    pub fn frame_sensor_bank(
        &self,
        x: &flexdyn_dynamics::State,
    ) -> Result<SensorBank, ConfigError> {
        SensorBank::new(&self.sensor_build(self.frame_ns as f64 * 1e-9, 0, x))
    }

    /// Builds the spacecraft: one [`PanelPair`] per configured pair (errors name
    /// `panel_pairs[i]…`), then one [`ReactionWheel`] per wheel (`reaction_wheels[i]…`), then
    /// the appended bodies of [`Self::components`], then [`Spacecraft::new`], then its listed
    /// actuators (magnetorquers, then thrusters, …: listed dynamic effectors, after the bodies in
    /// the effector order), then the dynamic effectors of `[environment]`.
    pub fn build_spacecraft(&self) -> Result<Spacecraft, ConfigError> {
        let mut effectors: Vec<Box<dyn StateEffector>> = Vec::with_capacity(self.panel_pairs.len());
        for (i, (params, initial)) in self.panel_pairs.iter().enumerate() {
            let pair = PanelPair::new(params.clone(), *initial, &format!("panel_pairs[{i}]"))?;
            effectors.push(Box::new(pair));
        }
        for (i, params) in self.reaction_wheels.iter().enumerate() {
            let wheel = ReactionWheel::new(params.clone(), &format!("reaction_wheels[{i}]"))?;
            effectors.push(Box::new(wheel));
        }
        let timing = StepTiming {
            step_ns: self.step_ns,
            frame_ns: self.frame_ns,
        };
        let mut listed = Vec::new();
        for (path, c) in self.components.with_paths() {
            match c.build(&path, timing)? {
                BuiltComponent::Body(body) => effectors.push(body),
                BuiltComponent::Listed(actuator) => listed.push(actuator),
            }
        }
        let mut sc = Spacecraft::new(
            self.hub.clone(),
            self.gravity,
            effectors,
            self.initial,
            self.step_ns,
        )?;
        sc.set_integrator(self.integrator);
        for actuator in listed {
            sc.try_add_dynamic_effector(actuator)?;
        }
        if let Some(env) = &self.environment {
            world::add_dynamic_effectors(&mut sc, env, &self.gravity);
        }
        Ok(sc)
    }

    /// The environment models of `[environment]` for the `[epoch]`, when some model reads the
    /// date (the gravity gradient alone reads none: `None`, as without `[environment]`).
    pub fn environment_model(
        &self,
    ) -> Result<Option<flexdyn_environment::model::EnvironmentModel>, ConfigError> {
        match (&self.environment, &self.epoch) {
            (Some(env), Some(epoch)) if env.needs_epoch() => {
                flexdyn_environment::model::EnvironmentModel::new(env, epoch)
                    .map(|m| Some(m.on_step_grid(self.step_ns)))
                    .map_err(|e| ConfigError::Invalid {
                        field: "environment".into(),
                        problem: e.to_string(),
                        at: Default::default(),
                    })
            }
            _ => Ok(None),
        }
    }
}

/// Short name of a gravity model, as in the configuration file.
pub fn gravity_model_name(g: &GravityModel) -> &'static str {
    match g {
        GravityModel::None => "none",
        GravityModel::PointMass { .. } => "point_mass",
        GravityModel::J2 { .. } => "j2",
    }
}

/// One-line summary of a valid configuration.
pub fn config_summary(cfg: &SimConfig) -> String {
    format!(
        "{} panel pairs{}{}, {} IMUs{}{}{}, total mass {} kg, step {} s ({} ns{}), frame {} Hz ({} ns = {} steps), gravity {}, {} wrench schedule rows{}",
        cfg.panel_pairs.len(),
        if cfg.reaction_wheels.is_empty() {
            String::new()
        } else {
            format!(", {} reaction wheels", cfg.reaction_wheels.len())
        },
        {
            let mut s = String::new();
            for kind in flexdyn_dynamics::kinds::KINDS {
                let n = cfg.components.count(kind);
                if n > 0 {
                    s += &format!(", {n} {}", kind.section);
                }
            }
            s
        },
        cfg.sensors.of::<ImuConfig>().count(),
        {
            let names: Vec<&str> = cfg.sensors.of::<ImuConfig>().map(|i| i.name.as_str()).collect();
            if names.is_empty() {
                String::new()
            } else {
                format!(" ({})", names.join(", "))
            }
        },
        {
            let names: Vec<&str> = cfg.sensors.of::<StarTrackerConfig>().map(|s| s.name.as_str()).collect();
            if names.is_empty() {
                String::new()
            } else {
                format!(", {} star trackers ({})", names.len(), names.join(", "))
            }
        },
        {
            let names: Vec<&str> = cfg.sensors.of::<MagnetometerConfig>().map(|s| s.name.as_str()).collect();
            if names.is_empty() {
                String::new()
            } else {
                format!(", {} magnetometers ({})", names.len(), names.join(", "))
            }
        },
        cfg.total_mass_kg(),
        cfg.step_ns as f64 * 1e-9,
        cfg.step_ns,
        if cfg.integrator == &RK4 {
            String::new()
        } else {
            format!(", {}", cfg.integrator.name)
        },
        cfg.frame_hz,
        cfg.frame_ns,
        cfg.steps_per_frame(),
        gravity_model_name(&cfg.gravity),
        cfg.wrench_schedule.len(),
        match cfg.effector_input_schedule.len() {
            0 => String::new(),
            n => format!(", {n} effector input schedule rows"),
        },
    )
}

/// The TOML document `s`, or its syntax error with its line and column.
pub(crate) fn parse_document(s: &str) -> Result<toml::Spanned<DeTable<'_>>, ConfigError> {
    DeTable::parse(s).map_err(|e| {
        let loc = e
            .span()
            .map(|sp| location(s, sp.start))
            .unwrap_or(Location { line: 1, column: 1 });
        ConfigError::Syntax {
            line: loc.line,
            column: loc.column,
            message: e.message().to_string(),
        }
    })
}

// ---------------------------------------------------------------------------------------------
// Raw (file-shaped) schema, read by [`TableReader`]: every key, type and length is checked here
// (pass 2), before any value is interpreted.

/// Keys of the document's root table.
const ROOT_KEYS: &[&str] = &[
    "simulation",
    "gravity",
    "hub",
    "initial",
    "panel_pairs",
    "reaction_wheels",
    "wrench_schedule",
    "effector_input_schedule",
    "server",
    "faults",
    "fsw_streams",
];

struct RawConfig {
    world: world::RawWorld,
    simulation: RawSimulation,
    gravity: RawGravity,
    hub: RawHub,
    initial: RawInitial,
    panel_pairs: Vec<RawPanelPair>,
    reaction_wheels: Vec<ReactionWheelParams>,
    components: Vec<Box<dyn flexdyn_dynamics::component::ComponentSpec>>,
    wrench_schedule: Vec<RawWrench>,
    effector_input_schedule: Vec<schedule::RawInputRow>,
    server: toml::Table,
    sensors: sensors::RawSensors,
    faults: Vec<flexdyn_faults::schema::RawFault>,
    fsw_streams: Vec<fsw::RawFswStream>,
}

struct RawSimulation {
    step_s: f64,
    frame_hz: f64,
    integrator: Option<String>,
}

struct RawGravity {
    model: String,
    mu_m3_s2: Option<f64>,
    j2: Option<f64>,
    r_eq_m: Option<f64>,
}

struct RawHub {
    mass_kg: f64,
    inertia_bc_b_kg_m2: [[f64; 3]; 3],
    r_bcb_b_m: [f64; 3],
}

struct RawInitial {
    r_cn_n_m: Option<[f64; 3]>,
    v_cn_n_m_s: Option<[f64; 3]>,
    r_bn_n_m: Option<[f64; 3]>,
    v_bn_n_m_s: Option<[f64; 3]>,
    sigma_bn: [f64; 3],
    omega_bn_b_rad_s: [f64; 3],
}

struct RawWrench {
    t_s: f64,
    force_b_newton: [f64; 3],
    torque_b_nm: [f64; 3],
}

impl RawConfig {
    /// Pass 2: reads the whole document against the schema.
    fn read(source: &str, doc: &DeTable<'_>, map: &SourceMap) -> Result<Self, ConfigError> {
        let root_keys: Vec<&str> = ROOT_KEYS
            .iter()
            .copied()
            .chain(sensors::root_keys())
            .chain(world::ROOT_KEYS.iter().copied())
            .chain(components::root_keys())
            .collect();
        let root = TableReader::root(source, doc, &root_keys)?;
        let world = world::RawWorld::read(&root, map)?;
        let sim = root.table("simulation", &["step_s", "frame_hz", "integrator"])?;
        let simulation = RawSimulation {
            step_s: sim.f64("step_s")?,
            frame_hz: sim.f64("frame_hz")?,
            integrator: match sim.get("integrator") {
                Some(_) => Some(sim.string("integrator")?),
                None => None,
            },
        };
        let g = root.table("gravity", &["model", "mu_m3_s2", "j2", "r_eq_m"])?;
        let gravity = RawGravity {
            model: g.string("model")?,
            mu_m3_s2: g.opt_f64("mu_m3_s2")?,
            j2: g.opt_f64("j2")?,
            r_eq_m: g.opt_f64("r_eq_m")?,
        };
        let h = root.table("hub", &["mass_kg", "inertia_bc_b_kg_m2", "r_bcb_b_m"])?;
        let hub = RawHub {
            mass_kg: h.f64("mass_kg")?,
            inertia_bc_b_kg_m2: h.mat3("inertia_bc_b_kg_m2")?,
            r_bcb_b_m: h.floats("r_bcb_b_m")?,
        };
        let i = root.table(
            "initial",
            &[
                "r_cn_n_m",
                "v_cn_n_m_s",
                "r_bn_n_m",
                "v_bn_n_m_s",
                "sigma_bn",
                "omega_bn_b_rad_s",
            ],
        )?;
        let initial = RawInitial {
            r_cn_n_m: i.opt_floats("r_cn_n_m")?,
            v_cn_n_m_s: i.opt_floats("v_cn_n_m_s")?,
            r_bn_n_m: i.opt_floats("r_bn_n_m")?,
            v_bn_n_m_s: i.opt_floats("v_bn_n_m_s")?,
            sigma_bn: i.floats("sigma_bn")?,
            omega_bn_b_rad_s: i.floats("omega_bn_b_rad_s")?,
        };
        let panel_pairs = root
            .req_tables("panel_pairs", &panel_pair::schema::KEYS)?
            .iter()
            .map(RawPanelPair::read)
            .collect::<Result<Vec<_>, _>>()?;
        let reaction_wheels = root.read_tables(
            "reaction_wheels",
            &reaction_wheel::schema::KEYS,
            reaction_wheel::schema::read,
        )?;
        let components = components::read(&root)?;
        let wrench_schedule = root
            .tables("wrench_schedule", &["t_s", "force_b_newton", "torque_b_nm"])?
            .unwrap_or_default()
            .iter()
            .map(|w| {
                Ok(RawWrench {
                    t_s: w.f64("t_s")?,
                    force_b_newton: w.floats("force_b_newton")?,
                    torque_b_nm: w.floats("torque_b_nm")?,
                })
            })
            .collect::<Result<Vec<_>, ConfigError>>()?;
        let effector_input_schedule = root.read_tables(
            "effector_input_schedule",
            &schedule::KEYS,
            schedule::RawInputRow::read,
        )?;
        // `[server]` is read and validated by the server's own schema
        // (`flexdyn_server::settings`); here it only has to be a table. `check-config` runs
        // that schema too.
        let server = if root.is_table("server")? {
            let full: toml::Table =
                source
                    .parse()
                    .map_err(|e: toml::de::Error| ConfigError::Syntax {
                        line: 1,
                        column: 1,
                        message: e.message().to_string(),
                    })?;
            match full.get("server") {
                Some(toml::Value::Table(t)) => t.clone(),
                _ => toml::Table::new(),
            }
        } else {
            toml::Table::new()
        };
        let sensors = sensors::read(&root)?;
        let faults = root.read_tables(
            "faults",
            &flexdyn_faults::schema::KEYS,
            flexdyn_faults::schema::read,
        )?;
        let fsw_streams = root.read_tables("fsw_streams", &fsw::KEYS, |t| {
            fsw::RawFswStream::read(t, map)
        })?;
        Ok(RawConfig {
            faults,
            fsw_streams,
            world,
            simulation,
            gravity,
            hub,
            initial,
            panel_pairs,
            reaction_wheels,
            components,
            wrench_schedule,
            effector_input_schedule,
            server,
            sensors,
        })
    }
}

impl RawConfig {
    fn into_config(
        self,
        source: &str,
        map: &SourceMap,
        base_dir: &Path,
    ) -> Result<SimConfig, ConfigError> {
        let param = |e: ParamError| map.param_error(e);

        // [simulation]
        let sim = &self.simulation;
        if sim.step_s <= 0.0 {
            return Err(param(ParamError::NotPositive {
                field: "simulation.step_s".into(),
                value: sim.step_s,
            }));
        }
        check_max_time(map, "simulation.step_s", sim.step_s)?;
        let step_ns = match whole_ns(sim.step_s) {
            Some(ns) if ns > 0 => ns,
            _ => {
                return Err(map.timing(
                    "simulation.step_s",
                    format!(
                        "step {} s is not a whole number of nanoseconds",
                        Num(sim.step_s)
                    ),
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
                        Num(sim.frame_hz),
                        Num(1e9 / sim.frame_hz)
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
                    Num(sim.frame_hz)
                ),
            ));
        }

        let integrator = match sim.integrator.as_deref() {
            None => &RK4,
            Some(name) => integrator::by_name(name).ok_or_else(|| {
                map.invalid(
                    "simulation.integrator",
                    format!(
                        "unknown integrator \"{name}\" (expected {})",
                        integrator::names_for_message()
                    ),
                )
            })?,
        };

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

        // [epoch], [orbit], [environment]
        let has_orbit = self.world.has_orbit();
        let world = self.world.resolve(&gravity, base_dir, map)?;

        // [initial] (its position and velocity come from [orbit] when that is given)
        let initial = self
            .initial
            .to_initial(map, world.orbit.as_ref(), has_orbit)?;

        // [[panel_pairs]]
        if self.panel_pairs.len() > MAX_PANEL_PAIRS {
            return Err(map.invalid(
                "panel_pairs",
                format!(
                    "{} panel pairs is more than the wire format carries: a StateMsg holds at \
                     most {MAX_PANEL_PAIRS} (proto/README.md)",
                    self.panel_pairs.len()
                ),
            ));
        }
        let mut panel_pairs = Vec::with_capacity(self.panel_pairs.len());
        let mut names = HashSet::new();
        for (i, raw) in self.panel_pairs.into_iter().enumerate() {
            let path = format!("panel_pairs[{i}]");
            unique_name(map, &path, &raw.name, &mut names, "panel pair")?;
            let (params, init) = raw.into_params();
            params.validate(&path).map_err(param)?;
            init.validate(&path).map_err(param)?;
            panel_pairs.push((params, init));
        }

        // [[reaction_wheels]]
        let mut reaction_wheels = Vec::with_capacity(self.reaction_wheels.len());
        let mut wheel_names = HashSet::new();
        for (i, params) in self.reaction_wheels.into_iter().enumerate() {
            let path = format!("reaction_wheels[{i}]");
            unique_name(map, &path, &params.name, &mut wheel_names, "reaction wheel")?;
            params.validate(&path).map_err(param)?;
            reaction_wheels.push(params);
        }
        // The generic sections: [[magnetorquers]], [[thrusters]], …
        let timing = StepTiming { step_ns, frame_ns };
        let components = components::resolve(self.components, map, timing, &names)?;
        check_wire_capacity(map, panel_pairs.len(), &reaction_wheels, &components)?;

        // [[wrench_schedule]]
        let mut wrench_schedule = Vec::with_capacity(self.wrench_schedule.len());
        for (i, row) in self.wrench_schedule.iter().enumerate() {
            let path = format!("wrench_schedule[{i}]");
            let t_start_ns = schedule::row_time_ns(
                map,
                &format!("{path}.t_s"),
                row.t_s,
                step_ns,
                wrench_schedule.last().map(|w: &WrenchSegment| w.t_start_ns),
                |field, problem| map.wrench_order(field, problem),
            )?;
            let seg = WrenchSegment {
                t_start_ns,
                force_b_newton: vec3(&row.force_b_newton),
                torque_b_nm: vec3(&row.torque_b_nm),
            };
            seg.validate(&path).map_err(param)?;
            wrench_schedule.push(seg);
        }

        // [[imus]], [[star_trackers]], …: every sensor kind, in registry order.
        let sensors = sensors::resolve(self.sensors, map, sim.frame_hz)?;

        // [environment] telemetry_rate_hz: a whole number of frames.
        let mut environment = world.environment;
        if let Some(env) = environment.as_mut() {
            if let Some(hz) = env.telemetry_rate_hz {
                env.telemetry_every_frames = Some(every_frames(
                    map,
                    "environment.telemetry_rate_hz",
                    hz,
                    sim.frame_hz,
                    "environment message",
                )?);
            }
        }

        // [[fsw_streams]]
        let fsw_streams = fsw::resolve(&self.fsw_streams, map)?;

        let mut cfg = SimConfig {
            step_ns,
            integrator,
            frame_ns,
            frame_hz: sim.frame_hz,
            hub,
            gravity,
            initial,
            panel_pairs,
            reaction_wheels,
            components,
            wrench_schedule,
            // Resolved below, against the built spacecraft's effectors.
            effector_input_schedule: Vec::new(),
            server: self.server,
            sensors,
            epoch: world.epoch,
            environment,
            // Resolved below, against the built spacecraft and sensors.
            faults: Vec::new(),
            fsw_streams,
            source_toml: source.to_string(),
        };
        check_body_extent(&cfg, map)?;
        check_resolved_by_step(&cfg, map)?;
        // Both remaining checks look at the built spacecraft's initial state: build it once.
        let mut sc = cfg.build_spacecraft()?;
        cfg.effector_input_schedule =
            schedule::resolve(&self.effector_input_schedule, &sc, step_ns, map)?;
        check_gravity_bound(&cfg, &sc, map)?;
        check_initial_outputs_finite(&cfg, &mut sc, map)?;
        cfg.faults = self::faults::resolve(&self.faults, &cfg, &sc, map)?;
        Ok(cfg)
    }
}

/// Checks that every effector fits one StateMsg: at most [`flexdyn_proto::MAX_EFFECTORS`]
/// effectors and [`flexdyn_proto::MAX_MESSAGE_BYTES`] bytes.
fn check_wire_capacity(
    map: &SourceMap,
    n_pairs: usize,
    wheels: &[ReactionWheelParams],
    components: &Components,
) -> Result<(), ConfigError> {
    use flexdyn_proto::{
        EFFECTOR_STATE_FIXED_LEN, MAX_EFFECTORS, MAX_MESSAGE_BYTES, STATE_FIXED_LEN,
    };
    let n = n_pairs + wheels.len() + components.len();
    if n > MAX_EFFECTORS {
        return Err(map.invalid(
            "reaction_wheels",
            format!(
                "{n_pairs} panel pairs, {} reaction wheels and {} other components make {n} \
                 effectors, more than a StateMsg carries ({MAX_EFFECTORS}, proto/README.md)",
                wheels.len(),
                components.len()
            ),
        ));
    }
    // Each effector's entry: the fixed part and 8 bytes per state and output, with the kinds'
    // own state and output lists.
    let entry = |states: usize, outputs: usize| EFFECTOR_STATE_FIXED_LEN + 8 * (states + outputs);
    let wheel_len = |w: &ReactionWheelParams| {
        let states = if w.imbalanced() {
            reaction_wheel::IMBALANCED_STATE_NAMES.len()
        } else {
            reaction_wheel::BALANCED_STATE_NAMES.len()
        };
        entry(states, reaction_wheel::OUTPUT_NAMES.len())
    };
    let bytes = STATE_FIXED_LEN
        + n_pairs * entry(panel_pair::STATE_NAMES.len(), 0)
        + wheels.iter().map(wheel_len).sum::<usize>()
        + components::wire_bytes(components);
    if bytes > MAX_MESSAGE_BYTES {
        return Err(map.invalid(
            "reaction_wheels",
            format!(
                "the StateMsg of {n_pairs} panel pairs, {} reaction wheels and {} other \
                 components would be {bytes} bytes, more than the {MAX_MESSAGE_BYTES}-byte \
                 message limit",
                wheels.len(),
                components.len()
            ),
        ));
    }
    Ok(())
}

/// The longest simulation time a `u64` count of nanoseconds holds: 2⁶⁴ − 1 ns ≈ 584.5 years.
pub const MAX_SIM_TIME_S: f64 = u64::MAX as f64 * 1e-9;

/// What is wrong with `seconds` if it is beyond [`MAX_SIM_TIME_S`]: the one message of every
/// time in a file (configuration, `[server]`, campaign).
pub fn beyond_max_time(seconds: f64) -> Option<String> {
    (seconds >= MAX_SIM_TIME_S).then(|| {
        format!(
            "{} s is beyond the maximum simulation time ({} s ≈ 584 years, 2^64 − 1 ns)",
            Num(seconds),
            Rounded(MAX_SIM_TIME_S, 6)
        )
    })
}

/// An error naming `field` if `seconds` is beyond [`MAX_SIM_TIME_S`].
fn check_max_time(map: &SourceMap, field: &str, seconds: f64) -> Result<(), ConfigError> {
    match beyond_max_time(seconds) {
        Some(problem) => Err(map.timing(field, problem)),
        None => Ok(()),
    }
}

/// \[m\] Largest body-fixed distance in a spacecraft: a hub CoM offset, a hinge or sensor
/// location, a panel length. The largest structure ever flown (the ISS truss) is about 110 m;
/// 10 km leaves room for any tether-free design, while offsets of 1e18 m (a unit or exponent
/// slip) would make the system inertia about C ill-conditioned beyond what f64 resolves.
pub const MAX_BODY_EXTENT_M: f64 = 1e4;

/// Rejects body-fixed distances beyond [`MAX_BODY_EXTENT_M`].
fn check_body_extent(cfg: &SimConfig, map: &SourceMap) -> Result<(), ConfigError> {
    let check = |field: &str, r_m: f64| -> Result<(), ConfigError> {
        if r_m > MAX_BODY_EXTENT_M {
            return Err(map.invalid(
                field,
                format!(
                    "{} m is beyond the largest body-fixed distance flexdyn accepts ({} m): \
                     check the units",
                    Rounded(r_m, 4),
                    Num(MAX_BODY_EXTENT_M)
                ),
            ));
        }
        Ok(())
    };
    check("hub.r_bcb_b_m", cfg.hub.r_bcb_b_m.norm())?;
    for (i, (p, _)) in cfg.panel_pairs.iter().enumerate() {
        let path = format!("panel_pairs[{i}]");
        check(&format!("{path}.r_h1b_b_m"), p.r_h1b_b_m.norm())?;
        check(&format!("{path}.panel1.l_m"), p.l1_m)?;
        check(&format!("{path}.panel1.d_m"), p.panel1.d_m)?;
        check(&format!("{path}.panel2.d_m"), p.panel2.d_m)?;
    }
    for (i, imu) in cfg.sensors.of::<ImuConfig>().enumerate() {
        check(&format!("imus[{i}].r_sb_b_m"), imu.r_sb_b_m.norm())?;
    }
    for (i, w) in cfg.reaction_wheels.iter().enumerate() {
        check(&format!("reaction_wheels[{i}].r_wb_b_m"), w.r_wb_b_m.norm())?;
    }
    for (i, m) in cfg.sensors.of::<MagnetometerConfig>().enumerate() {
        if let Some(r) = &m.r_sb_b_m {
            check(&format!("magnetometers[{i}].r_sb_b_m"), r.norm())?;
        }
    }
    if let Some(env) = &cfg.environment {
        for (i, f) in env.facets.iter().enumerate() {
            let path = format!("environment.facets[{i}]");
            check(&format!("{path}.r_cp_b_m"), f.r_cp_b_m.norm())?;
            // A plate within the body's extent is at most that extent squared.
            if f.area_m2 > MAX_BODY_EXTENT_M * MAX_BODY_EXTENT_M {
                return Err(map.invalid(
                    &format!("{path}.area_m2"),
                    format!(
                        "{} m² is beyond the largest plate flexdyn accepts ({} m², the \
                         largest body-fixed distance squared): check the units",
                        Rounded(f.area_m2, 4),
                        Num(MAX_BODY_EXTENT_M * MAX_BODY_EXTENT_M)
                    ),
                ));
            }
        }
    }
    // Mass and inertia ratios: the hub's 3×3 Schur complement (Eqs. 151–153) subtracts the
    // panels' contributions from the hub's; beyond MAX_MASS_RATIO the difference loses the
    // digits the back-substitution needs (the dense-Kane cross-check measured κ ≈ 3.5e3 for a
    // 200:1 panel-to-hub ratio).
    let hub_m = cfg.hub.mass_kg;
    let hub_i_min = cfg.hub.inertia_bc_b_kg_m2.symmetric_eigenvalues().min();
    // A body of mass `mass_kg` whose largest moment `i_max` is called `moment` in messages.
    let check = |path: &str,
                 mass_kg: f64,
                 inertia_field: &str,
                 i_max: f64,
                 moment: &str|
     -> Result<(), ConfigError> {
        let ratio = (mass_kg / hub_m).max(hub_m / mass_kg);
        if ratio > MAX_MASS_RATIO {
            return Err(map.invalid(
                &format!("{path}.mass_kg"),
                format!(
                    "{} kg against a {} kg hub is a mass ratio of {}; flexdyn accepts at most {} \
                     either way (the hub solve would lose its precision)",
                    Num(mass_kg),
                    Num(hub_m),
                    Rounded(ratio, 3),
                    Num(MAX_MASS_RATIO)
                ),
            ));
        }
        if i_max > MAX_MASS_RATIO * hub_i_min {
            return Err(map.invalid(
                &format!("{path}.{inertia_field}"),
                format!(
                    "a {moment} of {} kg·m² is more than {} times the hub's smallest principal \
                     moment ({} kg·m²)",
                    Num(i_max),
                    Num(MAX_MASS_RATIO),
                    Rounded(hub_i_min, 6)
                ),
            ));
        }
        Ok(())
    };
    for (i, (p, _)) in cfg.panel_pairs.iter().enumerate() {
        for (which, panel) in [("panel1", &p.panel1), ("panel2", &p.panel2)] {
            check(
                &format!("panel_pairs[{i}].{which}"),
                panel.mass_kg,
                "inertia_s_kg_m2",
                panel.inertia_s_kg_m2.max(),
                "principal moment",
            )?;
        }
    }
    for (i, w) in cfg.reaction_wheels.iter().enumerate() {
        check(
            &format!("reaction_wheels[{i}]"),
            w.mass_kg,
            "j_s_kg_m2",
            w.j_s_kg_m2.max(w.j_t_kg_m2),
            "rotor moment",
        )?;
    }
    Ok(())
}

/// Largest ratio between a panel's mass and the hub's (either way), and between a panel's
/// largest principal moment and the hub's smallest.
pub const MAX_MASS_RATIO: f64 = 1e6;

/// Largest product of a rate and the RK4 step that a configuration may start with or build in:
/// a hinge's natural frequency √(k/I) or damping rate c/I, or an initial angular rate, times the
/// step. RK4 loses stability at ω·h ≈ 2.83 for an oscillator (2.79 for decay), and well before
/// that its error is no longer small; 1 rad per step keeps every configured motion resolved.
pub const MAX_RATE_TIMES_STEP: f64 = 1.0;

/// Rejects hinge stiffnesses, dampings and initial rates that the step cannot resolve (see
/// [`MAX_RATE_TIMES_STEP`]). Each panel is taken about its own hinge with the hub held fixed,
/// I = I_s2 + m d² (the inertia about the hinge axis ŝ2, by the parallel-axis theorem).
fn check_resolved_by_step(cfg: &SimConfig, map: &SourceMap) -> Result<(), ConfigError> {
    let h = cfg.step_ns as f64 * 1e-9;
    let too_fast = |field: &str, what: &str, rate: f64| -> Result<(), ConfigError> {
        if rate * h > MAX_RATE_TIMES_STEP {
            return Err(map.invalid(
                field,
                format!(
                    "{what} = {} rad/s is too fast for the {} s step: rate × step = {} > {} \
                     (use a smaller simulation.step_s or a slower value)",
                    Rounded(rate, 4),
                    Num(h),
                    Rounded(rate * h, 4),
                    MAX_RATE_TIMES_STEP
                ),
            ));
        }
        Ok(())
    };
    too_fast(
        "initial.omega_bn_b_rad_s",
        "|omega_bn_b|",
        cfg.initial.omega_bn_b_rad_s.norm(),
    )?;
    for (i, (p, init)) in cfg.panel_pairs.iter().enumerate() {
        for (which, panel, theta, theta_dot) in [
            ("panel1", &p.panel1, init.theta1_rad, init.theta1_dot_rad_s),
            ("panel2", &p.panel2, init.theta2_rad, init.theta2_dot_rad_s),
        ] {
            let path = format!("panel_pairs[{i}].{which}");
            let i_hinge = panel.inertia_s_kg_m2.y + panel.mass_kg * panel.d_m * panel.d_m;
            too_fast(
                &format!("{path}.k_nm_rad"),
                "the hinge frequency sqrt(k / (I_s2 + m d^2))",
                (panel.k_nm_rad / i_hinge).sqrt(),
            )?;
            too_fast(
                &format!("{path}.c_nm_s_rad"),
                "the hinge damping rate c / (I_s2 + m d^2)",
                panel.c_nm_s_rad / i_hinge,
            )?;
            too_fast(
                &format!("{path}.theta_dot_rad_s"),
                "theta_dot",
                theta_dot.abs(),
            )?;
            if theta.abs() > std::f64::consts::PI {
                return Err(map.invalid(
                    &format!("{path}.theta_rad"),
                    format!(
                        "{} rad is more than half a turn from the hinge's rest angle: a hinged \
                         panel's angle must be within [-pi, pi] (fold a wing with \
                         theta_h2s1_rad instead)",
                        Rounded(theta, 6)
                    ),
                ));
            }
        }
    }
    for (i, w) in cfg.reaction_wheels.iter().enumerate() {
        let path = format!("reaction_wheels[{i}]");
        too_fast(
            &format!("{path}.viscous_friction_nm_s_rad"),
            "the viscous spin-down rate b / J_s",
            w.viscous_friction_nm_s_rad / w.j_s_kg_m2,
        )?;
        too_fast(
            &format!("{path}.coulomb_band_rad_s"),
            "the Coulomb friction's linear-region rate tau_c / (band J_s)",
            w.coulomb_friction_nm / (w.coulomb_band_rad_s * w.j_s_kg_m2),
        )?;
        if w.imbalanced() {
            // The jitter rotates at the wheel speed: the step must resolve it.
            too_fast(
                &format!("{path}.max_speed_rad_s"),
                "the imbalanced wheel's max speed",
                w.max_speed_rad_s,
            )?;
        }
    }
    Ok(())
}

/// Rejects a configuration whose initial outputs overflow (an energy, a momentum or an
/// acceleration that is not finite although every input is): nothing could be published.
fn check_initial_outputs_finite(
    cfg: &SimConfig,
    sc: &mut Spacecraft,
    map: &SourceMap,
) -> Result<(), ConfigError> {
    if let Some(w) = cfg.wrench_schedule.first().filter(|w| w.t_start_ns == 0) {
        sc.set_wrench(w.wrench());
    }
    let out = sc.hub_outputs();
    let c = sc.conserved();
    let named: [(&str, &[f64]); 6] = [
        ("omega_dot_bn_b", out.omega_dot_bn_b.as_slice()),
        ("nongrav_accel_bn_b", out.nongrav_accel_bn_b.as_slice()),
        ("orb_energy_j", std::slice::from_ref(&c.orb_energy_j)),
        ("rot_energy_j", std::slice::from_ref(&c.rot_energy_j)),
        ("orb_ang_mom_n", c.orb_ang_mom_n.as_slice()),
        ("rot_ang_mom_c_n", c.rot_ang_mom_c_n.as_slice()),
    ];
    let bad = named
        .iter()
        .find(|(_, v)| v.iter().any(|x| !x.is_finite()))
        .map(|(n, _)| *n);
    match bad {
        None => Ok(()),
        Some(quantity) => Err(map.invalid(
            "initial",
            format!(
                "the initial {quantity} overflows to infinity: the masses, inertias, rates and \
                 wrenches are too large together to be represented"
            ),
        )),
    }
}

/// Smallest ratio of the dynamical time √(r³/μ) at the initial CoM radius to the RK4 step.
///
/// √(r³/μ) is the time scale of motion in a point-mass field at radius r (a circular orbit's
/// period is 2π times it, and the free-fall time from rest is (π/2√2) times it). RK4 needs many
/// steps per such time: with fewer than [`MIN_STEPS_PER_DYNAMICAL_TIME`] the orbit is not
/// resolved, and at r = 0 the field itself is infinite (NaN from the first step).
pub const MIN_STEPS_PER_DYNAMICAL_TIME: f64 = 100.0;

/// Rejects an initial position that gravity cannot propagate: under `point_mass` and `j2`, the
/// system CoM must be where the field is finite and resolved by the step
/// (√(r³/μ) ≥ [`MIN_STEPS_PER_DYNAMICAL_TIME`] steps); under `j2` it must also be outside the
/// equatorial radius, where the zonal expansion no longer describes the field.
fn check_gravity_bound(
    cfg: &SimConfig,
    sc: &Spacecraft,
    map: &SourceMap,
) -> Result<(), ConfigError> {
    let (mu_m3_s2, r_eq_m) = match cfg.gravity {
        GravityModel::None => return Ok(()),
        GravityModel::PointMass { mu_m3_s2 } => (mu_m3_s2, None),
        GravityModel::J2 {
            mu_m3_s2, r_eq_m, ..
        } => (mu_m3_s2, Some(r_eq_m)),
    };
    let field = match cfg.initial.translation {
        InitialTranslation::CenterOfMass { .. } => "initial.r_cn_n_m",
        InitialTranslation::PointB { .. } => "initial.r_bn_n_m",
    };
    let (_, r_cb_b_m, _) = sc.center_of_mass();
    let x = sc.state();
    let dcm_nb = flexdyn_kernel::attitude::mrp_to_dcm(&x.sigma_bn).transpose();
    let r_cn_n_m = x.r_bn_n + dcm_nb * r_cb_b_m;
    let r_m = r_cn_n_m.norm();
    if let Some(r_eq_m) = r_eq_m {
        if r_m <= r_eq_m {
            return Err(map.invalid(
                field,
                format!(
                    "the system centre of mass is {} m from the central body's centre, at or \
                     inside its equatorial radius gravity.r_eq_m = {} m: J2 gravity is only \
                     defined outside the body",
                    Rounded(r_m, 6),
                    Num(r_eq_m)
                ),
            ));
        }
    }
    let step_s = cfg.step_ns as f64 * 1e-9;
    let r_min_m = (mu_m3_s2 * (MIN_STEPS_PER_DYNAMICAL_TIME * step_s).powi(2)).cbrt();
    if r_m.is_nan() || r_m < r_min_m {
        return Err(map.invalid(
            field,
            format!(
                "the system centre of mass is {} m from the central body's centre; with \
                 gravity.mu_m3_s2 = {} and a {} s step it must be at least {} m away, where \
                 the dynamical time sqrt(r^3/mu) spans {} steps (at r = 0 the field is infinite)",
                Rounded(r_m, 6),
                Num(mu_m3_s2),
                Num(step_s),
                Rounded(r_min_m, 6),
                MIN_STEPS_PER_DYNAMICAL_TIME
            ),
        ));
    }
    Ok(())
}

impl RawGravity {
    fn to_model(&self, map: &SourceMap) -> Result<GravityModel, ConfigError> {
        let needs = |key: &str, v: Option<f64>| -> Result<f64, ConfigError> {
            v.ok_or_else(|| {
                ConfigError::Schema(SchemaError::MissingKey {
                    field: format!("gravity.{key}"),
                    at: map.at("gravity"),
                })
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
    fn to_initial(
        &self,
        map: &SourceMap,
        orbit: Option<&flexdyn_environment::orbit::schema::InitialOrbit>,
        has_orbit: bool,
    ) -> Result<HubInitial, ConfigError> {
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
        if has_orbit {
            let given = [
                ("r_cn_n_m", self.r_cn_n_m.is_some()),
                ("v_cn_n_m_s", self.v_cn_n_m_s.is_some()),
                ("r_bn_n_m", self.r_bn_n_m.is_some()),
                ("v_bn_n_m_s", self.v_bn_n_m_s.is_some()),
            ];
            if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
                return Err(err(
                    &format!("initial.{key}"),
                    format!(
                        "both [orbit] and initial.{key} give the orbit: keep [orbit] and remove \
                         initial.{key} (with [orbit], [initial] holds only sigma_bn and \
                         omega_bn_b_rad_s)"
                    ),
                ));
            }
            // [orbit] gives the system centre of mass (the point whose motion the orbit is).
            let translation = orbit.map_or(
                InitialTranslation::CenterOfMass {
                    r_cn_n_m: nalgebra::Vector3::zeros(),
                    v_cn_n_m_s: nalgebra::Vector3::zeros(),
                },
                |o| InitialTranslation::CenterOfMass {
                    r_cn_n_m: o.r_n_m,
                    v_cn_n_m_s: o.v_n_m_s,
                },
            );
            return Ok(HubInitial {
                translation,
                sigma_bn: vec3(&self.sigma_bn),
                omega_bn_b_rad_s: vec3(&self.omega_bn_b_rad_s),
            });
        }
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
}
