//! Checkpoints: the complete state of a run at a frame boundary, as a versioned, checksummed
//! file, from which a run resumes bit for bit or forks.
//!
//! A checkpoint holds what was stepped, not what was built: every vehicle's mutable state
//! ([`World::archive`]: the integrated state and time, held inputs and commands, the effectors'
//! valve and clipping state, every sensor's generator, error states, latency ring and last
//! sample, the environment's held sample and next update, the faults' activations, generators
//! and pending events), plus the configuration it came from (its path, text and SHA-256) and the
//! front end's settings. A resume builds the run from that configuration again and then
//! overwrites its state from the checkpoint.
//!
//! # File format (version [`FORMAT_VERSION`])
//! All numbers little-endian.
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `FDYNCKPT` |
//! | 8 | 4 | format version (`u32`, 1) |
//! | 12 | 8 | payload length P (`u64`) |
//! | 20 | P | payload: the sections below ([`flexdyn_kernel::archive`] encoding) |
//! | 20 + P | 32 | SHA-256 of bytes 0 … 20 + P |
//!
//! The payload is a section `checkpoint` ([`CheckpointHeader`]: the wire protocol version, the
//! front end, the configuration's path, SHA-256 and text, the tick, the time, the step, the
//! frame and the front end's row interval), then the section `world`, one section per vehicle,
//! and in each the vehicle's parts, each a named section with its byte length. A restore checks
//! the magic, the format version, the length, the checksum and the protocol version, then reads
//! the state into a freshly built run section by section: the first section whose name, count or
//! length differs from the run's stops it, and the error names the section path.
//!
//! # Compatibility
//! A checkpoint restores into a run whose vehicles, effectors, sensors and configured faults are
//! the same in number, kind, name and state size, with the same step and frame. Anything else
//! may differ: that is a fork (a campaign disperses what comes after the checkpoint, such as a
//! fault's start time). A checkpoint written by a flexdyn whose state listing has changed is
//! refused by the same section checks.

use sha2::{Digest, Sha256};

use crate::config::{ConfigError, SimConfig, DEFAULT_CONFIG_TOML};
use crate::world::World;
use flexdyn_kernel::archive::{Archive, ArchiveError};

/// The file's first 8 bytes.
pub const MAGIC: &[u8; 8] = b"FDYNCKPT";
/// The format version this flexdyn writes and reads.
pub const FORMAT_VERSION: u32 = 1;
/// Bytes before the payload: magic, version, payload length.
const PREFIX_LEN: usize = 8 + 4 + 8;
/// Bytes of the checksum after the payload.
const DIGEST_LEN: usize = 32;
/// The longest configuration text a checkpoint carries (a configuration file is a few KiB).
const MAX_SOURCE_LEN: usize = 64 << 20;

/// What a checkpoint says about the run it came from.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct CheckpointHeader {
    /// The wire protocol version of the stream it continues ([`flexdyn_proto::PROTOCOL_VERSION`]).
    pub protocol_version: u16,
    /// The front end that wrote it: `simulate`, `fleet`, `run` (a server of one spacecraft) or
    /// `run --fleet`.
    pub front_end: String,
    /// The configuration file's absolute path (empty for the embedded default).
    pub source_path: String,
    /// The configuration file's text.
    pub source_text: String,
    /// SHA-256 of `source_text`.
    pub source_sha256: [u8; 32],
    /// The frame boundary it was taken at.
    pub tick: u64,
    /// \[ns\] the simulation time then.
    pub t_sim_ns: u64,
    /// \[ns\] the integration step.
    pub step_ns: u64,
    /// \[ns\] the frame period.
    pub frame_ns: u64,
    /// RK4 steps between the front end's output rows (`simulate --log-every-s`; 0 if none).
    pub row_steps: u64,
}

impl CheckpointHeader {
    /// SHA-256 of a configuration text, as [`Self::source_sha256`] holds it.
    pub fn digest(text: &str) -> [u8; 32] {
        Sha256::digest(text.as_bytes()).into()
    }

    fn archive(&mut self, a: &mut Archive<'_>) {
        a.section("checkpoint", |a| {
            a.put(&mut self.protocol_version);
            text(a, "the front end", &mut self.front_end, 64);
            text(a, "the configuration path", &mut self.source_path, 4096);
            text(
                a,
                "the configuration text",
                &mut self.source_text,
                MAX_SOURCE_LEN,
            );
            a.put(&mut self.source_sha256);
            a.put(&mut self.tick);
            a.put(&mut self.t_sim_ns);
            a.put(&mut self.step_ns);
            a.put(&mut self.frame_ns);
            a.put(&mut self.row_steps);
        });
    }
}

