//! The GPS receiver against its documented model (`crates/sensors/src/gps/mod.rs`): a zero-error
//! receiver reads the truth bit for bit (N from the state, ECEF through the environment's Earth
//! rotation) and its velocities are the time derivatives of its positions; ECEF and N agree
//! through the documented rotation, whose angle matches an independent sidereal time; the GPS
//! week and seconds of week match values derived by hand and hifitime's; bias and white noise are
//! recovered within their standard errors; rate, latency and the fix flag act as documented; two
//! runs give the same bytes; configuration errors name the file, the field and the problem; and
//! `flexdyn plot` draws the receiver through the generic sensor loop.

use flexdyn_dynamics::spacecraft::{HubOutputs, State};
use flexdyn_environment::earth_rotation::{EarthFrame, EarthOrientationModel, EarthRotation};
use flexdyn_environment::epoch::SimEpoch;
use flexdyn_proto::{decode_gps, gps_flags, Header};
use flexdyn_sensors::gps::{Gps, GpsConfig, GpsSample};
use flexdyn_sensors::{Sensor, Truth};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::Vector3;

const LEO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/scenarios/leo_environment.toml"
);

fn leo_text() -> String {
    std::fs::read_to_string(LEO).unwrap()
}

/// The LEO scenario (epoch 2026-11-24T06:00:00Z, every environment model on) with its GPS
/// receiver replaced by `blocks`.
fn leo_with(blocks: &str) -> String {
    let text = leo_text();
    let at = text.find("[[gps_receivers]]").unwrap();
    format!("{}{blocks}", &text[..at])
}

fn is_gps(s: &dyn Sensor) -> bool {
    s.kind().noun == "GPS receiver"
}

/// The documented Earth-fixed frame at `t_ns` (`[EN]` and ω_E/N of the environment).
fn earth_frame(epoch: &SimEpoch, t_ns: u64) -> EarthFrame {
    EarthRotation::new(epoch.earth_orientation()).at(&epoch.times(t_ns))
}

fn bits(v: &Vector3<f64>) -> [u64; 3] {
    v.map(f64::to_bits).into()
}

const BOTH: u8 = gps_flags::FIX | gps_flags::ECEF | gps_flags::INERTIAL;

