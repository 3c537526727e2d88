//! Configuration parsing and validation: every class of invalid input gives one error naming the
//! field (as a TOML path) and the problem; the reference and shipped scenarios are valid.
//!
//! The invalid (and the borderline valid) configurations are one table, [`cases`]: each row
//! changes a valid configuration — an edit of the reference parsed as a `toml::Table`, or a
//! replacement in a file's text (for line/column checks) — and says what must come out. Every
//! rejection is checked the same way: the message starts with the field's TOML path,
//! `ConfigError::field()` returns it, the message contains the row's words, and it names no
//! Rust type.

use std::path::{Path, PathBuf};

use flexdyn_dynamics::{GravityModel, InitialTranslation};
use flexdyn_kernel::schema::SchemaError;
use flexdyn_vehicle::config::{ConfigError, SimConfig, DEFAULT_CONFIG_TOML};
use nalgebra::{Matrix3, Vector3};
use toml::{Table, Value};

fn reference_table() -> Table {
    DEFAULT_CONFIG_TOML
        .parse::<Table>()
        .expect("reference is valid TOML")
}

fn table<'a>(t: &'a mut Table, key: &str) -> &'a mut Table {
    t.get_mut(key)
        .and_then(Value::as_table_mut)
        .unwrap_or_else(|| panic!("no table {key}"))
}

fn pair(t: &mut Table, i: usize) -> &mut Table {
    t.get_mut("panel_pairs")
        .and_then(Value::as_array_mut)
        .and_then(|a| a.get_mut(i))
        .and_then(Value::as_table_mut)
        .expect("pair")
}

fn vec_value(v: &[f64]) -> Value {
    Value::Array(v.iter().map(|x| Value::Float(*x)).collect())
}

fn mat_value(m: [[f64; 3]; 3]) -> Value {
    Value::Array(m.iter().map(|r| vec_value(r)).collect())
}

fn wrench_row(t_s: f64, force: [f64; 3], torque: [f64; 3]) -> Value {
    let mut row = Table::new();
    row.insert("t_s".into(), Value::Float(t_s));
    row.insert("force_b_newton".into(), vec_value(&force));
    row.insert("torque_b_nm".into(), vec_value(&torque));
    Value::Table(row)
}

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

// ---------------------------------------------------------------------------------------------
// Valid configurations.

#[test]
fn reference_parses_to_the_documented_values() {
    let cfg = SimConfig::from_toml_str(DEFAULT_CONFIG_TOML).expect("reference is valid");
    assert_eq!(cfg, SimConfig::reference());
    assert_eq!(cfg.step_ns, 1_000_000);
    assert_eq!(cfg.frame_ns, 10_000_000);
    assert_eq!(cfg.frame_hz, 100.0);
    assert_eq!(cfg.steps_per_frame(), 10);
    assert_eq!(
        cfg.gravity,
        GravityModel::PointMass {
            mu_m3_s2: 3.986004415e14
        }
    );
    assert_eq!(cfg.hub.mass_kg, 750.0);
    assert_eq!(
        cfg.hub.inertia_bc_b_kg_m2,
        Matrix3::from_diagonal(&Vector3::new(900.0, 800.0, 600.0))
    );
    assert_eq!(cfg.hub.r_bcb_b_m, Vector3::new(0.0, 0.0, 1.0));
    assert_eq!(
        cfg.initial.translation,
        InitialTranslation::CenterOfMass {
            r_cn_n_m: Vector3::new(-4020338.69, 7490566.74, 5248299.04),
            v_cn_n_m_s: Vector3::new(-5199.77710904, -3436.68156331, 1041.57627160),
        }
    );
    assert_eq!(cfg.initial.sigma_bn, Vector3::zeros());
    assert_eq!(
        cfg.initial.omega_bn_b_rad_s,
        Vector3::new(0.05, -0.05, 0.05)
    );
    assert_eq!(cfg.panel_pairs.len(), 2);
    let expected = [
        (
            "wing_px",
            [0.5, 0.0, 1.0],
            -1.0,
            [0.08726646259971647, -0.05235987755982989],
        ),
        (
            "wing_mx",
            [-0.5, 0.0, 1.0],
            1.0,
            [-0.03490658503988659, 0.06981317007977318],
        ),
    ];
    for ((p, init), (name, r, sign, theta)) in cfg.panel_pairs.iter().zip(expected) {
        assert_eq!(p.name, name);
        assert_eq!(p.r_h1b_b_m, Vector3::from(r));
        assert_eq!(
            p.dcm_h1b,
            Matrix3::from_diagonal(&Vector3::new(sign, sign, 1.0))
        );
        assert_eq!(p.theta_h2s1_rad, 0.0);
        assert_eq!(p.l1_m, 1.5);
        assert_eq!(p.motor_torque_nm, [0.0, 0.0]);
        for panel in [&p.panel1, &p.panel2] {
            assert_eq!(panel.mass_kg, 50.0);
            assert_eq!(panel.inertia_s_kg_m2, Vector3::new(50.0, 25.0, 25.0));
            assert_eq!(panel.d_m, 0.75);
            assert_eq!(panel.k_nm_rad, 100.0);
            assert_eq!(panel.c_nm_s_rad, 0.0);
        }
        assert_eq!(init.theta1_rad, theta[0]);
        assert_eq!(init.theta2_rad, theta[1]);
        assert_eq!(init.theta1_dot_rad_s, 0.0);
        assert_eq!(init.theta2_dot_rad_s, 0.0);
    }
    assert!(cfg.wrench_schedule.is_empty());
    assert!(cfg.server.is_empty());
    assert!(cfg.sensors.is_empty());
    assert_eq!(cfg.source_toml, DEFAULT_CONFIG_TOML);
    assert_eq!(cfg.total_mass_kg(), 950.0);
}

#[test]
fn reference_file_is_the_embedded_default() {
    let text = std::fs::read_to_string(scenarios_dir().join("reference.toml")).unwrap();
    assert_eq!(text, DEFAULT_CONFIG_TOML);
}

