//! `flexdyn simulate`: propagates a configuration offline through the vehicle layer's offline
//! loop ([`walk`], a world of one) and writes the state history, the scheduled wrench, the
//! environment record and the sensors as CSV.

use std::fmt;
use std::io::Write;
use std::num::NonZeroU64;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use flexdyn_proto::{command_flags, AppliedWrench, EnvironmentMsg, Header, StateMsg};

use super::checkpoint::{self as ckpt, CheckpointArgs, SaveAt};
use super::{exit, load, summary, whole_steps, CliError, OfflineRun};
use flexdyn_sensors::Sensor;
use flexdyn_server::settings::ServerSettings;
use flexdyn_sinks::table::{
    first_non_finite_column, prefixed_cells, prefixed_columns, state_cells, state_row, Cell,
    Column, CsvTable, ENVIRONMENT_COLUMN_PREFIX,
};
use flexdyn_vehicle::checkpoint::Source;
use flexdyn_vehicle::checkpoint::{Checkpoint, CheckpointHeader};
use flexdyn_vehicle::config::{log_warnings, SimConfig};
use flexdyn_vehicle::sim::Simulation;
use flexdyn_vehicle::world::{walk, RowPlan, RowSink, World};

/// Arguments of `flexdyn simulate`.
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct SimulateArgs {
    /// Configuration file (TOML). Default: the embedded reference spacecraft
    /// (`flexdyn print-default-config`).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// How long, and where the CSV goes.
    #[command(flatten)]
    pub run: OfflineRun,
    /// Interval between CSV rows in seconds; must be a whole number of RK4 steps. A row is also written
    /// at t = 0.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 0.01,
        allow_negative_numbers = true
    )]
    pub log_every_s: f64,
    /// Checkpoints: save one, or resume from one.
    #[command(flatten)]
    pub checkpoints: CheckpointArgs,
}

impl Default for SimulateArgs {
    fn default() -> Self {
        Self {
            config: None,
            run: OfflineRun::default(),
            log_every_s: 0.01,
            checkpoints: CheckpointArgs::default(),
        }
    }
}

/// The checkpoints of a `simulate` run: the one it resumes from, the one it writes.
#[derive(Debug, Default)]
pub struct Checkpoints<'a> {
    /// Resume from this checkpoint (read from this file).
    pub resume: Option<(&'a Checkpoint<'a>, &'a Path)>,
    /// Write a checkpoint, recording this configuration as the run's source.
    pub save: Option<(SaveAt, Source)>,
}

/// What `simulate` did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulateReport {
    /// RK4 steps taken.
    pub steps: u64,
    /// CSV data rows written (excluding the header).
    pub rows: u64,
    /// \[s\] wall time of the loop that steps and writes the rows (excludes configuration parsing,
    /// spacecraft construction and the final flush).
    pub wall_s: f64,
}

impl SimulateReport {
    /// Steps per wall-clock second.
    pub fn steps_per_s(&self) -> f64 {
        if self.wall_s > 0.0 {
            self.steps as f64 / self.wall_s
        } else {
            0.0
        }
    }
}

/// The one-line summary printed to stderr: `steps=<n> wall_s=<x> steps_per_s=<y>`.
impl fmt::Display for SimulateReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "steps={} wall_s={:.6} steps_per_s={:.1}",
            self.steps,
            self.wall_s,
            self.steps_per_s()
        )
    }
}

/// The scheduled wrench in effect at the current instant (schedule(t) alone, without the
/// commanded wrench), for `simulate`'s `wrench_schedule_*` columns.
fn scheduled_wrench(cfg: &SimConfig, t_ns: u64) -> AppliedWrench {
    let seg = cfg
        .wrench_schedule
        .iter()
        .take_while(|w| w.t_start_ns <= t_ns)
        .last();
    seg.map_or_else(AppliedWrench::default, |w| AppliedWrench {
        torque_b_nm: w.torque_b_nm.into(),
        force_b_newton: w.force_b_newton.into(),
    })
}

