use nalgebra::{Matrix3, Vector3};

use super::*;

const FRAME_NS: u64 = 100_000_000; // 10 Hz
const STEP_NS: u64 = 1_000_000; // 1 ms

fn params(tau_rise_s: f64, tau_fall_s: f64, min_on_s: f64) -> ThrusterParams {
    ThrusterParams {
        name: "thr".into(),
        r_tb_b_m: Vector3::new(1.0, 0.0, 1.0),
        force_axis_b: Vector3::y(),
        max_thrust_newton: 2.0,
        isp_s: 220.0,
        min_on_time_s: min_on_s,
        rise_time_constant_s: tau_rise_s,
        tail_off_time_constant_s: tau_fall_s,
        command: ThrusterCommand::OnTime,
        tank: None,
    }
}

fn stage() -> StageState {
    StageState {
        t_step_ns: 0,
        dt_stage_s: 0.0,
        r_bn_n_m: Vector3::zeros(),
        v_bn_n_m_s: Vector3::zeros(),
        sigma_bn: Vector3::zeros(),
        dcm_bn: Matrix3::identity(),
        omega_bn_b_rad_s: Vector3::zeros(),
        mass_kg: 100.0,
        r_cb_b_m: Vector3::zeros(),
        r_cn_n_m: Vector3::zeros(),
        inertia_pnt_b_b_kg_m2: Matrix3::identity(),
    }
}

/// Runs `frames` frames of steps, calling `command(frame)` at each frame start; returns the
/// force applied over each step (the step's average) and the thruster at the end.
fn run(mut t: Thruster, frames: u64, command: impl Fn(u64) -> Option<f64>) -> (Vec<f64>, Thruster) {
    let mut forces = Vec::new();
    let steps = FRAME_NS / STEP_NS;
    for f in 0..frames {
        if let Some(u) = command(f) {
            t.set_inputs(&[u]);
        }
        for s in 0..steps {
            t.begin_step((f * steps + s) * STEP_NS);
            let mut w = Wrench::ZERO;
            t.add_force_torque(&stage(), &EnvironmentSample::NONE, &mut w);
            forces.push(w.force_b_newton.y);
        }
    }
    // Close the last step.
    t.begin_step(frames * steps * STEP_NS);
    (forces, t)
}