/// Zero errors, every frame, both frames of output, in the LEO scenario: each solution's N
/// fields are the state's r_BN, v_BN bit for bit, its ECEF fields [EN] r_BN and
/// [EN](v_BN − ω × r_BN) of the environment's Earth rotation bit for bit. Independently:
/// |r_E| = |r_N| (a rotation), and each velocity is the central difference of its positions
/// over ±10 ms. The difference's truncation error is h²/6 · |d³r/dt³| ≈ 2e-7 m/s (h = 0.01 s,
/// |d³r/dt³| ≈ ω³ r ≈ 1e-2 m/s³); the ECEF velocity also leaves out the rate of the
/// precession-nutation of the pole (≤ 8e-12 rad/s × 6.9e6 m ≈ 6e-5 m/s), hence the 2e-4 m/s
/// bound. A wrong sign of ω × r would be off by 2 × 500 m/s.
#[test]
fn zero_error_receiver_reads_the_truth_bit_for_bit() {
    let block =
        "[[gps_receivers]]\nname = \"ideal\"\nrate_hz = 100.0\nseed = 1\nframes = \"both\"\n";
    let cfg = SimConfig::from_toml_str(&leo_with(block)).unwrap();
    let epoch = cfg.epoch.clone().unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut samples: Vec<GpsSample> = Vec::new();
    for tick in 0..200u64 {
        sim.sample_sensors(|s| is_gps(s) && s.due(tick));
        assert_eq!(sim.sensors().sampled().len(), 1, "tick {tick}");
        let got = sim.gps_receivers()[0].last();
        let (t, x) = (sim.t_sim_ns(), sim.spacecraft().state());
        assert_eq!((got.valid_sim_time_ns, got.flags), (t, BOTH));
        assert_eq!(bits(&got.r_bn_n_m), bits(&x.r_bn_n));
        assert_eq!(bits(&got.v_bn_n_m_s), bits(&x.v_bn_n));
        let frame = earth_frame(&epoch, t);
        assert_eq!(bits(&got.r_be_e_m), bits(&(frame.dcm_en * x.r_bn_n)));
        let v_rel = x.v_bn_n - frame.omega_en_n_rad_s.cross(&x.r_bn_n);
        assert_eq!(bits(&got.v_be_e_m_s), bits(&(frame.dcm_en * v_rel)));
        assert!((got.r_be_e_m.norm() - x.r_bn_n.norm()).abs() < 1e-7);
        samples.push(got);
        sim.step_frame();
    }
    let h_s = 0.01;
    let (mut worst_e, mut worst_n) = (0.0f64, 0.0f64);
    for w in samples.windows(3) {
        let fd_e = (w[2].r_be_e_m - w[0].r_be_e_m) / (2.0 * h_s);
        let fd_n = (w[2].r_bn_n_m - w[0].r_bn_n_m) / (2.0 * h_s);
        worst_e = worst_e.max((fd_e - w[1].v_be_e_m_s).norm());
        worst_n = worst_n.max((fd_n - w[1].v_bn_n_m_s).norm());
    }
    eprintln!("|Δr/Δt − v|: ECEF {worst_e:.2e} m/s, N {worst_n:.2e} m/s");
    assert!(worst_e < 2e-4, "ECEF {worst_e}");
    assert!(worst_n < 1e-5, "N {worst_n}");
    // The ECEF velocity is the velocity relative to the rotating Earth: it differs from the
    // inertial one (rotated to E) by the Earth's surface speed at B, ω_E r cos φ (φ the
    // latitude; ≈ 170 m/s at the start, near 70° S), with ω_E = 7.292115e-5 rad/s (WGS 84).
    let s = samples[0];
    let frame = earth_frame(&epoch, 0);
    let r = s.r_be_e_m;
    let cos_phi = r.xy().norm() / r.norm();
    let surface = (frame.dcm_en * s.v_bn_n_m_s - s.v_be_e_m_s).norm();
    eprintln!("surface speed {surface:.3} m/s");
    assert!(surface > 100.0);
    assert!((surface - 7.292_115e-5 * r.norm() * cos_phi).abs() < 1e-5 * surface);
}

/// The LEO scenario's epoch and a receiver built for it from `cfg`.
fn receiver(cfg: GpsConfig) -> (SimEpoch, Gps) {
    let leo = SimConfig::from_toml_str(&leo_text()).unwrap();
    let epoch = leo.epoch.clone().unwrap();
    let gps = Gps::new(
        cfg,
        "gps_receivers[0]",
        leo.frame_ns,
        Some(&epoch),
        EarthOrientationModel::Iau2006,
    )
    .unwrap();
    (epoch, gps)
}

fn ideal(seed: u64) -> GpsConfig {
    GpsConfig {
        name: "g".into(),
        every_frames: 1,
        latency_frames: 0,
        ecef: true,
        inertial: true,
        acquisition_ns: 0,
        outage_ns: None,
        position_sigma_m: 0.0,
        velocity_sigma_m_s: 0.0,
        position_bias_e_m: Vector3::zeros(),
        velocity_bias_e_m_s: Vector3::zeros(),
        seed,
    }
}

/// A state on the equator of N at 7,000 km (right ascension 0, declination 0), moving east.
fn equatorial_state() -> State {
    State {
        r_bn_n: Vector3::new(7.0e6, 0.0, 0.0),
        v_bn_n: Vector3::new(0.0, 7.5e3, 0.0),
        sigma_bn: Vector3::zeros(),
        omega_bn_b: Vector3::zeros(),
        effectors: Vec::new(),
    }
}

fn measure(gps: &mut Gps, t_sim_ns: u64, state: &State) -> GpsSample {
    let hub = HubOutputs::default();
    gps.measure(&Truth {
        t_sim_ns,
        state,
        hub: &hub,
        env: None,
        dynamic_effectors: &[],
    })
}

