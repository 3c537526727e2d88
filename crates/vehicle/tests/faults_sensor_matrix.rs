//! Every sensor fault mode on every sensor kind and every fault channel it exposes, against the
//! documented transforms (`crates/faults/src/modes.rs`, the fault table of docs/guides/faults.md), sample by sample.
//!
//! One scenario carries every sensor kind: `scenarios/acs_full.toml` (IMU, star tracker,
//! magnetometer, coarse and fine sun sensors, all at the 10 Hz frame rate) with its fine sun
//! sensor turned to the Sun (so its angles are measured, not the zeros of a sensor that sees
//! nothing), its star tracker's rate limit raised above the initial 3°/s (so it is valid), and
//! a GPS receiver added (10 Hz, 0.2 s latency: each message carries the
//! measurement of two frames before). For each cell (kind × channel × mode) a run with one
//! `[[faults]]` entry is compared, at every frame, with the healthy run of the same seeds:
//! - outside the window every published message of every sensor is the healthy one, bit for bit;
//! - inside it every other sensor's message, every other field of the target's message, and the
//!   axes the entry does not select are the healthy ones, bit for bit; the selected axes equal
//!   the transform of the healthy value, re-derived here from the table in `modes.rs` (not by
//!   calling the production transform);
//! - `dropout`: the target publishes nothing inside the window, and every other message of the
//!   run is the healthy one. An IMU's Δθ and Δv are increments over the interval since its last
//!   *sample*, and a fault acts on the published sample only (`crates/faults/src/ports.rs`: after the
//!   bank samples), so the first message after a dropout carries its own interval, as in the
//!   healthy run, not the dropped ones' sum; a `stuck_current` Δθ holds the first increment of
//!   the window. A GPS fault acts on the message leaving the latency ring
//!   (`crates/sensors/src/gps/mod.rs`, "Faults"): the value published at t, measured at t − latency;
//! - `validity_off` (the kinds with a validity flag): the flag cleared as each kind documents
//!   (that table), nothing else changed.
//!
//! The window opens between two frames (at 0.55 s, for 1 s: samples at 0.6 … 1.5 s), so
//! `bias_ramp`'s t_on (time since the activation began) and `stuck_current`'s x_on (the healthy
//! value at the activation's first *sample*) are not confused with each other. Modes alternate
//! between every axis and the axes 1 and 3 (where the channel has three or more), so the axis
//! selection and the draw order (only selected axes draw) are checked on every kind.
//!
//! Sensor faults do not feed back into the dynamics, so the truth is the same in both runs.

use std::sync::OnceLock;

use crate::sensor_faults_support::{
    acs_full_fss_at_the_sun, floats, gps_fix, gps_no_fix, Inside, Published, ACS_FULL,
};
use flexdyn_sensors::rng::NormalRng;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use serde_json::Value;

/// \[ns\] the frame period of acs_full (10 Hz).
const FRAME_NS: u64 = 100_000_000;
/// The matrix's window: [0.55 s, 1.55 s), opening between two frames.
const ONCE: Window = Window {
    start_ns: 550_000_000,
    duration_ns: 1_000_000_000,
    period_ns: None,
};
/// \[s\] the run's length (20 frames).
const END_S: f64 = 2.0;

/// A fault's window, re-derived from `crates/faults/src/window.rs`: active on
/// [start + n·period, start + n·period + duration), n = 0, 1, … (n = 0 only without a period).
#[derive(Clone, Copy)]
struct Window {
    start_ns: u64,
    duration_ns: u64,
    period_ns: Option<u64>,
}

impl Window {
    /// The start \[ns\] of the activation in force at `t_ns`.
    fn activation(&self, t_ns: u64) -> Option<u64> {
        let since = t_ns.checked_sub(self.start_ns)?;
        let n = self.period_ns.map_or(0, |p| since / p);
        let start = self.start_ns + n * self.period_ns.unwrap_or(0);
        (t_ns - start < self.duration_ns).then_some(start)
    }

    /// Its lines of a `[[faults]]` entry.
    fn toml(&self) -> String {
        let s = |ns: u64| ns as f64 * 1e-9;
        let mut t = format!(
            "start_s = {}\nduration_s = {}\n",
            s(self.start_ns),
            s(self.duration_ns)
        );
        if let Some(p) = self.period_ns {
            t += &format!("period_s = {}\n", s(p));
        }
        t
    }
}

