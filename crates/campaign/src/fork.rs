//! A campaign that starts every run from one checkpoint (`start_from = "detumbled.ckpt"`): each
//! run is a fork of the run the checkpoint was taken from, resumed at its tick K, so a thousand
//! "what next" runs do not each fly the first K ticks again (docs/guides/campaigns.md, "Start
//! every run from a checkpoint").
//!
//! - The checkpoint is read and checked when the campaign is loaded ([`StartFrom::read`]): a
//!   missing, damaged or foreign file is refused, naming the file and the reason, before any
//!   run starts. It must be a checkpoint of the campaign's own lockstep server (front end `run`,
//!   spacecraft `sc1`, the campaign's participants): `flexdyn campaign checkpoint` writes one.
//! - The runs' base configuration is the one the checkpoint recorded (a `base` given beside
//!   `start_from` must be that file's text).
//! - Whether the base fits the checkpoint (the same vehicle, effectors, sensors, faults and
//!   participants, step and frame) is the server's own resume check
//!   ([`flexdyn_server::checkpoint::check_fits`]), asked once at plan time and again by every
//!   run's server.
//! - A dispersion may only change what acts after the checkpoint ([`check_key`]): the window of
//!   a configured fault that opens after it. Anything that acted before K (the initial state, a
//!   mass, a sensor's noise) is already fixed by the checkpoint's state, and a run that changed
//!   it would not be the flight the checkpoint continues: it is refused with the reason.
//! - A flight-code latency from a fault (`fsw_event_latency`) must name a fault that opens after
//!   the checkpoint ([`check_criterion`]): no fork observes one that struck before it.
//! - What every run observes, hashes and judges starts at tick K ([`StartFrom::tick`]); each
//!   result records the SHA-256 of the checkpoint it read (`start_from_sha256`).

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::execute::hex;
use super::readback::{nearest_ns, FAULT_WINDOW_FIELDS};
use super::spec::CampaignError;
use flexdyn_kernel::numfmt::Num;
use flexdyn_server::checkpoint::{Resumed, FRONT_END};
use flexdyn_vehicle::checkpoint::Source;
use flexdyn_vehicle::config::SimConfig;

/// `start_from`: the checkpoint every run of a campaign starts from.
#[derive(Clone, Debug)]
pub struct StartFrom {
    /// The checkpoint file, as resolved against the campaign file.
    pub path: PathBuf,
    /// Its bytes (checked: magic, format version, length, checksum, front end `run`).
    pub bytes: Vec<u8>,
    /// SHA-256 of the file, hex.
    pub sha256: String,
    /// The frame boundary it was taken at (> 0): every run's first observed tick.
    pub tick: u64,
    /// \[ns\] the simulation time at that tick.
    pub t_sim_ns: u64,
    /// The configuration it recorded: the runs' base.
    pub source: Source,
    /// SHA-256 of that configuration's text, as the checkpoint holds it.
    pub source_sha256: [u8; 32],
}

impl StartFrom {
    /// Reads and checks checkpoint `path`; the error names the file and why it is refused.
    pub fn read(path: &Path) -> Result<Self, String> {
        let (resumed, header) =
            flexdyn_server::checkpoint::read(path, FRONT_END).map_err(|e| e.to_string())?;
        let sha256 = hex(&Sha256::digest(&resumed.bytes));
        Ok(Self {
            path: path.to_owned(),
            sha256,
            tick: header.tick,
            t_sim_ns: header.t_sim_ns,
            source: Source::recorded(&header),
            source_sha256: header.source_sha256,
            bytes: resumed.bytes,
        })
    }

    /// \[s\] the checkpoint's simulation time.
    pub fn t_s(&self) -> f64 {
        self.t_sim_ns as f64 * 1e-9
    }

    /// What a run's server resumes from.
    pub fn resumed(&self) -> Resumed {
        Resumed {
            file: self.path.clone(),
            bytes: self.bytes.clone(),
            tick: self.tick,
        }
    }

    /// The note on a criterion that reduces a run's series (`max`, `settling_time`, the flight
    /// code's times): what it saw.
    pub fn seen_from(&self) -> String {
        format!(
            "seen from tick {} (t = {} s), the checkpoint's; before it the run is the \
             checkpoint's flight, not observed",
            self.tick,
            Num(self.t_s())
        )
    }

