//! `flexdyn plot` from the outside: every figure of a recording and of a `simulate` CSV is a
//! valid PNG (decoded with the `png` crate), of the documented size, and not blank; figures
//! the input has no data for are skipped and named; bad input is an error naming the file.
//! What the figures show is checked on their data ([`flexdyn_sinks::plot::figures`]): each
//! invariant on its own scale, the intervals of external torque, the wheel and star-tracker
//! figures, the IMU layout, and every point inside its panel's axis bounds.

use flexdyn_testkit::ports;

use std::path::{Path, PathBuf};
use std::process::Command;

use flexdyn_sinks::plot::{draw, figures, register_font, Figure, PlotArgs, COLORS};

fn flexdyn(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(args)
        .output()
        .unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("plots")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.parent().unwrap()).unwrap();
    d
}

/// The colour of every figure's first line (`crates/sinks/src/plot.rs`, `COLORS[0]`).
const FIRST_LINE_RGB: [u8; 3] = [31, 119, 180];

/// Decodes `path` and returns (width, height, fraction of non-white pixels, distinct colours,
/// pixels of the first line's colour).
fn inspect_png(path: &Path) -> (u32, u32, f64, usize, usize) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bpp = info.line_size / info.width as usize;
    let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks(bpp).collect();
    let non_white = pixels.iter().filter(|p| p[..3] != [255, 255, 255]).count();
    let line = pixels.iter().filter(|p| p[..3] == FIRST_LINE_RGB).count();
    let mut colours: Vec<&[u8]> = pixels.clone();
    colours.sort_unstable();
    colours.dedup();
    (
        info.width,
        info.height,
        non_white as f64 / pixels.len() as f64,
        colours.len(),
        line,
    )
}

fn check_figures(dir: &Path, names: &[&str]) {
    for name in names {
        let path = dir.join(name);
        assert!(path.is_file(), "{name} was not written");
        let (w, h, ink, colours, line) = inspect_png(&path);
        eprintln!(
            "{name}: {w}×{h}, {:.1} % ink, {colours} colours, {line} px of the first line",
            ink * 100.0
        );
        assert_eq!((w, h), (1200, 800), "{name}");
        // Axes, text and at least one coloured line: a blank or axis-only figure fails.
        assert!(ink > 0.01, "{name} is (nearly) blank: {ink}");
        assert!(colours >= 8, "{name} has only {colours} colours");
        // The data itself: the first series is drawn (a 2 px line across the plot width).
        assert!(line >= 500, "{name}: the first line has only {line} pixels");
        // The title fits the width (issue 36: relative_motion.png's ran off both edges): no
        // ink in the title band within 6 px of either edge.
        let clipped = title_edge_ink(&path);
        assert_eq!(clipped, 0, "{name}: the title reaches the image's edge");
    }
}

/// Non-white pixels within 6 px of the left or right edge in the top 30 rows (the title band).
fn title_edge_ink(path: &Path) -> usize {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bpp = info.line_size / info.width as usize;
    let w = info.width as usize;
    (0..30)
        .flat_map(|row| (0..6).chain(w - 6..w).map(move |col| (row, col)))
        .filter(|(row, col)| {
            let at = row * info.line_size + col * bpp;
            buf[at..at + 3] != [255, 255, 255]
        })
        .count()
}

#[test]
fn a_recording_gives_every_figure() {
    let rec = tmp("batch.mcap");
    let status = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["run", "--mode", "batch", "--duration-s", "5"])
        .args(["--listen", ports::ANY_PORT, "--config"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wheels_star_tracker.toml"))
        .arg("--record")
        .arg(&rec)
        .status()
        .unwrap();
    assert!(status.success());
    let out = tmp("from_mcap");
    let r = flexdyn(&[
        "plot",
        rec.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--sigma-rn",
        "0.1,0.2,-0.1",
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    check_figures(
        &out,
        &[
            "attitude.png",
            "rates.png",
            "panels.png",
            "wrench.png",
            "conservation.png",
            "wheels.png",
            "star_tracker.png",
            "imu.png",
        ],
    );
    // A batch run is not paced: timing.png is skipped, and the message says why.
    assert!(
        err.contains("skipped timing.png: a batch run is not paced by the wall clock"),
        "{err}"
    );
    // No magnetorquers or thrusters in that scenario.
    assert!(
        err.contains("skipped actuators.png: no mtq<k>_* or thr<k>_* columns"),
        "{err}"
    );
    // Nor magnetometers.
    assert!(
        err.contains("skipped magnetometer.png: no magnetometer"),
        "{err}"
    );
    // Nor sun sensors.
    for fig in ["sun_sensors_coarse.png", "sun_sensors_fine.png"] {
        assert!(err.contains(&format!("skipped {fig}")), "{err}");
    }
    // Nor the environment message.
    assert!(
        err.contains("skipped disturbance_torques.png: no environment record"),
        "{err}"
    );
    // Nor a GPS receiver (issue 20: the generic sensor loop skips its figure by name).
    assert!(err.contains("skipped gps.png: no GPS receiver"), "{err}");
    assert_eq!(err.matches("skipped").count(), 7, "{err}");
    assert!(!out.join("timing.png").exists());

    let (figs, _) = figures(&args(&rec)).unwrap();
    check_axis_bounds(&figs);
    check_drawn_inside_axes(&figs, &out);
    // wheels_star_tracker.toml: 4 wheels, each with a speed, a torque and a flags line.
    let wheels = find(&figs, "wheels.png");
    assert_eq!(wheels.panels.len(), 3);
    for p in &wheels.panels {
        let labels: Vec<_> = p.lines.iter().map(|l| l.label.as_str()).collect();
        assert_eq!(labels.len(), 4, "{labels:?}");
        assert!(labels[3].ends_with("rw4"), "{labels:?}");
    }
    // Limit flags are 0..=3.
    assert!(wheels.panels[2]
        .lines
        .iter()
        .flat_map(|l| &l.points)
        .all(|(_, f)| (0.0..=3.0).contains(f)));
    // The 10 Hz tracker over 5 s: 51 samples of a unit quaternion, and a valid flag.
    let st = find(&figs, "star_tracker.png");
    assert_eq!(st.panels.len(), 2);
    let q = &st.panels[0].lines;
    assert_eq!(q.len(), 4);
    assert_eq!(q[0].points.len(), 51);
    let valid = &st.panels[1].lines[0];
    assert_eq!(valid.label, "valid (0/1)");
    assert!(valid.points.iter().all(|(_, v)| *v == 0.0 || *v == 1.0));
    let mut n_valid = 0;
    for k in 0..51 {
        if valid.points[k].1 == 1.0 {
            n_valid += 1;
            let n2: f64 = q.iter().map(|l| l.points[k].1.powi(2)).sum();
            assert!((n2 - 1.0).abs() < 1e-9, "|q|² = {n2} at sample {k}");
        }
    }
    assert!(n_valid > 0);
}

fn args(input: &Path) -> PlotArgs {
    PlotArgs {
        input: input.to_owned(),
        output: PathBuf::new(),
        sc_id: None,
        sigma_rn: None,
        relative_to: None,
    }
}

fn find<'a>(figs: &'a [Figure], name: &str) -> &'a Figure {
    figs.iter()
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("no {name}"))
}

