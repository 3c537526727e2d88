//! `[[imus]]` configuration: every invalid IMU key gives one error naming the field path and the
//! problem (no panic); defaults are zero; the shipped `imu_tactical` scenario is valid.

use std::path::Path;

use crate::imu_support::*;
use flexdyn_sensors::imu::{AccelErrors, GyroErrors, ImuConfig};
use flexdyn_vehicle::config::{ConfigError, SimConfig};
use flexdyn_vehicle::sim::Simulation;
use nalgebra::{Matrix3, Vector3};
use toml::{Table, Value};

/// The reference with one valid IMU `imu0` (and `extra` appended), after `edit` of imus[0].
fn error_after(extra: Vec<Table>, edit: impl FnOnce(&mut Table)) -> ConfigError {
    let mut t = reference_table();
    let mut imu = imu_table("imu0", Vector3::new(0.2, 0.1, 1.2), &Matrix3::identity(), 1);
    edit(&mut imu);
    let mut imus = vec![imu];
    imus.extend(extra);
    set_imus(&mut t, imus);
    let text = toml::to_string(&t).expect("serialises");
    match SimConfig::from_toml_str(&text) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

fn sub<'a>(imu: &'a mut Table, key: &str) -> &'a mut Table {
    imu.entry(key.to_string())
        .or_insert_with(|| Value::Table(Table::new()))
        .as_table_mut()
        .expect("table")
}

#[track_caller]
fn assert_names(e: &ConfigError, field: &str, problem: &[&str]) {
    let msg = e.to_string();
    assert!(
        msg.starts_with(field),
        "message does not start with `{field}`: {msg}"
    );
    for p in problem {
        assert!(msg.contains(p), "message does not say `{p}`: {msg}");
    }
    assert_eq!(e.field(), Some(field), "field() of: {msg}");
    println!("{msg}");
}

#[test]
fn unknown_keys_are_rejected() {
    let e = error_after(vec![], |imu| {
        imu.insert("colour".into(), Value::String("red".into()));
    });
    assert_names(&e, "imus[0].colour", &["unknown key", "seed"]);
    let e = error_after(vec![], |imu| {
        sub(imu, "gyro").insert("arw_deg_rt_h".into(), Value::Float(0.15));
    });
    assert_names(
        &e,
        "imus[0].gyro.arw_deg_rt_h",
        &["unknown key", "arw_rad_s_sqrt_hz"],
    );
    let e = error_after(vec![], |imu| {
        sub(imu, "accel").insert("arw_rad_s_sqrt_hz".into(), Value::Float(1e-5));
    });
    assert_names(
        &e,
        "imus[0].accel.arw_rad_s_sqrt_hz",
        &["unknown key", "vrw_m_s2_sqrt_hz"],
    );
    let e = error_after(vec![], |imu| {
        imu.insert("magnetometer".into(), Value::Table(Table::new()));
    });
    assert_names(&e, "imus[0].magnetometer", &["unknown key"]);
}

#[test]
fn missing_and_mistyped_keys() {
    let e = error_after(vec![], |imu| {
        imu.remove("seed");
    });
    assert_names(&e, "imus[0].seed", &["missing required key"]);
    let e = error_after(vec![], |imu| {
        imu.remove("dcm_pb");
    });
    assert_names(&e, "imus[0].dcm_pb", &["missing required key"]);
    let e = error_after(vec![], |imu| {
        imu.insert("seed".into(), Value::Integer(-3));
    });
    assert_names(&e, "imus[0].seed", &["invalid value"]);
    let e = error_after(vec![], |imu| {
        imu.insert("r_sb_b_m".into(), vec_value(&[1.0, 2.0]));
    });
    assert_names(&e, "imus[0].r_sb_b_m", &["invalid value"]);
    let e = error_after(vec![], |imu| {
        sub(imu, "gyro").insert("range_rad_s".into(), Value::String("fast".into()));
    });
    assert_names(&e, "imus[0].gyro.range_rad_s", &["invalid value"]);
}

