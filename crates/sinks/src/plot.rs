//! `flexdyn plot INPUT --output DIR`: PNG figures of a recording (`.mcap`) or of a
//! `flexdyn simulate` / `flexdyn export` CSV, with the `plotters` crate.
//!
//! Figures (each skipped, and said so, when the input lacks its data):
//! - `attitude.png`: σ_BN, and the attitude error σ_BR with |σ_BR| when `--sigma-rn` gives the
//!   target;
//! - `rates.png`: ω_BN;
//! - `panels.png`: θ1 and θ2 of each pair;
//! - `wrench.png`: the commanded torque and force held over each frame, and the command flags;
//! - `conservation.png`: each invariant on its own (orbital, rotational and total energy;
//!   orbital, rotational and total angular momentum), as its change relative to its own scale,
//!   log axis, with the intervals where an external wrench acts shaded (the invariants are
//!   constant only without external wrench, damping or motor torques);
//! - `wheels.png`: each reaction wheel's speed, applied motor torque and limit flags;
//! - `actuators.png`: each magnetorquer's applied dipole, and each thruster's thrust (its
//!   firings), pulse count and propellant used;
//! - `disturbance_torques.png`: the environment message's torque and force of each source
//!   (gravity gradient, drag, solar pressure, residual dipole), magnitudes on a log axis, and
//!   the shadow factor;
//! - `star_tracker.png`: each star tracker's measured q_CN and its valid / status flags;
//! - `imu.png`: each IMU's measured rate and specific force, one column per IMU;
//! - `relative_motion.png` (with `--relative-to CHIEF`, from a recording of several vehicles):
//!   the plotted vehicle relative to CHIEF in CHIEF's Hill frame, its rate seen in that frame,
//!   range and range rate: the recorded RelativeStateMsg (centres of mass) when the recording
//!   holds it (a fleet server publishes it for each deputy), else computed from the two
//!   vehicles' recorded StateMsgs (hub points B);
//! - `timing.png`: frame lateness p50/p99/max from StatusMsg and the overrun count (real time
//!   only: a lockstep or batch run is not paced by the wall clock, so it is skipped and says so).
//!
//! Every fault (`[[faults]]`, random or live) is shaded over the intervals it was active, with a
//! legend entry naming it, on each panel that shows the faulted component: a sensor's panels
//! (`imus.hub.gyro` on IMU hub's), the wheel panels for a wheel, the magnetorquer or thruster
//! panels of `actuators.png`, the commanded wrench for a command link
//! ([`super::fault_spans`]: from the recording's fault events, or the `# fault=` lines of a
//! `simulate` CSV). A fault already active when the recording began is shaded too
//! ([`super::prior_faults`]): a configured one from its window's activation (its legend says
//! since when, before the data), a live one whose target the recording does not name on
//! `attitude.png`, from the first state, labelled as such.
//!
//! [`figures`] builds every figure's data and axis bounds ([`Panel::y_range`]) without drawing,
//! so tests can check what a figure shows.
//!
//! Text uses an embedded DejaVu Sans subset (`assets/fonts`, Bitstream Vera licence), so no
//! system font library is needed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::error::SinkError;
use super::fault_spans::{self, FaultShading};
use super::prior_faults;
use super::table::{prefixed_columns, row, Cell, Column, ENVIRONMENT_COLUMN_PREFIX};
use super::topics::{classify, Decoded, TopicKind};
use flexdyn_kernel::attitude::mrp_error;
use flexdyn_sensors::KINDS;

pub mod fsw;
pub mod read;

const FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans-subset.ttf");
/// The name the embedded font is registered under (see [`register_font`]).
pub const FONT_NAME: &str = "flexdyn-sans";

/// Registers the embedded font with plotters as [`FONT_NAME`] (idempotent).
pub fn register_font() -> Result<(), SinkError> {
    plotters::style::register_font(FONT_NAME, FontStyle::Normal, FONT)
        .map_err(|_| SinkError::Runtime("the embedded font does not load".into()))
}
const SIZE: (u32, u32) = (1200, 800);
/// The lines' colours, in order (and the colours of nothing else but legend keys).
pub const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// The shading colours of faults (by fault index, cycling), drawn at [`FAULT_ALPHA`] over the
/// background: distinct from the lines' and from the external-wrench shading.
pub const FAULT_COLORS: [RGBColor; 4] = [
    RGBColor(220, 20, 60),
    RGBColor(0, 128, 128),
    RGBColor(128, 0, 128),
    RGBColor(90, 90, 90),
];
/// The opacity of a fault's shading.
pub const FAULT_ALPHA: f64 = 0.2;

/// The shading colour of fault `index`.
pub fn fault_color(index: u32) -> RGBColor {
    FAULT_COLORS[index as usize % FAULT_COLORS.len()]
}

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
    /// With a recording of several vehicles: adds `relative_motion.png`, the plotted vehicle
    /// relative to vehicle CHIEF, in CHIEF's Hill frame (its recorded RelativeStateMsg when
    /// present, else from the two vehicles' StateMsgs).
    #[arg(long = "relative-to", value_name = "CHIEF")]
    pub relative_to: Option<String>,
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
                // Look up before inserting: the name is cloned once per column, not per row.
                let c = match self.cols.get_mut(name.as_str()) {
                    Some(c) => c,
                    None => self.cols.entry(name.clone()).or_default(),
                };
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
    /// Per (index in [`KINDS`], sensor name), the sensor's columns.
    sensors: BTreeMap<(usize, String), Columns>,
    /// The environment record's columns (EnvironmentMsg fields, no prefix).
    environment: Columns,
    /// The pacing mode of the recorded run (from its StatusMsg; none in a CSV).
    mode: Option<flexdyn_proto::Mode>,
    /// `--relative-to`: the chief's id and its state columns.
    chief: Option<(String, Columns)>,
    /// When each fault was active.
    faults: Vec<FaultShading>,
    /// `--relative-to`: the plotted vehicle's recorded RelativeStateMsg relative to the chief
    /// (`flexdyn/<sc>/tlm/rel/<chief>`), when the recording holds it.
    relative: Columns,
    /// The flight code's telemetry streams the recording's configuration declares, with their
    /// recorded samples ([`fsw`]).
    fsw: Vec<fsw::FswSeries>,
}

/// \[s\] the first and last instant of `c` (0, 0 when empty).
fn time_span(c: &Columns) -> (f64, f64) {
    let first = c.t_s.iter().copied().find(|t| t.is_finite()).unwrap_or(0.0);
    let last = c
        .t_s
        .iter()
        .copied()
        .rfind(|t| t.is_finite())
        .unwrap_or(first);
    (first, last)
}

fn input_err(path: &Path, problem: impl Into<String>) -> SinkError {
    SinkError::Input {
        path: path.to_owned(),
        problem: problem.into(),
    }
}

