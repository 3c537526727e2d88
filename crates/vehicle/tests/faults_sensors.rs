//! Sensor fault modes against the documented transforms (`crates/faults/src/modes.rs`): a run with one
//! `[[faults]]` entry and a healthy run of the same configuration (same seeds) are sampled at
//! every frame; outside the fault's window every published message is identical, inside it the
//! faulted fields equal the transform of the healthy ones, sample by sample, and every other
//! field is untouched. Sensor faults do not feed back into the dynamics, so the truth is the
//! same in both runs.
//!
//! The expected values are computed here from the module's table, not by the fault code; the
//! random draws come from the documented generator (`NormalRng` seeded with the fault's seed,
//! drawn per sample and axis in order).

use crate::sensor_faults_support::{
    acs_full_fss_at_the_sun, floats, gps_fix, gps_no_fix, split, without, Published, ACS_FULL,
};
use flexdyn_sensors::rng::NormalRng;
use serde_json::Value;

const LEO: &str = include_str!("../../../scenarios/leo_environment.toml");
/// Both scenarios run frames of 0.1 s (acs_full) or 0.01 s (leo, sensors at 10 Hz).
const START_S: f64 = 0.5;
const DURATION_S: f64 = 1.0;
const END_S: f64 = 2.0;

fn run(text: &str) -> Published {
    crate::sensor_faults_support::run(text, END_S)
}

fn with_fault(base: &str, fault: &str) -> String {
    format!("{base}\n[[faults]]\n{fault}\nstart_s = {START_S}\nduration_s = {DURATION_S}\n")
}

fn active(t_ns: u64) -> bool {
    let t = t_ns as f64 * 1e-9;
    (START_S..START_S + DURATION_S).contains(&(t + 1e-12))
}

/// Compares a faulted run with the healthy one for `sensor`: `expect(t_on_s, field, axis, x,
/// x_on)` gives the faulted value of `field`'s `axis` from the healthy `x` (`x_on`: the healthy
/// value at the window's first sample); `None` means unchanged. Returns the number of samples
/// inside the window (so a case cannot pass by never being sampled there).
fn compare(
    base: &str,
    fault: &str,
    sensor: &str,
    fields: &[&str],
    mut expect: impl FnMut(f64, &str, usize, f64, f64) -> Option<f64>,
) -> usize {
    let healthy = run(base);
    let faulted = run(&with_fault(base, fault));
    let first_on = healthy
        .iter()
        .find(|(t, row)| active(**t) && row.contains_key(sensor))
        .map(|(_, row)| row[sensor].clone())
        .expect("the sensor samples inside the window");
    let start_ns = (START_S * 1e9) as u64;
    let mut inside = 0;
    for (t, _, h, f) in split(&healthy, &faulted, sensor, |t| {
        active(t).then_some(start_ns)
    }) {
        // A sample the healthy run published is published faulted, and none is added.
        let (h, f) = match (h, f) {
            (Some(h), Some(f)) => (h, f),
            (None, None) => continue,
            (h, f) => panic!("{sensor} at t = {t} ns: published in one run only ({h:?} / {f:?})"),
        };
        inside += 1;
        // Whole nanoseconds since the activation, then seconds.
        let t_on_s = (t - start_ns) as f64 * 1e-9;
        for (key, hv) in h.as_object().unwrap() {
            let fv = &f[key];
            if !fields.contains(&key.as_str()) {
                assert_eq!(hv, fv, "{key} at t = {t} ns");
                continue;
            }
            let (hx, fx, on) = (floats(hv), floats(fv), floats(&first_on[key]));
            for a in 0..hx.len() {
                let want = expect(t_on_s, key, a, hx[a], on[a]).unwrap_or(hx[a]);
                assert_eq!(fx[a], want, "{key}[{a}] at t = {t} ns (healthy {})", hx[a]);
            }
        }
    }
    assert!(inside >= 10, "{inside} samples in the window");
    inside
}

