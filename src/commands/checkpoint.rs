//! The checkpoint files of the offline front ends (`simulate --checkpoint-at-s … --checkpoint
//! FILE`, `simulate --resume FILE`): the bytes are the vehicle layer's
//! ([`flexdyn_vehicle::checkpoint`]); here they are written and read, and their errors name the
//! file.

use std::path::{Path, PathBuf};

use super::CliError;
use flexdyn_vehicle::checkpoint::{self, Checkpoint, CheckpointError, CheckpointHeader};
use flexdyn_vehicle::config::{SimConfig, DEFAULT_CONFIG_TOML};
use flexdyn_vehicle::world::World;

/// Where and when a run writes a checkpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct SaveAt {
    /// \[s\] the simulation time: a frame boundary on which a row falls.
    pub t_s: f64,
    /// The file (written beside and renamed over, so a reader never sees half of one).
    pub file: PathBuf,
}

/// The configuration a run came from, as its checkpoints record it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Source {
    /// The file as the run was given it (empty: the embedded default).
    pub path: String,
    /// Its text.
    pub text: String,
}

impl Source {
    /// The configuration file `path` (its text read again), or the embedded default.
    pub fn of(path: Option<&Path>) -> Result<Self, CliError> {
        match path {
            None => Ok(Self {
                path: String::new(),
                text: DEFAULT_CONFIG_TOML.to_string(),
            }),
            Some(p) => {
                let text = std::fs::read_to_string(p).map_err(|source| CliError::Config {
                    file: Some(p.to_path_buf()),
                    source: flexdyn_vehicle::config::ConfigError::Io {
                        path: p.to_path_buf(),
                        source,
                    },
                })?;
                Ok(Self {
                    path: p.display().to_string(),
                    text,
                })
            }
        }
    }

    /// The configuration a checkpoint recorded, parsed with relative paths resolved beside the
    /// file it came from.
    pub fn config(&self) -> Result<SimConfig, CliError> {
        let base = Path::new(&self.path).parent().unwrap_or(Path::new("."));
        SimConfig::from_toml_str_in(&self.text, base).map_err(|source| CliError::Config {
            file: (!self.path.is_empty()).then(|| PathBuf::from(&self.path)),
            source,
        })
    }
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
    let c = Checkpoint::parse(bytes).map_err(|e| error(file, e))?;
    if c.header.front_end != front_end {
        return Err(error(
            file,
            CheckpointError::Mismatch {
                what: "the front end",
                checkpoint: format!("`{}`", c.header.front_end),
                run: format!("`{front_end}`"),
            },
        ));
    }
    Ok(c)
}

/// Writes the checkpoint of `world` to `file`: beside it first, then renamed over it.
pub fn write(file: &Path, header: &CheckpointHeader, world: &mut World) -> Result<(), CliError> {
    let bytes = checkpoint::save(header, world).map_err(|e| error(file, e))?;
    let output = |source| CliError::Output {
        target: format!("checkpoint `{}`", file.display()),
        source,
    };
    let mut part = file.as_os_str().to_owned();
    part.push(".part");
    let part = PathBuf::from(part);
    std::fs::write(&part, &bytes).map_err(output)?;
    std::fs::rename(&part, file).map_err(output)
}
