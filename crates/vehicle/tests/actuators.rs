//! Magnetorquers and thrusters through the configuration and the simulation: closed forms on a
//! rigid hub, the momentum balance under a tumble, the state record's entries, and no
//! allocation while stepping.

use flexdyn_testkit::alloc_counter::allocations;

use flexdyn_dynamics::dynamic_effectors::{magnetorquer, thruster};
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_proto::{effector_kind, magnetorquer_flags, thruster_flags};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::{Matrix3, Vector3};

/// A rigid hub (no gravity, at rest at the origin, CoM at B) with `extra` appended.
fn rigid_hub(extra: &str) -> SimConfig {
    let text = format!(
        r#"
panel_pairs = []

[simulation]
step_s = 0.001
frame_hz = 10.0

[gravity]
model = "none"

[hub]
mass_kg = 500.0
inertia_bc_b_kg_m2 = [[600.0, 0.0, 0.0], [0.0, 500.0, 0.0], [0.0, 0.0, 400.0]]
r_bcb_b_m = [0.0, 0.0, 0.0]

[initial]
r_bn_n_m = [0.0, 0.0, 0.0]
v_bn_n_m_s = [0.0, 0.0, 0.0]
sigma_bn = [0.0, 0.0, 0.0]
omega_bn_b_rad_s = [0.0, 0.0, 0.0]
{extra}
"#
    );
    SimConfig::from_toml_str(&text).unwrap()
}

/// A `[[magnetorquers]]` entry.
fn rod(name: &str, axis_b: &str, max_dipole_am2: f64) -> String {
    format!(
        "\n[[magnetorquers]]\nname = \"{name}\"\naxis_b = {axis_b}\nr_mb_b_m = [0.5, 0.0, 0.0]\n\
         max_dipole_am2 = {max_dipole_am2:?}\n"
    )
}

/// A `[[thrusters]]` entry with the keys it must have; `more` adds optional ones.
fn thruster_entry(
    name: &str,
    r_tb_b_m: &str,
    force_axis_b: &str,
    thrust_n: f64,
    more: &str,
) -> String {
    format!(
        "\n[[thrusters]]\nname = \"{name}\"\nr_tb_b_m = {r_tb_b_m}\nforce_axis_b = {force_axis_b}\n\
         max_thrust_newton = {thrust_n:?}\nisp_s = 220.0\n{more}"
    )
}

fn field(b_n_t: Vector3<f64>) -> EnvironmentSample {
    EnvironmentSample {
        b_field_n_t: b_n_t,
        ..EnvironmentSample::NONE
    }
}

