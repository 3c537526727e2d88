//! The coarse and fine sun sensors against their documented models
//! (`crates/sensors/src/coarse_sun_sensor/mod.rs`, `crates/sensors/src/fine_sun_sensor/mod.rs`): zero-error
//! sensors read the closed-form truth bit for bit (and agree with independent forms of it), the
//! shadow factor and the field-of-view edges act as documented, bias / noise / quantisation are
//! recovered within their standard errors, two runs give the same bytes, and configuration
//! errors name the file, the field and the problem.

use std::f64::consts::FRAC_PI_2;

use flexdyn_dynamics::spacecraft::HubOutputs;
use flexdyn_environment::EnvironmentSample;
use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_proto::{fss_flags, Header};
use flexdyn_sensors::coarse_sun_sensor::{CoarseSunSensor, CoarseSunSensorConfig};
use flexdyn_sensors::fine_sun_sensor::{FineSunSensor, FineSunSensorConfig};
use flexdyn_sensors::{Sensor, Truth};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::{Matrix3, Vector2, Vector3};

const LEO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/scenarios/leo_environment.toml"
);

fn leo_text() -> String {
    std::fs::read_to_string(LEO).unwrap()
}

/// The scenario with its sun sensors replaced by `blocks`.
fn leo_with(blocks: &str) -> String {
    let text = leo_text();
    let at = text.find("[[coarse_sun_sensors]]").unwrap();
    format!("{}{blocks}", &text[..at])
}

/// Six faces: ±x, ±y, ±z.
fn faces() -> Vec<Vector3<f64>> {
    let mut n = Vec::new();
    for i in 0..3 {
        for sign in [1.0, -1.0] {
            let mut v = Vector3::zeros();
            v[i] = sign;
            n.push(v);
        }
    }
    n
}

fn ideal_css(seed: u64) -> CoarseSunSensorConfig {
    CoarseSunSensorConfig {
        name: "c".into(),
        normals_b: faces(),
        fov_half_angle_rad: FRAC_PI_2,
        scale: 1.0,
        bias: 0.0,
        noise_sigma: 0.0,
        lsb: 0.0,
        every_frames: 1,
        seed,
    }
}

fn ideal_fss(seed: u64) -> FineSunSensorConfig {
    FineSunSensorConfig {
        name: "f".into(),
        dcm_fb: Matrix3::identity(),
        fov_half_angle_rad: 1.0,
        bias_rad: Vector2::zeros(),
        noise_sigma_rad: 0.0,
        lsb_rad: 0.0,
        min_shadow_factor: 0.5,
        every_frames: 1,
        seed,
    }
}

/// The unit Sun direction in B as the test derives it from the environment sample and the
/// attitude: [BN] (r / |r|).
fn sun_b(sim: &Simulation) -> Vector3<f64> {
    let r = sim.spacecraft().environment().r_sun_b_n_m;
    mrp_to_dcm(&sim.spacecraft().state().sigma_bn) * (r / r.norm())
}

/// Zero errors, hemispherical detectors on the six faces, in the LEO scenario (Meeus Sun,
/// conical shadow, tumbling slowly): every update equals scale · (n̂ₖ · ŝ_B) · ν bit for bit,
/// and independently (i) cos θ from θ = atan2(|n̂ × ŝ|, n̂ · ŝ) agrees to 1e-15, (ii) with opposite
/// pairs Σ yₖ n̂ₖ = ν ŝ_B (one face of each pair reads |ŝ_i|, the other 0) to 1e-15.
#[test]
fn zero_error_coarse_array_reads_the_truth_bit_for_bit() {
    let block = "[[coarse_sun_sensors]]\nname = \"ideal\"\nrate_hz = 10.0\nseed = 1\n\
        normals_b = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], \
        [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]\n";
    let cfg = SimConfig::from_toml_str(&leo_with(block)).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut checked = 0;
    for tick in 0..60u64 {
        sim.sample_sensors(|s| s.kind().noun == "coarse sun sensor" && s.due(tick));
        if tick % 10 == 0 {
            let s = sun_b(&sim);
            let shadow = sim.spacecraft().environment().shadow_factor;
            assert_eq!(shadow, 1.0, "the scenario starts in sunlight");
            let got = sim.coarse_sun_sensors()[0].last();
            assert_eq!(got.detector_count, 6);
            assert!(got.readings[6..].iter().all(|&r| r == 0.0));
            let mut sum = Vector3::zeros();
            for (k, n) in faces().iter().enumerate() {
                let cos = n.dot(&s);
                let want = if cos > 0.0 { 1.0 * cos * shadow } else { 0.0 };
                assert_eq!(
                    got.readings[k].to_bits(),
                    want.to_bits(),
                    "tick {tick} k {k}"
                );
                let theta = n.cross(&s).norm().atan2(cos);
                assert!((got.readings[k] - theta.cos().max(0.0)).abs() < 1e-15);
                sum += n * got.readings[k];
            }
            assert!((sum - s * shadow).norm() < 1e-15, "{sum} vs {s}");
            checked += 1;
        }
        sim.step_frame();
    }
    assert_eq!(checked, 6);
}