/// The configuration a run came from, as its checkpoints record it.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Source {
    /// The file's absolute path (empty: the embedded default).
    pub path: String,
    /// Its text.
    pub text: String,
}

impl Source {
    /// The configuration (or fleet) file `path`, its text read again, or the embedded default.
    pub fn of(path: Option<&std::path::Path>) -> Result<Self, ConfigError> {
        let Some(p) = path else {
            return Ok(Self {
                path: String::new(),
                text: DEFAULT_CONFIG_TOML.to_string(),
            });
        };
        let io = |source| ConfigError::Io {
            path: p.to_path_buf(),
            source,
        };
        let text = std::fs::read_to_string(p).map_err(io)?;
        // Absolute, so a resume from another directory finds the files it names.
        let path = std::fs::canonicalize(p).map_err(io)?;
        Ok(Self {
            path: path.display().to_string(),
            text,
        })
    }

    /// What a checkpoint recorded.
    pub fn recorded(header: &CheckpointHeader) -> Self {
        Self {
            path: header.source_path.clone(),
            text: header.source_text.clone(),
        }
    }

    /// The file's path (`None`: the embedded default).
    pub fn file(&self) -> Option<std::path::PathBuf> {
        (!self.path.is_empty()).then(|| std::path::PathBuf::from(&self.path))
    }

    /// The directory its relative paths are resolved in.
    pub fn base_dir(&self) -> &std::path::Path {
        std::path::Path::new(&self.path)
            .parent()
            .unwrap_or(std::path::Path::new("."))
    }

    /// The configuration it holds, parsed with relative paths resolved beside its file.
    pub fn config(&self) -> Result<SimConfig, ConfigError> {
        SimConfig::from_toml_str_in(&self.text, self.base_dir())
    }

    /// Fills `header`'s source fields with this one.
    pub fn into_header(self, header: &mut CheckpointHeader) {
        header.source_sha256 = CheckpointHeader::digest(&self.text);
        header.source_path = self.path;
        header.source_text = self.text;
    }
}

/// Saves or restores a UTF-8 text up to `max` bytes.
fn text(a: &mut Archive<'_>, what: &'static str, s: &mut String, max: usize) {
    let mut bytes = std::mem::take(s).into_bytes();
    a.blob(what, &mut bytes, max);
    match String::from_utf8(bytes) {
        Ok(t) => *s = t,
        Err(e) => a.invalid(what, e.utf8_error().valid_up_to() as u64),
    }
}

/// Why a checkpoint was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CheckpointError {
    /// The bytes do not start with [`MAGIC`].
    #[error("not a flexdyn checkpoint (it does not start with \"FDYNCKPT\")")]
    NotACheckpoint,
    /// Another format version.
    #[error("checkpoint format version {found}; this flexdyn reads version {FORMAT_VERSION}")]
    FormatVersion {
        /// The file's version.
        found: u32,
    },
    /// Shorter or longer than its own length field says.
    #[error("the file is {found} bytes where its header promises {expected}: it was cut short or appended to")]
    Length {
        /// Bytes the header implies.
        expected: u64,
        /// Bytes there are.
        found: u64,
    },
    /// The checksum does not match: the file is damaged.
    #[error("its SHA-256 does not match its contents: the file is damaged")]
    Checksum,
    /// A stream of another wire protocol version.
    #[error("it continues a protocol {found} stream; this flexdyn speaks protocol {this}")]
    Protocol {
        /// The checkpoint's.
        found: u16,
        /// This build's.
        this: u16,
    },
    /// The run it is restored into differs where it must not.
    #[error("it was taken with {what} {checkpoint}; this run has {run}")]
    Mismatch {
        /// What differs.
        what: &'static str,
        /// The checkpoint's value.
        checkpoint: String,
        /// This run's.
        run: String,
    },
    /// The state does not fit this run (or is damaged in a way the checksum did not catch).
    #[error("its state does not fit this run: {0}")]
    State(#[from] ArchiveError),
}

/// Writes the checkpoint of `world` with `header` (its `protocol_version` is set here) as the
/// bytes of a checkpoint file. It fails only on state a checkpoint cannot hold yet (a fault
/// injected live, `flexdyn_faults::Faults::archive`). Not on the stepping path: it allocates
/// the file's bytes.
pub fn save(header: &CheckpointHeader, world: &mut World) -> Result<Vec<u8>, CheckpointError> {
    save_with(header, |a| world.archive(a))
}