#[test]
fn bad_dcm() {
    let e = error_after(vec![], |imu| {
        let m = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 1e-6, 0.0, 0.0, 1.0);
        imu.insert("dcm_pb".into(), mat_value(&m));
    });
    assert_names(&e, "imus[0].dcm_pb", &["orthonormal"]);
    // A reflection is orthogonal but not proper.
    let e = error_after(vec![], |imu| {
        imu.insert(
            "dcm_pb".into(),
            mat_value(&Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0))),
        );
    });
    assert_names(&e, "imus[0].dcm_pb", &["orthonormal"]);
}

#[test]
fn names_must_be_unique_and_topic_safe() {
    let second = imu_table("imu0", Vector3::zeros(), &Matrix3::identity(), 2);
    let e = error_after(vec![second], |_| {});
    assert_names(&e, "imus[1].name", &["duplicate IMU name `imu0`"]);
    for bad in ["imu/0", "", "imu 0", "imu*", "ünï"] {
        let e = error_after(vec![], |imu| {
            imu.insert("name".into(), Value::String(bad.into()));
        });
        assert_names(&e, "imus[0].name", &["imu name"]);
    }
    let e = error_after(vec![], |imu| {
        imu.insert("name".into(), Value::String("x".repeat(65)));
    });
    assert_names(&e, "imus[0].name", &["64"]);
}

#[test]
fn negative_terms_are_rejected() {
    let gyro_keys = [
        "arw_rad_s_sqrt_hz",
        "bias_instability_sigma_rad_s",
        "bias_instability_tau_s",
        "rrw_rad_s2_sqrt_hz",
        "range_rad_s",
        "lsb_rad_s",
        "dtheta_lsb_rad",
    ];
    let accel_keys = [
        "vrw_m_s2_sqrt_hz",
        "bias_instability_sigma_m_s2",
        "bias_instability_tau_s",
        "rrw_m_s3_sqrt_hz",
        "range_m_s2",
        "lsb_m_s2",
        "dv_lsb_m_s",
    ];
    for (table, keys) in [("gyro", &gyro_keys), ("accel", &accel_keys)] {
        for key in keys.iter() {
            let e = error_after(vec![], |imu| {
                sub(imu, table).insert((*key).into(), Value::Float(-1e-6));
            });
            assert_names(
                &e,
                &format!("imus[0].{table}.{key}"),
                &["must be >= 0", "(got -1e-6)"],
            );
        }
    }
}

#[test]
fn nan_and_inf_are_rejected() {
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = error_after(vec![], |imu| {
            sub(imu, "accel").insert("vrw_m_s2_sqrt_hz".into(), Value::Float(v));
        });
        assert_names(&e, "imus[0].accel.vrw_m_s2_sqrt_hz", &["must be finite"]);
        let e = error_after(vec![], |imu| {
            sub(imu, "gyro").insert("bias_rad_s".into(), vec_value(&[0.0, v, 0.0]));
        });
        assert_names(&e, "imus[0].gyro.bias_rad_s[1]", &["must be finite"]);
        let e = error_after(vec![], |imu| {
            imu.insert("r_sb_b_m".into(), vec_value(&[v, 0.0, 0.0]));
        });
        assert_names(&e, "imus[0].r_sb_b_m[0]", &["must be finite"]);
    }
}

#[test]
fn model_consistency_checks() {
    let e = error_after(vec![], |imu| {
        sub(imu, "accel").insert("bias_instability_sigma_m_s2".into(), Value::Float(1e-4));
    });
    assert_names(
        &e,
        "imus[0].accel.bias_instability_tau_s",
        &["must be > 0 when bias_instability_sigma_m_s2 > 0"],
    );
    let e = error_after(vec![], |imu| {
        let mut m = Matrix3::zeros();
        m[(1, 1)] = 1e-4;
        sub(imu, "gyro").insert("misalignment_rad".into(), mat_value(&m));
    });
    assert_names(
        &e,
        "imus[0].gyro.misalignment_rad[1][1]",
        &["diagonal must be 0"],
    );
    let e = error_after(vec![], |imu| {
        let mut m = Matrix3::zeros();
        m[(2, 0)] = -0.2;
        sub(imu, "accel").insert("misalignment_rad".into(), mat_value(&m));
    });
    assert_names(
        &e,
        "imus[0].accel.misalignment_rad[2][0]",
        &["small angles"],
    );
    let e = error_after(vec![], |imu| {
        sub(imu, "gyro").insert("scale_factor".into(), vec_value(&[0.0, 0.0, 150.0]));
    });
    assert_names(
        &e,
        "imus[0].gyro.scale_factor[2]",
        &["(-1, 1)", "1 ppm = 1e-6"],
    );
}

