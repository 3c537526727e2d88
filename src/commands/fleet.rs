//! `flexdyn fleet`: propagates a fleet file offline and writes one CSV of every vehicle's
//! centre-of-mass state and every (chief, deputy) pair's relative state.
//!
//! Columns (a row at t = 0 and every `--log-every-s`):
//! - `t_s`;
//! - per vehicle `<id>`: `<id>_r_cn_n_m_{1,2,3}`, `<id>_v_cn_n_m_s_{1,2,3}` (its system centre
//!   of mass C in N);
//! - per deputy `<d>` given relative to chief `<c>`: `<d>_in_<c>_r_h_m_{1,2,3}` and
//!   `<d>_in_<c>_v_h_m_s_{1,2,3}` (the deputy relative to the chief in the chief's Hill frame:
//!   radial, along-track, cross-track; the rate seen in that frame), `<d>_in_<c>_range_m` and
//!   `<d>_in_<c>_range_rate_m_s` (`super::relative`).

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::PathBuf;

use nalgebra::Vector3;

use std::process::ExitCode;

use super::checkpoint::{self as ckpt, CheckpointArgs, SaveAt};
use super::{exit, summary, whole_steps, CliError, OfflineRun};
use flexdyn_vehicle::checkpoint::CheckpointHeader;
use flexdyn_vehicle::world::relative::com_state_n;
use flexdyn_vehicle::world::{walk, FleetConfig, FleetError, RowPlan, RowSink, World};

/// Arguments of `flexdyn fleet`.
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct FleetArgs {
    /// The fleet file (TOML): `[[vehicles]]` entries (docs/guides/fleets.md).
    pub fleet: PathBuf,
    /// How long, and where the CSV goes.
    #[command(flatten)]
    pub run: OfflineRun,
    /// Interval between CSV rows in seconds; must be a whole number of RK4 steps. A row is also
    /// written at t = 0.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    pub log_every_s: f64,
    /// Checkpoints: save one, or resume from one.
    #[command(flatten)]
    pub checkpoints: CheckpointArgs,
}

/// An error of `flexdyn fleet`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FleetRunError {
    /// The fleet file (or a vehicle's spacecraft configuration) is invalid.
    #[error(transparent)]
    Fleet(#[from] FleetError),
    /// An option or the output.
    #[error(transparent)]
    Cli(#[from] CliError),
}

impl FleetRunError {
    /// 2 for invalid input, 1 for a failure while running.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Fleet(_) => 2,
            Self::Cli(e) => e.exit_code(),
        }
    }
}

/// What `fleet` did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FleetReport {
    /// Vehicles propagated.
    pub vehicles: usize,
    /// RK4 steps of each vehicle.
    pub steps: u64,
    /// CSV rows written.
    pub rows: u64,
}

/// Runs `flexdyn fleet`.
pub fn fleet(args: &FleetArgs) -> Result<FleetReport, FleetRunError> {
    let fleet = FleetConfig::from_file(&args.fleet)?;
    fleet_with(&fleet, args, || {
        let (out, target) = args.run.open_csv()?;
        Ok((io::BufWriter::new(out), target))
    })
}

fn output_err(target: &str, source: io::Error) -> FleetRunError {
    FleetRunError::Cli(CliError::Output {
        target: target.to_string(),
        source,
    })
}

/// Propagates `fleet` for `args.run.duration_s`, writing the CSV to `out`.
pub fn fleet_to<W: Write>(
    fleet: &FleetConfig,
    args: &FleetArgs,
    target: &str,
    out: W,
) -> Result<FleetReport, FleetRunError> {
    fleet_with(fleet, args, || Ok((out, target.to_string())))
}

