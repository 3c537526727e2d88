//! The propellant tank (`effectors/propellant_tank`) and the thrusters that draw from it,
//! checked against closed forms written here from the physics, not from the library:
//!
//! - the propellant used is ∫F dt/(I_sp g₀), for a constant thrust and for one pulse with a
//!   first-order build-up and tail-off;
//! - after burning Δm the vehicle's mass, centre of mass and inertia about B are the
//!   hand-computed ones;
//! - with a full tank and no thrust, energy and angular momentum are conserved as before;
//! - a thrust whose line passes through the centre of mass turns nothing, and the velocity
//!   change is the rocket equation's Δv = I_sp g₀ ln(m₀/m₁), with the linear momentum of the
//!   vehicle plus its exhaust conserved;
//! - a tank that runs dry stops its thrusters at exactly the propellant it held.

use nalgebra::{Matrix3, Vector3};

use crate::common;
use common::*;
use flexdyn_dynamics::dynamic_effectors::thruster::{
    Thruster, ThrusterCommand, ThrusterParams, G0_M_S2,
};
use flexdyn_dynamics::effectors::propellant_tank::{
    PropellantTank, PropellantTankParams, TankInertiaModel, EMPTY,
};
use flexdyn_dynamics::{EffectorMassProps, GravityModel, HubParams, Spacecraft, StateEffector};

const STEP_NS: u64 = 1_000_000; // 1 ms
const FRAME_NS: u64 = 100_000_000; // 10 Hz
const ISP_S: f64 = 220.0;

/// \[kg\] the round-off of `steps` steps that each add a small decrement to a propellant mass
/// state of at most `m_kg`: each addition rounds by up to half an ulp of m, and a constant
/// decrement rounds the same way every step, so the error grows linearly, ≤ steps · ε · m.
fn mass_round_off_kg(steps: u64, m_kg: f64) -> f64 {
    steps as f64 * f64::EPSILON * m_kg
}

fn tank(mass_kg: f64, r_tcb_b_m: Vector3<f64>) -> Box<dyn StateEffector> {
    Box::new(
        PropellantTank::new(
            PropellantTankParams {
                name: "main".into(),
                r_tcb_b_m,
                propellant_mass_kg: mass_kg,
                inertia: TankInertiaModel::ConstantVolume { radius_m: 0.3 },
            },
            "propellant_tanks[0]",
        )
        .expect("valid tank"),
    )
}

fn thruster(force_newton: f64, r_tb_b_m: Vector3<f64>, tau_s: (f64, f64)) -> Box<Thruster> {
    Box::new(
        Thruster::new(
            ThrusterParams {
                name: "thr".into(),
                r_tb_b_m,
                force_axis_b: Vector3::z(),
                max_thrust_newton: force_newton,
                isp_s: ISP_S,
                min_on_time_s: 0.0,
                rise_time_constant_s: tau_s.0,
                tail_off_time_constant_s: tau_s.1,
                command: ThrusterCommand::OnTime,
                tank: Some("main".into()),
            },
            "thrusters[0]",
            FRAME_NS,
            STEP_NS,
        )
        .expect("valid thruster"),
    )
}

/// A 100 kg hub, its centre of mass at B, with `effectors`, at rest, without gravity.
fn free_vehicle(effectors: Vec<Box<dyn StateEffector>>) -> Spacecraft {
    Spacecraft::new(
        HubParams {
            mass_kg: 100.0,
            inertia_bc_b_kg_m2: Matrix3::from_diagonal(&Vector3::new(10.0, 12.0, 8.0)),
            r_bcb_b_m: Vector3::zeros(),
        },
        GravityModel::None,
        effectors,
        at_rest(),
        STEP_NS,
    )
    .expect("valid spacecraft")
}

/// Steps `n` frames, commanding the valve-open time `on_time_s(frame)` at each frame start.
fn fly(sc: &mut Spacecraft, frames: u64, on_time_s: impl Fn(u64) -> f64) {
    for f in 0..frames {
        sc.set_effector_inputs(&[on_time_s(f)]).unwrap();
        for _ in 0..FRAME_NS / STEP_NS {
            sc.step();
        }
    }
}

fn propellant_kg(sc: &Spacecraft) -> f64 {
    sc.state().effectors[0]
}