fn from_mcap(
    path: &Path,
    sc_id: Option<&str>,
    relative_to: Option<&str>,
) -> Result<PlotData, SinkError> {
    // Only the plotted vehicle's channels and the chief's states, streamed with progress.
    let (rec, sc) = read::read_for_plot(path, sc_id, relative_to)?;
    if let Some(why) = &rec.truncated {
        tracing::warn!(file = %path.display(), reason = %why, "the recording ends early; plotting what it holds");
    }
    let sc = sc.ok_or_else(|| input_err(path, "holds no flexdyn channel"))?;
    if relative_to == Some(sc.as_str()) {
        return Err(SinkError::Arg {
            flag: "--relative-to",
            problem: format!("{sc:?} is the plotted vehicle itself (choose it with --sc-id)"),
        });
    }
    let mut data = PlotData {
        chief: relative_to.map(|c| (c.to_owned(), Columns::default())),
        ..PlotData::default()
    };
    let mut fsw_samples: BTreeMap<String, Vec<flexdyn_proto::FswMsg>> = BTreeMap::new();
    let mut progress = read::ReadProgress::decoding(rec.samples.len() as u64);
    for (i, s) in rec.samples.iter().enumerate() {
        if i % 4096 == 0 {
            progress.update(i as u64);
        }
        let Some(topic) = classify(&s.key) else {
            continue;
        };
        if let Some((chief, states)) = &mut data.chief {
            if topic.sc_id == chief.as_str() && topic.kind == TopicKind::State {
                if let Ok(d) = Decoded::decode(topic.kind, &s.payload) {
                    states.push(&row(&d));
                }
                continue;
            }
        }
        if topic.sc_id != sc {
            continue;
        }
        let Ok(d) = Decoded::decode(topic.kind, &s.payload) else {
            continue;
        };
        let cells = row(&d);
        match topic.kind {
            TopicKind::State => data.state.push(&cells),
            TopicKind::Status => {
                if let Decoded::Status(m) = &d {
                    data.mode = Some(m.mode);
                }
                data.status.push(&cells);
            }
            TopicKind::Sensor(kind) => data
                .sensors
                .entry((kind, topic.sensor.unwrap_or_default().to_owned()))
                .or_default()
                .push(&cells),
            TopicKind::Environment => data.environment.push(&cells),
            // Read with the faults active before the recording, below.
            TopicKind::FaultEvent
            | TopicKind::Command
            | TopicKind::Time
            | TopicKind::Operator
            | TopicKind::FaultCommand => {}
            TopicKind::Fsw => {
                if let Decoded::Fsw(m) = d {
                    fsw_samples
                        .entry(topic.sensor.unwrap_or_default().to_owned())
                        .or_default()
                        .push(m);
                }
            }
            TopicKind::RelativeState => {
                if data.chief.as_ref().map(|(c, _)| c.as_str()) == topic.sensor {
                    data.relative.push(&cells);
                }
            }
        }
    }
    progress.finish(rec.samples.len() as u64);
    data.fsw = fsw_series(&rec, &sc, fsw_samples);
    let (first, last) = time_span(&data.state);
    let events = prior_faults::fault_events(&rec)
        .remove(&sc)
        .map(|v| v.events)
        .unwrap_or_default();
    data.faults = fault_spans::from_events(&events, first, last);
    if data.state.is_empty() {
        return Err(input_err(
            path,
            format!("holds no StateMsg of spacecraft {sc:?}"),
        ));
    }
    if let Some((chief, states)) = &data.chief {
        if states.is_empty() && data.relative.is_empty() {
            return Err(input_err(
                path,
                format!(
                    "holds no StateMsg of spacecraft {chief:?} and no RelativeStateMsg of \
                     {sc:?} relative to it (--relative-to)"
                ),
            ));
        }
    }
    Ok(data)
}

/// The streams the recording's configuration of vehicle `sc` declares, each with its samples
/// (in tick order); none when the recording has no configuration of it (a warning when it has
/// one that does not load).
fn fsw_series(
    rec: &crate::reader::Recording,
    sc: &str,
    mut samples: BTreeMap<String, Vec<flexdyn_proto::FswMsg>>,
) -> Vec<fsw::FswSeries> {
    let Some(info) = rec.vehicles().into_iter().find(|v| v.sc_id == sc) else {
        return Vec::new();
    };
    let streams = match flexdyn_vehicle::config::fsw::read_streams(&info.config_toml) {
        Ok(s) => s,
        Err(e) => {
            tracing::warn!(sc_id = sc, error = %e, "the recording's [[fsw_streams]] do not load: no flight-code figures");
            return Vec::new();
        }
    };
    streams
        .into_iter()
        .map(|decl| {
            let mut samples = samples.remove(&decl.name).unwrap_or_default();
            samples.sort_by_key(|m| m.header.tick);
            fsw::FswSeries { decl, samples }
        })
        .collect()
}