/// [`fleet_to`], with the output given by `open` (the CSV and its name for errors), called once
/// the options and the checkpoints are checked: a refused run never creates or truncates it.
pub fn fleet_with<W: Write>(
    fleet: &FleetConfig,
    args: &FleetArgs,
    open: impl FnOnce() -> Result<(W, String), CliError>,
) -> Result<FleetReport, FleetRunError> {
    let mut world = World::new(fleet)?;
    let step_ns = fleet.vehicles[0].cfg.step_ns;
    let frame_ns = fleet.vehicles[0].cfg.frame_ns;
    let steps = whole_steps("--duration-s", args.run.duration_s, step_ns, true)?;
    let every = whole_steps("--log-every-s", args.log_every_s, step_ns, false)?;
    // A resumed run's state is restored before anything is written.
    let bytes = args
        .checkpoints
        .resume
        .as_deref()
        .map(ckpt::read)
        .transpose()?;
    let start_step = match (args.checkpoints.resume.as_deref(), &bytes) {
        (Some(file), Some(b)) => {
            let c = ckpt::parse(file, b, "fleet")?;
            let text = ckpt::source_of(Some(&args.fleet))?.text;
            if CheckpointHeader::digest(&text) != c.header.source_sha256 {
                summary(format_args!(
                    "note: resuming `{}` with a fleet file that differs from the one it was \
                     taken with: a fork",
                    file.display()
                ));
            }
            ckpt::resume(&c, file, &mut world, every, steps)?
        }
        _ => 0,
    };
    let save = match (
        args.checkpoints.checkpoint_at_s,
        &args.checkpoints.checkpoint,
    ) {
        (Some(t_s), Some(file)) => {
            let at = SaveAt {
                t_s,
                file: file.clone(),
            };
            let step = ckpt::save_step(&at, step_ns, frame_ns, every, steps, start_step)?;
            let source = ckpt::source_of(Some(&args.fleet))?;
            Some((
                step,
                CheckpointHeader {
                    front_end: "fleet".into(),
                    source_sha256: CheckpointHeader::digest(&source.text),
                    source_path: source.path,
                    source_text: source.text,
                    tick: step / world.steps_per_frame().max(1),
                    t_sim_ns: step * step_ns,
                    step_ns,
                    frame_ns,
                    row_steps: every,
                    ..CheckpointHeader::default()
                },
                at.file,
            ))
        }
        _ => None,
    };
    let mut line = String::from("t_s");
    for v in world.vehicles() {
        for q in ["r_cn_n_m", "v_cn_n_m_s"] {
            for k in 1..=3 {
                let _ = write!(line, ",{}_{q}_{k}", v.id);
            }
        }
    }
    for &(c, d) in world.relative_pairs() {
        let pair = format!("{}_in_{}", world.vehicles()[d].id, world.vehicles()[c].id);
        for q in ["r_h_m", "v_h_m_s"] {
            for k in 1..=3 {
                let _ = write!(line, ",{pair}_{q}_{k}");
            }
        }
        let _ = write!(line, ",{pair}_range_m,{pair}_range_rate_m_s");
    }
    line.push('\n');
    // Everything is checked: only now is the output created.
    let (mut out, target) = open()?;
    let target = target.as_str();
    out.write_all(line.as_bytes())
        .map_err(|e| output_err(target, e))?;
    // The offline loop every front end shares: a row at t = 0 and at every whole log
    // interval, the steps after the last one stepped without a row.
    let plan = RowPlan {
        total_steps: steps,
        log_steps: every,
        frame_stops: false,
        start_step,
    };
    let mut sink = FleetRows {
        out,
        line,
        target,
        save,
    };
    let rows = walk(&mut world, plan, &mut sink)?;
    sink.out.flush().map_err(|e| output_err(target, e))?;
    Ok(FleetReport {
        vehicles: world.vehicles().len(),
        steps: steps - start_step,
        rows,
    })
}

/// `fleet`'s rows, written as the offline loop ([`walk`]) reaches them.
struct FleetRows<'a, W: Write> {
    out: W,
    /// The row's text, reused row to row.
    line: String,
    target: &'a str,
    /// A checkpoint to write after the row at this step.
    save: Option<(u64, CheckpointHeader, PathBuf)>,
}

impl<W: Write> RowSink for FleetRows<'_, W> {
    type Error = FleetRunError;

    fn row(&mut self, world: &mut World, _k: u64, step: u64) -> Result<(), FleetRunError> {
        self.line.clear();
        row(world, &mut self.line);
        self.out
            .write_all(self.line.as_bytes())
            .map_err(|e| output_err(self.target, e))?;
        if let Some((at, header, file)) = &self.save {
            if *at == step {
                // Everything written so far reaches the file before the checkpoint does.
                self.out.flush().map_err(|e| output_err(self.target, e))?;
                ckpt::write(file, header, world)?;
            }
        }
        Ok(())
    }
}

