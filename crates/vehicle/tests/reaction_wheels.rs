//! Reaction wheels against physics: invariants, analytic limits and the documented limits.
//!
//! Oracles (none is the code's own output):
//! - the motor and bearing torques are internal, so the angular momentum about the system CoM is
//!   conserved, and the rotational energy changes by exactly the motor work ∫ u Ω dt;
//! - a wheel spun up on a rigid hub obeys the closed-form solution of (W3) with H = 0;
//! - viscous friction gives an exponential, Coulomb friction a linear spin-down;
//! - a static imbalance U_s shakes the centre of mass at amplitude U_s Ω / m (force U_s Ω²).

use flexdyn_proto::wheel_flags;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

const NO_GRAVITY: &str = include_str!("../../../scenarios/no_gravity.toml");

/// A 4-wheel pyramid (spin axes 30° above the x-y plane, one per quadrant), frictionless,
/// at different initial speeds.
fn pyramid(omega0: [f64; 4]) -> String {
    let mut s = String::new();
    let e = 30f64.to_radians();
    for (j, az) in [45.0f64, 135.0, 225.0, 315.0].iter().enumerate() {
        let az = az.to_radians();
        let axis = [e.cos() * az.cos(), e.cos() * az.sin(), e.sin()];
        s += &format!(
            "\n[[reaction_wheels]]\nname = \"rw{j}\"\nspin_axis_b = [{:?}, {:?}, {:?}]\n\
             r_wb_b_m = [{:?}, {:?}, 0.4]\nmass_kg = 5.0\nj_s_kg_m2 = 0.05\nj_t_kg_m2 = 0.03\n\
             max_torque_nm = 0.2\nmax_speed_rad_s = 600.0\nomega_rad_s = {:?}\n",
            axis[0],
            axis[1],
            axis[2],
            0.3 * az.cos(),
            0.3 * az.sin(),
            omega0[j]
        );
    }
    s
}

/// A rigid hub (no panels, CoM at B, diag(900, 800, 600) kg·m²) at rest in free space with
/// `wheels` appended.
fn rigid_hub(wheels: &str) -> SimConfig {
    let text = format!(
        "panel_pairs = []\n[simulation]\nstep_s = 0.001\nframe_hz = 100.0\n[gravity]\nmodel = \"none\"\n\
         [hub]\nmass_kg = 750.0\ninertia_bc_b_kg_m2 = [[900.0, 0.0, 0.0], [0.0, 800.0, 0.0], [0.0, 0.0, 600.0]]\n\
         r_bcb_b_m = [0.0, 0.0, 0.0]\n[initial]\nr_bn_n_m = [0.0, 0.0, 0.0]\nv_bn_n_m_s = [0.0, 0.0, 0.0]\n\
         sigma_bn = [0.0, 0.0, 0.0]\nomega_bn_b_rad_s = [0.0, 0.0, 0.0]\n{wheels}"
    );
    SimConfig::from_toml_str(&text).unwrap_or_else(|e| panic!("{e}"))
}

/// One wheel along +z at B: m = 5 kg, J_s = 0.05, J_t = 0.03 kg·m², plus `extra` keys.
fn z_wheel(extra: &str) -> String {
    format!(
        "[[reaction_wheels]]\nname = \"rw\"\nspin_axis_b = [0.0, 0.0, 1.0]\nr_wb_b_m = [0.0, 0.0, 0.0]\n\
         mass_kg = 5.0\nj_s_kg_m2 = 0.05\nj_t_kg_m2 = 0.03\n{extra}\n"
    )
}

const J_S: f64 = 0.05;
/// The spacecraft's inertia about z with the rotor (J_s about its own axis, at B).
const I_TOTAL_Z: f64 = 600.0 + J_S;
/// J_s (1 − J_s / I_total): the wheel's effective inertia on a free hub (from (W3) with H_z = 0).
const J_EFF: f64 = J_S * (1.0 - J_S / I_TOTAL_Z);

fn wheel_omega(sim: &Simulation, effector: usize) -> f64 {
    let r = sim.spacecraft().effector_ranges()[effector].clone();
    sim.spacecraft().state().effectors[r.start]
}