/// One `simulate` row in the CSV dialect of [`flexdyn_sinks::table`]: the state record (as
/// `export` writes it), the scheduled wrench, then each sensor's columns in publication order
/// (`None`: no sample in this row, its cells stay empty).
fn simulate_row(
    state: &StateMsg,
    wrench_schedule: &AppliedWrench,
    environment: Option<&EnvironmentMsg>,
    sensors: impl Iterator<Item = Option<Vec<Column>>>,
) -> Vec<Column> {
    let mut row = state_row(state);
    row.extend(prefixed_columns("wrench_schedule", wrench_schedule));
    if let Some(env) = environment {
        row.extend(prefixed_columns(ENVIRONMENT_COLUMN_PREFIX, env));
    }
    row.extend(sensors.flatten().flatten());
    row
}

/// A sensor's CSV columns from its encoded message `bytes`: the fields without the header,
/// prefixed `<kind>_<name>_` (`imu_hub_omega_p_rad_s_1`, `st_st1_q_cn_0`).
fn sensor_columns(s: &dyn Sensor, bytes: &[u8]) -> Vec<Column> {
    prefixed_columns(&sensor_prefix(s), &sensor_json(s, bytes))
}

/// A sensor's encoded message as its kind decodes it (`null` if it does not decode).
fn sensor_json(s: &dyn Sensor, bytes: &[u8]) -> serde_json::Value {
    (s.kind().decode)(bytes).map_or(serde_json::Value::Null, |(_, json)| json)
}

/// Where a row's cells go in the header: the state, scheduled-wrench and environment cells
/// first, always all of them, then each sensor's block, in publication order.
struct Layout {
    /// The number of state, scheduled-wrench and environment cells.
    fixed: usize,
    /// Per sensor: the header position of its first cell and its number of cells.
    sensors: Vec<(usize, usize)>,
}

/// A row's cells without names, and their header positions ([`SimulateRows::row`]).
#[derive(Default)]
struct Placed {
    cells: Vec<Column>,
    positions: Vec<usize>,
}

/// `<kind>_<name>`.
fn sensor_prefix(s: &dyn Sensor) -> String {
    format!("{}_{}", s.kind().column_prefix, s.name())
}

/// Simulates `cfg` for `duration_s`, writing a CSV row at t = 0 and every `log_every_s` to
/// `out`. `target` names the output in errors.
///
/// Each row is the state record the server would publish at that instant (`tick` is the frame
/// the instant falls in, `seq` the row number; no flight code, so `wrench_applied` is zero and
/// `command_flags` says no command yet), then the scheduled wrench, then the sensors: those
/// that integrate over an interval (the IMUs) at every row, their interval being the log
/// interval; the others (the star trackers) sampled at the frame boundaries where they are due,
/// as the server does, their cells filled in the rows that fall on such a sample. With
/// `[environment] telemetry_rate_hz` set, every row also carries the environment record at its
/// instant (`env_*`: the EnvironmentMsg fields, [`Simulation::environment_into`]), before the
/// sensors.
///
/// Comment lines before the header: `epoch_utc=…` with an `[epoch]`, and one
/// `fault=<index>,<start_ns>,<duration_ns>,<period_ns>,<mode>,<target>` per `[[faults]]`
/// entry, its window as resolved at load ([`flexdyn_sinks::fault_spans`]).
pub fn simulate_to<W: Write>(
    cfg: &SimConfig,
    duration_s: f64,
    log_every_s: f64,
    out: W,
    target: &str,
) -> Result<SimulateReport, CliError> {
    simulate_with(
        cfg,
        duration_s,
        log_every_s,
        || Ok((out, target.to_string())),
        Checkpoints::default(),
    )
}

/// [`simulate_to`], resuming from a checkpoint and writing one as `checkpoints` asks. A resumed
/// run writes the rows after the checkpoint's instant (its comments and header as a whole run
/// writes them), each bit-identical to the uninterrupted run's. `open` gives the output and its
/// name for errors; it is called once every option, the configuration and the checkpoints have
/// been checked, so a refused run never creates or truncates its output.
pub fn simulate_with<W: Write>(
    cfg: &SimConfig,
    duration_s: f64,
    log_every_s: f64,
    open: impl FnOnce() -> Result<(W, String), CliError>,
    checkpoints: Checkpoints<'_>,
) -> Result<SimulateReport, CliError> {
    simulate_rows(cfg, duration_s, log_every_s, open, checkpoints, false)
}

