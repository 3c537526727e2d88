//! Actuator fault modes against the documented transforms (`crates/faults/src/ports.rs`, "Actuator
//! modes, physically"). The input modes are checked by equivalence: a run with the fault and a
//! healthy run of the same configuration whose flight code commands, inside the window, the
//! documented transform of the command (outside it, the command itself) give bit-identical
//! state records at every frame. The physics is untouched, so nothing else may differ.
//!
//! The two wheel modes that depend on the wheel's own speed are checked physically:
//! `friction_scale` against a healthy wheel whose friction coefficients are multiplied, and
//! `seized` by the rotor stopping at the motor's torque limit, staying at rest, and the total
//! angular momentum about C being conserved (the brake is an internal torque).

use flexdyn_proto::StateMsg;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

const ACS_FULL: &str = include_str!("../../../scenarios/acs_full.toml");
const WHEELS: &str = include_str!("../../../scenarios/wheels_star_tracker.toml");
/// Frames of 0.1 s (acs_full); the window covers frames 5 to 14.
const START_S: f64 = 0.5;
const DURATION_S: f64 = 1.0;
const FRAMES: u64 = 20;

/// The flat input index of effector `name`'s (first) input.
fn input_index(sim: &Simulation, name: &str) -> usize {
    let sc = sim.spacecraft();
    let k = sc
        .effector_entries()
        .position(|e| e.name == name)
        .unwrap_or_else(|| panic!("no effector {name}"));
    sc.effector_input_ranges()[k].start
}

/// Runs `text` for [`FRAMES`] frames commanding `command(k)` at `target`'s input at frame `k`
/// (others 0); `transform` (if given) replaces it inside the window. The state record after
/// each frame.
fn run(
    text: &str,
    target: &str,
    command: impl Fn(u64) -> f64,
    transform: Option<&dyn Fn(f64) -> f64>,
) -> Vec<StateMsg> {
    let cfg = SimConfig::from_toml_str(text).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&cfg).unwrap();
    let i = input_index(&sim, target);
    let mut u = vec![0.0; sim.spacecraft().effector_input_len()];
    let frame_s = cfg.frame_ns as f64 * 1e-9;
    (0..FRAMES)
        .map(|k| {
            let t = k as f64 * frame_s;
            u[i] = command(k);
            if let Some(f) = transform {
                if (START_S..START_S + DURATION_S).contains(&(t + 1e-9)) {
                    u[i] = f(u[i]);
                }
            }
            sim.set_effector_inputs(&u).unwrap();
            sim.step_frame();
            sim.state_msg()
        })
        .collect()
}

/// acs_full with one fault on `target` (`params`: the mode's parameter lines).
fn fault(base: &str, target: &str, mode: &str, params: &str) -> String {
    format!(
        "{base}\n[[faults]]\ntarget = \"{target}\"\nmode = \"{mode}\"\n{params}\n\
         start_s = {START_S}\nduration_s = {DURATION_S}\n"
    )
}

/// The faulted run equals the healthy run commanding `transform(command)` in the window, frame
/// by frame, and differs from the untransformed healthy run (so the case cannot pass vacuously).
fn equivalent(
    mode: &str,
    params: &str,
    name: &str,
    command: fn(u64) -> f64,
    transform: &dyn Fn(f64) -> f64,
) {
    let section = if name.starts_with("rw") {
        "reaction_wheels"
    } else if name.starts_with("mtq") {
        "magnetorquers"
    } else {
        "thrusters"
    };
    let text = fault(ACS_FULL, &format!("{section}.{name}"), mode, params);
    let faulted = run(&text, name, command, None);
    let reference = run(ACS_FULL, name, command, Some(transform));
    let healthy = run(ACS_FULL, name, command, None);
    for (k, (f, r)) in faulted.iter().zip(&reference).enumerate() {
        assert_eq!(f, r, "{mode} on {name}: frame {k}");
    }
    assert_ne!(
        faulted.last(),
        healthy.last(),
        "{mode} on {name} changes nothing"
    );
}

/// A command that changes sign and size from frame to frame.
fn torque(k: u64) -> f64 {
    0.15 * (k as f64 + 0.5).sin()
}

