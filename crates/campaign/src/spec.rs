//! The campaign file (TOML), read with the configuration's schema reader, so every error names
//! its field (`dispersions[2].sigma: invalid value: …`).
//!
//! ```toml
//! base = "reference.toml"      # relative to this file; absent: the embedded default
//! runs = 20
//! seed = 1
//! duration_s = 60.0
//! controller = "flexdyn-acs-demo --connect {endpoint} --sc-id {sc_id} --sender-id {sender_id}"
//! sigma_rn = [0.1, 0.2, -0.1]  # the target of the sigma_br criteria (default 0)
//! max_redraws = 100
//! participant_timeout_s = 5.0
//!
//! [resources]                    # per run, for `campaign submit --slurm` (optional)
//! cpus_per_run = 2
//! memory_mb = 2048
//! time_limit_s = 600
//!
//! [[dispersions]]
//! key = "hub.inertia_bc_b_kg_m2[0][0]"
//! distribution = "normal"        # mean = the nominal value unless `mean` is given
//! sigma = 45.0
//!
//! [[criteria]]
//! name = "pointing"
//! quantity = "sigma_br"          # sigma_br | sigma_bn | omega | theta
//! statistic = "final"            # final | max | settling_time
//! below = 0.01
//! ```
//!
//! Starting every run from a checkpoint (docs/guides/campaigns.md, "Start every run from a
//! checkpoint"; [`super::fork`]): `start_from = "detumbled.ckpt"` (relative to this file) in
//! place of `base`, and only a fault's window that opens after the checkpoint dispersed.
//!
//! Over a fleet (docs/guides/campaigns.md, "Campaigns over a fleet"): `fleet = "formation.toml"` replaces `base`,
//! every dispersion and criterion names its `vehicle`, and `[[controllers]]` (one per vehicle,
//! or one for several) replaces `controller`:
//!
//! ```toml
//! fleet = "formation.toml"
//! [[controllers]]
//! vehicle = "deputy"             # {vehicle} and {sc_id}
//! sender_id = 2                  # default: the vehicle's one participant (besides 9)
//! command = "flexdyn-formation-demo --connect {endpoint} --sc-id {sc_id} --chief chief --sender-id {sender_id}"
//! [[dispersions]]
//! vehicle = "deputy"
//! key = "relative.hill_position_m"   # or any key of its spacecraft configuration
//! distribution = "normal"
//! sigma = 1.0
//! [[criteria]]
//! vehicle = "deputy"
//! name = "range"
//! quantity = "range"             # |r_dc| to its chief, from the RelativeStateMsg
//! statistic = "max"
//! below = 150.0
//! ```

use std::path::{Path, PathBuf};

use toml::de::DeTable;

use super::command::split_command;
use super::fleet::FleetBase;
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::reader::TableReader;
use flexdyn_kernel::schema::{location, At, SchemaError};
use flexdyn_vehicle::config::{
    beyond_max_time, config_message, log_warnings, whole_ns, ConfigError, SimConfig, SourceMap,
    DEFAULT_CONFIG_TOML,
};

/// A distribution of a dispersion.
#[derive(Clone, Debug, PartialEq)]
pub enum Distribution {
    /// Normal; `mean` `None` is the nominal (base) value of each element.
    Normal {
        /// The mean, or `None` for the nominal value.
        mean: Option<f64>,
        /// Standard deviation (≥ 0).
        sigma: f64,
    },
    /// Uniform on [low, high).
    Uniform {
        /// Lower bound.
        low: f64,
        /// Upper bound (> low).
        high: f64,
    },
    /// A uniformly random orientation (Haar measure), written as the MRP set with |σ| ≤ 1;
    /// only for a 3-element MRP key such as `initial.sigma_bn`.
    UniformAttitude,
}

/// One `[[dispersions]]` entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Dispersion {
    /// The TOML path as written.
    pub key: String,
    /// Its distribution.
    pub distribution: Distribution,
    /// The vehicle whose configuration it writes into (a fleet campaign's; `None` otherwise).
    pub vehicle: Option<String>,
}

pub use super::criteria::{Criterion, FswRef, FswTarget, Quantity, Statistic};

