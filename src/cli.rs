//! The offline subcommands of the `flexdyn` binary: `simulate`, `check-config` and
//! `print-default-config`. `src/main.rs` only parses arguments and reports errors; the work is
//! here so tests can call it.

use std::fmt::{self, Write as _};
use std::io::{self, BufWriter, Write};
use std::num::NonZeroU64;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::config::{
    config_message, log_warnings, warning_message, whole_ns, ConfigError, SimConfig,
};
use crate::dynamics::StateEffector;
use crate::numfmt::Num;
use crate::sensors::imu::ImuSample;
use crate::server::error::SettingsError;
use crate::server::settings::ServerSettings;
use crate::sim::{Simulation, Snapshot};

/// Arguments of `flexdyn simulate`.
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct SimulateArgs {
    /// Configuration file (TOML). Default: the embedded reference spacecraft
    /// (`flexdyn print-default-config`).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Simulated duration in seconds; must be a whole number of RK4 steps.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 10.0,
        allow_negative_numbers = true
    )]
    pub duration_s: f64,
    /// Interval between CSV rows in seconds; must be a whole number of RK4 steps. A row is also written
    /// at t = 0.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 0.01,
        allow_negative_numbers = true
    )]
    pub log_every_s: f64,
    /// CSV output file; `-` (or no option) writes to standard output.
    #[arg(long, short, value_name = "FILE.csv")]
    pub output: Option<PathBuf>,
}

impl Default for SimulateArgs {
    fn default() -> Self {
        Self {
            config: None,
            duration_s: 10.0,
            log_every_s: 0.01,
            output: None,
        }
    }
}

/// An error of an offline subcommand.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CliError {
    /// The configuration is invalid or unreadable.
    #[error("{}", config_message(file.as_deref(), source))]
    Config {
        /// The file, or `None` for the embedded default.
        file: Option<PathBuf>,
        /// The error; it names the field.
        #[source]
        source: ConfigError,
    },
    /// A command-line value is invalid.
    #[error("{flag}: {problem}")]
    Arg {
        /// The option, e.g. `--log-every-s`.
        flag: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// The `[server]` table is invalid (checked by `check-config`, as `run` would); the error
    /// names the file, `server.<key>` and its line.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The propagated state stopped being finite; the row was not written.
    #[error(
        "the state became non-finite at step {step} (t = {} s): {quantity} is NaN or infinite; \
         stopping without writing that row (check the configuration's rates, stiffnesses and \
         wrenches for values the step cannot resolve)",
        Num(*t_s)
    )]
    NonFinite {
        /// The RK4 step count at the row.
        step: u64,
        /// \[s\] simulation time of the row.
        t_s: f64,
        /// The first non-finite quantity, by its CSV column name.
        quantity: String,
    },
    /// Writing the output failed.
    #[error("cannot write {target}: {source}")]
    Output {
        /// Where the output was going.
        target: String,
        /// The I/O error.
        #[source]
        source: io::Error,
    },
}

impl CliError {
    /// The process exit code for this error: 2 for invalid input (configuration or arguments),
    /// 1 for a failure while running (output not writable).
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Config { .. } | CliError::Arg { .. } | CliError::Settings(_) => 2,
            CliError::Output { .. } | CliError::NonFinite { .. } => 1,
        }
    }
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

/// [`crate::config::load_config`], its error as a [`CliError::Config`] naming the file.
fn load(path: Option<&Path>) -> Result<SimConfig, CliError> {
    crate::config::load_config(path).map_err(|source| CliError::Config {
        file: path.map(Path::to_path_buf),
        source,
    })
}

/// A duration option as a whole number of steps.
fn whole_steps(
    flag: &'static str,
    seconds: f64,
    step_ns: u64,
    allow_zero: bool,
) -> Result<u64, CliError> {
    let step_s = step_ns as f64 * 1e-9;
    if !seconds.is_finite() {
        return Err(CliError::Arg {
            flag,
            problem: format!("must be finite (got {seconds})"),
        });
    }
    if seconds < 0.0 || (!allow_zero && seconds == 0.0) {
        let bound = if allow_zero { ">= 0" } else { "> 0" };
        return Err(CliError::Arg {
            flag,
            problem: format!("must be {bound} (got {seconds})"),
        });
    }
    match whole_ns(seconds) {
        Some(ns) if ns % step_ns == 0 => Ok(ns / step_ns),
        _ => Err(CliError::Arg {
            flag,
            problem: format!(
                "{seconds} s is not a whole number of RK4 steps (step = {step_s} s = {step_ns} ns)"
            ),
        }),
    }
}

