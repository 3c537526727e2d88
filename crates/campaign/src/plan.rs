//! `flexdyn campaign plan`: every run's dispersed configuration, drawn from the master seed,
//! and a manifest, with nothing launched.
//!
//! # Seeds
//! Run `i` draws from the portable generator ([`flexdyn_sensors::rng::NormalRng`]) seeded with
//! `run_seed(i) = splitmix64(master_seed ⊕ splitmix64(i))`. Each sensor's `seed` key
//! (`<config array>[k].seed` of every sensor kind in [`flexdyn_sensors::KINDS`]: `imus[k].seed`,
//! `star_trackers[k].seed`), and `faults[k].seed` of every random fault (one with `mtbf_s`,
//! written in if absent), becomes `splitmix64(run_seed ⊕ fnv1a(key))`. A run
//! therefore depends only on the campaign file and its index: `--index I` reproduces it alone.
//! Over a fleet, the hashed key starts with the vehicle's id (`deputy.imus[0].seed`), so every
//! vehicle's sensors and random faults get seeds of their own, in every run.
//!
//! # Fleets
//! With `fleet` in place of `base`, each vehicle's document ([`super::fleet`]: its spacecraft
//! configuration plus a deputy's `relative` Hill offsets) is dispersed by the entries that
//! name it, from the one stream of the run, in file order. Keys in the manifest, the results
//! and `summary.csv` start with the vehicle's id (`deputy.hub.mass_kg`). A draw is valid when
//! the whole fleet is ([`super::fleet::from_run`]: the fleet file's rules, and every vehicle's
//! spacecraft builds). A run writes `fleet.toml` and `config-<id>.toml` per vehicle.
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
//! parameters; see [`readback`]; over a fleet, a deputy's Hill offsets, see
//! [`super::readback::fleet_readback`]). Any other key is an error at load time, so a
//! dispersion can never be silently ignored; `result.json` then holds the values read back from
//! each run's built model, not from its file.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use toml::Table;

use super::fleet::{offsets_table, FleetBase};
use super::keys;
pub use super::readback::readback;
use super::readback::{fleet_readback, nearest_ns, FAULT_WINDOW_FIELDS};
use super::spec::{Campaign, CampaignError, Distribution};
use flexdyn_sensors::rng::NormalRng;
use flexdyn_vehicle::config::SimConfig;