/// With errors, the N fields are the ECEF solution carried to N through the documented rotation:
/// r̃_N = [EN]ᵀ r̃_E and ṽ_N = [EN]ᵀ ṽ_E + ω × r̃_N (to rounding). And the rotation's angle is the
/// sidereal time: for the point at right ascension 0 on the equator, α − λ_E = GAST − m·t, with
/// - GMST (IAU 1982, Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., eq.
///   3-47): 67,310.54841 s + (876,600 h + 8,640,184.812866 s) T + 0.093104 s T² − 6.2e-6 s T³,
///   T = D_UT1 / 36,525, where D_UT1 = JD_UT1 − 2,451,545.0 for 2026-11-24T06:00:00 UTC + 0.05 s
///   (UT1 − UTC of the scenario): 2000-01-01T12:00 → 2026-01-01T12:00 is 26 · 365 + 7 leap
///   days (2000, 2004, …, 2024) = 9,497 d; → 2026-11-24T06:00 another 327 − 0.25 = 326.75 d
///   (Jan–Oct: 304 d, then 23); D = 9,823.75 d + 0.05 s;
/// - m·t the precession of the equinox in right ascension since J2000 (Lieske et al. 1977,
///   m = 4,612.4362″ per Julian century): 4,612.4362″ · T ≈ 1,239″ ≈ 0.344°;
/// - GAST − GMST, the equation of the equinoxes, |·| < 1.2 s of time (0.005°), polar motion
///   (0.4″) and the GCRS frame bias (0.02″) are inside the 0.01° bound. A rotation the wrong way
///   round or by ERA alone (no precession) is off by ≥ 0.34°.
#[test]
fn ecef_and_n_agree_through_the_earth_rotation() {
    let (epoch, mut noisy) = receiver(GpsConfig {
        position_sigma_m: 5.0,
        velocity_sigma_m_s: 0.1,
        position_bias_e_m: Vector3::new(1.0, -2.0, 3.0),
        velocity_bias_e_m_s: Vector3::new(0.01, 0.02, -0.03),
        ..ideal(7)
    });
    let x = equatorial_state();
    for k in 0..100u64 {
        let t = k * 10_000_000;
        let s = measure(&mut noisy, t, &x);
        let f = earth_frame(&epoch, t);
        let r_n = f.dcm_en.tr_mul(&s.r_be_e_m);
        let v_n = f.dcm_en.tr_mul(&s.v_be_e_m_s) + f.omega_en_n_rad_s.cross(&r_n);
        assert!(
            (r_n - s.r_bn_n_m).norm() < 1e-8,
            "{}",
            (r_n - s.r_bn_n_m).norm()
        );
        assert!((v_n - s.v_bn_n_m_s).norm() < 1e-9);
        assert!((s.r_bn_n_m - x.r_bn_n).norm() > 0.0);
    }
    // The sidereal angle at t = 0.
    let (_, mut g) = receiver(ideal(1));
    let s = measure(&mut g, 0, &x);
    let lambda_e = s.r_be_e_m[1].atan2(s.r_be_e_m[0]);
    let d_ut1: f64 = 9_823.75 + 0.05 / 86_400.0;
    let t_c = d_ut1 / 36_525.0;
    let gmst_s: f64 =
        67_310.548_41 + (876_600.0 * 3_600.0 + 8_640_184.812_866) * t_c + 0.093_104 * t_c * t_c
            - 6.2e-6 * t_c.powi(3);
    let gmst_deg = (gmst_s / 240.0).rem_euclid(360.0);
    let m_t_deg = 4_612.436_2 * t_c / 3_600.0;
    let got_deg = (-lambda_e).to_degrees().rem_euclid(360.0);
    let want_deg = (gmst_deg - m_t_deg).rem_euclid(360.0);
    eprintln!("α − λ_E = {got_deg:.5}°, GMST82 − m·t = {want_deg:.5}° (GMST82 {gmst_deg:.5}°, m·t {m_t_deg:.5}°)");
    assert!((got_deg - want_deg).abs() < 0.01, "{got_deg} vs {want_deg}");
    // The pole: the equatorial point stays within precession-nutation (< 0.2°) of E's equator.
    assert!((s.r_be_e_m[2] / 7.0e6).asin().to_degrees().abs() < 0.2);
}