/// [`simulate_with`], each row written by position ([`Layout`]), or with `by_name` every row
/// built with its column names and placed by name (the tests' reference).
fn simulate_rows<W: Write>(
    cfg: &SimConfig,
    duration_s: f64,
    log_every_s: f64,
    open: impl FnOnce() -> Result<(W, String), CliError>,
    checkpoints: Checkpoints<'_>,
    by_name: bool,
) -> Result<SimulateReport, CliError> {
    let total_steps = whole_steps("--duration-s", duration_s, cfg.step_ns, true)?;
    let log_steps = whole_steps("--log-every-s", log_every_s, cfg.step_ns, false)?;
    let mut sim = Simulation::new(cfg).map_err(|source| CliError::Config { file: None, source })?;
    // The sensors' sample interval is the log interval (log_steps ≥ 1 and step_ns ≥ 1).
    if let Some(ns) = NonZeroU64::new(log_steps * cfg.step_ns) {
        sim.set_sensor_sample_interval_ns(ns);
    }
    // The server's numeric id, so a row equals the StateMsg a server run of this file
    // publishes (`check-config` and `run` validate `[server]`; `simulate` only reads the id).
    let settings = ServerSettings::from_table(&cfg.server).unwrap_or_default();
    let spacecraft_id = settings.spacecraft_id;
    let steps_per_frame = sim.steps_per_frame();
    let at_frames = sim.sensors().any(|s| !s.every_output());
    // A world of one, stepped by the offline loop every front end shares; a resumed run's state
    // is restored before anything is written.
    let mut world = World::of_one(settings.sc_id, spacecraft_id, sim);
    let start_step = match checkpoints.resume {
        Some((c, file)) => ckpt::resume(c, file, &mut world, log_steps, total_steps)?,
        None => 0,
    };
    let sim = &world.vehicles()[0].sim;
    let save = match checkpoints.save {
        Some((at, source)) => {
            let step = ckpt::save_step(
                &at,
                cfg.step_ns,
                cfg.frame_ns,
                log_steps,
                total_steps,
                start_step,
            )?;
            Some((
                step,
                CheckpointHeader {
                    front_end: "simulate".into(),
                    source_sha256: CheckpointHeader::digest(&source.text),
                    source_path: source.path,
                    source_text: source.text,
                    tick: step / steps_per_frame.max(1),
                    t_sim_ns: step * cfg.step_ns,
                    step_ns: cfg.step_ns,
                    frame_ns: cfg.frame_ns,
                    row_steps: log_steps,
                    ..CheckpointHeader::default()
                },
                at.file,
            ))
        }
        None => None,
    };

    let mut state = sim.blank_state();
    state.command_flags = command_flags::NO_COMMAND_YET;
    // `[environment] telemetry_rate_hz` set: the environment record at every row's instant.
    let environment = sim
        .environment_every_frames()
        .map(|_| EnvironmentMsg::default());
    // The header: every column a row can have (each sensor as at a sample).
    let blocks: Vec<Vec<Column>> = sim
        .sensors()
        .sensors()
        .iter()
        .map(|s| prefixed_columns(&sensor_prefix(s.as_ref()), &(s.kind().default_json)()))
        .collect();
    let lens: Vec<usize> = blocks.iter().map(Vec::len).collect();
    let all = blocks.into_iter().map(Some);
    let columns: Vec<String> =
        simulate_row(&state, &AppliedWrench::default(), environment.as_ref(), all)
            .into_iter()
            .map(|(name, _)| name)
            .collect();
    // The sensors' blocks close the header; what comes before them is the fixed part.
    let fixed = columns.len() - lens.iter().sum::<usize>();
    let mut at = fixed;
    let layout = Layout {
        fixed,
        sensors: lens
            .into_iter()
            .map(|len| {
                at += len;
                (at - len, len)
            })
            .collect(),
    };
    // What t_s = 0 is, when the configuration has an [epoch]; then each fault's resolved
    // window (`flexdyn plot` shades it).
    let comments: Vec<String> = cfg
        .epoch
        .iter()
        .map(|e| format!("epoch_utc={}", e.utc_iso()))
        .chain(
            cfg.faults
                .iter()
                .enumerate()
                .map(|(i, f)| flexdyn_sinks::fault_spans::csv_comment(i, f)),
        )
        .collect();
    // Everything is checked: only now is the output created.
    let (out, target) = open()?;
    let target = target.as_str();
    let io_err = |source| CliError::Output {
        target: target.to_string(),
        source,
    };
    let table = CsvTable::with_comments(out, &comments, &columns).map_err(io_err)?;
    let mut rows = SimulateRows {
        cfg,
        spacecraft_id,
        steps_per_frame,
        state,
        environment,
        last: vec![(None, Vec::new()); sim.sensors().len()],
        table,
        layout: (!by_name).then_some(layout),
        placed: Placed::default(),
        target,
        save,
    };
    let plan = RowPlan {
        total_steps,
        log_steps,
        frame_stops: at_frames,
        start_step,
    };
    let start = Instant::now();
    let written = walk(&mut world, plan, &mut rows)?;
    let wall_s = start.elapsed().as_secs_f64();
    rows.table.flush().map_err(io_err)?;
    tracing::debug!(steps = total_steps, rows = written, "simulate done");
    Ok(SimulateReport {
        steps: total_steps - start_step,
        rows: written,
        wall_s,
    })
}

