//! `flexdyn plot INPUT --output DIR`: PNG figures of a recording (`.mcap`) or of a
//! `flexdyn simulate` / `flexdyn export` CSV, with the `plotters` crate.
//!
//! Figures (each skipped, and said so, when the input lacks its data):
//! - `attitude.png`: σ_BN, and the attitude error σ_BR with |σ_BR| when `--sigma-rn` gives the
//!   target;
//! - `rates.png`: ω_BN;
//! - `panels.png`: θ1 and θ2 of each pair;
//! - `wrench.png`: the commanded torque and force held over each frame, and the command flags;
//! - `conservation.png`: relative drift of total energy and angular momentum, log axis (these
//!   are constant only without external wrench, damping or motor torques);
//! - `imu.png`: each IMU's measured rate and specific force;
//! - `timing.png`: frame lateness p50/p99/max from StatusMsg and the overrun count.
//!
//! Text uses an embedded DejaVu Sans subset (`assets/fonts`, Bitstream Vera licence), so no
//! system font library is needed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::error::SinkError;
use super::reader::read_recording;
use super::table::{prefixed_columns, row, Cell, Column};
use super::topics::{classify, Decoded, TopicKind};
use crate::attitude::mrp_error;
use flexdyn_proto::{ImuMsg, StarTrackerMsg};

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");
/// The name the embedded font is registered under (see [`register_font`]).
pub const FONT_NAME: &str = "flexdyn-sans";

/// Registers the embedded font with plotters as [`FONT_NAME`] (idempotent).
pub fn register_font() -> Result<(), SinkError> {
    plotters::style::register_font(FONT_NAME, FontStyle::Normal, FONT)
        .map_err(|_| SinkError::Runtime("the embedded font does not load".into()))
}
const SIZE: (u32, u32) = (1200, 800);
const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// Arguments of `flexdyn plot`.
#[derive(Clone, Debug, PartialEq, clap::Args)]
pub struct PlotArgs {
    /// A recording (`.mcap`) or a `flexdyn simulate` / `flexdyn export` state CSV (`.csv`).
    #[arg(value_name = "INPUT")]
    pub input: PathBuf,
    /// Directory for the PNG files (created if missing).
    #[arg(long, short, value_name = "DIR")]
    pub output: PathBuf,
    /// The spacecraft to plot from a recording with several [default: the first one].
    #[arg(long = "sc-id", value_name = "ID")]
    pub sc_id: Option<String>,
    /// Target attitude σ_RN: adds the attitude error σ_BR to `attitude.png`.
    #[arg(
        long,
        value_name = "S1,S2,S3",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub sigma_rn: Option<Vec<f64>>,
}

/// Named columns over time.
#[derive(Clone, Debug, Default)]
struct Columns {
    t_s: Vec<f64>,
    cols: BTreeMap<String, Vec<f64>>,
}

impl Columns {
    fn push(&mut self, cells: &[(String, Cell)]) {
        let n = self.t_s.len();
        for (name, cell) in cells {
            let x = match cell {
                Cell::Num(x) => *x,
                Cell::Int(i) => *i as f64,
                Cell::Text(_) => continue,
            };
            if name == "t_s" {
                self.t_s.push(x);
            } else {
                let c = self.cols.entry(name.clone()).or_default();
                c.resize(n, f64::NAN);
                c.push(x);
            }
        }
        for c in self.cols.values_mut() {
            c.resize(self.t_s.len(), f64::NAN);
        }
    }

    /// The column `name`, if present.
    fn get(&self, name: &str) -> Option<&Vec<f64>> {
        self.cols.get(name)
    }

    /// A 3-vector column set: `<base>_1..3`.
    fn vec3(&self, base: &str) -> Option<[&Vec<f64>; 3]> {
        let one = |i: usize| self.get(&format!("{base}_{i}"));
        Some([one(1)?, one(2)?, one(3)?])
    }

    fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }
}