/// The fault channels of each kind (as `Sensor::fault_channels` states them, checked below)
/// and the message field each one is: `(section.name, [(channel, field)])`.
const CHANNELS: &[(&str, &[(&str, &str)])] = &[
    (
        "imus.hub",
        &[
            ("gyro", "omega_p_rad_s"),
            ("accel", "accel_p_m_s2"),
            ("dtheta", "dtheta_p_rad"),
            ("dv", "dv_p_m_s"),
        ],
    ),
    ("star_trackers.st1", &[("q", "q_cn")]),
    ("magnetometers.mag1", &[("field", "b_s_t")]),
    ("coarse_sun_sensors.css", &[("readings", "readings")]),
    (
        "fine_sun_sensors.fss",
        &[("alpha", "alpha_rad"), ("beta", "beta_rad")],
    ),
    (
        "gps_receivers.gps1",
        &[
            ("position_e", "r_be_e_m"),
            ("velocity_e", "v_be_e_m_s"),
            ("position_n", "r_bn_n_m"),
            ("velocity_n", "v_bn_n_m_s"),
        ],
    ),
];

/// The value modes with their parameters (as a `[[faults]]` entry writes them).
const VALUE_MODES: &[(&str, &str)] = &[
    ("stuck_current", ""),
    ("stuck_value", "value = 1.5"),
    ("bias_step", "value = 0.25"),
    ("bias_ramp", "rate_per_s = 0.5"),
    ("scale", "factor = -0.5"),
    ("noise", "sigma = 0.1\nseed = 5"),
    ("spikes", "probability = 0.5\namplitude = 2.0\nseed = 9"),
];

/// The scenario: acs_full with its sun sensor looking at the Sun and a GPS receiver.
fn scenario() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| {
        // The tracker's rate limit (2°/s) would blind it at the initial 3°/s: 6°/s.
        let rate = "max_rate_rad_s = 0.0349";
        assert!(ACS_FULL.contains(rate));
        format!(
            "{}\n[[gps_receivers]]\nname = \"gps1\"\nrate_hz = 10.0\nseed = 51\n\
             frames = \"both\"\nlatency_s = 0.2\nacquisition_s = 0.0\nposition_sigma_m = 3.0\n\
             velocity_sigma_m_s = 0.05\nposition_bias_e_m = [0.5, -0.3, 0.8]\n",
            acs_full_fss_at_the_sun().replacen(rate, "max_rate_rad_s = 0.1047", 1)
        )
    })
}

fn run(text: &str) -> Published {
    crate::sensor_faults_support::run(text, END_S)
}

fn healthy() -> &'static Published {
    static RUN: OnceLock<Published> = OnceLock::new();
    RUN.get_or_init(|| run(scenario()))
}

fn faulted(entry: &str, window: Window) -> Published {
    run(&format!(
        "{}\n[[faults]]\n{entry}\n{}",
        scenario(),
        window.toml()
    ))
}

/// The part of a healthy message a value fault acts on: the channel's axes (a CSS array's
/// readings beyond its detectors are none; a GPS message without a fix has none).
fn axis_count(sensor: &str, msg: &Value, field: &str) -> usize {
    match sensor {
        "coarse_sun_sensors.css" => msg["detector_count"].as_u64().unwrap() as usize,
        "gps_receivers.gps1" if !gps_fix(msg) => 0,
        _ => floats(&msg[field]).len(),
    }
}

/// [`sensor_faults_support::split`] in `window`.
fn split<'a>(
    healthy: &'a Published,
    faulted: &'a Published,
    sensor: &str,
    window: Window,
) -> Vec<Inside<'a>> {
    crate::sensor_faults_support::split(healthy, faulted, sensor, |t| window.activation(t))
}

/// A value-mode fault: `mode` (with `params`) on `sensor`'s `channel` (message field `field`),
/// with `axes` (1-based) selected or every axis.
struct Cell<'a> {
    sensor: &'a str,
    channel: &'a str,
    field: &'a str,
    mode: &'a str,
    params: &'a str,
    axes: &'a [u32],
}

impl<'a> Cell<'a> {
    /// `mode` (with `params`) on `sensor`'s `(channel, field)`, `axes` selected.
    fn new(
        sensor: &'a str,
        (channel, field): (&'a str, &'a str),
        mode: (&'a str, &'a str),
    ) -> Self {
        Self {
            sensor,
            channel,
            field,
            mode: mode.0,
            params: mode.1,
            axes: &[],
        }
    }
}

