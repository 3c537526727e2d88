//! The magnetometer against its documented model (`crates/sensors/src/magnetometer/mod.rs`): a
//! zero-error sensor reads [SB][BN] B_N bit for bit, bias / noise / quantisation are recovered
//! within their standard errors, scale factor, misalignment and saturation act as documented,
//! the stream is reproducible, and configuration errors name the file, the field and the problem.

use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_proto::magnetometer_flags;
use flexdyn_sensors::magnetometer::{Magnetometer, MagnetometerConfig};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::{Matrix3, Vector3};

const LEO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/scenarios/leo_environment.toml"
);

/// S x = B y, S y = −B x, S z = B z: a 90° mounting about z, so a swapped axis shows up.
fn dcm_sb() -> Matrix3<f64> {
    Matrix3::new(0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
}

fn ideal(seed: u64) -> MagnetometerConfig {
    MagnetometerConfig {
        name: "m".into(),
        dcm_sb: dcm_sb(),
        scale_factor: Vector3::zeros(),
        misalignment_rad: Matrix3::zeros(),
        bias_s_t: Vector3::zeros(),
        noise_sigma_t: 0.0,
        range_t: 0.0,
        lsb_t: 0.0,
        every_frames: 1,
        seed,
        r_sb_b_m: None,
    }
}

/// The scenario's magnetometer block replaced by `block`.
fn leo_with(block: &str) -> String {
    let text = std::fs::read_to_string(LEO).unwrap();
    let at = text.find("[[magnetometers]]").unwrap();
    format!("{}{block}", &text[..at])
}

const IDEAL_BLOCK: &str = "[[magnetometers]]\nname = \"ideal\"\n\
    dcm_sb = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]\nrate_hz = 10.0\nseed = 1\n";

/// Zero errors: in the LEO scenario (IGRF-14, tumbling slowly) every update equals
/// [SB]([BN] B_N) computed here from the environment sample and the state, bit for bit, and the
/// field is Earth's (20–60 µT at 500 km).
#[test]
fn zero_error_magnetometer_reads_the_truth_bit_for_bit() {
    let cfg = SimConfig::from_toml_str(&leo_with(IDEAL_BLOCK)).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut checked = 0;
    for tick in 0..60u64 {
        sim.sample_sensors(|s| s.kind().noun == "magnetometer" && s.due(tick));
        if tick % 10 == 0 {
            let b_n_t = sim.spacecraft().environment().b_field_n_t;
            let dcm_bn = mrp_to_dcm(&sim.spacecraft().state().sigma_bn);
            let want = dcm_sb() * (dcm_bn * b_n_t);
            let got = sim.magnetometers()[0].last();
            assert_eq!(
                got.b_s_t.map(f64::to_bits),
                want.map(f64::to_bits),
                "tick {tick}"
            );
            assert_eq!(got.saturation_flags, 0);
            let norm = want.norm();
            assert!((2e-5..6e-5).contains(&norm), "|B| = {norm} T");
            checked += 1;
        }
        sim.step_frame();
    }
    assert_eq!(checked, 6);
}

/// The rods' own field (`r_sb_b_m` given): two rods commanded at tick 0, one on the sensor's
/// axis 2 m away (axial field (μ0/4π) 2m/r³ along the rod) and one 1 m broadside (−(μ0/4π) m/r³
/// along the rod); the reading minus that of the same vehicle with the rods at zero is their sum,
/// in S. Without `r_sb_b_m` the rods change nothing.
#[test]
fn magnetorquer_dipoles_add_their_closed_form_field() {
    let rods = "[[magnetorquers]]\nname = \"axial\"\naxis_b = [0.0, 0.0, 1.0]\n\
        r_mb_b_m = [0.0, 0.0, 1.0]\nmax_dipole_am2 = 400.0\n\n\
        [[magnetorquers]]\nname = \"broadside\"\naxis_b = [1.0, 0.0, 0.0]\n\
        r_mb_b_m = [0.0, -1.0, 3.0]\nmax_dipole_am2 = 400.0\n\n";
    let read = |position: &str, dipoles: [f64; 2]| {
        let text = leo_with(&format!("{rods}{IDEAL_BLOCK}{position}"));
        let cfg = SimConfig::from_toml_str(&text).unwrap();
        let mut sim = Simulation::new(&cfg).unwrap();
        let mut u = sim.effector_inputs().to_vec();
        let n = u.len();
        u[n - 2..].copy_from_slice(&dipoles);
        sim.set_effector_inputs(&u).unwrap();
        sim.sample_sensors(|s| s.kind().noun == "magnetometer");
        sim.magnetometers()[0].last().b_s_t
    };
    let (m_axial, m_broadside) = (100.0, 50.0);
    let at = "r_sb_b_m = [0.0, 0.0, 3.0]\n";
    let rods_on = read(at, [m_axial, m_broadside]);
    let rods_off = read(at, [0.0, 0.0]);
    // μ0/4π = 1e-7 T·m/A: axial 1e-7 · 2 · 100 / 2³ = 2.5 µT along +z; broadside
    // −1e-7 · 50 / 1³ = −5 µT along +x.
    let want_b = Vector3::new(-1e-7 * m_broadside, 0.0, 1e-7 * 2.0 * m_axial / 8.0);
    let want_s = dcm_sb() * want_b;
    let got = rods_on - rods_off;
    assert!(
        (got - want_s).norm() <= 1e-17,
        "rods' field {got:?} T, closed form {want_s:?} T"
    );
    assert!(want_s.norm() > 5e-6);
    // No position: the Earth's field alone, bit for bit.
    let unplaced_on = read("", [m_axial, m_broadside]);
    let unplaced_off = read("", [0.0, 0.0]);
    assert_eq!(
        unplaced_on.map(f64::to_bits),
        unplaced_off.map(f64::to_bits)
    );
    assert_eq!(unplaced_off.map(f64::to_bits), rods_off.map(f64::to_bits));
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, var.sqrt())
}