#[test]
fn stuck_current_holds_the_first_sample_of_the_window_on_the_selected_axis() {
    let fault = "target = \"imus.hub.gyro\"\nmode = \"stuck_current\"\naxes = [2]";
    compare(
        ACS_FULL,
        fault,
        "imus.hub",
        &["omega_p_rad_s"],
        |_, _, a, _, on| (a == 1).then_some(on),
    );
}

#[test]
fn stuck_value_replaces_every_axis() {
    let fault = "target = \"imus.hub.accel\"\nmode = \"stuck_value\"\nvalue = 1.5";
    compare(
        ACS_FULL,
        fault,
        "imus.hub",
        &["accel_p_m_s2"],
        |_, _, _, _, _| Some(1.5),
    );
}

#[test]
fn bias_step_adds_the_value() {
    let fault = "target = \"imus.hub.gyro\"\nmode = \"bias_step\"\nvalue = 0.01\naxes = [1, 3]";
    compare(
        ACS_FULL,
        fault,
        "imus.hub",
        &["omega_p_rad_s"],
        |_, _, a, x, _| (a != 1).then_some(x + 0.01),
    );
}

#[test]
fn bias_ramp_grows_from_the_activation() {
    let fault = "target = \"imus.hub.dtheta\"\nmode = \"bias_ramp\"\nrate_per_s = 0.02";
    compare(
        ACS_FULL,
        fault,
        "imus.hub",
        &["dtheta_p_rad"],
        |t_on, _, _, x, _| Some(x + 0.02 * t_on),
    );
}

#[test]
fn scale_multiplies_a_whole_sensor_without_a_channel() {
    // No channel: every channel of the sensor (a CSS array has one, its detectors).
    let fault = "target = \"coarse_sun_sensors.css\"\nmode = \"scale\"\nfactor = 2.0";
    let mut lit = 0;
    compare(
        ACS_FULL,
        fault,
        "coarse_sun_sensors.css",
        &["readings"],
        |_, _, a, x, _| {
            lit += usize::from(x != 0.0);
            // The readings beyond the array's detectors stay 0 either way.
            let _ = a;
            Some(2.0 * x)
        },
    );
    assert!(lit > 0, "some detector sees the Sun");
}

#[test]
fn scale_on_a_magnetometer_field() {
    let fault = "target = \"magnetometers.mag1.field\"\nmode = \"scale\"\nfactor = -0.5";
    compare(
        LEO,
        fault,
        "magnetometers.mag1",
        &["b_s_t"],
        |_, _, _, x, _| Some(-0.5 * x),
    );
}

#[test]
fn noise_adds_the_documented_draws_in_channel_then_axis_order() {
    let fault = "target = \"fine_sun_sensors.fss\"\nmode = \"noise\"\nsigma = 0.001\nseed = 5";
    let mut rng = NormalRng::new(5);
    // Fields come in message order: alpha, then beta (the channel order).
    compare(
        ACS_FULL,
        fault,
        "fine_sun_sensors.fss",
        &["alpha_rad", "beta_rad"],
        |_, _, _, x, _| Some(x + 0.001 * rng.normal()),
    );
}

#[test]
fn spikes_add_the_amplitude_with_the_probability() {
    let fault = "target = \"imus.hub.gyro\"\nmode = \"spikes\"\nprobability = 0.3\namplitude = 0.1\nseed = 9";
    let mut rng = NormalRng::new(9);
    let mut spikes = 0;
    let n = compare(
        ACS_FULL,
        fault,
        "imus.hub",
        &["omega_p_rad_s"],
        |_, _, _, x, _| {
            let (u1, u2) = (rng.uniform01(), rng.uniform01());
            if u1 < 0.3 {
                spikes += 1;
                Some(if u2 < 0.5 { x + 0.1 } else { x - 0.1 })
            } else {
                Some(x)
            }
        },
    );
    assert!(
        spikes > 0 && spikes < 3 * n,
        "{spikes} spikes in {n} samples"
    );
}