    /// The manifest's record of the fork.
    pub fn manifest(&self) -> serde_json::Value {
        serde_json::json!({
            "file": self.path.display().to_string(),
            "sha256": self.sha256,
            "tick": self.tick,
            "t_s": self.t_s(),
            "configuration": self.source.file().map_or(
                "(embedded default)".to_owned(), |p| p.display().to_string()),
            "configuration_sha256": hex(&self.source_sha256),
        })
    }
}

/// The line `campaign run` and `summarize` print about the fork.
pub fn line(start: &StartFrom) -> String {
    line_of(
        &start.path.display().to_string(),
        &start.sha256,
        start.tick,
        start.t_s(),
    )
}

/// The fork's line from its parts (the manifest's `start_from`).
pub fn line_of(file: &str, sha256: &str, tick: u64, t_s: f64) -> String {
    format!(
        "forked: every run starts from checkpoint {file} (sha256 {sha256}) at tick {tick} (t = \
         {} s); hashes and criteria cover tick {tick} to the end",
        Num(t_s)
    )
}

/// The fault index and field of a concrete key `faults[k].<field>`, if it is one.
fn fault_field(key: &str) -> Option<(usize, &str)> {
    let (k, field) = key.strip_prefix("faults[")?.split_once("].")?;
    Some((k.parse().ok()?, field))
}

/// Whether the concrete dispersion key `key` of a campaign forked from `start` may be dispersed
/// over the base `cfg` (the checkpoint's configuration): only the window (`start_s`,
/// `duration_s`, `period_s`) of a configured fault whose window opens after the checkpoint.
/// Anything else acted on the flight before tick K, which the checkpoint has already fixed.
pub fn check_key(key: &str, cfg: &SimConfig, start: &StartFrom) -> Result<(), String> {
    let at = format!(
        "the checkpoint {} at tick {} (t = {} s)",
        start.path.display(),
        start.tick,
        Num(start.t_s())
    );
    let fields = FAULT_WINDOW_FIELDS.join(", ");
    let Some((k, field)) = fault_field(key) else {
        let what = if key.starts_with("initial.") {
            "is the state at t = 0"
        } else {
            "acts on the flight from t = 0"
        };
        return Err(format!(
            "{key} {what}; every run starts from {at}, whose state already holds its effect, so \
             a run with another value would not be the flight the checkpoint continues: only \
             what acts after the checkpoint can be dispersed (the window of a fault that opens \
             after it: faults[k].{fields})"
        ));
    };
    let Some(fault) = cfg.faults.get(k) else {
        return Err(format!("{key}: the base has no faults[{k}]"));
    };
    if !FAULT_WINDOW_FIELDS.contains(&field) {
        return Err(format!(
            "{key}: only a fault's window ({fields}) can be dispersed from {at}"
        ));
    }
    if fault.window.start_ns <= start.t_sim_ns {
        return Err(format!(
            "{key}: faults[{k}] opens at t = {} s, not after {at}: its activation before the \
             checkpoint is part of the checkpoint's state, so its window cannot change",
            Num(fault.window.start_ns as f64 * 1e-9)
        ));
    }
    Ok(())
}

/// Whether criterion `c` of a campaign forked from `start` over the base `cfg` can be judged:
/// a flight code's latency after a fault (`fsw_event_latency`) needs the fault to open after
/// the checkpoint. One that opens at or before it struck in the checkpoint's flight, before
/// the flight code of a fork started: no fork would measure a latency, and every one would
/// pass it as "did not activate within the run".
pub fn check_criterion(
    c: &super::criteria::Criterion,
    cfg: &SimConfig,
    start: &StartFrom,
) -> Result<(), String> {
    let Some(super::criteria::FswRef {
        target: super::criteria::FswTarget::Event { fault: Some(k), .. },
        ..
    }) = &c.fsw
    else {
        return Ok(());
    };
    let Some(fault) = cfg.faults.get(*k) else {
        return Ok(());
    };
    if fault.window.start_ns <= start.t_sim_ns {
        return Err(format!(
            "{}: faults[{k}] opens at t = {} s, not after the checkpoint {} at tick {} (t = {} \
             s): it struck in the checkpoint's flight, before each run's flight code started, so \
             no run could measure a latency after it and every run would pass the criterion \
             without one; name a fault that opens after the checkpoint",
            c.name,
            Num(fault.window.start_ns as f64 * 1e-9),
            start.path.display(),
            start.tick,
            Num(start.t_s())
        ));
    }
    Ok(())
}

