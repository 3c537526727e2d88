//! Checkpoints of a running server: the complete state of its world at a frame boundary, saved
//! from the live run (at a tick given on the command line, or when an operator asks) and
//! resumed by a new server that then publishes the same stream from that tick on, bit for bit.
//!
//! The file is the vehicle layer's ([`flexdyn_vehicle::checkpoint`], front end `run` or
//! `run --fleet`); what a server adds to each vehicle's simulation is its command book (every
//! participant's last command, the link faults' state and delay lines) and the command held
//! over the last frame, which the next state message reports.
//!
//! # When
//! A checkpoint of tick `k` is taken at boundary `k` after the frame `k − 1 → k` is stepped
//! and before the telemetry of `k` is filled: a resumed server fills and publishes tick `k`
//! first, the same bytes the uninterrupted run published, then waits for (lockstep) or takes
//! (real time) the commands of tick `k`.
//!
//! # Cost on the stepping thread
//! The state is listed into a buffer on the thread that steps the frames (tens of µs for
//! `acs_full`, `tools/benches/checkpoint_realtime.rs`; it allocates that buffer, once per
//! checkpoint); the checksum ([`checkpoint::seal`]) and the file are the checkpoint writer
//! thread's, so a slow disk never stalls a frame. The longest listing is reported ([`CheckpointStats`]). A request made while
//! the writer still holds [`WRITER_QUEUE`] checkpoints is refused and counted, never waited
//! for.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::Arc;
use std::time::Instant;

use flexdyn_kernel::archive::Archive;
use flexdyn_vehicle::checkpoint::{self, Checkpoint, CheckpointError, CheckpointHeader, Source};

use super::error::ServerError;
use super::world::WorldStepper;

/// The front end a one-spacecraft server's checkpoints name.
pub const FRONT_END: &str = "run";
/// The front end a fleet server's checkpoints name.
pub const FRONT_END_FLEET: &str = "run --fleet";
/// Checkpoints the writer may hold before a new request is refused.
pub const WRITER_QUEUE: usize = 4;

/// Lists the state of a running `world` (saved or restored): per vehicle its simulation, its
/// command book and the command held over the last frame.
pub fn list(world: &mut WorldStepper, a: &mut Archive<'_>) {
    a.section("world", |a| {
        a.expect_count("vehicles", world.vehicles.len());
        for v in &mut world.vehicles {
            let name = format!("vehicle {}", v.id);
            a.section(&name, |a| {
                v.stepper.sim.archive(a);
                v.stepper.book.archive(a);
                a.section("held command", |a| a.put(&mut v.stepper.held));
            });
        }
    });
}

/// What the checkpoints of a run cost and how many were written.
#[derive(Debug, Default)]
pub struct CheckpointStats {
    /// Checkpoints written to their files.
    pub written: AtomicU64,
    /// Checkpoints that could not be taken or written (logged with the reason).
    pub failed: AtomicU64,
    /// \[ns\] the longest time the stepping thread spent listing a checkpoint's state.
    pub max_list_ns: AtomicU64,
}

impl CheckpointStats {
    /// The counters as the run's report shows them.
    pub fn summary(&self) -> super::report::CheckpointSummary {
        super::report::CheckpointSummary {
            written: self.written.load(Ordering::Relaxed),
            failed: self.failed.load(Ordering::Relaxed),
            max_list_ns: self.max_list_ns.load(Ordering::Relaxed),
        }
    }
}

/// A server's checkpoint settings (`flexdyn run --checkpoint-at-tick/--checkpoint`,
/// `--checkpoint-dir`, `--resume`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CheckpointSettings {
    /// Save at this tick to this file.
    pub save_at: Option<(u64, PathBuf)>,
    /// Where an operator's checkpoints go (`<dir>/<sc_id>-tick<k>.ckpt`); `None`: an operator's
    /// request is refused.
    pub dir: Option<PathBuf>,
    /// The configuration the run came from, as its checkpoints record it.
    pub source: Source,
    /// Resume from this checkpoint file (its bytes, checked).
    pub resume: Option<Resumed>,
}

/// A checkpoint a server resumes from.
#[derive(Debug, Clone, PartialEq)]
pub struct Resumed {
    /// The file.
    pub file: PathBuf,
    /// Its bytes.
    pub bytes: Vec<u8>,
    /// The tick it was taken at.
    pub tick: u64,
}

impl CheckpointSettings {
    /// Whether this run may save a checkpoint.
    pub fn saves(&self) -> bool {
        self.save_at.is_some() || self.dir.is_some()
    }

    /// The tick the run starts at (the resumed checkpoint's, else 0).
    pub fn start_tick(&self) -> u64 {
        self.resume.as_ref().map_or(0, |r| r.tick)
    }
}