/// A mounting [FB] whose boresight (row 3) is `s` turned by small angles, so that the Sun is in
/// view with α, β both non-zero.
fn looking_near(s: &Vector3<f64>) -> Matrix3<f64> {
    let tilt = nalgebra::Rotation3::from_euler_angles(0.1, -0.2, 0.0);
    let z = (tilt * s).normalize();
    let x = z.cross(&Vector3::new(0.3, 0.5, 0.8)).normalize();
    let y = z.cross(&x);
    Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()])
}

/// Zero errors, a sensor looking near the Sun: every update is α = atan2(s₁, s₃),
/// β = atan2(s₂, s₃) of s = [FB] ŝ_B bit for bit, VALID | IN_FOV | SUNLIT, and independently the
/// unit vector (tan α, tan β, 1)/‖·‖ rebuilt from the angles is s to 1e-15.
#[test]
fn zero_error_fine_sensor_reads_the_truth_bit_for_bit() {
    let cfg = SimConfig::from_toml_str(&leo_text()).unwrap();
    let s0 = sun_b(&Simulation::new(&cfg).unwrap());
    let dcm_fb = looking_near(&s0);
    let rows: Vec<String> = (0..3)
        .map(|i| {
            let r = dcm_fb.row(i);
            format!("[{:?}, {:?}, {:?}]", r[0], r[1], r[2])
        })
        .collect();
    let block = format!(
        "[[fine_sun_sensors]]\nname = \"ideal\"\nrate_hz = 10.0\nseed = 1\n\
         fov_half_angle_rad = 1.0\ndcm_fb = [{}]\n",
        rows.join(", ")
    );
    let cfg = SimConfig::from_toml_str(&leo_with(&block)).unwrap();
    let dcm_fb = cfg.sensors.all::<FineSunSensorConfig>()[0].dcm_fb;
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut checked = 0;
    for tick in 0..60u64 {
        sim.sample_sensors(|s| s.kind().noun == "fine sun sensor" && s.due(tick));
        if tick % 10 == 0 {
            let s = dcm_fb * sun_b(&sim);
            let got = sim.fine_sun_sensors()[0].last();
            assert_eq!(
                got.flags,
                fss_flags::VALID | fss_flags::IN_FOV | fss_flags::SUNLIT
            );
            assert_eq!(got.alpha_rad.to_bits(), s[0].atan2(s[2]).to_bits());
            assert_eq!(got.beta_rad.to_bits(), s[1].atan2(s[2]).to_bits());
            assert!(got.alpha_rad.abs() > 0.01 && got.beta_rad.abs() > 0.01);
            let v = Vector3::new(got.alpha_rad.tan(), got.beta_rad.tan(), 1.0).normalize();
            assert!((v - s).norm() < 1e-15, "{v} vs {s}");
            checked += 1;
        }
        sim.step_frame();
    }
    assert_eq!(checked, 6);
}

