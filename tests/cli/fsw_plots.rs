//! The flight code's own telemetry in `flexdyn plot` and `flexdyn export` (issue 37), on a
//! recording built here with known answers: the truth turns about b3 at 0.01 rad per tick, the
//! flight code's target leads it by 2 mrad, its estimate is off by 1 mrad about b1, it reports
//! variances (1, 4, 9) µrad², switches mode at tick 20 and raises an event at tick 10.
//!
//! Checked against the closed forms: the pointing error against the flight code's target is
//! 2 mrad at every tick, the estimation error is 1 mrad about b1 and zero about b2 and b3, the
//! 3σ bounds are 3, 6 and 9 mrad; the mode timeline shades each mode over exactly its ticks and
//! marks the event; the declared values are drawn as sent; a declared stream with no samples is
//! skipped by name. `flexdyn export` writes the stream's names and typed values after the wire
//! columns. Drawn to PNG too.

use std::path::{Path, PathBuf};

use flexdyn_proto::{encode, fsw_flags, FswMsg, Header, StateMsg};
use flexdyn_sinks::plot::{figures, plot, Figure, PlotArgs};

const FRAME_NS: u64 = 100_000_000;
const TICKS: u64 = 40;

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("fsw_plots")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.parent().unwrap()).unwrap();
    d
}

/// q of a rotation by `angle` about body axis `axis` (scalar first).
fn q_axis(axis: usize, angle: f64) -> [f64; 4] {
    let mut q = [(angle / 2.0).cos(), 0.0, 0.0, 0.0];
    q[1 + axis] = (angle / 2.0).sin();
    q
}

/// The Hamilton product q₁ ⊗ q₂ (scalar first). For attitude quaternions (the DCM's
/// quaternion) it composes in the other order: [C(q₁ ⊗ q₂)] = [C(q₂)][C(q₁)], so
/// q(FN) = q(BN) ⊗ q(FB).
fn compose(q1: [f64; 4], q2: [f64; 4]) -> [f64; 4] {
    let [a0, a1, a2, a3] = q1;
    let [b0, b1, b2, b3] = q2;
    [
        a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
        a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
        a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
        a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0,
    ]
}

const STREAMS: &str = r#"
[[fsw_streams]]
name = "acs"
modes = ["detumble", "point"]
events = [{ name = "gyro-failure", severity = "error" }]
values = [
  { name = "h_b_nms", type = "f64", len = 2, unit = "N·m·s" },
  { name = "count", type = "i64" },
  { name = "ok", type = "bool" },
]

[[fsw_streams]]
name = "nav"
"#;

/// The recording, written to `name` (one per test: the tests run at once).
fn recording(name: &str) -> PathBuf {
    let rec = tmp(name);
    let config_toml = format!(
        "{}\n{STREAMS}",
        flexdyn_vehicle::config::DEFAULT_CONFIG_TOML
    );
    let mut sink = crate::mcap_support::sink_for(&rec, &config_toml);
    for k in 0..TICKS {
        let t_ns = k * FRAME_NS;
        let theta = 0.01 * k as f64;
        let q_bn = q_axis(2, theta);
        let state = StateMsg {
            header: Header::new(1, k, t_ns, k),
            q_bn,
            ..StateMsg::default()
        };
        sink.write("flexdyn/sc1/tlm/state", &encode(&state), None, t_ns)
            .unwrap();
        let mut m = FswMsg {
            header: Header::new(1, k, t_ns, k),
            flags: fsw_flags::MODE
                | fsw_flags::ESTIMATE
                | fsw_flags::TARGET
                | fsw_flags::COVARIANCE,
            mode: u32::from(k >= 20),
            // The estimate: the truth, then 1 mrad about b1 ([B̂N] = [B̂B][BN]).
            q_est_bn: compose(q_bn, q_axis(0, 1e-3)),
            q_target_rn: q_axis(2, theta + 2e-3),
            att_var_b_rad2: [1e-6, 4e-6, 9e-6],
            values: vec![
                (k as f64).to_bits(),
                (-(k as f64) * 0.5).to_bits(),
                (-(k as i64)) as u64,
                k % 2,
            ],
            ..FswMsg::default()
        };
        if k == 10 {
            m.event_count = 1;
        }
        sink.write("flexdyn/sc1/fsw/acs", &encode(&m), None, t_ns)
            .unwrap();
    }
    sink.finish().unwrap();
    rec
}

fn args(input: &Path, output: &Path) -> PlotArgs {
    PlotArgs {
        input: input.to_owned(),
        output: output.to_owned(),
        sc_id: None,
        sigma_rn: None,
        relative_to: None,
    }
}

fn find<'a>(figs: &'a [Figure], name: &str) -> &'a Figure {
    figs.iter().find(|f| f.name == name).unwrap_or_else(|| {
        panic!(
            "no {name} in {:?}",
            figs.iter().map(|f| &f.name).collect::<Vec<_>>()
        )
    })
}

/// \[s\] tick k's time, as every sink computes it.
fn t(k: u64) -> f64 {
    (k * FRAME_NS) as f64 / 1e9
}

fn close(got: f64, want: f64, what: &str) {
    assert!((got - want).abs() < 1e-9, "{what}: {got}, want {want}");
}

