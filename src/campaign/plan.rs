//! `flexdyn campaign plan`: every run's dispersed configuration, drawn from the master seed,
//! and a manifest, with nothing launched.
//!
//! # Seeds
//! Run `i` draws from the portable generator ([`crate::sensors::rng::NormalRng`]) seeded with
//! `run_seed(i) = splitmix64(master_seed ⊕ splitmix64(i))`. Each sensor's `seed` key
//! (`<config array>[k].seed` of every sensor kind in [`crate::sensors::KINDS`]: `imus[k].seed`,
//! `star_trackers[k].seed`), and `faults[k].seed` of every random fault (one with `mtbf_s`,
//! written in if absent), becomes `splitmix64(run_seed ⊕ fnv1a(key))`. A run
//! therefore depends only on the campaign file and its index: `--index I` reproduces it alone.
//!
//! # Invalid draws
//! A draw whose configuration fails validation (for example an inertia that breaks the
//! triangle inequality, or a negative stiffness) is **redrawn** from the run's own stream, up
//! to `max_redraws` times; each rejection is recorded in the manifest with its reason. A run
//! that never validates is marked invalid: it is not executed and counts as failed.
//!
//! # Read-back
//! A dispersion key must name parameters the built model reports (hub, initial state, panel
//! pairs, reaction wheels, magnetorquers, thrusters, environment facets, residual dipole, space
//! weather, epoch offset, and the magnetometers', sun sensors' and star trackers' error
//! parameters; see [`readback`]). Any other key is an error at load time, so a
//! dispersion can never be silently ignored; `result.json` then holds the values read back from
//! each run's built model, not from its file.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use toml::Table;

use super::keys;
use super::spec::{Campaign, CampaignError, Distribution};
use crate::config::SimConfig;
use crate::sensors::rng::NormalRng;

/// SplitMix64's finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix.
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn fnv1a(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The seed of run `run`.
pub fn run_seed(master: u64, run: u32) -> u64 {
    splitmix64(master ^ splitmix64(u64::from(run)))
}

/// Every numeric parameter of the model built from `cfg`, by configuration path: the hub, the
/// initial state (`initial.sigma_bn[i]`, `initial.omega_bn_b_rad_s[i]`, `initial.r_bn_n_m[i]`,
/// `initial.v_bn_n_m_s[i]`), each effector's [`crate::dynamics::StateEffector::parameters`]
/// under its kind's section (`panel_pairs[k].`, `reaction_wheels[k].`: [`crate::dynamics::kinds`]), each dynamic effector's
/// [`crate::dynamics::DynamicEffector::parameters`] (facets, residual dipole), the environment
/// models' (space weather) and the epoch's `epoch.offset_s`.
pub fn readback(cfg: &SimConfig) -> Result<BTreeMap<String, f64>, crate::config::ConfigError> {
    let sc = cfg.build_spacecraft()?;
    let mut out = BTreeMap::new();
    let hub = sc.hub();
    out.insert("hub.mass_kg".to_owned(), hub.mass_kg);
    for i in 0..3 {
        out.insert(format!("hub.r_bcb_b_m[{i}]"), hub.r_bcb_b_m[i]);
        for j in 0..3 {
            out.insert(
                format!("hub.inertia_bc_b_kg_m2[{i}][{j}]"),
                hub.inertia_bc_b_kg_m2[(i, j)],
            );
        }
    }
    let x = sc.state();
    for i in 0..3 {
        out.insert(format!("initial.sigma_bn[{i}]"), x.sigma_bn[i]);
        out.insert(format!("initial.omega_bn_b_rad_s[{i}]"), x.omega_bn_b[i]);
        out.insert(format!("initial.r_bn_n_m[{i}]"), x.r_bn_n[i]);
        out.insert(format!("initial.v_bn_n_m_s[{i}]"), x.v_bn_n[i]);
    }
    let mut per_kind: BTreeMap<&str, usize> = BTreeMap::new();
    let mut params = Vec::new();
    for (e, range) in sc.effectors().iter().zip(sc.effector_ranges()) {
        let section =
            crate::dynamics::kinds::by_name(e.kind().name).map_or(e.kind().name, |k| k.section);
        let k = per_kind.entry(section).or_insert(0);
        params.clear();
        e.parameters(&x.effectors[range.clone()], &mut params);
        for (key, v) in &params {
            out.insert(format!("{section}[{k}].{key}"), *v);
        }
        *k += 1;
    }
    // The sensors as built, each kind's entries counted in file order.
    let bank = crate::sensors::SensorBank::new(cfg, cfg.frame_ns as f64 * 1e-9, 0, x)?;
    let mut per_array: BTreeMap<&str, usize> = BTreeMap::new();
    for s in bank.sensors() {
        let section = s.kind().config_array;
        let k = per_array.entry(section).or_insert(0);
        params.clear();
        s.parameters(&mut params);
        for (key, v) in &params {
            out.insert(format!("{section}[{k}].{key}"), *v);
        }
        *k += 1;
    }
    let mut params = Vec::new();
    for d in sc.dynamic_effectors() {
        d.parameters(&mut params);
    }
    if let Some(epoch) = &cfg.epoch {
        params.push(("epoch.offset_s".to_owned(), epoch.offset_s()));
    }
    if let Some(env) = cfg.environment_model()? {
        env.parameters(&mut params);
    }
    out.extend(params);
    Ok(out)
}

/// Replaces `orbit.elements_file` (relative to `base_dir`) by `orbit.elements`, the file's text.
fn inline_elements_file(doc: &mut Table, base_dir: &Path) -> Result<(), String> {
    let Some(toml::Value::Table(orbit)) = doc.get_mut("orbit") else {
        return Ok(());
    };
    let Some(toml::Value::String(file)) = orbit.remove("elements_file") else {
        return Ok(());
    };
    let path = base_dir.join(&file);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("orbit.elements_file: cannot read {}: {e}", path.display()))?;
    orbit.insert("elements".into(), toml::Value::String(text));
    Ok(())
}