/// A validated campaign.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// The campaign file (errors start with its name).
    pub path: PathBuf,
    /// The campaign file's text (hashed into the manifest).
    pub source: String,
    /// Where the base configuration came from (`None`: embedded default).
    pub base_path: Option<PathBuf>,
    /// The base configuration's text.
    pub base_toml: String,
    /// Number of runs.
    pub runs: u32,
    /// The master seed.
    pub seed: u64,
    /// \[s\] simulated duration of each run, as written.
    pub duration_s: f64,
    /// \[ns\] the same, a whole number of frames of the base configuration.
    pub duration_ns: u64,
    /// The flight code's command line, if any.
    pub controller: Option<String>,
    /// Target attitude σ_RN of the `sigma_br` criteria.
    pub sigma_rn: [f64; 3],
    /// Draws allowed for a run whose dispersed configuration is invalid.
    pub max_redraws: u32,
    /// \[s\] lockstep wait for each answer.
    pub participant_timeout_s: f64,
    /// The dispersions.
    pub dispersions: Vec<Dispersion>,
    /// The criteria.
    pub criteria: Vec<Criterion>,
    /// The base configuration's random faults (`[[faults]]` with `mtbf_s`) were removed
    /// ([`Self::without_random_faults`]): the same campaign without them, for comparison.
    pub random_faults_removed: bool,
    /// `fleet`: the fleet the campaign runs over, in place of `base` (`base_path` is then
    /// `None` and `base_toml` empty; each vehicle has its own).
    pub fleet: Option<FleetBase>,
    /// `[[controllers]]` of a fleet campaign.
    pub controllers: Vec<Controller>,
    /// `[resources]`: what one run asks of a batch scheduler.
    pub resources: Resources,
    /// `start_from`: the checkpoint every run starts from (a fork at its tick; `None`: every
    /// run starts at t = 0). The base is then the configuration it recorded.
    pub start_from: Option<super::fork::StartFrom>,
}

/// `[resources]`: what one run needs on a cluster node (`campaign submit --slurm` asks for it
/// per array task). A run is a lockstep server plus its flight code, so two CPUs keep the two
/// from taking turns on one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resources {
    /// `cpus_per_run` (default 2).
    pub cpus_per_run: u32,
    /// `memory_mb`: \[MB\] memory per run; `None`: the partition's default.
    pub memory_mb: Option<u64>,
    /// `time_limit_s`: \[s\] wall-time limit per run; `None`: the partition's default. A run
    /// stopped by it could not be run (it is not a verdict on the flight code).
    pub time_limit_s: Option<u64>,
}

impl Default for Resources {
    fn default() -> Self {
        Self {
            cpus_per_run: 2,
            memory_mb: None,
            time_limit_s: None,
        }
    }
}

/// One `[[controllers]]` entry of a fleet campaign: a flight-code process per run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Controller {
    /// The vehicle it runs for: `{vehicle}` and `{sc_id}` in its command.
    pub vehicle: String,
    /// Its lockstep sender id (`{sender_id}`), a participant of `vehicle` in the fleet file
    /// (and of every other vehicle it commands).
    pub sender_id: u32,
    /// Its command line (`{endpoint}`, `{sc_id}`, `{vehicle}`, `{sender_id}`, `{run}`).
    pub command: String,
}

/// The sender id of the campaign's observer: it answers every tick of every vehicle with
/// `NoCommand` and records the states, so no controller may use it.
pub const OBSERVER_ID: u32 = 9;

