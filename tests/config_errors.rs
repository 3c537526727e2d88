//! Configuration parsing and validation: every class of invalid input gives one error naming the
//! field (as a TOML path) and the problem; the reference and shipped scenarios are valid.
//!
//! Bad configurations are built by parsing the reference TOML into a `toml::Table`, editing it
//! and re-serialising it, or by editing the reference text directly (for line/column checks).

use std::path::{Path, PathBuf};

use flexdyn::config::{ConfigError, SimConfig, DEFAULT_CONFIG_TOML};
use flexdyn::dynamics::{GravityModel, InitialTranslation};
use nalgebra::{Matrix3, Vector3};
use toml::{Table, Value};

fn reference_table() -> Table {
    DEFAULT_CONFIG_TOML
        .parse::<Table>()
        .expect("reference is valid TOML")
}

/// The error of the reference configuration after `edit`.
fn error_after(edit: impl FnOnce(&mut Table)) -> ConfigError {
    let mut t = reference_table();
    edit(&mut t);
    let text = toml::to_string(&t).expect("serialises");
    match SimConfig::from_toml_str(&text) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

/// Asserts that the message names `field` and contains every word of `problem`.
#[track_caller]
fn assert_names(e: &ConfigError, field: &str, problem: &[&str]) {
    let msg = e.to_string();
    assert!(
        msg.contains(field),
        "message does not name `{field}`: {msg}"
    );
    for p in problem {
        assert!(msg.contains(p), "message does not say `{p}`: {msg}");
    }
    assert_eq!(e.field(), Some(field), "field() of: {msg}");
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

fn panel<'a>(t: &'a mut Table, i: usize, which: &str) -> &'a mut Table {
    table(pair(t, i), which)
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
    assert!(cfg.imus.is_empty());
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
        if path.file_stem().is_some_and(|s| s == "campaign") {
            // A Monte Carlo campaign over the reference spacecraft, not a spacecraft: it must
            // load and plan (every dispersion key resolved and read back from the model).
            let c = flexdyn::campaign::spec::Campaign::from_file(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            flexdyn::campaign::plan::Plan::new(c)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            names.push("campaign".to_owned());
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
            "campaign",
            "damped_wing",
            "eight_pairs",
            "folded_wing",
            "imu_tactical",
            "j2_orbit",
            "no_gravity",
            "reference",
            "wheel_slew",
            "wheels_star_tracker"
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
    let dcm_nb = flexdyn::attitude::mrp_to_dcm(&sc.state().sigma_bn).transpose();
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
        cfg.imus,
        vec![flexdyn::sensors::imu::ImuConfig::ideal(
            "imu0",
            Vector3::new(0.2, 0.1, 1.2),
            Matrix3::identity(),
            1
        )]
    );
}

// ---------------------------------------------------------------------------------------------
// Structure: syntax, unknown keys, missing keys, types.

#[test]
fn syntax_error_reports_line_and_column() {
    let text = DEFAULT_CONFIG_TOML.replace("mass_kg = 750.0", "mass_kg = 750.0.0");
    let e = SimConfig::from_toml_str(&text).unwrap_err();
    let line = text
        .lines()
        .position(|l| l.starts_with("mass_kg = 750.0.0"))
        .unwrap()
        + 1;
    assert!(matches!(e, ConfigError::Syntax { .. }), "{e}");
    assert!(
        e.to_string().contains(&format!("line {line}, column")),
        "{e}"
    );
}

#[test]
fn unknown_top_level_key() {
    let e = error_after(|t| {
        t.insert("simulations".into(), Value::Table(Table::new()));
    });
    assert!(matches!(e, ConfigError::UnknownKey { .. }));
    assert_names(&e, "simulations", &["unknown key"]);
}

#[test]
fn unknown_key_in_a_table() {
    let e = error_after(|t| {
        table(t, "hub").insert("mass_lb".into(), Value::Float(1.0));
    });
    assert_names(&e, "hub.mass_lb", &["unknown key"]);
    let e = error_after(|t| {
        table(t, "simulation").insert("step_ms".into(), Value::Float(1.0));
    });
    assert_names(&e, "simulation.step_ms", &["unknown key"]);
}

#[test]
fn unknown_key_in_a_panel() {
    // panel2 has no length: l_m is only for panel1.
    let e = error_after(|t| {
        panel(t, 1, "panel2").insert("l_m".into(), Value::Float(1.5));
    });
    assert_names(&e, "panel_pairs[1].panel2.l_m", &["unknown key"]);
}

#[test]
fn unknown_key_in_wrench_schedule() {
    let e = error_after(|t| {
        let mut row = wrench_row(0.0, [0.0; 3], [0.0; 3]);
        row.as_table_mut()
            .unwrap()
            .insert("force_n".into(), vec_value(&[0.0; 3]));
        t.insert("wrench_schedule".into(), Value::Array(vec![row]));
    });
    assert_names(&e, "wrench_schedule[0].force_n", &["unknown key"]);
}

#[test]
fn unknown_key_reports_line_and_column() {
    let text =
        DEFAULT_CONFIG_TOML.replace("frame_hz = 100.0", "frame_hz = 100.0\nframe_rate = 1.0");
    let e = SimConfig::from_toml_str(&text).unwrap_err();
    let line = text
        .lines()
        .position(|l| l.starts_with("frame_rate"))
        .unwrap()
        + 1;
    assert_names(
        &e,
        "simulation.frame_rate",
        &["unknown key", &format!("line {line}, column 1")],
    );
}

#[test]
fn missing_key_in_a_table() {
    let e = error_after(|t| {
        table(t, "hub").remove("mass_kg");
    });
    assert!(matches!(e, ConfigError::MissingKey { .. }));
    assert_names(&e, "hub.mass_kg", &["missing"]);
    let e = error_after(|t| {
        table(t, "initial").remove("sigma_bn");
    });
    assert_names(&e, "initial.sigma_bn", &["missing"]);
}

#[test]
fn missing_key_in_a_panel() {
    let e = error_after(|t| {
        panel(t, 1, "panel1").remove("k_nm_rad");
    });
    assert_names(&e, "panel_pairs[1].panel1.k_nm_rad", &["missing"]);
    let e = error_after(|t| {
        panel(t, 0, "panel1").remove("l_m");
    });
    assert_names(&e, "panel_pairs[0].panel1.l_m", &["missing"]);
}

#[test]
fn missing_table() {
    let e = error_after(|t| {
        t.remove("simulation");
    });
    assert_names(&e, "simulation", &["missing"]);
    let e = error_after(|t| {
        t.remove("panel_pairs");
    });
    assert_names(&e, "panel_pairs", &["missing"]);
}

#[test]
fn wrong_type_or_shape() {
    let e = error_after(|t| {
        table(t, "hub").insert("mass_kg".into(), Value::String("heavy".into()));
    });
    assert!(matches!(e, ConfigError::InvalidValue { .. }));
    assert_names(&e, "hub.mass_kg", &["invalid", "string"]);
    let e = error_after(|t| {
        table(t, "hub").insert("r_bcb_b_m".into(), vec_value(&[0.0, 1.0]));
    });
    assert_names(&e, "hub.r_bcb_b_m", &["expected 3 elements, got 2"]);
}

// ---------------------------------------------------------------------------------------------
// Physics validation.

#[test]
fn non_positive_hub_mass() {
    for m in [0.0, -750.0] {
        let e = error_after(|t| {
            table(t, "hub").insert("mass_kg".into(), Value::Float(m));
        });
        assert!(matches!(e, ConfigError::Param { .. }));
        assert_names(&e, "hub.mass_kg", &["must be > 0"]);
    }
}

#[test]
fn non_positive_panel_mass() {
    let e = error_after(|t| {
        panel(t, 1, "panel1").insert("mass_kg".into(), Value::Float(-50.0));
    });
    assert_names(&e, "panel_pairs[1].panel1.mass_kg", &["must be > 0", "-50"]);
    let e = error_after(|t| {
        panel(t, 0, "panel2").insert("mass_kg".into(), Value::Float(0.0));
    });
    assert_names(&e, "panel_pairs[0].panel2.mass_kg", &["must be > 0"]);
}

#[test]
fn param_errors_report_line_and_column() {
    let text = DEFAULT_CONFIG_TOML.replace("mass_kg = 750.0", "mass_kg = -1.0");
    let e = SimConfig::from_toml_str(&text).unwrap_err();
    let line = text
        .lines()
        .position(|l| l.starts_with("mass_kg = -1.0"))
        .unwrap()
        + 1;
    assert_names(
        &e,
        "hub.mass_kg",
        &["must be > 0", &format!("line {line}, column 11")],
    );
}

#[test]
fn hub_inertia_not_symmetric() {
    let e = error_after(|t| {
        let m = [[900.0, 10.0, 0.0], [0.0, 800.0, 0.0], [0.0, 0.0, 600.0]];
        table(t, "hub").insert("inertia_bc_b_kg_m2".into(), mat_value(m));
    });
    assert_names(&e, "hub.inertia_bc_b_kg_m2", &["not symmetric"]);
}

#[test]
fn hub_inertia_not_positive_definite() {
    let e = error_after(|t| {
        let m = [[900.0, 0.0, 0.0], [0.0, -800.0, 0.0], [0.0, 0.0, 600.0]];
        table(t, "hub").insert("inertia_bc_b_kg_m2".into(), mat_value(m));
    });
    assert_names(&e, "hub.inertia_bc_b_kg_m2", &["not positive-definite"]);
    // Symmetric with positive diagonal but indefinite.
    let e = error_after(|t| {
        let m = [
            [900.0, 1000.0, 0.0],
            [1000.0, 800.0, 0.0],
            [0.0, 0.0, 600.0],
        ];
        table(t, "hub").insert("inertia_bc_b_kg_m2".into(), mat_value(m));
    });
    assert_names(&e, "hub.inertia_bc_b_kg_m2", &["not positive-definite"]);
}

#[test]
fn hub_inertia_triangle_inequality() {
    let e = error_after(|t| {
        let m = [[900.0, 0.0, 0.0], [0.0, 300.0, 0.0], [0.0, 0.0, 400.0]];
        table(t, "hub").insert("inertia_bc_b_kg_m2".into(), mat_value(m));
    });
    assert_names(&e, "hub.inertia_bc_b_kg_m2", &["triangle inequality"]);
}

#[test]
fn panel_moments_not_positive() {
    let e = error_after(|t| {
        panel(t, 0, "panel2").insert("inertia_s_kg_m2".into(), vec_value(&[0.0, 25.0, 25.0]));
    });
    assert_names(
        &e,
        "panel_pairs[0].panel2.inertia_s_kg_m2",
        &["not positive-definite"],
    );
}

#[test]
fn panel_moments_triangle_inequality() {
    let e = error_after(|t| {
        panel(t, 1, "panel1").insert("inertia_s_kg_m2".into(), vec_value(&[60.0, 25.0, 25.0]));
    });
    assert_names(
        &e,
        "panel_pairs[1].panel1.inertia_s_kg_m2",
        &["triangle inequality"],
    );
}

#[test]
fn dcm_not_orthonormal() {
    // Off by 1e-8 in one element: beyond the 1e-9 tolerance.
    let e = error_after(|t| {
        let m = [[1.0 + 1e-8, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        pair(t, 1).insert("dcm_h1b".into(), mat_value(m));
    });
    assert_names(&e, "panel_pairs[1].dcm_h1b", &["not proper orthonormal"]);
    // A reflection is orthonormal but not a rotation.
    let e = error_after(|t| {
        let m = [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        pair(t, 0).insert("dcm_h1b".into(), mat_value(m));
    });
    assert_names(&e, "panel_pairs[0].dcm_h1b", &["not proper orthonormal"]);
    // Within the tolerance: accepted.
    let mut t = reference_table();
    let m = [[1.0 + 1e-12, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    pair(&mut t, 1).insert("dcm_h1b".into(), mat_value(m));
    SimConfig::from_toml_str(&toml::to_string(&t).unwrap()).expect("1e-12 is within tolerance");
}

#[test]
fn d_exceeds_panel_length() {
    let e = error_after(|t| {
        panel(t, 1, "panel1").insert("d_m".into(), Value::Float(1.6));
    });
    assert_names(
        &e,
        "panel_pairs[1].panel1.d_m",
        &["exceeds the panel length", "1.6", "1.5"],
    );
}

#[test]
fn negative_stiffness() {
    let e = error_after(|t| {
        panel(t, 0, "panel2").insert("k_nm_rad".into(), Value::Float(-1.0));
    });
    assert_names(
        &e,
        "panel_pairs[0].panel2.k_nm_rad",
        &["must be >= 0", "-1"],
    );
}

#[test]
fn negative_damping() {
    let e = error_after(|t| {
        panel(t, 1, "panel1").insert("c_nm_s_rad".into(), Value::Float(-0.5));
    });
    assert_names(
        &e,
        "panel_pairs[1].panel1.c_nm_s_rad",
        &["must be >= 0", "-0.5"],
    );
}

#[test]
fn duplicate_pair_names() {
    let e = error_after(|t| {
        pair(t, 1).insert("name".into(), Value::String("wing_px".into()));
    });
    assert_names(&e, "panel_pairs[1].name", &["duplicate", "wing_px"]);
}

// ---------------------------------------------------------------------------------------------
// Timing.

#[test]
fn step_not_whole_nanoseconds() {
    let e = error_after(|t| {
        table(t, "simulation").insert("step_s".into(), Value::Float(1.5e-9));
    });
    assert!(matches!(e, ConfigError::Timing { .. }));
    assert_names(
        &e,
        "simulation.step_s",
        &["not a whole number of nanoseconds"],
    );
}

#[test]
fn non_positive_step_and_frame_rate() {
    for v in [0.0, -0.001] {
        let e = error_after(|t| {
            table(t, "simulation").insert("step_s".into(), Value::Float(v));
        });
        assert_names(&e, "simulation.step_s", &["must be > 0"]);
        let e = error_after(|t| {
            table(t, "simulation").insert("frame_hz".into(), Value::Float(v));
        });
        assert_names(&e, "simulation.frame_hz", &["must be > 0"]);
    }
}

#[test]
fn step_does_not_divide_frame() {
    let e = error_after(|t| {
        table(t, "simulation").insert("step_s".into(), Value::Float(0.003));
    });
    assert_names(&e, "simulation.frame_hz", &["does not divide the frame"]);
    // A frame shorter than the step.
    let e = error_after(|t| {
        table(t, "simulation").insert("frame_hz".into(), Value::Float(2000.0));
    });
    assert_names(&e, "simulation.frame_hz", &["does not divide the frame"]);
}

#[test]
fn frame_period_not_whole_nanoseconds() {
    let e = error_after(|t| {
        table(t, "simulation").insert("frame_hz".into(), Value::Float(300.0));
    });
    assert_names(
        &e,
        "simulation.frame_hz",
        &["not a whole number of nanoseconds"],
    );
}

#[test]
fn other_steps_and_frames_are_accepted() {
    let mut t = reference_table();
    table(&mut t, "simulation").insert("step_s".into(), Value::Float(0.0005));
    table(&mut t, "simulation").insert("frame_hz".into(), Value::Float(50.0));
    let cfg = SimConfig::from_toml_str(&toml::to_string(&t).unwrap()).unwrap();
    assert_eq!(
        (cfg.step_ns, cfg.frame_ns, cfg.steps_per_frame()),
        (500_000, 20_000_000, 40)
    );
}

// ---------------------------------------------------------------------------------------------
// NaN and Inf anywhere.

#[test]
fn nan_or_inf_anywhere() {
    type Edit = fn(&mut Table, f64);
    let cases: Vec<(&str, Edit)> = vec![
        ("simulation.step_s", |t, v| {
            table(t, "simulation").insert("step_s".into(), Value::Float(v));
        }),
        ("simulation.frame_hz", |t, v| {
            table(t, "simulation").insert("frame_hz".into(), Value::Float(v));
        }),
        ("gravity.mu_m3_s2", |t, v| {
            table(t, "gravity").insert("mu_m3_s2".into(), Value::Float(v));
        }),
        ("hub.mass_kg", |t, v| {
            table(t, "hub").insert("mass_kg".into(), Value::Float(v));
        }),
        ("hub.inertia_bc_b_kg_m2[2][1]", |t, v| {
            let m = [[900.0, 0.0, 0.0], [0.0, 800.0, 0.0], [0.0, v, 600.0]];
            table(t, "hub").insert("inertia_bc_b_kg_m2".into(), mat_value(m));
        }),
        ("hub.r_bcb_b_m[0]", |t, v| {
            table(t, "hub").insert("r_bcb_b_m".into(), vec_value(&[v, 0.0, 1.0]));
        }),
        ("initial.r_cn_n_m[1]", |t, v| {
            table(t, "initial").insert("r_cn_n_m".into(), vec_value(&[7e6, v, 0.0]));
        }),
        ("initial.v_cn_n_m_s[2]", |t, v| {
            table(t, "initial").insert("v_cn_n_m_s".into(), vec_value(&[0.0, 7e3, v]));
        }),
        ("initial.sigma_bn[0]", |t, v| {
            table(t, "initial").insert("sigma_bn".into(), vec_value(&[v, 0.0, 0.0]));
        }),
        ("initial.omega_bn_b_rad_s[1]", |t, v| {
            table(t, "initial").insert("omega_bn_b_rad_s".into(), vec_value(&[0.0, v, 0.0]));
        }),
        ("panel_pairs[1].r_h1b_b_m[2]", |t, v| {
            pair(t, 1).insert("r_h1b_b_m".into(), vec_value(&[-0.5, 0.0, v]));
        }),
        ("panel_pairs[0].dcm_h1b[1][1]", |t, v| {
            let m = [[-1.0, 0.0, 0.0], [0.0, v, 0.0], [0.0, 0.0, 1.0]];
            pair(t, 0).insert("dcm_h1b".into(), mat_value(m));
        }),
        ("panel_pairs[0].theta_h2s1_rad", |t, v| {
            pair(t, 0).insert("theta_h2s1_rad".into(), Value::Float(v));
        }),
        ("panel_pairs[1].motor_torque_nm[1]", |t, v| {
            pair(t, 1).insert("motor_torque_nm".into(), vec_value(&[0.0, v]));
        }),
        ("panel_pairs[1].panel1.l_m", |t, v| {
            panel(t, 1, "panel1").insert("l_m".into(), Value::Float(v));
        }),
        ("panel_pairs[0].panel2.inertia_s_kg_m2[0]", |t, v| {
            panel(t, 0, "panel2").insert("inertia_s_kg_m2".into(), vec_value(&[v, 25.0, 25.0]));
        }),
        ("panel_pairs[1].panel2.theta_rad", |t, v| {
            panel(t, 1, "panel2").insert("theta_rad".into(), Value::Float(v));
        }),
        ("panel_pairs[0].panel1.theta_dot_rad_s", |t, v| {
            panel(t, 0, "panel1").insert("theta_dot_rad_s".into(), Value::Float(v));
        }),
        ("wrench_schedule[0].t_s", |t, v| {
            t.insert(
                "wrench_schedule".into(),
                Value::Array(vec![wrench_row(v, [0.0; 3], [0.0; 3])]),
            );
        }),
        ("wrench_schedule[1].force_b_newton[0]", |t, v| {
            t.insert(
                "wrench_schedule".into(),
                Value::Array(vec![
                    wrench_row(0.0, [0.0; 3], [0.0; 3]),
                    wrench_row(1.0, [v, 0.0, 0.0], [0.0; 3]),
                ]),
            );
        }),
        ("wrench_schedule[0].torque_b_nm[2]", |t, v| {
            t.insert(
                "wrench_schedule".into(),
                Value::Array(vec![wrench_row(0.0, [0.0; 3], [0.0, 0.0, v])]),
            );
        }),
        ("server.period_s", |t, v| {
            let mut s = Table::new();
            s.insert("period_s".into(), Value::Float(v));
            t.insert("server".into(), Value::Table(s));
        }),
    ];
    for (field, edit) in cases {
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let e = error_after(|t| edit(t, v));
            assert_names(&e, field, &["must be finite"]);
        }
    }
}

#[test]
fn nan_literals_in_text() {
    for lit in ["nan", "+nan", "-nan", "inf", "+inf", "-inf"] {
        let text = DEFAULT_CONFIG_TOML.replace("mass_kg = 750.0", &format!("mass_kg = {lit}"));
        let e = SimConfig::from_toml_str(&text).unwrap_err();
        assert_names(&e, "hub.mass_kg", &["must be finite", "line"]);
    }
}

// ---------------------------------------------------------------------------------------------
// Initial state, gravity, wrench schedule.

#[test]
fn both_initial_positions() {
    let e = error_after(|t| {
        table(t, "initial").insert("r_bn_n_m".into(), vec_value(&[7e6, 0.0, 0.0]));
    });
    assert!(matches!(e, ConfigError::InitialPoint { .. }));
    assert_names(&e, "initial.r_bn_n_m", &["both", "r_cn_n_m", "exactly one"]);
}

#[test]
fn neither_initial_position() {
    let e = error_after(|t| {
        table(t, "initial").remove("r_cn_n_m");
    });
    assert_names(
        &e,
        "initial.r_cn_n_m",
        &["missing initial position", "r_bn_n_m"],
    );
}

#[test]
fn initial_velocity_of_the_other_point() {
    let e = error_after(|t| {
        let init = table(t, "initial");
        let v = init.remove("v_cn_n_m_s").unwrap();
        init.insert("v_bn_n_m_s".into(), v);
    });
    assert_names(&e, "initial.v_bn_n_m_s", &["same point"]);
    let e = error_after(|t| {
        table(t, "initial").remove("v_cn_n_m_s");
    });
    assert_names(&e, "initial.v_cn_n_m_s", &["missing initial velocity"]);
}

#[test]
fn bad_gravity_model_name() {
    let e = error_after(|t| {
        table(t, "gravity").insert("model".into(), Value::String("pointmass".into()));
    });
    assert!(matches!(e, ConfigError::Gravity { .. }));
    assert_names(
        &e,
        "gravity.model",
        &["unknown gravity model", "pointmass", "point_mass"],
    );
}

#[test]
fn gravity_parameters_must_match_the_model() {
    let e = error_after(|t| {
        table(t, "gravity").insert("j2".into(), Value::Float(1.08262668e-3));
    });
    assert_names(&e, "gravity.j2", &["not used by model \"point_mass\""]);
    let e = error_after(|t| {
        let g = table(t, "gravity");
        g.insert("model".into(), Value::String("j2".into()));
        g.insert("j2".into(), Value::Float(1.08262668e-3));
    });
    assert_names(&e, "gravity.r_eq_m", &["missing"]);
    let e = error_after(|t| {
        table(t, "gravity").insert("model".into(), Value::String("none".into()));
    });
    assert_names(&e, "gravity.mu_m3_s2", &["not used by model \"none\""]);
    let e = error_after(|t| {
        table(t, "gravity").remove("mu_m3_s2");
    });
    assert_names(&e, "gravity.mu_m3_s2", &["missing"]);
    let e = error_after(|t| {
        table(t, "gravity").insert("mu_m3_s2".into(), Value::Float(-1.0));
    });
    assert_names(&e, "gravity.mu_m3_s2", &["must be > 0"]);
}

#[test]
fn wrench_schedule_not_increasing() {
    let e = error_after(|t| {
        t.insert(
            "wrench_schedule".into(),
            Value::Array(vec![
                wrench_row(1.0, [0.0; 3], [0.0; 3]),
                wrench_row(0.5, [0.0; 3], [0.0; 3]),
            ]),
        );
    });
    assert!(matches!(e, ConfigError::WrenchSchedule { .. }));
    assert_names(&e, "wrench_schedule[1].t_s", &["strictly increasing"]);
    let e = error_after(|t| {
        t.insert(
            "wrench_schedule".into(),
            Value::Array(vec![
                wrench_row(1.0, [0.0; 3], [0.0; 3]),
                wrench_row(1.0, [1.0; 3], [0.0; 3]),
            ]),
        );
    });
    assert_names(&e, "wrench_schedule[1].t_s", &["strictly increasing"]);
}

#[test]
fn wrench_schedule_times() {
    let e = error_after(|t| {
        t.insert(
            "wrench_schedule".into(),
            Value::Array(vec![wrench_row(-1.0, [0.0; 3], [0.0; 3])]),
        );
    });
    assert_names(&e, "wrench_schedule[0].t_s", &["must be >= 0"]);
    let e = error_after(|t| {
        t.insert(
            "wrench_schedule".into(),
            Value::Array(vec![wrench_row(0.0015, [0.0; 3], [0.0; 3])]),
        );
    });
    assert_names(
        &e,
        "wrench_schedule[0].t_s",
        &["not a whole number of steps"],
    );
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

// ---------------------------------------------------------------------------------------------
// Holes an outside configuration fuzzer found: each of these was accepted (or misreported)
// before the typed reader.

/// The error of the reference text with `from` replaced by `to` (which must occur).
fn text_error(from: &str, to: &str) -> ConfigError {
    assert!(
        DEFAULT_CONFIG_TOML.contains(from),
        "reference lacks {from:?}"
    );
    let text = DEFAULT_CONFIG_TOML.replacen(from, to, 1);
    match SimConfig::from_toml_str(&text) {
        Ok(_) => panic!("expected an error after replacing {from:?} by {to:?}"),
        Err(e) => e,
    }
}

/// No message may name a Rust type or serde internals.
#[track_caller]
fn assert_speaks_toml(e: &ConfigError) {
    let msg = e.to_string();
    for leak in [
        "Raw", "struct", "i128", "$__", "f64", "u64", "usize", "Vec<", "Option<",
    ] {
        assert!(!msg.contains(leak), "message leaks `{leak}`: {msg}");
    }
}

#[test]
fn over_long_arrays_are_rejected_with_their_length() {
    let e = text_error(
        "r_bcb_b_m = [0.0, 0.0, 1.0]",
        r#"r_bcb_b_m = [0.0, 0.0, 1.0, "junk", true]"#,
    );
    assert_names(&e, "hub.r_bcb_b_m", &["expected 3 elements, got 5", "line"]);
    assert_speaks_toml(&e);
    // A 4th row in a 3×3 matrix, and a 4-element row.
    let e = error_after(|t| {
        let m = Value::Array(vec![
            vec_value(&[900.0, 0.0, 0.0]),
            vec_value(&[0.0, 800.0, 0.0]),
            vec_value(&[0.0, 0.0, 600.0]),
            vec_value(&[0.0, 0.0, 0.0]),
        ]);
        table(t, "hub").insert("inertia_bc_b_kg_m2".into(), m);
    });
    assert_names(&e, "hub.inertia_bc_b_kg_m2", &["expected 3 rows", "got 4"]);
    let e = error_after(|t| {
        let m = Value::Array(vec![
            vec_value(&[900.0, 0.0, 0.0]),
            vec_value(&[0.0, 800.0, 0.0, 1.0]),
            vec_value(&[0.0, 0.0, 600.0]),
        ]);
        table(t, "hub").insert("inertia_bc_b_kg_m2".into(), m);
    });
    assert_names(
        &e,
        "hub.inertia_bc_b_kg_m2[1]",
        &["expected 3 elements, got 4"],
    );
    let e = error_after(|t| {
        pair(t, 0).insert("motor_torque_nm".into(), vec_value(&[0.0, 0.0, 0.0]));
    });
    assert_names(
        &e,
        "panel_pairs[0].motor_torque_nm",
        &["expected 2 elements, got 3"],
    );
    // An element of the wrong type is named by its index.
    let e = text_error(
        "r_bcb_b_m = [0.0, 0.0, 1.0]",
        r#"r_bcb_b_m = [0.0, "0", 1.0]"#,
    );
    assert_names(&e, "hub.r_bcb_b_m[1]", &["expected a number, got a string"]);
}

#[test]
fn positional_inline_tables_are_rejected() {
    let e = error_after(|t| {
        let positional = Value::Array(vec![
            Value::Float(50.0),
            vec_value(&[50.0, 25.0, 25.0]),
            Value::Float(0.75),
            Value::Float(1.5),
            Value::Float(100.0),
            Value::Float(0.0),
            Value::Float(0.0),
            Value::Float(0.0),
        ]);
        pair(t, 0).insert("panel1".into(), positional);
    });
    assert_names(
        &e,
        "panel_pairs[0].panel1",
        &["expected a table with named keys", "positional"],
    );
    assert_speaks_toml(&e);
    // The same for a top-level table and an array-of-tables entry.
    let e = error_after(|t| {
        t.insert("gravity".into(), vec_value(&[1.0, 2.0]));
    });
    assert_names(&e, "gravity", &["expected a table with named keys"]);
    assert_speaks_toml(&e);
}

#[test]
fn imu_seed_range_is_toml_non_negative_integers() {
    let base = std::fs::read_to_string(scenarios_dir().join("imu_tactical.toml")).unwrap();
    let seed_line = base
        .lines()
        .find(|l| l.trim_start().starts_with("seed ="))
        .expect("a seed line")
        .to_string();
    let with = |v: &str| base.replacen(&seed_line, &format!("seed = {v}"), 1);
    // 2^63 − 1 is accepted; 2^63 and 2^64 − 1 are outside TOML's integers; −1 is below the range.
    let ok = SimConfig::from_toml_str(&with("9223372036854775807")).unwrap();
    assert_eq!(ok.imus[0].seed, i64::MAX as u64);
    for v in ["9223372036854775808", "18446744073709551615"] {
        let e = SimConfig::from_toml_str(&with(v)).unwrap_err();
        assert_names(&e, "imus[0].seed", &["64-bit integer range"]);
        assert_speaks_toml(&e);
    }
    let e = SimConfig::from_toml_str(&with("-1")).unwrap_err();
    assert_names(
        &e,
        "imus[0].seed",
        &["from 0 to 9223372036854775807", "got -1"],
    );
    let e = SimConfig::from_toml_str(&with("1.5")).unwrap_err();
    assert_names(&e, "imus[0].seed", &["expected an integer, got a float"]);
}

#[test]
fn positions_gravity_cannot_propagate_are_rejected() {
    // At the centre of a point mass: an infinite field.
    let e = error_after(|t| {
        table(t, "initial").insert("r_cn_n_m".into(), vec_value(&[0.0, 0.0, 0.0]));
    });
    assert_names(&e, "initial.r_cn_n_m", &["at least", "dynamical time"]);
    // The bound: √(r³/μ) ≥ 100 steps ⇔ r ≥ (μ (100 h)²)^(1/3). Just outside passes, just
    // inside fails (reference: μ = 3.986004418e14, h = 1 ms).
    let cfg = SimConfig::reference();
    let GravityModel::PointMass { mu_m3_s2 } = cfg.gravity else {
        panic!("reference gravity is point mass")
    };
    let r_min = (mu_m3_s2 * (100.0f64 * 1e-3).powi(2)).cbrt();
    for (r, ok) in [(1.01 * r_min, true), (0.99 * r_min, false)] {
        let mut t = reference_table();
        table(&mut t, "initial").insert("r_cn_n_m".into(), vec_value(&[r, 0.0, 0.0]));
        let res = SimConfig::from_toml_str(&toml::to_string(&t).unwrap());
        assert_eq!(res.is_ok(), ok, "r = {r} m, bound {r_min} m: {res:?}");
    }
    // J2: inside the equatorial radius is rejected, even where the point-mass bound holds.
    let j2 = std::fs::read_to_string(scenarios_dir().join("j2_orbit.toml")).unwrap();
    let mut t: Table = j2.parse().unwrap();
    let r_eq = table(&mut t, "gravity")["r_eq_m"].as_float().unwrap();
    let key = if table(&mut t, "initial").contains_key("r_cn_n_m") {
        "r_cn_n_m"
    } else {
        "r_bn_n_m"
    };
    table(&mut t, "initial").insert(key.into(), vec_value(&[0.9 * r_eq, 0.0, 0.0]));
    let e = SimConfig::from_toml_str(&toml::to_string(&t).unwrap()).unwrap_err();
    assert_names(&e, &format!("initial.{key}"), &["equatorial radius"]);
    // Free space has no bound.
    let mut t = reference_table();
    table(&mut t, "gravity").remove("mu_m3_s2");
    table(&mut t, "gravity").insert("model".into(), Value::String("none".into()));
    table(&mut t, "initial").insert("r_cn_n_m".into(), vec_value(&[0.0, 0.0, 0.0]));
    SimConfig::from_toml_str(&toml::to_string(&t).unwrap()).unwrap();
}

#[test]
fn messages_never_name_rust_types() {
    let cases: [(&str, &str, &str); 6] = [
        // A table where a string-keyed table is expected.
        (
            "model = \"point_mass\"",
            "model = { kind = 1 }",
            "gravity.model",
        ),
        // A datetime where a number is expected.
        (
            "mass_kg = 750.0",
            "mass_kg = 1979-05-27T07:32:00Z",
            "hub.mass_kg",
        ),
        // An integer beyond TOML's range.
        (
            "mass_kg = 750.0",
            "mass_kg = 99999999999999999999",
            "hub.mass_kg",
        ),
        // A boolean.
        ("mass_kg = 750.0", "mass_kg = true", "hub.mass_kg"),
        // A whole table replaced by a number.
        ("[gravity]\n", "gravity = 3\n[gravity_x]\n", "gravity"),
        // A datetime key in a table.
        ("step_s = 0.001", "step_s = 07:32:00", "simulation.step_s"),
    ];
    for (from, to, field) in cases {
        let e = text_error(from, to);
        assert_speaks_toml(&e);
        assert!(e.to_string().starts_with(field), "{e}");
    }
    let e = text_error("mass_kg = 750.0", "mass_kg = 1979-05-27T07:32:00Z");
    assert_names(&e, "hub.mass_kg", &["expected a number, got a datetime"]);
    let e = text_error("mass_kg = 750.0", "mass_kg = 99999999999999999999");
    assert_names(&e, "hub.mass_kg", &["64-bit integer range", "1e20"]);
}

#[test]
fn huge_values_are_compact_and_say_the_problem() {
    let e = error_after(|t| {
        t.insert(
            "wrench_schedule".into(),
            Value::Array(vec![wrench_row(1e300, [0.0; 3], [0.0; 3])]),
        );
    });
    let msg = e.to_string();
    assert_names(
        &e,
        "wrench_schedule[0].t_s",
        &["1e300", "beyond the maximum simulation time"],
    );
    assert!(msg.len() < 200, "{} characters: {msg}", msg.len());
    let e = error_after(|t| {
        table(t, "hub").insert("mass_kg".into(), Value::Float(-1e300));
    });
    assert_names(&e, "hub.mass_kg", &["must be > 0 (got -1e300)"]);
    assert!(e.to_string().len() < 120, "{e}");
    let e = error_after(|t| {
        table(t, "simulation").insert("step_s".into(), Value::Float(1e300));
    });
    assert_names(
        &e,
        "simulation.step_s",
        &["beyond the maximum simulation time"],
    );
}

#[test]
fn wire_limits_are_enforced_at_configuration_time() {
    // 1024 pairs fit a StateMsg; 1025 do not.
    let mut t = reference_table();
    let p = t["panel_pairs"].as_array().unwrap()[0].clone();
    let many = |n: usize| {
        Value::Array(
            (0..n)
                .map(|i| {
                    let mut q = p.as_table().unwrap().clone();
                    q.insert("name".into(), Value::String(format!("p{i}")));
                    Value::Table(q)
                })
                .collect(),
        )
    };
    t.insert("panel_pairs".into(), many(flexdyn_proto::MAX_PANEL_PAIRS));
    SimConfig::from_toml_str(&toml::to_string(&t).unwrap()).expect("1024 pairs are accepted");
    t.insert(
        "panel_pairs".into(),
        many(flexdyn_proto::MAX_PANEL_PAIRS + 1),
    );
    let e = SimConfig::from_toml_str(&toml::to_string(&t).unwrap()).unwrap_err();
    assert_names(&e, "panel_pairs", &["1025 panel pairs", "at most 1024"]);
}

#[test]
fn rates_the_step_cannot_resolve_are_rejected() {
    // Reference panel: I_s2 = 25, m = 50, d = 0.75 → I about the hinge = 53.125 kg·m²; with a
    // 1 ms step, sqrt(k / I) · h ≤ 1 ⇔ k ≤ 53.125e6 N·m/rad.
    let i_hinge = 25.0 + 50.0 * 0.75 * 0.75;
    for (k, ok) in [(0.99e6 * i_hinge, true), (1.01e6 * i_hinge, false)] {
        let mut t = reference_table();
        panel(&mut t, 0, "panel1").insert("k_nm_rad".into(), Value::Float(k));
        let res = SimConfig::from_toml_str(&toml::to_string(&t).unwrap());
        match res {
            Ok(_) => assert!(ok, "k = {k} accepted"),
            Err(e) => {
                assert!(!ok, "k = {k} rejected: {e}");
                assert_names(&e, "panel_pairs[0].panel1.k_nm_rad", &["too fast", "step"]);
            }
        }
    }
    let e = error_after(|t| {
        panel(t, 1, "panel2").insert("c_nm_s_rad".into(), Value::Float(2e3 * i_hinge));
    });
    assert_names(
        &e,
        "panel_pairs[1].panel2.c_nm_s_rad",
        &["damping rate", "too fast"],
    );
    let e = error_after(|t| {
        table(t, "initial").insert("omega_bn_b_rad_s".into(), vec_value(&[0.0, 0.0, 1e150]));
    });
    assert_names(
        &e,
        "initial.omega_bn_b_rad_s",
        &["1e150 rad/s is too fast for the 0.001 s step"],
    );
    let e = error_after(|t| {
        panel(t, 0, "panel1").insert("theta_dot_rad_s".into(), Value::Float(-2000.0));
    });
    assert_names(&e, "panel_pairs[0].panel1.theta_dot_rad_s", &["too fast"]);
}

#[test]
fn initial_outputs_that_overflow_are_rejected() {
    // Every input finite and in range, but the initial torque gives an infinite acceleration.
    let e = error_after(|t| {
        t.insert(
            "wrench_schedule".into(),
            Value::Array(vec![wrench_row(0.0, [0.0; 3], [f64::MAX, f64::MAX, 0.0])]),
        );
    });
    assert_names(&e, "initial", &["overflows to infinity"]);
}