/// The lag's closed form against a fine numerical integration of dκ/dt = (u − κ)/τ (RK4 with
/// 10⁵ steps), for a rise from 0.3 and a tail-off from 0.9.
#[test]
fn lag_segment_matches_a_numerical_integration() {
    for (kappa0, u, d, tau) in [(0.3, 1.0, 0.04, 0.015), (0.9, 0.0, 0.07, 0.025)] {
        let n = 100_000;
        let h = d / n as f64;
        let f = |k: f64| (u - k) / tau;
        let (mut k, mut integral) = (kappa0, 0.0);
        for _ in 0..n {
            // RK4 on (κ, ∫κ).
            let k1 = f(k);
            let k2 = f(k + 0.5 * h * k1);
            let k3 = f(k + 0.5 * h * k2);
            let k4 = f(k + h * k3);
            let i1 = k;
            let i2 = k + 0.5 * h * k1;
            let i3 = k + 0.5 * h * k2;
            let i4 = k + h * k3;
            integral += h / 6.0 * (i1 + 2.0 * i2 + 2.0 * i3 + i4);
            k += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        let (k_end, i) = lag_segment(kappa0, u, d, tau);
        assert!((k_end - k).abs() < 1e-13, "{k_end} vs {k}");
        assert!((i - integral).abs() < 1e-13, "{i} vs {integral}");
    }
    // τ = 0: the valve state at once.
    assert_eq!(lag_segment(0.4, 1.0, 0.01, 0.0), (1.0, 0.01));
    // Nothing happens in no time.
    assert_eq!(lag_segment(0.4, 1.0, 0.0, 0.02), (0.4, 0.0));
    // At rest (κ₀ = u), the shortcut gives the general expressions' bits.
    for (u, d, tau) in [
        (0.0f64, 0.01f64, 0.025f64),
        (1.0, 0.001, 0.015),
        (1.0, 0.0437, 0.02),
    ] {
        let one_minus_e = -(-d / tau).exp_m1();
        let general = (
            u + (u - u) * (1.0 - one_minus_e),
            u * d + (u - u) * tau * one_minus_e,
        );
        let (k, i) = lag_segment(u, u, d, tau);
        assert_eq!(
            (k.to_bits(), i.to_bits()),
            (general.0.to_bits(), general.1.to_bits())
        );
    }
}

/// One pulse of on-time t_on, then tail-off: the impulse is F [t_on − (τ_r − τ_f)(1 − e^(−t_on/τ_r))]
/// (rise: ∫ = t_on − τ_r κ₁ with κ₁ = 1 − e^(−t_on/τ_r); tail-off: ∫ = τ_f κ₁), and with equal
/// time constants exactly F t_on. The steps' forces integrate to the same impulse.
#[test]
fn one_pulse_delivers_the_closed_form_impulse() {
    let t_on = 0.0437;
    for (tr, tf) in [(0.015, 0.025), (0.02, 0.02), (0.0, 0.0)] {
        let th = Thruster::new(params(tr, tf, 0.0), "thrusters[0]", FRAME_NS, STEP_NS).unwrap();
        // Fire in frame 0, nothing afterwards; 2 s leaves e^(−1.95/0.025) of the tail.
        let (forces, th) = run(th, 20, |f| match f {
            0 => Some(t_on),
            1 => Some(0.0),
            _ => None,
        });
        let k1 = if tr > 0.0 {
            1.0 - (-t_on / tr).exp()
        } else {
            1.0
        };
        let expected = 2.0 * (t_on - (tr - tf) * k1);
        let from_steps: f64 = forces.iter().sum::<f64>() * STEP_NS as f64 * 1e-9;
        let mut out = [0.0; 4];
        th.outputs(&mut out);
        assert!(
            (out[3] - expected).abs() < 1e-12,
            "τ {tr}/{tf}: {} vs {expected}",
            out[3]
        );
        assert!(
            (from_steps - expected).abs() < 1e-12,
            "{from_steps} vs {expected}"
        );
        assert_eq!(out[1], 1.0, "one pulse");
        let propellant = expected / (220.0 * G0_M_S2);
        assert!(
            (out[2] - propellant).abs() < 1e-15,
            "{} vs {propellant}",
            out[2]
        );
    }
}

/// PWM: a duty cycle held for many frames gives the commanded mean force, except below the
/// minimum on-time, where the valve stays shut: the error is then at most F t_min / T (the
/// minimum-impulse-bit bound). Equal time constants make the lag's mean equal the valve's mean.
#[test]
fn pwm_mean_force_is_the_duty_times_the_thrust_within_the_minimum_impulse_bit() {
    let t_min = 0.02;
    let frame_s = FRAME_NS as f64 * 1e-9;
    for duty in [0.0, 0.05, 0.15, 0.2, 0.33, 0.5, 0.9, 1.0] {
        let mut p = params(0.02, 0.02, t_min);
        p.command = ThrusterCommand::DutyCycle;
        let th = Thruster::new(p, "thrusters[0]", FRAME_NS, STEP_NS).unwrap();
        let frames = 50;
        let (forces, th) = run(th, frames, |f| (f == 0).then_some(duty));
        // Mean over the last 40 frames (periodic steady state: e^(−1/0.02) ≈ 2e-22 after 1 s).
        let tail = &forces[10 * 100..];
        let mean = tail.iter().sum::<f64>() / tail.len() as f64;
        let commanded = duty * 2.0;
        let bound = 2.0 * t_min / frame_s;
        assert!(
            (mean - commanded).abs() <= bound,
            "duty {duty}: {mean} vs {commanded}"
        );
        let mut out = [0.0; 4];
        let flags = th.outputs(&mut out);
        if duty * frame_s < t_min && duty > 0.0 {
            assert_eq!(mean, 0.0, "below the minimum on-time nothing fires");
            assert_ne!(flags & BELOW_MIN_ON_TIME, 0);
            assert_eq!(out[1], 0.0);
        } else {
            // Above it the mean is exact (to the ns rounding of the on-time).
            assert!(
                (mean - commanded).abs() < 1e-9,
                "duty {duty}: {mean} vs {commanded}"
            );
            let pulses = if duty == 0.0 {
                0.0
            } else if duty == 1.0 {
                1.0 // held open: one opening
            } else {
                frames as f64
            };
            assert_eq!(out[1], pulses, "duty {duty}");
        }
    }
}

#[test]
fn torque_is_r_cross_f_and_the_force_is_along_the_axis() {
    let mut th = Thruster::new(params(0.0, 0.0, 0.0), "thrusters[0]", FRAME_NS, STEP_NS).unwrap();
    th.set_inputs(&[0.05]);
    th.begin_step(0);
    let mut w = Wrench::ZERO;
    th.add_force_torque(&stage(), &EnvironmentSample::NONE, &mut w);
    // Full thrust in the first step (τ = 0): F = 2 ŷ at r = (1, 0, 1): r × F = (−2, 0, 2).
    assert_eq!(w.force_b_newton, Vector3::new(0.0, 2.0, 0.0));
    assert_eq!(w.torque_b_nm, Vector3::new(-2.0, 0.0, 2.0));
    let mut out = [0.0; 4];
    assert_eq!(th.outputs(&mut out) & FIRING, FIRING);
}

/// Calling begin_step again at the same instant (the state record, then a new command) solves
/// the step again but counts nothing twice.
#[test]
fn begin_step_is_idempotent_at_one_instant() {
    let mut th = Thruster::new(params(0.01, 0.01, 0.0), "thrusters[0]", FRAME_NS, STEP_NS).unwrap();
    th.set_inputs(&[0.03]);
    th.begin_step(0);
    th.begin_step(0);
    th.set_inputs(&[0.05]);
    th.begin_step(0);
    for s in 1..=100 {
        th.begin_step(s * STEP_NS);
        th.begin_step(s * STEP_NS);
    }
    let mut out = [0.0; 4];
    th.outputs(&mut out);
    assert_eq!(out[1], 1.0);
    // The 0.05 s pulse, with equal time constants: 2 N × (0.05 s − the tail still to come).
    let k_end = out[0] / 2.0;
    let expected = 2.0 * 0.05 - 2.0 * 0.01 * k_end;
    assert!(
        (out[3] - expected).abs() < 1e-12,
        "{} vs {expected}",
        out[3]
    );
}

#[test]
fn commands_out_of_range_are_clipped_and_flagged() {
    let mut th = Thruster::new(params(0.0, 0.0, 0.02), "thrusters[0]", FRAME_NS, STEP_NS).unwrap();
    let mut out = [0.0; 4];
    for (u, flags) in [
        (0.05, 0),
        (0.5, COMMAND_CLIPPED),
        (-0.01, COMMAND_CLIPPED),
        (0.01, BELOW_MIN_ON_TIME),
        (0.0, 0),
    ] {
        th.set_inputs(&[u]);
        th.begin_step(0);
        assert_eq!(th.outputs(&mut out) & !FIRING, flags, "command {u}");
    }
    assert!(
        Thruster::new(params(0.0, 0.0, 0.2), "thrusters[3]", FRAME_NS, STEP_NS)
            .unwrap_err()
            .to_string()
            .starts_with("thrusters[3].min_on_time_s")
    );
    let mut p = params(0.0, 0.0, 0.0);
    p.isp_s = -1.0;
    assert!(Thruster::new(p, "thrusters[1]", FRAME_NS, STEP_NS)
        .unwrap_err()
        .to_string()
        .starts_with("thrusters[1].isp_s"));
}