/// GPS week and seconds of week, derived by hand: 2026-11-24 is 17,124 days after 1980-01-06
/// (1980-01-06 → 2026-01-06: 46 · 365 + 12 leap days (1980, 1984, …, 2024) = 16,802 d;
/// 2026-01-06 → 2026-11-24: 25 + 28 + 31 + 30 + 31 + 30 + 31 + 31 + 30 + 31 (Jan 6 to Oct 31) + 24
/// = 322 d), i.e. 2,446 weeks and 2 days: Tuesday of week 2446. GPS − UTC = ΔAT − 19 s = 37 − 19
/// = 18 s (IS-GPS-200 §3.3.4; ΔAT = 37 s since 2017-01-01), so 06:00:00 UTC is GPS seconds of
/// week 2 · 86,400 + 6 · 3,600 + 18 = 194,418 s. hifitime (a GPST epoch's time of week) must
/// agree. Across the week boundary: with the epoch at 2026-11-21T23:59:41Z (Saturday) GPS time
/// is 23:59:59, week 2445 and 604,799 s; one second later week 2446 starts at 0 s.
#[test]
fn week_and_seconds_of_week_match_the_hand_derivation_and_hifitime() {
    let block = "[[gps_receivers]]\nname = \"g\"\nrate_hz = 10.0\nseed = 1\n";
    let cfg = SimConfig::from_toml_str(&leo_with(block)).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    sim.sample_sensors(|s| is_gps(s) && s.due(0));
    let s = sim.gps_receivers()[0].last();
    assert_eq!((s.gps_week, s.gps_seconds_of_week), (2446, 194_418.0));
    let hf = hifitime::Epoch::from_gregorian_utc_hms(2026, 11, 24, 6, 0, 0)
        .to_time_scale(hifitime::TimeScale::GPST)
        .to_time_of_week();
    assert_eq!(hf, (2446, 194_418_000_000_000));

    let text = leo_with(block).replace(
        "utc = \"2026-11-24T06:00:00Z\"",
        "utc = \"2026-11-21T23:59:41Z\"",
    );
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut got = Vec::new();
    for tick in 0..=100u64 {
        sim.sample_sensors(|s| is_gps(s) && s.due(tick));
        if tick % 50 == 0 {
            let s = sim.gps_receivers()[0].last();
            got.push((s.gps_week, s.gps_seconds_of_week));
        }
        sim.step_frame();
    }
    assert_eq!(
        got,
        [(2445, 604_799.0), (2445, 604_799.5), (2446, 0.0)],
        "t = 0, 0.5, 1 s"
    );
    let hf = hifitime::Epoch::from_gregorian_utc_hms(2026, 11, 21, 23, 59, 41)
        .to_time_scale(hifitime::TimeScale::GPST)
        .to_time_of_week();
    assert_eq!(hf, (2445, 604_799_000_000_000));
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
    eprintln!("{what}: mean {mean:.4e} (want {want_mean:e}), std {std:.4e} (want {want_std:e})");
    assert!(
        (mean - want_mean).abs() < 5.0 * want_std / n.sqrt(),
        "{what}: mean {mean:e}, want {want_mean:e}"
    );
    assert!(
        (std - want_std).abs() < 5.0 * want_std / (2.0 * n).sqrt(),
        "{what}: std {std:e}, want {want_std:e}"
    );
}