/// One planned run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunPlan {
    /// Index, 0-based.
    pub run: u32,
    /// Its directory name (`run-0042`).
    pub dir: String,
    /// The seed its dispersions were drawn with.
    pub run_seed: u64,
    /// The sensor seeds written into its configuration, by key.
    pub sensor_seeds: BTreeMap<String, u64>,
    /// Draws rejected before the accepted one.
    pub redraws: u32,
    /// Why each rejected draw was invalid.
    pub redraw_reasons: Vec<String>,
    /// Whether a valid draw was found.
    pub valid: bool,
    /// The values written into its configuration file, by concrete key.
    pub dispersed: BTreeMap<String, f64>,
    /// \[ns\] the first activation of each random fault (`faults[k]` with `mtbf_s`): its
    /// `start_s` plus the time to failure drawn from the run's seed
    /// ([`crate::faults::failure_delay_ns`]), whether or not it falls within the run.
    #[serde(default)]
    pub random_failures_ns: BTreeMap<String, u64>,
    /// The full configuration, TOML (not in the manifest; written as `config.toml`).
    #[serde(skip)]
    pub config_toml: String,
}

/// A campaign's plan: the resolved dispersion keys and every run.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The campaign.
    pub campaign: Campaign,
    /// For each dispersion, the concrete keys it names.
    pub keys: Vec<Vec<String>>,
    base: Table,
    sensor_seed_keys: Vec<String>,
    /// The indices of the random faults (`faults[k]` with `mtbf_s`).
    random_faults: Vec<usize>,
}