/// Runs `c` in `window` against the healthy run; returns the healthy values held by
/// `stuck_current` (x_on), one per activation.
fn value_cell(c: &Cell, window: Window) -> Vec<Vec<f64>> {
    let (sensor, channel, field, mode, params, axes) =
        (c.sensor, c.channel, c.field, c.mode, c.params, c.axes);
    let cell = format!("{mode} on {sensor}.{channel} axes {axes:?}");
    let mut entry = format!("target = \"{sensor}.{channel}\"\nmode = \"{mode}\"\n{params}");
    if !axes.is_empty() {
        entry += &format!("\naxes = {axes:?}");
    }
    let f = faulted(&entry, window);
    let inside = split(healthy(), &f, sensor, window);
    let param = |key: &str| -> f64 {
        params
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key} = ")))
            .unwrap()
            .parse()
            .unwrap()
    };
    let seed = params
        .lines()
        .find_map(|l| l.strip_prefix("seed = "))
        .map_or(0, |s| s.parse().unwrap());
    let mut rng = NormalRng::new(seed);
    let selected = |a: usize| axes.is_empty() || axes.contains(&(a as u32 + 1));
    // x_on per activation: (its start, the healthy values at its first sample).
    let mut x_on: Vec<(u64, Vec<f64>)> = Vec::new();
    let (mut samples, mut changed, mut nonzero) = (0, 0, 0);
    for (t, on_ns, h, fv) in inside {
        let (Some(h), Some(fv)) = (h, fv) else {
            panic!("{cell}: t = {t} ns published in one run only ({h:?} / {fv:?})");
        };
        // Every other field untouched.
        for (key, hv) in h.as_object().unwrap() {
            if key != field {
                assert_eq!(hv, &fv[key], "{cell}: {key} at t = {t} ns");
            }
        }
        let (hx, fx) = (floats(&h[field]), floats(&fv[field]));
        assert_eq!(hx.len(), fx.len());
        let n = axis_count(sensor, h, field);
        // x_on: the activation's first sample; t_on: whole ns since it began, then seconds.
        if x_on.last().is_none_or(|(s, _)| *s != on_ns) {
            x_on.push((on_ns, hx.clone()));
        }
        let on = &x_on.last().unwrap().1;
        let t_on_s = (t - on_ns) as f64 * 1e-9;
        samples += 1;
        for a in 0..hx.len() {
            let x = hx[a];
            let want = if a >= n || !selected(a) {
                x
            } else {
                nonzero += usize::from(x != 0.0);
                match mode {
                    "stuck_current" => on[a],
                    "stuck_value" => param("value"),
                    "bias_step" => x + param("value"),
                    "bias_ramp" => x + param("rate_per_s") * t_on_s,
                    "scale" => param("factor") * x,
                    "noise" => x + param("sigma") * rng.normal(),
                    "spikes" => {
                        let (u1, u2) = (rng.uniform01(), rng.uniform01());
                        if u1 < param("probability") {
                            let amplitude = param("amplitude");
                            x + if u2 < 0.5 { amplitude } else { -amplitude }
                        } else {
                            x
                        }
                    }
                    _ => unreachable!("{mode}"),
                }
            };
            assert_eq!(
                fx[a].to_bits(),
                want.to_bits(),
                "{cell}: {field}[{a}] at t = {t} ns (healthy {x}, published {}, expected {want})",
                fx[a]
            );
            changed += usize::from(fx[a] != x);
        }
    }
    // The window's every frame is a sample, the healthy values are measured (not all 0), and
    // the fault did something: no cell passes by never being exercised.
    let frames = (0..=(END_S * 1e9) as u64 / FRAME_NS)
        .filter(|k| window.activation(k * FRAME_NS).is_some())
        .count();
    assert_eq!(samples, frames, "{cell}: samples in the window");
    assert!(
        nonzero > 0,
        "{cell}: every healthy value in the window is 0"
    );
    assert!(changed > 0, "{cell}: the fault changed nothing");
    x_on.into_iter().map(|(_, v)| v).collect()
}

