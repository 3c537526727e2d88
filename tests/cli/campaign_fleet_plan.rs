//! Campaign planning over a fleet, without a server (issue 22, "campaigns disperse per-vehicle
//! keys"). The fleet is two copies of `scenarios/imu_tactical.toml` (two IMUs each): the chief
//! by path, the deputy inline and 100 m behind it in the chief's Hill frame.
//!
//! - Dispersions on both vehicles, read back per vehicle from the built models (1000 draws),
//!   follow their distributions (the mean within 4 standard errors, the sample variance within
//!   4 of its standard errors, as `tests/cli/campaign_plan.rs`), equal what the plan wrote, and
//!   leave what they do not name at its nominal value, on the other vehicle too. A deputy's
//!   Hill offsets are read back by an independent path: the two built spacecraft's centres of
//!   mass, through `relative_state_hill`.
//! - Every vehicle's sensor seeds follow `splitmix64(run_seed ⊕ fnv1a("<id>.<key>"))`, reach its
//!   built IMUs, differ between vehicles and runs, and are the same when planned again.
//! - A run's folder stands alone: its `fleet.toml` read from disk builds the same models.
//! - Errors name the file, the field and its line: a vehicle missing with a fleet base, an
//!   unknown vehicle, a vehicle without a fleet base, `base` and `fleet` together, and more.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use flexdyn_campaign::plan::{fnv1a, splitmix64, Plan, RunPlan};
use flexdyn_campaign::readback::fleet_readback;
use flexdyn_campaign::spec::Campaign;
use flexdyn_sensors::imu::ImuConfig;
use flexdyn_vehicle::world::FleetConfig;

use crate::campaign_support;
use campaign_support::{check_normal, check_uniform};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A folder with `fleet.toml`: the chief by path, the deputy inline, 100 m behind the chief
/// (no `hill_velocity_m_s`: zeros).
fn fleet_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let imu = root().join("scenarios/imu_tactical.toml");
    let inline: toml::Table = std::fs::read_to_string(&imu).unwrap().parse().unwrap();
    let mut chief: toml::Table = "id = \"chief\"\nparticipants = [1]\n".parse().unwrap();
    chief.insert("spacecraft_file".into(), imu.display().to_string().into());
    let mut deputy: toml::Table = "id = \"deputy\"\nparticipants = [2]\n[relative]\n\
                                    chief = \"chief\"\nhill_position_m = [0.0, -100.0, 0.0]\n"
        .parse()
        .unwrap();
    deputy.insert("spacecraft".into(), toml::Value::Table(inline));
    let mut fleet = toml::Table::new();
    fleet.insert(
        "vehicles".into(),
        toml::Value::Array(vec![chief.into(), deputy.into()]),
    );
    std::fs::write(dir.join("fleet.toml"), toml::to_string(&fleet).unwrap()).unwrap();
    dir
}

const CONTROLLERS: &str = "
[[controllers]]
vehicle = \"chief\"
command = \"flexdyn-acs-demo --sc-id {sc_id} --sender-id {sender_id}\"
[[controllers]]
vehicle = \"deputy\"
command = \"flexdyn-formation-demo --sc-id {vehicle} --chief chief --sender-id {sender_id}\"
";

/// The campaign `text` as the file `dir/test-campaign.toml`, planned.
fn plan_in(dir: &Path, text: &str) -> Result<Plan, String> {
    let c =
        Campaign::from_str_at(text, &dir.join("test-campaign.toml")).map_err(|e| e.to_string())?;
    Plan::new(c).map_err(|e| e.to_string())
}

/// How far a read-back Hill offset may be from the one written: it goes to N (deputy =
/// chief's centre of mass + [NH] ρ, at |r| ≈ 1.0e7 m where one ulp is 1.9e-9 m), through the
/// deputy's point B and back to its centre of mass, then to H again: a few dozen roundings of
/// that size. 1e-6 m is 500 ulps, and six orders below the 2 m dispersion, so an offset that
/// did not reach the model fails. Velocities: ulps of |v| ≈ 6.4e3 m/s (9e-13 m/s) and ω_H·1e-6
/// m ≈ 6e-10 m/s: 1e-9 m/s.
fn tolerance(key: &str) -> f64 {
    if key.contains("relative.hill_position_m") {
        1e-6
    } else if key.contains("relative.hill_velocity_m_s") {
        1e-9
    } else {
        0.0
    }
}

