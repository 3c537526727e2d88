//! A library user's program: a spacecraft built and stepped with `flexdyn-dynamics` alone (no
//! configuration file, server or I/O stack), printing how well the free, undamped system keeps
//! its energy and angular momentum.
//!
//! `cargo run --release -p flexdyn-dynamics --example step_spacecraft`
//!
//! The spacecraft: a 750 kg hub carrying one dual-hinged wing (two 50 kg panels on torsional
//! springs, no damping) deflected 5° and −3°, tumbling at 0.05 rad/s about each axis, in a
//! 7,400 km circular orbit under point-mass gravity; 60 s of fixed-step RK4 at 1 ms.

use flexdyn_dynamics::{
    GravityModel, HubInitial, HubParams, InitialTranslation, PanelPair, PanelPairInitial,
    PanelPairParams, PanelParams, Spacecraft, StateEffector,
};
use nalgebra::{Matrix3, Vector3};

/// \[m³/s²\] the Earth's gravitational parameter.
const MU_EARTH_M3_S2: f64 = 3.986004415e14;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let hub = HubParams {
        mass_kg: 750.0,
        inertia_bc_b_kg_m2: Matrix3::from_diagonal(&Vector3::new(900.0, 800.0, 600.0)),
        r_bcb_b_m: Vector3::new(0.0, 0.0, 1.0),
    };
    let panel = PanelParams {
        mass_kg: 50.0,
        inertia_s_kg_m2: Vector3::new(50.0, 25.0, 25.0),
        d_m: 0.75,
        k_nm_rad: 100.0,
        c_nm_s_rad: 0.0,
        width_m: None,
        thickness_m: None,
    };
    let wing = PanelPairParams {
        name: "wing".into(),
        r_h1b_b_m: Vector3::new(0.5, 0.0, 1.0),
        dcm_h1b: Matrix3::from_diagonal(&Vector3::new(-1.0, -1.0, 1.0)),
        theta_h2s1_rad: 0.0,
        l1_m: 1.5,
        panel1: panel.clone(),
        panel2: panel,
        motor_torque_nm: [0.0; 2],
    };
    let deflected = PanelPairInitial {
        theta1_rad: 5f64.to_radians(),
        theta1_dot_rad_s: 0.0,
        theta2_rad: -3f64.to_radians(),
        theta2_dot_rad_s: 0.0,
    };
    // Every parameter is checked here; an error names the field (`wing.panel1.mass_kg`).
    let effectors: Vec<Box<dyn StateEffector>> =
        vec![Box::new(PanelPair::new(wing, deflected, "wing")?)];
    let r_m = 7.4e6;
    let initial = HubInitial {
        translation: InitialTranslation::CenterOfMass {
            r_cn_n_m: Vector3::new(r_m, 0.0, 0.0),
            v_cn_n_m_s: Vector3::new(0.0, (MU_EARTH_M3_S2 / r_m).sqrt(), 0.0),
        },
        sigma_bn: Vector3::zeros(),
        omega_bn_b_rad_s: Vector3::new(0.05, -0.05, 0.05),
    };
    let gravity = GravityModel::PointMass {
        mu_m3_s2: MU_EARTH_M3_S2,
    };
    let step_ns = 1_000_000;
    let mut sc = Spacecraft::new(hub, gravity, effectors, initial, step_ns)?;

    let start = sc.conserved();
    let t0 = std::time::Instant::now();
    let steps = 60_000;
    for _ in 0..steps {
        sc.step();
    }
    let wall_s = t0.elapsed().as_secs_f64();
    let end = sc.conserved();
    let rel = |a: f64, b: f64| ((b - a) / a).abs();
    println!(
        "t = {} ns after {steps} RK4 steps of {step_ns} ns ({:.2} µs per step)",
        sc.t_sim_ns(),
        wall_s / steps as f64 * 1e6
    );
    println!(
        "rotational + spring energy: {:.9e} J -> {:.9e} J (relative change {:.1e})",
        start.rot_energy_j,
        end.rot_energy_j,
        rel(start.rot_energy_j, end.rot_energy_j)
    );
    println!(
        "angular momentum about the CoM: |H| {:.9e} -> {:.9e} kg m^2/s (relative change {:.1e})",
        start.rot_ang_mom_c_n.norm(),
        end.rot_ang_mom_c_n.norm(),
        (end.rot_ang_mom_c_n - start.rot_ang_mom_c_n).norm() / start.rot_ang_mom_c_n.norm()
    );
    println!(
        "orbital energy: {:.9e} J -> {:.9e} J (relative change {:.1e})",
        start.orb_energy_j,
        end.orb_energy_j,
        rel(start.orb_energy_j, end.orb_energy_j)
    );
    Ok(())
}