/// `simulate`'s rows, written as the offline loop ([`walk`]) reaches them.
struct SimulateRows<'a, W: Write> {
    cfg: &'a SimConfig,
    spacecraft_id: u32,
    steps_per_frame: u64,
    /// The state record, reused row to row.
    state: StateMsg,
    /// `[environment] telemetry_rate_hz` set: the environment record, reused row to row.
    environment: Option<EnvironmentMsg>,
    /// Per sensor: the step of its last sample and that sample's message, encoded when it was
    /// taken. It becomes CSV columns (a decode into JSON, then text) only if a row falls on that
    /// step: a 10 Hz sensor logged every second is encoded ten times and formatted once.
    last: Vec<(Option<u64>, Vec<u8>)>,
    table: CsvTable<W>,
    /// Where a row's cells go: each row is written by position, its cells built without
    /// names. A row whose cells do not fit it, or that has a non-finite value, is built by
    /// name (`None`: every row is, the reference the tests compare with).
    layout: Option<Layout>,
    /// The last row's cells, reused.
    placed: Placed,
    target: &'a str,
    /// A checkpoint to write after the row at this step.
    save: Option<(u64, CheckpointHeader, PathBuf)>,
}

impl<W: Write> SimulateRows<'_, W> {
    /// Encodes the samples the sensors just took, noting their step.
    fn take(&mut self, sim: &Simulation, step: u64, header: Header) {
        let bank = sim.sensors();
        for &i in bank.sampled() {
            let (at, bytes) = &mut self.last[i];
            bank.sensors()[i].encode(header, bytes);
            *at = Some(step);
        }
    }
}

impl<W: Write> RowSink for SimulateRows<'_, W> {
    type Error = CliError;

    /// A frame boundary: the sensors sampled there (not those that integrate over a row) take
    /// their samples where a server's would.
    fn frame(&mut self, world: &mut World, step: u64) {
        let Some(v) = world.vehicles_mut().first_mut() else {
            return;
        };
        let tick = step / self.steps_per_frame;
        v.sim.sample_sensors(|s| !s.every_output() && s.due(tick));
        let header = Header::new(self.spacecraft_id, tick, v.sim.t_sim_ns(), tick);
        self.take(&v.sim, step, header);
    }

    fn row(&mut self, world: &mut World, k: u64, step: u64) -> Result<(), CliError> {
        let io_err = |source| CliError::Output {
            target: self.target.to_string(),
            source,
        };
        let Some(v) = world.vehicles_mut().first_mut() else {
            return Ok(());
        };
        let sim = &mut v.sim;
        sim.state_into(&mut self.state);
        let t_ns = self.state.header.sim_time_ns;
        self.state.header = Header::new(self.spacecraft_id, t_ns / self.cfg.frame_ns, t_ns, k);
        sim.sample_sensors(|s| s.every_output());
        let header = self.state.header;
        self.take(sim, step, header);
        if let Some(env) = self.environment.as_mut() {
            sim.environment_into(env);
        }
        let bank = sim.sensors().sensors();
        if let Some(layout) = &self.layout {
            let wrench = scheduled_wrench(self.cfg, t_ns);
            let env = self.environment.as_ref();
            let sensors = self.last.iter().zip(bank).map(|((at, bytes), s)| {
                (*at == Some(step)).then(|| sensor_json(s.as_ref(), bytes))
            });
            if self
                .placed
                .place(layout, &self.state, &wrench, env, sensors)
            {
                let placed = &self.placed;
                let cells = placed.cells.iter().map(|(_, c)| c);
                let row = placed.positions.iter().copied().zip(cells);
                self.table.write_positioned(row).map_err(io_err)?;
                return self.after_row(world, step);
            }
        }
        let now =
            self.last.iter().zip(bank).map(|((at, bytes), s)| {
                (*at == Some(step)).then(|| sensor_columns(s.as_ref(), bytes))
            });
        let row = simulate_row(
            &self.state,
            &scheduled_wrench(self.cfg, t_ns),
            self.environment.as_ref(),
            now,
        );
        // Once per row, outside the stepping loop: never write a non-finite state.
        if let Some(quantity) = first_non_finite_column(&row) {
            self.table.flush().map_err(io_err)?;
            return Err(CliError::NonFinite {
                step,
                t_s: t_ns as f64 / 1e9,
                quantity: quantity.to_owned(),
            });
        }
        self.table.write_row(&row).map_err(io_err)?;
        self.after_row(world, step)
    }
}