/// The shadow factor comes from the environment sample through `Sensor::sample`: in umbra
/// (ν = 0) every detector reads 0 and the fine sensor is not SUNLIT (angles 0); in penumbra
/// the readings scale by ν, and the fine sensor measures down to its threshold.
#[test]
fn shadow_scales_the_coarse_array_and_invalidates_the_fine_sensor() {
    let cfg = SimConfig::from_toml_str(&leo_text()).unwrap();
    let sim = Simulation::new(&cfg).unwrap();
    let state = sim.spacecraft().state();
    let hub = HubOutputs::default();
    // The Sun along B's (1, 2, 2)/3 (the identity attitude of a state with σ = 0 is not
    // assumed: the direction is set in N through the state's attitude).
    let s_b = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    let r_sun_n = mrp_to_dcm(&state.sigma_bn).transpose() * (s_b * 1.496e11);
    let mut css = CoarseSunSensor::new(
        CoarseSunSensorConfig {
            scale: 2.5,
            ..ideal_css(1)
        },
        "coarse_sun_sensors[0]",
    )
    .unwrap();
    let mut fss = FineSunSensor::new(
        FineSunSensorConfig {
            // Boresight +z_F within 0.25 rad of the Sun: in view.
            dcm_fb: looking_near(&s_b),
            ..ideal_fss(1)
        },
        "fine_sun_sensors[0]",
    )
    .unwrap();
    for (shadow, fss_flags_want) in [
        (0.0, fss_flags::IN_FOV),
        (0.37, fss_flags::IN_FOV),
        (
            0.5,
            fss_flags::IN_FOV | fss_flags::SUNLIT | fss_flags::VALID,
        ),
        (
            1.0,
            fss_flags::IN_FOV | fss_flags::SUNLIT | fss_flags::VALID,
        ),
    ] {
        let env = EnvironmentSample {
            r_sun_b_n_m: r_sun_n,
            shadow_factor: shadow,
            ..EnvironmentSample::NONE
        };
        let truth = Truth {
            t_sim_ns: 0,
            state,
            hub: &hub,
            env: Some(&env),
            dynamic_effectors: &[],
        };
        css.sample(&truth);
        fss.sample(&truth);
        let r = css.last();
        for (k, n) in faces().iter().enumerate() {
            let cos = n.dot(&s_b);
            let want = if cos > 0.0 { 2.5 * cos * shadow } else { 0.0 };
            assert!((r.readings[k] - want).abs() < 1e-14, "ν {shadow} k {k}");
        }
        if shadow == 0.0 {
            assert!(r.readings.iter().all(|&x| x == 0.0));
        }
        let f = fss.last();
        assert_eq!(f.flags, fss_flags_want, "ν {shadow}");
        assert_eq!(f.valid(), shadow >= 0.5);
        if !f.valid() {
            assert_eq!((f.alpha_rad, f.beta_rad), (0.0, 0.0));
        }
    }
    // No Sun at all (no ephemeris): zeros and no flags.
    let env = EnvironmentSample::NONE;
    let truth = Truth {
        t_sim_ns: 0,
        state,
        hub: &hub,
        env: Some(&env),
        dynamic_effectors: &[],
    };
    css.sample(&truth);
    fss.sample(&truth);
    assert!(css.last().readings.iter().all(|&x| x == 0.0));
    assert_eq!(fss.last().flags, 0);
}

/// The Sun at angle θ from the unit direction `axis` (turned towards a perpendicular).
fn at_angle(axis: &Vector3<f64>, theta: f64) -> Vector3<f64> {
    let perp = axis.cross(&Vector3::new(0.0, 0.0, 1.0)).normalize();
    axis * theta.cos() + perp * theta.sin()
}

