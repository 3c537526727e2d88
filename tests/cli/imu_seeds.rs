//! Determinism of the IMU streams: the same seed gives the same bytes (bincode `ImuMsg`), a
//! different seed gives different noise (and leaves the other IMUs alone), and `simulate`
//! reproduces the per-frame (lockstep) stream bit for bit.

use std::path::Path;

use flexdyn::commands::simulate::simulate_to;
use flexdyn_proto::{encode, Header, ImuMsg};
use flexdyn_sensors::imu::{attitude_increment_b, ImuSample};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::Vector3;

fn tactical() -> SimConfig {
    SimConfig::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/imu_tactical.toml"))
        .expect("imu_tactical.toml is valid")
}

/// Per IMU, the concatenated encoded `ImuMsg`s of `frames` + 1 frames (tick 0 included), as the
/// server would publish them.
fn imu_streams(cfg: &SimConfig, frames: u64) -> Vec<Vec<u8>> {
    let mut sim = Simulation::new(cfg).unwrap();
    let mut streams = vec![Vec::new(); sim.n_imus()];
    let mut out = Vec::new();
    for tick in 0..=frames {
        if tick > 0 {
            sim.step_frame();
        }
        sim.imu_samples_into(&mut out);
        for (stream, s) in streams.iter_mut().zip(&out) {
            let msg: ImuMsg = s.to_msg(Header::new(7, tick, sim.t_sim_ns(), tick));
            stream.extend_from_slice(&encode(&msg));
        }
    }
    streams
}

#[test]
fn regress_same_seed_gives_identical_bytes() {
    let cfg = tactical();
    let a = imu_streams(&cfg, 300);
    let b = imu_streams(&cfg, 300);
    assert_eq!(a.len(), 2);
    assert_eq!(a[0].len(), 301 * 127, "ImuMsg is 127 bytes");
    assert_eq!(a, b);
}

#[test]
fn a_different_seed_changes_only_that_imus_noise() {
    let cfg = tactical();
    let mut other = cfg.clone();
    other
        .sensors
        .of_mut::<flexdyn_sensors::imu::ImuConfig>()
        .next()
        .unwrap()
        .seed = 12345;
    let a = imu_streams(&cfg, 100);
    let b = imu_streams(&other, 100);
    assert_eq!(a[1], b[1], "imus[1] keeps its own stream");
    // Every message of imus[0] differs (its white noise is redrawn every sample).
    let differing = a[0]
        .chunks(127)
        .zip(b[0].chunks(127))
        .filter(|(x, y)| x != y)
        .count();
    assert_eq!(differing, 101);
}

fn csv_imu_columns(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let first = header
        .iter()
        .position(|h| h.starts_with("imu_"))
        .expect("IMU columns");
    let rows = lines
        .map(|l| {
            l.split(',')
                .skip(first)
                .map(|v| v.parse().unwrap())
                .collect()
        })
        .collect();
    (header[first..].to_vec(), rows)
}

#[test]
fn simulate_reproduces_the_lockstep_stream_bit_for_bit() {
    let cfg = tactical();
    let mut buf = Vec::new();
    simulate_to(&cfg, 1.0, 0.01, &mut buf, "buffer").unwrap();
    let text = String::from_utf8(buf).unwrap();
    let (header, rows) = csv_imu_columns(&text);
    let mut expected_header = Vec::new();
    for name in ["hub", "bracket"] {
        for q in ["omega_p_rad_s", "accel_p_m_s2", "dtheta_p_rad", "dv_p_m_s"] {
            for i in 1..=3 {
                expected_header.push(format!("imu_{name}_{q}_{i}"));
            }
        }
        expected_header.push(format!("imu_{name}_saturation_flags"));
    }
    assert_eq!(header, expected_header);
    assert_eq!(rows.len(), 101);

    // The server's loop: one interval per frame (the log interval here is one frame).
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut out: Vec<ImuSample> = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        if k > 0 {
            sim.step_frame();
        }
        sim.imu_samples_into(&mut out);
        let lockstep: Vec<f64> = out
            .iter()
            .flat_map(|s| {
                [s.omega_p_rad_s, s.accel_p_m_s2, s.dtheta_p_rad, s.dv_p_m_s]
                    .into_iter()
                    .flat_map(|v| v.iter().copied().collect::<Vec<_>>())
                    .chain([f64::from(s.saturation_flags)])
            })
            .collect();
        assert_eq!(row, &lockstep, "row {k}");
        if k == 0 {
            // Δθ and Δv are zero in the first row (an empty interval), noise and bias included.
            for imu in 0..2 {
                assert!(row[imu * 13 + 6..imu * 13 + 12].iter().all(|v| *v == 0.0));
            }
        } else {
            assert!(row[6..9].iter().all(|v| *v != 0.0));
        }
    }
}

#[test]
fn simulate_with_a_longer_log_interval_integrates_over_it() {
    let cfg = tactical();
    let run = || {
        let mut buf = Vec::new();
        simulate_to(&cfg, 0.5, 0.05, &mut buf, "buffer").unwrap();
        String::from_utf8(buf).unwrap()
    };
    let text = run();
    assert_eq!(text, run(), "simulate is deterministic");
    let (_, rows) = csv_imu_columns(&text);
    assert_eq!(rows.len(), 11);
    // σ_B/N is in the same rows (sigma_bn_1..3): the true Δθ over each 0.05 s log interval.
    let first = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == "sigma_bn_1")
        .unwrap();
    let sigma: Vec<Vector3<f64>> = text
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l
                .split(',')
                .skip(first)
                .take(3)
                .map(|x| x.parse().unwrap())
                .collect();
            Vector3::new(v[0], v[1], v[2])
        })
        .collect();
    for k in 1..rows.len() {
        // imus[0] ("hub") has dcm_pb = I.
        let truth = attitude_increment_b(&sigma[k - 1], &sigma[k]);
        let measured = Vector3::new(rows[k][6], rows[k][7], rows[k][8]);
        // |Δθ| ≈ 4 mrad; errors: white noise N√dt ≈ 1e-5 rad, bias·dt < 1e-6, scale ≈ 1e-6.
        assert!(truth.norm() > 3e-3);
        assert!(
            (measured - truth).amax() < 6e-5,
            "interval {k}: {measured:?} vs {truth:?}"
        );
    }
}

#[test]
fn the_binary_writes_the_imu_columns() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/imu_tactical.toml");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["simulate", "--config"])
        .arg(&path)
        .args(["--duration-s", "0.05", "--log-every-s", "0.01"])
        .output()
        .expect("runs flexdyn");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    // The state columns, then 13 per IMU (docs/guides/configuration.md, "CSV output").
    let first = header.iter().position(|h| h.starts_with("imu_")).unwrap();
    assert_eq!(header.len(), first + 2 * 13);
    assert_eq!(header[first], "imu_hub_omega_p_rad_s_1");
    assert_eq!(header[first + 13 + 11], "imu_bracket_dv_p_m_s_3");
    let mut library = Vec::new();
    simulate_to(&tactical(), 0.05, 0.01, &mut library, "buffer").unwrap();
    assert_eq!(text.as_bytes(), library.as_slice());
}
