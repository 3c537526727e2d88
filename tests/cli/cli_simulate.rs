//! The `flexdyn` binary's offline subcommands, run as a user would: `simulate`, `check-config`
//! and `print-default-config`.

use flexdyn_testkit::ports;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use flexdyn_vehicle::config::{SimConfig, DEFAULT_CONFIG_TOML};

fn flexdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(args)
        .env("RUST_LOG", "info")
        .output()
        .expect("runs the flexdyn binary")
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("UTF-8 stdout")
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("UTF-8 stderr")
}

/// A fresh file path in the test scratch directory.
fn scratch(name: &str) -> PathBuf {
    let dir =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli_simulate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The documented columns of the reference spacecraft (docs/guides/configuration.md, "CSV output"), written out.
fn expected_header() -> Vec<String> {
    let mut h: Vec<String> = [
        "t_s",
        "protocol_version",
        "spacecraft_id",
        "tick",
        "sim_time_ns",
        "seq",
    ]
    .map(String::from)
    .to_vec();
    let v3 = |h: &mut Vec<String>, base: &str| h.extend((1..=3).map(|i| format!("{base}_{i}")));
    v3(&mut h, "sigma_bn");
    h.extend((0..=3).map(|i| format!("q_bn_{i}")));
    for base in [
        "omega_bn_b_rad_s",
        "omega_dot_bn_b_rad_s2",
        "r_bn_n_m",
        "v_bn_n_m_s",
        "nongrav_accel_bn_n_m_s2",
    ] {
        v3(&mut h, base);
    }
    h.push("conserved_orb_energy_j".into());
    h.push("conserved_rot_energy_j".into());
    v3(&mut h, "conserved_orb_ang_mom_n");
    v3(&mut h, "conserved_rot_ang_mom_c_n");
    v3(&mut h, "wrench_applied_torque_b_nm");
    v3(&mut h, "wrench_applied_force_b_newton");
    h.push("command_flags".into());
    for k in 1..=2 {
        for c in ["theta1", "theta1_dot", "theta2", "theta2_dot", "flags"] {
            h.push(format!("pair{k}_{c}"));
        }
    }
    v3(&mut h, "wrench_schedule_torque_b_nm");
    v3(&mut h, "wrench_schedule_force_b_newton");
    h
}

/// Significant digits of a `{:.16e}`-formatted number: the mantissa has 1 + 16 digits.
/// Significant digits of a decimal field (leading zeros and, for integers, trailing zeros do
/// not count).
fn significant_digits(field: &str) -> usize {
    let mantissa = field.split(['e', 'E']).next().unwrap();
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    let digits = digits.trim_start_matches('0');
    let digits = if mantissa.contains('.') {
        digits
    } else {
        digits.trim_end_matches('0')
    };
    digits.len().max(1)
}

/// The fewest significant digits that read back to `v` exactly (found by trying each
/// precision, independent of how the CSV writer formats).
fn shortest_digits(v: f64) -> usize {
    (1..=17)
        .find(|p| format!("{:.*e}", p - 1, v).parse::<f64>().unwrap() == v)
        .unwrap()
}

#[track_caller]
fn assert_summary_line(err: &str) {
    let line = err.lines().last().expect("a stderr line");
    let parts: Vec<&str> = line.split(' ').collect();
    assert_eq!(parts.len(), 3, "summary line: {line}");
    let value = |i: usize, key: &str| -> f64 {
        let v = parts[i]
            .strip_prefix(key)
            .unwrap_or_else(|| panic!("`{key}` in {line}"));
        v.parse()
            .unwrap_or_else(|_| panic!("number after {key} in {line}"))
    };
    assert_eq!(value(0, "steps="), 100.0, "{line}");
    assert!(value(1, "wall_s=") >= 0.0, "{line}");
    assert!(value(2, "steps_per_s=") >= 0.0, "{line}");
}

#[test]
fn simulate_writes_the_documented_csv() {
    let out = flexdyn(&["simulate", "--duration-s", "0.1", "--log-every-s", "0.01"]);
    let err = stderr(&out);
    assert!(out.status.success(), "stderr: {err}");
    let text = stdout(&out);
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    assert_eq!(header, expected_header());
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 11);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), header.len(), "row {k}");
        for f in row {
            let v: f64 = f.parse().unwrap_or_else(|_| panic!("`{f}` is a number"));
            assert!(v.is_finite());
            // The shortest form that round-trips: no digit more than needed.
            assert_eq!(
                significant_digits(f),
                shortest_digits(v),
                "`{f}` in row {k} is not the shortest round-trip form"
            );
        }
        let t: f64 = row[0].parse().unwrap();
        assert!((t - 0.01 * k as f64).abs() < 1e-12, "row {k}: t = {t}");
    }
    assert_eq!(rows[0][0].parse::<f64>().unwrap(), 0.0);
    // t = 0.03 s prints as such, not as 2.9999999999999999e-2.
    assert_eq!(rows[3][0], "0.03");
    // Row 0 is the configured initial state.
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(rows[0][col("omega_bn_b_rad_s_1")], "0.05");
    assert_eq!(rows[0][col("pair1_theta1")], "0.08726646259971647");
    // Row k is tick k (a row per 100 Hz frame here), numbered by seq.
    assert_eq!(rows[7][col("tick")], "7");
    assert_eq!(rows[7][col("seq")], "7");
    assert_eq!(rows[7][col("sim_time_ns")], "70000000");
    // Exactly one stderr line: the summary.
    assert_eq!(err.lines().count(), 1, "stderr: {err}");
    assert_summary_line(&err);
}