/// A `simulate` sensor column `<kind>_<name>_<field>` (`imu_hub_omega_p_rad_s_1`,
/// `st_st1_q_cn_0`) split into (index in [`KINDS`], sensor name, field), for the fields of that
/// kind's message (`fields[i]`: kind `i`'s column prefix and field columns).
fn sensor_column<'a>(
    column: &'a str,
    fields: &[(&'static str, Vec<String>)],
) -> Option<(usize, &'a str, &'a str)> {
    fields
        .iter()
        .enumerate()
        .find_map(|(kind, (prefix, names))| {
            let rest = column.strip_prefix(prefix)?.strip_prefix('_')?;
            names.iter().find_map(|f| {
                let name = rest.strip_suffix(f.as_str())?.strip_suffix('_')?;
                (!name.is_empty()).then(|| (kind, name, &rest[name.len() + 1..]))
            })
        })
}

fn from_csv(path: &Path) -> Result<PlotData, SinkError> {
    let text =
        std::fs::read_to_string(path).map_err(|e| input_err(path, format!("cannot read: {e}")))?;
    // Leading `# key=value` comments (the epoch, the faults' windows) precede the header.
    let mut windows = Vec::new();
    for (n, comment) in text.lines().map_while(|l| l.strip_prefix('#')).enumerate() {
        let Some(value) = comment
            .trim_start()
            .strip_prefix(fault_spans::CSV_KEY)
            .and_then(|v| v.strip_prefix('='))
        else {
            continue;
        };
        windows.push(
            fault_spans::parse_csv_comment(value)
                .map_err(|e| input_err(path, format!("line {}: {e}", n + 1)))?,
        );
    }
    let mut lines = text.lines().skip_while(|l| l.starts_with('#'));
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
    // The sensor columns `simulate` writes beside the state: the message fields of each kind's
    // sample, prefixed `<kind>_<name>_` (`imu_hub_`, `st_st1_`).
    let fields: Vec<(&'static str, Vec<String>)> = KINDS
        .iter()
        .map(|k| (k.column_prefix, column_names(&(k.default_json)())))
        .collect();
    let place: Vec<Option<(usize, &str, &str)>> =
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
        // `simulate`'s environment columns (`env_*`), with the prefix dropped.
        let mut environment = vec![("t_s".to_owned(), Cell::Num(f64::NAN))];
        // Per sensor: its cells, and whether this row has any (a star tracker's are empty
        // between its updates).
        let mut sensors: BTreeMap<(usize, &str), (Vec<Column>, bool)> = BTreeMap::new();
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
                environment[0].1 = Cell::Num(x);
            }
            let env_field = name
                .strip_prefix(ENVIRONMENT_COLUMN_PREFIX)
                .and_then(|f| f.strip_prefix('_'));
            if let Some(field) = env_field {
                environment.push((field.to_owned(), Cell::Num(x)));
                continue;
            }
            match place {
                Some((kind, sensor, field)) => {
                    let (cells, any) = sensors.entry((*kind, sensor)).or_default();
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
        if environment.len() > 1 {
            data.environment.push(&environment);
        }
        for ((kind, name), (cells, any)) in sensors {
            if any {
                data.sensors
                    .entry((kind, name.to_owned()))
                    .or_default()
                    .push(&cells);
            }
        }
    }
    if data.state.is_empty() {
        return Err(input_err(path, "no data rows"));
    }
    let (first, last) = time_span(&data.state);
    // One shading per fault: `export` writes a line per activation.
    for (i, w, mode, target) in &windows {
        let f = fault_spans::from_window(*i, w, mode, target, first, last);
        match data.faults.iter_mut().find(|s| s.fault_index == *i) {
            Some(s) => s.spans.extend(f.spans),
            None => data.faults.push(f),
        }
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
#[derive(Clone, Debug)]
pub struct Line {
    /// Its legend entry.
    pub label: String,
    /// (t \[s\], y) in the panel's unit, finite only.
    pub points: Vec<(f64, f64)>,
}

/// One chart of a figure.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// The chart's caption (e.g. which sensor), if any.
    pub caption: Option<String>,
    /// The y axis label, with its unit.
    pub y_label: String,
    /// A logarithmic y axis (only positive values are drawn).
    pub log_y: bool,
    /// The lines.
    pub lines: Vec<Line>,
    /// \[s\] time intervals shaded behind the lines (e.g. where an external wrench acts),
    /// with the legend entry of the shading.
    pub spans: Vec<(f64, f64)>,
    /// The legend entry of `spans`.
    pub span_label: String,
    /// The components whose values it shows, for shading their faults: a component
    /// (`imus.hub`) or a whole section whose every member it draws (`reaction_wheels`).
    pub components: Vec<String>,
    /// The faults of those components, each shaded over the intervals it was active.
    pub faults: Vec<FaultShading>,
    /// Labelled shaded bands behind everything else (the flight code's modes, its events).
    pub bands: Vec<Band>,
}

/// A labelled, coloured set of time intervals shaded behind a panel's lines (one legend entry).
#[derive(Clone, Debug)]
pub struct Band {
    /// Its legend entry.
    pub label: String,
    /// Its colour.
    pub color: RGBColor,
    /// Its opacity (0–1).
    pub alpha: f64,
    /// \[s\] the intervals, in time order.
    pub spans: Vec<(f64, f64)>,
}

/// One figure (one PNG file).
#[derive(Clone, Debug)]
pub struct Figure {
    /// The file name (`conservation.png`).
    pub name: String,
    /// The title over every panel.
    pub title: String,
    /// The panels, filled row by row into `columns` columns.
    pub panels: Vec<Panel>,
    /// Panels side by side (1: stacked).
    pub columns: usize,
}

impl Panel {
    /// The panel's x axis bounds \[s\]: the time span of its lines (±0.5 s if a single instant).
    pub fn t_range(&self) -> (f64, f64) {
        let (t0, t1) = self
            .lines
            .iter()
            .flat_map(|l| l.points.iter())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (t, _)| {
                (a.min(*t), b.max(*t))
            });
        if t1 > t0 {
            (t0, t1)
        } else if t0.is_finite() {
            (t0 - 0.5, t0 + 0.5)
        } else {
            (0.0, 1.0)
        }
    }

    /// The panel's y axis bounds: every drawn point lies inside, with a 5 % margin on a linear
    /// axis and a factor of 2 on a log axis (whose lower bound is at least 1e-18).
    pub fn y_range(&self) -> (f64, f64) {
        let ys = self.lines.iter().flat_map(|l| l.points.iter().map(|p| p.1));
        if self.log_y {
            let (lo, hi) = ys
                .filter(|y| *y > 0.0)
                .fold((f64::INFINITY, 0.0_f64), |(a, b), y| (a.min(y), b.max(y)));
            if !lo.is_finite() {
                // Nothing positive to draw (every invariant exactly constant, or zero
                // throughout): a fixed decade range, never an infinite one.
                return (1e-18, 1.0);
            }
            let lo = lo.max(1e-18);
            let hi = hi.max(lo * 10.0);
            return (lo * 0.5, hi * 2.0);
        }
        let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
            (a.min(y), b.max(y))
        });
        if !lo.is_finite() {
            (-1.0, 1.0)
        } else if hi - lo < 1e-12 * (lo.abs() + 1.0) {
            (lo - 0.5 * (lo.abs() + 1e-9), hi + 0.5 * (hi.abs() + 1e-9))
        } else {
            let pad = 0.05 * (hi - lo);
            (lo - pad, hi + pad)
        }
    }
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

/// Shades `spans` over the y range `y`, with one legend entry `label`; clipped to `t` when
/// given (drawn from the axis' start when it began before the data).
fn shade_spans<Y: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>>(
    chart: &mut Chart<'_, Y>,
    spans: &[(f64, f64)],
    t: Option<(f64, f64)>,
    (y0, y1): (f64, f64),
    shade: RGBAColor,
    label: &str,
) -> Result<(), String> {
    let clip = |(a, b): (f64, f64)| match t {
        Some((t0, t1)) => (a.clamp(t0, t1), b.clamp(t0, t1)),
        None => (a, b),
    };
    chart
        .draw_series(
            spans
                .iter()
                .map(|s| clip(*s))
                .filter(|(a, b)| t.is_none() || a < b)
                .map(|(a, b)| Rectangle::new([(a, y0), (b, y1)], shade.filled())),
        )
        .map_err(|e| e.to_string())?
        .label(label)
        .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], shade.filled()));
    Ok(())
}

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
        .y_labels(6)
        .label_style(label_style.clone())
        .y_label_formatter(y_ticks)
        .x_label_formatter(x_ticks)
        .draw()
        .map_err(|e| e.to_string())?;
    let (y0, y1) = panel.y_range();
    // A band or a fault active from before the data is drawn from the axis' start.
    let t = Some(panel.t_range());
    for b in &panel.bands {
        shade_spans(chart, &b.spans, t, (y0, y1), b.color.mix(b.alpha), &b.label)?;
    }
    if !panel.spans.is_empty() {
        let shade = RGBColor(255, 200, 0).mix(0.3);
        shade_spans(
            chart,
            &panel.spans,
            None,
            (y0, y1),
            shade,
            &panel.span_label,
        )?;
    }
    for f in &panel.faults {
        let shade = fault_color(f.fault_index).mix(FAULT_ALPHA);
        shade_spans(chart, &f.spans, t, (y0, y1), shade, &f.label)?;
    }
    // The first line last, on top: where lines coincide (a total dominated by one part) the
    // first one listed stays visible.
    for (k, l) in panel.lines.iter().enumerate().rev() {
        let c = COLORS[k % COLORS.len()];
        chart
            // Segment by segment: a 2 px polyline gets mitred joins, and at the sharp turns of
            // a noisy signal the mitres reach far outside the axes.
            .draw_series(
                l.points
                    .iter()
                    .filter(|(_, y)| keep(*y))
                    .copied()
                    .collect::<Vec<_>>()
                    .windows(2)
                    .map(|w| PathElement::new(vec![w[0], w[1]], c.stroke_width(2))),
            )
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

/// The pixel rectangle (x range, y range) of a chart's plotting area.
pub type PixelRect = (std::ops::Range<i32>, std::ops::Range<i32>);

/// \[px\] the title's font size: [`TITLE_PX`], or smaller (not below [`TITLE_MIN_PX`]) until
/// the title fits the figure's width less [`TITLE_SIDE_PX`] on each side (plotters centres it
/// and cuts what overflows).
pub fn title_font_px(title: &str) -> u32 {
    let room = SIZE.0 - 2 * TITLE_SIDE_PX;
    (TITLE_MIN_PX..=TITLE_PX)
        .rev()
        .find(|px| text_width_px(title, *px) <= room)
        .unwrap_or(TITLE_MIN_PX)
}

/// \[px\] the width of `text` in the embedded font at `px` (plotters' own estimate, as it
/// lays the text out; the font must be registered, [`register_font`]).
pub fn text_width_px(text: &str, px: u32) -> u32 {
    (FONT_NAME, f64::from(px))
        .into_font()
        .box_size(text)
        .map_or(u32::MAX, |(w, _)| w)
}

/// \[px\] a figure title's font size when it fits.
pub const TITLE_PX: u32 = 26;
/// \[px\] the smallest title font size.
pub const TITLE_MIN_PX: u32 = 14;
/// \[px\] the room kept free of the title at each side of a figure.
pub const TITLE_SIDE_PX: u32 = 10;

/// Draws `fig` into the PNG file `path`; returns each panel's plotting area in pixels (what
/// lies outside is axes, labels and titles).
pub fn draw(path: &Path, fig: &Figure) -> Result<Vec<PixelRect>, SinkError> {
    let err = |e: &dyn std::fmt::Display| SinkError::Output {
        path: path.to_owned(),
        problem: e.to_string(),
    };
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(
            &fig.title,
            (FONT_NAME, title_font_px(&fig.title)).into_font(),
        )
        .map_err(|e| err(&e))?;
    let columns = fig.columns.max(1);
    let rows = fig.panels.len().div_ceil(columns);
    let areas = root.split_evenly((rows, columns));
    let mut plotting = Vec::new();
    for (area, panel) in areas.iter().zip(&fig.panels) {
        let (t0, t1) = panel.t_range();
        let (lo, hi) = panel.y_range();
        let x_ticks = move |x: &f64| tick_label(*x, t0, t1);
        let mut builder = ChartBuilder::on(area);
        builder
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(110);
        if let Some(c) = &panel.caption {
            builder.caption(c, (FONT_NAME, 20).into_font());
        }
        if panel.log_y {
            let mut chart = builder
                .build_cartesian_2d(t0..t1, (lo..hi).log_scale())
                .map_err(|e| err(&e))?;
            plotting.push(chart.plotting_area().get_pixel_range());
            draw_panel(&mut chart, panel, &|y| format!("{y:.0e}"), &x_ticks, |y| {
                y > 0.0
            })
            .map_err(|e| err(&e))?;
        } else {
            let mut chart = builder
                .build_cartesian_2d(t0..t1, lo..hi)
                .map_err(|e| err(&e))?;
            plotting.push(chart.plotting_area().get_pixel_range());
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
    Ok(plotting)
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
        lines: (0..3).map(|i| line(labels[i], &cols.t_s, v[i])).collect(),
        ..Panel::default()
    })
}

/// A panel of the scalar columns `<prefix><k><suffix>` for k = 1, 2, … (one line per
/// effector or sensor), labelled `<label><k>`; `None` when there is none.
fn numbered_panel(
    cols: &Columns,
    prefix: &str,
    suffix: &str,
    label: &str,
    y_label: &str,
) -> Option<Panel> {
    let lines: Vec<Line> = (1..)
        .map_while(|k| {
            cols.get(&format!("{prefix}{k}{suffix}"))
                .map(|c| line(&format!("{label}{k}"), &cols.t_s, c))
        })
        .collect();
    // The kind whose effectors these columns are (`rw` → `reaction_wheels`): the panel shows
    // every one of them.
    let section = flexdyn_dynamics::kinds::KINDS
        .iter()
        .find(|k| k.effector.column_prefix == prefix)
        .map(|k| k.section.to_owned());
    (!lines.is_empty()).then(|| Panel {
        y_label: y_label.to_owned(),
        lines,
        components: section.into_iter().collect(),
        ..Panel::default()
    })
}

/// |x(t) − x(0)| / scale: the change of an invariant relative to its own scale, the largest
/// |x| over the run (so a quantity that starts at zero still has one). All NaN when x is zero
/// throughout.
fn relative_change(x: &[f64]) -> Vec<f64> {
    let x0 = x
        .iter()
        .copied()
        .find(|v| v.is_finite())
        .unwrap_or(f64::NAN);
    let scale = x
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    x.iter().map(|v| (v - x0).abs() / scale).collect()
}

/// The same for a vector: |h(t) − h(0)| / max |h|.
fn relative_change_vec(h: &[nalgebra::Vector3<f64>]) -> Vec<f64> {
    let h0 = h.first().copied().unwrap_or_default();
    let scale = h.iter().fold(0.0_f64, |m, v| m.max(v.norm()));
    h.iter().map(|v| (v - h0).norm() / scale).collect()
}

/// A line of a relative change on a log axis, which cannot show zero: when the change is
/// exactly zero throughout, the legend says so.
fn invariant_line(label: &str, t: &[f64], change: &[f64]) -> Line {
    let l = line(label, t, change);
    if !l.points.is_empty() && l.points.iter().all(|(_, y)| *y == 0.0) {
        return Line {
            label: format!("{label}: exactly constant"),
            ..l
        };
    }
    l
}

/// The rows of a 3-vector column set as vectors.
fn vectors(v: [&Vec<f64>; 3]) -> Vec<nalgebra::Vector3<f64>> {
    (0..v[0].len())
        .map(|k| nalgebra::Vector3::new(v[0][k], v[1][k], v[2][k]))
        .collect()
}

/// \[s\] the intervals over which an external wrench acts: the commanded wrench
/// (`wrench_applied_*`, held over the frame that ends at a row) and the scheduled one
/// (`wrench_schedule_*`, `simulate` only: in effect from a row on). Each non-zero row
/// contributes the interval between its neighbours on the side where it acts.
fn external_wrench_spans(s: &Columns) -> Vec<(f64, f64)> {
    let t = &s.t_s;
    let nonzero = |base: &str, k: usize| {
        s.vec3(base)
            .is_some_and(|v| v.iter().any(|c| c[k] != 0.0 && !c[k].is_nan()))
    };
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for k in 0..t.len() {
        let held = [
            "wrench_applied_torque_b_nm",
            "wrench_applied_force_b_newton",
        ]
        .iter()
        .any(|b| nonzero(b, k));
        let scheduled = [
            "wrench_schedule_torque_b_nm",
            "wrench_schedule_force_b_newton",
        ]
        .iter()
        .any(|b| nonzero(b, k));
        let mut add = |a: f64, b: f64| match spans.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => spans.push((a, b)),
        };
        if held && k > 0 {
            add(t[k - 1], t[k]);
        }
        if scheduled && k + 1 < t.len() {
            add(t[k], t[k + 1]);
        }
    }
    spans
}

