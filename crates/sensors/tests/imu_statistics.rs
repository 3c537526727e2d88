//! The IMU error model driven directly with a static truth (no dynamics): Allan deviation,
//! Gauss–Markov statistics, white-noise scaling, saturation and quantisation with carried
//! remainders.
//!
//! Allan variance oracles (IEEE Std 952-1997 Annex C; El-Sheimy et al., IEEE TIM 57(1) 2008):
//! - white rate noise of density N:       σ_A²(T) = N² / T
//! - first-order Gauss–Markov, σ and τ:   σ_A²(T) = σ² g(T/τ), g(x) = (2x − 3 + 4e^(−x) − e^(−2x)) / x²
//!   (derived from Var ∫₀ᵀ b = 2σ²τ²(T/τ − 1 + e^(−T/τ)) and σ_A² = (4V(T) − V(2T)) / (2T²));
//!   g peaks at x ≈ 1.893 with g = 0.3811, i.e. σ_A,max = 0.6174 σ;
//! - rate random walk K:                  σ_A²(T) = K² T / 3.
//!
//! Independent terms add in Allan variance, so the configured values are recovered by a
//! weighted linear least-squares fit of those basis functions (τ known) to the overlapping Allan
//! variance of the integrated output Σ Δθ (or Σ Δv), weights ∝ the number of clusters L/T.

use flexdyn_proto::saturation_flags;
use flexdyn_sensors::imu::{AccelErrors, GyroErrors, Imu, ImuConfig, ImuSample, ImuTruth};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

const DEG: f64 = std::f64::consts::PI / 180.0;

fn ideal(seed: u64) -> ImuConfig {
    ImuConfig::ideal("imu", Vector3::zeros(), Matrix3::identity(), seed)
}

/// A static truth over an interval of `dt` s: Earth rate about x, 1 g along −z.
fn static_truth(dt: f64) -> ImuTruth {
    let w = Vector3::new(7.292_115e-5, 0.0, 0.0);
    let f = Vector3::new(0.0, 0.0, -9.806_65);
    ImuTruth {
        omega_p_rad_s: w,
        accel_p_m_s2: f,
        dtheta_p_rad: w * dt,
        dv_p_m_s: f * dt,
    }
}

/// Overlapping Allan variance of the integrated output `x` (x[0] = 0, x[k] = Σ of k increments
/// of `dt` s) at T = m·dt, for m = 1, 2, 4, … ≤ L/8. Returns (T, σ_A²) per axis.
fn allan(x: &[Vector3<f64>], dt: f64) -> Vec<(f64, Vector3<f64>)> {
    let l = x.len() - 1;
    let mut out = Vec::new();
    let mut m = 1;
    while m <= l / 8 {
        let t = m as f64 * dt;
        let mut acc = Vector3::zeros();
        let n = l - 2 * m + 1;
        for k in 0..n {
            let d = x[k + 2 * m] - x[k + m] * 2.0 + x[k];
            acc += d.component_mul(&d);
        }
        out.push((t, acc / (2.0 * t * t * n as f64)));
        m *= 2;
    }
    out
}

fn gm_allan_shape(x: f64) -> f64 {
    (2.0 * x - 3.0 + 4.0 * (-x).exp() - (-2.0 * x).exp()) / (x * x)
}

/// Fits σ_A²(T) ≈ a·f1(T) + b·f2(T) (relative residuals, weights L/T); returns (a, b).
fn fit2(
    points: &[(f64, f64)],
    l_s: f64,
    f1: impl Fn(f64) -> f64,
    f2: impl Fn(f64) -> f64,
) -> (f64, f64) {
    let mut ata = Matrix2::zeros();
    let mut atb = Vector2::zeros();
    for &(t, obs) in points {
        let w = l_s / t;
        let row = Vector2::new(f1(t), f2(t)) / obs;
        ata += row * row.transpose() * w;
        atb += row * w;
    }
    let sol = ata.lu().solve(&atb).expect("well-posed fit");
    (sol[0], sol[1])
}