/// Momentum dumping in closed form. A wheel on z at the CoM stores H_w = J_s(Ω + ω_z); a rod on
/// x makes τ = m x̂ × B ŷ = m B ẑ in B = 30 µT along N's y. The wheel's motor torque u = m B
/// (commanded, on the rotor) puts −u on the hub, which cancels τ: the hub stays at rest and the
/// wheel's momentum changes by exactly ∫τ dt = m B t. With m < 0 that is a dump:
/// H_w(t) = H_w(0) + m B t.
#[test]
fn a_magnetorquer_unloads_a_wheel_by_the_time_integral_of_its_torque() {
    let wheel = r#"
[[reaction_wheels]]
name = "rw1"
spin_axis_b = [0.0, 0.0, 1.0]
r_wb_b_m = [0.0, 0.0, 0.0]
mass_kg = 5.0
j_s_kg_m2 = 0.05
j_t_kg_m2 = 0.03
max_torque_nm = 0.25
max_speed_rad_s = 600.0
omega_rad_s = 200.0
"#;
    let cfg = rigid_hub(&format!(
        "{wheel}{}",
        rod("mtq_x", "[1.0, 0.0, 0.0]", 400.0)
    ));
    let mut sim = Simulation::new(&cfg).unwrap();
    let b_t = 3.0e-5;
    sim.spacecraft_mut()
        .set_environment(&field(Vector3::new(0.0, b_t, 0.0)));
    let m_am2 = -350.0;
    let tau_nm = m_am2 * b_t;
    // Effector order: rw1, then mtq_x; one input each.
    sim.set_effector_inputs(&[tau_nm, m_am2]).unwrap();
    let h0 = 0.05 * 200.0;
    let t_s = 100.0;
    sim.step_n((t_s * 1000.0) as u64);
    let x = sim.spacecraft().state();
    let h = 0.05 * (x.effectors[0] + x.omega_bn_b.z);
    let expected = h0 + tau_nm * t_s;
    // Round-off only: 10⁵ steps each rounding Ω ≈ 200 rad/s (ε|Ω| J_s ≈ 2.2e-15 N m s) bound the
    // accumulated error by 10⁵ × 2.2e-15 = 2.2e-10 N m s.
    assert!(
        (h - expected).abs() < 2.2e-10,
        "H_w {h} vs {expected} N m s (dumped {} of {h0})",
        h0 - h
    );
    assert!(h < h0 - 1.0, "the stored momentum dropped: {h0} → {h}");
    assert!(
        x.omega_bn_b.norm() < 1e-15,
        "the hub stayed at rest: {:?}",
        x.omega_bn_b
    );
    // The state record: the wheel, then the rod with its applied dipole.
    let msg = sim.state_msg();
    assert_eq!(msg.effectors.len(), 2);
    assert_eq!(msg.effectors[1].kind, effector_kind::MAGNETORQUER);
    assert_eq!(msg.effectors[1].outputs, vec![m_am2]);
    assert_eq!(msg.effectors[1].flags, 0);
    // Past its limit the rod saturates, and says so.
    sim.set_effector_inputs(&[0.0, -500.0]).unwrap();
    let msg = sim.state_msg();
    assert_eq!(msg.effectors[1].outputs, vec![-400.0]);
    assert_eq!(msg.effectors[1].flags, magnetorquer_flags::SATURATED);
}

/// Under a tumble the rods' torque turns with the body: the angular momentum about C (N
/// components) changes by ∫ ([NB] m_B) × B_N dt. The integral is taken independently, by
/// Simpson's rule over the attitude at every step, and matches to its own O(h⁴) error.
#[test]
fn the_momentum_changes_by_the_integral_of_m_cross_b_under_a_tumble() {
    let mut cfg = rigid_hub(&format!(
        "{}{}",
        rod("mtq_x", "[1.0, 0.0, 0.0]", 400.0),
        rod("mtq_y", "[0.0, 0.6, 0.8]", 400.0)
    ));
    cfg.initial.omega_bn_b_rad_s = Vector3::new(0.05, -0.03, 0.04);
    let mut sim = Simulation::new(&cfg).unwrap();
    let b_n = Vector3::new(1.2e-5, -2.5e-5, 3.1e-5);
    sim.spacecraft_mut().set_environment(&field(b_n));
    let (m1, m2) = (120.0, -250.0);
    sim.set_effector_inputs(&[m1, m2]).unwrap();
    let m_b = Vector3::new(m1, 0.0, 0.0) + Vector3::new(0.0, 0.6, 0.8) * m2;
    let tau_n = |sim: &Simulation| {
        let dcm_nb = mrp_to_dcm(&sim.spacecraft().state().sigma_bn).transpose();
        (dcm_nb * m_b).cross(&b_n)
    };
    let h0 = sim.spacecraft().conserved().rot_ang_mom_c_n;
    // 60 s of 1 ms steps, an even number of intervals for Simpson.
    let n = 60_000;
    let mut integral = tau_n(&sim);
    for i in 1..=n {
        sim.step();
        let w = if i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        integral += tau_n(&sim) * w;
    }
    integral *= 1e-3 / 3.0;
    let dh = sim.spacecraft().conserved().rot_ang_mom_c_n - h0;
    assert!(
        integral.norm() > 0.1,
        "the rods did something: {integral:?}"
    );
    assert!(
        (dh - integral).norm() < 1e-9 * integral.norm(),
        "ΔH {dh:?} vs ∫τ {integral:?}"
    );
}