/// The CSV header for a spacecraft with `effectors` (no trailing newline). Each effector adds
/// its states and then its outputs, named `<prefix><k>_<name>` with `k` its 1-based index among
/// effectors of its kind (`pair1_theta1`, `rw2_omega_rad_s`), and, when it has outputs, a
/// `<prefix><k>_flags` column with its status bits.
pub fn csv_header(effectors: &[Box<dyn StateEffector>]) -> String {
    let mut h = String::from("t_s");
    for base in ["sigma_bn", "omega_bn_b", "r_bn_n", "v_bn_n"] {
        for i in 1..=3 {
            let _ = write!(h, ",{base}_{i}");
        }
    }
    for (i, e) in effectors.iter().enumerate() {
        let kind = e.kind();
        let k = 1 + effectors[..i].iter().filter(|o| o.kind() == kind).count();
        for col in e.state_names().iter().chain(e.output_names()) {
            let _ = write!(h, ",{}{k}_{col}", kind.column_prefix);
        }
        if !e.output_names().is_empty() {
            let _ = write!(h, ",{}{k}_flags", kind.column_prefix);
        }
    }
    h.push_str(",orb_energy_j,rot_energy_j");
    for base in ["orb_ang_mom_n", "rot_ang_mom_c_n"] {
        for i in 1..=3 {
            let _ = write!(h, ",{base}_{i}");
        }
    }
    h
}

/// The IMU columns appended to [`csv_header`], for IMUs `names` in config order: for each,
/// `imu_<name>_omega_p_1..3`, `imu_<name>_accel_p_1..3`, `imu_<name>_dtheta_p_1..3`,
/// `imu_<name>_dv_p_1..3` (each prefixed by a comma; empty for no IMU).
pub fn csv_imu_header(names: &[String]) -> String {
    let mut h = String::new();
    for name in names {
        for q in ["omega_p", "accel_p", "dtheta_p", "dv_p"] {
            for i in 1..=3 {
                let _ = write!(h, ",imu_{name}_{q}_{i}");
            }
        }
    }
    h
}

/// Appends the IMU columns of one row (each value prefixed by a comma, in the shortest form
/// that reads back to the same f64: [`Num`]) to `row`.
pub fn csv_imu_row(samples: &[ImuSample], row: &mut String) {
    for s in samples {
        for v in [
            &s.omega_p_rad_s,
            &s.accel_p_m_s2,
            &s.dtheta_p_rad,
            &s.dv_p_m_s,
        ] {
            for x in v.iter() {
                let _ = write!(row, ",{}", Num(*x));
            }
        }
    }
}

/// Appends one CSV row for `s` to `row` (cleared first; no trailing newline). Floats are in the
/// shortest form that reads back to the same f64 ([`Num`]: `0.03`, `-4020338.689621511`,
/// `1.5e-20`), so they round-trip exactly.
pub fn csv_row(s: &Snapshot, row: &mut String) {
    row.clear();
    let mut push = |v: f64| {
        if !row.is_empty() {
            row.push(',');
        }
        let _ = write!(row, "{}", Num(v));
    };
    push(s.t_s());
    for v in [&s.sigma_bn, &s.omega_bn_b, &s.r_bn_n, &s.v_bn_n] {
        v.iter().for_each(|x| push(*x));
    }
    for e in &s.effectors {
        e.states.iter().chain(&e.outputs).for_each(|x| push(*x));
        if !e.outputs.is_empty() {
            push(f64::from(e.flags));
        }
    }
    push(s.conserved.orb_energy_j);
    push(s.conserved.rot_energy_j);
    s.conserved.orb_ang_mom_n.iter().for_each(|x| push(*x));
    s.conserved.rot_ang_mom_c_n.iter().for_each(|x| push(*x));
}