/// Why a campaign file is not usable. Every message starts with the name of the file that
/// holds the offending field: the campaign file, or its base configuration.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CampaignError {
    /// The file cannot be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
    /// Not TOML.
    #[error("{}: TOML syntax error{at}: {message}", path.display())]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
        /// Where the parser stopped.
        at: At,
    },
    /// A field has the wrong shape.
    #[error("{}: {source}", path.display())]
    Schema {
        /// The file.
        path: PathBuf,
        /// The field-named error.
        #[source]
        source: SchemaError,
    },
    /// A field's value is not usable.
    #[error("{}: {field}: {problem}{at}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The TOML path of the field.
        field: String,
        /// What is wrong.
        problem: String,
        /// Where the field is.
        at: At,
    },
    /// The fleet file (`fleet`) is invalid: the message is the fleet file's own (it names the
    /// vehicle and the field), with its position in that file, then names the campaign.
    #[error("{}: {source}{at} (the fleet of {})", fleet.display(), campaign.display())]
    Fleet {
        /// The campaign file.
        campaign: PathBuf,
        /// The fleet file.
        fleet: PathBuf,
        /// The fleet file's error.
        #[source]
        source: Box<flexdyn_vehicle::world::FleetError>,
        /// Where the field is in the fleet file.
        at: At,
    },
    /// The base configuration (`base`) is invalid: the message is the configuration's own,
    /// starting with the base file's name, then names the campaign.
    #[error(
        "{} (the base configuration of {})",
        config_message(base.as_deref(), source),
        campaign.display()
    )]
    Base {
        /// The campaign file.
        campaign: PathBuf,
        /// The base file (`None`: the embedded default).
        base: Option<PathBuf>,
        /// The configuration's error; it names the field.
        #[source]
        source: Box<ConfigError>,
    },
}

const ROOT_KEYS: &[&str] = &[
    "base",
    "fleet",
    "controllers",
    "runs",
    "seed",
    "duration_s",
    "controller",
    "sigma_rn",
    "max_redraws",
    "participant_timeout_s",
    "dispersions",
    "criteria",
    "resources",
    "start_from",
];

/// \[s\] default of `participant_timeout_s`.
const DEFAULT_PARTICIPANT_TIMEOUT_S: f64 = 5.0;

impl Campaign {
    /// The folder relative paths in the base configuration are resolved against (its file's;
    /// the working directory for the embedded default).
    pub fn base_dir(&self) -> PathBuf {
        self.base_path
            .as_deref()
            .and_then(Path::parent)
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
    }

    /// Removes the base configuration's random faults (`[[faults]]` entries with `mtbf_s`), so
    /// the same campaign runs without them (`--without-random-faults`). Every run keeps its
    /// dispersions and sensor seeds: those are drawn from streams of their own, so run i with
    /// and without the faults differ by the faults only (a paired comparison). Returns how many
    /// were removed.
    pub fn without_random_faults(&mut self) -> Result<usize, CampaignError> {
        let mut removed = 0;
        if let Some(fleet) = &mut self.fleet {
            for v in &mut fleet.vehicles {
                let (text, n) = remove_random_faults(&v.base_toml).map_err(|e| {
                    invalid_at(
                        &self.source,
                        &self.path,
                        "fleet",
                        format!("vehicle {:?}: {e}", v.id),
                    )
                })?;
                v.base_toml = text;
                removed += n;
            }
        } else {
            let (text, n) =
                remove_random_faults(&self.base_toml).map_err(|e| self.invalid("base", e))?;
            if let (Some(start), true) = (&self.start_from, n > 0) {
                return Err(self.invalid(
                    "start_from",
                    format!(
                        "--without-random-faults would remove {n} fault(s) from the base, and \
                         the checkpoint {} holds their state: a run without them cannot start \
                         from it",
                        start.path.display()
                    ),
                ));
            }
            self.base_toml = text;
            removed = n;
        }
        self.random_faults_removed = true;
        Ok(removed)
    }