impl<W: Write> SimulateRows<'_, W> {
    /// After the row at `step`: the checkpoint, if one is due there.
    fn after_row(&mut self, world: &mut World, step: u64) -> Result<(), CliError> {
        if let Some((at, header, file)) = &self.save {
            if *at == step {
                // Everything written so far reaches the output before the checkpoint does.
                self.table.flush().map_err(|source| CliError::Output {
                    target: self.target.to_string(),
                    source,
                })?;
                ckpt::write(file, header, world)?;
            }
        }
        Ok(())
    }
}

impl Placed {
    /// Builds a row's cells (as [`simulate_row`] orders them, without names) and their header
    /// positions; `false` if they do not fit `layout` (a sensor message that did not decode)
    /// or a value is not finite: that row is built by name, which names the bad column.
    fn place(
        &mut self,
        layout: &Layout,
        state: &StateMsg,
        wrench: &AppliedWrench,
        environment: Option<&EnvironmentMsg>,
        sensors: impl Iterator<Item = Option<serde_json::Value>>,
    ) -> bool {
        let (cells, positions) = (&mut self.cells, &mut self.positions);
        cells.clear();
        positions.clear();
        state_cells(state, cells);
        prefixed_cells(wrench, cells);
        if let Some(env) = environment {
            prefixed_cells(env, cells);
        }
        if cells.len() != layout.fixed {
            return false;
        }
        positions.extend(0..layout.fixed);
        for (json, &(first, len)) in sensors.zip(&layout.sensors) {
            let Some(json) = json else { continue };
            let before = cells.len();
            prefixed_cells(&json, cells);
            if cells.len() - before != len {
                return false;
            }
            positions.extend(first..first + len);
        }
        cells
            .iter()
            .all(|(_, c)| !matches!(c, Cell::Num(x) if !x.is_finite()))
    }
}

/// `flexdyn simulate`: loads the configuration, checks the options, and writes the CSV to the
/// output file or stdout. The output file is created only once everything else is valid.
pub fn simulate(args: &SimulateArgs) -> Result<SimulateReport, CliError> {
    // A resumed run: the checkpoint's configuration, or with `--config` another one (a fork).
    let bytes = match &args.checkpoints.resume {
        Some(file) => Some(ckpt::read(file)?),
        None => None,
    };
    let resumed = match (&args.checkpoints.resume, &bytes) {
        (Some(file), Some(b)) => Some((ckpt::parse(file, b, "simulate")?, file.as_path())),
        _ => None,
    };
    // The configuration's path and text, which a checkpoint records: read only when this run
    // resumes or saves one.
    let source = match (&resumed, &args.config) {
        (Some((c, _)), None) => Some(Source::recorded(&c.header)),
        _ if resumed.is_some() || args.checkpoints.checkpoint_at_s.is_some() => {
            Some(ckpt::source_of(args.config.as_deref())?)
        }
        _ => None,
    };
    let cfg = match (&resumed, &source, &args.config) {
        (Some(_), Some(source), None) => ckpt::recorded_config(source)?,
        _ => load(args.config.as_deref())?,
    };
    if let (Some((c, file)), Some(source)) = (&resumed, &source) {
        if CheckpointHeader::digest(&source.text) != c.header.source_sha256 {
            summary(format_args!(
                "note: resuming `{}` with a configuration that differs from the one it was \
                 taken with: a fork",
                file.display()
            ));
        }
    }
    log_warnings(&cfg, args.config.as_deref());
    // `simulate_with` checks the options, the configuration and the checkpoints before it
    // creates (and truncates) the output file.
    let save = match (
        args.checkpoints.checkpoint_at_s,
        &args.checkpoints.checkpoint,
        source,
    ) {
        (Some(t_s), Some(file), Some(source)) => Some((
            SaveAt {
                t_s,
                file: file.clone(),
            },
            source,
        )),
        _ => None,
    };
    let checkpoints = Checkpoints {
        resume: resumed.as_ref().map(|(c, f)| (c, *f)),
        save,
    };
    simulate_with(
        &cfg,
        args.run.duration_s,
        args.log_every_s,
        || args.run.open_csv(),
        checkpoints,
    )
}