/// [`save`] of a run whose state `body` lists (a server lists its vehicles' simulations and
/// command books; [`World::archive`] is the offline runs').
pub fn save_with(
    header: &CheckpointHeader,
    body: impl FnOnce(&mut Archive<'_>),
) -> Result<Vec<u8>, CheckpointError> {
    list_with(header, body).map(seal)
}

/// [`save_with`] without the checksum: the bytes before it, for [`seal`] to finish on another
/// thread (a server lists on the thread that steps the frames and checksums on its writer's).
pub fn list_with(
    header: &CheckpointHeader,
    body: impl FnOnce(&mut Archive<'_>),
) -> Result<Vec<u8>, CheckpointError> {
    let mut header = header.clone();
    header.protocol_version = flexdyn_proto::PROTOCOL_VERSION;
    let mut out = Vec::with_capacity(PREFIX_LEN + header.source_text.len() + 64 * 1024);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&0u64.to_le_bytes());
    let mut a = Archive::saving(&mut out);
    header.archive(&mut a);
    body(&mut a);
    a.finish()?;
    let payload_len = (out.len() - PREFIX_LEN) as u64;
    out[12..20].copy_from_slice(&payload_len.to_le_bytes());
    Ok(out)
}

/// Appends the SHA-256 of `listed` ([`list_with`]'s bytes): a checkpoint file's bytes.
pub fn seal(mut listed: Vec<u8>) -> Vec<u8> {
    let digest: [u8; 32] = Sha256::digest(&listed).into();
    listed.extend_from_slice(&digest);
    listed
}

/// Writes a checkpoint file's `bytes` to `file`: beside it first (`<file>.part`, removed again
/// if anything fails), then renamed over it, so a reader never sees half of one. `sync`: the
/// bytes reach the disk before the rename (a server in real time does without: a sync's I/O
/// delayed its boundaries, and a file a crash damaged is refused by its checksum).
pub fn write_file(file: &std::path::Path, bytes: &[u8], sync: bool) -> std::io::Result<()> {
    use std::io::Write;
    let mut part = file.as_os_str().to_owned();
    part.push(".part");
    let part = std::path::PathBuf::from(part);
    let written = std::fs::File::create(&part)
        .and_then(|mut f| {
            f.write_all(bytes)?;
            if sync {
                f.sync_all()?;
            }
            Ok(())
        })
        .and_then(|()| std::fs::rename(&part, file));
    if written.is_err() {
        let _ = std::fs::remove_file(&part);
    }
    written
}

/// A checkpoint's bytes, checked (magic, version, length, checksum, protocol) and split into
/// its header and its world state.
#[derive(Debug)]
pub struct Checkpoint<'a> {
    /// What it says about its run.
    pub header: CheckpointHeader,
    world: &'a [u8],
}

impl<'a> Checkpoint<'a> {
    /// Checks `bytes` and reads the header.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, CheckpointError> {
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(CheckpointError::NotACheckpoint);
        }
        if bytes.len() < PREFIX_LEN {
            return Err(CheckpointError::Length {
                expected: (PREFIX_LEN + DIGEST_LEN) as u64,
                found: bytes.len() as u64,
            });
        }
        let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap_or_default());
        if version != FORMAT_VERSION {
            return Err(CheckpointError::FormatVersion { found: version });
        }
        let payload_len = u64::from_le_bytes(bytes[12..20].try_into().unwrap_or_default());
        let expected = (PREFIX_LEN as u64)
            .saturating_add(payload_len)
            .saturating_add(DIGEST_LEN as u64);
        if bytes.len() as u64 != expected {
            return Err(CheckpointError::Length {
                expected,
                found: bytes.len() as u64,
            });
        }
        let (body, digest) = bytes.split_at(bytes.len() - DIGEST_LEN);
        let computed: [u8; 32] = Sha256::digest(body).into();
        if computed[..] != digest[..] {
            return Err(CheckpointError::Checksum);
        }
        let payload = &body[PREFIX_LEN..];
        let mut header = CheckpointHeader::default();
        // The header section alone; the world's sections follow it.
        let header_len =
            section_len(payload).ok_or(CheckpointError::State(ArchiveError::Truncated {
                at: "checkpoint".into(),
                needed: 1,
            }))?;
        let mut a = Archive::loading(&payload[..header_len]);
        header.archive(&mut a);
        a.finish()?;
        if header.protocol_version != flexdyn_proto::PROTOCOL_VERSION {
            return Err(CheckpointError::Protocol {
                found: header.protocol_version,
                this: flexdyn_proto::PROTOCOL_VERSION,
            });
        }
        Ok(Self {
            header,
            world: &payload[header_len..],
        })
    }

    /// [`Self::parse`], and checks that the front end `front_end` wrote it.
    pub fn parse_of(bytes: &'a [u8], front_end: &str) -> Result<Self, CheckpointError> {
        let c = Self::parse(bytes)?;
        if c.header.front_end != front_end {
            return Err(CheckpointError::Mismatch {
                what: "the front end",
                checkpoint: format!("`{}`", c.header.front_end),
                run: format!("`{front_end}`"),
            });
        }
        Ok(c)
    }

    /// Restores the state into `world`, freshly built from a compatible configuration (module
    /// docs): its step and frame must be the checkpoint's. On an error `world` is half
    /// restored: discard it.
    pub fn restore(&self, world: &mut World) -> Result<(), CheckpointError> {
        let run_step = world.vehicles().first().map_or(0, |v| v.sim.step_ns());
        let run_frame = world.vehicles().first().map_or(0, |v| v.sim.frame_ns());
        self.restore_with(run_step, run_frame, |a| world.archive(a))
    }

    /// [`Self::restore`] into a run of step `run_step_ns` and frame `run_frame_ns` whose state
    /// `body` lists, as [`save_with`]'s did.
    pub fn restore_with(
        &self,
        run_step_ns: u64,
        run_frame_ns: u64,
        body: impl FnOnce(&mut Archive<'_>),
    ) -> Result<(), CheckpointError> {
        let h = &self.header;
        for (what, checkpoint, run) in [
            ("an RK4 step of", h.step_ns, run_step_ns),
            ("a frame period of", h.frame_ns, run_frame_ns),
        ] {
            if checkpoint != run {
                return Err(CheckpointError::Mismatch {
                    what,
                    checkpoint: format!("{checkpoint} ns"),
                    run: format!("{run} ns"),
                });
            }
        }
        let mut a = Archive::loading(self.world);
        body(&mut a);
        a.finish()?;
        Ok(())
    }
}