/// Adds each fault's shading to every panel showing its target ([`fault_spans::shows`]). A
/// fault active from before the data's first instant `t_first_s` (a recording started after
/// it fired) says since when in its legend entry, as the axes do not reach back there.
fn shade_faults(figures: &mut [Figure], faults: &[FaultShading], t_first_s: f64) {
    let faults: Vec<FaultShading> = faults
        .iter()
        .filter(|f| !f.spans.is_empty())
        .map(|f| match f.spans.first() {
            Some(&(start, _)) if start < t_first_s => FaultShading {
                label: format!("{} (on since {start} s, before the data)", f.label),
                ..f.clone()
            },
            _ => f.clone(),
        })
        .collect();
    for panel in figures.iter_mut().flat_map(|f| f.panels.iter_mut()) {
        for f in &faults {
            if panel
                .components
                .iter()
                .any(|c| fault_spans::shows(c, &f.target))
            {
                panel.faults.push(f.clone());
            }
        }
    }
}

/// Figures not drawn, each with the reason.
pub type Skipped = Vec<(String, String)>;

/// Builds every figure the input has data for, without drawing: the figures, and the ones
/// skipped with the reason.
pub fn figures(args: &PlotArgs) -> Result<(Vec<Figure>, Skipped), SinkError> {
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
        from_mcap(
            &args.input,
            args.sc_id.as_deref(),
            args.relative_to.as_deref(),
        )?
    } else if args.relative_to.is_some() {
        return Err(SinkError::Arg {
            flag: "--relative-to",
            problem: "needs a recording (.mcap) of several vehicles; a CSV holds one".into(),
        });
    } else {
        from_csv(&args.input)?
    };
    let mut skipped = Vec::new();
    let s = &data.state;
    let t = &s.t_s;
    let mut figures: Vec<Figure> = Vec::new();
    let mut skip = |name: &str, why: &str| skipped.push((name.to_owned(), why.to_owned()));
    let mut fig = |name: &'static str, title: String, panels: Vec<Panel>| {
        figures.push(Figure {
            name: name.to_owned(),
            title,
            panels,
            columns: 1,
        });
    };

    // The vehicle as a whole: where a fault the recording does not name is shaded.
    let whole_vehicle = || vec![fault_spans::UNKNOWN_TARGET.to_owned()];
    match vec_panel(s, "sigma_bn", ["σ1", "σ2", "σ3"], "σ_BN (MRP, –)") {
        Some(sigma) => {
            let mut panels = vec![Panel {
                components: whole_vehicle(),
                ..sigma
            }];
            if let (Some(target), Some(v)) = (target, s.vec3("sigma_bn")) {
                let err: Vec<nalgebra::Vector3<f64>> = vectors(v)
                    .iter()
                    .map(|sigma| mrp_error(sigma, &target))
                    .collect();
                let comp = |i: usize| err.iter().map(|e| e[i]).collect::<Vec<_>>();
                let norm: Vec<f64> = err.iter().map(|e| e.norm()).collect();
                panels.push(Panel {
                    y_label: "σ_BR (MRP, –)".into(),
                    lines: vec![
                        line("σ_BR,1", t, &comp(0)),
                        line("σ_BR,2", t, &comp(1)),
                        line("σ_BR,3", t, &comp(2)),
                        line("|σ_BR|", t, &norm),
                    ],
                    components: whole_vehicle(),
                    ..Panel::default()
                });
            }
            let title = match target {
                Some(r) => format!(
                    "Attitude σ_BN and error σ_BR to σ_RN = ({}, {}, {})",
                    r.x, r.y, r.z
                ),
                None => "Attitude σ_BN (no target given: --sigma-rn adds σ_BR)".into(),
            };
            fig("attitude.png", title, panels);
        }
        None => skip("attitude.png", "no sigma_bn columns"),
    }
    match vec_panel(
        s,
        "omega_bn_b_rad_s",
        ["ω1", "ω2", "ω3"],
        "ω_BN, B components (rad/s)",
    ) {
        Some(p) => fig("rates.png", "Body angular rate ω_BN".into(), vec![p]),
        None => skip("rates.png", "no omega_bn_b_rad_s columns"),
    }
    if let Some((chief, _)) = &data.chief {
        if let Some(panels) = recorded_relative_motion(&data.relative) {
            fig(
                "relative_motion.png",
                // The legends name the axes (x radial, y along-track, z normal).
                format!("Centre of mass relative to {chief}'s, in its Hill frame (recorded)"),
                panels,
            );
        }
    }
    if let (Some((chief, states)), true) = (&data.chief, data.relative.is_empty()) {
        match relative_motion(s, states) {
            Some(panels) => fig(
                "relative_motion.png",
                format!("Hub point B relative to {chief}'s, in its Hill frame"),
                panels,
            ),
            None => skip(
                "relative_motion.png",
                "no instant with both vehicles' r_bn_n_m and v_bn_n_m_s, or the chief has no \
                 orbit plane",
            ),
        }
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
            lines: vec![line("θ1", t, th1), line("θ2", t, th2)],
            ..Panel::default()
        });
    }
    if pairs.is_empty() {
        skip("panels.png", "no pair<k>_theta1/2 columns");
    } else {
        fig(
            "panels.png",
            "Panel hinge angles θ1 (hub–panel 1), θ2 (panel 1–panel 2)".into(),
            pairs,
        );
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
        (Some(tq), Some(f), Some(flags)) => fig(
            "wrench.png",
            "Commanded wrench held over each frame (B components) and command flags".into(),
            // What the participants command: their command links' faults show here.
            [
                tq,
                f,
                Panel {
                    y_label: "command_flags (bits)".into(),
                    lines: vec![line("flags", t, flags)],
                    ..Panel::default()
                },
            ]
            .into_iter()
            .map(|p| Panel {
                components: vec![flexdyn_faults::link::SECTION.to_owned()],
                ..p
            })
            .collect(),
        ),
        _ => skip("wrench.png", "no wrench_applied_* columns"),
    }
    let spans = external_wrench_spans(s);
    let invariant_panel = |y_label: &str, lines: Vec<Line>| Panel {
        y_label: y_label.to_owned(),
        log_y: true,
        lines,
        spans: spans.clone(),
        span_label: "external wrench acts".into(),
        ..Panel::default()
    };
    let energy = match (
        s.get("conserved_orb_energy_j"),
        s.get("conserved_rot_energy_j"),
    ) {
        (Some(o), Some(r)) => {
            let total: Vec<f64> = o.iter().zip(r).map(|(a, b)| a + b).collect();
            Some(invariant_panel(
                "|E − E(0)| / max|E| (–)",
                vec![
                    invariant_line("total energy", t, &relative_change(&total)),
                    invariant_line("orbital energy", t, &relative_change(o)),
                    invariant_line("rotational energy", t, &relative_change(r)),
                ],
            ))
        }
        _ => None,
    };
    let momentum = match (
        s.vec3("conserved_orb_ang_mom_n"),
        s.vec3("conserved_rot_ang_mom_c_n"),
    ) {
        (Some(o), Some(r)) => {
            let (o, r) = (vectors(o), vectors(r));
            let total: Vec<_> = o.iter().zip(&r).map(|(a, b)| a + b).collect();
            Some(invariant_panel(
                "|H − H(0)| / max|H| (–)",
                vec![
                    invariant_line("total H", t, &relative_change_vec(&total)),
                    invariant_line("orbital H (about N)", t, &relative_change_vec(&o)),
                    invariant_line("rotational H (about C)", t, &relative_change_vec(&r)),
                ],
            ))
        }
        _ => None,
    };
    match (energy, momentum) {
        (Some(e), Some(h)) => fig(
            "conservation.png",
            "Invariants, each relative to its own scale (log); shaded: an external wrench acts"
                .into(),
            vec![e, h],
        ),
        _ => skip("conservation.png", "no conserved_* columns"),
    }
    let wheels: Vec<Panel> = [
        ("_omega_rad_s", "Ω", "speed Ω, rel. hub (rad/s)"),
        ("_motor_torque_nm", "u", "motor torque applied (N·m)"),
        ("_flags", "flags", "flags (1 torque-, 2 speed-limited)"),
    ]
    .iter()
    .filter_map(|(suffix, label, y)| numbered_panel(s, "rw", suffix, &format!("{label} rw"), y))
    .collect();
    if wheels.is_empty() {
        skip("wheels.png", "no rw<k>_* columns");
    } else {
        fig(
            "wheels.png",
            "Reaction wheels: speed, motor torque after the limits, limit flags".into(),
            wheels,
        );
    }
    let actuators: Vec<Panel> = [
        ("mtq", "_dipole_am2", "m mtq", "rod dipole applied (A·m²)"),
        ("thr", "_thrust_newton", "F thr", "thrust (N)"),
        ("thr", "_pulse_count", "pulses thr", "pulse count"),
        (
            "thr",
            "_propellant_used_kg",
            "used thr",
            "propellant used (kg)",
        ),
    ]
    .iter()
    .filter_map(|(prefix, suffix, label, y)| numbered_panel(s, prefix, suffix, label, y))
    .collect();
    if actuators.is_empty() {
        skip("actuators.png", "no mtq<k>_* or thr<k>_* columns");
    } else {
        fig(
            "actuators.png",
            "Actuators: magnetorquer dipoles; thruster firings, pulses, propellant".into(),
            actuators,
        );
    }
    match disturbance_panels(&data.environment) {
        Some(panels) => fig(
            "disturbance_torques.png",
            "Environment disturbances by source (EnvironmentMsg): |torque| about B, |force|, \
             shadow factor"
                .into(),
            panels,
        ),
        None => skip(
            "disturbance_torques.png",
            "no environment record ([environment] telemetry_rate_hz unset)",
        ),
    }
    // One figure per sensor kind, its panels side by side per sensor (`SensorKind::plot`).
    for (i, kind) in KINDS.iter().enumerate() {
        let (file, title, specs) = kind.plot;
        let mut sensors: Vec<Vec<Panel>> = Vec::new();
        for ((_, name), c) in data
            .sensors
            .range((i, String::new())..(i + 1, String::new()))
        {
            let sensor_panels: Vec<Panel> = specs
                .iter()
                .map(|spec| Panel {
                    caption: Some(format!("{} {name}", kind.noun)),
                    components: vec![format!("{}.{name}", kind.config_array)],
                    y_label: spec.y_label.into(),
                    lines: spec
                        .lines
                        .iter()
                        .filter(|(col, _)| plotted_column(c, col))
                        .filter_map(|(col, label)| c.get(col).map(|v| line(label, &c.t_s, v)))
                        .collect(),
                    ..Panel::default()
                })
                .collect();
            if sensor_panels.iter().any(|p| !p.lines.is_empty()) {
                sensors.push(sensor_panels);
            }
        }
        // A panel no sensor of the kind has a line on (a coarse array's detectors 7–16 when
        // none has more than 6) is left out for all of them, so the grid stays regular.
        let kept: Vec<usize> = (0..specs.len())
            .filter(|k| sensors.iter().any(|p| !p[*k].lines.is_empty()))
            .collect();
        let rows = kept.len();
        let panels: Vec<Panel> = sensors
            .into_iter()
            .flat_map(|mut p| {
                kept.iter()
                    .map(|k| std::mem::take(&mut p[*k]))
                    .collect::<Vec<_>>()
            })
            .collect();
        if panels.is_empty() {
            skip(file, &format!("no {}", kind.noun));
        } else {
            figures.push(sensor_grid(file, title, panels, rows));
        }
    }
    let st = &data.status;
    let timing = (
        st.get("timing_lateness_p50_ns"),
        st.get("timing_lateness_p99_ns"),
        st.get("timing_lateness_max_ns"),
        st.get("timing_overrun_count"),
    );
    match (data.mode, timing) {
        (Some(mode @ (flexdyn_proto::Mode::Lockstep | flexdyn_proto::Mode::Batch)), _) => {
            let why = format!(
                "a {} run is not paced by the wall clock, so it has no frame lateness",
                if mode == flexdyn_proto::Mode::Lockstep {
                    "lockstep"
                } else {
                    "batch"
                }
            );
            skipped.push(("timing.png".into(), why));
        }
        (_, (Some(p50), Some(p99), Some(max), Some(overruns))) => {
            let us = |v: &Vec<f64>| v.iter().map(|x| x * 1e-3).collect::<Vec<_>>();
            figures.push(Figure {
                name: "timing.png".into(),
                title: "Real-time frame lateness (cumulative percentiles from StatusMsg)".into(),
                panels: vec![
                    Panel {
                        y_label: "lateness (µs)".into(),
                        lines: vec![
                            line("p50", &st.t_s, &us(p50)),
                            line("p99", &st.t_s, &us(p99)),
                            line("max", &st.t_s, &us(max)),
                        ],
                        ..Panel::default()
                    },
                    Panel {
                        y_label: "overruns (count)".into(),
                        lines: vec![line("overruns", &st.t_s, overruns)],
                        ..Panel::default()
                    },
                ],
                columns: 1,
            });
        }
        _ => skipped.push((
            "timing.png".into(),
            "no StatusMsg (only recordings have it)".into(),
        )),
    }
    shade_faults(&mut figures, &data.faults, time_span(s).0);
    flight_code_figures(&data, &mut figures, &mut skipped);
    Ok((figures, skipped))
}