/// Simulates `cfg` for `duration_s`, writing a CSV row at t = 0 and every `log_every_s` to
/// `out` (through a `BufWriter`). `target` names the output in errors.
pub fn simulate_to<W: Write>(
    cfg: &SimConfig,
    duration_s: f64,
    log_every_s: f64,
    out: W,
    target: &str,
) -> Result<SimulateReport, CliError> {
    let total_steps = whole_steps("--duration-s", duration_s, cfg.step_ns, true)?;
    let log_steps = whole_steps("--log-every-s", log_every_s, cfg.step_ns, false)?;
    let mut sim = Simulation::new(cfg).map_err(|source| CliError::Config { file: None, source })?;
    // The IMU sample interval is the log interval (log_steps ≥ 1 and step_ns ≥ 1).
    if let Some(ns) = NonZeroU64::new(log_steps * cfg.step_ns) {
        sim.set_imu_sample_interval_ns(ns);
    }
    let io_err = |source| CliError::Output {
        target: target.to_string(),
        source,
    };

    let mut out = BufWriter::new(out);
    let mut row = csv_header(sim.spacecraft().effectors());
    row.push_str(&csv_imu_header(sim.imu_names()));
    row.push('\n');
    out.write_all(row.as_bytes()).map_err(io_err)?;

    let mut snap = Snapshot::for_simulation(&sim);
    let mut imu_samples = Vec::with_capacity(sim.n_imus());
    let n_logged = total_steps / log_steps;
    let start = Instant::now();
    for k in 0..=n_logged {
        if k > 0 {
            sim.step_n(log_steps);
        }
        sim.snapshot_into(&mut snap);
        sim.imu_samples_into(&mut imu_samples);
        // Once per row, outside the stepping loop: never write a non-finite state.
        let imu_bad = imu_samples
            .iter()
            .zip(sim.imu_names())
            .find_map(|(s, name)| {
                s.first_non_finite()
                    .map(|q| format!("imu_{name}_{q} (an IMU output)"))
            });
        if let Some(quantity) = snap.first_non_finite().or(imu_bad) {
            out.flush().map_err(io_err)?;
            return Err(CliError::NonFinite {
                step: k * log_steps,
                t_s: snap.t_s(),
                quantity,
            });
        }
        csv_row(&snap, &mut row);
        csv_imu_row(&imu_samples, &mut row);
        row.push('\n');
        out.write_all(row.as_bytes()).map_err(io_err)?;
    }
    // Steps after the last multiple of the log interval, up to the duration.
    sim.step_n(total_steps - n_logged * log_steps);
    let wall_s = start.elapsed().as_secs_f64();
    out.flush().map_err(io_err)?;
    tracing::debug!(steps = total_steps, rows = n_logged + 1, "simulate done");
    Ok(SimulateReport {
        steps: total_steps,
        rows: n_logged + 1,
        wall_s,
    })
}

/// `flexdyn simulate`: loads the configuration, checks the options, and writes the CSV to the
/// output file or stdout. The output file is created only once everything else is valid.
pub fn simulate(args: &SimulateArgs) -> Result<SimulateReport, CliError> {
    let cfg = load(args.config.as_deref())?;
    log_warnings(&cfg, args.config.as_deref());
    // Check the options before creating (and truncating) the output file.
    whole_steps("--duration-s", args.duration_s, cfg.step_ns, true)?;
    whole_steps("--log-every-s", args.log_every_s, cfg.step_ns, false)?;
    match args.output.as_deref() {
        None => simulate_to(
            &cfg,
            args.duration_s,
            args.log_every_s,
            io::stdout().lock(),
            "stdout",
        ),
        Some(p) if p == Path::new("-") => simulate_to(
            &cfg,
            args.duration_s,
            args.log_every_s,
            io::stdout().lock(),
            "stdout",
        ),
        Some(p) => {
            let target = format!("CSV output `{}`", p.display());
            let file = std::fs::File::create(p).map_err(|source| CliError::Output {
                target: target.clone(),
                source,
            })?;
            simulate_to(&cfg, args.duration_s, args.log_every_s, file, &target)
        }
    }
}

/// `flexdyn check-config FILE`: parses, validates and builds the spacecraft; returns one
/// `warning: FILE: field: …` line per implausible value ([`SimConfig::warnings`]: legal, but
/// almost surely a unit slip), then the summary line `ok: FILE: …`.
///
/// It runs every check that `flexdyn run` and `flexdyn simulate` run on a file, the `[server]`
/// table's included (keys, values, cross-setting rules, and a duration that is a whole number of
/// frames), and says `ok` only when all pass. Warnings do not make it fail.
pub fn check_config(path: &Path) -> Result<String, CliError> {
    let cfg = load(Some(path))?;
    cfg.build_spacecraft().map_err(|source| CliError::Config {
        file: Some(path.to_path_buf()),
        source,
    })?;
    ServerSettings::resolve(&cfg, Some(path), &[])?;
    let mut out = String::new();
    for w in cfg.warnings() {
        out.push_str(&format!("warning: {}\n", warning_message(Some(path), &w)));
    }
    out.push_str(&format!("ok: {}: {}", path.display(), cfg.summary()));
    Ok(out)
}

/// Logs to stderr at `RUST_LOG` (default `info`); see [`crate::logging::init_tracing`].
pub use crate::logging::init_tracing;

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
        assert_eq!(n_cols, 1 + 12 + 8 + 2 + 6);
        assert!(lines[1..].iter().all(|l| l.split(',').count() == n_cols));
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