/// A thruster through the centre of mass: the vehicle's velocity changes by the pulse's impulse
/// over the mass, Δv = F [t_on − (τ_r − τ_f)(1 − e^(−t_on/τ_r))] / m (the lag's closed form,
/// `thruster` module), and the attitude is untouched. The pulse count and the propellant follow.
#[test]
fn a_pulse_through_the_centre_of_mass_changes_the_velocity_by_its_impulse() {
    let cfg = rigid_hub(&thruster_entry(
        "thr1",
        "[0.0, -1.0, 0.0]",
        "[0.0, 1.0, 0.0]",
        1.0,
        "min_on_time_s = 0.02\nrise_time_constant_s = 0.015\ntail_off_time_constant_s = 0.025\n",
    ));
    let mut sim = Simulation::new(&cfg).unwrap();
    let t_on = 0.0637;
    sim.set_effector_inputs(&[t_on]).unwrap();
    sim.step_frame();
    sim.set_effector_inputs(&[0.0]).unwrap();
    // 3 s of tail-off: e^(−3/0.025) of the thrust is left.
    for _ in 0..30 {
        sim.step_frame();
    }
    let k1 = 1.0 - (-t_on / 0.015f64).exp();
    let impulse = 1.0 * (t_on - (0.015 - 0.025) * k1);
    let x = sim.spacecraft().state();
    let dv = impulse / 500.0;
    assert!(
        (x.v_bn_n - Vector3::new(0.0, dv, 0.0)).norm() < 1e-15,
        "{:?} vs {dv}",
        x.v_bn_n
    );
    assert!(x.omega_bn_b.norm() < 1e-15, "no torque through the CoM");
    let msg = sim.state_msg();
    let e = &msg.effectors[0];
    assert_eq!(e.kind, effector_kind::THRUSTER);
    assert!(e.states.is_empty());
    assert_eq!(e.outputs[1], 1.0, "one pulse");
    assert!((e.outputs[3] - impulse).abs() < 1e-13);
    assert!((e.outputs[2] - impulse / (220.0 * thruster::G0_M_S2)).abs() < 1e-16);
    assert_eq!(e.flags & thruster_flags::FIRING, 0, "the valve is shut now");
}

/// Off the centre of mass the same thruster turns the hub: at the first step of a full-thrust
/// pulse (τ = 0) the hub's angular acceleration is [I_C]⁻¹ (r_T/C × F), the closed form for a
/// rigid body at rest.
#[test]
fn an_offset_thruster_torques_the_hub_by_r_cross_f() {
    let cfg = rigid_hub(&thruster_entry(
        "thr1",
        "[1.0, 0.3, -0.2]",
        "[0.0, 0.6, 0.8]",
        2.0,
        "",
    ));
    let mut sim = Simulation::new(&cfg).unwrap();
    sim.set_effector_inputs(&[0.05]).unwrap();
    let msg = sim.state_msg();
    let f = Vector3::new(0.0, 0.6, 0.8) * 2.0;
    let torque = Vector3::new(1.0, 0.3, -0.2).cross(&f);
    let inertia = Matrix3::from_diagonal(&Vector3::new(600.0, 500.0, 400.0));
    let expected = inertia.try_inverse().unwrap() * torque;
    let got = Vector3::from(msg.omega_dot_bn_b_rad_s2);
    assert!((got - expected).norm() < 1e-16, "{got:?} vs {expected:?}");
    assert_eq!(
        msg.effectors[0].flags & thruster_flags::FIRING,
        thruster_flags::FIRING
    );
}

