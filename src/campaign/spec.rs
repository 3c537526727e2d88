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

use std::path::{Path, PathBuf};

use toml::de::DeTable;

use super::command::split_command;
use crate::config::{
    beyond_max_time, config_message, log_warnings, whole_ns, ConfigError, SimConfig, SourceMap,
    DEFAULT_CONFIG_TOML,
};
use crate::numfmt::Num;
use crate::schema::reader::TableReader;
use crate::schema::{location, At, SchemaError};

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
}

/// What a criterion measures at each state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// |σ_BR|, the attitude error to the campaign's `sigma_rn` (MRP, –).
    SigmaBr,
    /// |σ_BN| (–).
    SigmaBn,
    /// |ω_BN| (rad/s).
    Omega,
    /// The largest |θ1|, |θ2| over every panel pair (rad).
    Theta,
}

/// How a criterion reduces the quantity over time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Statistic {
    /// The value at the last state.
    Final,
    /// The maximum over the states at or after `after_s`.
    Max,
    /// The time (s) after which the quantity stays below `threshold` to the end; the run's
    /// duration + 1 frame if it never settles.
    SettlingTime {
        /// The settling band.
        threshold: f64,
    },
}

/// One `[[criteria]]` entry: passes when the statistic is below `below`.
#[derive(Clone, Debug, PartialEq)]
pub struct Criterion {
    /// Unique name (a column of `summary.csv`).
    pub name: String,
    /// The quantity.
    pub quantity: Quantity,
    /// The reduction.
    pub statistic: Statistic,
    /// \[s\] the window starts here (for `max`; default 0).
    pub after_s: f64,
    /// Pass if the statistic is strictly below this.
    pub below: f64,
}

