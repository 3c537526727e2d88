use nalgebra::{Matrix3, Vector3};

use super::*;
use flexdyn_kernel::attitude::mrp_to_dcm;

fn rod(axis_b: Vector3<f64>, max: f64) -> Magnetorquer {
    Magnetorquer::new(
        MagnetorquerParams {
            name: "mtq_x".into(),
            axis_b,
            r_mb_b_m: Vector3::new(0.5, 0.0, 0.0),
            max_dipole_am2: max,
        },
        "magnetorquers[0]",
    )
    .unwrap()
}

fn stage(sigma_bn: Vector3<f64>) -> StageState {
    StageState {
        t_step_ns: 0,
        dt_stage_s: 0.0,
        r_bn_n_m: Vector3::new(7.0e6, 0.0, 0.0),
        v_bn_n_m_s: Vector3::zeros(),
        sigma_bn,
        dcm_bn: mrp_to_dcm(&sigma_bn),
        omega_bn_b_rad_s: Vector3::zeros(),
        mass_kg: 100.0,
        r_cb_b_m: Vector3::zeros(),
        r_cn_n_m: Vector3::new(7.0e6, 0.0, 0.0),
        inertia_pnt_b_b_kg_m2: Matrix3::identity(),
    }
}

/// τ = m × B with m = μ â and B_B = [BN] B_N, written out component by component (the cross
/// product's determinant form) so the check does not reuse the code under test.
#[test]
fn torque_is_the_dipole_cross_the_field_in_b() {
    let axis = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    let mut m = rod(axis, 50.0);
    m.set_inputs(&[-20.0]);
    let sigma = Vector3::new(0.1, -0.2, 0.3);
    let b_n = Vector3::new(2.0e-5, -1.0e-5, 3.0e-5);
    let env = EnvironmentSample {
        b_field_n_t: b_n,
        ..EnvironmentSample::NONE
    };
    let mut sum = Wrench::ZERO;
    m.add_force_torque(&stage(sigma), &env, &mut sum);
    let b = mrp_to_dcm(&sigma) * b_n;
    let mu = -20.0 * axis;
    let expected = Vector3::new(
        mu.y * b.z - mu.z * b.y,
        mu.z * b.x - mu.x * b.z,
        mu.x * b.y - mu.y * b.x,
    );
    assert!((sum.torque_b_nm - expected).norm() <= 1e-18, "{sum:?}");
    assert_eq!(
        sum.force_b_newton,
        Vector3::zeros(),
        "a uniform field exerts no force"
    );
    // The torque is perpendicular to both the dipole and the field.
    assert!(sum.torque_b_nm.dot(&axis).abs() < 1e-18);
    assert!(sum.torque_b_nm.dot(&b).abs() < 1e-22);
}

#[test]
fn saturation_clips_and_flags_and_the_output_is_the_applied_dipole() {
    let mut m = rod(Vector3::x(), 30.0);
    let mut out = [0.0];
    for (cmd, applied, flags) in [
        (10.0, 10.0, 0),
        (30.0, 30.0, 0),
        (30.5, 30.0, SATURATED),
        (-1e9, -30.0, SATURATED),
        (-29.0, -29.0, 0),
    ] {
        m.set_inputs(&[cmd]);
        assert_eq!(m.outputs(&mut out), flags, "command {cmd}");
        assert_eq!(out[0], applied, "command {cmd}");
        assert_eq!(m.dipole_b_am2(), Vector3::new(applied, 0.0, 0.0));
    }
}

#[test]
fn bad_parameters_name_the_field() {
    let p = MagnetorquerParams {
        name: "m".into(),
        axis_b: Vector3::new(1.0, 1.0, 0.0),
        r_mb_b_m: Vector3::zeros(),
        max_dipole_am2: 1.0,
    };
    let e = Magnetorquer::new(p.clone(), "magnetorquers[2]").unwrap_err();
    assert!(e.to_string().starts_with("magnetorquers[2].axis_b"), "{e}");
    let e = Magnetorquer::new(
        MagnetorquerParams {
            axis_b: Vector3::z(),
            max_dipole_am2: 0.0,
            ..p.clone()
        },
        "magnetorquers[1]",
    )
    .unwrap_err();
    assert!(
        e.to_string().starts_with("magnetorquers[1].max_dipole_am2"),
        "{e}"
    );
    let e = Magnetorquer::new(
        MagnetorquerParams {
            axis_b: Vector3::z(),
            r_mb_b_m: Vector3::new(f64::NAN, 0.0, 0.0),
            ..p
        },
        "magnetorquers[0]",
    )
    .unwrap_err();
    assert!(
        e.to_string().starts_with("magnetorquers[0].r_mb_b_m"),
        "{e}"
    );
}