/// Reads and checks checkpoint `file` for a server (`front_end`).
pub fn read(file: &Path, front_end: &str) -> Result<(Resumed, CheckpointHeader), ServerError> {
    let bytes = std::fs::read(file).map_err(|e| ServerError::Checkpoint {
        file: file.to_path_buf(),
        problem: format!("cannot read it: {e}"),
    })?;
    let header = {
        let c = Checkpoint::parse_of(&bytes, front_end).map_err(|e| refused(file, e))?;
        if c.header.tick == 0 {
            return Err(ServerError::Checkpoint {
                file: file.to_path_buf(),
                problem: "it is taken at tick 0: a run from tick 0 is its configuration".into(),
            });
        }
        c.header
    };
    Ok((
        Resumed {
            file: file.to_path_buf(),
            tick: header.tick,
            bytes,
        },
        header,
    ))
}

fn parse<'a>(file: &Path, bytes: &'a [u8]) -> Result<Checkpoint<'a>, ServerError> {
    Checkpoint::parse(bytes).map_err(|e| refused(file, e))
}

fn refused(file: &Path, e: CheckpointError) -> ServerError {
    ServerError::Checkpoint {
        file: file.to_path_buf(),
        problem: e.to_string(),
    }
}

/// Restores `r` into `world`, freshly built; checks that the state is at the header's time.
pub fn restore(r: &Resumed, world: &mut WorldStepper) -> Result<(), ServerError> {
    let c = parse(&r.file, &r.bytes)?;
    let (step_ns, frame_ns) = world.vehicles.first().map_or((0, 0), |v| {
        (v.stepper.sim.step_ns(), v.stepper.sim.frame_ns())
    });
    c.restore_with(step_ns, frame_ns, |a| list(world, a))
        .map_err(|e| refused(&r.file, e))?;
    if world.sim_time_ns() != c.header.t_sim_ns {
        return Err(ServerError::Checkpoint {
            file: r.file.clone(),
            problem: format!(
                "its header says t = {} ns and its state t = {} ns: it is damaged",
                c.header.t_sim_ns,
                world.sim_time_ns()
            ),
        });
    }
    Ok(())
}

/// Whether checkpoint `r` fits a one-spacecraft server of `settings` over `cfg`, without
/// running it: the world is built as the server builds it and `r` restored into it, with the
/// checks of a resume (the same vehicle, effectors, sensors, faults and participants, the same
/// step and frame). A campaign that starts every run from one checkpoint asks this before
/// any run starts (`flexdyn_campaign::fork`).
pub fn check_fits(
    r: &Resumed,
    settings: &super::ServerSettings,
    cfg: &flexdyn_vehicle::config::SimConfig,
) -> Result<(), ServerError> {
    let sim = flexdyn_vehicle::sim::Simulation::new(cfg)
        .map_err(|source| ServerError::Config { file: None, source })?;
    let stepper = super::stepper::Stepper::new(sim, settings);
    let mut world = WorldStepper::one(settings.sc_id.clone(), stepper);
    restore(r, &mut world)
}

/// A checkpoint listed on the stepping thread, for the writer.
enum Job {
    Write {
        file: PathBuf,
        tick: u64,
        bytes: Result<Vec<u8>, CheckpointError>,
    },
    /// Everything queued before is written: say so.
    Flush(SyncSender<()>),
}

/// The stepping thread's side: takes the checkpoints due at a boundary.
pub struct Checkpointer {
    header: CheckpointHeader,
    save_at: Option<(u64, PathBuf)>,
    dir: Option<PathBuf>,
    stem: String,
    /// The operator's requested tick (`u64::MAX`: none), set by the operator callback.
    requested: Arc<AtomicU64>,
    stats: Arc<CheckpointStats>,
    tx: SyncSender<Job>,
}

impl Checkpointer {
    /// At boundary `k` of `world`: takes the checkpoint due there, if any (the command line's
    /// tick, or an operator's request for this tick or an earlier one). Without one due: two
    /// compares and one atomic load.
    #[inline]
    pub fn at_boundary(&mut self, world: &mut WorldStepper, k: u64) {
        let cli = matches!(&self.save_at, Some((t, _)) if *t == k);
        let operator = self.requested.load(Ordering::Acquire) <= k;
        if cli || operator {
            self.take(world, k, cli, operator);
        }
    }

