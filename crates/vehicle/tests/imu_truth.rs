//! Truth at the sensor with the zero-error model, against analytic results and an independent
//! quadrature: the gyro is ω exactly, the accelerometer at the centre of mass reads 0 (free fall
//! included), a spinning spacecraft gives the analytic centripetal specific force, Δθ is ω·dt for
//! a steady spin, and Δv is the integral of the instantaneous specific force.

use crate::imu_support::*;
use flexdyn_sensors::imu::{sensor_truth, ImuSample};
use flexdyn_vehicle::sim::Simulation;
use nalgebra::{Matrix3, Vector3};

/// Largest |a − b| over the components, relative to max(|b|, floor).
fn rel_err(a: &Vector3<f64>, b: &Vector3<f64>, floor: f64) -> f64 {
    (a - b).amax() / b.amax().max(floor)
}

#[test]
fn validate_gyro_is_omega_exactly_and_accel_is_the_dynamics_truth() {
    // The reference spacecraft: tumbling, panels oscillating, point-mass gravity.
    let mut t = reference_table();
    let dcm = tilted_dcm_pb();
    set_imus(
        &mut t,
        vec![
            imu_table("a", Vector3::new(0.2, 0.1, 1.2), &dcm, 1),
            imu_table("b", Vector3::new(-1.0, 0.5, 0.0), &Matrix3::identity(), 2),
        ],
    );
    let cfg = parse(&t);
    let mut sim = Simulation::new(&cfg).unwrap();
    assert_eq!(sim.imu_names(), ["a", "b"]);
    let mut out: Vec<ImuSample> = Vec::new();
    for frame in 0..50 {
        if frame > 0 {
            sim.step_frame();
        }
        sim.imu_samples_into(&mut out);
        assert_eq!(out.len(), 2);
        let points = sim.imu_points().to_vec();
        let sc = sim.spacecraft_mut();
        let hub = sc.hub_outputs();
        let omega_b = sc.state().omega_bn_b;
        for (i, s) in out.iter().enumerate() {
            let dcm_pb = points[i].dcm_pb;
            let (w_p, f_p) = sensor_truth(&points[i], sc.state(), &hub);
            // Bit-exact: the zero-error model adds nothing.
            assert_eq!(s.omega_p_rad_s, dcm_pb * omega_b, "frame {frame}, imu {i}");
            assert_eq!(s.omega_p_rad_s, w_p);
            assert_eq!(s.accel_p_m_s2, f_p, "frame {frame}, imu {i}");
            assert_eq!(s.saturation_flags, 0);
            if frame == 0 {
                assert_eq!(s.dtheta_p_rad, Vector3::zeros());
                assert_eq!(s.dv_p_m_s, Vector3::zeros());
            } else {
                // Δθ over 10 ms of a 0.087 rad/s tumble is about ω·dt.
                let approx = w_p * 0.01;
                assert!(rel_err(&s.dtheta_p_rad, &approx, 1e-9) < 0.02);
            }
        }
        // The same Δθ in both platforms, rotated by their relative orientation.
        let rel = points[0].dcm_pb * points[1].dcm_pb.transpose();
        assert!(rel_err(&out[0].dtheta_p_rad, &(rel * out[1].dtheta_p_rad), 1e-12) < 1e-12);
    }
}