/// The flight code's figures ([`fsw`]): each stream's mode timeline under the attitude, and its
/// own figures against the truth attitude of the same ticks.
fn flight_code_figures(data: &PlotData, figures: &mut Vec<Figure>, skipped: &mut Skipped) {
    let s = &data.state;
    let truth: fsw::Truth = match (
        s.get("tick"),
        (0..4)
            .map(|i| s.get(&format!("q_bn_{i}")))
            .collect::<Option<Vec<_>>>(),
    ) {
        (Some(ticks), Some(q)) => ticks
            .iter()
            .enumerate()
            .map(|(k, tick)| {
                (
                    *tick as u64,
                    nalgebra::Vector4::new(q[0][k], q[1][k], q[2][k], q[3][k]),
                )
            })
            .collect(),
        _ => fsw::Truth::new(),
    };
    for series in &data.fsw {
        let name = &series.decl.name;
        if series.samples.is_empty() {
            skipped.push((
                format!("fsw_{name}.png"),
                format!("the configuration declares stream `{name}`, but the recording holds no sample of it"),
            ));
            continue;
        }
        if let Some(panel) = fsw::mode_panel(series) {
            if let Some(att) = figures.iter_mut().find(|f| f.name == "attitude.png") {
                att.panels.push(panel);
            }
        }
        figures.extend(fsw::figures(series, &truth));
    }
}