/// Every drawn point of every panel is inside the panel's axes.
fn check_axis_bounds(figs: &[Figure]) {
    for f in figs {
        for (i, p) in f.panels.iter().enumerate() {
            let ((t0, t1), (lo, hi)) = (p.t_range(), p.y_range());
            assert!(lo < hi && t0 < t1, "{} panel {i}", f.name);
            for l in &p.lines {
                for (t, y) in &l.points {
                    let drawn = !p.log_y || *y > 0.0;
                    assert!(
                        !drawn || ((t0..=t1).contains(t) && (lo..=hi).contains(y)),
                        "{} panel {i} {}: ({t}, {y}) outside [{t0}, {t1}] × [{lo}, {hi}]",
                        f.name,
                        l.label
                    );
                }
            }
        }
    }
}

/// Draws each figure into `dir` and counts the pixels of a line colour outside every panel's
/// plotting area (grown by 2 px for the stroke): lines must stay inside their axes.
fn check_drawn_inside_axes(figs: &[Figure], dir: &Path) {
    register_font().unwrap();
    for f in figs {
        let path = dir.join(format!("drawn_{}", f.name));
        let areas = draw(&path, f).unwrap();
        assert_eq!(areas.len(), f.panels.len());
        let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        let bpp = info.line_size / info.width as usize;
        let colours: Vec<[u8; 3]> = COLORS.iter().map(|c| [c.0, c.1, c.2]).collect();
        let mut outside = Vec::new();
        for (i, p) in buf[..info.buffer_size()].chunks(bpp).enumerate() {
            if !colours.iter().any(|c| p[..3] == c[..]) {
                continue;
            }
            let (x, y) = (
                (i as u32 % info.width) as i32,
                (i as u32 / info.width) as i32,
            );
            let inside = areas.iter().any(|(xs, ys)| {
                (xs.start - 2..xs.end + 2).contains(&x) && (ys.start - 2..ys.end + 2).contains(&y)
            });
            if !inside {
                outside.push((x, y));
            }
        }
        assert!(
            outside.is_empty(),
            "{}: {} line pixels outside the axes, e.g. {:?}",
            f.name,
            outside.len(),
            &outside[..outside.len().min(5)]
        );
    }
}