/// One CSV row of the world's current state.
fn row(world: &World, line: &mut String) {
    // Integer nanoseconds divided once (correctly rounded), as every other CSV's `t_s`: 15 s
    // prints `15`, where `ns * 1e-9` printed `15.000000000000002`.
    let _ = write!(line, "{}", world.t_sim_ns() as f64 / 1e9);
    for v in world.vehicles() {
        let (r, v) = com_state_n(v.sim.spacecraft());
        push(line, &r);
        push(line, &v);
    }
    for &(c, d) in world.relative_pairs() {
        match world.relative_state(c, d) {
            Some(rel) => {
                push(line, &rel.r_dc_h_m);
                push(line, &rel.v_dc_h_m_s);
                let _ = write!(line, ",{},{}", rel.range_m, rel.range_rate_m_s);
            }
            // A chief without an orbit plane has no Hill frame: empty cells.
            None => line.push_str(",,,,,,,,"),
        }
    }
    line.push('\n');
}

/// `,x1,x2,x3`.
fn push(line: &mut String, x: &Vector3<f64>) {
    for c in x.iter() {
        let _ = write!(line, ",{c}");
    }
}

/// `flexdyn fleet`: the CSV, then what was propagated on stderr.
pub fn main(args: &FleetArgs) -> ExitCode {
    match exit(fleet(args), FleetRunError::exit_code) {
        Ok(r) => {
            summary(format_args!(
                "propagated {} vehicles for {} steps; wrote {} rows",
                r.vehicles, r.steps, r.rows
            ));
            ExitCode::SUCCESS
        }
        Err(code) => code,
    }
}

#[cfg(test)]
mod tests {
    use super::{fleet_to, CheckpointArgs, FleetArgs, OfflineRun};
    use flexdyn_testkit::fleets::LEO_PAIR;
    use flexdyn_vehicle::world::{FleetConfig, World};
    use std::path::Path;

    const SCENARIOS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");

    #[test]
    fn fleet_csv_holds_each_vehicle_and_the_relative_state() {
        let fleet = FleetConfig::from_toml_str_in(LEO_PAIR, Path::new(SCENARIOS)).unwrap();
        let args = FleetArgs {
            fleet: "unused.toml".into(),
            run: OfflineRun {
                duration_s: 0.5,
                output: None,
            },
            log_every_s: 0.1,
            checkpoints: CheckpointArgs::default(),
        };
        let mut csv = Vec::new();
        let report = fleet_to(&fleet, &args, "memory", &mut csv).unwrap();
        // Rows at t = 0, 0.1, …, 0.5 s; 1 ms steps.
        assert_eq!((report.vehicles, report.steps, report.rows), (2, 500, 6));
        let text = String::from_utf8(csv).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 7);
        let header: Vec<&str> = lines[0].split(',').collect();
        // t, 2 vehicles × 6, one pair × 8.
        assert_eq!(header.len(), 1 + 12 + 8);
        assert_eq!(header[1], "chief_r_cn_n_m_1");
        assert_eq!(header[13], "deputy_in_chief_r_h_m_1");
        assert_eq!(header[20], "deputy_in_chief_range_rate_m_s");
        // Times as written: integer nanoseconds divided once.
        let times: Vec<&str> = lines[1..]
            .iter()
            .map(|l| &l[..l.find(',').unwrap()])
            .collect();
        assert_eq!(times, ["0", "0.1", "0.2", "0.3", "0.4", "0.5"]);
        let last: Vec<f64> = lines[6].split(',').map(|c| c.parse().unwrap()).collect();
        assert_eq!(last[0], 0.5);
        // The same world stepped 500 times: the same numbers (Display of f64 round-trips).
        let mut world = World::new(&fleet).unwrap();
        for _ in 0..500 {
            world.step();
        }
        let rel = world.relative_state(0, 1).unwrap();
        assert_eq!(&last[13..16], rel.r_dc_h_m.as_slice());
        assert_eq!(&last[16..19], rel.v_dc_h_m_s.as_slice());
        assert_eq!((last[19], last[20]), (rel.range_m, rel.range_rate_m_s));
        // A duration that is not a whole number of steps is refused, naming the option.
        let bad = FleetArgs {
            run: OfflineRun {
                duration_s: 0.0005,
                output: None,
            },
            ..args
        };
        let err = fleet_to(&fleet, &bad, "memory", Vec::new()).unwrap_err();
        assert!(err.to_string().starts_with("--duration-s: "), "{err}");
        assert_eq!(err.exit_code(), 2);
    }
}