/// Bias and white noise from 40,000 solutions of one truth: per ECEF axis the mean error is the
/// bias and its standard deviation σ within 5 standard errors; the axes are uncorrelated
/// (|ρ| < 5/√n); the same seed gives the same stream and another seed another.
#[test]
fn bias_and_noise_statistics() {
    const N: usize = 40_000;
    let (sigma_r, sigma_v) = (3.0, 0.05);
    let (bias_r, bias_v) = (Vector3::new(0.5, -0.3, 0.8), Vector3::new(0.01, 0.0, -0.02));
    let cfg = GpsConfig {
        position_sigma_m: sigma_r,
        velocity_sigma_m_s: sigma_v,
        position_bias_e_m: bias_r,
        velocity_bias_e_m_s: bias_v,
        ..ideal(51)
    };
    let (_, mut gps) = receiver(cfg.clone());
    let (_, mut twin) = receiver(cfg.clone());
    let (_, mut other) = receiver(GpsConfig { seed: 52, ..cfg });
    let (_, mut truth) = receiver(ideal(1));
    let x = equatorial_state();
    let t = 1_000_000_000;
    let want = measure(&mut truth, t, &x);
    let mut dr = vec![Vec::new(); 3];
    let mut dv = vec![Vec::new(); 3];
    let mut same_as_other = 0;
    for _ in 0..N {
        let s = measure(&mut gps, t, &x);
        assert_eq!(s, measure(&mut twin, t, &x));
        if s == measure(&mut other, t, &x) {
            same_as_other += 1;
        }
        for i in 0..3 {
            dr[i].push(s.r_be_e_m[i] - want.r_be_e_m[i]);
            dv[i].push(s.v_be_e_m_s[i] - want.v_be_e_m_s[i]);
        }
    }
    assert_eq!(same_as_other, 0);
    for i in 0..3 {
        assert_stats(&dr[i], bias_r[i], sigma_r, &format!("position axis {i}"));
        assert_stats(&dv[i], bias_v[i], sigma_v, &format!("velocity axis {i}"));
    }
    let (m0, s0) = mean_std(&dr[0]);
    let (m1, s1) = mean_std(&dr[1]);
    let rho = dr[0]
        .iter()
        .zip(&dr[1])
        .map(|(a, b)| (a - m0) * (b - m1))
        .sum::<f64>()
        / ((N - 1) as f64 * s0 * s1);
    assert!(rho.abs() < 5.0 / (N as f64).sqrt(), "ρ = {rho}");
}

/// Three receivers at 10 Hz on 100 Hz frames in the LEO scenario: `now` (no latency), `late`
/// (0.3 s: 30 frames, three periods) and `odd` (0.15 s: 15 frames, not a whole period). A
/// receiver with latency L publishes at the ticks L + 10k, and its message there is `now`'s
/// message of tick 10k (the truth of L earlier) with the publication header: same bytes after
/// the header, `valid_sim_time_ns` = `sim_time_ns` − L, `seq` = k. No message before L.
#[test]
fn rate_and_latency() {
    let blocks = "[[gps_receivers]]\nname = \"now\"\nrate_hz = 10.0\nseed = 1\nframes = \"both\"\n\
        [[gps_receivers]]\nname = \"late\"\nrate_hz = 10.0\nseed = 1\nframes = \"both\"\nlatency_s = 0.3\n\
        [[gps_receivers]]\nname = \"odd\"\nrate_hz = 10.0\nseed = 1\nframes = \"both\"\nlatency_s = 0.15\n";
    let cfg = SimConfig::from_toml_str(&leo_with(blocks)).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut published: Vec<(u64, String, Vec<u8>)> = Vec::new();
    for tick in 0..120u64 {
        sim.sample_sensors(|s| is_gps(s) && s.due(tick));
        let bank = sim.sensors();
        for &i in bank.sampled() {
            let s = &bank.sensors()[i];
            let mut buf = Vec::new();
            s.encode(Header::new(1, tick, sim.t_sim_ns(), tick), &mut buf);
            published.push((tick, s.name().to_string(), buf));
        }
        sim.step_frame();
    }
    let of = |name: &str| -> Vec<(u64, Vec<u8>)> {
        published
            .iter()
            .filter(|p| p.1 == name)
            .map(|p| (p.0, p.2.clone()))
            .collect()
    };
    let now = of("now");
    assert_eq!(
        now.iter().map(|p| p.0).collect::<Vec<_>>(),
        (0..12).map(|k| 10 * k).collect::<Vec<_>>()
    );
    for (name, latency_frames) in [("late", 30u64), ("odd", 15)] {
        let msgs = of(name);
        let ticks: Vec<u64> = msgs.iter().map(|p| p.0).collect();
        let want: Vec<u64> = (0..)
            .map(|k| latency_frames + 10 * k)
            .take_while(|&t| t < 120)
            .collect();
        assert_eq!(ticks, want, "{name}");
        for (k, (tick, bytes)) in msgs.iter().enumerate() {
            let m = decode_gps(bytes).unwrap();
            let earlier = decode_gps(&now[k].1).unwrap();
            assert_eq!(m.header.tick, *tick);
            assert_eq!(m.header.seq, k as u64, "{name}");
            assert_eq!(
                m.valid_sim_time_ns,
                m.header.sim_time_ns - latency_frames * 10_000_000
            );
            assert_eq!(m.valid_sim_time_ns, earlier.header.sim_time_ns);
            assert_eq!(bytes[30..], now[k].1[30..], "{name} message {k}");
            assert_eq!(m.flags, BOTH);
        }
    }
}