#[test]
fn output_dash_is_stdout_and_file_output_matches() {
    let args = ["simulate", "--duration-s", "0.1", "--log-every-s", "0.01"];
    let plain = flexdyn(&args);
    let dash = flexdyn(&[&args[..], &["--output", "-"]].concat());
    assert!(dash.status.success(), "{}", stderr(&dash));
    assert_eq!(stdout(&dash), stdout(&plain));
    assert_summary_line(&stderr(&dash));

    let path = scratch("out.csv");
    let file = flexdyn(&[&args[..], &["--output", path.to_str().unwrap()]].concat());
    assert!(file.status.success(), "{}", stderr(&file));
    assert!(file.stdout.is_empty());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), stdout(&plain));
    assert_summary_line(&stderr(&file));
}

#[test]
fn simulate_with_a_config_file() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/eight_pairs.toml");
    let out = flexdyn(&[
        "simulate",
        "--config",
        path.to_str().unwrap(),
        "--duration-s",
        "0.02",
        "--log-every-s",
        "0.01",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let header = text.lines().next().unwrap();
    // The reference's columns with 8 pairs of 5 instead of 2.
    assert_eq!(header.split(',').count(), expected_header().len() + 6 * 5);
    assert!(header.contains("pair8_theta2_dot"));
    assert_eq!(text.lines().count(), 1 + 3);
}

#[test]
fn log_interval_not_a_whole_number_of_steps() {
    let path = scratch("never-written.csv");
    let out = flexdyn(&[
        "simulate",
        "--duration-s",
        "0.1",
        "--log-every-s",
        "0.0015",
        "--output",
        path.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.starts_with("error: --log-every-s:"), "{err}");
    assert!(err.contains("whole number of RK4 steps"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        !path.exists(),
        "the output file is not created on an argument error"
    );
}

#[test]
fn bad_duration_and_interval_values() {
    for (flag, value, problem) in [
        ("--duration-s", "0.0105", "whole number of RK4 steps"),
        ("--duration-s", "-1", "must be >= 0"),
        ("--log-every-s", "0", "must be > 0"),
        ("--log-every-s", "nan", "must be finite"),
    ] {
        let mut args = vec!["simulate", "--duration-s", "0.1", "--log-every-s", "0.01"];
        let i = args.iter().position(|a| *a == flag).unwrap();
        args[i + 1] = value;
        let out = flexdyn(&args);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}");
        let err = stderr(&out);
        assert!(err.starts_with(&format!("error: {flag}:")), "{err}");
        assert!(err.contains(problem), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn check_config_names_the_imus() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/imu_tactical.toml");
    let out = flexdyn(&["check-config", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("2 IMUs (hub, bracket)"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn check_config_accepts_the_reference() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/reference.toml");
    let out = flexdyn(&["check-config", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let summary = stdout(&out);
    assert_eq!(summary.lines().count(), 1);
    for word in [
        "2 panel pairs",
        "0 IMUs,",
        "total mass 950 kg",
        "step 0.001 s",
        "frame 100 Hz",
    ] {
        assert!(summary.contains(word), "{summary}");
    }
}

#[test]
fn check_config_rejects_a_bad_file() {
    let cases = [
        (
            "mass_kg = 750.0",
            "mass_kg = -750.0",
            "hub.mass_kg",
            "must be > 0",
        ),
        (
            "mass_kg = 750.0",
            "mass_kg = nan",
            "hub.mass_kg",
            "must be finite",
        ),
        (
            "mass_kg = 750.0",
            "mass_kg = 750.0\ncolour = \"red\"",
            "hub.colour",
            "unknown key",
        ),
        (
            "step_s = 0.001 ",
            "step_s = 0.0000000015 ",
            "simulation.step_s",
            "whole number of nanoseconds",
        ),
        (
            "d_m = 0.75, l_m = 1.5",
            "d_m = 1.75, l_m = 1.5",
            "panel_pairs[0].panel1.d_m",
            "exceeds",
        ),
    ];
    for (i, (from, to, field, problem)) in cases.iter().enumerate() {
        let path = scratch(&format!("bad{i}.toml"));
        std::fs::write(&path, DEFAULT_CONFIG_TOML.replacen(from, to, 1)).unwrap();
        let out = flexdyn(&["check-config", path.to_str().unwrap()]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.starts_with("error: "), "{err}");
        assert!(err.contains(field) && err.contains(problem), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(out.stdout.is_empty());
    }
}

#[test]
fn check_config_on_a_missing_file_or_garbage() {
    let missing = scratch("missing.toml");
    let out = flexdyn(&["check-config", missing.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.starts_with("error: cannot read config file") && err.contains("missing.toml"),
        "{err}"
    );

    let garbage = scratch("garbage.toml");
    std::fs::write(&garbage, b"\xff\xfe not toml [[[").unwrap();
    let out = flexdyn(&["check-config", garbage.to_str().unwrap()]);
    let err = stderr(&out);
    assert_ne!(out.status.code(), Some(0));
    assert!(
        err.starts_with("error: ") && !err.contains("panicked"),
        "{err}"
    );

    let syntax = scratch("syntax.toml");
    std::fs::write(&syntax, "[simulation\nstep_s = 0.001\n").unwrap();
    let out = flexdyn(&["check-config", syntax.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("TOML syntax error at line 1"), "{err}");
}

#[test]
fn simulate_with_a_bad_config_fails_cleanly() {
    let path = scratch("bad-sim.toml");
    std::fs::write(
        &path,
        DEFAULT_CONFIG_TOML.replacen("k_nm_rad = 100.0", "k_nm_rad = -100.0", 1),
    )
    .unwrap();
    let out = flexdyn(&[
        "simulate",
        "--config",
        path.to_str().unwrap(),
        "--duration-s",
        "0.01",
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("panel_pairs[0].panel1.k_nm_rad") && err.contains(">= 0"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn print_default_config_is_the_embedded_default() {
    let out = flexdyn(&["print-default-config"]);
    assert!(out.status.success());
    let text = stdout(&out);
    assert_eq!(text, DEFAULT_CONFIG_TOML);
    assert_eq!(
        SimConfig::from_toml_str(&text).unwrap(),
        SimConfig::reference()
    );
}

// Plain `flexdyn` (no subcommand) now runs the real-time server on tcp/127.0.0.1:7447 until
// stopped, so it is not run here; `--help` lists every subcommand instead.
#[test]
fn help_lists_every_subcommand() {
    let out = flexdyn(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let text = stdout(&out);
    for sub in ["run", "simulate", "check-config", "print-default-config"] {
        assert!(text.contains(sub), "{text}");
    }
}

/// The reference text with `[server]` lines appended.
fn with_server(lines: &str) -> String {
    format!("{DEFAULT_CONFIG_TOML}\n[server]\n{lines}\n")
}

#[test]
fn check_config_validates_the_server_table_as_run_does() {
    // (the [server] lines, the message, the line of the offending key)
    let cases = [
        ("mode = \"fast\"", "server.mode: unknown mode", "mode"),
        ("colour = 1", "server.colour: unknown key", "colour"),
        (
            "stale_after_s = -0.5",
            "server.stale_after_s: must be > 0",
            "stale_after_s",
        ),
        (
            "participants = \"1,2\"",
            "server.participants: expected a list of sender ids",
            "participants",
        ),
        ("sc_id = \"a/b\"", "server.sc_id:", "sc_id"),
        (
            "mode = \"lockstep\"\nparticipants = []",
            "server.participants: lockstep needs at least one participant",
            "participants",
        ),
        (
            "duration_s = 0.015",
            "server.duration_s: 0.015 s is not a whole number of frames",
            "duration_s",
        ),
        // The shortest form, not 301 digits.
        (
            "duration_s = 1e300",
            "server.duration_s: 1e300 s is beyond the maximum simulation time",
            "duration_s",
        ),
        (
            "status_hz = 1e300",
            "server.status_hz: must be <= 1000 Hz (got 1e300)",
            "status_hz",
        ),
    ];
    for (i, (lines, want, key)) in cases.iter().enumerate() {
        let path = scratch(&format!("server{i}.toml"));
        let text = with_server(lines);
        std::fs::write(&path, &text).unwrap();
        let p = path.to_str().unwrap();
        let check = flexdyn(&["check-config", p]);
        let err = stderr(&check);
        assert_eq!(check.status.code(), Some(2), "{lines}: {err}");
        assert_eq!(err.lines().count(), 1, "{lines}: {err}");
        let line = err.lines().next().unwrap();
        assert!(line.starts_with(&format!("error: {p}: ")), "{line}");
        assert!(line.contains(want), "{lines}: {line}");
        // Like every other section's errors, it ends with the key's line and column.
        let lines_of: Vec<&str> = text.lines().collect();
        let key_line = 1 + lines_of.iter().rposition(|l| l.starts_with(key)).unwrap();
        let at = format!("(line {key_line}, column ");
        let tail = line.rsplit_once(" (line ").map(|(_, t)| t).unwrap_or("");
        assert!(
            line.contains(&at) && tail.ends_with(')') && tail.contains("column"),
            "{lines}: not at {at}: {line}"
        );
        // Numbers in their shortest form: no run of 20 digits.
        let longest_digits = line
            .split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max();
        assert!(longest_digits < Some(20), "{lines}: {line}");
        assert!(stdout(&check).is_empty());
        // `run` rejects the same file the same way, before opening any session.
        let run = flexdyn(&["run", "--config", p, "--listen", ports::ANY_PORT]);
        let run_err = stderr(&run);
        assert_eq!(run.status.code(), Some(2), "run {lines}: {run_err}");
        assert!(run_err.contains(want), "run {lines}: {run_err}");
        assert!(run_err.contains(&format!("error: {p}: ")), "run: {run_err}");
        assert!(run_err.contains(&at), "run {lines}: not at {at}: {run_err}");
    }
    // A valid [server] table passes.
    let path = scratch("server_ok.toml");
    std::fs::write(
        &path,
        with_server("mode = \"lockstep\"\nparticipants = [1, 2]\nduration_s = 12.0"),
    )
    .unwrap();
    let ok = flexdyn(&["check-config", path.to_str().unwrap()]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    assert!(stdout(&ok).starts_with("ok: "));
}

/// A configuration that passes every check but whose state overflows: from t = 0.5 s a hub
/// torque of 1e300 N·m spins the hub up until its rotational energy overflows to infinity.
fn blow_up_config() -> PathBuf {
    let path = scratch("blow_up.toml");
    let text = format!(
        "{DEFAULT_CONFIG_TOML}\n[[wrench_schedule]]\nt_s = 0.5\nforce_b_newton = [0.0, 0.0, 0.0]\n\
         torque_b_nm = [0.0, 0.0, 1e300]\n"
    );
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn simulate_stops_on_a_non_finite_state_naming_step_and_quantity() {
    let path = blow_up_config();
    let p = path.to_str().unwrap();
    let check = flexdyn(&["check-config", p]);
    assert!(check.status.success(), "{}", stderr(&check));
    let out = flexdyn(&["simulate", "--config", p, "--duration-s", "1"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: the state became non-finite at step ")
            && err.contains("is NaN or infinite"),
        "{err}"
    );
    // Every row written is finite; the bad row is not among them.
    let text = stdout(&out);
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert!(!rows.is_empty(), "the initial row is finite and written");
    for r in &rows {
        for f in r.split(',') {
            assert!(f.parse::<f64>().unwrap().is_finite(), "{f} in {r}");
        }
    }
    // The message names the step of the first row not written.
    let step: u64 = err["error: the state became non-finite at step ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(step, 10 * rows.len() as u64, "{err}");
}

#[test]
fn the_server_stops_on_a_non_finite_state_with_exit_1() {
    let path = blow_up_config();
    let out = flexdyn(&[
        "run",
        "--config",
        path.to_str().unwrap(),
        "--mode",
        "batch",
        "--duration-s",
        "1",
        "--listen",
        ports::ANY_PORT,
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let last = err.lines().last().unwrap();
    assert!(
        last.starts_with("error: the state became non-finite at tick 51 (t = 0.51 s): "),
        "{err}"
    );
}

/// Legal values that are almost surely a unit slip: `check-config` still says `ok` (exit 0),
/// after one `warning:` line naming the file, the field, the likely unit and the converted
/// value, and the value's line; `simulate` logs the same at WARN.
#[test]
fn check_config_warns_of_likely_unit_slips() {
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wheels_star_tracker.toml"),
    )
    .unwrap();
    // (the scenario's line, the slip, the field, what the warning must say)
    let cases: [(&str, &str, &str, &str); 9] = [
        // 5″ typed as radians: the example.
        (
            "sigma_cross_boresight_rad = 2.4241e-5",
            "sigma_cross_boresight_rad = 5.0",
            "star_trackers[0].sigma_cross_boresight_rad",
            "5 rad is far above a star tracker's noise (1σ) (1e-7–0.005 rad on datasheets); \
             is it in arcsec? 5 arcsec = 2.4241e-5 rad",
        ),
        (
            "sun_exclusion_rad = 0.5236",
            "sun_exclusion_rad = 30.0",
            "star_trackers[0].sun_exclusion_rad",
            "is it in deg? 30 deg = 0.5236 rad",
        ),
        (
            "max_rate_rad_s = 0.0349",
            "max_rate_rad_s = 2.0",
            "star_trackers[0].max_rate_rad_s",
            "is it in deg/s? 2 deg/s = 0.034907 rad/s",
        ),
        (
            "max_speed_rad_s = 600.0",
            "max_speed_rad_s = 6000.0",
            "reaction_wheels[0].max_speed_rad_s",
            "is it in rpm? 6000 rpm = 628.32 rad/s",
        ),
        (
            "max_torque_nm = 0.2",
            "max_torque_nm = 5.0",
            "reaction_wheels[0].max_torque_nm",
            "is it in mN·m? 5 mN·m = 0.005 N·m",
        ),
        (
            "range_rad_s = 8.5521",
            "range_rad_s = 490.0",
            "imus[0].gyro.range_rad_s",
            "is it in °/s? 490 °/s = 8.5521 rad/s",
        ),
        (
            "arw_rad_s_sqrt_hz = 4.3633e-5",
            "arw_rad_s_sqrt_hz = 0.15",
            "imus[0].gyro.arw_rad_s_sqrt_hz",
            "0.15 °/√h = 4.3633e-5 rad/s/√Hz",
        ),
        (
            "bias_instability_sigma_m_s2 = 7.9424e-4",
            "bias_instability_sigma_m_s2 = 50.0",
            "imus[0].accel.bias_instability_sigma_m_s2",
            "is it in µg? 50 µg = 0.00049033 m/s²",
        ),
        (
            "range_m_s2 = 294.20",
            "range_m_s2 = 8.0",
            "imus[0].accel.range_m_s2",
            "8 m/s² is below an accelerometer's full scale (9.80665–2000 m/s² on datasheets); \
             is it in g? 8 g = 78.453 m/s²",
        ),
    ];
    for (i, (from, to, field, says)) in cases.iter().enumerate() {
        assert!(base.contains(from), "the scenario lacks {from:?}");
        let text = base.replacen(from, to, 1);
        let path = scratch(&format!("slip{i}.toml"));
        std::fs::write(&path, &text).unwrap();
        let p = path.to_str().unwrap();
        let out = flexdyn(&["check-config", p]);
        assert!(out.status.success(), "{to}: {}", stderr(&out));
        let text_out = stdout(&out);
        let lines: Vec<&str> = text_out.lines().collect();
        assert_eq!(lines.len(), 2, "{to}: {text_out}");
        assert!(lines[1].starts_with(&format!("ok: {p}: ")), "{text_out}");
        let line_no = 1 + text.lines().position(|l| l.starts_with(to)).unwrap();
        let w = lines[0];
        assert!(
            w.starts_with(&format!("warning: {p}: {field}: ")),
            "{to}: {w}"
        );
        assert!(w.contains(says), "{to}: {w}");
        assert!(
            w.ends_with(&format!(
                "(line {line_no}, column {})",
                from.find('=').unwrap() + 3
            )),
            "{to}: {w}"
        );
    }
    // `simulate` (and `run`) log the warning at WARN and go on.
    let path = scratch("slip0.toml");
    let csv = scratch("slip0.csv");
    let (p, c) = (path.to_str().unwrap(), csv.to_str().unwrap());
    let out = flexdyn(&["simulate", "--config", p, "--duration-s", "0.01", "-o", c]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("WARN") && err.contains("star_trackers[0].sigma_cross_boresight_rad"),
        "{err}"
    );
}

#[test]
fn shipped_scenarios_give_no_warning() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut checked = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        // Not a campaign, not a device list (`*.devices.toml`) and not a fleet file
        // (`[[vehicles]]`): a spacecraft.
        let is_config = path.extension().is_some_and(|e| e == "toml")
            && path.file_stem().is_some_and(|s| {
                let s = s.to_string_lossy();
                !s.ends_with("campaign") && !s.ends_with(".devices")
            })
            && !std::fs::read_to_string(&path)
                .unwrap()
                .contains("[[vehicles]]");
        if !is_config {
            continue;
        }
        let out = flexdyn(&["check-config", path.to_str().unwrap()]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert_eq!(stdout(&out).lines().count(), 1, "{}", stdout(&out));
        assert!(!stdout(&out).contains("warning"), "{}", stdout(&out));
        checked += 1;
    }
    // At least the eight spacecraft shipped when this test was written (the filter works).
    assert!(checked >= 8, "only {checked} spacecraft files checked");
}