/// Whether a sensor's column `col` is one of its own: a coarse array's `readings_<k>` only
/// for k up to its `detector_count` (the CssMsg's slots beyond are 0 and no detector's).
fn plotted_column(c: &Columns, col: &str) -> bool {
    let Some(k) = col
        .strip_prefix("readings_")
        .and_then(|k| k.parse::<f64>().ok())
    else {
        return true;
    };
    c.get("detector_count").is_none_or(|n| {
        let count = n
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(0.0, f64::max);
        k <= count
    })
}

/// The disturbance figure's panels: per environment source, |τ_B| and |F_B| from its
/// `<source>_torque_b_nm_1..3` / `<source>_force_b_newton_1..3` columns (log axes: the sources
/// differ by orders of magnitude), and the shadow factor. `None` without the record.
/// The deputy's hub point B relative to the chief's, at the instants both were recorded, in the
/// chief's Hill frame ([`flexdyn_vehicle::world::relative_state_hill`], with the hub points standing in
/// for the centres of mass: the relative state of the points the StateMsg carries): position,
/// its rate seen in that frame, range and range rate.
fn relative_motion(deputy: &Columns, chief: &Columns) -> Option<Vec<Panel>> {
    let (rd, vd) = (deputy.vec3("r_bn_n_m")?, deputy.vec3("v_bn_n_m_s")?);
    let (rc, vc) = (chief.vec3("r_bn_n_m")?, chief.vec3("v_bn_n_m_s")?);
    // Recorded instants are whole nanoseconds: match them exactly.
    let ns = |t: f64| (t * 1e9).round() as i64;
    let at: BTreeMap<i64, usize> = chief
        .t_s
        .iter()
        .enumerate()
        .map(|(j, t)| (ns(*t), j))
        .collect();
    let v3 = |c: [&Vec<f64>; 3], k: usize| nalgebra::Vector3::new(c[0][k], c[1][k], c[2][k]);
    let (mut t, mut r_h, mut v_h) = (
        Vec::new(),
        [vec![], vec![], vec![]],
        [vec![], vec![], vec![]],
    );
    let (mut range, mut range_rate) = (Vec::new(), Vec::new());
    for (i, td) in deputy.t_s.iter().enumerate() {
        let Some(&j) = at.get(&ns(*td)) else {
            continue;
        };
        let Some(rel) = flexdyn_vehicle::world::relative_state_hill(
            &v3(rc, j),
            &v3(vc, j),
            &v3(rd, i),
            &v3(vd, i),
        ) else {
            continue;
        };
        t.push(*td);
        for k in 0..3 {
            r_h[k].push(rel.r_dc_h_m[k]);
            v_h[k].push(rel.v_dc_h_m_s[k]);
        }
        range.push(rel.range_m);
        range_rate.push(rel.range_rate_m_s);
    }
    if t.is_empty() {
        return None;
    }
    Some(relative_panels(&t, &r_h, &v_h, &range, &range_rate))
}