/// No fix before `acquisition_s`, within `outage_s` and without an `[epoch]`: flags without FIX
/// (the configured frame bits stay) and every number 0, the valid time still set.
#[test]
fn fix_flag_acquisition_outage_and_no_epoch() {
    let block = "[[gps_receivers]]\nname = \"g\"\nrate_hz = 10.0\nseed = 1\n\
        acquisition_s = 0.5\noutage_s = [1.0, 1.5]\nposition_sigma_m = 1.0\n";
    let cfg = SimConfig::from_toml_str(&leo_with(block)).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut fixes = Vec::new();
    for tick in 0..200u64 {
        sim.sample_sensors(|s| is_gps(s) && s.due(tick));
        if tick % 10 == 0 {
            let s = sim.gps_receivers()[0].last();
            assert_eq!(s.valid_sim_time_ns, sim.t_sim_ns());
            assert_eq!(
                s.flags & !gps_flags::FIX,
                gps_flags::ECEF,
                "ECEF only by default"
            );
            if !s.fix() {
                assert_eq!(
                    s,
                    GpsSample {
                        valid_sim_time_ns: s.valid_sim_time_ns,
                        flags: s.flags,
                        ..GpsSample::default()
                    }
                );
            } else {
                assert!(s.r_be_e_m.norm() > 6.0e6 && s.r_bn_n_m == Vector3::zeros());
            }
            fixes.push(s.fix());
        }
        sim.step_frame();
    }
    let want: Vec<bool> = (0..20).map(|k| (5..10).contains(&k) || k >= 15).collect();
    assert_eq!(fixes, want);

    // The reference scenario has no [epoch]: no GPS time, no Earth rotation, no fix.
    let reference = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/reference.toml"
    ))
    .unwrap();
    assert!(!reference.contains("[epoch]"));
    let cfg = SimConfig::from_toml_str(&format!(
        "{reference}\n[[gps_receivers]]\nname = \"g\"\nrate_hz = 10.0\nseed = 1\nframes = \"n\"\n"
    ))
    .unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    for tick in 0..30u64 {
        sim.sample_sensors(|s| is_gps(s) && s.due(tick));
        let s = sim.gps_receivers()[0].last();
        assert_eq!(
            (s.flags, s.gps_week, s.r_bn_n_m),
            (gps_flags::INERTIAL, 0, Vector3::zeros())
        );
        sim.step_frame();
    }
}

/// Two runs of the scenario (its receiver: 1 Hz, 0.2 s latency, noise and bias) give the same
/// encoded GpsMsg bytes at every publication (the lockstep server publishes exactly these);
/// another seed other noise.
#[test]
fn scenario_stream_reproduces_bit_for_bit() {
    let run = |seed: u64| {
        let text = leo_text().replace("seed = 51", &format!("seed = {seed}"));
        let cfg = SimConfig::from_toml_str(&text).unwrap();
        let mut sim = Simulation::new(&cfg).unwrap();
        let mut out = Vec::new();
        for tick in 0..350u64 {
            sim.sample_sensors(|s| is_gps(s) && s.due(tick));
            let bank = sim.sensors();
            for &i in bank.sampled() {
                let mut buf = Vec::new();
                bank.sensors()[i].encode(Header::new(1, tick, sim.t_sim_ns(), tick), &mut buf);
                out.push((tick, buf));
            }
            sim.step_frame();
        }
        out
    };
    let a = run(51);
    assert_eq!(
        a.iter().map(|p| p.0).collect::<Vec<_>>(),
        [20, 120, 220, 320]
    );
    let m = decode_gps(&a[1].1).unwrap();
    assert_eq!(
        (m.header.seq, m.valid_sim_time_ns, m.flags),
        (1, 1_000_000_000, BOTH)
    );
    assert_eq!((m.gps_week, m.gps_seconds_of_week), (2446, 194_419.0));
    assert_eq!(a, run(51));
    assert_ne!(a, run(52));
}