#[test]
fn errors_point_at_the_line() {
    let text = format!(
        "{}\n[[imus]]\nname = \"a\"\nr_sb_b_m = [0.0, 0.0, 0.0]\ndcm_pb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\nseed = 1\n[imus.gyro]\narw_rad_s_sqrt_hz = -1.0\n",
        flexdyn_vehicle::config::DEFAULT_CONFIG_TOML
    );
    let line = text
        .lines()
        .position(|l| l.starts_with("arw_rad_s_sqrt_hz"))
        .unwrap()
        + 1;
    let e = SimConfig::from_toml_str(&text).unwrap_err();
    assert_names(
        &e,
        "imus[0].gyro.arw_rad_s_sqrt_hz",
        &["must be >= 0", &format!("line {line}, column 21")],
    );
}

#[test]
fn absent_tables_and_keys_default_to_zero() {
    let mut t = reference_table();
    let mut imu = imu_table("a", Vector3::zeros(), &Matrix3::identity(), 0);
    sub(&mut imu, "gyro").insert("arw_rad_s_sqrt_hz".into(), Value::Float(1e-5));
    set_imus(&mut t, vec![imu]);
    let cfg = parse(&t);
    assert_eq!(
        cfg.sensors.all::<ImuConfig>()[0].gyro,
        GyroErrors {
            arw_rad_s_sqrt_hz: 1e-5,
            ..GyroErrors::default()
        }
    );
    assert_eq!(
        cfg.sensors.all::<ImuConfig>()[0].accel,
        AccelErrors::default()
    );
    assert_eq!(AccelErrors::default().misalignment_rad, Matrix3::zeros());
}

#[test]
fn shipped_imu_tactical_scenario() {
    let path = Path::new(crate::REPO).join("scenarios/imu_tactical.toml");
    let cfg = SimConfig::from_file(&path).unwrap();
    // The spacecraft is the reference one.
    let reference = SimConfig::reference();
    assert_eq!(cfg.hub, reference.hub);
    assert_eq!(cfg.panel_pairs, reference.panel_pairs);
    assert_eq!(cfg.initial, reference.initial);
    assert_eq!(cfg.sensors.all::<ImuConfig>().len(), 2);
    assert_eq!(cfg.sensors.all::<ImuConfig>()[0].name, "hub");
    assert_eq!(cfg.sensors.all::<ImuConfig>()[1].name, "bracket");
    let deg = std::f64::consts::PI / 180.0;
    for imu in cfg.sensors.of::<ImuConfig>() {
        // The conversions (docs/models/imu.md) of the tactical-grade datasheet values.
        assert!((imu.gyro.arw_rad_s_sqrt_hz / (0.15 * deg / 60.0) - 1.0).abs() < 1e-4);
        assert!(
            (imu.gyro.bias_instability_sigma_rad_s * 0.617_364 / (deg / 3600.0) - 1.0).abs() < 1e-4
        );
        assert!((imu.accel.vrw_m_s2_sqrt_hz / (0.05 / 60.0) - 1.0).abs() < 1e-4);
        assert!(
            (imu.accel.bias_instability_sigma_m_s2 * 0.617_364 / (50e-6 * 9.806_65) - 1.0).abs()
                < 1e-4
        );
        assert_ne!(imu.gyro.dtheta_lsb_rad, 0.0);
        assert_ne!(imu.accel.dv_lsb_m_s, 0.0);
    }
    let sim = Simulation::new(&cfg).unwrap();
    assert_eq!(sim.imu_points().len(), 2);
    assert_eq!(sim.imu_points()[1].r_sb_b_m, Vector3::new(0.0, 1.0, 0.5));
    assert_eq!(sim.imu_names(), ["hub", "bracket"]);
}