/// Case 1 of "the accelerometer at the CoM reads 0": a rigid spacecraft (no panels), tumbling
/// about a non-principal axis (so ω̇ ≠ 0), with B away from the CoM, in a point-mass orbit. The
/// CoM of a rigid body is a body-fixed point; with no external force and gravity applied as a
/// uniform field at the CoM, its specific force is zero at every instant. At the sensor the
/// non-zero terms a_B,nongrav, ω̇ × r and ω × (ω × r) must cancel.
#[test]
fn validate_accel_at_com_of_tumbling_rigid_body_in_free_fall_reads_zero() {
    let mut t = reference_table();
    set_no_panels(&mut t);
    let inertia = Matrix3::new(900.0, 30.0, -20.0, 30.0, 800.0, 10.0, -20.0, 10.0, 600.0);
    let r_bcb = [0.3, -0.2, 1.0];
    set_hub(&mut t, 750.0, &inertia, r_bcb);
    set_omega(&mut t, [0.2, -0.1, 0.3]);
    let dcm = tilted_dcm_pb();
    set_imus(
        &mut t,
        vec![
            imu_table("com", Vector3::from(r_bcb), &dcm, 1),
            imu_table("off", Vector3::new(1.3, 0.8, -0.5), &dcm, 2),
        ],
    );
    let mut sim = Simulation::new(&parse(&t)).unwrap();
    let (_, c_b, _) = sim.spacecraft().center_of_mass();
    assert!((c_b - Vector3::from(r_bcb)).amax() < 1e-15);
    let mut out = Vec::new();
    let mut max_com: f64 = 0.0;
    let mut max_off: f64 = 0.0;
    let mut max_dv: f64 = 0.0;
    for frame in 0..200 {
        if frame > 0 {
            sim.step_frame();
        }
        sim.imu_samples_into(&mut out);
        max_com = max_com.max(out[0].accel_p_m_s2.amax());
        max_dv = max_dv.max(out[0].dv_p_m_s.amax());
        max_off = max_off.max(out[1].accel_p_m_s2.amax());
        let hub = sim.spacecraft_mut().hub_outputs();
        assert!(hub.omega_dot_bn_b.amax() > 1e-4, "the test needs ω̇ ≠ 0");
    }
    println!("rigid tumbling, free fall: max |f| at CoM {max_com:e} m/s², off CoM {max_off:e} m/s², max |Δv| at CoM {max_dv:e} m/s");
    // The terms that cancel are ~|ω|²|r| ≈ 0.15 m/s²; gravity (≈ 4 m/s²) never enters f.
    assert!(max_com < 1e-14, "{max_com:e}");
    assert!(max_dv < 1e-16, "{max_dv:e}");
    assert!(
        max_off > 1e-2,
        "off-CoM sensor must read the rotation terms"
    );
}

/// Case 2, with panels: the reference spacecraft with its wings at rest (θ = θ̇ = 0), spinning
/// about the wing axis x̂ in a point-mass orbit. Every panel's CoM lies on the spin axis through
/// the system CoM and x̂ is a principal axis of every panel, so there is no centrifugal load on
/// the hinges: the panels stay at rest relative to the hub (asserted), c′ = c″ = 0, and the
/// hub-fixed point at the system CoM stays the system CoM. Its specific force is therefore zero.
/// A second sensor off the axis reads the analytic centripetal specific force ω × (ω × r_S/C).
#[test]
fn validate_accel_with_panels_at_rest_spinning_about_the_wing_axis() {
    let mut t = reference_table();
    panels_at_rest(&mut t);
    let w = 0.3;
    set_omega(&mut t, [w, 0.0, 0.0]);
    // The CoM of the reference is (0, 0, 1) (hub CoM and both wings at z = 1, symmetric in x).
    let r_off = Vector3::new(0.4, 0.7, -0.3);
    let dcm = tilted_dcm_pb();
    set_imus(
        &mut t,
        vec![
            imu_table("com", Vector3::new(0.0, 0.0, 1.0), &dcm, 1),
            imu_table("off", r_off, &dcm, 2),
        ],
    );
    let mut sim = Simulation::new(&parse(&t)).unwrap();
    let (_, c_b, _) = sim.spacecraft().center_of_mass();
    assert!(
        (c_b - Vector3::new(0.0, 0.0, 1.0)).amax() < 1e-15,
        "{c_b:?}"
    );
    let omega = Vector3::new(w, 0.0, 0.0);
    let expected_off = dcm * omega.cross(&omega.cross(&(r_off - c_b)));
    let mut out = Vec::new();
    for frame in 0..200 {
        if frame > 0 {
            sim.step_frame();
        }
        sim.imu_samples_into(&mut out);
        let x = &sim.spacecraft().state().effectors;
        assert!(x.iter().all(|v| v.abs() < 1e-12), "panels moved: {x:?}");
        assert!(
            out[0].accel_p_m_s2.amax() < 1e-14,
            "{:?}",
            out[0].accel_p_m_s2
        );
        assert!(rel_err(&out[1].accel_p_m_s2, &expected_off, 0.0) < 1e-12);
        if frame > 0 {
            assert!(out[0].dv_p_m_s.amax() < 1e-16);
            assert!(rel_err(&out[1].dv_p_m_s, &(expected_off * 0.01), 0.0) < 1e-12);
        }
    }
}