/// Simulates `config` with `extra` appended, and returns the CSV's path.
fn simulate(name: &str, config: &str, extra: &str, duration_s: &str, log_s: &str) -> PathBuf {
    let dir = tmp(name);
    std::fs::create_dir_all(&dir).unwrap();
    let base = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(config)).unwrap();
    let cfg = dir.join("run.toml");
    std::fs::write(&cfg, format!("{base}\n{extra}")).unwrap();
    let csv = dir.join("run.csv");
    let r = flexdyn(&[
        "simulate",
        "--config",
        cfg.to_str().unwrap(),
        "--duration-s",
        duration_s,
        "--log-every-s",
        log_s,
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    csv
}

#[test]
fn conservation_shows_each_invariant_on_its_own_scale_and_marks_external_torque() {
    // The reference spacecraft in orbit, a 1 N·m torque about z from 2 s to 4 s. A torque
    // changes the rotational angular momentum about C by up to |τ|·2 s = 2 N·m·s, and leaves
    // the CoM's orbit (the orbital momentum m r_C × v_C) alone; the sum of the two is
    // dominated by the orbit (~1e13 kg·m²/s), where the change would be invisible (~1e-13).
    let csv = simulate(
        "torque",
        "scenarios/reference.toml",
        "[[wrench_schedule]]\nt_s = 2.0\nforce_b_newton = [0.0, 0.0, 0.0]\ntorque_b_nm = [0.0, 0.0, 1.0]\n\n\
         [[wrench_schedule]]\nt_s = 4.0\nforce_b_newton = [0.0, 0.0, 0.0]\ntorque_b_nm = [0.0, 0.0, 0.0]\n",
        "6",
        "0.05",
    );
    let (figs, _) = figures(&args(&csv)).unwrap();
    check_axis_bounds(&figs);
    let c = find(&figs, "conservation.png");
    assert_eq!(c.panels.len(), 2);
    let h = &c.panels[1];
    assert!(h.log_y && h.y_label.contains("H"), "{}", h.y_label);
    let line = |label: &str| {
        h.lines
            .iter()
            .find(|l| l.label.starts_with(label))
            .unwrap_or_else(|| panic!("no {label} line"))
    };
    let max_after = |label: &str, t_min: f64, t_max: f64| {
        line(label)
            .points
            .iter()
            .filter(|(t, _)| (t_min..=t_max).contains(t))
            .fold(0.0_f64, |m, (_, y)| m.max(*y))
    };
    // Before the torque: everything conserved to integration accuracy.
    assert!(max_after("rotational H", 0.0, 2.0) < 1e-9);
    // After: the rotational momentum changed by a visible fraction of its own scale.
    let rot = max_after("rotational H", 4.0, 6.0);
    assert!(rot > 1e-3 && rot <= 2.0, "rotational H change {rot}");
    // The orbital momentum did not (the torque does not move the CoM).
    assert!(max_after("orbital H", 0.0, 6.0) < 1e-9);
    // The shading: exactly the torque's interval, to within a log interval.
    assert_eq!(h.spans.len(), 1, "{:?}", h.spans);
    let (a, b) = h.spans[0];
    assert!(
        (a - 2.0).abs() < 1e-9 && (b - 4.0).abs() < 0.05 + 1e-9,
        "{a}..{b}"
    );
    assert_eq!(h.spans, c.panels[0].spans);
}

#[test]
fn imu_figure_gives_each_imu_its_own_column() {
    // Two IMUs stacked in four rows left each panel too short for its labels, which ran over
    // the neighbouring panels. Now one column per IMU, two rows.
    let csv = simulate("imus", "scenarios/imu_tactical.toml", "", "20", "0.01");
    let (figs, _) = figures(&args(&csv)).unwrap();
    check_axis_bounds(&figs);
    // Drawn: the noisy specific force of 2001 samples per panel stays inside its axes (a 2 px
    // polyline's mitred joins reached up to 60 px past them).
    check_drawn_inside_axes(&figs, csv.parent().unwrap());
    let imu = find(&figs, "imu.png");
    assert_eq!(imu.columns, 2);
    assert_eq!(imu.panels.len(), 4);
    // Row-major: row 1 the rates of both IMUs, row 2 their specific forces.
    let captions: Vec<_> = imu
        .panels
        .iter()
        .map(|p| p.caption.clone().unwrap())
        .collect();
    assert_eq!(captions[0], captions[2]);
    assert_ne!(captions[0], captions[1]);
    assert!(imu.panels[0].y_label.contains("rad/s") && imu.panels[3].y_label.contains("m/s²"));
}

#[test]
fn a_simulate_csv_gives_the_state_figures_and_names_the_rest() {
    let dir = tmp("from_csv");
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("ref.csv");
    let r = flexdyn(&[
        "simulate",
        "--duration-s",
        "10",
        "--log-every-s",
        "0.05",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(r.status.success());
    let r = flexdyn(&["plot", csv.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    check_figures(
        &dir,
        &[
            "attitude.png",
            "rates.png",
            "panels.png",
            "wrench.png",
            "conservation.png",
        ],
    );
    for skipped in [
        "wheels.png",
        "actuators.png",
        "star_tracker.png",
        "imu.png",
        "magnetometer.png",
        "sun_sensors_coarse.png",
        "sun_sensors_fine.png",
        "timing.png",
    ] {
        assert!(err.contains(&format!("skipped {skipped}")), "{err}");
        assert!(!dir.join(skipped).exists());
    }

    // Not a state CSV: an error that names the file and the problem, exit code 2.
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "a,b\n1,2\n").unwrap();
    let r = flexdyn(&["plot", bad.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.csv") && err.contains("t_s"), "{err}");
}

/// A rod and a thruster driven by the input schedule: `actuators.png` shows the rod's dipole,
/// the thruster's firings (1 N while the valve is open, 0.03 s of each 0.1 s frame, no lag), its
/// pulse count (one per frame) and the propellant.
#[test]
fn the_actuator_figure_shows_dipoles_and_firings() {
    let dir = tmp("actuators");
    std::fs::create_dir_all(&dir).unwrap();
    let config = dir.join("actuators.toml");
    std::fs::write(
        &config,
        r#"panel_pairs = []
[simulation]
step_s = 0.001
frame_hz = 10.0
[gravity]
model = "none"
[hub]
mass_kg = 500.0
inertia_bc_b_kg_m2 = [[600.0, 0.0, 0.0], [0.0, 500.0, 0.0], [0.0, 0.0, 400.0]]
r_bcb_b_m = [0.0, 0.0, 0.0]
[initial]
r_bn_n_m = [0.0, 0.0, 0.0]
v_bn_n_m_s = [0.0, 0.0, 0.0]
sigma_bn = [0.0, 0.0, 0.0]
omega_bn_b_rad_s = [0.0, 0.0, 0.0]
[[magnetorquers]]
name = "mtq_x"
axis_b = [1.0, 0.0, 0.0]
r_mb_b_m = [0.5, 0.0, 0.0]
max_dipole_am2 = 100.0
[[thrusters]]
name = "thr1"
r_tb_b_m = [0.0, 0.0, 0.0]
force_axis_b = [1.0, 0.0, 0.0]
max_thrust_newton = 1.0
isp_s = 220.0
[[effector_input_schedule]]
t_s = 0.0
effector = "thr1"
inputs = [0.03]
[[effector_input_schedule]]
t_s = 1.0
effector = "mtq_x"
inputs = [60.0]
"#,
    )
    .unwrap();
    let csv = dir.join("actuators.csv");
    let r = flexdyn(&[
        "simulate",
        "--config",
        config.to_str().unwrap(),
        "--duration-s",
        "2",
        "--log-every-s",
        "0.01",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let r = flexdyn(&["plot", csv.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    check_figures(&dir, &["actuators.png"]);
    let (figs, _) = figures(&args(&csv)).unwrap();
    let a = find(&figs, "actuators.png");
    let labels: Vec<&str> = a.panels.iter().map(|p| p.lines[0].label.as_str()).collect();
    assert_eq!(labels, ["m mtq1", "F thr1", "pulses thr1", "used thr1"]);
    let dipole = &a.panels[0].lines[0].points;
    assert!(dipole
        .iter()
        .all(|&(t, m)| m == if t < 1.0 { 0.0 } else { 60.0 }));
    // Rows every 0.01 s: the valve is open in the first 3 of each frame's 10 rows.
    let thrust = &a.panels[1].lines[0].points;
    let on = thrust.iter().filter(|(_, f)| *f == 1.0).count();
    let off = thrust.iter().filter(|(_, f)| *f == 0.0).count();
    assert_eq!((on, off, thrust.len()), (60, 141, 201), "{thrust:?}");
    let pulses = &a.panels[2].lines[0].points;
    assert_eq!(pulses.last().unwrap().1, 20.0);
    let used = a.panels[3].lines[0].points.last().unwrap().1;
    let expected = 20.0 * 0.03 / (220.0 * 9.80665);
    assert!((used - expected).abs() < 1e-15, "{used} vs {expected}");
}

/// The LEO scenario's sun sensors (a six-detector array, a fine sensor) through `simulate` and
/// `plot`: both figures are drawn, the array's panel holds its six detectors' columns (not
/// the message's unused slots 7–16) and the fine sensor's its two angles and flags.
#[test]
fn sun_sensor_figures_from_a_simulate_csv() {
    let dir = tmp("sun_sensors");
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("leo.csv");
    let config = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/leo_environment.toml"
    );
    let r = flexdyn(&[
        "simulate",
        "--config",
        config,
        "--duration-s",
        "2",
        "--log-every-s",
        "0.1",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let r = flexdyn(&["plot", csv.to_str().unwrap(), "-o", dir.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    check_figures(&dir, &["sun_sensors_coarse.png", "sun_sensors_fine.png"]);
    let (figs, _) = figures(&args(&csv)).unwrap();
    // Issue 36: only the array's own six detectors (its detector_count), not the 10 unused
    // slots of the message.
    let coarse = find(&figs, "sun_sensors_coarse.png");
    assert_eq!(coarse.panels.len(), 1);
    let labels: Vec<&str> = coarse.panels[0]
        .lines
        .iter()
        .map(|l| l.label.as_str())
        .collect();
    assert_eq!(labels, ["1", "2", "3", "4", "5", "6"]);
    let lit: usize = coarse.panels[0]
        .lines
        .iter()
        .filter(|s| s.points.iter().any(|p| p.1 > 0.05))
        .count();
    assert!((1..=3).contains(&lit), "lit faces: {lit}");
    let fine = find(&figs, "sun_sensors_fine.png");
    assert_eq!(fine.panels.len(), 2);
}

/// `--relative-to`: a recording of two vehicles written here, the chief on a circular orbit of
/// radius R and the deputy held at a fixed offset ρ_H = (30, 100, −20) m in the chief's Hill
/// frame (its inertial state from `deputy_state_n`, the frame's own inverse). The figure must
/// show that offset, a zero rate seen in H and the constant range |ρ_H|, at every recorded
/// instant; then the bad uses are errors naming the flag or the file.
#[test]
fn relative_motion_shows_the_deputy_in_the_chiefs_hill_frame() {
    use flexdyn_proto::{encode, Header, StateMsg};
    use flexdyn_sinks::mcap_file::{McapSink, RecordingInfo};
    use flexdyn_vehicle::world::relative::deputy_state_n;
    use nalgebra::Vector3;

    let rec = tmp("pair.mcap");
    let info = RecordingInfo {
        recorder: "tests/cli/plots.rs".into(),
        command_line: String::new(),
    };
    let mut sink = McapSink::create(&rec, &info).unwrap();
    let (r_m, mu): (f64, f64) = (7.0e6, 3.986004418e14);
    let n = (mu / (r_m * r_m * r_m)).sqrt();
    let offset_h = Vector3::new(30.0, 100.0, -20.0);
    for k in 0..50u64 {
        let t_ns = k * 10_000_000_000;
        let th = n * t_ns as f64 * 1e-9;
        let rc = Vector3::new(r_m * th.cos(), r_m * th.sin(), 0.0);
        let vc = Vector3::new(-r_m * n * th.sin(), r_m * n * th.cos(), 0.0);
        let (rd, vd) = deputy_state_n(&rc, &vc, &offset_h, &Vector3::zeros()).unwrap();
        for (id, num, r, v) in [("chief", 1, rc, vc), ("deputy", 2, rd, vd)] {
            let m = StateMsg {
                header: Header::new(num, k, t_ns, k),
                r_bn_n_m: r.into(),
                v_bn_n_m_s: v.into(),
                ..StateMsg::default()
            };
            let key = format!("flexdyn/{id}/tlm/state");
            sink.write(&key, &encode(&m), None, t_ns).unwrap();
        }
    }
    sink.finish().unwrap();

    let mut a = args(&rec);
    a.sc_id = Some("deputy".into());
    a.relative_to = Some("chief".into());
    let (figs, _) = figures(&a).unwrap();
    let f = find(&figs, "relative_motion.png");
    let [pos, rate, range, range_rate] = &f.panels[..] else {
        panic!("four panels, got {}", f.panels.len())
    };
    for (k, want) in offset_h.iter().enumerate() {
        let pts = &pos.lines[k].points;
        assert_eq!(pts.len(), 50);
        for (t, x) in pts {
            assert!(
                (x - want).abs() < 1e-6,
                "axis {k} at {t} s: {x} m, want {want}"
            );
        }
        // ρ' = C_HN (v_d − v_c) − ω × ρ: zero for a fixed offset, up to rounding of 7e3 m/s.
        assert!(rate.lines[k].points.iter().all(|(_, v)| v.abs() < 1e-8));
    }
    let norm = offset_h.norm();
    assert!(range.lines[0]
        .points
        .iter()
        .all(|(_, r)| (r - norm).abs() < 1e-6));
    assert!(range_rate.lines[0]
        .points
        .iter()
        .all(|(_, v)| v.abs() < 1e-8));
    check_axis_bounds(std::slice::from_ref(f));

    // Without --relative-to there is no such figure; the CLI draws it with.
    let (figs, _) = figures(&args(&rec)).unwrap();
    assert!(figs.iter().all(|f| f.name != "relative_motion.png"));
    plot_relative_motion(&rec, "relative_png");

    // Errors: the plotted vehicle itself, a vehicle not in the file, a CSV.
    a.relative_to = Some("deputy".into());
    let e = figures(&a).err().unwrap().to_string();
    assert!(
        e.contains("--relative-to") && e.contains("the plotted vehicle itself"),
        "{e}"
    );
    a.relative_to = Some("nobody".into());
    let e = figures(&a).err().unwrap().to_string();
    assert!(
        e.contains("pair.mcap") && e.contains("no StateMsg of spacecraft \"nobody\""),
        "{e}"
    );
    let mut c = args(Path::new("x.csv"));
    c.relative_to = Some("chief".into());
    let e = figures(&c).err().unwrap().to_string();
    assert!(
        e.contains("--relative-to") && e.contains("needs a recording"),
        "{e}"
    );
}

/// Issue 36: the title of `relative_motion.png` from a fleet recording (its RelativeStateMsg)
/// ran off both edges of the image. A recording of the deputy's RelativeStateMsg relative to
/// the chief (and the chief's states) is plotted, and the title band has no ink at either edge
/// ([`check_figures`]).
#[test]
fn the_recorded_relative_motion_title_fits_the_figure() {
    use flexdyn_proto::{encode, Header, RelativeStateMsg, StateMsg};
    use flexdyn_sinks::mcap_file::{McapSink, RecordingInfo};

    let rec = tmp("rel_recorded.mcap");
    let info = RecordingInfo {
        recorder: "tests/cli/plots.rs".into(),
        command_line: String::new(),
    };
    let mut sink = McapSink::create(&rec, &info).unwrap();
    for k in 0..50u64 {
        let t_ns = k * 10_000_000_000;
        for id in ["chief", "deputy"] {
            let m = StateMsg {
                header: Header::new(1, k, t_ns, k),
                r_bn_n_m: [7.0e6, 0.0, 0.0],
                v_bn_n_m_s: [0.0, 7.5e3, 0.0],
                ..StateMsg::default()
            };
            sink.write(&format!("flexdyn/{id}/tlm/state"), &encode(&m), None, t_ns)
                .unwrap();
        }
        let rel = RelativeStateMsg {
            header: Header::new(2, k, t_ns, k),
            r_dc_h_m: [30.0, 100.0 + k as f64, -20.0],
            v_dc_h_m_s: [0.0, 0.1, 0.0],
            range_m: 100.0 + k as f64,
            range_rate_m_s: 0.1,
            ..RelativeStateMsg::default()
        };
        sink.write("flexdyn/deputy/tlm/rel/chief", &encode(&rel), None, t_ns)
            .unwrap();
    }
    sink.finish().unwrap();
    plot_relative_motion(&rec, "rel_recorded_png");
    let mut a = args(&rec);
    a.sc_id = Some("deputy".into());
    a.relative_to = Some("chief".into());
    let (figs, _) = figures(&a).unwrap();
    let title = &find(&figs, "relative_motion.png").title;
    register_font().unwrap();
    let px = flexdyn_sinks::plot::title_font_px(title);
    let width = flexdyn_sinks::plot::text_width_px(title, px);
    assert!(width <= 1200 - 20, "{title:?}: {width} px at {px} px");
}

/// Fault 0: the IMU's gyro biased from 0.5 s for 0.3 s; fault 1: wheel rw2 seized from 0.7 s
/// to the end (`scenarios/wheels_star_tracker.toml`: IMU `hub`, wheels rw1–rw4).
const FAULTS: &str = "[[faults]]\ntarget = \"imus.hub.gyro\"\nmode = \"bias_step\"\nvalue = 0.25\n\
                      start_s = 0.5\nduration_s = 0.3\n\n\
                      [[faults]]\ntarget = \"reaction_wheels.rw2\"\nmode = \"seized\"\nstart_s = 0.7\n";

/// The panels of `figs` with fault shading, as (figure, caption or y label, [(label, spans)]).
type Shaded<'a> = Vec<(&'a str, String, PanelShading<'a>)>;
fn shaded(figs: &[Figure]) -> Shaded<'_> {
    figs.iter()
        .flat_map(|f| {
            f.panels.iter().filter(|p| !p.faults.is_empty()).map(|p| {
                (
                    f.name.as_str(),
                    p.caption.clone().unwrap_or_else(|| p.y_label.clone()),
                    p.faults
                        .iter()
                        .map(|s| (s.label.as_str(), s.spans.as_slice()))
                        .collect(),
                )
            })
        })
        .collect()
}

/// Checks that exactly the IMU's two panels carry `gyro` and the three wheel panels `wheel`,
/// and nothing else is shaded.
fn check_fault_panels(figs: &[Figure], gyro: &[(f64, f64)], wheel: &[(f64, f64)]) {
    let got = shaded(figs);
    let want_gyro = ("fault 0: imus.hub.gyro bias_step", gyro);
    let want_wheel = ("fault 1: reaction_wheels.rw2 seized", wheel);
    let imu: Vec<_> = got.iter().filter(|g| g.0 == "imu.png").collect();
    assert_eq!(imu.len(), 2, "{got:?}");
    for g in &imu {
        assert_eq!(g.1, "IMU hub");
        assert_eq!(g.2, vec![want_gyro], "{got:?}");
    }
    let wheels: Vec<_> = got.iter().filter(|g| g.0 == "wheels.png").collect();
    assert_eq!(wheels.len(), 3, "{got:?}");
    for g in &wheels {
        assert_eq!(g.2, vec![want_wheel], "{got:?}");
    }
    // Nothing else: the truth (attitude, rates, panels, invariants), the commanded wrench and
    // the star tracker show neither component.
    assert_eq!(got.len(), 5, "{got:?}");
}

/// The pixels of fault `index`'s shading over the white background (fault colour at its
/// alpha), as the x extent (first, last column) in the lower part of panel `area`.
fn shading_columns(
    path: &Path,
    area: &(std::ops::Range<i32>, std::ops::Range<i32>),
    index: u32,
) -> (i32, i32) {
    use flexdyn_sinks::plot::{fault_color, FAULT_ALPHA};
    let c = fault_color(index);
    let blend = |v: u8| 255.0 * (1.0 - FAULT_ALPHA) + f64::from(v) * FAULT_ALPHA;
    let want = [blend(c.0), blend(c.1), blend(c.2)];
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bpp = info.line_size / info.width as usize;
    let (mut lo, mut hi) = (i32::MAX, i32::MIN);
    for (i, p) in buf[..info.buffer_size()].chunks(bpp).enumerate() {
        let (x, y) = (
            (i as u32 % info.width) as i32,
            (i as u32 / info.width) as i32,
        );
        // The bottom fifth of the plotting area: clear of the legend (upper right), whose key
        // has the shading's colour too.
        let bottom = area.1.end - (area.1.end - area.1.start) / 5..area.1.end;
        if !(area.0.contains(&x) && bottom.contains(&y)) {
            continue;
        }
        if (0..3).all(|k| (f64::from(p[k]) - want[k]).abs() <= 2.0) {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    (lo, hi)
}

/// `flexdyn simulate` writes each fault's window as a `# fault=` line; `plot` shades, on the
/// faulted components' panels only, exactly the configured intervals, and draws them where the
/// panel's time axis puts them.
#[test]
fn a_simulate_csv_shades_each_fault_on_its_components_panels() {
    let csv = simulate(
        "faults_csv",
        "scenarios/wheels_star_tracker.toml",
        FAULTS,
        "1.2",
        "0.01",
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let comments: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
    assert_eq!(
        comments,
        [
            "# fault=0,500000000,300000000,,bias_step,imus.hub.gyro",
            "# fault=1,700000000,,,seized,reaction_wheels.rw2"
        ]
    );
    let (figs, _) = figures(&args(&csv)).unwrap();
    check_fault_panels(&figs, &[(0.5, 0.8)], &[(0.7, 1.2)]);

    // Drawn: the shading's pixels span [0.5 s, 0.8 s] of the IMU rate panel's time axis.
    let imu = find(&figs, "imu.png");
    let dir = csv.parent().unwrap();
    register_font().unwrap();
    let areas = draw(&dir.join("imu.png"), imu).unwrap();
    let (t0, t1) = imu.panels[0].t_range();
    let xs = &areas[0].0;
    let px = |t: f64| xs.start as f64 + (t - t0) / (t1 - t0) * f64::from(xs.end - xs.start - 1);
    let (lo, hi) = shading_columns(&dir.join("imu.png"), &areas[0], 0);
    assert!(
        (f64::from(lo) - px(0.5)).abs() <= 2.0 && (f64::from(hi) - px(0.8)).abs() <= 2.0,
        "shading at columns {lo}..{hi}, expected {:.1}..{:.1}",
        px(0.5),
        px(0.8)
    );
    // And the figures through the command line.
    let out = dir.join("figures");
    let r = flexdyn(&["plot", csv.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    check_figures(&out, &["imu.png", "wheels.png"]);

    // A damaged fault line is an error naming the file and the line.
    let bad = dir.join("bad.csv");
    std::fs::write(
        &bad,
        text.replacen("# fault=0,500000000", "# fault=0,-5", 1),
    )
    .unwrap();
    let e = figures(&args(&bad)).err().unwrap().to_string();
    assert!(
        e.contains("bad.csv") && e.contains("line 1") && e.contains("start_ns"),
        "{e}"
    );
}

/// A recording: the shading comes from the fault events (a repeating gyro fault and a wheel
/// seized to the end of the run), on the same panels as from a CSV.
#[test]
fn a_recording_shades_each_fault_from_its_events() {
    let dir = tmp("faults_mcap");
    // The gyro fault repeats: on at 0.1 s for 0.05 s, every 0.2 s.
    let faults = FAULTS
        .replace(
            "start_s = 0.5\nduration_s = 0.3",
            "start_s = 0.1\nduration_s = 0.05\nperiod_s = 0.2",
        )
        .replace("start_s = 0.7", "start_s = 0.25");
    let rec = record_faulty_run(&dir, &faults);
    let (figs, _) = figures(&args(&rec)).unwrap();
    // The last activation (0.5 s) is cleared at 0.55 s; the wheel stays seized to the last
    // state, at 0.6 s.
    check_fault_panels(
        &figs,
        &[(0.1, 0.15), (0.3, 0.35), (0.5, 0.55)],
        &[(0.25, 0.6)],
    );
    let out = dir.join("figures");
    let r = flexdyn(&["plot", rec.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    check_figures(&out, &["imu.png", "wheels.png"]);
    // `flexdyn export` carries the events into the state CSV (`# fault=` lines, one per
    // activation): the same shading from it, with the IMU's columns absent (wheels only).
    let (figs, _) = figures(&args(&export_state_csv(&rec, &dir.join("csv")))).unwrap();
    let wheels: Vec<_> = shaded(&figs)
        .into_iter()
        .filter(|g| g.0 == "wheels.png")
        .collect();
    assert_eq!(wheels.len(), 3);
    for g in &wheels {
        assert_eq!(
            g.2,
            vec![("fault 1: reaction_wheels.rw2 seized", &[(0.25, 0.6)][..])]
        );
    }
}

/// A 0.6 s batch run of `scenarios/wheels_star_tracker.toml` with `faults` appended, recorded
/// (`flexdyn run --record`) into `dir/run.mcap`, which is returned.
fn record_faulty_run(dir: &Path, faults: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/wheels_star_tracker.toml"),
    )
    .unwrap();
    let cfg = dir.join("run.toml");
    std::fs::write(&cfg, format!("{base}\n{faults}")).unwrap();
    let rec = dir.join("run.mcap");
    let status = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["run", "--mode", "batch", "--duration-s", "0.6"])
        .args(["--listen", ports::ANY_PORT, "--config"])
        .arg(&cfg)
        .arg("--record")
        .arg(&rec)
        .status()
        .unwrap();
    assert!(status.success());
    rec
}

/// `flexdyn export REC --csv DIR`; returns the path of vehicle sc1's state CSV.
fn export_state_csv(rec: &Path, dir: &Path) -> PathBuf {
    let r = flexdyn(&[
        "export",
        rec.to_str().unwrap(),
        "--csv",
        dir.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    dir.join("flexdyn_sc1_tlm_state.csv")
}

/// What `flexdyn record` started at `from_ns` into the recorded run `rec` would have written
/// into `out`: each vehicle's description (its configuration replaced by `config` of it), then
/// every sample from `from_ns` on, through the recorder's own writer.
fn record_from(rec: &Path, from_ns: u64, out: &Path, config: impl Fn(&str) -> String) {
    use flexdyn_sinks::mcap_file::{McapSink, RecordingInfo};
    let r = flexdyn_sinks::reader::read_recording(rec).unwrap();
    assert!(r.truncated.is_none());
    let info = RecordingInfo {
        recorder: "flexdyn record".into(),
        command_line: format!("(the samples of {} from {from_ns} ns on)", rec.display()),
    };
    let mut sink = McapSink::create(out, &info).unwrap();
    let vehicles = r.vehicles();
    assert!(!vehicles.is_empty());
    for mut v in vehicles {
        v.config_toml = config(&v.config_toml);
        sink.describe_vehicle(&v).unwrap();
    }
    for s in r.samples.iter().filter(|s| s.log_time_ns >= from_ns) {
        sink.write(
            &s.key,
            &s.payload,
            Some(s.publish_time_ns),
            s.publish_time_ns,
        )
        .unwrap();
    }
    sink.finish().unwrap();
}

/// A panel's shading: its faults' (label, spans).
type PanelShading<'a> = Vec<(&'a str, &'a [(f64, f64)])>;

/// The shaded panels of figure `name`: (caption or y label, its shading).
fn shaded_in<'a>(figs: &'a [Figure], name: &str) -> Vec<(String, PanelShading<'a>)> {
    shaded(figs)
        .into_iter()
        .filter(|g| g.0 == name)
        .map(|g| (g.1, g.2))
        .collect()
}

/// A recording started at 0.3 s, after three configured faults fired: the gyro bias of
/// [0.1 s, 0.5 s), a star-tracker fault repeating on [0.05 s + k·0.4 s, +0.3 s), and wheel
/// rw2 seized from 0.2 s on. The recorder saw none of their activations (only the gyro's and
/// the current star-tracker activation's clearances, the next star-tracker activation, and
/// StatusMsg's active set), yet `plot` shades each from its window's true start — to its
/// clearance, or to the end of the data — on its own panels only, and `export` writes the same
/// intervals, which `plot` shades again from the CSV. Without the inference the gyro and
/// star-tracker intervals start at 0.3 s and the wheel is not shaded at all.
#[test]
fn faults_active_before_the_recording_are_shaded_from_their_true_start() {
    let dir = tmp("faults_before_recording");
    let wheel_fault =
        "[[faults]]\ntarget = \"reaction_wheels.rw2\"\nmode = \"seized\"\nstart_s = 0.2\n";
    let faults = format!(
        "[[faults]]\ntarget = \"imus.hub.gyro\"\nmode = \"bias_step\"\nvalue = 0.25\n\
         start_s = 0.1\nduration_s = 0.4\n\n\
         [[faults]]\ntarget = \"star_trackers.st1\"\nmode = \"validity_off\"\n\
         start_s = 0.05\nduration_s = 0.3\nperiod_s = 0.4\n\n{wheel_fault}"
    );
    let full = record_faulty_run(&dir, &faults);
    let late = dir.join("late.mcap");
    record_from(&full, 300_000_000, &late, str::to_owned);

    // From the recording: the data span [0.3 s, 0.6 s]; each fault from its window's start.
    let (figs, _) = figures(&args(&late)).unwrap();
    let gyro = (
        "fault 0: imus.hub.gyro bias_step (on since 0.1 s, before the data)",
        &[(0.1, 0.5)][..],
    );
    let st = (
        "fault 1: star_trackers.st1 validity_off (on since 0.05 s, before the data)",
        &[(0.05, 0.35), (0.45, 0.6)][..],
    );
    let wheel = (
        "fault 2: reaction_wheels.rw2 seized (on since 0.2 s, before the data)",
        &[(0.2, 0.6)][..],
    );
    let got = shaded(&figs);
    let imu = shaded_in(&figs, "imu.png");
    assert_eq!(imu.len(), 2, "{got:?}");
    assert!(
        imu.iter().all(|g| g.0 == "IMU hub" && g.1 == [gyro]),
        "{got:?}"
    );
    let trackers = shaded_in(&figs, "star_tracker.png");
    assert!(!trackers.is_empty(), "{got:?}");
    assert!(trackers.iter().all(|g| g.1 == [st]), "{got:?}");
    let wheels = shaded_in(&figs, "wheels.png");
    assert_eq!(wheels.len(), 3, "{got:?}");
    assert!(wheels.iter().all(|g| g.1 == [wheel]), "{got:?}");
    assert_eq!(
        got.len(),
        5 + trackers.len(),
        "nothing else is shaded: {got:?}"
    );

    // `export`: one line per activation, the missed ones with their inferred starts.
    let state_csv = export_state_csv(&late, &dir.join("csv"));
    let text = std::fs::read_to_string(&state_csv).unwrap();
    let lines: Vec<&str> = text
        .lines()
        .take_while(|l| l.starts_with('#'))
        .filter(|l| l.starts_with("# fault="))
        .collect();
    assert_eq!(
        lines,
        [
            "# fault=1,50000000,300000000,,validity_off,star_trackers.st1",
            "# fault=0,100000000,400000000,,bias_step,imus.hub.gyro",
            "# fault=1,450000000,,,validity_off,star_trackers.st1",
            "# fault=2,200000000,,,seized,reaction_wheels.rw2",
        ]
    );
    // The state CSV has the wheels (not the sensors): the same wheel shading from it.
    let (figs, _) = figures(&args(&state_csv)).unwrap();
    let got = shaded(&figs);
    let wheels = shaded_in(&figs, "wheels.png");
    assert_eq!(wheels.len(), 3, "{got:?}");
    assert!(wheels.iter().all(|g| g.1 == [wheel]), "{got:?}");
    assert_eq!(got.len(), 3, "{got:?}");

    // Drawn from the axis' start: the wheel speed panel's shading covers [0.3 s, 0.6 s].
    let w = find(&figs, "wheels.png");
    register_font().unwrap();
    let png = dir.join("wheels.png");
    let areas = draw(&png, w).unwrap();
    let (t0, t1) = w.panels[0].t_range();
    assert_eq!((t0, t1), (0.3, 0.6));
    let (lo, hi) = shading_columns(&png, &areas[0], 2);
    let xs = &areas[0].0;
    assert!(
        (lo - xs.start).abs() <= 2 && (hi - (xs.end - 1)).abs() <= 2,
        "shading at columns {lo}..{hi}, the axis spans {xs:?}"
    );

    // The same recording, described by a configuration without the wheel's entry: fault 2
    // is then a live fault injected before the recording, and no event of it names its
    // target. It is shaded from the first state on the attitude figure only, as unknown.
    let live = dir.join("live.mcap");
    record_from(&full, 300_000_000, &live, |c| {
        let cut = c.rfind(wheel_fault).expect("the wheel's entry");
        c[..cut].to_owned()
    });
    let unknown = (
        "fault 2: live, injected before the recording (target unknown)",
        &[(0.3, 0.6)][..],
    );
    let (figs, _) = figures(&args(&live)).unwrap();
    let got = shaded(&figs);
    assert!(shaded_in(&figs, "wheels.png").is_empty(), "{got:?}");
    assert_eq!(
        shaded_in(&figs, "attitude.png"),
        [("σ_BN (MRP, –)".to_owned(), vec![unknown])]
    );
    assert_eq!(got.len(), 3 + trackers.len(), "{got:?}");
    let state_csv = export_state_csv(&live, &dir.join("csv_live"));
    let text = std::fs::read_to_string(&state_csv).unwrap();
    assert!(
        text.contains("\n# fault=2,300000000,,,live,\n"),
        "{text:.600}"
    );
    let (figs, _) = figures(&args(&state_csv)).unwrap();
    assert_eq!(
        shaded_in(&figs, "attitude.png"),
        [("σ_BN (MRP, –)".to_owned(), vec![unknown])]
    );
    assert_eq!(shaded(&figs).len(), 1);
}

/// `flexdyn plot REC -o <tmp OUT> --sc-id deputy --relative-to chief` succeeds and writes a
/// well-formed `relative_motion.png` ([`check_figures`]).
pub(crate) fn plot_relative_motion(rec: &Path, out: &str) {
    let out = tmp(out);
    let r = flexdyn(&[
        "plot",
        rec.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--sc-id",
        "deputy",
        "--relative-to",
        "chief",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    check_figures(&out, &["relative_motion.png"]);
}