    #[cold]
    fn take(&mut self, world: &mut WorldStepper, k: u64, cli: bool, operator: bool) {
        let started = Instant::now();
        self.header.tick = k;
        self.header.t_sim_ns = world.sim_time_ns();
        let bytes = checkpoint::list_with(&self.header, |a| list(world, a));
        let list_ns = u64::try_from(started.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.stats.max_list_ns.fetch_max(list_ns, Ordering::Relaxed);
        let mut files = Vec::with_capacity(2);
        if cli {
            if let Some((_, f)) = &self.save_at {
                files.push(f.clone());
            }
        }
        if operator {
            self.requested.store(u64::MAX, Ordering::Release);
            if let Some(dir) = &self.dir {
                files.push(dir.join(format!("{}-tick{k}.ckpt", self.stem)));
            }
        }
        // One copy per file, the last one moved.
        let copies = std::iter::repeat_n(bytes, files.len());
        for (file, bytes) in files.into_iter().zip(copies) {
            let job = Job::Write {
                file,
                tick: k,
                bytes,
            };
            match self.tx.try_send(job) {
                Ok(()) => {}
                Err(TrySendError::Full(Job::Write { file, .. })) => {
                    self.stats.failed.fetch_add(1, Ordering::Relaxed);
                    tracing::error!(file = %file.display(), tick = k,
                        "checkpoint not taken: the writer still holds {WRITER_QUEUE}");
                }
                Err(_) => {
                    self.stats.failed.fetch_add(1, Ordering::Relaxed);
                    tracing::error!(tick = k, "checkpoint not taken: the writer thread is gone");
                }
            }
        }
    }
}

/// The run's side of the checkpoint writer thread: flushes it at the end of the run.
pub struct Writer {
    tx: SyncSender<Job>,
    /// The writer's counters (also the report's).
    pub stats: Arc<CheckpointStats>,
    /// The operator's requested tick, which [`Checkpointer`] reads.
    pub requested: Arc<AtomicU64>,
}

impl Writer {
    /// Starts the writer thread, and the stepping thread's side for a run of `front_end` whose
    /// files are named after `stem` (the spacecraft id, or `fleet`), with the step and frame
    /// `(step_ns, frame_ns)`; `sync`: each file is synced to the disk before it is renamed into
    /// place ([`checkpoint::write_file`]).
    pub fn start(
        settings: &CheckpointSettings,
        (front_end, stem): (&str, &str),
        (step_ns, frame_ns): (u64, u64),
        sync: bool,
    ) -> Result<(Self, Checkpointer), ServerError> {
        let (tx, rx) = sync_channel(WRITER_QUEUE);
        let stats = Arc::new(CheckpointStats::default());
        let requested = Arc::new(AtomicU64::new(u64::MAX));
        let thread_stats = stats.clone();
        std::thread::Builder::new()
            .name("flexdyn-checkpoint".into())
            .spawn(move || write_all(&rx, &thread_stats, sync))
            .map_err(|e| {
                ServerError::Internal(format!("cannot start the checkpoint writer: {e}"))
            })?;
        let mut header = CheckpointHeader {
            front_end: front_end.into(),
            step_ns,
            frame_ns,
            ..CheckpointHeader::default()
        };
        settings.source.clone().into_header(&mut header);
        let checkpointer = Checkpointer {
            header,
            save_at: settings.save_at.clone(),
            dir: settings.dir.clone(),
            stem: stem.into(),
            requested: requested.clone(),
            stats: stats.clone(),
            tx: tx.clone(),
        };
        Ok((
            Self {
                tx,
                stats,
                requested,
            },
            checkpointer,
        ))
    }

    /// The requested tick an operator's checkpoint requests set, when `settings` give them a
    /// directory (`None`: they are refused).
    pub fn operator_requests(&self, settings: &CheckpointSettings) -> Option<Arc<AtomicU64>> {
        settings.dir.as_ref().map(|_| self.requested.clone())
    }

    /// Waits (up to 10 s) until every checkpoint taken so far is written.
    pub fn flush(&self) {
        let (ack_tx, ack_rx) = sync_channel(1);
        if self.tx.send(Job::Flush(ack_tx)).is_ok() {
            let _ = ack_rx.recv_timeout(std::time::Duration::from_secs(10));
        }
    }
}

impl Drop for Writer {
    /// A run that ends on an error still writes the checkpoints it took.
    fn drop(&mut self) {
        self.flush();
    }
}

/// The writer thread: writes each checkpoint beside its file, then renames it over, so a
/// reader never sees half of one.
fn write_all(rx: &Receiver<Job>, stats: &CheckpointStats, sync: bool) {
    while let Ok(job) = rx.recv() {
        let (file, tick, bytes) = match job {
            Job::Flush(ack) => {
                let _ = ack.send(());
                continue;
            }
            Job::Write { file, tick, bytes } => (file, tick, bytes),
        };
        let written = bytes
            .map(checkpoint::seal)
            .map_err(|e| e.to_string())
            .and_then(|b| {
                checkpoint::write_file(&file, &b, sync)
                    .map(|()| b.len())
                    .map_err(|e| e.to_string())
            });
        match written {
            Ok(len) => {
                stats.written.fetch_add(1, Ordering::Relaxed);
                tracing::info!(file = %file.display(), tick, bytes = len, "checkpoint written");
            }
            Err(problem) => {
                stats.failed.fetch_add(1, Ordering::Relaxed);
                tracing::error!(file = %file.display(), tick, "checkpoint not written: {problem}");
            }
        }
    }
}