impl Plan {
    /// Resolves every dispersion key against the base configuration and its built model.
    pub fn new(campaign: Campaign) -> Result<Self, CampaignError> {
        // Dispersion keys are the campaign file's fields; a bad base is the base file's.
        let mut base: Table = toml::from_str(&campaign.base_toml)
            .map_err(|e| campaign.invalid("base", format!("not a TOML table: {e}")))?;
        let base_dir = campaign.base_dir();
        let cfg = SimConfig::from_toml_str_in(&campaign.base_toml, &base_dir)
            .map_err(|e| campaign.base_error(e))?;
        // Each run's config.toml must stand alone (it is read from its own folder, by a server
        // started anywhere): a relative `orbit.elements_file` becomes the elements themselves.
        inline_elements_file(&mut base, &base_dir).map_err(|e| campaign.invalid("base", e))?;
        let model = readback(&cfg).map_err(|e| campaign.base_error(e))?;
        let mut all_keys = Vec::new();
        for (i, d) in campaign.dispersions.iter().enumerate() {
            let field = format!("dispersions[{i}].key");
            let concrete = keys::expand(&base, &d.key)
                .map_err(|e| campaign.invalid(&field, format!("{:?}: {e}", d.key)))?;
            for k in &concrete {
                if !model.contains_key(k) {
                    return Err(campaign.invalid(
                        &field,
                        format!(
                            "{k} is not a parameter the built model reports (the hub, initial \
                             state, panel pairs, reaction wheels, facets, residual dipole, space \
                             weather and epoch offset are), so its dispersion \
                             could not be verified; it is refused rather than risk a silent \
                             no-op"
                        ),
                    ));
                }
            }
            if d.distribution == Distribution::UniformAttitude
                && (concrete.len() != 3 || !d.key.ends_with("sigma_bn"))
            {
                return Err(campaign.invalid(
                    &field,
                    format!(
                        "uniform_attitude needs an MRP set such as initial.sigma_bn, got {:?}",
                        d.key
                    ),
                ));
            }
            if let Some(prev) = all_keys.iter().flatten().find(|k| concrete.contains(*k)) {
                return Err(campaign.invalid(&field, format!("{prev} is dispersed twice")));
            }
            all_keys.push(concrete);
        }
        let mut sensor_seed_keys = Vec::new();
        for section in crate::sensors::KINDS.iter().map(|k| k.config_array) {
            if let Some(toml::Value::Array(items)) = base.get(section) {
                for (k, item) in items.iter().enumerate() {
                    if item.get("seed").is_some() {
                        sensor_seed_keys.push(format!("{section}[{k}].seed"));
                    }
                }
            }
        }
        // A random fault (`mtbf_s`) gets a seed of its own per run, written in if absent, so
        // every run samples its own failure time.
        let mut random_faults = Vec::new();
        if let Some(toml::Value::Array(items)) = base.get("faults") {
            for (k, item) in items.iter().enumerate() {
                if item.get("mtbf_s").is_some() {
                    sensor_seed_keys.push(format!("faults[{k}].seed"));
                    random_faults.push(k);
                }
            }
        }
        Ok(Self {
            campaign,
            keys: all_keys,
            base,
            sensor_seed_keys,
            random_faults,
        })
    }