#[test]
fn wheel_command_ignored_and_torque_limit() {
    equivalent("command_ignored", "", "rw2", torque, &|_| 0.0);
    // 0.25 of max_torque_nm = 0.2 N·m.
    equivalent("torque_limit", "fraction = 0.25", "rw2", torque, &|u| {
        u.clamp(-0.05, 0.05)
    });
}

#[test]
fn thruster_stuck_on_stuck_off_and_scaled() {
    let on_time = |k: u64| {
        if k.is_multiple_of(3) {
            0.0
        } else {
            0.03 + 0.01 * (k % 4) as f64
        }
    };
    // Stuck open: the whole 0.1 s frame.
    equivalent("stuck_on", "", "thr_pz1", on_time, &|_| 0.1);
    equivalent("stuck_off", "", "thr_pz1", on_time, &|_| 0.0);
    equivalent("thrust_scale", "factor = 0.5", "thr_mz2", on_time, &|u| {
        0.5 * u
    });
}

#[test]
fn magnetorquer_dead_and_scaled_before_the_clip() {
    // 600 A·m² clips at 400 healthy; scaled by 0.5 first, it is 300 and passes.
    let dipole = |k: u64| if k.is_multiple_of(2) { 600.0 } else { -250.0 };
    equivalent("dead", "", "mtq_x", dipole, &|_| 0.0);
    equivalent("dipole_scale", "factor = 0.5", "mtq_y", dipole, &|u| {
        0.5 * u
    });
}

/// The index of rw2's speed Ω in the state's effector states.
fn rw2_omega_index(sim: &Simulation) -> usize {
    let sc = sim.spacecraft();
    sc.effector_entries()
        .find(|e| e.name == "rw2")
        .unwrap()
        .state_range
        .start
}

/// rw2's speed Ω \[rad/s\] after each frame of `text` with no command.
fn rw2_speeds(text: &str, frames: u64) -> Vec<f64> {
    let cfg = SimConfig::from_toml_str(text).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&cfg).unwrap();
    let k = rw2_omega_index(&sim);
    (0..frames)
        .map(|_| {
            sim.step_frame();
            sim.spacecraft().state().effectors[k]
        })
        .collect()
}

/// `text` with rw2's initial speed and bearing lines (from `omega_rad_s` through
/// `coulomb_friction_nm`) replaced by `bearing`.
fn with_rw2_bearing(text: &str, bearing: &str) -> String {
    let rw2 = text.find("name = \"rw2\"").expect("acs_full has rw2");
    let start = rw2 + text[rw2..].find("omega_rad_s = ").expect("rw2 omega_rad_s");
    let coulomb = start
        + text[start..]
            .find("coulomb_friction_nm = ")
            .expect("rw2 coulomb");
    let end = coulomb + text[coulomb..].find('\n').expect("a line end");
    format!("{}{bearing}{}", &text[..start], &text[end..])
}