/// The model of run `rp`, built as the run's folder builds it, read back per vehicle, after
/// checking that every dispersed value reached it.
fn read_back(rp: &RunPlan) -> BTreeMap<String, f64> {
    assert!(rp.valid, "run {}: {:?}", rp.run, rp.redraw_reasons);
    let model = fleet_readback(&rp.fleet().unwrap()).unwrap();
    for (key, written) in &rp.dispersed {
        let got = model[key];
        assert!(
            (got - written).abs() <= tolerance(key),
            "run {}: {key} read back {got}, but {written} was drawn",
            rp.run
        );
    }
    model
}

#[test]
fn dispersions_of_each_vehicle_reach_its_model_and_only_its_model() {
    let dir = fleet_dir("campaign_fleet_stats");
    let plan = plan_in(
        &dir,
        &format!(
            "fleet = \"fleet.toml\"\nruns = 1000\nseed = 7\nduration_s = 1.0\n{CONTROLLERS}
            [[dispersions]]
            vehicle = \"chief\"
            key = \"hub.inertia_bc_b_kg_m2[0][0]\"
            distribution = \"normal\"
            sigma = 45.0
            [[dispersions]]
            vehicle = \"deputy\"
            key = \"hub.mass_kg\"
            distribution = \"uniform\"
            low = 700.0
            high = 800.0
            [[dispersions]]
            vehicle = \"deputy\"
            key = \"panel_pairs[*].panel1.k_nm_rad\"
            distribution = \"uniform\"
            low = 80.0
            high = 120.0
            [[dispersions]]
            vehicle = \"deputy\"
            key = \"relative.hill_position_m\"
            distribution = \"normal\"
            sigma = 2.0
            [[dispersions]]
            vehicle = \"deputy\"
            key = \"relative.hill_velocity_m_s\"
            distribution = \"normal\"
            sigma = 0.05
            "
        ),
    )
    .unwrap();
    assert_eq!(
        plan.keys.iter().flatten().cloned().collect::<Vec<_>>(),
        [
            "chief.hub.inertia_bc_b_kg_m2[0][0]",
            "deputy.hub.mass_kg",
            "deputy.panel_pairs[0].panel1.k_nm_rad",
            "deputy.panel_pairs[1].panel1.k_nm_rad",
            "deputy.relative.hill_position_m[0]",
            "deputy.relative.hill_position_m[1]",
            "deputy.relative.hill_position_m[2]",
            "deputy.relative.hill_velocity_m_s[0]",
            "deputy.relative.hill_velocity_m_s[1]",
            "deputy.relative.hill_velocity_m_s[2]",
        ]
    );
    // The undispersed fleet, built from the fleet file itself.
    let nominal =
        fleet_readback(&FleetConfig::from_file(&dir.join("fleet.toml")).unwrap()).unwrap();
    assert!((nominal["deputy.relative.hill_position_m[1]"] + 100.0).abs() < 1e-6);
    let mut inertia = Vec::new();
    let mut mass = Vec::new();
    let mut k = [Vec::new(), Vec::new()];
    let mut rho: [Vec<f64>; 3] = Default::default();
    let mut rho_dot: [Vec<f64>; 3] = Default::default();
    for r in 0..1000 {
        let rp = plan.run(r);
        assert_eq!(rp.redraws, 0, "run {r}: {:?}", rp.redraw_reasons);
        let model = read_back(&rp);
        inertia.push(model["chief.hub.inertia_bc_b_kg_m2[0][0]"]);
        mass.push(model["deputy.hub.mass_kg"]);
        for (p, v) in k.iter_mut().enumerate() {
            v.push(model[&format!("deputy.panel_pairs[{p}].panel1.k_nm_rad")]);
        }
        for i in 0..3 {
            rho[i].push(model[&format!("deputy.relative.hill_position_m[{i}]")]);
            rho_dot[i].push(model[&format!("deputy.relative.hill_velocity_m_s[{i}]")]);
        }
        // What each vehicle's dispersions do not name keeps its nominal value, on the other
        // vehicle too: the chief's mass, stiffnesses and orbit, the deputy's inertia.
        for key in [
            "chief.hub.mass_kg",
            "chief.panel_pairs[0].panel1.k_nm_rad",
            "chief.panel_pairs[1].panel1.k_nm_rad",
            "chief.initial.r_bn_n_m[0]",
            "chief.initial.v_bn_n_m_s[2]",
            "deputy.hub.inertia_bc_b_kg_m2[0][0]",
            "deputy.hub.inertia_bc_b_kg_m2[1][1]",
            "deputy.panel_pairs[0].panel2.k_nm_rad",
            "deputy.initial.omega_bn_b_rad_s[0]",
        ] {
            assert_eq!(model[key], nominal[key], "run {r}: {key} changed");
        }
    }
    check_normal("chief inertia[0][0] ~ N(900, 45)", &inertia, 900.0, 45.0);
    check_uniform("deputy mass ~ U(700, 800)", &mass, 700.0, 800.0);
    for (p, v) in k.iter().enumerate() {
        check_uniform(&format!("deputy pair {p} k ~ U(80, 120)"), v, 80.0, 120.0);
    }
    // Normal dispersions are centred on the fleet file's offsets: (0, -100, 0) m, at rest.
    for (i, mu) in [0.0, -100.0, 0.0].iter().enumerate() {
        check_normal(&format!("deputy ρ[{i}] ~ N({mu}, 2)"), &rho[i], *mu, 2.0);
        check_normal(
            &format!("deputy ρ'[{i}] ~ N(0, 0.05)"),
            &rho_dot[i],
            0.0,
            0.05,
        );
    }
}