    /// Draws run `run` (the same result whichever other runs are drawn).
    pub fn run(&self, run: u32) -> RunPlan {
        let c = &self.campaign;
        let seed = run_seed(c.seed, run);
        let mut rng = NormalRng::new(seed);
        let mut sensor_seeds = BTreeMap::new();
        let mut reasons = Vec::new();
        for attempt in 0..=c.max_redraws {
            let mut doc = self.base.clone();
            let mut dispersed = BTreeMap::new();
            for (d, concrete) in c.dispersions.iter().zip(&self.keys) {
                match &d.distribution {
                    Distribution::Normal { mean, sigma } => {
                        for k in concrete {
                            let m = mean.unwrap_or_else(|| keys::get(&self.base, k).unwrap_or(0.0));
                            let x = m + sigma * rng.normal();
                            keys::set(&mut doc, k, x);
                            dispersed.insert(k.clone(), x);
                        }
                    }
                    Distribution::Uniform { low, high } => {
                        for k in concrete {
                            let x = low + (high - low) * rng.uniform01();
                            keys::set(&mut doc, k, x);
                            dispersed.insert(k.clone(), x);
                        }
                    }
                    Distribution::UniformAttitude => {
                        // Four independent normals, normalised: uniform on S³ (Marsaglia 1972),
                        // i.e. a uniformly random rotation; the MRP set with |σ| ≤ 1 (β0 ≥ 0).
                        let mut q = [0.0f64; 4];
                        let mut n2 = 0.0;
                        while n2 < 1e-12 {
                            q = [rng.normal(), rng.normal(), rng.normal(), rng.normal()];
                            n2 = q.iter().map(|v| v * v).sum();
                        }
                        let n = n2.sqrt();
                        let s = if q[0] < 0.0 { -1.0 / n } else { 1.0 / n };
                        let b0 = q[0] * s;
                        for (i, k) in concrete.iter().enumerate() {
                            let x = q[i + 1] * s / (1.0 + b0);
                            keys::set(&mut doc, k, x);
                            dispersed.insert(k.clone(), x);
                        }
                    }
                }
            }
            sensor_seeds.clear();
            for k in &self.sensor_seed_keys {
                let s = splitmix64(seed ^ fnv1a(k)) >> 1; // TOML integers are signed
                let (section, rest) = k.split_once('[').unwrap_or((k, ""));
                let idx: usize = rest
                    .split(']')
                    .next()
                    .and_then(|i| i.parse().ok())
                    .unwrap_or(0);
                if let Some(toml::Value::Array(items)) = doc.get_mut(section) {
                    if let Some(toml::Value::Table(t)) = items.get_mut(idx) {
                        t.insert("seed".into(), toml::Value::Integer(s as i64));
                    }
                }
                sensor_seeds.insert(k.clone(), s);
            }
            let text = match toml::to_string(&doc) {
                Ok(t) => t,
                Err(e) => {
                    reasons.push(format!("cannot write TOML: {e}"));
                    continue;
                }
            };
            let check =
                SimConfig::from_toml_str(&text).and_then(|cfg| cfg.build_spacecraft().map(|_| cfg));
            match check {
                Ok(cfg) => {
                    let random_failures_ns = self
                        .random_faults
                        .iter()
                        .filter_map(|&k| {
                            let f = cfg.faults.get(k)?;
                            Some((format!("faults[{k}]"), f.window.start_ns))
                        })
                        .collect();
                    return RunPlan {
                        random_failures_ns,
                        run,
                        dir: run_dir(run),
                        run_seed: seed,
                        sensor_seeds,
                        redraws: attempt,
                        redraw_reasons: reasons,
                        valid: true,
                        dispersed,
                        config_toml: text,
                    };
                }
                Err(e) => reasons.push(e.to_string()),
            }
        }
        RunPlan {
            run,
            dir: run_dir(run),
            run_seed: seed,
            sensor_seeds,
            redraws: c.max_redraws + 1,
            redraw_reasons: reasons,
            valid: false,
            dispersed: BTreeMap::new(),
            random_failures_ns: BTreeMap::new(),
            config_toml: String::new(),
        }
    }

    /// The manifest (JSON) of `runs`.
    pub fn manifest(&self, runs: &[RunPlan]) -> serde_json::Value {
        let c = &self.campaign;
        let sha: String = Sha256::digest(c.source.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        serde_json::json!({
            "campaign_sha256": sha,
            "flexdyn_version": env!("CARGO_PKG_VERSION"),
            "base": c.base_path.as_ref().map_or("(embedded default)".to_owned(), |p| p.display().to_string()),
            "runs": c.runs,
            "seed": c.seed,
            "duration_s": c.duration_s,
            // false: `--without-random-faults` removed the base's random faults.
            "random_faults": !c.random_faults_removed,
            "controller": c.controller,
            "dispersed_keys": self.keys.iter().flatten().collect::<Vec<_>>(),
            "criteria": c.criteria.iter().map(|k| k.name.clone()).collect::<Vec<_>>(),
            // The figures' axes: each criterion's unit and pass threshold (value < below).
            "criterion_axes": c.criteria.iter().map(|k| serde_json::json!({
                "name": k.name,
                "unit": k.unit(),
                "below": k.below,
            })).collect::<Vec<_>>(),
            "run_plans": runs,
        })
    }

    /// Writes `DIR/campaign.toml`, `DIR/manifest.json` and `DIR/run-NNNN/config.toml` for every
    /// run; returns the plans.
    pub fn write(&self, dir: &Path) -> Result<Vec<RunPlan>, std::io::Error> {
        let runs: Vec<RunPlan> = (0..self.campaign.runs).map(|r| self.run(r)).collect();
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join("campaign.toml"), &self.campaign.source)?;
        for r in &runs {
            let d = dir.join(&r.dir);
            std::fs::create_dir_all(&d)?;
            if r.valid {
                std::fs::write(d.join("config.toml"), &r.config_toml)?;
            }
        }
        let text =
            serde_json::to_string_pretty(&self.manifest(&runs)).map_err(std::io::Error::other)?;
        std::fs::write(dir.join("manifest.json"), text + "\n")?;
        Ok(runs)
    }
}

/// `run-0042`.
pub fn run_dir(run: u32) -> String {
    format!("run-{run:04}")
}