    /// Reads and validates `path`. Dispersion keys are checked against the base configuration
    /// later, by [`super::plan::Plan::new`], which also builds the model.
    pub fn from_file(path: &Path) -> Result<Self, CampaignError> {
        let source = std::fs::read_to_string(path).map_err(|source| CampaignError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::from_str_at(&source, path)
    }

    /// An error about `field` of the campaign file, with its position in the file.
    pub fn invalid(&self, field: &str, problem: String) -> CampaignError {
        invalid_at(&self.source, &self.path, field, problem)
    }

    /// An error of the base configuration (it names the base file).
    pub fn base_error(&self, source: ConfigError) -> CampaignError {
        CampaignError::Base {
            campaign: self.path.clone(),
            base: self.base_path.clone(),
            source: Box::new(source),
        }
    }

    /// Reads a campaign from `source`; `path` names it in errors and anchors `base`.
    pub fn from_str_at(source: &str, path: &Path) -> Result<Self, CampaignError> {
        let schema = |source: SchemaError| CampaignError::Schema {
            path: path.to_owned(),
            source,
        };
        let invalid = |field: &str, problem: String| invalid_at(source, path, field, problem);
        let doc = DeTable::parse(source).map_err(|e| CampaignError::Syntax {
            path: path.to_owned(),
            message: e.message().to_owned(),
            at: At(e.span().map(|sp| location(source, sp.start))),
        })?;
        let doc = doc.get_ref();
        let root = TableReader::root(source, doc, ROOT_KEYS).map_err(schema)?;
        // As in a configuration, every float must be finite (TOML accepts `nan` and `inf`).
        if let Some((field, at)) = SourceMap::new(source, doc).first_non_finite(doc) {
            return Err(CampaignError::Invalid {
                path: path.to_owned(),
                field,
                problem: "must be finite (got NaN or Inf)".into(),
                at,
            });
        }
        // `base` and `fleet` are relative to the campaign file.
        let file_field = |key: &str| -> Result<Option<PathBuf>, CampaignError> {
            if root.get(key).is_none() {
                return Ok(None);
            }
            let rel = PathBuf::from(root.string(key).map_err(schema)?);
            Ok(Some(if rel.is_absolute() {
                rel
            } else {
                path.parent().unwrap_or(Path::new(".")).join(rel)
            }))
        };
        let mut base_path = file_field("base")?;
        let fleet_path = file_field("fleet")?;
        let start_from = match file_field("start_from")? {
            Some(p) => {
                Some(super::fork::StartFrom::read(&p).map_err(|e| invalid("start_from", e))?)
            }
            None => None,
        };
        if base_path.is_some() && fleet_path.is_some() {
            return Err(invalid(
                "fleet",
                "give either base (one spacecraft configuration) or fleet (a fleet file), not \
                 both"
                    .into(),
            ));
        }
        if let (Some(start), Some(_)) = (&start_from, &fleet_path) {
            return Err(invalid(
                "start_from",
                format!(
                    "{} ({} is one spacecraft's); start_from works with base",
                    super::fork::NO_FLEET_YET,
                    start.path.display()
                ),
            ));
        }
        // A forked campaign's base is the configuration its checkpoint recorded.
        let forked_base = match &start_from {
            Some(start) => {
                if let Some(p) = &base_path {
                    let text = std::fs::read_to_string(p).map_err(|e| {
                        invalid("base", format!("cannot read {}: {e}", p.display()))
                    })?;
                    if flexdyn_vehicle::checkpoint::CheckpointHeader::digest(&text)
                        != start.source_sha256
                    {
                        return Err(invalid(
                            "base",
                            format!(
                                "{} is not the configuration the checkpoint {} was taken with \
                                 ({}): every run starts from that checkpoint, so its base is \
                                 that configuration; leave base out",
                                p.display(),
                                start.path.display(),
                                start
                                    .source
                                    .file()
                                    .map_or("the embedded default".to_owned(), |f| f
                                        .display()
                                        .to_string())
                            ),
                        ));
                    }
                }
                base_path = start.source.file();
                Some(start.source.text.clone())
            }
            None => None,
        };
        let fleet = match &fleet_path {
            Some(p) => {
                let text = std::fs::read_to_string(p)
                    .map_err(|e| invalid("fleet", format!("cannot read {}: {e}", p.display())))?;
                let fleet = FleetBase::new(p, &text).map_err(|e| fleet_error(path, p, &text, e))?;
                for v in &fleet.config.vehicles {
                    log_warnings(&v.cfg, None);
                }
                Some(fleet)
            }
            None => None,
        };
        // The frame every run is a whole number of (a fleet's vehicles share theirs).
        let (base_toml, frame_ns, frame_hz, base) = match &fleet {
            Some(f) => {
                let first = &f.config.vehicles[0].cfg;
                (String::new(), first.frame_ns, first.frame_hz, None)
            }
            None => {
                let base_toml = match (&forked_base, &base_path) {
                    (Some(text), _) => text.clone(),
                    (None, Some(p)) => std::fs::read_to_string(p).map_err(|e| {
                        invalid("base", format!("cannot read {}: {e}", p.display()))
                    })?,
                    (None, None) => DEFAULT_CONFIG_TOML.to_owned(),
                };
                let base_dir = base_path
                    .as_deref()
                    .and_then(Path::parent)
                    .unwrap_or(Path::new("."));
                let base = SimConfig::from_toml_str_in(&base_toml, base_dir).map_err(|source| {
                    CampaignError::Base {
                        campaign: path.to_owned(),
                        base: base_path.clone(),
                        source: Box::new(source),
                    }
                })?;
                log_warnings(&base, base_path.as_deref());
                (base_toml, base.frame_ns, base.frame_hz, Some(base))
            }
        };
        let runs = root.int_in("runs", 1, 1_000_000).map_err(schema)? as u32;
        let seed = root.int_in("seed", 0, i64::MAX).map_err(schema)? as u64;
        let duration_s = root.f64("duration_s").map_err(schema)?;
        let duration_ns =
            within_time("duration_s", duration_s).map_err(|p| invalid("duration_s", p))?;
        if duration_ns % frame_ns != 0 {
            return Err(invalid(
                "duration_s",
                format!(
                    "{} s is not a whole number of frames (frame = {} s at {} Hz)",
                    Num(duration_s),
                    Num(frame_ns as f64 / 1e9),
                    Num(frame_hz)
                ),
            ));
        }
        if let Some(start) = &start_from {
            if start.t_sim_ns >= duration_ns {
                return Err(invalid(
                    "start_from",
                    format!(
                        "the checkpoint {} is at t = {} s, at or after the end of the runs \
                         (duration_s = {} s, counted from t = 0)",
                        start.path.display(),
                        Num(start.t_s()),
                        Num(duration_s)
                    ),
                ));
            }
        }
        let controller = match root.get("controller") {
            Some(_) => Some(root.string("controller").map_err(schema)?),
            None => None,
        };
        if let Some(c) = &controller {
            if fleet.is_some() {
                return Err(invalid(
                    "controller",
                    "a campaign over a fleet starts a controller per vehicle: use \
                     [[controllers]] (vehicle, command) instead"
                        .into(),
                ));
            }
            let words = split_command(c).map_err(|e| invalid("controller", e))?;
            if words.is_empty() {
                return Err(invalid("controller", "is empty".into()));
            }
        }
        let controllers = match &fleet {
            Some(f) => read_controllers(&root, f, source, path)?,
            None if root.get("controllers").is_some() => {
                return Err(invalid(
                    "controllers",
                    "applies only to a campaign over a fleet (fleet = \"…\"); with one \
                     spacecraft, use controller"
                        .into(),
                ))
            }
            None => Vec::new(),
        };
        let sigma_rn = root
            .opt_floats::<3>("sigma_rn")
            .map_err(schema)?
            .unwrap_or([0.0; 3]);
        let max_redraws = match root.get("max_redraws") {
            Some(_) => root.int_in("max_redraws", 0, 1_000_000).map_err(schema)? as u32,
            None => 100,
        };
        let participant_timeout_s = root
            .opt_f64("participant_timeout_s")
            .map_err(schema)?
            .unwrap_or(DEFAULT_PARTICIPANT_TIMEOUT_S);
        within_time("participant_timeout_s", participant_timeout_s)
            .map_err(|p| invalid("participant_timeout_s", p))?;

        let resources = match root
            .opt_table("resources", &["cpus_per_run", "memory_mb", "time_limit_s"])
            .map_err(schema)?
        {
            None => Resources::default(),
            Some(t) => Resources {
                cpus_per_run: match t.get("cpus_per_run") {
                    Some(_) => t.int_in("cpus_per_run", 1, 4096).map_err(schema)? as u32,
                    None => Resources::default().cpus_per_run,
                },
                memory_mb: match t.get("memory_mb") {
                    Some(_) => Some(t.int_in("memory_mb", 1, 1 << 40).map_err(schema)? as u64),
                    None => None,
                },
                time_limit_s: match t.get("time_limit_s") {
                    // Slurm's limit is whole seconds at most a year here (`D-HH:MM:SS`).
                    Some(_) => {
                        Some(t.int_in("time_limit_s", 1, 366 * 86_400).map_err(schema)? as u64)
                    }
                    None => None,
                },
            },
        };

        let mut dispersions = Vec::new();
        let tables = root
            .tables(
                "dispersions",
                &[
                    "key",
                    "distribution",
                    "mean",
                    "sigma",
                    "low",
                    "high",
                    "vehicle",
                ],
            )
            .map_err(schema)?
            .unwrap_or_default();
        for (i, t) in tables.iter().enumerate() {
            let field = |k: &str| format!("dispersions[{i}].{k}");
            let key = t.string("key").map_err(schema)?;
            super::keys::parse(&key).map_err(|e| invalid(&field("key"), e))?;
            let vehicle = entry_vehicle(
                t,
                fleet.as_ref(),
                &format!("dispersions[{i}]"),
                "key",
                source,
                path,
            )?;
            let kind = t.string("distribution").map_err(schema)?;
            let only = |allowed: &[&str]| -> Result<(), CampaignError> {
                for k in ["mean", "sigma", "low", "high"] {
                    if !allowed.contains(&k) && t.get(k).is_some() {
                        return Err(invalid(
                            &field(k),
                            format!("does not apply to distribution {kind:?}"),
                        ));
                    }
                }
                Ok(())
            };
            let distribution = match kind.as_str() {
                "normal" => {
                    only(&["mean", "sigma"])?;
                    let sigma = t.f64("sigma").map_err(schema)?;
                    if sigma < 0.0 {
                        return Err(invalid(
                            &field("sigma"),
                            format!("must be ≥ 0, got {}", Num(sigma)),
                        ));
                    }
                    Distribution::Normal {
                        mean: t.opt_f64("mean").map_err(schema)?,
                        sigma,
                    }
                }
                "uniform" => {
                    only(&["low", "high"])?;
                    let (low, high) = (
                        t.f64("low").map_err(schema)?,
                        t.f64("high").map_err(schema)?,
                    );
                    if high <= low {
                        return Err(invalid(
                            &field("high"),
                            format!("must be greater than low ({}), got {}", Num(low), Num(high)),
                        ));
                    }
                    if !(high - low).is_finite() {
                        return Err(invalid(
                            &field("high"),
                            format!(
                                "high - low = {} - ({}) overflows a float: no draw could be made",
                                Num(high),
                                Num(low)
                            ),
                        ));
                    }
                    Distribution::Uniform { low, high }
                }
                "uniform_attitude" => {
                    only(&[])?;
                    Distribution::UniformAttitude
                }
                other => {
                    return Err(invalid(
                        &field("distribution"),
                        format!(
                            "{other:?} is not one of \"normal\", \"uniform\", \"uniform_attitude\""
                        ),
                    ))
                }
            };
            dispersions.push(Dispersion {
                key,
                distribution,
                vehicle,
            });
        }

        let tables = root
            .tables("criteria", &super::criteria::criterion_keys())
            .map_err(schema)?
            .unwrap_or_default();
        let cx = super::criteria::Context {
            source,
            path,
            fleet: fleet.as_ref(),
            base: base.as_ref(),
            duration_s,
        };
        let criteria = super::criteria::read(&tables, &cx, &|t, i| {
            entry_vehicle(
                t,
                fleet.as_ref(),
                &format!("criteria[{i}]"),
                "name",
                source,
                path,
            )
        })?;
        Ok(Self {
            path: path.to_owned(),
            source: source.to_owned(),
            base_path,
            base_toml,
            runs,
            seed,
            duration_s,
            duration_ns,
            controller,
            sigma_rn,
            max_redraws,
            participant_timeout_s,
            dispersions,
            criteria,
            random_faults_removed: false,
            fleet,
            controllers,
            resources,
            start_from,
        })
    }
}

/// The `vehicle` of the `[[dispersions]]` or `[[criteria]]` entry `entry` (`dispersions[2]`):
/// required with a fleet, refused without one, and one of the fleet's ids. A missing one is
/// located at the entry's `near` key.
fn entry_vehicle(
    t: &TableReader<'_, '_>,
    fleet: Option<&FleetBase>,
    entry: &str,
    near: &str,
    source: &str,
    path: &Path,
) -> Result<Option<String>, CampaignError> {
    let field = format!("{entry}.vehicle");
    let vehicle = match t.get("vehicle") {
        Some(_) => Some(
            t.string("vehicle")
                .map_err(|source| CampaignError::Schema {
                    path: path.to_owned(),
                    source,
                })?,
        ),
        None => None,
    };
    match (fleet, &vehicle) {
        (None, None) => Ok(None),
        (None, Some(_)) => Err(invalid_at(
            source,
            path,
            &field,
            "applies only to a campaign over a fleet (fleet = \"…\"); this one has a single \
             spacecraft"
                .into(),
        )),
        (Some(f), None) => Err(CampaignError::Invalid {
            path: path.to_owned(),
            field,
            problem: format!(
                "missing: over a fleet, every entry names its vehicle (one of {})",
                f.ids()
            ),
            at: SourceMap::locate(source, &format!("{entry}.{near}")),
        }),
        (Some(f), Some(id)) if f.vehicle(id).is_none() => Err(invalid_at(
            source,
            path,
            &field,
            format!(
                "{id:?} is not a vehicle of {} (its vehicles: {})",
                f.path.display(),
                f.ids()
            ),
        )),
        (Some(_), Some(_)) => Ok(vehicle),
    }
}

/// The `[[controllers]]` of a campaign over `fleet`: each a vehicle of the fleet, a command, and
/// a sender id that vehicle lists as a participant (default: its one participant besides the
/// observer); no two with one sender id; and every participant the fleet file lists, besides
/// the observer, run by one of them (else every tick would wait for it).
fn read_controllers(
    root: &TableReader<'_, '_>,
    fleet: &FleetBase,
    source: &str,
    path: &Path,
) -> Result<Vec<Controller>, CampaignError> {
    let schema = |source: SchemaError| CampaignError::Schema {
        path: path.to_owned(),
        source,
    };
    let invalid = |field: &str, problem: String| invalid_at(source, path, field, problem);
    let tables = root
        .tables("controllers", &["vehicle", "sender_id", "command"])
        .map_err(schema)?
        .unwrap_or_default();
    let mut out: Vec<Controller> = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        let field = |k: &str| format!("controllers[{i}].{k}");
        let vehicle = t.string("vehicle").map_err(schema)?;
        let v = fleet.vehicle(&vehicle).ok_or_else(|| {
            invalid(
                &field("vehicle"),
                format!(
                    "{vehicle:?} is not a vehicle of {} (its vehicles: {})",
                    fleet.path.display(),
                    fleet.ids()
                ),
            )
        })?;
        let command = t.string("command").map_err(schema)?;
        let words = split_command(&command).map_err(|e| invalid(&field("command"), e))?;
        if words.is_empty() {
            return Err(invalid(&field("command"), "is empty".into()));
        }
        let sender_id = match t.get("sender_id") {
            Some(_) => t
                .int_in("sender_id", 0, i64::from(u32::MAX))
                .map_err(schema)? as u32,
            None => {
                let own: Vec<u32> = v
                    .participants
                    .iter()
                    .copied()
                    .filter(|p| *p != OBSERVER_ID)
                    .collect();
                match own.as_slice() {
                    [one] => *one,
                    _ => {
                        return Err(CampaignError::Invalid {
                            path: path.to_owned(),
                            field: field("sender_id"),
                            problem: format!(
                                "missing: vehicle {vehicle:?} lists {} participants {:?} in {} \
                                 (besides the observer, {OBSERVER_ID}): say which one this \
                                 controller answers as",
                                if own.is_empty() { "no" } else { "several" },
                                own,
                                fleet.path.display()
                            ),
                            at: SourceMap::locate(source, &field("vehicle")),
                        })
                    }
                }
            }
        };
        if sender_id == OBSERVER_ID {
            return Err(invalid(
                &field("sender_id"),
                format!(
                    "{OBSERVER_ID} is the campaign's observer (it answers every vehicle's ticks \
                     and records them): give the controller another sender id"
                ),
            ));
        }
        if !v.participants.contains(&sender_id) {
            return Err(invalid(
                &field("sender_id"),
                format!(
                    "{sender_id} is not a participant of vehicle {vehicle:?} in {} (its \
                     participants: {:?}): the server would refuse its commands",
                    fleet.path.display(),
                    v.participants
                ),
            ));
        }
        if let Some(j) = out.iter().position(|c| c.sender_id == sender_id) {
            return Err(invalid(
                &field("sender_id"),
                format!(
                    "sender {sender_id} is already controllers[{j}]'s: two processes cannot \
                     answer as one participant"
                ),
            ));
        }
        out.push(Controller {
            vehicle,
            sender_id,
            command,
        });
    }
    for (i, v) in fleet.vehicles.iter().enumerate() {
        if let Some(p) = v
            .participants
            .iter()
            .find(|p| **p != OBSERVER_ID && !out.iter().any(|c| c.sender_id == **p))
        {
            return Err(CampaignError::Invalid {
                path: path.to_owned(),
                field: "controllers".into(),
                problem: format!(
                    "vehicles[{i}] ({:?}) of {} lists participant {p}, and no [[controllers]] \
                     entry answers as sender {p}: every lockstep tick would wait for it",
                    v.id,
                    fleet.path.display()
                ),
                at: match SourceMap::locate(source, "controllers") {
                    At(None) => SourceMap::locate(source, "fleet"),
                    at => at,
                },
            });
        }
    }
    Ok(out)
}