/// `friction_scale` k adds (k − 1) τ_f(Ω) at each step's start to the motor torque: the wheel
/// then spins down as a healthy wheel whose viscous and Coulomb coefficients are k times larger
/// (W3: J_s Ω̇ = u + τ_f). Here the fault is on from t = 0 for 1.5 s, so both start alike. The
/// fault holds τ_f over each step of h = 1 ms where the reference evaluates it at every stage:
/// with b = 1e-6 N·m·s/rad (the Coulomb part is constant outside its band) and Ω̇ ≈
/// −k·6e-4/0.05 = −0.12 rad/s², the extra drag differs on average by (k − 1) b |Ω̇| h/2, so the
/// speeds drift apart by (k − 1) b |Ω̇| h²/(2 J_s) ≈ 1.1e-11 rad/s per step: the bound below is
/// twice that times the steps so far. The healthy wheel slows by (k − 1)·6e-4/0.05 ≈ 0.1 rad/s
/// less per second.
#[test]
fn wheel_friction_scale_is_a_k_times_rougher_bearing() {
    let bearing =
        "omega_rad_s = 100.0\nviscous_friction_nm_s_rad = 1.0e-6\ncoulomb_friction_nm = 5.0e-4";
    let rough =
        "omega_rad_s = 100.0\nviscous_friction_nm_s_rad = 1.0e-5\ncoulomb_friction_nm = 5.0e-3";
    // rw2 at the 100 rad/s, and steps of the 1 ms, the bound is derived for, whatever acs_full
    // uses.
    let (step, derived) = (
        ACS_FULL
            .lines()
            .find(|l| l.starts_with("step_s = "))
            .unwrap(),
        "step_s = 0.001",
    );
    let acs = ACS_FULL.replacen(step, derived, 1);
    let base = with_rw2_bearing(&acs, bearing);
    let faulted = rw2_speeds(
        &format!(
            "{base}\n[[faults]]\ntarget = \"reaction_wheels.rw2\"\nmode = \"friction_scale\"\n\
             factor = 10.0\nduration_s = 1.5\n"
        ),
        FRAMES,
    );
    let rough = with_rw2_bearing(&acs, rough);
    let healthy = rw2_speeds(&base, FRAMES);
    let reference = rw2_speeds(&rough, FRAMES);
    let per_step = 9.0 * 1e-6 * 0.12 * 1e-6 / (2.0 * 0.05);
    for (k, (f, r)) in faulted.iter().zip(&reference).take(15).enumerate() {
        let steps = 100.0 * (k + 1) as f64;
        assert!(
            (f - r).abs() < 2.0 * per_step * steps,
            "frame {k}: {f} vs {r}"
        );
    }
    // After the window it spins down at the healthy rate again.
    let drop = |v: &[f64], a: usize, b: usize| v[a] - v[b];
    let (f_in, h_in) = (drop(&faulted, 0, 14), drop(&healthy, 0, 14));
    assert!(f_in > 5.0 * h_in && h_in > 0.0, "{f_in} vs {h_in}");
    let (f_out, h_out) = (drop(&faulted, 15, 19), drop(&healthy, 15, 19));
    assert!((f_out - h_out).abs() < 1e-3 * h_out, "{f_out} vs {h_out}");
}

/// `seized`: the rotor brakes at the motor's limit (Ω̇ = −max_torque/J_s = −4 rad/s² from
/// 2 rad/s, so it stops in 0.5 s) and is then held at rest; the brake is internal, so the total
/// angular momentum about C is conserved as in the healthy run (no external torque in this
/// scenario, RK4 at 1 ms keeps it to ~1e-12 relative).
#[test]
fn wheel_seized_stops_the_rotor_and_keeps_the_angular_momentum() {
    let slow = WHEELS.replace("omega_rad_s = 100.0", "omega_rad_s = 2.0");
    assert_ne!(slow, WHEELS);
    let text = format!(
        "{slow}\n[[faults]]\ntarget = \"reaction_wheels.rw2\"\nmode = \"seized\"\nstart_s = 0.1\n"
    );
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let k = rw2_omega_index(&sim);
    let h0 = sim.spacecraft().conserved().rot_ang_mom_c_n;
    let omega = |sim: &Simulation| sim.spacecraft().state().effectors[k];
    // 0.1 s healthy (friction only), then 0.45 s braking at 4 rad/s²: not yet at rest.
    sim.step_n(100);
    let omega_on = omega(&sim);
    assert!((omega_on - 2.0).abs() < 1e-3, "{omega_on}");
    sim.step_n(450);
    let braking = omega(&sim);
    // Ω̇ ≈ −4 rad/s² (the motor's limit; friction and the hub coupling add < 1 %).
    assert!(
        (braking - (omega_on - 4.0 * 0.45)).abs() < 0.02,
        "{braking}"
    );
    sim.step_n(450);
    // Held at rest: each step the brake cancels the speed it starts with, so what remains is
    // the hub's share of (W3), −ĝ_sᵀ ω̇_B/N, over one step: |Ω| ≤ h |ω̇_B/N| (the panels keep
    // the hub oscillating). 2× for the variation of ω̇ within the step.
    let (mut worst, mut bound) = (0.0_f64, 0.0_f64);
    for _ in 0..1000 {
        sim.step();
        worst = worst.max(omega(&sim).abs());
        let w_dot = nalgebra::Vector3::from(sim.state_msg().omega_dot_bn_b_rad_s2);
        bound = bound.max(2.0 * 1e-3 * w_dot.norm());
    }
    assert!(
        worst < bound && bound < 1e-4,
        "held at rest: |Ω| up to {worst}, bound {bound}"
    );
    let h = sim.spacecraft().conserved().rot_ang_mom_c_n;
    assert!((h - h0).norm() < 1e-10 * h0.norm(), "{h0} → {h}");
}