#[test]
fn configuration_errors_name_the_file_field_and_problem() {
    let text = leo_text();
    for (from, to, field, words) in [
        ("rate_hz = 1.0\nseed = 51", "rate_hz = 3.0\nseed = 51", "gps_receivers[0].rate_hz", "whole number"),
        ("latency_s = 0.2 ", "latency_s = 0.205 ", "gps_receivers[0].latency_s", "whole number of frames"),
        ("latency_s = 0.2 ", "latency_s = -0.2 ", "gps_receivers[0].latency_s", ">= 0"),
        ("frames = \"both\"", "frames = \"ecf\"", "gps_receivers[0].frames", "ecef"),
        ("acquisition_s = 0.0", "acquisition_s = 0.0\noutage_s = [2.0, 1.0]", "gps_receivers[0].outage_s", "must end after it starts"),
        ("acquisition_s = 0.0", "acquisition_s = 0.0\noutage_s = [2.0]", "gps_receivers[0].outage_s", "2 elements"),
        ("position_sigma_m = 3.0", "position_sigma_m = -3.0", "gps_receivers[0].position_sigma_m", ">= 0"),
        ("velocity_sigma_m_s = 0.05", "velocity_sigma_m_s = nan", "gps_receivers[0].velocity_sigma_m_s", ""),
        ("position_bias_e_m = [0.5, -0.3, 0.8]", "position_bias_e_m = [0.5, -0.3]", "gps_receivers[0].position_bias_e_m", "3 elements"),
        ("seed = 51", "seed = -51", "gps_receivers[0].seed", ""),
        ("seed = 51", "seed = 51\nantenna = 1", "gps_receivers[0].antenna", "unknown key"),
        ("name = \"gps1\"", "name = \"gps/1\"", "gps_receivers[0].name", "/"),
        (
            "velocity_bias_e_m_s = [0.0, 0.0, 0.0]",
            "velocity_bias_e_m_s = [0.0, 0.0, 0.0]\n[[gps_receivers]]\nname = \"gps1\"\nrate_hz = 1.0\nseed = 2",
            "gps_receivers[1].name",
            "duplicate GPS receiver name",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let e = SimConfig::from_toml_str(&text.replacen(from, to, 1)).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains(field), "{to}: {msg}");
        assert!(msg.contains(words), "{to}: {msg}");
    }
    // Through the command line, the message names the file too.
    let dir = std::env::temp_dir().join(format!("flexdyn-gps-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad_gps.toml");
    std::fs::write(
        &path,
        text.replacen("latency_s = 0.2 ", "latency_s = 0.205 ", 1),
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
        msg.contains("bad_gps.toml: gps_receivers[0].latency_s: ") && msg.contains("(line "),
        "{msg}"
    );
}

/// `simulate` writes the receiver's columns (`gps_<name>_*`) through the generic sensor loop,
/// filled in the rows of its publications, and `flexdyn plot` draws `gps.png` from them.
#[test]
fn simulate_columns_and_plot() {
    let dir = std::env::temp_dir().join(format!("flexdyn-gps-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("leo.csv");
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_flexdyn"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    run(&[
        "simulate",
        "--config",
        LEO,
        "--duration-s",
        "3",
        "--log-every-s",
        "0.1",
        "-o",
        csv.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    let (t, week, sow, valid) = (
        col("t_s"),
        col("gps_gps1_gps_week"),
        col("gps_gps1_gps_seconds_of_week"),
        col("gps_gps1_valid_sim_time_ns"),
    );
    col("gps_gps1_r_be_e_m_1");
    col("gps_gps1_v_bn_n_m_s_3");
    let rows: Vec<Vec<&str>> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|r| !r[week].is_empty())
        .collect();
    let got: Vec<(&str, &str, &str, &str)> = rows
        .iter()
        .map(|r| (r[t], r[week], r[sow], r[valid]))
        .collect();
    assert_eq!(
        got,
        [
            ("0.2", "2446", "194418", "0"),
            ("1.2", "2446", "194419", "1000000000"),
            ("2.2", "2446", "194420", "2000000000")
        ]
    );
    run(&["plot", csv.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
    let png = std::fs::metadata(dir.join("gps.png")).unwrap();
    assert!(png.len() > 10_000, "{} bytes", png.len());
    std::fs::remove_dir_all(&dir).unwrap();
}