#[test]
fn validate_allan_deviation_recovers_arw_bias_instability_vrw_and_rrw() {
    // A tactical-grade gyro (the example of docs/models/imu.md): ARW 0.15 °/√h; bias instability 1 °/h read as
    // the Allan floor, i.e. σ_GM = (1 °/h) / 0.6174, τ = 300 s. Accelerometer: VRW 0.05 m/s/√h
    // and an acceleration random walk K = 1e-5 m/s³/√Hz.
    let arw = 0.15 * DEG / 60.0;
    let bi_floor = 1.0 * DEG / 3600.0;
    let sigma_gm = bi_floor / 0.617_364;
    let tau = 300.0;
    let vrw = 0.05 / 60.0;
    let k_rrw = 1e-5;
    let mut cfg = ideal(2024);
    cfg.gyro = GyroErrors {
        arw_rad_s_sqrt_hz: arw,
        bias_instability_sigma_rad_s: sigma_gm,
        bias_instability_tau_s: tau,
        bias_rad_s: Vector3::new(1e-5, -2e-5, 3e-5),
        ..GyroErrors::default()
    };
    cfg.accel = AccelErrors {
        vrw_m_s2_sqrt_hz: vrw,
        rrw_m_s3_sqrt_hz: k_rrw,
        ..AccelErrors::default()
    };
    // dt = 2 s (not 1 s, where N·√dt and N·dt would coincide).
    let dt = 2.0;
    let l = 300_000; // 600 000 s ≈ 1000 clusters at the Gauss–Markov peak T ≈ 570 s
    let mut imu = Imu::new(&cfg, "imus[0]", dt).unwrap();
    let truth = static_truth(dt);
    let mut theta = Vec::with_capacity(l + 1);
    let mut vel = Vec::with_capacity(l + 1);
    theta.push(Vector3::zeros());
    vel.push(Vector3::zeros());
    for k in 0..l {
        let s = imu.sample(&truth, dt);
        // Remove the known truth so the sums stay small (Allan variance is blind to it anyway).
        theta.push(theta[k] + (s.dtheta_p_rad - truth.dtheta_p_rad));
        vel.push(vel[k] + (s.dv_p_m_s - truth.dv_p_m_s));
    }
    let l_s = l as f64 * dt;

    let g = allan(&theta, dt);
    let a = allan(&vel, dt);
    println!("T [s]    gyro σ_A [°/h] (axis 1)   model    accel σ_A [m/s²] (axis 1)   model");
    for ((t, vg), (_, va)) in g.iter().zip(&a) {
        let mg = (arw * arw / t + sigma_gm * sigma_gm * gm_allan_shape(t / tau)).sqrt();
        let ma = (vrw * vrw / t + k_rrw * k_rrw * t / 3.0).sqrt();
        println!(
            "{t:>8.0}  {:>10.4}  {:>10.4}   {:>12.4e}  {:>12.4e}",
            vg[0].sqrt() / DEG * 3600.0,
            mg / DEG * 3600.0,
            va[0].sqrt(),
            ma
        );
    }
    for axis in 0..3 {
        let pts_g: Vec<(f64, f64)> = g.iter().map(|(t, v)| (*t, v[axis])).collect();
        let (n2, s2) = fit2(&pts_g, l_s, |t| 1.0 / t, |t| gm_allan_shape(t / tau));
        let (n_fit, s_fit) = (n2.sqrt(), s2.sqrt());
        let pts_a: Vec<(f64, f64)> = a.iter().map(|(t, v)| (*t, v[axis])).collect();
        let (v2, k2) = fit2(&pts_a, l_s, |t| 1.0 / t, |t| t / 3.0);
        let (v_fit, k_fit) = (v2.sqrt(), k2.sqrt());
        println!(
            "axis {}: ARW {:.4} vs {:.4} °/√h ({:+.2}%); bias instability σ_GM {:.4} vs {:.4} °/h ({:+.2}%), Allan floor 0.6174·σ = {:.4} °/h",
            axis + 1,
            n_fit / DEG * 60.0,
            arw / DEG * 60.0,
            100.0 * (n_fit / arw - 1.0),
            s_fit / DEG * 3600.0,
            sigma_gm / DEG * 3600.0,
            100.0 * (s_fit / sigma_gm - 1.0),
            0.617_364 * s_fit / DEG * 3600.0,
        );
        println!(
            "axis {}: VRW {:.4} vs {:.4} m/s/√h ({:+.2}%); RRW {:.4e} vs {:.4e} m/s³/√Hz ({:+.2}%)",
            axis + 1,
            v_fit * 60.0,
            vrw * 60.0,
            100.0 * (v_fit / vrw - 1.0),
            k_fit,
            k_rrw,
            100.0 * (k_fit / k_rrw - 1.0),
        );
        assert!((n_fit / arw - 1.0).abs() < 0.10, "ARW axis {axis}");
        assert!((s_fit / sigma_gm - 1.0).abs() < 0.10, "σ_GM axis {axis}");
        assert!((v_fit / vrw - 1.0).abs() < 0.10, "VRW axis {axis}");
        assert!((k_fit / k_rrw - 1.0).abs() < 0.10, "RRW axis {axis}");
        // The standard short-τ relation on its own: σ_A(τ0) = N/√τ0.
        let n_short = g[0].1[axis].sqrt() * g[0].0.sqrt();
        assert!(
            (n_short / arw - 1.0).abs() < 0.02,
            "σ_A(τ0)·√τ0 = {n_short:e}"
        );
    }
}

