//! The checkpoint files of the offline front ends (`simulate --checkpoint-at-s … --checkpoint
//! FILE`, `simulate --resume FILE`): the bytes are the vehicle layer's
//! ([`flexdyn_vehicle::checkpoint`]); here they are written and read, and their errors name the
//! file.

use std::path::{Path, PathBuf};

use super::{whole_steps, CliError};
use flexdyn_kernel::numfmt::Num;
use flexdyn_vehicle::checkpoint::{self, Checkpoint, CheckpointError, CheckpointHeader, Source};
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::world::World;

/// The checkpoint options `simulate` and `fleet` share.
#[derive(Debug, Clone, PartialEq, Default, clap::Args)]
pub struct CheckpointArgs {
    /// Write a checkpoint of the run at this simulated time (after t = 0, a frame boundary on
    /// which a row falls) to `--checkpoint`; the run goes on to the end.
    #[arg(long, value_name = "SECONDS", requires = "checkpoint")]
    pub checkpoint_at_s: Option<f64>,
    /// The checkpoint file `--checkpoint-at-s` writes.
    #[arg(long, value_name = "FILE", requires = "checkpoint_at_s")]
    pub checkpoint: Option<PathBuf>,
    /// Resume from a checkpoint: the rows after its instant, bit-identical to the uninterrupted
    /// run's; another configuration or fleet file than the one it was taken with is a fork.
    /// `--duration-s` still counts from t = 0.
    #[arg(long, value_name = "FILE")]
    pub resume: Option<PathBuf>,
}

/// Where and when a run writes a checkpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct SaveAt {
    /// \[s\] the simulation time: a frame boundary on which a row falls.
    pub t_s: f64,
    /// The file (written beside and renamed over, so a reader never sees half of one).
    pub file: PathBuf,
}

/// The configuration file `path` (its text read again), or the embedded default, as a
/// checkpoint records it.
pub fn source_of(path: Option<&Path>) -> Result<Source, CliError> {
    Source::of(path).map_err(|source| CliError::Config {
        file: path.map(Path::to_path_buf),
        source,
    })
}

/// The configuration a checkpoint recorded, parsed with relative paths resolved beside the
/// file it came from.
pub fn recorded_config(source: &Source) -> Result<SimConfig, CliError> {
    source.config().map_err(|e| CliError::Config {
        file: source.file(),
        source: e,
    })
}

/// A checkpoint file's error, naming the file.
pub(crate) fn error(file: &Path, source: CheckpointError) -> CliError {
    CliError::Checkpoint {
        file: file.to_path_buf(),
        source,
    }
}

/// Reads a checkpoint file's bytes.
pub fn read(file: &Path) -> Result<Vec<u8>, CliError> {
    std::fs::read(file).map_err(|source| CliError::Input {
        target: format!("checkpoint `{}`", file.display()),
        source,
    })
}

/// Checks a checkpoint's bytes and that `front_end` wrote it.
pub fn parse<'a>(
    file: &Path,
    bytes: &'a [u8],
    front_end: &str,
) -> Result<Checkpoint<'a>, CliError> {
    Checkpoint::parse_of(bytes, front_end).map_err(|e| error(file, e))
}

/// Writes the checkpoint of `world` to `file`: beside it first, then renamed over it.
pub fn write(file: &Path, header: &CheckpointHeader, world: &mut World) -> Result<(), CliError> {
    let bytes = checkpoint::save(header, world).map_err(|e| error(file, e))?;
    // Not synced, as before: an offline run's checkpoint is written once, and a file a crash
    // damaged is refused by its checksum.
    checkpoint::write_file(file, &bytes, false).map_err(|source| CliError::Output {
        target: format!("checkpoint `{}`", file.display()),
        source,
    })
}

/// Restores checkpoint `c` (read from `file`) into `world`, freshly built; the step it is at.
pub(crate) fn resume(
    c: &Checkpoint<'_>,
    file: &Path,
    world: &mut World,
    log_steps: u64,
    total_steps: u64,
) -> Result<u64, CliError> {
    c.restore(world).map_err(|e| error(file, e))?;
    let h = &c.header;
    if world.t_sim_ns() != h.t_sim_ns || h.t_sim_ns == 0 {
        return Err(error(
            file,
            CheckpointError::Mismatch {
                what: "its header at t =",
                checkpoint: format!("{} ns", h.t_sim_ns),
                run: format!("its state at t = {} ns", world.t_sim_ns()),
            },
        ));
    }
    if h.row_steps != log_steps {
        return Err(CliError::Arg {
            flag: "--log-every-s",
            problem: format!(
                "the checkpoint's rows fall every {} s; resume with that interval",
                Num((h.row_steps * h.step_ns) as f64 * 1e-9)
            ),
        });
    }
    let start_step = h.t_sim_ns / h.step_ns.max(1);
    if start_step > total_steps {
        return Err(CliError::Arg {
            flag: "--duration-s",
            problem: format!(
                "the checkpoint is at t = {} s, after the end of the run (the duration counts \
                 from t = 0)",
                Num(h.t_sim_ns as f64 * 1e-9)
            ),
        });
    }
    Ok(start_step)
}

/// The step of `--checkpoint-at-s`: a whole number of steps, on a row and a frame boundary,
/// within the run and after a resumed start.
pub(crate) fn save_step(
    at: &SaveAt,
    step_ns: u64,
    frame_ns: u64,
    log_steps: u64,
    total_steps: u64,
    start_step: u64,
) -> Result<u64, CliError> {
    let flag = "--checkpoint-at-s";
    let step = whole_steps(flag, at.t_s, step_ns, true)?;
    let steps_per_frame = (frame_ns / step_ns).max(1);
    let problem = if step == 0 {
        Some("must be after t = 0 (a run from t = 0 is its configuration)".to_string())
    } else if step > total_steps {
        Some("is after the end of the run".to_string())
    } else if step % log_steps != 0 || step % steps_per_frame != 0 {
        Some(format!(
            "must fall on a row (every {} s) and a frame boundary (every {} s)",
            Num((log_steps * step_ns) as f64 * 1e-9),
            Num(frame_ns as f64 * 1e-9)
        ))
    } else if step <= start_step {
        Some("must be after the checkpoint this run resumes from".to_string())
    } else {
        None
    };
    match problem {
        Some(problem) => Err(CliError::Arg { flag, problem }),
        None => Ok(step),
    }
}
