//! Shared by the sensor-fault tests (`faults_sensors`, `faults_sensor_matrix`): a run's every
//! published sensor message, decoded, per sample instant; the scenario edits that make every
//! sensor of `scenarios/acs_full.toml` measure; the documented no-fix GPS message.

use std::collections::BTreeMap;

use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_proto::Header;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::Vector3;
use serde_json::Value;

pub const ACS_FULL: &str = include_str!("../../../scenarios/acs_full.toml");

/// Every published sensor message of a run, per sample instant: `[t_ns] → {sensor → JSON}`
/// (`sensor` as `section.name`).
pub type Published = BTreeMap<u64, BTreeMap<String, Value>>;

/// Runs the configuration `text` for `end_s` and samples each sensor at the frames it is due,
/// through the fault port, as the server does.
pub fn run(text: &str, end_s: f64) -> Published {
    let cfg = SimConfig::from_toml_str(text).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&cfg).unwrap();
    let frames = (end_s * 1e9) as u64 / cfg.frame_ns;
    let mut out = Published::new();
    let mut buf = Vec::new();
    for k in 0..=frames {
        if k > 0 {
            sim.step_frame();
        }
        sim.sample_sensors(|s| s.due(k));
        let t = sim.t_sim_ns();
        let bank = sim.sensors();
        let row = out.entry(t).or_default();
        for &i in bank.sampled() {
            let s = &bank.sensors()[i];
            s.encode(Header::new(1, k, t, k), &mut buf);
            let (_, json) = (s.kind().decode)(&buf).unwrap();
            row.insert(format!("{}.{}", s.kind().config_array, s.name()), json);
        }
    }
    out
}

/// A message field's numbers (one for a scalar).
pub fn floats(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().map(|x| x.as_f64().unwrap()).collect(),
        x => vec![x.as_f64().unwrap()],
    }
}

/// `row` without `sensor`'s message.
pub fn without(row: &BTreeMap<String, Value>, sensor: &str) -> BTreeMap<String, Value> {
    let mut row = row.clone();
    row.remove(sensor);
    row
}

/// acs_full with its fine sun sensor looking at the Sun. acs_full's looks 90° from it; this one
/// looks at the Sun's direction in B at t = 0 (ŝ_B = [BN] r̂_sun; the body turns 3°/s, well
/// inside the ±60° field of view over a few seconds): [FB] rows x_F, y_F ⊥ ŝ_B, z_F = ŝ_B.
pub fn acs_full_fss_at_the_sun() -> String {
    let sim = Simulation::new(&SimConfig::from_toml_str(ACS_FULL).unwrap()).unwrap();
    let r = sim.spacecraft().environment().r_sun_b_n_m;
    let s0 = mrp_to_dcm(&sim.spacecraft().state().sigma_bn) * (r / r.norm());
    let x = s0.cross(&Vector3::new(0.3, 0.5, 0.8)).normalize();
    let y = s0.cross(&x);
    let row = |v: Vector3<f64>| format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2]);
    let fss =
        "name = \"fss\"\n# [FB] = I: boresight +z_F along +z_B, the wings' solar-cell normal.\n\
               dcm_fb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]";
    assert!(ACS_FULL.contains(fss));
    ACS_FULL.replacen(
        fss,
        &format!(
            "name = \"fss\"\ndcm_fb = [{}, {}, {}]",
            row(x),
            row(y),
            row(s0)
        ),
        1,
    )
}

/// A GPS message made a no-fix one, as `validity_off` documents (`crates/sensors/src/gps/mod.rs`,
/// "Faults"): FIX (bit 0) cleared and every number 0; the valid time and the frame flags stay.
pub fn gps_no_fix(m: &mut Value) {
    m["flags"] = Value::from(m["flags"].as_u64().unwrap() & !1);
    m["gps_week"] = Value::from(0);
    m["gps_seconds_of_week"] = Value::from(0.0);
    for key in ["r_be_e_m", "v_be_e_m_s", "r_bn_n_m", "v_bn_n_m_s"] {
        m[key] = serde_json::json!([0.0, 0.0, 0.0]);
    }
}

/// Whether a GPS message has a fix.
pub fn gps_fix(m: &Value) -> bool {
    m["flags"].as_u64().unwrap() & 1 == 1
}

/// A sample instant inside a fault's window: \[ns\] its time, \[ns\] the start of the
/// activation in force, the target's healthy and faulted messages (`None`: not published).
pub type Inside<'a> = (u64, u64, Option<&'a Value>, Option<&'a Value>);

/// Compares a faulted run with the healthy one everywhere but the target inside the window:
/// both runs sample the same instants; where `activation(t_ns)` (the start of the activation
/// in force, `None` outside the window) is `None` every message is the healthy one; inside,
/// every sensor but `sensor` is. Returns the instants inside, for the caller's check of the
/// target (a sample published in one run only is the caller's to fail or allow).
pub fn split<'a>(
    healthy: &'a Published,
    faulted: &'a Published,
    sensor: &str,
    activation: impl Fn(u64) -> Option<u64>,
) -> Vec<Inside<'a>> {
    assert_eq!(
        healthy.keys().collect::<Vec<_>>(),
        faulted.keys().collect::<Vec<_>>()
    );
    let mut inside = Vec::new();
    for ((t, h), f) in healthy.iter().zip(faulted.values()) {
        let Some(on_ns) = activation(*t) else {
            assert_eq!(h, f, "{sensor}: outside the window at t = {t} ns");
            continue;
        };
        assert_eq!(
            without(h, sensor),
            without(f, sensor),
            "{sensor}: other sensors at t = {t} ns"
        );
        inside.push((*t, on_ns, h.get(sensor), f.get(sensor)));
    }
    inside
}