/// Whether a draw of `distribution` for the key `key` (already [`check_key`]ed) always falls
/// after the checkpoint: a fault's `start_s` must be drawn after it, so only a uniform
/// distribution whose `low` is after it is accepted (a normal one can draw any time).
pub fn check_draws(
    key: &str,
    distribution: &super::spec::Distribution,
    start: &StartFrom,
) -> Result<(), String> {
    use super::spec::Distribution;
    if fault_field(key).map(|(_, f)| f) != Some("start_s") {
        return Ok(());
    }
    let t_k = Num(start.t_s());
    let ckpt = start.path.display();
    match distribution {
        // A draw is rounded to the nanosecond: `low` must be after the checkpoint once rounded.
        Distribution::Uniform { low, .. }
            if nearest_ns(*low).is_some_and(|l| l > start.t_sim_ns) =>
        {
            Ok(())
        }
        Distribution::Uniform { low, .. } => Err(format!(
            "{key}: low = {} s can draw a start at or before the checkpoint {ckpt} (t = {t_k} \
             s): the fault would have struck in the flight the checkpoint already holds; give \
             low > {t_k}",
            Num(*low),
        )),
        Distribution::Normal { .. } => Err(format!(
            "{key}: a normal distribution can draw a start at or before the checkpoint {ckpt} \
             (t = {t_k} s); use distribution = \"uniform\" with low > {t_k}"
        )),
        Distribution::UniformAttitude => Err(format!(
            "{key}: uniform_attitude draws an orientation, not a time; a start after the \
             checkpoint {ckpt} (t = {t_k} s) is drawn from distribution = \"uniform\" with \
             low > {t_k}"
        )),
    }
}

/// Why a campaign over a fleet has no fork (`start_from`), nor a checkpoint to fork from.
pub const NO_FLEET_YET: &str = "a campaign over a fleet cannot start from a checkpoint yet";

/// What `flexdyn campaign checkpoint --at-s` flies for campaign `c`: its base configuration
/// and the frame boundary, a whole number of frames after t = 0 and before the end of the runs.
/// Refused (invalid input): a campaign over a fleet, one that already starts from a checkpoint,
/// and a time that is not such a boundary.
pub fn checkpoint_at(
    c: &super::spec::Campaign,
    at_s: f64,
) -> Result<(SimConfig, u64), CampaignError> {
    if c.fleet.is_some() {
        return Err(c.invalid("fleet", NO_FLEET_YET.into()));
    }
    if c.start_from.is_some() {
        return Err(c.invalid(
            "start_from",
            "this campaign already starts from a checkpoint: take the checkpoint with the \
             campaign that flies from t = 0"
                .into(),
        ));
    }
    let bad = |problem: String| CampaignError::Invalid {
        path: c.path.clone(),
        field: "--at-s".into(),
        problem,
        at: flexdyn_kernel::schema::At(None),
    };
    let cfg =
        SimConfig::from_toml_str_in(&c.base_toml, &c.base_dir()).map_err(|e| c.base_error(e))?;
    let t_ns = flexdyn_vehicle::config::whole_ns(at_s).ok_or_else(|| {
        bad(format!(
            "{} s is not a whole number of nanoseconds",
            Num(at_s)
        ))
    })?;
    if t_ns == 0 || t_ns % cfg.frame_ns != 0 || t_ns >= c.duration_ns {
        return Err(bad(format!(
            "{} s must be a whole number of frames (frame = {} s), after t = 0 and before the \
             end of the runs (duration_s = {} s)",
            Num(at_s),
            Num(cfg.frame_ns as f64 * 1e-9),
            Num(c.duration_s)
        )));
    }
    let tick = t_ns / cfg.frame_ns;
    Ok((cfg, tick))
}