/// A rigid hub spinning about its principal axis ẑ (through its CoM; B is elsewhere). The
/// accelerometer reads the specific force f = ω × (ω × r_S/C) = −|ω|² r⊥: the structure pushes
/// the sensor toward the spin axis (the centripetal acceleration, sensed as a specific force
/// with the same sign since gravity is absent). In B it is constant, so Δv = f·dt; the attitude
/// turns at constant ω, so Δθ = ω·dt.
#[test]
fn validate_spinning_rigid_body_centripetal_and_increments() {
    let mut t = reference_table();
    set_no_panels(&mut t);
    set_gravity_none(&mut t);
    let r_bcb = Vector3::new(0.1, 0.2, 0.3);
    set_hub(
        &mut t,
        500.0,
        &Matrix3::from_diagonal(&Vector3::new(400.0, 350.0, 300.0)),
        r_bcb.into(),
    );
    let w = 0.5;
    set_omega(&mut t, [0.0, 0.0, w]);
    let r_sb = Vector3::new(1.0, -0.5, 2.0);
    let dcm = tilted_dcm_pb();
    set_imus(&mut t, vec![imu_table("spin", r_sb, &dcm, 7)]);
    let cfg = parse(&t);
    let mut sim = Simulation::new(&cfg).unwrap();
    let omega = Vector3::new(0.0, 0.0, w);
    let r_sc = r_sb - r_bcb;
    let f_b = omega.cross(&omega.cross(&r_sc));
    // The sign: f points from the sensor toward the axis, −|ω|² r⊥.
    let r_perp = Vector3::new(r_sc.x, r_sc.y, 0.0);
    assert!((f_b + r_perp * (w * w)).amax() < 1e-15);
    let f_p = dcm * f_b;
    let dt = cfg.frame_ns as f64 * 1e-9;
    let mut out = Vec::new();
    let mut worst: [f64; 4] = [0.0; 4];
    for frame in 0..300 {
        if frame > 0 {
            sim.step_frame();
        }
        sim.imu_samples_into(&mut out);
        let s = &out[0];
        worst[0] = worst[0].max(rel_err(&s.omega_p_rad_s, &(dcm * omega), 0.0));
        worst[1] = worst[1].max(rel_err(&s.accel_p_m_s2, &f_p, 0.0));
        if frame > 0 {
            worst[2] = worst[2].max(rel_err(&s.dtheta_p_rad, &(dcm * omega * dt), 0.0));
            worst[3] = worst[3].max(rel_err(&s.dv_p_m_s, &(f_p * dt), 0.0));
        }
    }
    println!(
        "spin: relative errors ω {:e}, f {:e}, Δθ {:e}, Δv {:e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    assert!(worst[0] < 1e-14);
    assert!(worst[1] < 1e-12);
    assert!(worst[2] < 1e-10);
    assert!(worst[3] < 1e-12);
}

/// Δv from the RK4 accumulator against an independent quadrature of the instantaneous specific
/// force: composite Simpson over `sensor_truth` at every RK4 step boundary (h = 1 ms), on the
/// reference spacecraft (tumbling, panels oscillating, point-mass gravity) at an off-CoM sensor.
/// Both approximate the same integral to O(h⁴); the bound is 1e-10 relative. The same with RK8,
/// whose stage values reach the IMU through the stage hook and its 13 weights (a wrong weight
/// would be off by the whole stage's share of Δv).
#[test]
fn validate_dv_is_the_integral_of_the_specific_force() {
    for method in ["rk4", "rk8"] {
        dv_matches_simpson(method);
    }
}

fn dv_matches_simpson(method: &str) {
    let mut t = reference_table();
    table_mut(&mut t, "simulation").insert("integrator".into(), toml::Value::String(method.into()));
    let dcm = tilted_dcm_pb();
    set_imus(
        &mut t,
        vec![imu_table("boom", Vector3::new(0.9, -0.4, 2.5), &dcm, 3)],
    );
    let mut sim = Simulation::new(&parse(&t)).unwrap();
    let mut out = Vec::new();
    sim.imu_samples_into(&mut out); // closes the empty interval at t = 0
    let steps = 500; // 0.5 s, an even number of steps
    let h = sim.step_ns() as f64 * 1e-9;
    let mut worst: f64 = 0.0;
    for interval in 0..4 {
        let mut f = Vec::with_capacity(steps + 1);
        for k in 0..=steps {
            if k > 0 {
                sim.step();
            }
            let point = sim.imu_points()[0];
            let sc = sim.spacecraft_mut();
            let hub = sc.hub_outputs();
            f.push(sensor_truth(&point, sc.state(), &hub).1);
        }
        let mut simpson = f[0] + f[steps];
        for (k, fk) in f.iter().enumerate().take(steps).skip(1) {
            simpson += fk * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        simpson *= h / 3.0;
        sim.imu_samples_into(&mut out);
        let e = rel_err(&out[0].dv_p_m_s, &simpson, 0.0);
        println!(
            "{method} interval {interval}: Δv accumulator {:?} m/s, Simpson {:?} m/s, relative difference {e:e}",
            out[0].dv_p_m_s.as_slice(),
            simpson.as_slice()
        );
        worst = worst.max(e);
    }
    assert!(worst <= 1e-10, "{method}: {worst:e}");
}