/// The byte length of the section at the start of `bytes` (its name, length and body).
fn section_len(bytes: &[u8]) -> Option<usize> {
    let name_len = u16::from_le_bytes(bytes.get(0..2)?.try_into().ok()?) as usize;
    let at = 2 + name_len;
    let body = u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?);
    let end = (at as u64 + 8).checked_add(body)?;
    (end <= bytes.len() as u64).then_some(end as usize)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::Simulation;

    fn world() -> World {
        let cfg = SimConfig::from_toml_str(DEFAULT_CONFIG_TOML).unwrap();
        World::of_one("sc".into(), 1, Simulation::new(&cfg).unwrap())
    }

    fn header() -> CheckpointHeader {
        CheckpointHeader {
            front_end: "simulate".into(),
            source_text: DEFAULT_CONFIG_TOML.into(),
            source_sha256: CheckpointHeader::digest(DEFAULT_CONFIG_TOML),
            step_ns: 1_000_000,
            frame_ns: 10_000_000,
            row_steps: 10,
            ..CheckpointHeader::default()
        }
    }

    #[test]
    fn a_restored_world_saves_to_the_same_bytes_and_steps_on_identically() {
        let mut a = world();
        a.step_n(1234);
        let bytes = save(&header(), &mut a).unwrap();
        let c = Checkpoint::parse(&bytes).unwrap();
        assert_eq!(c.header.protocol_version, flexdyn_proto::PROTOCOL_VERSION);
        assert_eq!(c.header.source_text, DEFAULT_CONFIG_TOML);
        let mut b = world();
        c.restore(&mut b).unwrap();
        assert_eq!(b.t_sim_ns(), 1_234_000_000);
        assert_eq!(save(&header(), &mut b).unwrap(), bytes);
        // Both step on to the same state, bit for bit.
        a.step_n(777);
        b.step_n(777);
        let (sa, sb) = (
            a.vehicles()[0].sim.spacecraft().state(),
            b.vehicles()[0].sim.spacecraft().state(),
        );
        assert_eq!(sa, sb);
    }

    #[test]
    fn another_protocol_is_refused_even_with_a_good_checksum() {
        let bytes = save(&header(), &mut world()).unwrap();
        // The protocol version follows the `checkpoint` section's name (2 + 10 bytes) and body
        // length (8) at the payload's start (offset 20).
        let at = PREFIX_LEN + 2 + "checkpoint".len() + 8;
        let mut other = bytes[..bytes.len() - DIGEST_LEN].to_vec();
        assert_eq!(
            u16::from_le_bytes([other[at], other[at + 1]]),
            flexdyn_proto::PROTOCOL_VERSION
        );
        other[at] = other[at].wrapping_add(1);
        let digest: [u8; 32] = Sha256::digest(&other).into();
        other.extend_from_slice(&digest);
        assert_eq!(
            Checkpoint::parse(&other).unwrap_err(),
            CheckpointError::Protocol {
                found: flexdyn_proto::PROTOCOL_VERSION + 1,
                this: flexdyn_proto::PROTOCOL_VERSION
            }
        );
        // Appended to: the length.
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(matches!(
            Checkpoint::parse(&longer),
            Err(CheckpointError::Length { .. })
        ));
    }
}