#[test]
fn the_flight_codes_telemetry_is_plotted_against_the_truth() {
    let rec = recording("plot.mcap");
    let out = tmp("png");
    let (figs, skipped) = figures(&args(&rec, &out)).unwrap();

    // The mode timeline under the attitude: each mode shaded over its ticks, the event marked.
    let att = find(&figs, "attitude.png");
    let timeline = att.panels.last().unwrap();
    assert_eq!(timeline.bands.len(), 3, "two modes and one event");
    assert_eq!(timeline.bands[0].label, "0: detumble");
    assert_eq!(timeline.bands[0].spans, [(t(0), t(20))]);
    assert_eq!(timeline.bands[1].label, "1: point");
    assert_eq!(timeline.bands[1].spans, [(t(20), t(TICKS - 1))]);
    assert_eq!(timeline.bands[2].label, "event gyro-failure (error) ×1");
    assert_eq!(timeline.bands[2].spans.len(), 1);
    assert_eq!(timeline.bands[2].spans[0].0, t(10));
    let modes: Vec<f64> = timeline.lines[0].points.iter().map(|p| p.1).collect();
    assert_eq!(modes.len() as u64, TICKS);
    assert!(modes[..20].iter().all(|&m| m == 0.0) && modes[20..].iter().all(|&m| m == 1.0));

    // Pointing against the flight code's own target: 2 mrad; estimation: 1 mrad.
    let f = find(&figs, "fsw_acs.png");
    let [_, pointing, estimation] = &f.panels[..] else {
        panic!("three panels, got {}", f.panels.len())
    };
    for (t_s, e) in &pointing.lines[0].points {
        close(
            *e,
            2e-3_f64.to_degrees(),
            &format!("pointing error at {t_s} s"),
        );
    }
    for (t_s, e) in &estimation.lines[0].points {
        close(
            *e,
            1e-3_f64.to_degrees(),
            &format!("estimation error at {t_s} s"),
        );
    }
    assert_eq!(pointing.lines[0].points.len() as u64, TICKS);

    // About each axis, with ±3σ from the variances.
    let est = find(&figs, "fsw_acs.estimation.png");
    for (axis, (want, sigma)) in [(1e-3_f64, 1e-3_f64), (0.0, 2e-3), (0.0, 3e-3)]
        .into_iter()
        .enumerate()
    {
        let p = &est.panels[axis];
        for (_, e) in &p.lines[0].points {
            close(e.abs(), want.to_degrees(), &format!("axis {}", axis + 1));
        }
        for (_, b) in &p.lines[1].points {
            close(
                *b,
                3.0 * sigma.to_degrees(),
                &format!("+3σ about b{}", axis + 1),
            );
        }
        for (_, b) in &p.lines[2].points {
            close(
                *b,
                -3.0 * sigma.to_degrees(),
                &format!("−3σ about b{}", axis + 1),
            );
        }
    }

    // The declared values, as sent.
    let v = find(&figs, "fsw_acs.values.png");
    assert_eq!(v.panels.len(), 3);
    assert_eq!(v.panels[0].y_label, "h_b_nms (N·m·s)");
    assert_eq!(v.panels[0].lines[1].label, "h_b_nms[1]");
    assert_eq!(v.panels[0].lines[1].points[7], (t(7), -3.5));
    assert_eq!(v.panels[1].lines[0].points[7].1, -7.0);
    assert_eq!(v.panels[2].lines[0].points[7].1, 1.0);

    // A declared stream without samples is skipped by name.
    assert!(
        skipped
            .iter()
            .any(|(name, why)| name == "fsw_nav.png" && why.contains("no sample")),
        "{skipped:?}"
    );

    // Drawn.
    let report = plot(&args(&rec, &out)).unwrap();
    for name in [
        "attitude.png",
        "fsw_acs.png",
        "fsw_acs.estimation.png",
        "fsw_acs.values.png",
    ] {
        assert!(
            report.written.contains(&out.join(name)),
            "{name}: {report:?}"
        );
        assert!(
            std::fs::metadata(out.join(name)).unwrap().len() > 10_000,
            "{name}"
        );
    }
}

#[test]
fn export_names_the_flight_codes_values() {
    let rec = recording("export.mcap");
    let dir = tmp("csv");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["export", "--csv"])
        .arg(&dir)
        .arg(&rec)
        .status()
        .unwrap();
    assert!(status.success());
    let text = std::fs::read_to_string(dir.join("flexdyn_sc1_fsw_acs.csv")).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len() as u64, TICKS);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    // The wire columns stay, the names follow.
    assert_eq!(rows[25][col("mode")], "1");
    assert_eq!(rows[25][col("mode_name")], "point");
    assert_eq!(rows[10][col("event_names")], "gyro-failure");
    assert_eq!(rows[11][col("event_names")], "");
    assert_eq!(rows[7][col("v_h_b_nms[0]")], "7");
    assert_eq!(rows[7][col("v_h_b_nms[1]")], "-3.5");
    assert_eq!(rows[7][col("v_count")], "-7");
    assert_eq!(rows[7][col("v_ok")], "1");
    assert_eq!(rows[8][col("v_ok")], "0");
    assert!(col("values_1") < col("mode_name"));
}