/// (1a) A constant 2 N for 10 frames of 0.1 s (valve open all frame, no lag): the flow is
/// F/(I_sp g₀) = 2/(220 · 9.80665) = 9.2703e-4 kg/s, and after 1 s the tank has lost exactly
/// that times 1 s.
#[test]
fn propellant_used_is_thrust_over_isp_g0_constant_thrust() {
    let mut sc = free_vehicle(vec![tank(10.0, Vector3::new(0.0, 0.0, 0.3))]);
    sc.add_dynamic_effector(thruster(2.0, Vector3::new(0.0, 0.0, -1.0), (0.0, 0.0)));
    fly(&mut sc, 10, |_| 0.1);
    let want = 2.0 * 1.0 / (ISP_S * G0_M_S2);
    let used = 10.0 - propellant_kg(&sc);
    eprintln!("constant thrust: used {used:e} kg, closed form {want:e} kg");
    assert!(
        (used - want).abs() <= mass_round_off_kg(1000, 10.0),
        "{used} vs {want}"
    );
    // Outputs: the tank's ṁ (the held command keeps firing: −F/(I_sp g₀)), fraction and used,
    // then the thruster's thrust, pulses, propellant used (impulse/(I_sp g₀)) and impulse.
    let mut out = [0.0; 7];
    let mut flags = [0; 2];
    sc.effector_outputs(&mut out, &mut flags);
    assert!(
        (out[0] + 2.0 / (ISP_S * G0_M_S2)).abs() < 1e-18,
        "{}",
        out[0]
    );
    assert!((out[2] - used).abs() < 1e-15);
    // The thruster sums its impulse per step, 1000 additions to at most 2 N s.
    assert!((out[5] - want).abs() <= 1000.0 * f64::EPSILON * 2.0 / (ISP_S * G0_M_S2));
}

/// (1b) One pulse of t = 0.05 s with build-up τ_r = 0.015 s and tail-off τ_f = 0.025 s, then
/// the valve shut for 1.9 s. With κ the thrust fraction (κ̇ = (u − κ)/τ):
/// open, κ(s) = 1 − e^(−s/τ_r), ∫₀ᵗ κ = t − τ_r (1 − e^(−t/τ_r)), κ_t = 1 − e^(−t/τ_r);
/// shut, κ = κ_t e^(−s/τ_f), ∫ over the remaining T − t = κ_t τ_f (1 − e^(−(T−t)/τ_f)).
/// The propellant is F_max (∫κ)/(I_sp g₀).
#[test]
fn propellant_used_is_thrust_over_isp_g0_with_build_up_and_tail_off() {
    let (t, tr, tf, big_t) = (0.05, 0.015, 0.025, 2.0);
    let mut sc = free_vehicle(vec![tank(10.0, Vector3::new(0.0, 0.0, 0.3))]);
    sc.add_dynamic_effector(thruster(2.0, Vector3::new(0.0, 0.0, -1.0), (tr, tf)));
    fly(&mut sc, 20, |f| if f == 0 { t } else { 0.0 });
    let kt = 1.0 - (-t / tr).exp();
    let integral = t - tr * (1.0 - (-t / tr).exp()) + kt * tf * (1.0 - (-(big_t - t) / tf).exp());
    let want = 2.0 * integral / (ISP_S * G0_M_S2);
    let used = 10.0 - propellant_kg(&sc);
    eprintln!("one lagged pulse: used {used:e} kg, closed form {want:e} kg");
    assert!(
        (used - want).abs() <= mass_round_off_kg(2000, 10.0),
        "{used} vs {want}"
    );
}