/// The relative-motion panels from the recorded RelativeStateMsg columns (`r_dc_h_m_1..3`,
/// `v_dc_h_m_s_1..3`, `range_m`, `range_rate_m_s`), as the server computed them at the
/// centres of mass. `None` without them.
fn recorded_relative_motion(rel: &Columns) -> Option<Vec<Panel>> {
    if rel.is_empty() {
        return None;
    }
    let (r, v) = (rel.vec3("r_dc_h_m")?, rel.vec3("v_dc_h_m_s")?);
    let (range, range_rate) = (rel.get("range_m")?, rel.get("range_rate_m_s")?);
    let own = |c: [&Vec<f64>; 3]| [c[0].clone(), c[1].clone(), c[2].clone()];
    Some(relative_panels(
        &rel.t_s,
        &own(r),
        &own(v),
        range,
        range_rate,
    ))
}

/// Position and rate in H, range and range rate against time.
fn relative_panels(
    t: &[f64],
    r_h: &[Vec<f64>; 3],
    v_h: &[Vec<f64>; 3],
    range: &[f64],
    range_rate: &[f64],
) -> Vec<Panel> {
    let xyz = |c: &[Vec<f64>; 3], unit: &str| {
        vec![
            line(&format!("x radial ({unit})"), t, &c[0]),
            line(&format!("y along-track ({unit})"), t, &c[1]),
            line(&format!("z normal ({unit})"), t, &c[2]),
        ]
    };
    vec![
        Panel {
            y_label: "position in H (m)".into(),
            lines: xyz(r_h, "m"),
            ..Panel::default()
        },
        Panel {
            y_label: "rate seen in H (m/s)".into(),
            lines: xyz(v_h, "m/s"),
            ..Panel::default()
        },
        Panel {
            y_label: "range (m)".into(),
            lines: vec![line("range", t, range)],
            ..Panel::default()
        },
        Panel {
            y_label: "range rate (m/s)".into(),
            lines: vec![line("range rate", t, range_rate)],
            ..Panel::default()
        },
    ]
}