/// `flexdyn simulate`: the CSV, then `steps=… wall_s=… steps_per_s=…` on stderr.
pub fn main(args: &SimulateArgs) -> ExitCode {
    match exit(simulate(args), CliError::exit_code) {
        Ok(report) => {
            summary(report);
            ExitCode::SUCCESS
        }
        Err(code) => code,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_rows() {
        let cfg = SimConfig::reference();
        let mut buf = Vec::new();
        let rep = simulate_to(&cfg, 0.1, 0.01, &mut buf, "buffer").unwrap();
        assert_eq!(rep.steps, 100);
        assert_eq!(rep.rows, 11);
        let text = String::from_utf8(buf).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 12);
        let n_cols = lines[0].split(',').count();
        // t_s, 5 header fields, 3 + 4 + 5·3 state, 2 + 6 conserved, 6 + 1 command, 2 pairs of
        // 4 states and a flag, 6 scheduled wrench.
        assert_eq!(n_cols, 1 + 5 + 22 + 8 + 7 + 2 * 5 + 6);
        assert!(lines[1..].iter().all(|l| l.split(',').count() == n_cols));
    }

    /// `simulate`'s rows placed by position are byte for byte the rows built by name, on the
    /// files with the most kinds of columns: `acs_full.toml` (two panel pairs, four wheels,
    /// the environment record, a sensor of every kind at 10 Hz and the IMUs at every row) and
    /// `leo_environment.toml` (a GPS receiver at 1 Hz with its latency), both logged at every
    /// RK4 step so that most rows carry only some of the sensors.
    #[test]
    fn rows_placed_by_position_are_the_rows_placed_by_name() {
        for (file, text, duration_s) in [
            (
                "acs_full.toml",
                include_str!("../../scenarios/acs_full.toml"),
                2.0,
            ),
            (
                "leo_environment.toml",
                include_str!("../../scenarios/leo_environment.toml"),
                3.0,
            ),
        ] {
            let cfg = SimConfig::from_toml_str(text).unwrap();
            let csv = |by_name: bool| {
                let mut buf = Vec::new();
                let out = &mut buf;
                let open = move || Ok((out, "buffer".to_string()));
                let every_s = cfg.step_ns as f64 / 1e9;
                let checkpoints = Checkpoints::default();
                simulate_rows(&cfg, duration_s, every_s, open, checkpoints, by_name).unwrap();
                String::from_utf8(buf).unwrap()
            };
            let (placed, named) = (csv(false), csv(true));
            let lines = named.lines().count();
            assert!(lines > 20, "{file}: {lines} lines");
            // Rows with and without sensor cells, so both kinds were compared.
            let with_empty = named.lines().filter(|l| l.contains(",,")).count();
            assert!(
                with_empty > 0 && with_empty < lines - 1,
                "{file}: {with_empty}"
            );
            for (i, (a, b)) in placed.lines().zip(named.lines()).enumerate() {
                assert_eq!(a, b, "{file}, line {i}");
            }
            assert_eq!(placed.len(), named.len(), "{file}");
        }
    }

    #[test]
    fn bad_intervals() {
        let cfg = SimConfig::reference();
        let e = simulate_to(&cfg, 0.1, 0.0015, Vec::new(), "buffer").unwrap_err();
        assert!(e.to_string().starts_with("--log-every-s:"), "{e}");
        let e = simulate_to(&cfg, 0.1005, 0.01, Vec::new(), "buffer").unwrap_err();
        assert!(e.to_string().starts_with("--duration-s:"), "{e}");
        let e = simulate_to(&cfg, 0.1, -0.01, Vec::new(), "buffer").unwrap_err();
        assert_eq!(e.exit_code(), 2);
    }
}