#[test]
fn every_vehicle_gets_its_own_sensor_seeds_in_every_run() {
    let dir = fleet_dir("campaign_fleet_seeds");
    let text =
        format!("fleet = \"fleet.toml\"\nruns = 5\nseed = 9\nduration_s = 1.0\n{CONTROLLERS}");
    let plan = plan_in(&dir, &text).unwrap();
    let mut seen = Vec::new();
    for r in 0..5 {
        let rp = plan.run(r);
        let keys: Vec<&str> = rp.sensor_seeds.keys().map(String::as_str).collect();
        assert_eq!(
            keys,
            [
                "chief.imus[0].seed",
                "chief.imus[1].seed",
                "deputy.imus[0].seed",
                "deputy.imus[1].seed"
            ]
        );
        for (key, seed) in &rp.sensor_seeds {
            // The documented rule, with the vehicle's id in the hashed key.
            assert_eq!(
                *seed,
                splitmix64(rp.run_seed ^ fnv1a(key)) >> 1,
                "run {r}: {key}"
            );
        }
        // The built IMUs of each vehicle carry the planned seeds.
        let fleet = rp.fleet().unwrap();
        for v in &fleet.vehicles {
            let built: Vec<u64> = v.cfg.sensors.of::<ImuConfig>().map(|i| i.seed).collect();
            let planned: Vec<u64> = (0..2)
                .map(|k| rp.sensor_seeds[&format!("{}.imus[{k}].seed", v.id)])
                .collect();
            assert_eq!(built, planned, "run {r}: {}", v.id);
        }
        // Planned again, alone, and by another plan of the same file: the same seeds.
        assert_eq!(plan.run(r).sensor_seeds, rp.sensor_seeds);
        assert_eq!(
            plan_in(&dir, &text).unwrap().run(r).sensor_seeds,
            rp.sensor_seeds
        );
        seen.extend(rp.sensor_seeds.values().copied());
    }
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(
        seen.len(),
        20,
        "every run, vehicle and IMU gets its own seed"
    );
}