#[test]
fn wheels_conserve_momentum_and_energy_changes_by_motor_work() {
    let cfg = SimConfig::from_toml_str(&format!(
        "{NO_GRAVITY}{}",
        pyramid([100.0, -50.0, 0.0, 300.0])
    ))
    .unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let h = sim.step_ns() as f64 * 1e-9;
    let first_wheel = 2; // after the two panel pairs
    let c0 = sim.spacecraft().conserved();
    let h0 = c0.rot_ang_mom_c_n.norm();
    let mut work_j = 0.0;
    let mut max_h_err = 0.0_f64;
    let mut max_u = 0.0_f64;
    for k in 0..10_000u64 {
        let t = k as f64 * h;
        let u: Vec<f64> = (0..4)
            .map(|j| 0.15 * (2.0 * std::f64::consts::PI * t / 3.0 + j as f64).sin())
            .collect();
        max_u = max_u.max(u[0].abs());
        sim.set_effector_inputs(&u).unwrap();
        let before: Vec<f64> = (0..4).map(|j| wheel_omega(&sim, first_wheel + j)).collect();
        sim.step();
        // u is held over the step; ∫ u Ω dt by the trapezoid rule on Ω (error ~1e-11 J/step).
        for j in 0..4 {
            let after = wheel_omega(&sim, first_wheel + j);
            work_j += u[j] * 0.5 * (before[j] + after) * h;
        }
        if k % 100 == 99 {
            let c = sim.spacecraft().conserved();
            max_h_err = max_h_err.max((c.rot_ang_mom_c_n - c0.rot_ang_mom_c_n).norm() / h0);
        }
    }
    let c1 = sim.spacecraft().conserved();
    let de = c1.rot_energy_j - c0.rot_energy_j;
    eprintln!(
        "4 wheels + 2 panel pairs, 10 s: |dH|/|H| max {max_h_err:.2e}; dE {de:.6} J, motor work \
         {work_j:.6} J, rel diff {:.2e}",
        (de - work_j).abs() / work_j.abs()
    );
    assert!(max_u > 0.14, "the wheels were driven");
    assert!(max_h_err <= 1e-12, "angular momentum drift {max_h_err:e}");
    assert!(work_j.abs() > 1.0, "the motors did work: {work_j}");
    assert!(
        (de - work_j).abs() <= 1e-8 * work_j.abs(),
        "energy change {de} vs motor work {work_j}"
    );
}

#[test]
fn spin_up_on_a_rigid_hub_matches_the_closed_form() {
    let cfg = rigid_hub(&z_wheel("max_torque_nm = 1.0\nmax_speed_rad_s = 10000.0"));
    let mut sim = Simulation::new(&cfg).unwrap();
    let u = 0.1;
    sim.set_effector_inputs(&[u]).unwrap();
    sim.step_n(10_000);
    let t = 10.0;
    let omega = wheel_omega(&sim, 0);
    // (W3) with ω̇_z = −J_s Ω̇ / I_total (H_z = 0): Ω = u t / J_eff; hub rate = −J_s Ω / I_total.
    let omega_expected = u * t / J_EFF;
    let w = sim.spacecraft().state().omega_bn_b;
    let w_expected = -J_S * omega / I_TOTAL_Z;
    eprintln!(
        "spin-up: Omega {omega} vs {omega_expected}; omega_z {} vs {w_expected}",
        w.z
    );
    assert!((omega - omega_expected).abs() <= 1e-12 * omega_expected);
    assert!((w.z - w_expected).abs() <= 1e-12 * w_expected.abs());
    assert!(w.x.abs() < 1e-15 && w.y.abs() < 1e-15);
}

#[test]
fn torque_and_speed_limits_clip_and_flag() {
    let cfg = rigid_hub(&z_wheel("max_torque_nm = 0.2\nmax_speed_rad_s = 50.0"));
    let mut sim = Simulation::new(&cfg).unwrap();
    sim.set_effector_inputs(&[0.5]).unwrap();
    let s = sim.state_msg();
    let rw = &s.effectors[0];
    assert_eq!(rw.outputs[0], 0.2, "torque clipped to the limit");
    assert_eq!(rw.flags, wheel_flags::TORQUE_LIMITED);
    // Reaching 50 rad/s at 0.2 N·m takes 50 J_eff / 0.2 = 12.5 s; run 15 s.
    let mut first_limited = None;
    for k in 0..15_000u64 {
        sim.step();
        if first_limited.is_none() && wheel_omega(&sim, 0) >= 50.0 {
            first_limited = Some(k);
        }
    }
    let omega = wheel_omega(&sim, 0);
    let s = sim.state_msg();
    let rw = &s.effectors[0];
    eprintln!("speed limit: Omega {omega} after 15 s, reached at step {first_limited:?}");
    // Held at the limit: it overshoots by at most one step's increment, u h / J_eff = 4e-3.
    assert!((50.0..=50.0 + 0.2 * 1e-3 / J_EFF * 1.001).contains(&omega));
    assert_eq!(rw.outputs[0], 0.0, "no torque beyond the speed limit");
    assert_eq!(
        rw.flags,
        wheel_flags::TORQUE_LIMITED | wheel_flags::SPEED_LIMITED
    );
    let reached = first_limited.expect("reached the limit") as f64 * 1e-3;
    assert!(
        (reached - 50.0 * J_EFF / 0.2).abs() <= 2e-3,
        "reached at {reached} s"
    );
    // A torque that slows the wheel applies at once.
    sim.set_effector_inputs(&[-0.1]).unwrap();
    let s = sim.state_msg();
    assert_eq!(s.effectors[0].outputs[0], -0.1);
    assert_eq!(s.effectors[0].flags, 0);
}