/// (2) Mass properties after a burn: hub 100 kg at B with [I_hub] = diag(10, 12, 8); 10 kg of
/// propellant at r_T = (0.4, −0.2, 0.3) m in a 0.3 m constant-volume sphere. Firing 2 N for
/// 5 s burns Δm = 2 · 5/(220 g₀) kg, leaving m_p = 10 − Δm. Then
/// m = 100 + m_p, c = m_p r_T / m, and [I_B] = [I_hub] + (2/5) m_p R² [1] + m_p (|r_T|² [1] − r_T r_Tᵀ).
#[test]
fn mass_properties_follow_the_propellant_used() {
    let r_t = Vector3::new(0.4, -0.2, 0.3);
    let mut sc = free_vehicle(vec![tank(10.0, r_t)]);
    sc.add_dynamic_effector(thruster(2.0, Vector3::new(0.0, 0.0, -1.0), (0.0, 0.0)));
    fly(&mut sc, 50, |_| 0.1);
    let m_p = 10.0 - 2.0 * 5.0 / (ISP_S * G0_M_S2);
    let (m, c, _) = sc.center_of_mass();
    // The mass state's round-off over 5000 steps bounds every comparison.
    let dm = mass_round_off_kg(5000, 10.0);
    assert!((m - (100.0 + m_p)).abs() <= dm, "{m}");
    let c_want = r_t * m_p / (100.0 + m_p);
    assert!(
        (c - c_want).norm() <= dm * r_t.norm() / 100.0,
        "{c} vs {c_want}"
    );
    let mut mp = [EffectorMassProps::default()];
    sc.effector_mass_props(&mut mp);
    let i_b = Matrix3::from_diagonal(&Vector3::new(10.0, 12.0, 8.0)) + mp[0].inertia_pnt_b_b_kg_m2;
    let i_want = Matrix3::from_diagonal(&Vector3::new(10.0, 12.0, 8.0))
        + Matrix3::from_diagonal_element(0.4 * m_p * 0.09)
        + (Matrix3::from_diagonal_element(r_t.norm_squared()) - r_t * r_t.transpose()) * m_p;
    assert!((i_b - i_want).norm() <= dm * 1.0, "{i_b} vs {i_want}");
    // The mass really left: I_xx fell by Δm (2/5 R² + |r_T|² − x_T²) = Δm (0.036 + 0.13) from
    // the full tank's 10 + 10 (0.036 + 0.13) = 11.66 kg·m².
    let delta_m = 10.0 - m_p;
    assert!(
        (11.66 - i_b[(0, 0)] - delta_m * 0.166).abs() <= 1e-12,
        "{}",
        i_b[(0, 0)]
    );
}

/// (3a) With a full tank and no thrust the tank is a rigid part of the vehicle: the reference
/// spacecraft (two undamped panel pairs, point-mass orbit) with a tank and an idle thruster
/// conserves energy and angular momentum over 10 s at 1 ms to the same bound as without it.
#[test]
fn validate_conservation_with_a_full_idle_tank() {
    let mut effectors = reference_effectors_with_wheels(0, |_| {});
    effectors.push(tank(40.0, Vector3::new(0.3, -0.2, 0.4)));
    let mut sc = Spacecraft::new(
        reference_hub(),
        GravityModel::PointMass { mu_m3_s2: MU_EARTH },
        effectors,
        reference_initial(),
        STEP_NS,
    )
    .unwrap();
    sc.add_dynamic_effector(thruster(2.0, Vector3::new(0.5, 0.0, -1.0), (0.0, 0.0)));
    sc.set_effector_inputs(&[0.0]).unwrap();
    let d = run_drift(&mut sc, 10_000);
    eprintln!("full idle tank + 2 pairs, point-mass orbit, 10 s @ 1 ms: {d:?}");
    d.assert_all(1e-12);
    assert_eq!(*sc.state().effectors.last().unwrap(), 40.0);
}