#[test]
fn a_run_folder_stands_alone_and_builds_the_planned_models() {
    let dir = fleet_dir("campaign_fleet_write");
    let plan = plan_in(
        &dir,
        &format!(
            "fleet = \"fleet.toml\"\nruns = 3\nseed = 4\nduration_s = 1.0\n{CONTROLLERS}
            [[dispersions]]
            vehicle = \"deputy\"
            key = \"relative.hill_position_m[2]\"
            distribution = \"uniform\"
            low = -5.0
            high = 5.0
            [[dispersions]]
            vehicle = \"chief\"
            key = \"hub.mass_kg\"
            distribution = \"normal\"
            sigma = 10.0
            "
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let runs = plan.write(&out).unwrap();
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["vehicles"], serde_json::json!(["chief", "deputy"]));
    assert_eq!(manifest["controllers"][1]["sender_id"], 2);
    for rp in &runs {
        let folder = out.join(&rp.dir);
        for f in ["fleet.toml", "config-chief.toml", "config-deputy.toml"] {
            assert!(folder.join(f).is_file(), "{}/{f}", rp.dir);
        }
        // Read from disk as `flexdyn run --fleet run-NNNN/fleet.toml` reads it, from another
        // working directory: the same models as in memory, bit for bit.
        let on_disk =
            fleet_readback(&FleetConfig::from_file(&folder.join("fleet.toml")).unwrap()).unwrap();
        assert_eq!(on_disk, read_back(rp), "{}", rp.dir);
        assert_eq!(
            on_disk["chief.hub.mass_kg"],
            rp.dispersed["chief.hub.mass_kg"]
        );
    }
}

/// The error of the campaign `text` in `dir`, which must start with the campaign file, then
/// `field`, contain each of `says`, and point at the line holding `marker`.
fn assert_error(dir: &Path, text: &str, field: &str, says: &[&str], marker: &str) {
    let e = match plan_in(dir, text) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    };
    let head = format!("{}: {field}: ", dir.join("test-campaign.toml").display());
    assert!(e.starts_with(&head), "{field}: {e}");
    for w in says {
        assert!(e.contains(w), "{field}: no `{w}`: {e}");
    }
    let line = 1 + text
        .lines()
        .position(|l| l.contains(marker))
        .unwrap_or_else(|| panic!("no line contains {marker:?}"));
    let at = format!("(line {line}, column ");
    assert!(e.contains(&at), "{field}: not at {at}: {e}");
}