fn dropout_cell(sensor: &str) {
    let f = faulted(&format!("target = \"{sensor}\"\nmode = \"dropout\""), ONCE);
    let inside = split(healthy(), &f, sensor, ONCE);
    assert_eq!(inside.len(), 10);
    for (t, _, h, fv) in inside {
        assert!(
            h.is_some(),
            "{sensor}: the healthy run publishes at t = {t} ns"
        );
        assert!(fv.is_none(), "dropout on {sensor}: published at t = {t} ns");
    }
}

/// `validity_off` on `sensor`: each message in the window is `invalidate(healthy)`, and some
/// healthy one there was valid (`is_valid`).
fn validity_cell(sensor: &str, invalidate: fn(&mut Value), is_valid: fn(&Value) -> bool) {
    let f = faulted(
        &format!("target = \"{sensor}\"\nmode = \"validity_off\""),
        ONCE,
    );
    let inside = split(healthy(), &f, sensor, ONCE);
    assert_eq!(inside.len(), 10);
    let mut valid = 0;
    for (t, _, h, fv) in inside {
        let (Some(h), Some(fv)) = (h, fv) else {
            panic!("validity_off on {sensor}: t = {t} ns published in one run only");
        };
        valid += usize::from(is_valid(h));
        let mut want = h.clone();
        invalidate(&mut want);
        assert_eq!(fv, &want, "validity_off on {sensor} at t = {t} ns");
        assert!(!is_valid(fv));
    }
    assert!(
        valid > 0,
        "{sensor}: no healthy sample in the window is valid"
    );
}

/// Every value mode on every channel of `sensor`.
fn every_value_mode(sensor: &str) {
    let (_, channels) = CHANNELS.iter().find(|(s, _)| *s == sensor).unwrap();
    let h = healthy();
    let first = h.values().find_map(|row| row.get(sensor)).unwrap();
    for (channel, field) in *channels {
        let n = floats(&first[*field]).len();
        for (i, (mode, params)) in VALUE_MODES.iter().enumerate() {
            let axes: &[u32] = if i % 2 == 1 && n >= 3 { &[1, 3] } else { &[] };
            let cell = Cell {
                axes,
                ..Cell::new(sensor, (channel, field), (mode, params))
            };
            value_cell(&cell, ONCE);
        }
    }
}

/// The table above is what the kinds state: every sensor kind is in the scenario, with its
/// fault channels in order, and the validity flag where the tests below clear one.
#[test]
fn the_scenario_has_every_kind_and_the_table_every_channel() {
    let sim = Simulation::new(&SimConfig::from_toml_str(scenario()).unwrap()).unwrap();
    let bank = sim.sensors();
    let mut kinds = Vec::new();
    for s in bank.sensors() {
        let key = format!("{}.{}", s.kind().config_array, s.name());
        let (_, channels) = CHANNELS
            .iter()
            .find(|(k, _)| *k == key)
            .unwrap_or_else(|| panic!("{key} is not in the table"));
        let names: Vec<&str> = channels.iter().map(|(c, _)| *c).collect();
        assert_eq!(s.fault_channels(), names, "{key}");
        assert_eq!(
            s.has_validity(),
            ["star_trackers", "fine_sun_sensors", "gps_receivers"].contains(&s.kind().config_array),
            "{key}"
        );
        kinds.push(s.kind().config_array);
    }
    let all: Vec<&str> = flexdyn_sensors::KINDS
        .iter()
        .map(|k| k.config_array)
        .collect();
    kinds.sort_unstable();
    let mut want = all.clone();
    want.sort_unstable();
    assert_eq!(kinds, want, "one sensor of every kind");
    // Every one publishes at every frame of the window (the GPS from its third frame on).
    for (t, row) in healthy() {
        if ONCE.activation(*t).is_some() {
            assert_eq!(row.len(), CHANNELS.len(), "t = {t} ns");
        }
    }
}

#[test]
fn imu_every_value_mode_on_gyro_accel_dtheta_dv() {
    every_value_mode("imus.hub");
}

#[test]
fn star_tracker_every_value_mode_on_q() {
    every_value_mode("star_trackers.st1");
}

#[test]
fn magnetometer_every_value_mode_on_field() {
    every_value_mode("magnetometers.mag1");
}

#[test]
fn coarse_sun_sensor_every_value_mode_on_readings() {
    every_value_mode("coarse_sun_sensors.css");
}