#[test]
fn every_shipped_scenario_is_valid() {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(scenarios_dir()).unwrap() {
        let path = entry.unwrap().path();
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let is_fleet = path.extension().is_some_and(|e| e == "toml")
            && std::fs::read_to_string(&path)
                .unwrap()
                .contains("[[vehicles]]");
        if let Some(scenario) = stem.strip_suffix(".devices") {
            // A device gateway's device list: every description it names resolves against what
            // its scenario (the same name without `.devices`) serves.
            let text = std::fs::read_to_string(scenarios_dir().join(format!("{scenario}.toml")))
                .unwrap_or_else(|e| panic!("{}: no scenario {scenario}.toml: {e}", path.display()));
            let cfg = flexdyn_proto::client::vehicle::VehicleConfig::from_toml(&text).unwrap();
            let catalog = flexdyn_devices::catalog::VehicleCatalog::from_config(&cfg);
            flexdyn_gateway::device::DeviceSet::load(&path, catalog.catalog())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            names.push(stem);
        } else if stem.ends_with("campaign") {
            // A Monte Carlo campaign (over the reference spacecraft, or over a fleet), not a
            // spacecraft: it must load and plan (every dispersion key resolved and read back
            // from the model) and draw a valid first run.
            let c = flexdyn_campaign::spec::Campaign::from_file(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let plan = flexdyn_campaign::plan::Plan::new(c)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let first = plan.run(0);
            assert!(
                first.valid,
                "{}: {:?}",
                path.display(),
                first.redraw_reasons
            );
            names.push(stem);
        } else if is_fleet {
            // A fleet file: every vehicle's configuration valid, and the world builds.
            let fleet = flexdyn_vehicle::world::FleetConfig::from_file(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            flexdyn_vehicle::world::World::new(&fleet)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            names.push(stem);
        } else if path.extension().is_some_and(|e| e == "toml") {
            let cfg =
                SimConfig::from_file(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            cfg.build_spacecraft()
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            names.push(path.file_stem().unwrap().to_string_lossy().into_owned());
        }
    }
    names.sort();
    assert_eq!(
        names,
        [
            "acs_full",
            "campaign",
            "damped_wing",
            "depletion",
            "eight_pairs",
            "fdir",
            "fdir_campaign",
            "folded_wing",
            "formation",
            "formation_campaign",
            "gateway_pointing",
            "gateway_pointing.devices",
            "imu_tactical",
            "j2_orbit",
            "leo_environment",
            "no_gravity",
            "panel_chain",
            "reference",
            "slosh",
            "srp_cannonball_basilisk",
            "wheel_slew",
            "wheels_star_tracker",
            "wheels_star_tracker.devices"
        ]
    );
}

#[test]
fn shipped_scenarios_have_their_advertised_features() {
    let load = |n: &str| SimConfig::from_file(&scenarios_dir().join(format!("{n}.toml"))).unwrap();
    assert_eq!(load("no_gravity").gravity, GravityModel::None);
    let damped = load("damped_wing");
    assert!(damped
        .panel_pairs
        .iter()
        .all(|(p, _)| p.panel1.c_nm_s_rad > 0.0 && p.panel2.c_nm_s_rad > 0.0));
    assert!(load("folded_wing")
        .panel_pairs
        .iter()
        .all(|(p, _)| p.theta_h2s1_rad != 0.0));
    let eight = load("eight_pairs");
    assert_eq!(eight.panel_pairs.len(), 8);
    for (i, (a, _)) in eight.panel_pairs.iter().enumerate() {
        for (b, _) in &eight.panel_pairs[i + 1..] {
            assert!(
                (a.dcm_h1b - b.dcm_h1b).abs().max() > 0.1,
                "{} and {} share a dcm_h1b",
                a.name,
                b.name
            );
        }
    }
    assert_eq!(
        load("j2_orbit").gravity,
        GravityModel::J2 {
            mu_m3_s2: 3.986004415e14,
            j2: 1.08262668e-3,
            r_eq_m: 6378136.3
        }
    );
}

#[test]
fn r_cn_sets_the_centre_of_mass() {
    let cfg = SimConfig::reference();
    let InitialTranslation::CenterOfMass {
        r_cn_n_m,
        v_cn_n_m_s,
    } = cfg.initial.translation
    else {
        panic!("reference gives the CoM");
    };
    let sc = cfg.build_spacecraft().unwrap();
    let (mass, c_b, c_dot_b) = sc.center_of_mass();
    assert_eq!(mass, 950.0);
    let dcm_nb = flexdyn_kernel::attitude::mrp_to_dcm(&sc.state().sigma_bn).transpose();
    let r_c = sc.state().r_bn_n + dcm_nb * c_b;
    // `c_dot_b` is the inertial rate of c (it includes ω × c), B components.
    let v_c = sc.state().v_bn_n + dcm_nb * c_dot_b;
    assert!(
        (r_c - r_cn_n_m).norm() <= 1e-9 * r_cn_n_m.norm(),
        "{r_c} vs {r_cn_n_m}"
    );
    assert!(
        (v_c - v_cn_n_m_s).norm() <= 1e-9 * v_cn_n_m_s.norm(),
        "{v_c} vs {v_cn_n_m_s}"
    );
    // The orbital angular momentum is m r_C × v_C.
    let h = sc.conserved().orb_ang_mom_n;
    let expected = r_cn_n_m.cross(&v_cn_n_m_s) * 950.0;
    assert!((h - expected).norm() <= 1e-9 * expected.norm());
    // The CoM is offset from B (the wings are deflected and the hub CoM is at z = 1 m).
    assert!(c_b.norm() > 0.5);
}

#[test]
fn r_bn_sets_point_b() {
    let cfg = SimConfig::from_toml_str(
        &DEFAULT_CONFIG_TOML
            .replace("r_cn_n_m = [", "r_bn_n_m = [")
            .replace("v_cn_n_m_s = [", "v_bn_n_m_s = ["),
    )
    .unwrap();
    let sc = cfg.build_spacecraft().unwrap();
    assert_eq!(
        sc.state().r_bn_n,
        Vector3::new(-4020338.69, 7490566.74, 5248299.04)
    );
    assert_eq!(
        sc.state().v_bn_n,
        Vector3::new(-5199.77710904, -3436.68156331, 1041.57627160)
    );
}

#[test]
fn optional_keys_are_mapped() {
    let mut t = reference_table();
    pair(&mut t, 1).insert("motor_torque_nm".into(), vec_value(&[1.5, -0.5]));
    t.insert(
        "wrench_schedule".into(),
        Value::Array(vec![
            wrench_row(0.0, [1.0, 2.0, 3.0], [0.1, 0.2, 0.3]),
            wrench_row(0.25, [0.0; 3], [0.0; 3]),
        ]),
    );
    let mut server = Table::new();
    server.insert("anything".into(), Value::String("kept raw".into()));
    t.insert("server".into(), Value::Table(server.clone()));
    let mut imu = Table::new();
    imu.insert("name".into(), Value::String("imu0".into()));
    imu.insert("r_sb_b_m".into(), vec_value(&[0.2, 0.1, 1.2]));
    imu.insert(
        "dcm_pb".into(),
        mat_value([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
    );
    imu.insert("seed".into(), Value::Integer(1));
    t.insert("imus".into(), Value::Array(vec![Value::Table(imu)]));
    let cfg = SimConfig::from_toml_str(&toml::to_string(&t).unwrap()).unwrap();
    assert_eq!(cfg.panel_pairs[1].0.motor_torque_nm, [1.5, -0.5]);
    assert_eq!(cfg.panel_pairs[0].0.motor_torque_nm, [0.0, 0.0]);
    assert_eq!(cfg.wrench_schedule.len(), 2);
    assert_eq!(cfg.wrench_schedule[0].t_start_ns, 0);
    assert_eq!(
        cfg.wrench_schedule[0].force_b_newton,
        Vector3::new(1.0, 2.0, 3.0)
    );
    assert_eq!(
        cfg.wrench_schedule[0].torque_b_nm,
        Vector3::new(0.1, 0.2, 0.3)
    );
    assert_eq!(cfg.wrench_schedule[1].t_start_ns, 250_000_000);
    assert_eq!(cfg.server, server);
    // An IMU without [imus.gyro] / [imus.accel] tables has every error term zero.
    assert_eq!(
        cfg.sensors.all::<flexdyn_sensors::imu::ImuConfig>(),
        vec![&flexdyn_sensors::imu::ImuConfig::ideal(
            "imu0",
            Vector3::new(0.2, 0.1, 1.2),
            Matrix3::identity(),
            1
        )]
    );
}

// ---------------------------------------------------------------------------------------------
// The table: a change to a valid configuration, and what it must give.

/// One step of a TOML path: a table key or an array index.
enum Step {
    Key(String),
    Index(usize),
}

/// `hub.inertia_bc_b_kg_m2[2][1]` → `hub`, `inertia_bc_b_kg_m2`, `[2]`, `[1]`.
fn steps(path: &str) -> Vec<Step> {
    let mut out = Vec::new();
    for segment in path.split('.') {
        let (name, indices) = segment.split_once('[').unwrap_or((segment, ""));
        out.push(Step::Key(name.to_owned()));
        for i in indices.split('[') {
            let i = i.trim_end_matches(']');
            if !i.is_empty() {
                out.push(Step::Index(i.parse().expect("an index")));
            }
        }
    }
    out
}

/// The value at `steps`, which must exist.
fn value_at<'a>(t: &'a mut Table, steps: &[Step]) -> &'a mut Value {
    let (Some(Step::Key(first)), rest) = (steps.first(), steps.get(1..).unwrap_or_default()) else {
        panic!("a path starts with a key");
    };
    let mut v = t.get_mut(first).unwrap_or_else(|| panic!("no key {first}"));
    for s in rest {
        v = match (s, v) {
            (Step::Key(k), Value::Table(t)) => t.get_mut(k).unwrap_or_else(|| panic!("no key {k}")),
            (Step::Index(i), Value::Array(a)) => &mut a[*i],
            _ => panic!("the path does not fit the document"),
        };
    }
    v
}

/// Sets the value at `path` (its last key is created if absent).
fn put(t: &mut Table, path: &str, v: Value) {
    let steps = steps(path);
    let (last, parent) = steps.split_last().expect("a path");
    let Step::Key(key) = last else {
        *value_at(t, &steps) = v;
        return;
    };
    let table = if parent.is_empty() {
        t
    } else {
        value_at(t, parent)
            .as_table_mut()
            .expect("the parent is a table")
    };
    table.insert(key.clone(), v);
}

/// Removes the key at `path`, which must exist.
fn remove(t: &mut Table, path: &str) {
    let steps = steps(path);
    let (Some(Step::Key(key)), parent) = (steps.last(), &steps[..steps.len() - 1]) else {
        panic!("{path} does not end on a key");
    };
    let table = if parent.is_empty() {
        t
    } else {
        value_at(t, parent).as_table_mut().expect("a table")
    };
    table.remove(key).unwrap_or_else(|| panic!("no key {path}"));
}

fn f(x: f64) -> Value {
    Value::Float(x)
}

fn s(x: &str) -> Value {
    Value::String(x.into())
}

/// What a row changes: `base` is a shipped scenario (`scenarios/<base>.toml`; `reference` is
/// the embedded default).
struct Input {
    base: &'static str,
    change: Change,
}

enum Change {
    /// The file parsed as a table, edited, and written back.
    Edit(Box<dyn Fn(&mut Table)>),
    /// The file's text with the first `from` replaced by `to`.
    Replace(&'static str, String),
}

impl Input {
    fn text(&self) -> String {
        let base = std::fs::read_to_string(scenarios_dir().join(format!("{}.toml", self.base)))
            .expect("a shipped scenario");
        match &self.change {
            Change::Edit(edit) => {
                let mut t: Table = base.parse().expect("a valid scenario");
                edit(&mut t);
                toml::to_string(&t).expect("serialises")
            }
            Change::Replace(from, to) => {
                assert!(base.contains(from), "{} lacks {from:?}", self.base);
                base.replacen(from, to, 1)
            }
        }
    }
}

fn edit(change: impl Fn(&mut Table) + 'static) -> Input {
    Input {
        base: "reference",
        change: Change::Edit(Box::new(change)),
    }
}

fn text(from: &'static str, to: impl Into<String>) -> Input {
    Input {
        base: "reference",
        change: Change::Replace(from, to.into()),
    }
}

/// The `ConfigError` variant, by name.
fn kind(e: &ConfigError) -> &'static str {
    match e {
        ConfigError::Io { .. } => "Io",
        ConfigError::Syntax { .. } => "Syntax",
        ConfigError::Schema(SchemaError::UnknownKey { .. }) => "UnknownKey",
        ConfigError::Schema(SchemaError::MissingKey { .. }) => "MissingKey",
        ConfigError::Schema(SchemaError::InvalidValue { .. }) => "InvalidValue",
        ConfigError::Param { .. } => "Param",
        ConfigError::Timing { .. } => "Timing",
        ConfigError::InitialPoint { .. } => "InitialPoint",
        ConfigError::Gravity { .. } => "Gravity",
        ConfigError::WrenchSchedule { .. } => "WrenchSchedule",
        ConfigError::Invalid { .. } => "Invalid",
        _ => "another variant",
    }
}

enum Want {
    /// Accepted; the check, if any, looks at what was read.
    Accepted(Option<fn(&SimConfig)>),
    /// Rejected: the message starts with `field` (`None`: a syntax error, which has none),
    /// `field()` returns it, and the message contains each of `says`.
    Rejected {
        field: Option<&'static str>,
        says: &'static [&'static str],
        /// The `ConfigError` variant, where the row pins it.
        kind: Option<&'static str>,
        /// The message ends with the line of the changed text that starts with this prefix (and
        /// this column, if given).
        line_of: Option<(&'static str, Option<usize>)>,
        /// The message is shorter than this (no 301-digit numbers).
        shorter_than: Option<usize>,
    },
}

struct Case {
    input: Input,
    want: Want,
}

fn rejects(input: Input, field: &'static str, says: &'static [&'static str]) -> Case {
    Case {
        input,
        want: Want::Rejected {
            field: Some(field),
            says,
            kind: None,
            line_of: None,
            shorter_than: None,
        },
    }
}

fn accepts(input: Input) -> Case {
    Case {
        input,
        want: Want::Accepted(None),
    }
}

fn accepts_and(input: Input, check: fn(&SimConfig)) -> Case {
    Case {
        input,
        want: Want::Accepted(Some(check)),
    }
}

/// `path` set to `v` is rejected, naming `path`.
fn bad(path: &'static str, v: Value, says: &'static [&'static str]) -> Case {
    rejects(edit(move |t| put(t, path, v.clone())), path, says)
}

/// `path` removed is rejected as missing.
fn missing(path: &'static str) -> Case {
    rejects(edit(move |t| remove(t, path)), path, &["missing"])
}

/// A 3×3 matrix at `path` is rejected, naming `path`.
fn bad_mat(path: &'static str, m: [[f64; 3]; 3], says: &'static [&'static str]) -> Case {
    bad(path, mat_value(m), says)
}

/// The wrench schedule `rows` (t_s, force, torque) is rejected, naming `field`.
fn bad_wrenches(
    rows: &'static [(f64, [f64; 3], [f64; 3])],
    field: &'static str,
    says: &'static [&'static str],
) -> Case {
    let rows = Value::Array(
        rows.iter()
            .map(|(t, f, m)| wrench_row(*t, *f, *m))
            .collect(),
    );
    rejects(
        edit(move |t| put(t, "wrench_schedule", rows.clone())),
        field,
        says,
    )
}

impl Case {
    fn on(mut self, base: &'static str) -> Self {
        self.input.base = base;
        self
    }

    fn kind(mut self, k: &'static str) -> Self {
        if let Want::Rejected { kind, .. } = &mut self.want {
            *kind = Some(k);
        }
        self
    }

    fn at_line_of(mut self, prefix: &'static str, column: Option<usize>) -> Self {
        if let Want::Rejected { line_of, .. } = &mut self.want {
            *line_of = Some((prefix, column));
        }
        self
    }

    fn shorter_than(mut self, n: usize) -> Self {
        if let Want::Rejected { shorter_than, .. } = &mut self.want {
            *shorter_than = Some(n);
        }
        self
    }

    /// Checks the row; the error says what differs.
    fn check(&self) -> Result<(), String> {
        let text = self.input.text();
        let result = SimConfig::from_toml_str(&text);
        let (e, field, says, want_kind, line_of, shorter_than) = match (&self.want, result) {
            (Want::Accepted(check), Ok(cfg)) => {
                if let Some(check) = check {
                    check(&cfg);
                }
                return Ok(());
            }
            (Want::Accepted(_), Err(e)) => return Err(format!("rejected: {e}")),
            (Want::Rejected { field, .. }, Ok(_)) => {
                return Err(format!("accepted, but {field:?} should be rejected"))
            }
            (
                Want::Rejected {
                    field,
                    says,
                    kind,
                    line_of,
                    shorter_than,
                },
                Err(e),
            ) => (e, field, says, kind, line_of, shorter_than),
        };
        let msg = e.to_string();
        if let Some(field) = field {
            if !msg.starts_with(field) {
                return Err(format!("message does not start with `{field}`: {msg}"));
            }
        }
        if e.field() != *field {
            return Err(format!("field() is {:?}, not {field:?}: {msg}", e.field()));
        }
        for word in *says {
            if !msg.contains(word) {
                return Err(format!("message does not say `{word}`: {msg}"));
            }
        }
        if let Some(k) = want_kind {
            if kind(&e) != *k {
                return Err(format!("a {} error, not {k}: {msg}", kind(&e)));
            }
        }
        if let Some((prefix, column)) = line_of {
            let line = 1 + text
                .lines()
                .position(|l| l.starts_with(prefix))
                .ok_or_else(|| format!("no line starts with {prefix:?}"))?;
            let at = match column {
                Some(c) => format!("line {line}, column {c}"),
                None => format!("line {line}, column"),
            };
            if !msg.contains(&at) {
                return Err(format!("message does not point at `{at}`: {msg}"));
            }
        }
        if let Some(n) = shorter_than {
            if msg.len() >= *n {
                return Err(format!(
                    "{} characters, not fewer than {n}: {msg}",
                    msg.len()
                ));
            }
        }
        // No message may name a Rust type or serde internals.
        for leak in [
            "Raw", "struct", "i128", "$__", "f64", "u64", "usize", "Vec<", "Option<",
        ] {
            if msg.contains(leak) {
                return Err(format!("message leaks `{leak}`: {msg}"));
            }
        }
        Ok(())
    }
}

/// The smallest CoM radius the reference's point-mass gravity accepts: √(r³/μ) ≥ 100 steps ⇔
/// r ≥ (μ (100 h)²)^(1/3), with μ = 3.986004415e14 m³/s² and h = 1 ms.
fn r_min_m() -> f64 {
    let GravityModel::PointMass { mu_m3_s2 } = SimConfig::reference().gravity else {
        panic!("reference gravity is point mass")
    };
    (mu_m3_s2 * (100.0f64 * 1e-3).powi(2)).cbrt()
}

/// The reference panel's inertia about its hinge: I_s2 + m d² = 25 + 50 · 0.75² kg·m².
const I_HINGE_KG_M2: f64 = 25.0 + 50.0 * 0.75 * 0.75;

/// `n` copies of the reference's first panel pair, named `p0`, `p1`, ….
fn many_pairs(t: &mut Table, n: usize) {
    let p = t["panel_pairs"].as_array().expect("pairs")[0].clone();
    let pairs = (0..n)
        .map(|i| {
            let mut q = p.as_table().expect("a pair").clone();
            q.insert("name".into(), s(&format!("p{i}")));
            Value::Table(q)
        })
        .collect();
    t.insert("panel_pairs".into(), Value::Array(pairs));
}

/// Every float the non-finite rows set (to NaN, +Inf and −Inf), and what each needs first.
fn non_finite_rows() -> Vec<Case> {
    fn none(_: &mut Table) {}
    fn one_wrench(t: &mut Table) {
        t.insert(
            "wrench_schedule".into(),
            Value::Array(vec![wrench_row(0.0, [0.0; 3], [0.0; 3])]),
        );
    }
    fn two_wrenches(t: &mut Table) {
        t.insert(
            "wrench_schedule".into(),
            Value::Array(vec![
                wrench_row(0.0, [0.0; 3], [0.0; 3]),
                wrench_row(1.0, [0.0; 3], [0.0; 3]),
            ]),
        );
    }
    fn server(t: &mut Table) {
        t.insert("server".into(), Value::Table(Table::new()));
    }
    type Setup = fn(&mut Table);
    let fields: [(&'static str, Setup); 22] = [
        ("simulation.step_s", none),
        ("simulation.frame_hz", none),
        ("gravity.mu_m3_s2", none),
        ("hub.mass_kg", none),
        ("hub.inertia_bc_b_kg_m2[2][1]", none),
        ("hub.r_bcb_b_m[0]", none),
        ("initial.r_cn_n_m[1]", none),
        ("initial.v_cn_n_m_s[2]", none),
        ("initial.sigma_bn[0]", none),
        ("initial.omega_bn_b_rad_s[1]", none),
        ("panel_pairs[1].r_h1b_b_m[2]", none),
        ("panel_pairs[0].dcm_h1b[1][1]", none),
        ("panel_pairs[0].theta_h2s1_rad", none),
        ("panel_pairs[1].motor_torque_nm", none),
        ("panel_pairs[1].panel1.l_m", none),
        ("panel_pairs[0].panel2.inertia_s_kg_m2[0]", none),
        ("panel_pairs[1].panel2.theta_rad", none),
        ("panel_pairs[0].panel1.theta_dot_rad_s", none),
        ("wrench_schedule[0].t_s", one_wrench),
        ("wrench_schedule[1].force_b_newton[0]", two_wrenches),
        ("wrench_schedule[0].torque_b_nm[2]", one_wrench),
        ("server.period_s", server),
    ];
    let mut rows = Vec::new();
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for (field, setup) in fields {
            let row = if field == "panel_pairs[1].motor_torque_nm" {
                // An optional key the reference leaves out: written whole, its 2nd element bad.
                rejects(
                    edit(move |t| put(t, field, vec_value(&[0.0, v]))),
                    "panel_pairs[1].motor_torque_nm[1]",
                    &["must be finite"],
                )
            } else {
                rejects(
                    edit(move |t| {
                        setup(t);
                        put(t, field, f(v));
                    }),
                    field,
                    &["must be finite"],
                )
            };
            rows.push(row);
        }
    }
    for lit in ["nan", "+nan", "-nan", "inf", "+inf", "-inf"] {
        rows.push(
            rejects(
                text("mass_kg = 750.0", format!("mass_kg = {lit}")),
                "hub.mass_kg",
                &["must be finite", "line"],
            )
            .at_line_of("mass_kg", None),
        );
    }
    rows
}

fn cases() -> Vec<Case> {
    const Z: [f64; 3] = [0.0; 3];
    let mut rows = vec![
        // --- Structure: syntax, unknown keys, missing keys, types.
        Case {
            input: text("mass_kg = 750.0", "mass_kg = 750.0.0"),
            want: Want::Rejected {
                field: None,
                says: &[],
                kind: Some("Syntax"),
                line_of: Some(("mass_kg = 750.0.0", None)),
                shorter_than: None,
            },
        },
        bad("simulations", Value::Table(Table::new()), &["unknown key"]).kind("UnknownKey"),
        bad("hub.mass_lb", f(1.0), &["unknown key"]),
        bad("simulation.step_ms", f(1.0), &["unknown key"]),
        // panel2 has no length: l_m is only for panel1.
        bad("panel_pairs[1].panel2.l_m", f(1.5), &["unknown key"]),
        rejects(
            edit(|t| {
                put(
                    t,
                    "wrench_schedule",
                    Value::Array(vec![wrench_row(0.0, Z, Z)]),
                );
                put(t, "wrench_schedule[0].force_n", vec_value(&Z));
            }),
            "wrench_schedule[0].force_n",
            &["unknown key"],
        ),
        rejects(
            text("frame_hz = 100.0", "frame_hz = 100.0\nframe_rate = 1.0"),
            "simulation.frame_rate",
            &["unknown key"],
        )
        .at_line_of("frame_rate", Some(1)),
        missing("hub.mass_kg").kind("MissingKey"),
        missing("initial.sigma_bn"),
        missing("panel_pairs[1].panel1.k_nm_rad"),
        missing("panel_pairs[0].panel1.l_m"),
        missing("simulation"),
        missing("panel_pairs"),
        bad("hub.mass_kg", s("heavy"), &["invalid", "string"]).kind("InvalidValue"),
        bad(
            "hub.r_bcb_b_m",
            vec_value(&[0.0, 1.0]),
            &["expected 3 elements, got 2"],
        ),
        // --- Physics.
        bad("hub.mass_kg", f(0.0), &["must be > 0"]).kind("Param"),
        bad("hub.mass_kg", f(-750.0), &["must be > 0"]).kind("Param"),
        bad(
            "panel_pairs[1].panel1.mass_kg",
            f(-50.0),
            &["must be > 0", "-50"],
        ),
        bad("panel_pairs[0].panel2.mass_kg", f(0.0), &["must be > 0"]),
        rejects(
            text("mass_kg = 750.0", "mass_kg = -1.0"),
            "hub.mass_kg",
            &["must be > 0"],
        )
        .at_line_of("mass_kg = -1.0", Some(11)),
        bad_mat(
            "hub.inertia_bc_b_kg_m2",
            [[900.0, 10.0, 0.0], [0.0, 800.0, 0.0], [0.0, 0.0, 600.0]],
            &["not symmetric"],
        ),
        bad_mat(
            "hub.inertia_bc_b_kg_m2",
            [[900.0, 0.0, 0.0], [0.0, -800.0, 0.0], [0.0, 0.0, 600.0]],
            &["not positive-definite"],
        ),
        // Symmetric with positive diagonal but indefinite.
        bad_mat(
            "hub.inertia_bc_b_kg_m2",
            [
                [900.0, 1000.0, 0.0],
                [1000.0, 800.0, 0.0],
                [0.0, 0.0, 600.0],
            ],
            &["not positive-definite"],
        ),
        bad_mat(
            "hub.inertia_bc_b_kg_m2",
            [[900.0, 0.0, 0.0], [0.0, 300.0, 0.0], [0.0, 0.0, 400.0]],
            &["triangle inequality"],
        ),
        bad(
            "panel_pairs[0].panel2.inertia_s_kg_m2",
            vec_value(&[0.0, 25.0, 25.0]),
            &["not positive-definite"],
        ),
        bad(
            "panel_pairs[1].panel1.inertia_s_kg_m2",
            vec_value(&[60.0, 25.0, 25.0]),
            &["triangle inequality"],
        ),
        // Off by 1e-8 in one element: beyond the 1e-9 tolerance.
        bad_mat(
            "panel_pairs[1].dcm_h1b",
            [[1.0 + 1e-8, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            &["not proper orthonormal"],
        ),
        // A reflection is orthonormal but not a rotation.
        bad_mat(
            "panel_pairs[0].dcm_h1b",
            [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            &["not proper orthonormal"],
        ),
        // Within the tolerance: accepted.
        accepts(edit(|t| {
            let m = [[1.0 + 1e-12, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            put(t, "panel_pairs[1].dcm_h1b", mat_value(m));
        })),
        bad(
            "panel_pairs[1].panel1.d_m",
            f(1.6),
            &["exceeds the panel length", "1.6", "1.5"],
        ),
        bad(
            "panel_pairs[0].panel2.k_nm_rad",
            f(-1.0),
            &["must be >= 0", "-1"],
        ),
        bad(
            "panel_pairs[1].panel1.c_nm_s_rad",
            f(-0.5),
            &["must be >= 0", "-0.5"],
        ),
        bad(
            "panel_pairs[1].name",
            s("wing_px"),
            &["duplicate", "wing_px"],
        ),
        // --- Timing.
        bad(
            "simulation.step_s",
            f(1.5e-9),
            &["not a whole number of nanoseconds"],
        )
        .kind("Timing"),
        bad("simulation.step_s", f(0.0), &["must be > 0"]),
        bad("simulation.step_s", f(-0.001), &["must be > 0"]),
        bad("simulation.frame_hz", f(0.0), &["must be > 0"]),
        bad("simulation.frame_hz", f(-0.001), &["must be > 0"]),
        rejects(
            edit(|t| put(t, "simulation.step_s", f(0.003))),
            "simulation.frame_hz",
            &["does not divide the frame"],
        ),
        // A frame shorter than the step.
        bad(
            "simulation.frame_hz",
            f(2000.0),
            &["does not divide the frame"],
        ),
        bad(
            "simulation.frame_hz",
            f(300.0),
            &["not a whole number of nanoseconds"],
        ),
        accepts_and(
            edit(|t| {
                put(t, "simulation.step_s", f(0.0005));
                put(t, "simulation.frame_hz", f(50.0));
            }),
            |cfg| {
                let got = (cfg.step_ns, cfg.frame_ns, cfg.steps_per_frame());
                assert_eq!(got, (500_000, 20_000_000, 40));
            },
        ),
        // --- Integrator (docs/models/verification.md, "Choosing the integrator").
        bad(
            "simulation.integrator",
            s("rk5"),
            &["unknown integrator \"rk5\"", "expected \"rk4\" or \"rk8\""],
        )
        .kind("Invalid"),
        bad(
            "simulation.integrator",
            s("RK4"),
            &["unknown integrator \"RK4\""],
        ),
        bad("simulation.integrator", f(8.0), &["string"]).kind("InvalidValue"),
        rejects(
            text(
                "frame_hz = 100.0",
                "frame_hz = 100.0\nintegrator = \"dopri\"",
            ),
            "simulation.integrator",
            &["unknown integrator"],
        )
        .at_line_of("integrator = ", Some(14)),
        accepts_and(edit(|_| {}), |cfg| assert_eq!(cfg.integrator.name, "rk4")),
        accepts_and(edit(|t| put(t, "simulation.integrator", s("rk8"))), |cfg| {
            assert_eq!(cfg.integrator.name, "rk8");
            assert_eq!(cfg.build_spacecraft().unwrap().integrator().name, "rk8");
            assert!(
                cfg.summary().contains("(1000000 ns, rk8)"),
                "{}",
                cfg.summary()
            );
        }),
        // --- Initial state, gravity, wrench schedule.
        rejects(
            edit(|t| put(t, "initial.r_bn_n_m", vec_value(&[7e6, 0.0, 0.0]))),
            "initial.r_bn_n_m",
            &["both", "r_cn_n_m", "exactly one"],
        )
        .kind("InitialPoint"),
        rejects(
            edit(|t| remove(t, "initial.r_cn_n_m")),
            "initial.r_cn_n_m",
            &["missing initial position", "r_bn_n_m"],
        ),
        rejects(
            edit(|t| {
                let v = table(t, "initial").remove("v_cn_n_m_s").unwrap();
                put(t, "initial.v_bn_n_m_s", v);
            }),
            "initial.v_bn_n_m_s",
            &["same point"],
        ),
        rejects(
            edit(|t| remove(t, "initial.v_cn_n_m_s")),
            "initial.v_cn_n_m_s",
            &["missing initial velocity"],
        ),
        bad(
            "gravity.model",
            s("pointmass"),
            &["unknown gravity model", "pointmass", "point_mass"],
        )
        .kind("Gravity"),
        bad(
            "gravity.j2",
            f(1.08262668e-3),
            &["not used by model \"point_mass\""],
        ),
        rejects(
            edit(|t| {
                put(t, "gravity.model", s("j2"));
                put(t, "gravity.j2", f(1.08262668e-3));
            }),
            "gravity.r_eq_m",
            &["missing"],
        ),
        rejects(
            edit(|t| put(t, "gravity.model", s("none"))),
            "gravity.mu_m3_s2",
            &["not used by model \"none\""],
        ),
        missing("gravity.mu_m3_s2"),
        bad("gravity.mu_m3_s2", f(-1.0), &["must be > 0"]),
        bad_wrenches(
            &[(1.0, Z, Z), (0.5, Z, Z)],
            "wrench_schedule[1].t_s",
            &["strictly increasing"],
        )
        .kind("WrenchSchedule"),
        bad_wrenches(
            &[(1.0, Z, Z), (1.0, [1.0; 3], Z)],
            "wrench_schedule[1].t_s",
            &["strictly increasing"],
        ),
        // The previous row's time in its shortest form: 0.3 s, not 0.30000000000000004 s
        // (3e8 ns × 1e-9 rounds up; 3e8 / 1e9 is the nearest double to 0.3).
        bad_wrenches(
            &[(0.3, Z, Z), (0.2, Z, Z)],
            "wrench_schedule[1].t_s",
            &["t_s = 0.2 s is not after the previous row's (0.3 s)"],
        ),
        bad_wrenches(&[(-1.0, Z, Z)], "wrench_schedule[0].t_s", &["must be >= 0"]),
        bad_wrenches(
            &[(0.0015, Z, Z)],
            "wrench_schedule[0].t_s",
            &["not a whole number of steps"],
        ),
        // --- Holes an outside configuration fuzzer found: each of these was accepted (or
        // misreported) before the typed reader.
        rejects(
            text(
                "r_bcb_b_m = [0.0, 0.0, 1.0]",
                r#"r_bcb_b_m = [0.0, 0.0, 1.0, "junk", true]"#,
            ),
            "hub.r_bcb_b_m",
            &["expected 3 elements, got 5", "line"],
        ),
        // A 4th row in a 3×3 matrix, and a 4-element row.
        bad(
            "hub.inertia_bc_b_kg_m2",
            Value::Array(vec![
                vec_value(&[900.0, 0.0, 0.0]),
                vec_value(&[0.0, 800.0, 0.0]),
                vec_value(&[0.0, 0.0, 600.0]),
                vec_value(&Z),
            ]),
            &["expected 3 rows", "got 4"],
        ),
        bad(
            "hub.inertia_bc_b_kg_m2[1]",
            vec_value(&[0.0, 800.0, 0.0, 1.0]),
            &["expected 3 elements, got 4"],
        ),
        bad(
            "panel_pairs[0].motor_torque_nm",
            vec_value(&Z),
            &["expected 2 elements, got 3"],
        ),
        // An element of the wrong type is named by its index.
        rejects(
            text(
                "r_bcb_b_m = [0.0, 0.0, 1.0]",
                r#"r_bcb_b_m = [0.0, "0", 1.0]"#,
            ),
            "hub.r_bcb_b_m[1]",
            &["expected a number, got a string"],
        ),
        // A positional list where a table is expected: an inline table, a top-level table.
        bad(
            "panel_pairs[0].panel1",
            Value::Array(vec![
                f(50.0),
                vec_value(&[50.0, 25.0, 25.0]),
                f(0.75),
                f(1.5),
                f(100.0),
                f(0.0),
                f(0.0),
                f(0.0),
            ]),
            &["expected a table with named keys", "positional"],
        ),
        bad(
            "gravity",
            vec_value(&[1.0, 2.0]),
            &["expected a table with named keys"],
        ),
        // IMU seeds: 2^63 − 1 is accepted; 2^63 and 2^64 − 1 are outside TOML's integers; −1
        // is below the range.
        accepts_and(text("seed = 1", "seed = 9223372036854775807"), |cfg| {
            assert_eq!(
                cfg.sensors.all::<flexdyn_sensors::imu::ImuConfig>()[0].seed,
                i64::MAX as u64
            );
        })
        .on("imu_tactical"),
        rejects(
            text("seed = 1", "seed = 9223372036854775808"),
            "imus[0].seed",
            &["64-bit integer range"],
        )
        .on("imu_tactical"),
        rejects(
            text("seed = 1", "seed = 18446744073709551615"),
            "imus[0].seed",
            &["64-bit integer range"],
        )
        .on("imu_tactical"),
        rejects(
            text("seed = 1", "seed = -1"),
            "imus[0].seed",
            &["from 0 to 9223372036854775807", "got -1"],
        )
        .on("imu_tactical"),
        rejects(
            text("seed = 1", "seed = 1.5"),
            "imus[0].seed",
            &["expected an integer, got a float"],
        )
        .on("imu_tactical"),
        // Positions gravity cannot propagate: at the centre of a point mass (an infinite
        // field), and just inside the bound r_min (just outside passes).
        bad(
            "initial.r_cn_n_m",
            vec_value(&Z),
            &["at least", "dynamical time"],
        ),
        accepts(edit(|t| {
            put(
                t,
                "initial.r_cn_n_m",
                vec_value(&[1.01 * r_min_m(), 0.0, 0.0]),
            );
        })),
        rejects(
            edit(|t| {
                put(
                    t,
                    "initial.r_cn_n_m",
                    vec_value(&[0.99 * r_min_m(), 0.0, 0.0]),
                )
            }),
            "initial.r_cn_n_m",
            &["at least", "dynamical time"],
        ),
        // J2: inside the equatorial radius is rejected, even where the point-mass bound holds.
        rejects(
            edit(|t| {
                let r_eq = t["gravity"]["r_eq_m"].as_float().expect("r_eq_m");
                put(t, "initial.r_cn_n_m", vec_value(&[0.9 * r_eq, 0.0, 0.0]));
            }),
            "initial.r_cn_n_m",
            &["equatorial radius"],
        )
        .on("j2_orbit"),
        // Free space has no bound.
        accepts(edit(|t| {
            remove(t, "gravity.mu_m3_s2");
            put(t, "gravity.model", s("none"));
            put(t, "initial.r_cn_n_m", vec_value(&Z));
        })),
        // Messages never name Rust types: a table where a string is expected, a datetime, an
        // integer beyond TOML's range, a boolean, a whole table replaced by a number (the
        // unknown key that follows is reported first), a time of day.
        rejects(
            text("model = \"point_mass\"", "model = { kind = 1 }"),
            "gravity.model",
            &[],
        ),
        rejects(
            text("mass_kg = 750.0", "mass_kg = 1979-05-27T07:32:00Z"),
            "hub.mass_kg",
            &["expected a number, got a datetime"],
        ),
        rejects(
            text("mass_kg = 750.0", "mass_kg = 99999999999999999999"),
            "hub.mass_kg",
            &["64-bit integer range", "1e20"],
        ),
        rejects(
            text("mass_kg = 750.0", "mass_kg = true"),
            "hub.mass_kg",
            &[],
        ),
        rejects(
            text("[gravity]\n", "gravity = 3\n[gravity_x]\n"),
            "gravity_x",
            &["unknown key"],
        ),
        rejects(
            text("step_s = 0.001", "step_s = 07:32:00"),
            "simulation.step_s",
            &[],
        ),
        // Huge values are compact and say the problem.
        bad_wrenches(
            &[(1e300, Z, Z)],
            "wrench_schedule[0].t_s",
            &["1e300", "beyond the maximum simulation time"],
        )
        .shorter_than(200),
        bad("hub.mass_kg", f(-1e300), &["must be > 0 (got -1e300)"]).shorter_than(120),
        bad(
            "simulation.step_s",
            f(1e300),
            &["beyond the maximum simulation time"],
        ),
        // Wire limits: 1024 pairs fit a StateMsg; 1025 do not.
        accepts(edit(|t| many_pairs(t, flexdyn_proto::MAX_PANEL_PAIRS))),
        rejects(
            edit(|t| many_pairs(t, flexdyn_proto::MAX_PANEL_PAIRS + 1)),
            "panel_pairs",
            &["1025 panel pairs", "at most 1024"],
        ),
        // Rates the step cannot resolve: with a 1 ms step, sqrt(k / I) · h ≤ 1 ⇔
        // k ≤ 1e6 · I_HINGE_KG_M2 = 53.125e6 N·m/rad.
        accepts(edit(|t| {
            put(
                t,
                "panel_pairs[0].panel1.k_nm_rad",
                f(0.99e6 * I_HINGE_KG_M2),
            );
        })),
        bad(
            "panel_pairs[0].panel1.k_nm_rad",
            f(1.01e6 * I_HINGE_KG_M2),
            &["too fast", "step"],
        ),
        bad(
            "panel_pairs[1].panel2.c_nm_s_rad",
            f(2e3 * I_HINGE_KG_M2),
            &["damping rate", "too fast"],
        ),
        bad(
            "initial.omega_bn_b_rad_s",
            vec_value(&[0.0, 0.0, 1e150]),
            &["1e150 rad/s is too fast for the 0.001 s step"],
        ),
        bad(
            "panel_pairs[0].panel1.theta_dot_rad_s",
            f(-2000.0),
            &["too fast"],
        ),
        // Every input finite and in range, but the initial torque gives an infinite
        // acceleration.
        bad_wrenches(
            &[(0.0, Z, [f64::MAX, f64::MAX, 0.0])],
            "initial",
            &["overflows to infinity"],
        ),
    ];
    rows.extend(non_finite_rows());
    rows.extend(world_rows());
    rows
}

/// `from` replaced by `to` in `scenarios/leo_environment.toml` (every world model on).
fn leo(from: &'static str, to: impl Into<String>) -> Input {
    Input {
        base: "leo_environment",
        change: Change::Replace(from, to.into()),
    }
}

/// `[epoch]`, `[orbit]` and `[environment]`: each error names its field and its line.
fn world_rows() -> Vec<Case> {
    const UTC: &str = "utc = \"2026-11-24T06:00:00Z\"";
    vec![
        // [orbit] and [initial] r/v are alternatives.
        rejects(
            leo("[initial]\n", "[initial]\nr_cn_n_m = [7.0e6, 0.0, 0.0]\n"),
            "initial.r_cn_n_m",
            &["both [orbit] and initial.r_cn_n_m"],
        )
        .at_line_of("r_cn_n_m = [7.0e6", None),
        // Dated models need [epoch].
        rejects(
            text("[hub]", "[environment]\nmagnetic = \"igrf14\"\n\n[hub]"),
            "environment.magnetic",
            &["needs a date", "[epoch]"],
        )
        .at_line_of("magnetic = \"igrf14\"", None),
        rejects(
            text(
                "[hub]",
                "[orbit]\naltitude_m = 500e3\neccentricity = 0.0\ninclination_deg = 97.4\n\
                 raan_deg = 0.0\narg_perigee_deg = 0.0\ntrue_anomaly_deg = 0.0\n\n[hub]",
            ),
            "orbit",
            &["needs a date", "[epoch]"],
        )
        .at_line_of("[orbit]", None),
        // An epoch outside IGRF-14 (1900-2030) with the field on is an error on the epoch.
        rejects(
            text(
                "[hub]",
                "[epoch]\nutc = \"2031-06-01T00:00:00Z\"\n\n[environment]\n\
                 magnetic = \"igrf14\"\n\n[hub]",
            ),
            "epoch.utc",
            &["outside the magnetic field model", "2030"],
        )
        .at_line_of("utc = \"2031", None),
        // The same epoch without the field is fine: nothing needs IGRF.
        accepts(text(
            "[hub]",
            "[epoch]\nutc = \"2031-06-01T00:00:00Z\"\n\n[environment]\nsun = true\n\n[hub]",
        )),
        rejects(
            leo(UTC, format!("{UTC}\ntai = \"2026-11-24T06:00:37\"")),
            "epoch.tai",
            &["either", "not both"],
        ),
        // An element set far from the epoch.
        rejects(
            leo(UTC, "utc = \"2027-03-01T00:00:00Z\""),
            "orbit.elements",
            &["days", "max_element_age_days"],
        ),
        // Model names and parameters.
        rejects(
            leo("magnetic = \"igrf14\"", "magnetic = \"igrf15\""),
            "environment.magnetic",
            &["unknown model \"igrf15\"", "\"igrf14\""],
        )
        .at_line_of("magnetic = \"igrf15\"", None),
        rejects(
            leo("magnetic_degree = 13", "magnetic_degree = 14"),
            "environment.magnetic_degree",
            &["14"],
        )
        .at_line_of("magnetic_degree = 14", None),
        rejects(
            leo("f107_sfu = 150.0", "f107_sfu = 5000.0"),
            "environment.f107_sfu",
            &["5000"],
        )
        .at_line_of("f107_sfu = 5000.0", None),
        rejects(
            leo("sun = true", "sun = false"),
            "environment.shadow",
            &["needs the Sun"],
        ),
        rejects(
            leo("moon = true", "mooon = true"),
            "environment.mooon",
            &["unknown key"],
        )
        .at_line_of("mooon = true", None),
        rejects(
            leo("update_hz = 10.0", "update_hz = -1.0"),
            "environment.update_hz",
            &["> 0"],
        )
        .at_line_of("update_hz = -1.0", None),
        rejects(
            leo("area_m2 = 4.0", "area_m2 = -4.0"),
            "environment.facets[0].area_m2",
            &["-4"],
        )
        .at_line_of("area_m2 = -4.0", None),
        // The models' constants (environment::model::constants).
        rejects(
            leo(
                "magnetic = \"igrf14\"\nmagnetic_degree = 13",
                "magnetic = \"dipole\"",
            ),
            "environment.magnetic",
            &["needs its dipole", "dipole_g10_nt", "dipole_moment_am2"],
        ),
        rejects(
            leo(
                "magnetic = \"igrf14\"\nmagnetic_degree = 13",
                "magnetic = \"dipole\"\ndipole_g10_nt = -29350.0\ndipole_moment_am2 = 7.7e22\n\
                 dipole_axis_e = [0.0, 0.0, -1.0]",
            ),
            "environment.dipole_moment_am2",
            &["not both"],
        ),
        rejects(
            leo(
                "magnetic_degree = 13",
                "magnetic_degree = 13\ndipole_g10_nt = -29350.0",
            ),
            "environment.dipole_g10_nt",
            &["only used by magnetic = \"dipole\""],
        )
        .at_line_of("dipole_g10_nt", None),
        rejects(
            leo(
                "magnetic = \"igrf14\"\nmagnetic_degree = 13",
                "magnetic = \"dipole\"\ndipole_g10_nt = -2.935e13",
            ),
            "environment.dipole_g10_nt",
            &["nT", "check the units"],
        ),
        rejects(
            leo(
                "magnetic = \"igrf14\"\nmagnetic_degree = 13",
                "magnetic = \"dipole\"\ndipole_moment_am2 = 7.7e22\n\
                 dipole_axis_e = [0.0, 1.0, -1.0]",
            ),
            "environment.dipole_axis_e",
            &["unit vector", "1.414"],
        ),
        rejects(
            leo(
                "atmosphere = \"nrlmsise00\"\nf107_sfu = 150.0\nf107a_sfu = 150.0\nap = 15.0",
                "atmosphere = \"exponential\"\nexponential_base_density_kg_m3 = 1.217",
            ),
            "environment.exponential_scale_height_m",
            &["missing"],
        ),
        rejects(
            leo(
                "atmosphere = \"nrlmsise00\"\nf107_sfu = 150.0\nf107a_sfu = 150.0\nap = 15.0",
                "atmosphere = \"exponential\"\nexponential_radius_m = 6378137.0",
            ),
            "environment.exponential_radius_m",
            &["only used by exponential_altitude = \"spherical\""],
        ),
        rejects(
            leo(
                "atmosphere = \"nrlmsise00\"\nf107_sfu = 150.0\nf107a_sfu = 150.0\nap = 15.0",
                "atmosphere = \"exponential\"\nexponential_altitude = \"ellipsoidal\"",
            ),
            "environment.exponential_altitude",
            &["\"ellipsoidal\"", "\"spherical\""],
        ),
        rejects(
            leo(
                "atmosphere = \"nrlmsise00\"\nf107_sfu = 150.0\nf107a_sfu = 150.0\nap = 15.0",
                "atmosphere = \"exponential\"\nexponential_base_density_kg_m3 = -1.0\n\
                 exponential_scale_height_m = 8500.0",
            ),
            "environment.exponential_base_density_kg_m3",
            &["-1", "> 0"],
        ),
        rejects(
            text("[hub]", "[environment]\ncorotating_wind = false\n\n[hub]"),
            "environment.corotating_wind",
            &["only used by an atmosphere"],
        ),
        rejects(
            leo("moon = true", "moon = true\nearth_rotation = \"itrf\""),
            "environment.earth_rotation",
            &["unknown model \"itrf\"", "\"uniform\""],
        ),
        rejects(
            leo(
                "moon = true",
                "moon = true\nearth_rotation_rate_rad_s = 7.29e-5",
            ),
            "environment.earth_rotation_rate_rad_s",
            &["only used by earth_rotation = \"uniform\""],
        ),
        rejects(
            leo(
                "moon = true",
                "moon = true\nsun_direction_n = [1.0, 1.0, 0.0]",
            ),
            "environment.sun_direction_n",
            &["unit vector"],
        ),
        rejects(
            leo("moon = true", "moon = true\nshadow_sun_radius_m = -1.0"),
            "environment.shadow_sun_radius_m",
            &["-1", "> 0"],
        ),
        rejects(
            leo(
                "solar_irradiance_1au_w_m2 = 1361.0",
                "solar_irradiance_1au_w_m2 = 0.0",
            ),
            "environment.solar_irradiance_1au_w_m2",
            &["> 0"],
        ),
        rejects(
            leo(
                "moon = true",
                "moon = true\nsolar_pressure_model = \"cannonball\"",
            ),
            "environment.cannonball_area_m2",
            &["missing"],
        ),
        rejects(
            leo(
                "moon = true",
                "moon = true\nsolar_pressure_model = \"cannonball\"\ncannonball_area_m2 = 4.0\n\
                 cannonball_reflectivity_coefficient = 3.0",
            ),
            "environment.cannonball_reflectivity_coefficient",
            &["3", "from 0 to 2"],
        ),
        rejects(
            leo("moon = true", "moon = true\ncannonball_area_m2 = 4.0"),
            "environment.cannonball_area_m2",
            &["only used by solar_pressure_model = \"cannonball\""],
        ),
        // Effectors without what they read.
        rejects(
            text("[hub]", "[environment]\ndrag = true\n\n[hub]"),
            "environment.drag",
            &["needs an atmosphere"],
        )
        .at_line_of("drag = true", None),
        rejects(
            text(
                "[hub]",
                "[environment]\nresidual_dipole_m_b_am2 = [0.0, 0.0, 1.0]\n\n[hub]",
            ),
            "environment.residual_dipole_m_b_am2",
            &["needs a magnetic field"],
        ),
        // Gravity gradient alone needs no date, and adds one dynamic effector.
        accepts_and(
            text("[hub]", "[environment]\ngravity_gradient = true\n\n[hub]"),
            |cfg| {
                let sc = cfg.build_spacecraft().unwrap();
                assert_eq!(sc.dynamic_effectors().len(), 1);
            },
        ),
        // Earth albedo (issue 39 §4): off by default, 0.3 when on, needs the Sun.
        accepts_and(
            leo("moon = true", "moon = true\nalbedo = \"lambertian\""),
            |cfg| {
                let env = cfg.environment.as_ref().unwrap();
                assert_eq!(env.models.albedo, Some(0.3));
            },
        ),
        accepts_and(leo("moon = true", "moon = true"), |cfg| {
            assert_eq!(cfg.environment.as_ref().unwrap().models.albedo, None);
        }),
        rejects(
            leo(
                "moon = true",
                "moon = true\nalbedo = \"lambertian\"\nalbedo_coefficient = 1.3",
            ),
            "environment.albedo_coefficient",
            &["1.3", "from 0 to 1"],
        ),
        rejects(
            leo("moon = true", "moon = true\nalbedo_coefficient = 0.3"),
            "environment.albedo_coefficient",
            &["only used by albedo = \"lambertian\""],
        ),
        rejects(
            leo("moon = true", "moon = true\nalbedo = \"toms\""),
            "environment.albedo",
            &["unknown model \"toms\""],
        ),
        rejects(
            text("[hub]", "[environment]\nalbedo = \"lambertian\"\n\n[hub]"),
            "environment.albedo",
            &["sunlight reflected by the Earth", "environment.sun = true"],
        )
        .at_line_of("albedo = \"lambertian\"", None),
    ]
}

#[test]
fn every_row_gives_its_outcome() {
    let rows = cases();
    let mut failures = Vec::new();
    for (i, row) in rows.iter().enumerate() {
        if let Err(why) = row.check() {
            failures.push(format!("row {i} ({}): {why}", row.input.base));
        }
    }
    let rejected = rows
        .iter()
        .filter(|r| matches!(r.want, Want::Rejected { .. }))
        .count();
    eprintln!(
        "{} rows: {rejected} rejected, {} accepted",
        rows.len(),
        rows.len() - rejected
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// ---------------------------------------------------------------------------------------------
// Files.

#[test]
fn unreadable_file_names_the_path() {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("does-not-exist.toml");
    let e = SimConfig::from_file(&path).unwrap_err();
    assert!(matches!(e, ConfigError::Io { .. }));
    assert!(e.to_string().contains("does-not-exist.toml"), "{e}");
}