#[test]
fn viscous_friction_spins_down_exponentially() {
    let b = 1e-3;
    let cfg = rigid_hub(&z_wheel(&format!(
        "max_torque_nm = 1.0\nmax_speed_rad_s = 1000.0\nomega_rad_s = 100.0\nviscous_friction_nm_s_rad = {b:?}"
    )));
    let mut sim = Simulation::new(&cfg).unwrap();
    let s = sim.state_msg();
    assert_eq!(s.effectors[0].outputs[1], -b * 100.0, "friction output");
    sim.step_n(10_000);
    let omega = wheel_omega(&sim, 0);
    let expected = 100.0 * (-b * 10.0 / J_EFF).exp();
    eprintln!("viscous: Omega(10 s) {omega} vs {expected}");
    assert!((omega - expected).abs() <= 1e-9 * expected);
}

#[test]
fn coulomb_friction_spins_down_linearly_and_stops() {
    let (tau_c, band) = (0.01, 0.05);
    let cfg = rigid_hub(&z_wheel(&format!(
        "max_torque_nm = 1.0\nmax_speed_rad_s = 1000.0\nomega_rad_s = 5.0\ncoulomb_friction_nm = {tau_c:?}"
    )));
    let mut sim = Simulation::new(&cfg).unwrap();
    // Outside the band the deceleration is τ_c / J_eff: Ω reaches the band at (5 − band) J_eff / τ_c.
    let t_band = (5.0 - band) * J_EFF / tau_c;
    let mut reached = None;
    let mut min_omega = f64::INFINITY;
    for k in 1..=60_000u64 {
        sim.step();
        let om = wheel_omega(&sim, 0);
        min_omega = min_omega.min(om);
        if reached.is_none() && om <= band {
            reached = Some(k as f64 * 1e-3);
        }
    }
    let reached = reached.expect("the wheel slowed into the Coulomb band");
    let omega = wheel_omega(&sim, 0);
    eprintln!("Coulomb: band reached at {reached} s (expected {t_band} s), Omega(60 s) {omega:e}");
    assert!((reached - t_band).abs() <= 1.5e-3);
    assert!(
        min_omega >= 0.0,
        "no chatter across zero: min {min_omega:e}"
    );
    assert!(omega < 1e-6, "stopped: {omega:e}");
}

#[test]
fn static_imbalance_shakes_the_centre_of_mass_at_us_omega_squared() {
    let (u_s, omega0) = (1e-4, 200.0);
    let cfg = rigid_hub(&z_wheel(&format!(
        "max_torque_nm = 1.0\nmax_speed_rad_s = 300.0\nomega_rad_s = {omega0:?}\nstatic_imbalance_kg_m = {u_s:?}"
    )));
    let mut sim = Simulation::new(&cfg).unwrap();
    let m = 755.0;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for _ in 0..1000 {
        sim.step();
        let v = sim.spacecraft().state().v_bn_n.x;
        lo = lo.min(v);
        hi = hi.max(v);
    }
    // F = U_s Ω² rotating at Ω through the CoM: v_C oscillates with amplitude U_s Ω / m.
    let amplitude = 0.5 * (hi - lo);
    let expected = u_s * omega0 / m;
    eprintln!("jitter: v_C amplitude {amplitude:e} vs U_s Omega / m = {expected:e}");
    assert!((amplitude - expected).abs() <= 2e-3 * expected);
    // Balanced otherwise: the wheel keeps its speed and the hub does not turn.
    assert!((wheel_omega(&sim, 0) - omega0).abs() < 1e-9);
    assert!(sim.spacecraft().state().omega_bn_b.norm() < 1e-12);
}