/// The error of the fleet file `fleet` (text `text`) of the campaign `campaign`, with the
/// position of the field it names (`vehicles[1] ("deputy").relative.chief` is the TOML path
/// `vehicles[1].relative.chief`).
fn fleet_error(
    campaign: &Path,
    fleet: &Path,
    text: &str,
    e: flexdyn_vehicle::world::FleetError,
) -> CampaignError {
    let at = match &e {
        flexdyn_vehicle::world::FleetError::Field { field, .. } => {
            let toml_path = match (field.find(" (\""), field.find("\")")) {
                (Some(a), Some(b)) if b > a => format!("{}{}", &field[..a], &field[b + 2..]),
                _ => field.clone(),
            };
            SourceMap::locate(text, &toml_path)
        }
        _ => At(None),
    };
    CampaignError::Fleet {
        campaign: campaign.to_owned(),
        fleet: fleet.to_owned(),
        source: Box::new(e),
        at,
    }
}

/// `text` (a configuration) without its random faults (`[[faults]]` entries with `mtbf_s`), and
/// how many there were; unchanged when there were none.
fn remove_random_faults(text: &str) -> Result<(String, usize), String> {
    let mut base: toml::Table =
        toml::from_str(text).map_err(|e| format!("not a TOML table: {e}"))?;
    let mut removed = 0;
    if let Some(toml::Value::Array(items)) = base.get_mut("faults") {
        let before = items.len();
        items.retain(|f| f.get("mtbf_s").is_none());
        removed = before - items.len();
        if items.is_empty() {
            base.remove("faults");
        }
    }
    if removed == 0 {
        return Ok((text.to_owned(), 0));
    }
    let text = toml::to_string(&base).map_err(|e| format!("cannot write TOML: {e}"))?;
    Ok((text, removed))
}

/// `seconds` as a whole number of nanoseconds that a `u64` holds, or why not.
fn within_time(field: &str, seconds: f64) -> Result<u64, String> {
    if seconds <= 0.0 {
        return Err(format!("must be > 0, got {}", Num(seconds)));
    }
    if let Some(problem) = beyond_max_time(seconds) {
        return Err(problem);
    }
    whole_ns(seconds).ok_or_else(|| {
        format!(
            "{} s is not a whole number of nanoseconds ({field})",
            Num(seconds)
        )
    })
}

/// An error about `field` of the campaign file `path` (text `source`), with its position.
pub(crate) fn invalid_at(source: &str, path: &Path, field: &str, problem: String) -> CampaignError {
    CampaignError::Invalid {
        path: path.to_owned(),
        field: field.to_owned(),
        problem,
        at: SourceMap::locate(source, field),
    }
}