impl Criterion {
    /// The unit of the criterion's value (its figures' axis): seconds for a settling time,
    /// else the quantity's (`–` for an MRP norm).
    pub fn unit(&self) -> &'static str {
        match (self.statistic, self.quantity) {
            (Statistic::SettlingTime { .. }, _) => "s",
            (_, Quantity::Omega) => "rad/s",
            (_, Quantity::Theta) => "rad",
            (_, Quantity::SigmaBr | Quantity::SigmaBn) => "–",
        }
    }
}

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
}

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
    "runs",
    "seed",
    "duration_s",
    "controller",
    "sigma_rn",
    "max_redraws",
    "participant_timeout_s",
    "dispersions",
    "criteria",
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
        let mut base: toml::Table = toml::from_str(&self.base_toml)
            .map_err(|e| self.invalid("base", format!("not a TOML table: {e}")))?;
        let mut removed = 0;
        if let Some(toml::Value::Array(items)) = base.get_mut("faults") {
            let before = items.len();
            items.retain(|f| f.get("mtbf_s").is_none());
            removed = before - items.len();
            if items.is_empty() {
                base.remove("faults");
            }
        }
        if removed > 0 {
            self.base_toml = toml::to_string(&base)
                .map_err(|e| self.invalid("base", format!("cannot write TOML: {e}")))?;
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
        let base_path = match root.get("base") {
            Some(_) => {
                let rel = PathBuf::from(root.string("base").map_err(schema)?);
                Some(if rel.is_absolute() {
                    rel
                } else {
                    path.parent().unwrap_or(Path::new(".")).join(rel)
                })
            }
            None => None,
        };
        let base_toml = match &base_path {
            Some(p) => std::fs::read_to_string(p)
                .map_err(|e| invalid("base", format!("cannot read {}: {e}", p.display())))?,
            None => DEFAULT_CONFIG_TOML.to_owned(),
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
        let runs = root.int_in("runs", 1, 1_000_000).map_err(schema)? as u32;
        let seed = root.int_in("seed", 0, i64::MAX).map_err(schema)? as u64;
        let duration_s = root.f64("duration_s").map_err(schema)?;
        let duration_ns =
            within_time("duration_s", duration_s).map_err(|p| invalid("duration_s", p))?;
        if duration_ns % base.frame_ns != 0 {
            return Err(invalid(
                "duration_s",
                format!(
                    "{} s is not a whole number of frames (frame = {} s at {} Hz)",
                    Num(duration_s),
                    Num(base.frame_ns as f64 / 1e9),
                    Num(base.frame_hz)
                ),
            ));
        }
        let controller = match root.get("controller") {
            Some(_) => Some(root.string("controller").map_err(schema)?),
            None => None,
        };
        if let Some(c) = &controller {
            let words = split_command(c).map_err(|e| invalid("controller", e))?;
            if words.is_empty() {
                return Err(invalid("controller", "is empty".into()));
            }
        }
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

        let mut dispersions = Vec::new();
        let tables = root
            .tables(
                "dispersions",
                &["key", "distribution", "mean", "sigma", "low", "high"],
            )
            .map_err(schema)?
            .unwrap_or_default();
        for (i, t) in tables.iter().enumerate() {
            let field = |k: &str| format!("dispersions[{i}].{k}");
            let key = t.string("key").map_err(schema)?;
            super::keys::parse(&key).map_err(|e| invalid(&field("key"), e))?;
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
            dispersions.push(Dispersion { key, distribution });
        }

        let mut criteria: Vec<Criterion> = Vec::new();
        let tables = root
            .tables(
                "criteria",
                &[
                    "name",
                    "quantity",
                    "statistic",
                    "after_s",
                    "below",
                    "threshold",
                ],
            )
            .map_err(schema)?
            .unwrap_or_default();
        for (i, t) in tables.iter().enumerate() {
            let field = |k: &str| format!("criteria[{i}].{k}");
            let name = t.string("name").map_err(schema)?;
            if name.is_empty() || name.contains([',', '"', '\n']) {
                return Err(invalid(
                    &field("name"),
                    "must be non-empty, without commas, quotes or newlines".into(),
                ));
            }
            if criteria.iter().any(|c| c.name == name) {
                return Err(invalid(&field("name"), format!("{name:?} is used twice")));
            }
            let quantity = match t.string("quantity").map_err(schema)?.as_str() {
                "sigma_br" => Quantity::SigmaBr,
                "sigma_bn" => Quantity::SigmaBn,
                "omega" => Quantity::Omega,
                "theta" => Quantity::Theta,
                other => {
                    return Err(invalid(
                        &field("quantity"),
                        format!(
                        "{other:?} is not one of \"sigma_br\", \"sigma_bn\", \"omega\", \"theta\""
                    ),
                    ))
                }
            };
            let stat = t.string("statistic").map_err(schema)?;
            let threshold = t.opt_f64("threshold").map_err(schema)?;
            let statistic = match (stat.as_str(), threshold) {
                ("final", None) => Statistic::Final,
                ("max", None) => Statistic::Max,
                ("settling_time", Some(threshold)) if threshold > 0.0 => {
                    Statistic::SettlingTime { threshold }
                }
                ("settling_time", _) => {
                    return Err(invalid(
                        &field("threshold"),
                        "settling_time needs a threshold > 0".into(),
                    ))
                }
                ("final" | "max", Some(_)) => {
                    return Err(invalid(
                        &field("threshold"),
                        format!("does not apply to statistic {stat:?}"),
                    ))
                }
                (other, _) => {
                    return Err(invalid(
                        &field("statistic"),
                        format!("{other:?} is not one of \"final\", \"max\", \"settling_time\""),
                    ))
                }
            };
            let after_s = t.opt_f64("after_s").map_err(schema)?;
            if after_s.is_some() && statistic != Statistic::Max {
                // Only `max` has a window; elsewhere the key would be silently ignored.
                return Err(invalid(
                    &field("after_s"),
                    format!("does not apply to statistic {stat:?} (only \"max\" has a window)"),
                ));
            }
            let after_s = after_s.unwrap_or(0.0);
            if !(0.0..=duration_s).contains(&after_s) {
                return Err(invalid(
                    &field("after_s"),
                    format!(
                        "must be within 0..=duration_s ({}), got {}",
                        Num(duration_s),
                        Num(after_s)
                    ),
                ));
            }
            let below = t.f64("below").map_err(schema)?;
            if below <= 0.0 {
                // Every quantity is a magnitude or a time (≥ 0), and a criterion passes when
                // its statistic is strictly below `below`.
                return Err(invalid(
                    &field("below"),
                    format!(
                        "must be > 0, got {}: every quantity is ≥ 0, so the criterion could never \
                         pass",
                        Num(below)
                    ),
                ));
            }
            criteria.push(Criterion {
                name,
                quantity,
                statistic,
                after_s,
                below,
            });
        }
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
        })
    }
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
fn invalid_at(source: &str, path: &Path, field: &str, problem: String) -> CampaignError {
    CampaignError::Invalid {
        path: path.to_owned(),
        field: field.to_owned(),
        problem,
        at: SourceMap::locate(source, field),
    }
}
