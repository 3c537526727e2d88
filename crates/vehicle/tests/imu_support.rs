//! Shared fixtures for the `imu_*` tests: configurations built by editing the reference TOML as
//! a `toml::Table`, and IMU tables.

use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_vehicle::config::{SimConfig, DEFAULT_CONFIG_TOML};
use nalgebra::{Matrix3, Vector3};
use toml::{Table, Value};

pub fn reference_table() -> Table {
    DEFAULT_CONFIG_TOML
        .parse::<Table>()
        .expect("reference is valid TOML")
}

pub fn vec_value(v: &[f64]) -> Value {
    Value::Array(v.iter().map(|x| Value::Float(*x)).collect())
}

pub fn mat_value(m: &Matrix3<f64>) -> Value {
    Value::Array(
        (0..3)
            .map(|i| vec_value(&[m[(i, 0)], m[(i, 1)], m[(i, 2)]]))
            .collect(),
    )
}

pub fn table_mut<'a>(t: &'a mut Table, key: &str) -> &'a mut Table {
    t.get_mut(key)
        .and_then(Value::as_table_mut)
        .unwrap_or_else(|| panic!("no table {key}"))
}

/// A generic (non-axis-aligned) platform orientation [PB].
pub fn tilted_dcm_pb() -> Matrix3<f64> {
    mrp_to_dcm(&Vector3::new(0.1, -0.25, 0.35))
}

/// An `[[imus]]` entry with every error term zero.
pub fn imu_table(name: &str, r_sb_b_m: Vector3<f64>, dcm_pb: &Matrix3<f64>, seed: i64) -> Table {
    let mut t = Table::new();
    t.insert("name".into(), Value::String(name.into()));
    t.insert("r_sb_b_m".into(), vec_value(r_sb_b_m.as_slice()));
    t.insert("dcm_pb".into(), mat_value(dcm_pb));
    t.insert("seed".into(), Value::Integer(seed));
    t
}

pub fn set_imus(t: &mut Table, imus: Vec<Table>) {
    t.insert(
        "imus".into(),
        Value::Array(imus.into_iter().map(Value::Table).collect()),
    );
}

pub fn parse(t: &Table) -> SimConfig {
    let text = toml::to_string(t).expect("serialises");
    SimConfig::from_toml_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

pub fn set_gravity_none(t: &mut Table) {
    let mut g = Table::new();
    g.insert("model".into(), Value::String("none".into()));
    t.insert("gravity".into(), Value::Table(g));
}

pub fn set_omega(t: &mut Table, w: [f64; 3]) {
    table_mut(t, "initial").insert("omega_bn_b_rad_s".into(), vec_value(&w));
}

pub fn set_no_panels(t: &mut Table) {
    t.insert("panel_pairs".into(), Value::Array(vec![]));
}

pub fn set_hub(t: &mut Table, mass_kg: f64, inertia: &Matrix3<f64>, r_bcb_b_m: [f64; 3]) {
    let hub = table_mut(t, "hub");
    hub.insert("mass_kg".into(), Value::Float(mass_kg));
    hub.insert("inertia_bc_b_kg_m2".into(), mat_value(inertia));
    hub.insert("r_bcb_b_m".into(), vec_value(&r_bcb_b_m));
}

/// Sets every panel's initial θ and θ̇ to zero.
pub fn panels_at_rest(t: &mut Table) {
    for p in t
        .get_mut("panel_pairs")
        .and_then(Value::as_array_mut)
        .expect("panel_pairs")
    {
        let p = p.as_table_mut().expect("pair");
        for which in ["panel1", "panel2"] {
            let panel = table_mut(p, which);
            panel.insert("theta_rad".into(), Value::Float(0.0));
            panel.insert("theta_dot_rad_s".into(), Value::Float(0.0));
        }
    }
}