/// The field-of-view edges: a 60° coarse detector reads cos θ at 59.99° and 0 at 60.01°; a 60°
/// fine sensor is IN_FOV (and valid) at 59.99° and not at 60.01°.
#[test]
fn field_of_view_edges() {
    let fov = 60f64.to_radians();
    let d = 0.01f64.to_radians();
    let n = Vector3::new(1.0, 0.0, 0.0);
    let mut css = CoarseSunSensor::new(
        CoarseSunSensorConfig {
            normals_b: vec![n],
            fov_half_angle_rad: fov,
            ..ideal_css(2)
        },
        "coarse_sun_sensors[0]",
    )
    .unwrap();
    let inside = css.measure(Some((at_angle(&n, fov - d), 1.0)));
    assert!((inside.readings[0] - (fov - d).cos()).abs() < 1e-15);
    assert_eq!(inside.detector_count, 1);
    let outside = css.measure(Some((at_angle(&n, fov + d), 1.0)));
    assert_eq!(outside.readings[0], 0.0);
    // Behind a hemispherical detector: 0, not a negative cosine.
    let mut css = CoarseSunSensor::new(ideal_css(2), "coarse_sun_sensors[0]").unwrap();
    let behind = css.measure(Some((at_angle(&n, 2.0), 1.0)));
    assert_eq!(behind.readings[0], 0.0);
    assert!(behind.readings[1] > 0.4);

    let mut fss = FineSunSensor::new(
        FineSunSensorConfig {
            fov_half_angle_rad: fov,
            ..ideal_fss(3)
        },
        "fine_sun_sensors[0]",
    )
    .unwrap();
    let z = Vector3::new(0.0, 0.0, 1.0);
    // The Sun in the 1–3 plane at θ from the boresight: α = θ, β = 0.
    let s = z * (fov - d).cos() + Vector3::new(1.0, 0.0, 0.0) * (fov - d).sin();
    let f = fss.measure(Some((s, 1.0)));
    assert!(f.valid() && f.flags & fss_flags::IN_FOV != 0);
    assert!((f.alpha_rad - (fov - d)).abs() < 1e-15 && f.beta_rad == 0.0);
    let s = z * (fov + d).cos() + Vector3::new(1.0, 0.0, 0.0) * (fov + d).sin();
    let f = fss.measure(Some((s, 1.0)));
    assert_eq!(f.flags, fss_flags::SUNLIT);
    assert_eq!((f.alpha_rad, f.beta_rad), (0.0, 0.0));
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

/// `|mean − want_mean| < 5 σ/√n` and `|std − want_std| < 5 σ/√(2n)` (normal data).
fn assert_stats(err: &[f64], want_mean: f64, want_std: f64, what: &str) {
    let n = err.len() as f64;
    let (mean, std) = mean_std(err);
    assert!(
        (mean - want_mean).abs() < 5.0 * want_std / n.sqrt(),
        "{what}: mean {mean:e}, want {want_mean:e}"
    );
    assert!(
        (std - want_std).abs() < 5.0 * want_std / (2.0 * n).sqrt(),
        "{what}: std {std:e}, want {want_std:e}"
    );
}

/// Bias and white noise from 40 000 updates of a fixed Sun: each detector's mean error is the
/// bias and its standard deviation σ within 5 standard errors. The Sun is lit on three faces
/// (cos θ = 1/3, 2/3, 2/3) and far from the clip at 0 (σ = 0.005).
#[test]
fn coarse_bias_and_noise_statistics() {
    const N: usize = 40_000;
    let (bias, sigma) = (0.01, 0.005);
    let mut css = CoarseSunSensor::new(
        CoarseSunSensorConfig {
            bias,
            noise_sigma: sigma,
            ..ideal_css(5)
        },
        "coarse_sun_sensors[0]",
    )
    .unwrap();
    let s = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    let mut err = vec![Vec::new(); 6];
    for _ in 0..N {
        let r = css.measure(Some((s, 1.0)));
        for (k, n) in faces().iter().enumerate() {
            err[k].push(r.readings[k] - n.dot(&s).max(0.0));
        }
    }
    for k in [0, 2, 4] {
        assert_stats(&err[k], bias, sigma, &format!("detector {k}"));
    }
    // The dark faces read max(0, bias + σz): bias 2σ, so P(clip) = Φ(−2) = 2.3 %.
    let clipped = err[1].iter().filter(|&&e| e == 0.0).count() as f64 / N as f64;
    assert!((clipped - 0.02275).abs() < 5.0 * (0.02275f64 * 0.977 / N as f64).sqrt());
}

/// Quantisation: with no noise every reading is the nearest multiple of the LSB; with σ = LSB
/// the variance is σ² + LSB²/12 (Sheppard's correction: Widrow & Kollár, "Quantization Noise",
/// 2008, §5), recovered within 5 standard errors. Both sensors.
#[test]
fn quantisation_statistics() {
    let lsb = 0.001;
    let mut css = CoarseSunSensor::new(
        CoarseSunSensorConfig {
            lsb,
            ..ideal_css(6)
        },
        "coarse_sun_sensors[0]",
    )
    .unwrap();
    for k in 0..1000 {
        let s = Vector3::new(0.3 + k as f64 * 3.7e-4, 0.5, 0.6).normalize();
        let r = css.measure(Some((s, 1.0)));
        assert_eq!(r.readings[0], (s[0] / lsb).round() * lsb);
    }
    const N: usize = 40_000;
    let want = (lsb * lsb + lsb * lsb / 12.0).sqrt();
    let mut css = CoarseSunSensor::new(
        CoarseSunSensorConfig {
            lsb,
            noise_sigma: lsb,
            ..ideal_css(7)
        },
        "coarse_sun_sensors[0]",
    )
    .unwrap();
    let s = Vector3::new(0.6123, 0.0, 0.7906).normalize();
    let err: Vec<f64> = (0..N)
        .map(|_| css.measure(Some((s, 1.0))).readings[0] - s[0])
        .collect();
    assert_stats(&err, 0.0, want, "coarse, σ = LSB");

    let lsb: f64 = 1e-4;
    let want = (lsb * lsb + lsb * lsb / 12.0).sqrt();
    let mut fss = FineSunSensor::new(
        FineSunSensorConfig {
            lsb_rad: lsb,
            noise_sigma_rad: lsb,
            ..ideal_fss(8)
        },
        "fine_sun_sensors[0]",
    )
    .unwrap();
    let s: Vector3<f64> = Vector3::new(0.123, -0.234, 1.0).normalize();
    let (a, b) = (s[0].atan2(s[2]), s[1].atan2(s[2]));
    let mut ea = Vec::new();
    let mut eb = Vec::new();
    for _ in 0..N {
        let f = fss.measure(Some((s, 1.0)));
        ea.push(f.alpha_rad - a);
        eb.push(f.beta_rad - b);
    }
    assert_stats(&ea, 0.0, want, "fine α, σ = LSB");
    assert_stats(&eb, 0.0, want, "fine β, σ = LSB");
}

/// The fine sensor's bias and noise per angle, from 40 000 updates.
#[test]
fn fine_bias_and_noise_statistics() {
    const N: usize = 40_000;
    let sigma = 8.7e-4;
    let bias = Vector2::new(1e-4, -5e-5);
    let mut fss = FineSunSensor::new(
        FineSunSensorConfig {
            bias_rad: bias,
            noise_sigma_rad: sigma,
            ..ideal_fss(9)
        },
        "fine_sun_sensors[0]",
    )
    .unwrap();
    let s: Vector3<f64> = Vector3::new(-0.2, 0.3, 1.0).normalize();
    let (a, b) = (s[0].atan2(s[2]), s[1].atan2(s[2]));
    let mut ea = Vec::new();
    let mut eb = Vec::new();
    for _ in 0..N {
        let f = fss.measure(Some((s, 1.0)));
        ea.push(f.alpha_rad - a);
        eb.push(f.beta_rad - b);
    }
    assert_stats(&ea, bias[0], sigma, "α");
    assert_stats(&eb, bias[1], sigma, "β");
}

/// Two runs of the scenario give the same encoded CssMsg and FssMsg bytes at every update (the
/// lockstep server publishes exactly these); another seed gives other noise. Both update at
/// 10 Hz on 100 Hz frames, `seq` counting updates.
#[test]
fn scenario_streams_reproduce_bit_for_bit() {
    let run = |css_seed: u64| {
        let text = leo_text().replace("seed = 41", &format!("seed = {css_seed}"));
        let cfg = SimConfig::from_toml_str(&text).unwrap();
        let mut sim = Simulation::new(&cfg).unwrap();
        let mut out = Vec::new();
        for tick in 0..200u64 {
            sim.sample_sensors(|s| s.kind().noun.ends_with("sun sensor") && s.due(tick));
            for s in sim.sensors().sensors() {
                if s.kind().noun.ends_with("sun sensor") && s.due(tick) {
                    let mut buf = Vec::new();
                    s.encode(Header::new(1, tick, sim.t_sim_ns(), tick), &mut buf);
                    out.push((tick, s.kind().noun, buf));
                }
            }
            sim.step_frame();
        }
        out
    };
    let a = run(41);
    assert_eq!(a.len(), 40);
    assert_eq!(a[2].0, 10);
    let css = flexdyn_proto::decode_css(&a[2].2).unwrap();
    assert_eq!((css.header.seq, css.detector_count), (1, 6));
    assert!(css.readings.iter().any(|&r| r > 0.1));
    assert_eq!(a, run(41));
    let b = run(42);
    assert_ne!(a, b);
    // The fine sensor's stream does not depend on the array's seed.
    let fine = |v: &[(u64, &str, Vec<u8>)]| -> Vec<Vec<u8>> {
        v.iter()
            .filter(|x| x.1 == "fine sun sensor")
            .map(|x| x.2.clone())
            .collect()
    };
    assert_eq!(fine(&a), fine(&b));
}

#[test]
fn configuration_errors_name_the_file_field_and_problem() {
    let text = leo_text();
    let normals = "normals_b = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]";
    let seventeen = format!("normals_b = [{}]", vec!["[1.0, 0.0, 0.0]"; 17].join(", "));
    for (from, to, field, words) in [
        ("rate_hz = 10.0\nseed = 41", "rate_hz = 30.0\nseed = 41", "coarse_sun_sensors[0].rate_hz", "whole number"),
        (normals, "normals_b = []", "coarse_sun_sensors[0].normals_b", "1 to 16 detectors"),
        (normals, &seventeen, "coarse_sun_sensors[0].normals_b", "got 17"),
        (normals, "normals_b = [[1.0, 0.0, 0.1]]", "coarse_sun_sensors[0].normals_b[0]", "unit vector"),
        (normals, "normals_b = [[1.0, 0.0]]", "coarse_sun_sensors[0].normals_b[0]", "3 elements"),
        ("fov_half_angle_rad = 1.3962634015954636", "fov_half_angle_rad = 1.6", "coarse_sun_sensors[0].fov_half_angle_rad", "(0, π/2]"),
        ("scale = 1.0", "scale = 0.0", "coarse_sun_sensors[0].scale", "> 0"),
        ("noise_sigma = 0.005", "noise_sigma = -0.005", "coarse_sun_sensors[0].noise_sigma", ">= 0"),
        ("lsb = 0.001", "lsb = 0.001\ncolour = 1", "coarse_sun_sensors[0].colour", "unknown key"),
        ("name = \"css\"", "name = \"c/ss\"", "coarse_sun_sensors[0].name", "/"),
        (
            "lsb = 0.001",
            "lsb = 0.001\n[[coarse_sun_sensors]]\nname = \"css\"\nnormals_b = [[1.0, 0.0, 0.0]]\nrate_hz = 10.0\nseed = 2",
            "coarse_sun_sensors[1].name",
            "duplicate coarse sun sensor name",
        ),
        (
            "dcm_fb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]",
            "dcm_fb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]",
            "fine_sun_sensors[0].dcm_fb",
            "orthonormal",
        ),
        ("fov_half_angle_rad = 1.0471975511965976", "fov_half_angle_rad = 1.5707963267948966", "fine_sun_sensors[0].fov_half_angle_rad", "(0, π/2)"),
        ("bias_rad = [1.0e-4, -5.0e-5]", "bias_rad = [1.0e-4]", "fine_sun_sensors[0].bias_rad", "2 elements"),
        ("noise_sigma_rad = 8.7e-4", "noise_sigma_rad = nan", "fine_sun_sensors[0].noise_sigma_rad", ""),
        ("min_shadow_factor = 0.5", "min_shadow_factor = 0.0", "fine_sun_sensors[0].min_shadow_factor", "(0, 1]"),
        ("seed = 43", "seed = -43", "fine_sun_sensors[0].seed", ""),
        ("rate_hz = 10.0\nseed = 43", "seed = 43", "fine_sun_sensors[0].rate_hz", ""),
    ] {
        assert!(text.contains(from), "{from}");
        let e = SimConfig::from_toml_str(&text.replacen(from, to, 1)).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains(field), "{to}: {msg}");
        assert!(msg.contains(words), "{to}: {msg}");
    }
    // Through the command line, the message names the file too.
    let dir = std::env::temp_dir().join(format!("flexdyn-sun-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad_sun.toml");
    std::fs::write(
        &path,
        text.replacen("lsb_rad = 1.0e-4", "lsb_rad = -1.0", 1),
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .arg("check-config")
        .arg(&path)
        .output()
        .unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        msg.contains("bad_sun.toml: fine_sun_sensors[0].lsb_rad: must be >= 0 (got -1) (line "),
        "{msg}"
    );
}