/// A thruster and a rod take rows of the input schedule by name, like a wheel.
#[test]
fn the_input_schedule_drives_actuators_by_name() {
    let schedule = r#"
[[effector_input_schedule]]
t_s = 0.0
effector = "thr1"
inputs = [0.25]

[[effector_input_schedule]]
t_s = 0.5
effector = "mtq_x"
inputs = [12.0]
"#;
    let cfg = rigid_hub(&format!(
        "{}{}{schedule}",
        rod("mtq_x", "[1.0, 0.0, 0.0]", 400.0),
        thruster_entry(
            "thr1",
            "[0.0, 0.0, 0.0]",
            "[1.0, 0.0, 0.0]",
            1.0,
            "command = \"duty_cycle\"\n"
        )
    ));
    let mut sim = Simulation::new(&cfg).unwrap();
    for _ in 0..10 {
        sim.step_frame();
    }
    let msg = sim.state_msg();
    assert_eq!(msg.effectors[0].outputs, vec![12.0]);
    // 10 frames at duty 0.25 of 0.1 s, 1 N, no lag: 0.25 N s, 10 pulses.
    assert!((msg.effectors[1].outputs[3] - 0.25).abs() < 1e-12);
    assert_eq!(msg.effectors[1].outputs[1], 10.0);
    assert_eq!(sim.spacecraft().effector_entries().count(), 2);
}

/// The configuration's errors name the entry and the field.
#[test]
fn bad_actuator_entries_are_named() {
    let text = |extra: &str| format!("{}\n{extra}", flexdyn_vehicle::config::DEFAULT_CONFIG_TOML);
    let thr = |more: &str| thruster_entry("t", "[0.0, 0.0, 0.0]", "[1.0, 0.0, 0.0]", 1.0, more);
    let cases = [
        (
            thr("command = \"bang\"\n"),
            "thrusters[0].command",
            "`bang` is not one of: on_time_s, duty_cycle",
        ),
        (
            thr("min_on_time_s = 0.5\n"),
            "thrusters[0].min_on_time_s",
            "longer than the frame period",
        ),
        (
            rod("m", "[2.0, 0.0, 0.0]", 1.0),
            "magnetorquers[0].axis_b",
            "",
        ),
        (
            rod("m", "[1.0, 0.0, 0.0]", 1.0).repeat(2),
            "magnetorquers[1].name",
            "duplicate magnetorquer name",
        ),
        (
            rod("m", "[1.0, 0.0, 0.0]", 1.0).replace("r_mb_b_m = [0.5, 0.0, 0.0]\n", ""),
            "magnetorquers[0].r_mb_b_m",
            "",
        ),
    ];
    for (extra, field, problem) in cases {
        let e = SimConfig::from_toml_str(&text(&extra))
            .unwrap_err()
            .to_string();
        assert!(e.contains(field), "{field}: {e}");
        assert!(e.contains(problem), "{problem}: {e}");
    }
}

/// Stepping the whole ACS scenario (every environment model, wheels, rods and thrusters
/// firing) allocates nothing once built.
#[test]
fn stepping_with_actuators_firing_allocates_nothing() {
    let path = std::path::Path::new(crate::REPO).join("scenarios/acs_full.toml");
    let cfg = SimConfig::from_file(&path).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let entries: Vec<_> = sim
        .spacecraft()
        .effector_entries()
        .map(|e| e.kind.name)
        .collect();
    assert_eq!(
        entries
            .iter()
            .filter(|k| **k == magnetorquer::KIND.name)
            .count(),
        3
    );
    assert_eq!(
        entries
            .iter()
            .filter(|k| **k == thruster::KIND.name)
            .count(),
        4
    );
    // Wheels 0.01 N m, rods 100 A m², thrusters 0.05 s per frame.
    let mut u = vec![0.01; 4];
    u.extend([100.0, -100.0, 50.0]);
    u.extend([0.05; 4]);
    sim.set_effector_inputs(&u).unwrap();
    let mut msg = sim.blank_state();
    sim.step_frame();
    sim.state_into(&mut msg);
    let before = allocations();
    for _ in 0..20 {
        sim.step_frame();
        sim.state_into(&mut msg);
    }
    let after = allocations();
    assert_eq!(
        after - before,
        0,
        "allocations while stepping with actuators firing"
    );
    // They did fire: 21 pulses each (one per frame), and the rods torque in the real field.
    let thr = &msg.effectors[msg.effectors.len() - 1];
    assert_eq!(thr.outputs[1], 21.0);
    assert!(sim.spacecraft().environment().b_field_n_t.norm() > 1e-5);
}