/// Everything the figures draw from.
#[derive(Default)]
struct PlotData {
    state: Columns,
    status: Columns,
    imus: BTreeMap<String, Columns>,
    star_trackers: BTreeMap<String, Columns>,
}

fn input_err(path: &Path, problem: impl Into<String>) -> SinkError {
    SinkError::Input {
        path: path.to_owned(),
        problem: problem.into(),
    }
}

fn from_mcap(path: &Path, sc_id: Option<&str>) -> Result<PlotData, SinkError> {
    let rec = read_recording(path)?;
    if let Some(why) = &rec.truncated {
        tracing::warn!(file = %path.display(), reason = %why, "the recording ends early; plotting what it holds");
    }
    let sc = match sc_id {
        Some(s) => s.to_owned(),
        None => rec
            .samples
            .iter()
            .find_map(|s| classify(&s.key).map(|t| t.sc_id.to_owned()))
            .ok_or_else(|| input_err(path, "holds no flexdyn channel"))?,
    };
    let mut data = PlotData::default();
    for s in &rec.samples {
        let Some(topic) = classify(&s.key) else {
            continue;
        };
        if topic.sc_id != sc {
            continue;
        }
        let Ok(d) = Decoded::decode(topic.kind, &s.payload) else {
            continue;
        };
        let cells = row(&d);
        match topic.kind {
            TopicKind::State => data.state.push(&cells),
            TopicKind::Status => data.status.push(&cells),
            TopicKind::Imu => data
                .imus
                .entry(topic.sensor.unwrap_or_default().to_owned())
                .or_default()
                .push(&cells),
            TopicKind::StarTracker => data
                .star_trackers
                .entry(topic.sensor.unwrap_or_default().to_owned())
                .or_default()
                .push(&cells),
            TopicKind::Command => {}
        }
    }
    if data.state.is_empty() {
        return Err(input_err(
            path,
            format!("holds no StateMsg of spacecraft {sc:?}"),
        ));
    }
    Ok(data)
}

