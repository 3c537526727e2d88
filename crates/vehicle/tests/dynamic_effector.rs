//! The dynamic-effector seam: an external force and torque evaluated at every RK4 stage.
//!
//! Oracles:
//! - a constant torque through the seam is the same physics as the same torque held by
//!   `set_wrench`, bit for bit (the seam adds it into the same place of Eq. 150);
//! - a torque that grows linearly in time, τ(t) = k t, on a rigid spherical hub (I = i 𝟙, so
//!   ω × Iω = 0 and ω̇ = τ/i exactly) gives ω(t) = k t²/(2 i). RK4 integrates a quadratic in t
//!   exactly when the torque is evaluated at the stage times; a torque held over each step (one
//!   value per step) would give the rectangle rule, k h² n(n−1)/(2 i), which the test rejects;
//! - a force applied off the centre of mass turns the hub by r × F: on a rigid hub at rest, the
//!   initial angular acceleration equals [I_C]⁻¹ (r_P/C × F) from Euler's equation.

use flexdyn_dynamics::{DynamicEffector, Spacecraft, StageState, State, Wrench};
use flexdyn_environment::EnvironmentSample;
use flexdyn_vehicle::config::SimConfig;
use nalgebra::{Matrix3, Vector3};

/// A rigid hub with I = `inertia` about its CoM at B, at rest, in free space.
fn rigid_hub(inertia: [f64; 3]) -> Spacecraft {
    let toml = format!(
        r#"
panel_pairs = []
[simulation]
step_s = 0.01
frame_hz = 10.0
[gravity]
model = "none"
[hub]
mass_kg = 100.0
inertia_bc_b_kg_m2 = [[{}, 0.0, 0.0], [0.0, {}, 0.0], [0.0, 0.0, {}]]
r_bcb_b_m = [0.0, 0.0, 0.0]
[initial]
r_bn_n_m = [0.0, 0.0, 0.0]
v_bn_n_m_s = [0.0, 0.0, 0.0]
sigma_bn = [0.0, 0.0, 0.0]
omega_bn_b_rad_s = [0.0, 0.0, 0.0]
"#,
        inertia[0], inertia[1], inertia[2]
    );
    SimConfig::from_toml_str(&toml)
        .unwrap()
        .build_spacecraft()
        .unwrap()
}

/// The reference spacecraft (two flexing wings, tumbling, in orbit).
fn reference() -> Spacecraft {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/reference.toml"
    ))
    .unwrap();
    SimConfig::from_toml_str(&text)
        .unwrap()
        .build_spacecraft()
        .unwrap()
}

#[derive(Debug)]
struct ConstantTorque(Vector3<f64>);

impl DynamicEffector for ConstantTorque {
    fn name(&self) -> &str {
        "constant"
    }
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
    fn add_force_torque(&mut self, _s: &StageState, _e: &EnvironmentSample, sum: &mut Wrench) {
        sum.torque_b_nm += self.0;
    }
}

#[derive(Debug)]
struct RampTorque {
    k_nm_s: Vector3<f64>,
}

impl DynamicEffector for RampTorque {
    fn name(&self) -> &str {
        "ramp"
    }
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
    fn add_force_torque(&mut self, s: &StageState, _e: &EnvironmentSample, sum: &mut Wrench) {
        sum.torque_b_nm += self.k_nm_s * s.t_s();
    }
}

/// A force applied at a point P fixed on the hub.
#[derive(Debug)]
struct ForceAtPoint {
    r_pb_b_m: Vector3<f64>,
    force_b_newton: Vector3<f64>,
}

impl DynamicEffector for ForceAtPoint {
    fn name(&self) -> &str {
        "force_at_point"
    }
    fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
    fn add_force_torque(&mut self, _s: &StageState, _e: &EnvironmentSample, sum: &mut Wrench) {
        sum.force_b_newton += self.force_b_newton;
        sum.torque_b_nm += self.r_pb_b_m.cross(&self.force_b_newton);
    }
}

fn bits(x: &State) -> Vec<u64> {
    let mut v: Vec<f64> = Vec::new();
    v.extend(x.r_bn_n.iter());
    v.extend(x.v_bn_n.iter());
    v.extend(x.sigma_bn.iter());
    v.extend(x.omega_bn_b.iter());
    v.extend(x.effectors.iter());
    v.into_iter().map(f64::to_bits).collect()
}