fn disturbance_panels(env: &Columns) -> Option<Vec<Panel>> {
    if env.is_empty() {
        return None;
    }
    let magnitude_panel = |what: &str, y_label: &str| {
        let lines = flexdyn_dynamics::EnvironmentSource::ALL
            .iter()
            .filter_map(|src| {
                let v = env.vec3(&format!("{}_{what}", src.name()))?;
                let norm: Vec<f64> = (0..env.t_s.len())
                    .map(|i| (v[0][i].powi(2) + v[1][i].powi(2) + v[2][i].powi(2)).sqrt())
                    .collect();
                Some(line(src.name(), &env.t_s, &norm))
            })
            .collect();
        Panel {
            y_label: y_label.to_owned(),
            log_y: true,
            lines,
            ..Panel::default()
        }
    };
    let mut panels = vec![
        magnitude_panel("torque_b_nm", "|torque about B| (N·m)"),
        magnitude_panel("force_b_newton", "|force| (N)"),
    ];
    if let Some(nu) = env.get("shadow_factor") {
        panels.push(Panel {
            y_label: "shadow factor ν (1 sunlit, 0 umbra)".into(),
            lines: vec![line("ν", &env.t_s, nu)],
            ..Panel::default()
        });
    }
    if panels[0].lines.is_empty() {
        None
    } else {
        Some(panels)
    }
}

/// A figure of `rows` panels per sensor (given sensor by sensor), one column per sensor, so
/// each panel keeps the height its labels need however many sensors there are.
fn sensor_grid(name: &'static str, title: &str, panels: Vec<Panel>, rows: usize) -> Figure {
    let columns = panels.len() / rows.max(1);
    Figure {
        name: name.to_owned(),
        title: title.to_owned(),
        panels: interleave_columns(panels, columns),
        columns,
    }
}

/// Panels given sensor by sensor (`rows` per sensor, consecutive) reordered row by row for a
/// grid of `columns` sensors side by side.
fn interleave_columns(panels: Vec<Panel>, columns: usize) -> Vec<Panel> {
    let rows = panels.len() / columns.max(1);
    let mut slots: Vec<Option<Panel>> = panels.into_iter().map(Some).collect();
    let mut out = Vec::with_capacity(slots.len());
    for r in 0..rows {
        for c in 0..columns {
            if let Some(p) = slots[c * rows + r].take() {
                out.push(p);
            }
        }
    }
    out
}

/// Draws every figure the input has data for.
pub fn plot(args: &PlotArgs) -> Result<PlotReport, SinkError> {
    plot_with(args, &mut |_| {})
}

/// [`plot`], calling `written` with each figure's path as soon as it is written (reading a
/// recording prints its progress on stderr, [`read::ReadProgress`]).
pub fn plot_with(args: &PlotArgs, written: &mut dyn FnMut(&Path)) -> Result<PlotReport, SinkError> {
    let (figures, skipped) = figures(args)?;
    std::fs::create_dir_all(&args.output).map_err(|e| SinkError::Output {
        path: args.output.clone(),
        problem: e.to_string(),
    })?;
    register_font()?;
    let mut report = PlotReport {
        written: Vec::new(),
        skipped,
    };
    for f in &figures {
        let path = args.output.join(&f.name);
        draw(&path, f)?;
        written(&path);
        report.written.push(path);
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A log panel with nothing positive (a vehicle at rest: every invariant zero or exactly
    /// constant) gets finite bounds; it used to get (∞, ∞), and plotters then ran out of memory.
    #[test]
    fn a_log_panel_with_nothing_positive_has_finite_bounds() {
        let panel = Panel {
            log_y: true,
            lines: vec![Line {
                label: "H".into(),
                points: vec![(0.0, 0.0), (1.0, 0.0)],
            }],
            ..Panel::default()
        };
        let (lo, hi) = panel.y_range();
        assert!(
            lo.is_finite() && hi.is_finite() && 0.0 < lo && lo < hi,
            "{lo} {hi}"
        );
    }

    /// Issue 36: a title too wide for the figure at the usual size is set smaller until it
    /// fits (plotters centres it and cuts both ends otherwise); a short one keeps the size.
    #[test]
    fn titles_fit_the_figure_width() {
        register_font().unwrap();
        let room = SIZE.0 - 2 * TITLE_SIDE_PX;
        let short = "Body angular rate ω_BN";
        assert_eq!(title_font_px(short), TITLE_PX);
        // The title relative_motion.png had before (issue 36), with formation.toml's chief.
        let long = "Centre of mass relative to chief's, in chief's Hill frame (x radial, \
                    y along-track, z orbit normal; recorded RelativeStateMsg)";
        assert!(text_width_px(long, TITLE_PX) > room);
        let px = title_font_px(long);
        assert!(px < TITLE_PX && text_width_px(long, px) <= room, "{px}");
    }

    /// Every column a sensor kind's plot panels name is a column of its message, so no panel
    /// of a registered kind is silently empty.
    #[test]
    fn every_kind_plots_columns_of_its_message() {
        for kind in KINDS {
            let columns = column_names(&(kind.default_json)());
            for spec in kind.plot.2 {
                for (col, _) in spec.lines {
                    assert!(
                        columns.iter().any(|c| c == col),
                        "{}: panel column {col} not in {columns:?}",
                        kind.noun
                    );
                }
            }
        }
    }
}