/// SplitMix64's finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix.
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// FNV-1a, 64 bits (Fowler, Noll & Vo): the hash of a seed's key.
pub fn fnv1a(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The seed of run `run`.
pub fn run_seed(master: u64, run: u32) -> u64 {
    splitmix64(master ^ splitmix64(u64::from(run)))
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
    /// ([`flexdyn_faults::failure_delay_ns`]), whether or not it falls within the run.
    #[serde(default)]
    pub random_failures_ns: BTreeMap<String, u64>,
    /// The full configuration, TOML (not in the manifest; written as `config.toml`); over a
    /// fleet, the run's fleet file (written as `fleet.toml`).
    #[serde(skip)]
    pub config_toml: String,
    /// Over a fleet: each vehicle's id and resolved configuration (written as
    /// `config-<id>.toml`, which `config_toml` names). Empty for one spacecraft.
    #[serde(skip)]
    pub vehicle_configs: Vec<(String, String)>,
}

impl RunPlan {
    /// The fleet of a fleet run, as its folder reads ([`super::fleet::from_run`]).
    pub fn fleet(&self) -> Result<flexdyn_vehicle::world::FleetConfig, String> {
        super::fleet::from_run(&self.config_toml, &self.vehicle_configs)
    }
}

/// One configuration the dispersions write into: the base, or one vehicle of a fleet.
#[derive(Clone, Debug)]
struct Unit {
    /// The prefix of its keys in the manifest, the results and the seeds' hashed keys: empty
    /// for one spacecraft, `<id>.` for a vehicle.
    prefix: String,
    /// The document (a vehicle's: its configuration and, for a deputy, `relative`).
    base: Table,
    /// Its sensor and random-fault seed keys (`imus[0].seed`, `faults[1].seed`).
    seed_keys: Vec<String>,
    /// The indices of its random faults (`faults[k]` with `mtbf_s`).
    random_faults: Vec<usize>,
}

impl Unit {
    /// The unit of document `base`; `fork_at_s`: the time of the checkpoint every run starts
    /// from, if any.
    fn new(prefix: String, base: Table, fork_at_s: Option<f64>) -> Self {
        let mut seed_keys = Vec::new();
        // A forked run's sensors continue the checkpoint's generators (a seed would change
        // nothing): their seeds stay the checkpoint configuration's.
        for section in flexdyn_sensors::KINDS.iter().map(|k| k.config_array) {
            if let (Some(toml::Value::Array(items)), None) = (base.get(section), fork_at_s) {
                for (k, item) in items.iter().enumerate() {
                    if item.get("seed").is_some() {
                        seed_keys.push(format!("{section}[{k}].seed"));
                    }
                }
            }
        }
        // A random fault (`mtbf_s`) gets a seed of its own per run, written in if absent, so
        // every run samples its own failure time; in a forked campaign only one whose
        // `start_s` is after the checkpoint (its failure time is then after it too).
        let mut random_faults = Vec::new();
        if let Some(toml::Value::Array(items)) = base.get("faults") {
            for (k, item) in items.iter().enumerate() {
                if item.get("mtbf_s").is_some() {
                    let start_s = item
                        .get("start_s")
                        .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
                        .unwrap_or(0.0);
                    if fork_at_s.is_none_or(|t| start_s > t) {
                        seed_keys.push(format!("faults[{k}].seed"));
                    }
                    random_faults.push(k);
                }
            }
        }
        Self {
            prefix,
            base,
            seed_keys,
            random_faults,
        }
    }
}

/// A run's resolved configuration: its text(s) and its random faults' first activations.
struct Resolved {
    config_toml: String,
    vehicle_configs: Vec<(String, String)>,
    random_failures_ns: BTreeMap<String, u64>,
}

/// A campaign's plan: the resolved dispersion keys and every run.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The campaign.
    pub campaign: Campaign,
    /// For each dispersion, the concrete keys it names (over a fleet, `<vehicle>.<key>`).
    pub keys: Vec<Vec<String>>,
    units: Vec<Unit>,
    /// For each dispersion, its unit and its concrete keys in that unit's document.
    targets: Vec<(usize, Vec<String>)>,
}