#[test]
fn validate_gauss_markov_bias_variance_and_correlation() {
    // Gauss–Markov only (so the instantaneous output is the bias itself), sampled at dt = τ/10.
    let (sigma_g, tau_g) = (1e-3, 10.0);
    let (sigma_a, tau_a) = (5e-4, 20.0);
    let mut cfg = ideal(77);
    cfg.gyro.bias_instability_sigma_rad_s = sigma_g;
    cfg.gyro.bias_instability_tau_s = tau_g;
    cfg.accel.bias_instability_sigma_m_s2 = sigma_a;
    cfg.accel.bias_instability_tau_s = tau_a;
    let dt = 1.0;
    let n = 300_000;
    let zero = ImuTruth::default();
    let mut imu = Imu::new(&cfg, "imus[0]", dt).unwrap();
    let mut g = Vec::with_capacity(n);
    let mut a = Vec::with_capacity(n);
    for _ in 0..n {
        let s = imu.sample(&zero, dt);
        g.push(s.omega_p_rad_s);
        a.push(s.accel_p_m_s2);
    }
    for (name, x, sigma, tau) in [("gyro", &g, sigma_g, tau_g), ("accel", &a, sigma_a, tau_a)] {
        let lag = (tau / dt) as usize;
        let (mut var, mut cov) = (0.0, 0.0);
        for axis in 0..3 {
            let mean = x.iter().map(|v| v[axis]).sum::<f64>() / n as f64;
            var += x.iter().map(|v| (v[axis] - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
            cov += (0..n - lag)
                .map(|k| (x[k][axis] - mean) * (x[k + lag][axis] - mean))
                .sum::<f64>()
                / (n - lag) as f64;
        }
        var /= 3.0;
        let rho = cov / 3.0 / var;
        // Standard error of the sample variance of an AR(1) sequence with φ = e^(−dt/τ),
        // 3 independent axes: √(2(1 + φ²) / (3n(1 − φ²))).
        let phi = (-dt / tau).exp();
        let se = (2.0 * (1.0 + phi * phi) / (3.0 * n as f64 * (1.0 - phi * phi))).sqrt();
        let ratio = var / (sigma * sigma);
        println!(
            "{name}: sample variance / σ² = {ratio:.4} (standard error {se:.4}); autocorrelation at lag τ = {rho:.4} (expected e^-1 = {:.4})",
            (-1.0f64).exp()
        );
        assert!((ratio - 1.0).abs() < 5.0 * se, "{name}: {ratio}");
        assert!((rho - (-1.0f64).exp()).abs() < 0.02, "{name}: {rho}");
    }
}

#[test]
fn validate_white_noise_scaling_of_rate_and_increment() {
    // Rate output: σ = N/√T_s (T_s = 0.01 s); Δθ over dt = 0.04 s: σ = N·√dt; independent draws.
    let arw = 1e-3;
    let vrw = 2e-3;
    let mut cfg = ideal(5);
    cfg.gyro.arw_rad_s_sqrt_hz = arw;
    cfg.accel.vrw_m_s2_sqrt_hz = vrw;
    let t_s = 0.01;
    let dt = 0.04;
    let mut imu = Imu::new(&cfg, "imus[0]", t_s).unwrap();
    let zero = ImuTruth::default();
    let n = 100_000;
    let (mut s_w, mut s_th, mut s_f, mut s_dv, mut cross) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut m4, mut tail) = (0.0, 0usize);
    for _ in 0..n {
        let s = imu.sample(&zero, dt);
        for i in 0..3 {
            let z = s.omega_p_rad_s[i] / (arw / t_s.sqrt());
            s_w += z * z;
            m4 += z.powi(4);
            tail += usize::from(z.abs() > 3.0);
            let zt = s.dtheta_p_rad[i] / (arw * dt.sqrt());
            s_th += zt * zt;
            cross += z * zt;
            s_f += (s.accel_p_m_s2[i] / (vrw / t_s.sqrt())).powi(2);
            s_dv += (s.dv_p_m_s[i] / (vrw * dt.sqrt())).powi(2);
        }
    }
    let m = (3 * n) as f64;
    let (v_w, v_th, v_f, v_dv) = (s_w / m, s_th / m, s_f / m, s_dv / m);
    let kurt = m4 / m / (v_w * v_w);
    let p_tail = tail as f64 / m;
    println!("normalised variances: rate {v_w:.4}, Δθ {v_th:.4}, f {v_f:.4}, Δv {v_dv:.4}; correlation rate·Δθ {:.4}; kurtosis {kurt:.3}; P(|z| > 3) = {p_tail:.5} (normal 0.00270)", cross / m);
    // Standard error of a normalised variance over 3e5 draws: √(2/3e5) = 0.0026.
    for v in [v_w, v_th, v_f, v_dv] {
        assert!((v - 1.0).abs() < 0.013, "{v}");
    }
    assert!(
        (cross / m).abs() < 0.01,
        "rate and Δθ noise must be independent"
    );
    assert!((kurt - 3.0).abs() < 0.05, "kurtosis {kurt}");
    assert!((p_tail - 0.0027).abs() < 0.0006, "tail {p_tail}");
}

#[test]
fn saturation_clips_each_axis_and_sets_its_flag() {
    let mut cfg = ideal(1);
    cfg.gyro.range_rad_s = 1.0;
    cfg.accel.range_m_s2 = 50.0;
    let dt = 0.01;
    let mut imu = Imu::new(&cfg, "imus[0]", dt).unwrap();
    let inside = ImuTruth {
        omega_p_rad_s: Vector3::new(1.0, -0.5, 0.99),
        accel_p_m_s2: Vector3::new(-50.0, 10.0, 0.0),
        dtheta_p_rad: Vector3::new(0.01, -0.005, 0.0099),
        dv_p_m_s: Vector3::new(-0.5, 0.1, 0.0),
    };
    let s = imu.sample(&inside, dt);
    assert_eq!(s.saturation_flags, 0, "at or inside the range: no flag");
    assert_eq!(s.omega_p_rad_s, inside.omega_p_rad_s);
    assert_eq!(s.dv_p_m_s, inside.dv_p_m_s);

    let gyro_over = ImuTruth {
        omega_p_rad_s: Vector3::new(2.0, -0.5, -3.0),
        dtheta_p_rad: Vector3::new(0.02, -0.005, -0.03),
        ..inside
    };
    let s = imu.sample(&gyro_over, dt);
    assert_eq!(
        s.saturation_flags,
        saturation_flags::GYRO_RATE | saturation_flags::DTHETA
    );
    assert_eq!(s.omega_p_rad_s, Vector3::new(1.0, -0.5, -1.0));
    assert_eq!(s.dtheta_p_rad, Vector3::new(0.01, -0.005, -0.01));
    assert_eq!(s.accel_p_m_s2, inside.accel_p_m_s2);

    // Only the increment over a long interval exceeds range·dt (the instantaneous value does not).
    let dv_over = ImuTruth {
        dv_p_m_s: Vector3::new(0.0, 0.0, 0.6),
        ..inside
    };
    let s = imu.sample(&dv_over, dt);
    assert_eq!(s.saturation_flags, saturation_flags::DV);
    assert_eq!(s.dv_p_m_s, Vector3::new(0.0, 0.0, 0.5));
    let accel_over = ImuTruth {
        accel_p_m_s2: Vector3::new(0.0, -80.0, 0.0),
        ..inside
    };
    let s = imu.sample(&accel_over, dt);
    assert_eq!(s.saturation_flags, saturation_flags::ACCEL);
    assert_eq!(s.accel_p_m_s2, Vector3::new(0.0, -50.0, 0.0));
    assert_eq!(s.saturation_flags & saturation_flags::RESERVED_MASK, 0);
}

#[test]
fn quantisation_rounds_outputs_and_carries_increment_remainders() {
    let lsb_w = 1e-3;
    let lsb_th = 1e-6;
    let lsb_f = 0.01;
    let lsb_dv = 1e-4;
    // The same seed with and without quantisation: every draw is made either way, so the
    // unquantised model gives the exact pre-quantisation values of the quantised one.
    let mut noisy = ideal(99);
    noisy.gyro.arw_rad_s_sqrt_hz = 1e-5;
    noisy.gyro.bias_rad_s = Vector3::new(3.3e-6, 0.0, -1.7e-6);
    noisy.accel.vrw_m_s2_sqrt_hz = 1e-4;
    let mut quant = noisy.clone();
    quant.gyro.lsb_rad_s = lsb_w;
    quant.gyro.dtheta_lsb_rad = lsb_th;
    quant.accel.lsb_m_s2 = lsb_f;
    quant.accel.dv_lsb_m_s = lsb_dv;
    let dt = 0.01;
    let mut q = Imu::new(&quant, "imus[0]", dt).unwrap();
    let mut u = Imu::new(&noisy, "imus[0]", dt).unwrap();
    let (mut sum_q_th, mut sum_u_th) = (Vector3::zeros(), Vector3::zeros());
    let (mut sum_q_dv, mut sum_u_dv) = (Vector3::zeros(), Vector3::zeros());
    let mut worst_th: f64 = 0.0;
    let mut worst_dv: f64 = 0.0;
    let n = 200_000;
    for k in 0..n {
        // A slowly varying truth whose increments are a fraction of an LSB.
        let ph = k as f64 * 1e-3;
        let truth = ImuTruth {
            omega_p_rad_s: Vector3::new(0.0123, -0.0456 * ph.sin(), 0.3),
            accel_p_m_s2: Vector3::new(0.123, 9.8 * ph.cos(), -0.004),
            dtheta_p_rad: Vector3::new(3.7e-7, -2.2e-7 * ph.sin(), 1.31e-6),
            dv_p_m_s: Vector3::new(4.1e-5, 2.7e-5 * ph.cos(), -1e-6),
        };
        let sq: ImuSample = q.sample(&truth, dt);
        let su: ImuSample = u.sample(&truth, dt);
        for i in 0..3 {
            // Instantaneous outputs: the nearest multiple of the LSB, no carry.
            assert_eq!(
                sq.omega_p_rad_s[i],
                lsb_w * (su.omega_p_rad_s[i] / lsb_w).round()
            );
            assert_eq!(
                sq.accel_p_m_s2[i],
                lsb_f * (su.accel_p_m_s2[i] / lsb_f).round()
            );
            // Increments: whole multiples of their LSB.
            let c = sq.dtheta_p_rad[i] / lsb_th;
            assert!((c - c.round()).abs() < 1e-6, "Δθ {c}");
            let c = sq.dv_p_m_s[i] / lsb_dv;
            assert!((c - c.round()).abs() < 1e-6, "Δv {c}");
        }
        sum_q_th += sq.dtheta_p_rad;
        sum_u_th += su.dtheta_p_rad;
        sum_q_dv += sq.dv_p_m_s;
        sum_u_dv += su.dv_p_m_s;
        worst_th = worst_th.max((sum_q_th - sum_u_th).amax() / lsb_th);
        worst_dv = worst_dv.max((sum_q_dv - sum_u_dv).amax() / lsb_dv);
    }
    let (rem_th, rem_dv) = q.remainders();
    println!("after {n} intervals: max |Σ quantised − Σ unquantised| = {worst_th:.6} LSB (Δθ), {worst_dv:.6} LSB (Δv); final remainders {:?} rad, {:?} m/s", rem_th.as_slice(), rem_dv.as_slice());
    // ½ LSB from the rounding, plus the float error of summing 2e5 terms.
    assert!(worst_th <= 0.5 + 1e-6, "{worst_th}");
    assert!(worst_dv <= 0.5 + 1e-6, "{worst_dv}");
    // The running difference is exactly minus the carried remainder.
    assert!(((sum_q_th - sum_u_th) + rem_th).amax() < 1e-6 * lsb_th);
    assert!(((sum_q_dv - sum_u_dv) + rem_dv).amax() < 1e-6 * lsb_dv);
}

#[test]
fn increments_below_one_lsb_are_not_lost() {
    // Without the carry, an increment of 0.3 LSB per interval would always round to 0.
    let mut cfg = ideal(3);
    cfg.gyro.dtheta_lsb_rad = 1.0e-6;
    cfg.accel.dv_lsb_m_s = 1.0e-3;
    let mut imu = Imu::new(&cfg, "imus[0]", 0.01).unwrap();
    let truth = ImuTruth {
        dtheta_p_rad: Vector3::new(0.3e-6, -0.3e-6, 0.0),
        dv_p_m_s: Vector3::new(0.7e-3, 0.0, -0.45e-3),
        ..ImuTruth::default()
    };
    let mut counts = Vector3::zeros();
    let mut dv_counts = Vector3::zeros();
    for _ in 0..1000 {
        let s = imu.sample(&truth, 0.01);
        counts += (s.dtheta_p_rad / 1.0e-6).map(f64::round);
        dv_counts += (s.dv_p_m_s / 1.0e-3).map(f64::round);
    }
    assert_eq!(counts, Vector3::new(300.0, -300.0, 0.0));
    assert_eq!(dv_counts, Vector3::new(700.0, 0.0, -450.0));
}

#[test]
fn scale_factor_misalignment_and_bias_follow_the_measurement_equation() {
    let mut cfg = ideal(11);
    cfg.gyro.scale_factor = Vector3::new(100e-6, -200e-6, 50e-6);
    cfg.gyro.misalignment_rad = Matrix3::new(0.0, 1e-4, -2e-4, 3e-4, 0.0, 5e-5, -1e-4, 2e-4, 0.0);
    cfg.gyro.bias_rad_s = Vector3::new(1e-5, 2e-5, -3e-5);
    cfg.accel.scale_factor = Vector3::new(-300e-6, 0.0, 1e-3);
    cfg.accel.misalignment_rad = Matrix3::new(0.0, -1e-3, 0.0, 0.0, 0.0, 2e-3, 1e-3, 0.0, 0.0);
    cfg.accel.bias_m_s2 = Vector3::new(0.01, -0.02, 0.005);
    let dt = 0.02;
    let mut imu = Imu::new(&cfg, "imus[0]", dt).unwrap();
    let truth = ImuTruth {
        omega_p_rad_s: Vector3::new(0.1, -0.2, 0.3),
        accel_p_m_s2: Vector3::new(1.0, 2.0, -9.8),
        dtheta_p_rad: Vector3::new(0.002, -0.004, 0.006),
        dv_p_m_s: Vector3::new(0.02, 0.04, -0.196),
    };
    let s = imu.sample(&truth, dt);
    let gg = Matrix3::identity()
        + Matrix3::from_diagonal(&cfg.gyro.scale_factor)
        + cfg.gyro.misalignment_rad;
    let ga = Matrix3::identity()
        + Matrix3::from_diagonal(&cfg.accel.scale_factor)
        + cfg.accel.misalignment_rad;
    let close = |a: &Vector3<f64>, b: &Vector3<f64>| (a - b).amax() <= 1e-15 * b.amax();
    assert!(close(
        &s.omega_p_rad_s,
        &(gg * truth.omega_p_rad_s + cfg.gyro.bias_rad_s)
    ));
    assert!(close(
        &s.dtheta_p_rad,
        &(gg * truth.dtheta_p_rad + cfg.gyro.bias_rad_s * dt)
    ));
    assert!(close(
        &s.accel_p_m_s2,
        &(ga * truth.accel_p_m_s2 + cfg.accel.bias_m_s2)
    ));
    assert!(close(
        &s.dv_p_m_s,
        &(ga * truth.dv_p_m_s + cfg.accel.bias_m_s2 * dt)
    ));

    // The sign convention: a +100 ppm scale factor reads 1.0001 × truth.
    let mut sf_only = ideal(11);
    sf_only.gyro.scale_factor = Vector3::new(100e-6, 0.0, 0.0);
    let mut imu = Imu::new(&sf_only, "imus[0]", dt).unwrap();
    let s = imu.sample(&truth, dt);
    assert!((s.omega_p_rad_s[0] - 0.1 * 1.0001).abs() < 1e-17);
    // A misalignment M[0][1] = +1 mrad: axis 1 picks up +1e-3 × the true axis-2 rate.
    let mut mis_only = ideal(11);
    mis_only.gyro.misalignment_rad[(0, 1)] = 1e-3;
    let mut imu = Imu::new(&mis_only, "imus[0]", dt).unwrap();
    let s = imu.sample(&truth, dt);
    assert!((s.omega_p_rad_s[0] - (0.1 + 1e-3 * -0.2)).abs() < 1e-17);
}