#[test]
fn fleet_campaign_errors_name_the_file_the_field_and_its_line() {
    let dir = fleet_dir("campaign_fleet_errors");
    let head =
        format!("fleet = \"fleet.toml\"\nruns = 2\nseed = 1\nduration_s = 1.0\n{CONTROLLERS}");
    let disp = |body: &str| {
        format!("{head}[[dispersions]]\n{body}\ndistribution = \"normal\"\nsigma = 1.0\n")
    };
    // A dispersion without its vehicle, with a fleet base: pointed at its key.
    assert_error(
        &dir,
        &disp("key = \"hub.mass_kg\""),
        "dispersions[0].vehicle",
        &["missing", "\"chief\", \"deputy\""],
        "hub.mass_kg",
    );
    // An unknown vehicle: the ids listed.
    assert_error(
        &dir,
        &disp("vehicle = \"mothership\"\nkey = \"hub.mass_kg\""),
        "dispersions[0].vehicle",
        &[
            "\"mothership\" is not a vehicle of",
            "fleet.toml",
            "\"chief\", \"deputy\"",
        ],
        "mothership",
    );
    // A vehicle without a fleet base.
    let imu = root().join("scenarios/imu_tactical.toml");
    assert_error(
        &dir,
        &format!(
            "base = {:?}\nruns = 2\nseed = 1\nduration_s = 1.0\n[[dispersions]]\nvehicle = \
             \"deputy\"\nkey = \"hub.mass_kg\"\ndistribution = \"normal\"\nsigma = 1.0\n",
            imu.display().to_string()
        ),
        "dispersions[0].vehicle",
        &["applies only to a campaign over a fleet"],
        "vehicle",
    );
    // `base` and `fleet` at once.
    assert_error(
        &dir,
        &format!("base = \"x.toml\"\n{head}"),
        "fleet",
        &["either base", "or fleet", "not both"],
        "fleet =",
    );
    // A key that does not exist in the vehicle's configuration names the vehicle.
    assert_error(
        &dir,
        &disp("vehicle = \"deputy\"\nkey = \"hub.mas_kg\""),
        "dispersions[0].key",
        &["vehicle \"deputy\"", "hub.mas_kg does not exist"],
        "hub.mas_kg",
    );
    // Hill offsets are a deputy's; a deputy's own position is replaced by them.
    assert_error(
        &dir,
        &disp("vehicle = \"chief\"\nkey = \"relative.hill_position_m\""),
        "dispersions[0].key",
        &["vehicle \"chief\" has no [vehicles.relative]"],
        "relative.hill_position_m",
    );
    assert_error(
        &dir,
        &disp("vehicle = \"deputy\"\nkey = \"initial.r_bn_n_m\""),
        "dispersions[0].key",
        &["disperse relative.hill_position_m"],
        "initial.r_bn_n_m",
    );
    // Criteria name their vehicle too; `range` is a deputy's.
    let crit = |body: &str| {
        format!("{head}[[criteria]]\nname = \"c\"\n{body}\nstatistic = \"final\"\nbelow = 1.0\n")
    };
    assert_error(
        &dir,
        &crit("quantity = \"omega\""),
        "criteria[0].vehicle",
        &["missing"],
        "name = \"c\"",
    );
    assert_error(
        &dir,
        &crit("vehicle = \"chief\"\nquantity = \"range\""),
        "criteria[0].quantity",
        &["\"chief\" has no chief"],
        "\"range\"",
    );
    // Controllers: one for every participant of the fleet file, each with a sender id of its
    // vehicle, never the observer's.
    let base = "fleet = \"fleet.toml\"\nruns = 2\nseed = 1\nduration_s = 1.0\n";
    let chief = "[[controllers]]\nvehicle = \"chief\"\ncommand = \"a\"\n";
    assert_error(
        &dir,
        &format!("{base}{chief}"),
        "controllers",
        &[
            "vehicles[1] (\"deputy\")",
            "participant 2",
            "would wait for it",
        ],
        "[[controllers]]",
    );
    assert_error(
        &dir,
        &format!(
            "{base}{chief}[[controllers]]\nvehicle = \"deputy\"\nsender_id = 9\ncommand = \"b\"\n"
        ),
        "controllers[1].sender_id",
        &["observer"],
        "sender_id = 9",
    );
    assert_error(
        &dir,
        &format!(
            "{base}{chief}[[controllers]]\nvehicle = \"deputy\"\nsender_id = 1\ncommand = \"b\"\n"
        ),
        "controllers[1].sender_id",
        &["1 is not a participant of vehicle \"deputy\"", "[2]"],
        "sender_id = 1",
    );
    assert_error(
        &dir,
        &format!("controller = \"x\"\n{head}"),
        "controller",
        &["[[controllers]]"],
        "controller = ",
    );
    // A bad fleet file: its own file, the vehicle and the field, and its line there.
    let bad = std::fs::read_to_string(dir.join("fleet.toml"))
        .unwrap()
        .replace("chief = \"chief\"", "chief = \"mothership\"");
    std::fs::write(dir.join("bad_fleet.toml"), &bad).unwrap();
    let e = plan_in(&dir, &head.replace("fleet.toml", "bad_fleet.toml")).unwrap_err();
    let want = format!(
        "{}: vehicles[1] (\"deputy\").relative.chief: \"mothership\" is not the id",
        dir.join("bad_fleet.toml").display()
    );
    assert!(e.starts_with(&want), "{e}");
    let line = 1 + bad.lines().position(|l| l.contains("mothership")).unwrap();
    assert!(e.contains(&format!("(line {line}, column ")), "{e}");
    assert!(
        e.contains("test-campaign.toml"),
        "names the campaign too: {e}"
    );
}