#[test]
fn dropout_publishes_nothing_in_the_window() {
    let base = run(ACS_FULL);
    let faulted = run(&with_fault(
        ACS_FULL,
        "target = \"star_trackers.st1\"\nmode = \"dropout\"",
    ));
    let mut dropped = 0;
    for ((t, h), (_, f)) in base.iter().zip(&faulted) {
        if active(*t) {
            assert!(h.contains_key("star_trackers.st1"));
            assert!(!f.contains_key("star_trackers.st1"), "t = {t}");
            dropped += 1;
            // The other sensors are untouched.
            assert_eq!(without(h, "star_trackers.st1"), *f);
        } else {
            assert_eq!(h, f);
        }
    }
    assert!(dropped >= 10);
}

/// Runs a `validity_off` fault on `sensor` and checks, sample by sample, that inside the window
/// the faulted message is `invalidate(healthy)` and outside it is the healthy one. Returns how
/// many healthy samples in the window were valid (`is_valid`).
fn validity_off(
    base: &str,
    sensor: &str,
    invalidate: fn(&mut Value),
    is_valid: fn(&Value) -> bool,
) -> usize {
    let healthy = run(base);
    let faulted = run(&with_fault(
        base,
        &format!("target = \"{sensor}\"\nmode = \"validity_off\""),
    ));
    let mut valid_before = 0;
    for ((t, h), (_, f)) in healthy.iter().zip(&faulted) {
        match (h.get(sensor), f.get(sensor)) {
            (Some(h), Some(f)) if active(*t) => {
                valid_before += usize::from(is_valid(h));
                let mut want = h.clone();
                invalidate(&mut want);
                assert_eq!(f, &want, "t = {t}");
            }
            (h, f) => assert_eq!(h, f, "t = {t}"),
        }
    }
    valid_before
}

#[test]
fn validity_off_clears_only_the_flag() {
    // acs_full's tracker starts blinded by its rate limit; this one tracks.
    let n = validity_off(
        include_str!("../../../scenarios/wheels_star_tracker.toml"),
        "star_trackers.st1",
        |m| m["valid"] = Value::Bool(false),
        |m| m["valid"] == Value::Bool(true),
    );
    assert!(n > 0, "the healthy tracker is valid in the window");
    // acs_full's sun sensor looks 90° from the Sun; this one looks at it.
    let n = validity_off(
        &acs_full_fss_at_the_sun(),
        "fine_sun_sensors.fss",
        |m| m["flags"] = Value::from(m["flags"].as_u64().unwrap() & !1),
        |m| m["flags"].as_u64().unwrap() & 1 == 1,
    );
    assert!(n > 0, "the healthy sun sensor is valid in the window");
}

/// LEO with its GPS receiver at 10 Hz (every 10th frame; the 0.2 s latency stays 20 frames),
/// so the 1 s window holds 10 of its messages.
fn leo_gps_10_hz() -> String {
    let from = "rate_hz = 1.0\nseed = 51";
    assert!(LEO.contains(from));
    LEO.replacen(from, "rate_hz = 10.0\nseed = 51", 1)
}

#[test]
fn bias_step_on_a_gps_position_moves_only_that_frame() {
    let fault = "target = \"gps_receivers.gps1.position_e\"\nmode = \"bias_step\"\nvalue = 25.0";
    compare(
        &leo_gps_10_hz(),
        fault,
        "gps_receivers.gps1",
        &["r_be_e_m"],
        |_, _, _, x, _| Some(x + 25.0),
    );
}

#[test]
fn validity_off_makes_a_gps_message_a_no_fix_one() {
    let n = validity_off(&leo_gps_10_hz(), "gps_receivers.gps1", gps_no_fix, gps_fix);
    assert!(n >= 10, "{n} healthy GPS messages with a fix in the window");
}
