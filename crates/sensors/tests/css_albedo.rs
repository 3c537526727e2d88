//! The coarse sun sensors' Earth albedo (module docs of `coarse_sun_sensor`, "Earth albedo"):
//! (C4)–(C5) through `Sensor::sample`, against the environment's cap computed apart, with the
//! detectors' normals turned by a non-trivial attitude; albedo not gated by the shadow factor;
//! no cap, no change.

use std::f64::consts::FRAC_PI_2;

use flexdyn_dynamics::{HubOutputs, State};
use flexdyn_environment::albedo::{Albedo, AlbedoCap};
use flexdyn_environment::ephemeris::AU_M;
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_sensors::coarse_sun_sensor::{CoarseSunSensor, CoarseSunSensorConfig};
use flexdyn_sensors::{Sensor, Truth};
use nalgebra::Vector3;

const R_M: f64 = 6_378_137.0;

/// The six faces ±x, ±y, ±z of B.
fn faces() -> Vec<Vector3<f64>> {
    vec![
        Vector3::x(),
        -Vector3::x(),
        Vector3::y(),
        -Vector3::y(),
        Vector3::z(),
        -Vector3::z(),
    ]
}

fn css(fov_half_angle_rad: f64) -> CoarseSunSensor {
    CoarseSunSensor::new(
        CoarseSunSensorConfig {
            name: "c".into(),
            normals_b: faces(),
            fov_half_angle_rad,
            scale: 2.5,
            bias: 0.0,
            noise_sigma: 0.0,
            lsb: 0.0,
            every_frames: 1,
            seed: 3,
        },
        "coarse_sun_sensors[0]",
    )
    .unwrap()
}

/// B at 500 km over the sub-solar point's neighbourhood (Sun 40° from the zenith), with an
/// attitude σ that is not the identity.
fn state() -> State {
    State {
        r_bn_n: Vector3::new(R_M + 500e3, 0.0, 0.0),
        v_bn_n: Vector3::zeros(),
        sigma_bn: Vector3::new(0.1, -0.2, 0.3),
        omega_bn_b: Vector3::zeros(),
        effectors: Vec::new(),
    }
}

fn sun_n_hat() -> Vector3<f64> {
    let z = 40f64.to_radians();
    Vector3::new(z.cos(), z.sin(), 0.0)
}

fn cap(state: &State) -> AlbedoCap {
    Albedo {
        coefficient: 0.3,
        earth_radius_m: R_M,
        irradiance_1au_w_m2: 1361.0,
    }
    .cap(&state.r_bn_n, &(sun_n_hat() * AU_M))
    .unwrap()
}

fn sample(css: &mut CoarseSunSensor, state: &State, env: &EnvironmentSample) -> Vec<f64> {
    let hub = HubOutputs::default();
    css.sample(&Truth {
        t_sim_ns: 0,
        state,
        hub: &hub,
        env: Some(env),
        dynamic_effectors: &[],
    });
    css.last().detectors().to_vec()
}

/// (C5): tₖ = scale · cₖ · ν + scale · E(n̂ₖ,N)/S, with n̂ₖ,N = [BN]ᵀ n̂ₖ. The expectation turns
/// each normal into N by the DCM of σ and asks the cap for the detector's sum directly; the
/// direct term is the sensor's own without albedo. In penumbra (ν = 0.4) the direct part
/// scales and the albedo does not; at ν = 0 a detector facing the lit Earth still reads its
/// albedo, and only it.
#[test]
fn albedo_adds_the_caps_irradiance_in_the_output_unit_whatever_the_shadow() {
    let st = state();
    let cap = cap(&st);
    let dcm_bn = mrp_to_dcm(&st.sigma_bn);
    let r_sun_b_n_m = sun_n_hat() * AU_M - st.r_bn_n;
    let mut any_albedo_only = false;
    for nu in [1.0, 0.4, 0.0] {
        let with = EnvironmentSample {
            r_sun_b_n_m,
            shadow_factor: nu,
            albedo: Some(cap),
            ..EnvironmentSample::NONE
        };
        let without = EnvironmentSample {
            albedo: None,
            ..with
        };
        let got = sample(&mut css(FRAC_PI_2), &st, &with);
        let direct = sample(&mut css(FRAC_PI_2), &st, &without);
        for (k, n_b) in faces().iter().enumerate() {
            let n_n = dcm_bn.transpose() * n_b;
            let albedo = 2.5 * cap.irradiance_fraction(&n_n, FRAC_PI_2.cos());
            let want = direct[k] + albedo;
            assert!(
                (got[k] - want).abs() <= 1e-15 * want.abs().max(1.0),
                "ν {nu} detector {k}: {} vs {want}",
                got[k]
            );
            // The nadir-facing side of B sees the lit cap.
            if n_n.dot(&cap.nadir_n) > 0.5 {
                assert!(albedo > 0.1, "ν {nu} detector {k}: albedo {albedo}");
            }
            if nu == 0.0 {
                assert_eq!(direct[k], 0.0);
                any_albedo_only |= got[k] > 0.0;
            }
        }
    }
    assert!(any_albedo_only, "no detector read albedo at ν = 0");
}

/// The field of view applies per element: a 30° cone facing the nadir reads less than a
/// hemisphere facing it, and the same as the cap's sum over the cone.
#[test]
fn field_of_view_cuts_the_cap_per_element() {
    let st = State {
        sigma_bn: Vector3::zeros(),
        ..state()
    };
    let cap = cap(&st);
    let env = EnvironmentSample {
        albedo: Some(cap),
        ..EnvironmentSample::NONE
    };
    // −x of B faces the Earth (B is on +x of N, identity attitude); no Sun: albedo only.
    let wide = sample(&mut css(FRAC_PI_2), &st, &env)[1];
    let narrow = sample(&mut css(30f64.to_radians()), &st, &env)[1];
    assert!(narrow > 0.0 && narrow < wide, "{narrow} vs {wide}");
    let want = 2.5 * cap.irradiance_fraction(&-Vector3::x(), 30f64.to_radians().cos());
    assert_eq!(narrow, want);
}

/// No cap (albedo off, the default): the readings are the direct model's, bit for bit.
#[test]
fn no_cap_no_change() {
    let st = state();
    let r_sun_b_n_m = sun_n_hat() * AU_M - st.r_bn_n;
    let env = EnvironmentSample {
        r_sun_b_n_m,
        shadow_factor: 0.7,
        ..EnvironmentSample::NONE
    };
    let got = sample(&mut css(FRAC_PI_2), &st, &env);
    let s_b = mrp_to_dcm(&st.sigma_bn) * r_sun_b_n_m.normalize();
    for (k, n) in faces().iter().enumerate() {
        let cos = n.dot(&s_b);
        let want = if cos > 0.0 { 2.5 * cos * 0.7 } else { 0.0 };
        assert_eq!(got[k].to_bits(), want.to_bits(), "detector {k}");
    }
}