/// A controller that commands several vehicles is one `[[controllers]]` entry whose sender id
/// the fleet file lists for each of them (here sender 3 for both): it covers every vehicle's
/// participant, so no other entry is needed, and without `sender_id` a vehicle with its one
/// participant gets it by default.
#[test]
fn one_controller_may_command_several_vehicles() {
    let dir = fleet_dir("campaign_fleet_shared_controller");
    let fleet = std::fs::read_to_string(dir.join("fleet.toml"))
        .unwrap()
        .replace("participants = [1]", "participants = [3]")
        .replace("participants = [2]", "participants = [3]");
    std::fs::write(dir.join("fleet.toml"), fleet).unwrap();
    let plan = plan_in(
        &dir,
        "fleet = \"fleet.toml\"\nruns = 2\nseed = 1\nduration_s = 1.0\n[[controllers]]\n\
         vehicle = \"deputy\"\ncommand = \"formation-controller --sender-id {sender_id}\"\n",
    )
    .unwrap();
    let c = &plan.campaign.controllers;
    assert_eq!(c.len(), 1);
    assert_eq!((c[0].vehicle.as_str(), c[0].sender_id), ("deputy", 3));
    assert!(plan.run(0).valid);
}

/// A random fault of one vehicle (`mtbf_s`) gets a seed per run keyed with that vehicle's id,
/// and its failure time from it; `--without-random-faults` removes it and changes nothing else
/// (the other seeds and the dispersions stay).
#[test]
fn a_vehicles_random_fault_is_seeded_per_vehicle_and_can_be_removed() {
    let dir = fleet_dir("campaign_fleet_random_fault");
    let mut fleet: toml::Table = std::fs::read_to_string(dir.join("fleet.toml"))
        .unwrap()
        .parse()
        .unwrap();
    let fault: toml::Table = "target = \"imus.hub.gyro\"\nmode = \"dropout\"\nstart_s = 1.0\n\
                              mtbf_s = 20.0\n"
        .parse()
        .unwrap();
    fleet["vehicles"][1]["spacecraft"]
        .as_table_mut()
        .unwrap()
        .insert("faults".into(), toml::Value::Array(vec![fault.into()]));
    std::fs::write(dir.join("fleet.toml"), toml::to_string(&fleet).unwrap()).unwrap();
    let text = format!(
        "fleet = \"fleet.toml\"\nruns = 3\nseed = 5\nduration_s = 1.0\n{CONTROLLERS}\
         [[dispersions]]\nvehicle = \"chief\"\nkey = \"hub.mass_kg\"\ndistribution = \
         \"normal\"\nsigma = 10.0\n"
    );
    let with = plan_in(&dir, &text).unwrap();
    let mut without = Campaign::from_str_at(&text, &dir.join("test-campaign.toml")).unwrap();
    assert_eq!(without.without_random_faults().unwrap(), 1);
    let without = Plan::new(without).unwrap();
    for r in 0..3 {
        let rp = with.run(r);
        let seed = rp.sensor_seeds["deputy.faults[0].seed"];
        assert_eq!(
            seed,
            splitmix64(rp.run_seed ^ fnv1a("deputy.faults[0].seed")) >> 1
        );
        let deputy = &rp.fleet().unwrap().vehicles[1].cfg;
        assert_eq!(
            rp.random_failures_ns["deputy.faults[0]"],
            1_000_000_000 + flexdyn_faults::failure_delay_ns(20.0, seed)
        );
        assert_eq!(
            deputy.faults[0].window.start_ns,
            rp.random_failures_ns["deputy.faults[0]"]
        );
        let alone = without.run(r);
        assert!(alone.fleet().unwrap().vehicles[1].cfg.faults.is_empty());
        assert!(alone.random_failures_ns.is_empty());
        let mut seeds = rp.sensor_seeds.clone();
        seeds.remove("deputy.faults[0].seed");
        assert_eq!(alone.sensor_seeds, seeds, "run {r}");
        assert_eq!(alone.dispersed, rp.dispersed, "run {r}");
    }
}