/// (3b) Thrust along a line through the centre of mass, no external force: hub 100 kg at B,
/// 20 kg of propellant at (0, 0, 0.5), 10 N along +z at (0, 0, −1). The centre of mass stays on
/// the z axis as the propellant goes, so nothing turns (ω stays exactly 0). The vehicle's
/// velocity follows m v̇ = F with ṁ = −F/(I_sp g₀): Δv = I_sp g₀ ln(m₀/m₁) (Tsiolkovsky). The
/// linear momentum of vehicle and exhaust is conserved: each step's Δm leaves at v − I_sp g₀,
/// so m₁ v₁ + Σ Δm (v̄ − I_sp g₀) = m₀ v₀ = 0 (v̄ the step's mean velocity, a trapezoid).
#[test]
fn thrust_through_the_centre_of_mass_obeys_the_rocket_equation() {
    let mut sc = free_vehicle(vec![tank(20.0, Vector3::new(0.0, 0.0, 0.5))]);
    sc.add_dynamic_effector(thruster(10.0, Vector3::new(0.0, 0.0, -1.0), (0.0, 0.0)));
    sc.set_effector_inputs(&[0.1]).unwrap();
    let c_e = ISP_S * G0_M_S2;
    let (m0, _, _) = sc.center_of_mass();
    let mut exhaust_momentum = 0.0;
    for _ in 0..100_000 {
        let (m_a, v_a) = (sc.center_of_mass().0, sc.state().v_bn_n.z);
        sc.step();
        let (m_b, v_b) = (sc.center_of_mass().0, sc.state().v_bn_n.z);
        exhaust_momentum += (m_a - m_b) * (0.5 * (v_a + v_b) - c_e);
    }
    let (m1, _, _) = sc.center_of_mass();
    let v1 = sc.state().v_bn_n;
    // m₁ in closed form: 100 s of 10 N burn 10 · 100/(I_sp g₀) kg.
    let m1_exact = m0 - 10.0 * 100.0 / c_e;
    let dm = mass_round_off_kg(100_000, 20.0);
    assert!((m1 - m1_exact).abs() <= dm, "{m1} vs {m1_exact}");
    let dv = c_e * (m0 / m1_exact).ln();
    eprintln!(
        "100 s at 10 N: m {m0} → {m1} kg, Δv {} m/s, rocket equation {dv} m/s, ω {:e}",
        v1.z,
        sc.state().omega_bn_b.norm()
    );
    assert_eq!(sc.state().omega_bn_b, Vector3::zeros());
    assert_eq!((v1.x, v1.y), (0.0, 0.0));
    // The velocity sees the mass state's round-off: δ(Δv) ≤ (I_sp g₀/m₁) δm.
    let bound = c_e / m1 * dm + 1e-12 * dv;
    eprintln!("Δv error {:e} m/s, bound {bound:e}", v1.z - dv);
    assert!((v1.z - dv).abs() <= bound, "{} vs {dv}", v1.z);
    let total = m1 * v1.z + exhaust_momentum;
    eprintln!(
        "vehicle + exhaust momentum {total:e} kg m/s (vehicle alone {})",
        m1 * v1.z
    );
    assert!(total.abs() <= 1e-9 * m1 * v1.z, "{total}");
}

/// (D5) A tank that runs dry: 0.05 kg under 10 N at I_sp 220 s (4.635e-3 kg/s) lasts 10.79 s.
/// After 20 s of firing it holds exactly 0 (never less), flags EMPTY, the thruster has used
/// exactly the 0.05 kg and delivered I_sp g₀ · 0.05 N s, and the velocity gained is the rocket
/// equation's for the whole load.
#[test]
fn an_empty_tank_stops_its_thrusters() {
    let mut sc = free_vehicle(vec![tank(0.05, Vector3::new(0.0, 0.0, 0.5))]);
    sc.add_dynamic_effector(thruster(10.0, Vector3::new(0.0, 0.0, -1.0), (0.0, 0.0)));
    fly(&mut sc, 200, |_| 0.1);
    let m_p = propellant_kg(&sc);
    assert!(m_p.abs() <= 1e-17, "{m_p}");
    let mut out = [0.0; 7];
    let mut flags = [0; 2];
    sc.effector_outputs(&mut out, &mut flags);
    assert_eq!(flags[0], EMPTY);
    assert_eq!(out[0], 0.0, "no flow once empty");
    assert_eq!(out[3], 0.0, "no thrust once empty");
    // The thruster's impulse sum: ~10 800 additions to at most I_sp g₀ · 0.05 N s.
    let steps = 10_800.0;
    assert!(
        (out[5] - 0.05).abs() <= steps * f64::EPSILON * 0.05,
        "thruster used {}",
        out[5]
    );
    let c_e = ISP_S * G0_M_S2;
    let dv = c_e * (100.05_f64 / 100.0).ln();
    let v = sc.state().v_bn_n.z;
    eprintln!("ran dry: Δv {v} m/s, rocket equation {dv} m/s");
    let bound = c_e / 100.0 * mass_round_off_kg(10_800, 0.05) + 1e-12 * dv;
    assert!((v - dv).abs() <= bound, "{v} vs {dv}");
    let before = sc.state().v_bn_n;
    fly(&mut sc, 10, |_| 0.1);
    assert_eq!(
        sc.state().v_bn_n,
        before,
        "an empty tank's thruster pushes nothing"
    );
}