impl Plan {
    /// Resolves every dispersion key against the base configuration (or each vehicle's) and
    /// its built model.
    pub fn new(campaign: Campaign) -> Result<Self, CampaignError> {
        let (units, base_cfg, model) = match &campaign.fleet {
            Some(fleet) => {
                let (units, model) = fleet_units(&campaign, fleet)?;
                (units, None, model)
            }
            None => {
                // Dispersion keys are the campaign file's fields; a bad base is the base file's.
                let mut base: Table = toml::from_str(&campaign.base_toml)
                    .map_err(|e| campaign.invalid("base", format!("not a TOML table: {e}")))?;
                let base_dir = campaign.base_dir();
                let cfg = SimConfig::from_toml_str_in(&campaign.base_toml, &base_dir)
                    .map_err(|e| campaign.base_error(e))?;
                // Each run's config.toml must stand alone (it is read from its own folder, by a
                // server started anywhere): a relative `orbit.elements_file` becomes the
                // elements themselves.
                inline_elements_file(&mut base, &base_dir)
                    .map_err(|e| campaign.invalid("base", e))?;
                let model = readback(&cfg).map_err(|e| campaign.base_error(e))?;
                if let Some(start) = &campaign.start_from {
                    // The server's own resume check, before any run starts.
                    flexdyn_server::checkpoint::check_fits(
                        &start.resumed(),
                        &super::execute::single_settings(&campaign),
                        &cfg,
                    )
                    .map_err(|e| {
                        campaign.invalid(
                            "start_from",
                            format!("{e} (the campaign's base and lockstep participants)"),
                        )
                    })?;
                    for (i, k) in campaign.criteria.iter().enumerate() {
                        super::fork::check_criterion(k, &cfg, start)
                            .map_err(|e| campaign.invalid(&format!("criteria[{i}].fault"), e))?;
                    }
                }
                let fork_at_s = campaign.start_from.as_ref().map(|s| s.t_s());
                (
                    vec![Unit::new(String::new(), base, fork_at_s)],
                    Some(cfg),
                    model,
                )
            }
        };
        let mut all_keys: Vec<Vec<String>> = Vec::new();
        let mut targets = Vec::new();
        for (i, d) in campaign.dispersions.iter().enumerate() {
            let field = format!("dispersions[{i}].key");
            let u = match &d.vehicle {
                Some(id) => units
                    .iter()
                    .position(|u| u.prefix == format!("{id}."))
                    .ok_or_else(|| campaign.invalid(&field, format!("no vehicle {id:?}")))?,
                None => 0,
            };
            // Over a fleet, the problem names the vehicle whose configuration the key is in.
            let whose = d
                .vehicle
                .as_ref()
                .map_or(String::new(), |id| format!("vehicle {id:?}: "));
            if let (Some(id), Some(fleet)) = (&d.vehicle, &campaign.fleet) {
                check_fleet_key(fleet, id, &d.key)
                    .map_err(|e| campaign.invalid(&field, format!("{whose}{:?}: {e}", d.key)))?;
            }
            let local = keys::expand(&units[u].base, &d.key)
                .map_err(|e| campaign.invalid(&field, format!("{whose}{:?}: {e}", d.key)))?;
            let prefix = &units[u].prefix;
            let concrete: Vec<String> = local.iter().map(|k| format!("{prefix}{k}")).collect();
            for k in &concrete {
                if !model.contains_key(k) {
                    return Err(campaign.invalid(
                        &field,
                        format!(
                            "{whose}{k} is not a parameter the built model reports (the hub, \
                             initial state, panel pairs, reaction wheels, facets, residual \
                             dipole, every sensor's error terms, space weather and epoch \
                             offset are; `flexdyn campaign plan` lists them), so its dispersion \
                             could not be verified; it is refused rather than risk a silent \
                             no-op"
                        ),
                    ));
                }
            }
            if let (Some(start), Some(cfg)) = (&campaign.start_from, &base_cfg) {
                for k in &concrete {
                    super::fork::check_key(k, cfg, start)
                        .and_then(|()| super::fork::check_draws(k, &d.distribution, start))
                        .map_err(|e| campaign.invalid(&field, e))?;
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
            targets.push((u, local));
        }
        Ok(Self {
            campaign,
            keys: all_keys,
            units,
            targets,
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
            let mut docs: Vec<Table> = self.units.iter().map(|u| u.base.clone()).collect();
            let mut dispersed = BTreeMap::new();
            for (d, (u, concrete)) in c.dispersions.iter().zip(&self.targets) {
                let (base, prefix) = (&self.units[*u].base, &self.units[*u].prefix);
                let doc = &mut docs[*u];
                let mut put = |k: &String, x: f64| {
                    let x = whole_ns_if_time(k, x);
                    keys::set(&mut *doc, k, x);
                    dispersed.insert(format!("{prefix}{k}"), x);
                };
                match &d.distribution {
                    Distribution::Normal { mean, sigma } => {
                        for k in concrete {
                            let m = mean.unwrap_or_else(|| keys::get(base, k).unwrap_or(0.0));
                            put(k, m + sigma * rng.normal());
                        }
                    }
                    Distribution::Uniform { low, high } => {
                        for k in concrete {
                            put(k, low + (high - low) * rng.uniform01());
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
                            put(k, q[i + 1] * s / (1.0 + b0));
                        }
                    }
                }
            }
            sensor_seeds.clear();
            for (unit, doc) in self.units.iter().zip(docs.iter_mut()) {
                for k in &unit.seed_keys {
                    let name = format!("{}{k}", unit.prefix);
                    let s = splitmix64(seed ^ fnv1a(&name)) >> 1; // TOML integers are signed
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
                    sensor_seeds.insert(name, s);
                }
            }
            match self.resolve(&docs) {
                Ok(r) => {
                    return RunPlan {
                        random_failures_ns: r.random_failures_ns,
                        run,
                        dir: run_dir(run),
                        run_seed: seed,
                        sensor_seeds,
                        redraws: attempt,
                        redraw_reasons: reasons,
                        valid: true,
                        dispersed,
                        config_toml: r.config_toml,
                        vehicle_configs: r.vehicle_configs,
                    };
                }
                Err(e) => reasons.push(e),
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
            vehicle_configs: Vec::new(),
        }
    }

    /// The run's configuration from its dispersed documents, if it is valid (else why not).
    fn resolve(&self, docs: &[Table]) -> Result<Resolved, String> {
        let failures = |prefix: &str, unit: &Unit, cfg: &SimConfig| {
            unit.random_faults
                .iter()
                .filter_map(|&k| {
                    let f = cfg.faults.get(k)?;
                    Some((format!("{prefix}faults[{k}]"), f.window.start_ns))
                })
                .collect::<Vec<_>>()
        };
        let Some(fleet) = &self.campaign.fleet else {
            let text = toml::to_string(&docs[0]).map_err(|e| format!("cannot write TOML: {e}"))?;
            let cfg = SimConfig::from_toml_str(&text)
                .and_then(|cfg| cfg.build_spacecraft().map(|_| cfg))
                .map_err(|e| e.to_string())?;
            return Ok(Resolved {
                random_failures_ns: failures("", &self.units[0], &cfg).into_iter().collect(),
                config_toml: text,
                vehicle_configs: Vec::new(),
            });
        };
        let (config_toml, vehicle_configs) = super::fleet::run_files(fleet, docs)?;
        let built = super::fleet::from_run(&config_toml, &vehicle_configs)?;
        let random_failures_ns = self
            .units
            .iter()
            .zip(&built.vehicles)
            .flat_map(|(u, v)| failures(&u.prefix, u, &v.cfg))
            .collect();
        Ok(Resolved {
            config_toml,
            vehicle_configs,
            random_failures_ns,
        })
    }

    /// The manifest (JSON) of `runs`.
    pub fn manifest(&self, runs: &[RunPlan]) -> serde_json::Value {
        let c = &self.campaign;
        let sha = super::execute::hex(&Sha256::digest(c.source.as_bytes()));
        let mut m = serde_json::json!({
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
        });
        if let (Some(start), Some(obj)) = (&c.start_from, m.as_object_mut()) {
            // Every run is a fork of the checkpoint's run at its tick.
            obj.insert("start_from".into(), start.manifest());
        }
        if let (Some(fleet), Some(obj)) = (&c.fleet, m.as_object_mut()) {
            // Over a fleet: the fleet file instead of a base, a controller per vehicle, and the
            // vehicles (their order is summary.csv's hash columns').
            obj.remove("base");
            obj.remove("controller");
            obj.insert("fleet".into(), fleet.path.display().to_string().into());
            obj.insert(
                "vehicles".into(),
                fleet.vehicles.iter().map(|v| v.id.clone()).collect(),
            );
            obj.insert(
                "controllers".into(),
                c.controllers
                    .iter()
                    .map(|k| {
                        serde_json::json!({
                            "vehicle": k.vehicle,
                            "sender_id": k.sender_id,
                            "command": k.command,
                        })
                    })
                    .collect(),
            );
            obj.insert(
                "criterion_vehicles".into(),
                c.criteria
                    .iter()
                    .map(|k| k.vehicle.clone().unwrap_or_default())
                    .collect(),
            );
        }
        m
    }

    /// Writes `DIR/campaign.toml`, `DIR/manifest.json` and `DIR/run-NNNN/config.toml` for every
    /// run (over a fleet, `DIR/run-NNNN/fleet.toml` and `config-<id>.toml` per vehicle);
    /// returns the plans.
    pub fn write(&self, dir: &Path) -> Result<Vec<RunPlan>, std::io::Error> {
        let runs: Vec<RunPlan> = (0..self.campaign.runs).map(|r| self.run(r)).collect();
        std::fs::create_dir_all(dir)?;
        write_settled(&dir.join("campaign.toml"), self.campaign.source.as_bytes())?;
        for r in &runs {
            let d = dir.join(&r.dir);
            std::fs::create_dir_all(&d)?;
            if !r.valid {
                continue;
            }
            if self.campaign.fleet.is_some() {
                write_settled(&d.join("fleet.toml"), r.config_toml.as_bytes())?;
                for (id, text) in &r.vehicle_configs {
                    write_settled(&d.join(super::fleet::vehicle_file(id)), text.as_bytes())?;
                }
            } else {
                write_settled(&d.join("config.toml"), r.config_toml.as_bytes())?;
            }
        }
        let text =
            serde_json::to_string_pretty(&self.manifest(&runs)).map_err(std::io::Error::other)?;
        write_settled(&dir.join("manifest.json"), (text + "\n").as_bytes())?;
        Ok(runs)
    }
}

/// Writes `bytes` to `path` unless the file already holds exactly them, through a temporary
/// file renamed over it. Every `campaign run --index` of a fanned-out campaign writes the same
/// plan into the shared directory while other runs read it: an unchanged file is left alone,
/// and a changed one is never seen half written.
fn write_settled(path: &Path, bytes: &[u8]) -> Result<(), std::io::Error> {
    if std::fs::read(path).is_ok_and(|old| old == bytes) {
        return Ok(());
    }
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp-{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

/// The units of a campaign over `fleet` (each vehicle's document: its configuration with its
/// elements file inlined, and a deputy's `relative` offsets) and the base fleet's read-back.
fn fleet_units(
    campaign: &Campaign,
    fleet: &FleetBase,
) -> Result<(Vec<Unit>, BTreeMap<String, f64>), CampaignError> {
    let mut units = Vec::with_capacity(fleet.vehicles.len());
    for v in &fleet.vehicles {
        let bad = |e: String| campaign.invalid("fleet", format!("vehicle {:?}: {e}", v.id));
        let mut doc: Table =
            toml::from_str(&v.base_toml).map_err(|e| bad(format!("not a TOML table: {e}")))?;
        inline_elements_file(&mut doc, &v.base_dir).map_err(bad)?;
        if v.chief.is_some() {
            doc.insert(
                "relative".into(),
                toml::Value::Table(offsets_table(&v.offsets)),
            );
        }
        units.push(Unit::new(format!("{}.", v.id), doc, None));
    }
    // The base fleet as a run would build it, read back.
    let docs: Vec<Table> = units.iter().map(|u| u.base.clone()).collect();
    let model = super::fleet::run_files(fleet, &docs)
        .and_then(|(text, configs)| super::fleet::from_run(&text, &configs))
        .and_then(|built| fleet_readback(&built))
        .map_err(|e| campaign.invalid("fleet", e))?;
    Ok((units, model))
}

/// What a dispersion key of vehicle `id` may not name: `relative.…` of a vehicle without a
/// chief, and the initial position or velocity of one with a chief (its `relative` offsets
/// replace them, so a dispersion of either would not reach the model).
fn check_fleet_key(fleet: &FleetBase, id: &str, key: &str) -> Result<(), String> {
    let Some(v) = fleet.vehicle(id) else {
        return Ok(());
    };
    match &v.chief {
        None if key.starts_with("relative") => Err(format!(
            "vehicle {id:?} has no [vehicles.relative] in {}: only a deputy's Hill offsets \
             (relative.hill_position_m, relative.hill_velocity_m_s) can be dispersed",
            fleet.path.display()
        )),
        Some(chief)
            if key.starts_with("initial.r_bn_n_m") || key.starts_with("initial.v_bn_n_m_s") =>
        {
            Err(format!(
                "vehicle {id:?} starts at an offset from {chief:?} ([vehicles.relative]), which \
                 replaces its own position and velocity: disperse relative.hill_position_m or \
                 relative.hill_velocity_m_s instead"
            ))
        }
        _ => Ok(()),
    }
}

/// `x` drawn for key `k`, rounded to a whole nanosecond if `k` is a fault's window time
/// ([`FAULT_WINDOW_FIELDS`]), which the configuration takes only in whole nanoseconds (a value
/// that is not a time is left for the configuration to refuse).
fn whole_ns_if_time(k: &str, x: f64) -> f64 {
    let time = k.starts_with("faults[")
        && FAULT_WINDOW_FIELDS
            .iter()
            .any(|f| k.strip_suffix(f).is_some_and(|h| h.ends_with('.')));
    match nearest_ns(x) {
        Some(ns) if time => ns as f64 * 1e-9,
        _ => x,
    }
}

/// `run-0042`.
pub fn run_dir(run: u32) -> String {
    format!("run-{run:04}")
}