/// A `simulate` sensor column `<kind>_<name>_<field>` (`imu_hub_omega_p_rad_s_1`,
/// `st_st1_q_cn_0`) split into (kind, sensor name, field), for the fields of that message.
fn sensor_column<'a>(
    column: &'a str,
    fields: &[(&'static str, Vec<String>)],
) -> Option<(&'static str, &'a str, &'a str)> {
    fields.iter().find_map(|(kind, names)| {
        let rest = column.strip_prefix(kind)?.strip_prefix('_')?;
        names.iter().find_map(|f| {
            let name = rest.strip_suffix(f.as_str())?.strip_suffix('_')?;
            (!name.is_empty()).then(|| (*kind, name, &rest[name.len() + 1..]))
        })
    })
}

fn from_csv(path: &Path) -> Result<PlotData, SinkError> {
    let text =
        std::fs::read_to_string(path).map_err(|e| input_err(path, format!("cannot read: {e}")))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or_else(|| input_err(path, "empty file"))?
        .split(',')
        .collect();
    if header.first() != Some(&"t_s") {
        return Err(input_err(
            path,
            "the first column must be t_s (a `flexdyn simulate` or `flexdyn export` state CSV)",
        ));
    }
    // The sensor columns `simulate` writes beside the state: the message fields of an IMU or a
    // star-tracker sample, prefixed `imu_<name>_` / `st_<name>_`.
    let fields = [
        ("imu", column_names(&ImuMsg::default())),
        ("st", column_names(&StarTrackerMsg::default())),
    ];
    let place: Vec<Option<(&str, &str, &str)>> =
        header.iter().map(|h| sensor_column(h, &fields)).collect();
    let mut data = PlotData::default();
    for (i, line) in lines.enumerate() {
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != header.len() {
            return Err(input_err(
                path,
                format!(
                    "line {}: {} fields, the header has {}",
                    i + 2,
                    fields.len(),
                    header.len()
                ),
            ));
        }
        let mut state = Vec::with_capacity(fields.len());
        // Per sensor: its cells, and whether this row has any (a star tracker's are empty
        // between its updates).
        let mut sensors: BTreeMap<(&str, &str), (Vec<Column>, bool)> = BTreeMap::new();
        // Column 0 is t_s (checked above), so the row's time is known before any sensor column.
        let mut t_s = f64::NAN;
        for ((name, f), place) in header.iter().zip(&fields).zip(&place) {
            let x = if f.is_empty() {
                f64::NAN
            } else {
                f.parse::<f64>().map_err(|e| {
                    input_err(path, format!("line {}, column {name}: {f:?}: {e}", i + 2))
                })?
            };
            if *name == "t_s" {
                t_s = x;
            }
            match place {
                Some((kind, sensor, field)) => {
                    let (cells, any) = sensors.entry((kind, sensor)).or_default();
                    if cells.is_empty() {
                        cells.push(("t_s".into(), Cell::Num(t_s)));
                    }
                    cells.push(((*field).to_owned(), Cell::Num(x)));
                    *any |= !f.is_empty();
                }
                None => state.push(((*name).to_owned(), Cell::Num(x))),
            }
        }
        data.state.push(&state);
        for ((kind, name), (cells, any)) in sensors {
            let map = if kind == "imu" {
                &mut data.imus
            } else {
                &mut data.star_trackers
            };
            if any {
                map.entry(name.to_owned()).or_default().push(&cells);
            }
        }
    }
    if data.state.is_empty() {
        return Err(input_err(path, "no data rows"));
    }
    Ok(data)
}

/// The column names of `msg`'s fields (no header), as in [`prefixed_columns`].
fn column_names<T: serde::Serialize>(msg: &T) -> Vec<String> {
    prefixed_columns("", msg)
        .into_iter()
        .map(|(n, _)| n)
        .collect()
}

/// One line on a panel.
struct Line {
    label: String,
    points: Vec<(f64, f64)>,
}

/// One chart of a figure.
struct Panel {
    y_label: String,
    log_y: bool,
    lines: Vec<Line>,
}

fn line(label: &str, t: &[f64], y: &[f64]) -> Line {
    Line {
        label: label.to_owned(),
        points: t
            .iter()
            .zip(y)
            .filter(|(t, y)| t.is_finite() && y.is_finite())
            .map(|(t, y)| (*t, *y))
            .collect(),
    }
}

/// A tick label for an axis spanning `lo..hi`: fixed-point with as many decimals as the tick
/// spacing needs when the magnitudes are ordinary, scientific otherwise; a value within
/// rounding of zero prints as 0.
fn tick_label(y: f64, lo: f64, hi: f64) -> String {
    let span = (hi - lo).abs();
    if y.abs() < 1e-9 * span {
        return "0".into();
    }
    let big = lo.abs().max(hi.abs());
    if (1e-3..1e5).contains(&big) {
        let step = span / 10.0;
        let decimals = (-step.log10().floor()).clamp(0.0, 6.0) as usize;
        format!("{y:.decimals$}")
    } else {
        format!("{y:.2e}")
    }
}

type Chart<'a, Y> = ChartContext<'a, BitMapBackend<'a>, Cartesian2d<RangedCoordf64, Y>>;

/// Axes, lines (points where `keep(y)`) and legend of one panel, on a linear or log y axis.
fn draw_panel<Y: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>>(
    chart: &mut Chart<'_, Y>,
    panel: &Panel,
    y_ticks: &dyn Fn(&f64) -> String,
    x_ticks: &dyn Fn(&f64) -> String,
    keep: fn(f64) -> bool,
) -> Result<(), String> {
    let label_style = (FONT_NAME, 18).into_font();
    chart
        .configure_mesh()
        .x_desc("simulation time t (s)")
        .y_desc(panel.y_label.as_str())
        .label_style(label_style.clone())
        .y_label_formatter(y_ticks)
        .x_label_formatter(x_ticks)
        .draw()
        .map_err(|e| e.to_string())?;
    for (k, l) in panel.lines.iter().enumerate() {
        let c = COLORS[k % COLORS.len()];
        chart
            .draw_series(LineSeries::new(
                l.points.iter().filter(|(_, y)| keep(*y)).copied(),
                c.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?
            .label(l.label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(label_style)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| e.to_string())
}

fn draw(path: &Path, title: &str, panels: &[Panel]) -> Result<(), SinkError> {
    let err = |e: &dyn std::fmt::Display| SinkError::Output {
        path: path.to_owned(),
        problem: e.to_string(),
    };
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(title, (FONT_NAME, 30).into_font())
        .map_err(|e| err(&e))?;
    let areas = root.split_evenly((panels.len(), 1));
    for (area, panel) in areas.iter().zip(panels) {
        let all: Vec<(f64, f64)> = panel
            .lines
            .iter()
            .flat_map(|l| l.points.iter().copied())
            .collect();
        let (t0, t1) = all
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (t, _)| {
                (a.min(*t), b.max(*t))
            });
        let (t0, t1) = if t1 > t0 {
            (t0, t1)
        } else {
            (t0 - 0.5, t0 + 0.5)
        };
        let x_ticks = move |x: &f64| tick_label(*x, t0, t1);
        let mut builder = ChartBuilder::on(area);
        builder
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(110);
        if panel.log_y {
            let ys: Vec<f64> = all.iter().map(|(_, y)| *y).filter(|y| *y > 0.0).collect();
            let lo = ys.iter().copied().fold(f64::INFINITY, f64::min).max(1e-18);
            let hi = ys.iter().copied().fold(0.0, f64::max).max(lo * 10.0);
            let mut chart = builder
                .build_cartesian_2d(t0..t1, (lo * 0.5..hi * 2.0).log_scale())
                .map_err(|e| err(&e))?;
            draw_panel(&mut chart, panel, &|y| format!("{y:.0e}"), &x_ticks, |y| {
                y > 0.0
            })
            .map_err(|e| err(&e))?;
        } else {
            let (lo, hi) = all
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (_, y)| {
                    (a.min(*y), b.max(*y))
                });
            let (lo, hi) = if !lo.is_finite() {
                (-1.0, 1.0)
            } else if hi - lo < 1e-12 * (lo.abs() + 1.0) {
                (lo - 0.5 * (lo.abs() + 1e-9), hi + 0.5 * (hi.abs() + 1e-9))
            } else {
                let pad = 0.05 * (hi - lo);
                (lo - pad, hi + pad)
            };
            let mut chart = builder
                .build_cartesian_2d(t0..t1, lo..hi)
                .map_err(|e| err(&e))?;
            draw_panel(
                &mut chart,
                panel,
                &|y| tick_label(*y, lo, hi),
                &x_ticks,
                f64::is_finite,
            )
            .map_err(|e| err(&e))?;
        }
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// What `plot` wrote and skipped.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PlotReport {
    /// The figures written.
    pub written: Vec<PathBuf>,
    /// Figures not drawn, with the reason.
    pub skipped: Vec<(String, String)>,
}

fn vec_panel(cols: &Columns, base: &str, labels: [&str; 3], y_label: &str) -> Option<Panel> {
    let v = cols.vec3(base)?;
    Some(Panel {
        y_label: y_label.to_owned(),
        log_y: false,
        lines: (0..3).map(|i| line(labels[i], &cols.t_s, v[i])).collect(),
    })
}

fn relative_drift(x: &[f64]) -> Vec<f64> {
    let x0 = x
        .iter()
        .copied()
        .find(|v| v.is_finite())
        .unwrap_or(f64::NAN);
    x.iter().map(|v| ((v - x0) / x0).abs()).collect()
}

/// Draws every figure the input has data for.
pub fn plot(args: &PlotArgs) -> Result<PlotReport, SinkError> {
    let target = match &args.sigma_rn {
        None => None,
        Some(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => {
            Some(nalgebra::Vector3::new(v[0], v[1], v[2]))
        }
        Some(v) => {
            return Err(SinkError::Arg {
                flag: "--sigma-rn",
                problem: format!("expected three finite numbers, got {v:?}"),
            })
        }
    };
    let is_mcap = args
        .input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
    let data = if is_mcap {
        from_mcap(&args.input, args.sc_id.as_deref())?
    } else {
        from_csv(&args.input)?
    };
    std::fs::create_dir_all(&args.output).map_err(|e| SinkError::Output {
        path: args.output.clone(),
        problem: e.to_string(),
    })?;
    register_font()?;
    let mut report = PlotReport::default();
    let s = &data.state;
    let t = &s.t_s;
    let mut figures: Vec<(&str, String, Vec<Panel>)> = Vec::new();
    let mut skip = |name: &str, why: &str| report.skipped.push((name.to_owned(), why.to_owned()));

    match vec_panel(s, "sigma_bn", ["σ1", "σ2", "σ3"], "σ_BN (MRP, –)") {
        Some(sigma) => {
            let mut panels = vec![sigma];
            if let (Some(target), Some(v)) = (target, s.vec3("sigma_bn")) {
                let err: Vec<nalgebra::Vector3<f64>> = (0..t.len())
                    .map(|k| mrp_error(&nalgebra::Vector3::new(v[0][k], v[1][k], v[2][k]), &target))
                    .collect();
                let comp = |i: usize| err.iter().map(|e| e[i]).collect::<Vec<_>>();
                let norm: Vec<f64> = err.iter().map(|e| e.norm()).collect();
                panels.push(Panel {
                    y_label: "σ_BR (MRP, –)".into(),
                    log_y: false,
                    lines: vec![
                        line("σ_BR,1", t, &comp(0)),
                        line("σ_BR,2", t, &comp(1)),
                        line("σ_BR,3", t, &comp(2)),
                        line("|σ_BR|", t, &norm),
                    ],
                });
            }
            let title = match target {
                Some(r) => format!(
                    "Attitude σ_BN and error σ_BR to σ_RN = ({}, {}, {})",
                    r.x, r.y, r.z
                ),
                None => "Attitude σ_BN (no target given: --sigma-rn adds σ_BR)".into(),
            };
            figures.push(("attitude.png", title, panels));
        }
        None => skip("attitude.png", "no sigma_bn columns"),
    }
    match vec_panel(
        s,
        "omega_bn_b_rad_s",
        ["ω1", "ω2", "ω3"],
        "ω_BN, B components (rad/s)",
    ) {
        Some(p) => figures.push(("rates.png", "Body angular rate ω_BN".into(), vec![p])),
        None => skip("rates.png", "no omega_bn_b columns"),
    }
    let mut pairs = Vec::new();
    for k in 1.. {
        let (Some(th1), Some(th2)) = (
            s.get(&format!("pair{k}_theta1")),
            s.get(&format!("pair{k}_theta2")),
        ) else {
            break;
        };
        pairs.push(Panel {
            y_label: format!("pair {k} (rad)"),
            log_y: false,
            lines: vec![line("θ1", t, th1), line("θ2", t, th2)],
        });
    }
    if pairs.is_empty() {
        skip("panels.png", "no pair<k>_theta1/2 columns");
    } else {
        figures.push((
            "panels.png",
            "Panel hinge angles θ1 (hub–panel 1), θ2 (panel 1–panel 2)".into(),
            pairs,
        ));
    }
    let torque = vec_panel(
        s,
        "wrench_applied_torque_b_nm",
        ["τ1", "τ2", "τ3"],
        "torque about B (N·m)",
    );
    let force = vec_panel(
        s,
        "wrench_applied_force_b_newton",
        ["F1", "F2", "F3"],
        "force at B (N)",
    );
    match (torque, force, s.get("command_flags")) {
        (Some(tq), Some(f), Some(flags)) => figures.push((
            "wrench.png",
            "Commanded wrench held over each frame (B components) and command flags".into(),
            vec![
                tq,
                f,
                Panel {
                    y_label: "command_flags (bits)".into(),
                    log_y: false,
                    lines: vec![line("flags", t, flags)],
                },
            ],
        )),
        _ => skip(
            "wrench.png",
            "no commanded-wrench columns (a simulate CSV has none)",
        ),
    }
    let energy = match (
        s.get("conserved_orb_energy_j"),
        s.get("conserved_rot_energy_j"),
    ) {
        (Some(o), Some(r)) => Some(o.iter().zip(r).map(|(a, b)| a + b).collect::<Vec<f64>>()),
        _ => None,
    };
    let momentum = match (
        s.vec3("conserved_orb_ang_mom_n"),
        s.vec3("conserved_rot_ang_mom_c_n"),
    ) {
        (Some(o), Some(r)) => {
            let h: Vec<nalgebra::Vector3<f64>> = (0..t.len())
                .map(|k| {
                    nalgebra::Vector3::new(o[0][k] + r[0][k], o[1][k] + r[1][k], o[2][k] + r[2][k])
                })
                .collect();
            let h0 = h.first().copied().unwrap_or_default();
            Some(
                h.iter()
                    .map(|v| (v - h0).norm() / h0.norm())
                    .collect::<Vec<f64>>(),
            )
        }
        _ => None,
    };
    match (energy, momentum) {
        (Some(e), Some(h)) => figures.push((
            "conservation.png",
            "Conservation: relative drift of total energy and angular momentum (log)".into(),
            vec![Panel {
                y_label: "relative drift (–)".into(),
                log_y: true,
                lines: vec![
                    line("|E − E0| / |E0|", t, &relative_drift(&e)),
                    line("|H − H0| / |H0|", t, &h),
                ],
            }],
        )),
        _ => skip("conservation.png", "no energy and momentum columns"),
    }
    let mut imu_panels = Vec::new();
    for (name, c) in &data.imus {
        if let Some(p) = vec_panel(
            c,
            "omega_p_rad_s",
            ["ω1", "ω2", "ω3"],
            &format!("{name}: rate (rad/s)"),
        ) {
            imu_panels.push(p);
        }
        if let Some(p) = vec_panel(
            c,
            "accel_p_m_s2",
            ["a1", "a2", "a3"],
            &format!("{name}: specific force (m/s²)"),
        ) {
            imu_panels.push(p);
        }
    }
    if imu_panels.is_empty() {
        skip("imu.png", "no IMU");
    } else {
        figures.push((
            "imu.png",
            "IMU measurements (sensor frame P)".into(),
            imu_panels,
        ));
    }
    let st = &data.status;
    match (
        st.get("timing_lateness_p50_ns"),
        st.get("timing_lateness_p99_ns"),
        st.get("timing_lateness_max_ns"),
        st.get("timing_overrun_count"),
    ) {
        (Some(p50), Some(p99), Some(max), Some(overruns)) => {
            let us = |v: &Vec<f64>| v.iter().map(|x| x * 1e-3).collect::<Vec<_>>();
            figures.push((
                "timing.png",
                "Real-time frame lateness (cumulative percentiles from StatusMsg)".into(),
                vec![
                    Panel {
                        y_label: "lateness (µs)".into(),
                        log_y: false,
                        lines: vec![
                            line("p50", &st.t_s, &us(p50)),
                            line("p99", &st.t_s, &us(p99)),
                            line("max", &st.t_s, &us(max)),
                        ],
                    },
                    Panel {
                        y_label: "overruns (count)".into(),
                        log_y: false,
                        lines: vec![line("overruns", &st.t_s, overruns)],
                    },
                ],
            ));
        }
        _ => skip("timing.png", "no StatusMsg (only recordings have it)"),
    }
    for (name, title, panels) in figures {
        let path = args.output.join(name);
        draw(&path, &title, &panels)?;
        report.written.push(path);
    }
    Ok(report)
}