#[test]
fn fine_sun_sensor_every_value_mode_on_alpha_and_beta() {
    every_value_mode("fine_sun_sensors.fss");
}

#[test]
fn gps_every_value_mode_on_every_frame() {
    every_value_mode("gps_receivers.gps1");
}

#[test]
fn dropout_on_every_kind_publishes_nothing_in_the_window_and_leaves_the_rest() {
    for (sensor, _) in CHANNELS {
        dropout_cell(sensor);
    }
}

#[test]
fn validity_off_on_every_kind_with_a_flag() {
    validity_cell(
        "star_trackers.st1",
        |m| m["valid"] = Value::Bool(false),
        |m| m["valid"] == Value::Bool(true),
    );
    validity_cell(
        "fine_sun_sensors.fss",
        |m| m["flags"] = Value::from(m["flags"].as_u64().unwrap() & !1),
        |m| m["flags"].as_u64().unwrap() & 1 == 1,
    );
    validity_cell("gps_receivers.gps1", gps_no_fix, gps_fix);
}

/// A repeating fault re-arms at each activation (`crates/faults/src/modes.rs`: x_on is the healthy
/// value at the first sample of the *current* activation, t_on the time since it began):
/// `stuck_current` holds a new value each time, `bias_ramp` starts again from 0. Activations
/// on [0.25, 0.55), [0.85, 1.15), [1.45, 1.75) s: samples at ticks 3–5, 9–11, 15–17.
#[test]
fn a_repeating_fault_re_arms_at_each_activation() {
    let repeating = Window {
        start_ns: 250_000_000,
        duration_ns: 300_000_000,
        period_ns: Some(600_000_000),
    };
    let starts: Vec<u64> = (0..=20)
        .filter_map(|k| repeating.activation(k * FRAME_NS))
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    assert_eq!(starts, [250_000_000, 850_000_000, 1_450_000_000]);
    for (sensor, channel, field) in [
        ("imus.hub", "gyro", "omega_p_rad_s"),
        ("imus.hub", "dtheta", "dtheta_p_rad"),
        ("gps_receivers.gps1", "position_n", "r_bn_n_m"),
        ("magnetometers.mag1", "field", "b_s_t"),
    ] {
        for (mode, params) in [("stuck_current", ""), ("bias_ramp", "rate_per_s = 0.5")] {
            let cell = Cell::new(sensor, (channel, field), (mode, params));
            let held = value_cell(&cell, repeating);
            // Three activations, each holding its own first sample: distinct values, so a
            // fault that kept the first one would have failed above.
            assert_eq!(held.len(), 3, "{sensor}.{channel}");
            assert!(
                held[0] != held[1] && held[1] != held[2],
                "{sensor}.{channel}: {held:?}"
            );
        }
    }
}

/// `stuck_current` on a GPS channel whose activation begins while the receiver has no fix: the
/// first samples of the activation carry no position (`fault_channel` is empty without a fix),
/// so the value to hold is the first one the activation sees, and a message with a fix must
/// never publish a position the receiver did not measure. The GPS acquires at 0.95 s (with the
/// 0.2 s latency: messages with a fix from 1.2 s), inside the window [0.55, 1.55).
#[test]
fn stuck_current_on_gps_holds_the_first_position_of_the_activation() {
    let from = "acquisition_s = 0.0";
    assert!(scenario().contains(from));
    let base = scenario().replacen(from, "acquisition_s = 0.95", 1);
    let entry = "target = \"gps_receivers.gps1.position_e\"\nmode = \"stuck_current\"\n";
    let healthy = run(&base);
    let faulted = run(&format!("{base}\n[[faults]]\n{entry}{}", ONCE.toml()));
    let mut held = None;
    let mut fixed = 0;
    for (t, _, h, f) in split(&healthy, &faulted, "gps_receivers.gps1", ONCE) {
        let (h, f) = (h.unwrap(), f.unwrap());
        if !gps_fix(h) {
            assert_eq!(h, f, "no fix at t = {t} ns: nothing to transform");
            continue;
        }
        fixed += 1;
        let on = held.get_or_insert_with(|| floats(&h["r_be_e_m"]));
        assert_eq!(floats(&f["r_be_e_m"]), *on, "t = {t} ns");
    }
    assert!(
        (1..10).contains(&fixed),
        "{fixed} samples with a fix in the window"
    );
}
