//! Unit tests of the slosh pendulum: its frame, its kinematics against finite differences, and
//! parameter errors that name the field.

use nalgebra::Vector3;

use super::*;

fn params() -> SloshPendulumParams {
    SloshPendulumParams {
        name: "tank1".into(),
        r_pb_b_m: Vector3::new(0.2, -0.1, 0.3),
        hang_axis_b: Vector3::new(0.0, 0.6, -0.8),
        l_m: 0.4,
        mass_kg: 30.0,
        c_nm_s_rad: 0.0,
        phi_rad: 0.3,
        phi_dot_rad_s: 0.2,
        theta_rad: -0.25,
        theta_dot_rad_s: 0.1,
    }
}

/// p̂1 is the hang axis, (p̂1, p̂2, p̂3) is right-handed and orthonormal, and the rod hangs along
/// p̂1 at φ = θ = 0.
#[test]
fn frame_is_right_handed_with_the_hang_first() {
    let p = SloshPendulum::new(params(), "slosh_pendulums[0]").unwrap();
    let [p1, p2, p3] = p.frame_b();
    assert!((p1 - Vector3::new(0.0, 0.6, -0.8)).norm() < 1e-15);
    assert!(p1.dot(&p2).abs() < 1e-15 && p1.dot(&p3).abs() < 1e-15 && p2.dot(&p3).abs() < 1e-15);
    assert!((p1.cross(&p2) - p3).norm() < 1e-15);
    let r = p.r_pcb_b_m(&[0.0, 0.0, 0.0, 0.0]);
    assert!((r - (params().r_pb_b_m + p1 * 0.4)).norm() < 1e-15);
}

/// (P2)'s r′ against a central difference of (P1)'s r along the state's own rates.
#[test]
fn velocity_matches_finite_differences() {
    let mut p = SloshPendulum::new(params(), "slosh_pendulums[0]").unwrap();
    let x = [0.3, 0.2, -0.25, 0.1];
    let mut mp = EffectorMassProps::default();
    p.update_mass_props(&x, &mut mp);
    let h = 1e-6;
    let at = |s: f64| p.r_pcb_b_m(&[x[0] + s * x[1], 0.0, x[2] + s * x[3], 0.0]);
    let fd = (at(h) - at(-h)) / (2.0 * h);
    let r_prime = mp.first_moment_prime_b_kg_m_s / 30.0;
    assert!((fd - r_prime).norm() < 1e-9, "{fd:?} vs {r_prime:?}");
}

#[test]
fn errors_name_the_field() {
    let mut q = params();
    q.theta_rad = 1.5;
    let err = SloshPendulum::new(q, "slosh_pendulums[1]")
        .unwrap_err()
        .to_string();
    assert!(err.contains("slosh_pendulums[1].theta_rad"), "{err}");
    let mut q = params();
    q.l_m = 0.0;
    let err = SloshPendulum::new(q, "slosh_pendulums[1]")
        .unwrap_err()
        .to_string();
    assert!(err.contains("slosh_pendulums[1].l_m"), "{err}");
}