/// Bias and white noise from 40 000 samples of a fixed field: each axis's mean error is the bias
/// within 5 standard errors (σ/√n), its standard deviation σ within 5 of its standard errors
/// (σ/√(2n), normal data).
#[test]
fn bias_and_noise_statistics() {
    const N: usize = 40_000;
    let sigma = 5e-8;
    let bias = Vector3::new(2e-7, -1e-7, 3e-7);
    let mut m = Magnetometer::new(
        MagnetometerConfig {
            bias_s_t: bias,
            noise_sigma_t: sigma,
            ..ideal(3)
        },
        "magnetometers[0]",
    )
    .unwrap();
    let b_b_t = Vector3::new(2e-5, -3e-5, 1e-5);
    let truth_s = dcm_sb() * b_b_t;
    let mut err = [Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..N {
        let y = m.measure(&b_b_t).b_s_t;
        for i in 0..3 {
            err[i].push(y[i] - truth_s[i]);
        }
    }
    let n = N as f64;
    for i in 0..3 {
        let (mean, std) = mean_std(&err[i]);
        assert!(
            (mean - bias[i]).abs() < 5.0 * sigma / n.sqrt(),
            "axis {i}: mean {mean:e}, bias {:e}",
            bias[i]
        );
        assert!(
            (std - sigma).abs() < 5.0 * sigma / (2.0 * n).sqrt(),
            "axis {i}: std {std:e}, σ {sigma:e}"
        );
    }
}

/// Quantisation: with no noise every output is the nearest multiple of the LSB (error ≤ ½ LSB);
/// with noise of σ = LSB the output variance is σ² + LSB²/12 (Sheppard's correction, exact to
/// < 1e-8 relative for σ = LSB: Widrow & Kollár, "Quantization Noise", 2008, §5), recovered
/// within 5 standard errors.
#[test]
fn quantisation_statistics() {
    let lsb = 1e-7;
    let mut m = Magnetometer::new(
        MagnetometerConfig {
            lsb_t: lsb,
            ..ideal(4)
        },
        "magnetometers[0]",
    )
    .unwrap();
    for k in 0..1000 {
        let b_b_t = Vector3::new(1e-5 + k as f64 * 3.7e-9, -2e-5, 4e-5 - k as f64 * 1.3e-9);
        let y = m.measure(&b_b_t).b_s_t;
        let t = dcm_sb() * b_b_t;
        for i in 0..3 {
            assert_eq!(y[i], (t[i] / lsb).round() * lsb);
            assert!((y[i] - t[i]).abs() <= 0.5 * lsb * (1.0 + 1e-9));
        }
    }
    const N: usize = 40_000;
    let mut m = Magnetometer::new(
        MagnetometerConfig {
            lsb_t: lsb,
            noise_sigma_t: lsb,
            ..ideal(5)
        },
        "magnetometers[0]",
    )
    .unwrap();
    let b_b_t = Vector3::new(1.23e-5, 0.0, 0.0);
    let t = dcm_sb() * b_b_t;
    let err: Vec<f64> = (0..N).map(|_| m.measure(&b_b_t).b_s_t[1] - t[1]).collect();
    let (mean, std) = mean_std(&err);
    let want = (lsb * lsb + lsb * lsb / 12.0).sqrt();
    let n = N as f64;
    assert!(mean.abs() < 5.0 * want / n.sqrt(), "mean {mean:e}");
    assert!(
        (std - want).abs() < 5.0 * want / (2.0 * n).sqrt(),
        "std {std:e}, want {want:e}"
    );
}

/// Scale factor and misalignment: y = (I + diag(s) + M)[SB] B; saturation clips each axis to
/// ± range and sets its bit only.
#[test]
fn scale_misalignment_and_saturation() {
    let s = Vector3::new(1e-3, -2e-3, 5e-4);
    let mis = Matrix3::new(0.0, 1e-3, -2e-3, 3e-3, 0.0, 1e-3, -1e-3, 2e-3, 0.0);
    let mut m = Magnetometer::new(
        MagnetometerConfig {
            scale_factor: s,
            misalignment_rad: mis,
            ..ideal(6)
        },
        "magnetometers[0]",
    )
    .unwrap();
    let b_b_t = Vector3::new(2e-5, -3e-5, 1e-5);
    let want = (Matrix3::identity() + Matrix3::from_diagonal(&s) + mis) * (dcm_sb() * b_b_t);
    let got = m.measure(&b_b_t).b_s_t;
    assert!((got - want).norm() < 1e-18, "{got} vs {want}");

    let mut m = Magnetometer::new(
        MagnetometerConfig {
            range_t: 2.5e-5,
            ..ideal(7)
        },
        "magnetometers[0]",
    )
    .unwrap();
    // S components: (−3e-5, −2e-5, 1e-5): only axis 1 saturates, at −range.
    let out = m.measure(&b_b_t);
    assert_eq!(out.b_s_t, Vector3::new(-2.5e-5, -2e-5, 1e-5));
    assert_eq!(out.saturation_flags, magnetometer_flags::AXIS_1);
}

/// The same seed gives the same bits through the simulation; another seed other noise; the
/// magnetometer updates at 10 Hz on 100 Hz frames.
#[test]
fn scenario_stream_reproduces_bit_for_bit() {
    let run = |seed: u64| {
        let text = std::fs::read_to_string(LEO)
            .unwrap()
            .replace("seed = 31", &format!("seed = {seed}"));
        let cfg = SimConfig::from_toml_str(&text).unwrap();
        let mut sim = Simulation::new(&cfg).unwrap();
        let mut out = Vec::new();
        for tick in 0..40u64 {
            sim.sample_sensors(|s| s.kind().noun == "magnetometer" && s.due(tick));
            if !sim.sensors().sampled().is_empty() {
                out.push((tick, sim.magnetometers()[0].last().b_s_t.map(f64::to_bits)));
            }
            sim.step_frame();
        }
        out
    };
    let a = run(31);
    assert_eq!(
        a.iter().map(|(t, _)| *t).collect::<Vec<_>>(),
        [0, 10, 20, 30]
    );
    assert_eq!(a, run(31));
    assert_ne!(a, run(32));
}

#[test]
fn configuration_errors_name_the_file_field_and_problem() {
    let text = std::fs::read_to_string(LEO).unwrap();
    for (from, to, field, words) in [
        ("rate_hz = 10.0\nseed = 31", "rate_hz = 30.0\nseed = 31", "magnetometers[0].rate_hz", "whole number"),
        ("rate_hz = 10.0\nseed = 31", "rate_hz = -1.0\nseed = 31", "magnetometers[0].rate_hz", "> 0"),
        ("name = \"mag1\"", "name = \"mag/1\"", "magnetometers[0].name", "/"),
        ("noise_sigma_t = 5e-8", "noise_sigma_t = -5e-8", "magnetometers[0].noise_sigma_t", ">= 0"),
        ("lsb_t = 1e-8", "lsb_t = nan", "magnetometers[0].lsb_t", ""),
        (
            "dcm_sb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]",
            "dcm_sb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]",
            "magnetometers[0].dcm_sb",
            "orthonormal",
        ),
        (
            "lsb_t = 1e-8",
            "lsb_t = 1e-8\nmisalignment_rad = [[1e-3, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]",
            "magnetometers[0].misalignment_rad",
            "diagonal must be zero",
        ),
        ("seed = 31", "seed = -31", "magnetometers[0].seed", ""),
        ("lsb_t = 1e-8", "lsb_t = 1e-8\ncolour = 1", "magnetometers[0].colour", "unknown key"),
        (
            "lsb_t = 1e-8",
            "lsb_t = 1e-8\n[[magnetometers]]\nname = \"mag1\"\ndcm_sb = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\nrate_hz = 10.0\nseed = 2",
            "magnetometers[1].name",
            "duplicate magnetometer name",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let e = SimConfig::from_toml_str(&text.replacen(from, to, 1)).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains(field), "{to}: {msg}");
        assert!(msg.contains(words), "{to}: {msg}");
    }
    // Through the command line, the message names the file too.
    let dir = std::env::temp_dir().join(format!("flexdyn-mag-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad_mag.toml");
    std::fs::write(&path, text.replacen("lsb_t = 1e-8", "lsb_t = -1.0", 1)).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .arg("check-config")
        .arg(&path)
        .output()
        .unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        msg.contains("bad_mag.toml: magnetometers[0].lsb_t: must be >= 0 (got -1) (line "),
        "{msg}"
    );
}

/// A datasheet number typed in nT where the key is in T gives a warning that names the field and
/// suggests the unit; the shipped scenario gives none.
#[test]
fn a_unit_slip_is_warned_about() {
    let text = std::fs::read_to_string(LEO).unwrap();
    assert!(SimConfig::from_toml_str(&text)
        .unwrap()
        .warnings()
        .is_empty());
    let cfg =
        SimConfig::from_toml_str(&text.replacen("noise_sigma_t = 5e-8", "noise_sigma_t = 50", 1))
            .unwrap();
    let w: Vec<String> = cfg.warnings().iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("magnetometers[0].noise_sigma_t: 50 T is far above")
            && w[0].contains("50 nT = 5e-8 T"),
        "{w:?}"
    );
}