#[test]
fn a_constant_torque_through_the_seam_equals_the_held_wrench_bit_for_bit() {
    let tau = Vector3::new(0.3, -0.2, 0.1);
    let mut held = reference();
    held.set_wrench(Wrench {
        force_b_newton: Vector3::zeros(),
        torque_b_nm: tau,
    });
    let mut seam = reference();
    seam.add_dynamic_effector(Box::new(ConstantTorque(tau)));
    for _ in 0..2000 {
        held.step();
        seam.step();
    }
    assert_eq!(bits(held.state()), bits(seam.state()));
    // And the torque really acts: without it the state differs.
    let mut free = reference();
    for _ in 0..2000 {
        free.step();
    }
    assert_ne!(bits(free.state()), bits(seam.state()));
}

#[test]
fn a_time_varying_torque_is_evaluated_at_every_rk4_stage() {
    let i = 10.0;
    let k = Vector3::new(0.02, -0.01, 0.005);
    let mut sc = rigid_hub([i, i, i]);
    sc.add_dynamic_effector(Box::new(RampTorque { k_nm_s: k }));
    let n = 500;
    for _ in 0..n {
        sc.step();
    }
    let t = sc.t_sim_ns() as f64 * 1e-9;
    let exact = k * (t * t / (2.0 * i));
    let err = (sc.state().omega_bn_b - exact).norm();
    assert!(
        err <= 1e-12 * exact.norm(),
        "ω = {:?}, closed form {exact:?}",
        sc.state().omega_bn_b
    );
    // The rectangle rule a per-step hold would give is far off: the test can tell them apart.
    let h = sc.step_ns() as f64 * 1e-9;
    let held = k * (h * h * (n * (n - 1)) as f64 / (2.0 * i));
    assert!((held - exact).norm() > 1e-3 * exact.norm());
}

#[test]
fn a_force_off_the_centre_of_mass_turns_the_hub_by_r_cross_f() {
    let inertia = [8.0, 6.0, 4.0];
    let mut sc = rigid_hub(inertia);
    let r_pb_b_m = Vector3::new(0.5, -0.2, 0.3);
    let force_b_newton = Vector3::new(0.0, 2.0, -1.0);
    sc.add_dynamic_effector(Box::new(ForceAtPoint {
        r_pb_b_m,
        force_b_newton,
    }));
    let out = sc.hub_outputs();
    // At rest, with C = B: ω̇ = [I]⁻¹ (r × F) (Euler's equation, no gyroscopic term).
    let expected = Matrix3::from_diagonal(&Vector3::from(inertia))
        .try_inverse()
        .unwrap()
        * r_pb_b_m.cross(&force_b_newton);
    assert!((out.omega_dot_bn_b - expected).norm() <= 1e-15 * expected.norm().max(1.0));
    // ... and accelerates the CoM by F/m.
    assert!((out.nongrav_accel_bn_b - force_b_newton / 100.0).norm() <= 1e-15);
}

#[test]
fn the_stage_state_carries_the_flexed_inertia_about_the_centre_of_mass() {
    // The reference spacecraft's inertia about C from the stage equals the one from its
    // conserved quantities: H_C = [I_C] ω when every panel is at rest relative to the hub.
    #[derive(Debug)]
    struct Probe(std::sync::Arc<std::sync::Mutex<Option<StageState>>>);
    impl DynamicEffector for Probe {
        fn name(&self) -> &str {
            "probe"
        }
        fn archive(&mut self, _a: &mut flexdyn_kernel::archive::Archive<'_>) {}
        fn add_force_torque(&mut self, s: &StageState, _e: &EnvironmentSample, _w: &mut Wrench) {
            *self.0.lock().unwrap() = Some(*s);
        }
    }
    let mut sc = reference();
    let mut state = sc.state().clone();
    for i in 0..state.effectors.len() {
        if i % 2 == 1 {
            state.effectors[i] = 0.0; // θ̇ = 0: the panels move with the hub
        }
    }
    sc.set_state(&state).unwrap();
    let seen = std::sync::Arc::new(std::sync::Mutex::new(None));
    sc.add_dynamic_effector(Box::new(Probe(seen.clone())));
    sc.hub_outputs();
    let stage = seen.lock().unwrap().unwrap();
    let h_c_n = sc.conserved().rot_ang_mom_c_n;
    let h_c_b = stage.dcm_bn * h_c_n;
    let i_c = stage.inertia_pnt_c_b_kg_m2();
    let from_stage = i_c * state.omega_bn_b;
    assert!(
        (from_stage - h_c_b).norm() <= 1e-12 * h_c_b.norm(),
        "[I_C] ω = {from_stage:?}, H_C = {h_c_b:?}"
    );
    let (m, c_b, _) = sc.center_of_mass();
    assert_eq!(stage.mass_kg, m);
    assert!((stage.r_cb_b_m - c_b).norm() <= 1e-15);
}
