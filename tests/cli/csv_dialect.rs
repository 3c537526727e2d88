//! One CSV dialect: `flexdyn simulate` and `flexdyn export` of the same run write the same
//! columns, with units in the names, and the same values.
//!
//! The run: `scenarios/wheels_star_tracker.toml` (4 wheels, an IMU, a star tracker) with a
//! scheduled wheel torque and a scheduled hub torque, for 1 s. `simulate` logs every frame;
//! a batch server with no flight code runs the same file and records it, and `export` writes
//! the recording's CSVs. With no commands, the server's states are the simulation's bit for
//! bit, so every shared cell must be the same text. The server's StateMsg has no scheduled
//! wrench (the wire carries the commanded one), and the sensors have their own topics, so
//! `simulate`'s row is the exported state row, then `wrench_schedule_*`, then each IMU's and
//! each star tracker's exported columns prefixed `imu_<name>_` / `st_<name>_`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn flexdyn() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexdyn"))
}

fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("csv_dialect-{}", std::process::id()))
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.parent().unwrap()).unwrap();
    d
}

#[track_caller]
fn run(cmd: &mut Command) {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{cmd:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// (header, rows) of a CSV file.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let split = |l: &str| l.split(',').map(str::to_owned).collect::<Vec<_>>();
    let header = split(lines.next().unwrap());
    (header, lines.map(split).collect())
}

/// The columns of an exported sensor CSV after `t_s` and the header fields.
fn body(header: &[String]) -> &[String] {
    let after = header.iter().position(|h| h == "seq").unwrap() + 1;
    assert_eq!(
        &header[..after],
        [
            "t_s",
            "protocol_version",
            "spacecraft_id",
            "tick",
            "sim_time_ns",
            "seq"
        ]
    );
    &header[after..]
}

#[test]
fn simulate_and_export_of_the_same_run_share_header_and_values() {
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wheels_star_tracker.toml"),
    )
    .unwrap();
    let config = scratch("run.toml");
    std::fs::write(
        &config,
        format!(
            "{base}\n[[effector_input_schedule]]\nt_s = 0.25\neffector = \"rw2\"\ninputs = [0.05]\n\n\
             [[wrench_schedule]]\nt_s = 0.5\nforce_b_newton = [0.0, 0.0, 0.0]\ntorque_b_nm = [0.0, 0.1, 0.0]\n"
        ),
    )
    .unwrap();
    let sim_csv = scratch("simulate.csv");
    run(flexdyn()
        .args([
            "simulate",
            "--duration-s",
            "1",
            "--log-every-s",
            "0.01",
            "--config",
        ])
        .arg(&config)
        .arg("-o")
        .arg(&sim_csv));
    let rec = scratch("run.mcap");
    run(flexdyn()
        .args(["run", "--mode", "batch", "--duration-s", "1"])
        .args(["--listen", "tcp/127.0.0.1:0", "--config"])
        .arg(&config)
        .arg("--record")
        .arg(&rec));
    let dir = scratch("export");
    run(flexdyn().arg("export").arg(&rec).arg("--csv").arg(&dir));

    let (sim_h, sim_rows) = read_csv(&sim_csv);
    let (state_h, state_rows) = read_csv(&dir.join("flexdyn_sc1_tlm_state.csv"));
    let (imu_h, imu_rows) = read_csv(&dir.join("flexdyn_sc1_tlm_imu_hub.csv"));
    let (st_h, st_rows) = read_csv(&dir.join("flexdyn_sc1_tlm_st_st1.csv"));

    // The header: the exported state row, the scheduled wrench, then the sensors.
    let mut expected = state_h.clone();
    for q in ["torque_b_nm", "force_b_newton"] {
        expected.extend((1..=3).map(|i| format!("wrench_schedule_{q}_{i}")));
    }
    expected.extend(body(&imu_h).iter().map(|c| format!("imu_hub_{c}")));
    expected.extend(body(&st_h).iter().map(|c| format!("st_st1_{c}")));
    assert_eq!(sim_h, expected);
    // Units in the names.
    for c in [
        "omega_bn_b_rad_s_1",
        "r_bn_n_m_1",
        "v_bn_n_m_s_1",
        "rw2_motor_torque_nm",
    ] {
        assert!(sim_h.iter().any(|h| h == c), "{c}");
    }

    // The values: ticks 0..=100, every exported cell equal as text.
    assert_eq!(sim_rows.len(), 101);
    assert_eq!(state_rows.len(), 101);
    assert_eq!(imu_rows.len(), 101);
    let col = |name: &str| sim_h.iter().position(|h| h == name).unwrap();
    let n_state = state_h.len();
    let imu_first = col("imu_hub_omega_p_rad_s_1");
    let st_first = col("st_st1_q_cn_0");
    let mut st_updates = st_rows.iter();
    for (k, row) in sim_rows.iter().enumerate() {
        assert_eq!(row[..n_state], state_rows[k][..], "state row {k}");
        assert_eq!(row[imu_first..st_first], imu_rows[k][6..], "IMU row {k}");
        // The 10 Hz tracker updates every 10th frame; its cells are empty in between.
        if k % 10 == 0 {
            let st = st_updates.next().unwrap();
            assert_eq!(row[st_first..], st[6..], "star-tracker row {k}");
        } else {
            assert!(row[st_first..].iter().all(String::is_empty), "row {k}");
        }
    }
    assert!(st_updates.next().is_none());

    // Both applied the schedules: the server's wheel 2 torque is 0.05 N·m from 0.25 s, and the
    // scheduled hub torque shows in simulate's column from 0.5 s.
    let torque = col("rw2_motor_torque_nm");
    assert_eq!(state_rows[24][torque], "0");
    assert_eq!(state_rows[25][torque], "0.05");
    assert_eq!(sim_rows[49][col("wrench_schedule_torque_b_nm_2")], "0");
    assert_eq!(sim_rows[50][col("wrench_schedule_torque_b_nm_2")], "0.1");
}
