//! Campaign planning without a server: the values read back from each run's built model follow
//! the requested distributions (1000 draws, bounds from the sampling distributions of the mean
//! and the variance), equal what the plan wrote, misspelled or unverifiable keys are load
//! errors naming the field, invalid draws are redrawn and recorded, and the same file gives
//! the same plan byte for byte.

use std::path::{Path, PathBuf};

use flexdyn_campaign::plan::{readback, Plan};
use flexdyn_campaign::spec::Campaign;
use flexdyn_vehicle::config::SimConfig;

use crate::campaign_support;
use campaign_support::{check_normal, check_uniform, stats};

fn campaign(text: &str) -> Result<Plan, String> {
    let c =
        Campaign::from_str_at(text, Path::new("test-campaign.toml")).map_err(|e| e.to_string())?;
    Plan::new(c).map_err(|e| e.to_string())
}

const HEAD: &str = "runs = 1000\nseed = 7\nduration_s = 1.0\n";

#[test]
fn applied_parameters_follow_the_requested_distributions() {
    let plan = campaign(&format!(
        "{HEAD}
        [[dispersions]]
        key = \"hub.inertia_bc_b_kg_m2[0][0]\"
        distribution = \"normal\"
        sigma = 45.0
        [[dispersions]]
        key = \"panel_pairs[*].panel1.k_nm_rad\"
        distribution = \"uniform\"
        low = 80.0
        high = 120.0
        [[dispersions]]
        key = \"initial.omega_bn_b_rad_s\"
        distribution = \"normal\"
        mean = 0.0
        sigma = 0.01
        [[dispersions]]
        key = \"initial.sigma_bn\"
        distribution = \"uniform_attitude\"
        "
    ))
    .unwrap();
    let n = 1000;
    let mut inertia = Vec::new();
    let mut k = [Vec::new(), Vec::new()];
    let mut omega = [Vec::new(), Vec::new(), Vec::new()];
    let mut beta = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for r in 0..n {
        let rp = plan.run(r);
        assert!(
            rp.valid && rp.redraws == 0,
            "run {r}: {:?}",
            rp.redraw_reasons
        );
        // Read back from the built model, not from the file.
        let model = readback(&SimConfig::from_toml_str(&rp.config_toml).unwrap()).unwrap();
        for (key, written) in &rp.dispersed {
            assert_eq!(
                model[key], *written,
                "run {r}: {key} was not applied as drawn"
            );
        }
        inertia.push(model["hub.inertia_bc_b_kg_m2[0][0]"]);
        for (p, v) in k.iter_mut().enumerate() {
            v.push(model[&format!("panel_pairs[{p}].panel1.k_nm_rad")]);
        }
        for (i, v) in omega.iter_mut().enumerate() {
            v.push(model[&format!("initial.omega_bn_b_rad_s[{i}]")]);
        }
        let s: Vec<f64> = (0..3)
            .map(|i| model[&format!("initial.sigma_bn[{i}]")])
            .collect();
        let s2: f64 = s.iter().map(|x| x * x).sum();
        assert!(s2 <= 1.0 + 1e-12, "run {r}: |σ| > 1");
        beta[0].push((1.0 - s2) / (1.0 + s2));
        for i in 0..3 {
            beta[i + 1].push(2.0 * s[i] / (1.0 + s2));
        }
        // Untouched parameters keep their nominal values.
        assert_eq!(model["hub.inertia_bc_b_kg_m2[1][1]"], 800.0);
        assert_eq!(model["panel_pairs[0].panel2.k_nm_rad"], 100.0);
    }
    let nf = n as f64;
    check_normal("inertia[0][0] ~ N(900, 45)", &inertia, 900.0, 45.0);
    for (p, v) in k.iter().enumerate() {
        check_uniform(&format!("pair {p} k ~ U(80, 120)"), v, 80.0, 120.0);
    }
    // The two pairs are drawn independently: their correlation is within 4/√n of 0.
    let (m0, v0) = stats(&k[0]);
    let (m1, v1) = stats(&k[1]);
    let cov = k[0]
        .iter()
        .zip(&k[1])
        .map(|(x, y)| (x - m0) * (y - m1))
        .sum::<f64>()
        / (nf - 1.0);
    assert!(
        (cov / (v0 * v1).sqrt()).abs() < 4.0 / nf.sqrt(),
        "pairs correlated"
    );
    for (i, v) in omega.iter().enumerate() {
        check_normal(&format!("omega[{i}] ~ N(0, 0.01)"), v, 0.0, 0.01);
    }
    // A uniform rotation: β uniform on the half 3-sphere β0 ≥ 0. E[β_i] = 0 (i = 1..3),
    // E[β_k²] = 1/4 for all four, and E[β0] = 4/(3π) (marginal density ∝ √(1 − x²)).
    for (i, b) in beta.iter().enumerate().skip(1) {
        let (m, _) = stats(b);
        assert!(m.abs() < 4.0 * (0.25 / nf).sqrt(), "E[β{i}] = {m}");
    }
    for (i, b) in beta.iter().enumerate() {
        let m2 = b.iter().map(|x| x * x).sum::<f64>() / nf;
        // Var(β²) for a uniform S³ point: E[β⁴] − 1/16 = 1/8 − 1/16.
        assert!(
            (m2 - 0.25).abs() < 4.0 * (1.0 / 16.0 / nf).sqrt(),
            "E[β{i}²] = {m2}"
        );
    }
    let (m0b, v0b) = stats(&beta[0]);
    let want = 4.0 / (3.0 * std::f64::consts::PI);
    assert!(
        (m0b - want).abs() < 4.0 * (v0b / nf).sqrt(),
        "E[β0] = {m0b}, want {want}"
    );
}

#[test]
fn wrong_keys_are_load_errors_that_name_the_field() {
    for (key, want) in [
        (
            "hub.inertai_bc_b_kg_m2[0][0]",
            "hub.inertai_bc_b_kg_m2 does not exist",
        ),
        (
            "panel_pairs[5].panel1.k_nm_rad",
            "panel_pairs[5] does not exist",
        ),
        (
            "panel_pairs[*].panel1.k_n_m_rad",
            "panel_pairs[0].panel1.k_n_m_rad does not exist",
        ),
        (
            "simulation.frame_hz",
            "is not a parameter the built model reports",
        ),
        ("hub.inertia_bc_b_kg_m2[0][0", "expected [index] or [*]"),
    ] {
        let e = campaign(&format!(
            "{HEAD}[[dispersions]]\nkey = \"{key}\"\ndistribution = \"normal\"\nsigma = 1.0\n"
        ))
        .unwrap_err();
        assert!(
            e.contains("dispersions[0].key") && e.contains(want),
            "{key}: {e}"
        );
    }
    for (body, want) in [
        (
            "distribution = \"gauss\"\nsigma = 1.0",
            "dispersions[0].distribution",
        ),
        (
            "distribution = \"normal\"\nsigma = -1.0",
            "dispersions[0].sigma: must be ≥ 0",
        ),
        (
            "distribution = \"uniform\"\nlow = 2.0\nhigh = 1.0",
            "dispersions[0].high",
        ),
        (
            "distribution = \"normal\"\nsigma = 1.0\nlow = 0.0",
            "dispersions[0].low: does not apply",
        ),
    ] {
        let e = campaign(&format!(
            "{HEAD}[[dispersions]]\nkey = \"hub.mass_kg\"\n{body}\n"
        ))
        .unwrap_err();
        assert!(e.contains(want), "{body}: {e}");
    }
    let e = campaign("runs = 0\nseed = 1\nduration_s = 1.0\n").unwrap_err();
    assert!(e.contains("runs"), "{e}");
    let e = campaign("runs = 2\nseed = 1\nduration_s = 0.015\n").unwrap_err();
    assert!(
        e.contains("duration_s") && e.contains("whole number of frames"),
        "{e}"
    );
}

/// `[resources]`: read with its defaults, and every bad value refused naming its key.
#[test]
fn resources_are_read_and_checked() {
    let head = "runs = 1\nseed = 1\nduration_s = 1.0\n";
    let plan = campaign(head).unwrap();
    let r = plan.campaign.resources;
    assert_eq!(
        (r.cpus_per_run, r.memory_mb, r.time_limit_s),
        (2, None, None)
    );
    let plan = campaign(&format!(
        "{head}[resources]\ncpus_per_run = 4\nmemory_mb = 2048\ntime_limit_s = 600\n"
    ))
    .unwrap();
    let r = plan.campaign.resources;
    assert_eq!(
        (r.cpus_per_run, r.memory_mb, r.time_limit_s),
        (4, Some(2048), Some(600))
    );
    for (body, key) in [
        ("cpus_per_run = 0", "resources.cpus_per_run"),
        ("memory_mb = 0", "resources.memory_mb"),
        ("time_limit_s = 0", "resources.time_limit_s"),
        ("time_limit_s = 1.5", "resources.time_limit_s"),
        ("gpus = 1", "gpus"),
    ] {
        let e = campaign(&format!("{head}[resources]\n{body}\n")).unwrap_err();
        assert!(e.contains(key), "{body}: {e}");
    }
}

#[test]
fn invalid_draws_are_redrawn_and_recorded_or_the_run_is_invalid() {
    // I_xx ~ U(0, 3000) with I_yy = 800, I_zz = 600: the triangle inequality needs
    // 200 < I_xx < 1400, so most draws are invalid.
    let body = "[[dispersions]]\nkey = \"hub.inertia_bc_b_kg_m2[0][0]\"\ndistribution = \"uniform\"\nlow = 0.0\nhigh = 3000.0\n";
    let plan = campaign(&format!("runs = 50\nseed = 3\nduration_s = 1.0\n{body}")).unwrap();
    let runs: Vec<_> = (0..50).map(|r| plan.run(r)).collect();
    let redrawn = runs.iter().filter(|r| r.redraws > 0).count();
    assert!(redrawn > 20, "only {redrawn} runs needed a redraw");
    for r in &runs {
        assert!(r.valid);
        assert_eq!(r.redraw_reasons.len(), r.redraws as usize);
        let i = r.dispersed["hub.inertia_bc_b_kg_m2[0][0]"];
        assert!(i > 200.0 && i < 1400.0, "run {}: accepted {i}", r.run);
        for why in &r.redraw_reasons {
            assert!(why.contains("hub.inertia_bc_b_kg_m2"), "{why}");
        }
    }
    let plan = campaign(&format!(
        "runs = 50\nseed = 3\nduration_s = 1.0\nmax_redraws = 0\n{body}"
    ))
    .unwrap();
    let invalid = (0..50).filter(|r| !plan.run(*r).valid).count();
    assert!(invalid > 20, "only {invalid} invalid runs without redraws");
}

#[test]
fn the_same_campaign_gives_the_same_plan_byte_for_byte() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let file = root.join("scenarios/campaign.toml");
    let dirs: Vec<PathBuf> = (0..2)
        .map(|i| Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("campaign_plan_{i}")))
        .collect();
    for d in &dirs {
        let _ = std::fs::remove_dir_all(d);
        let plan = Plan::new(Campaign::from_file(&file).unwrap()).unwrap();
        plan.write(d).unwrap();
    }
    let a = std::fs::read(dirs[0].join("manifest.json")).unwrap();
    assert_eq!(a, std::fs::read(dirs[1].join("manifest.json")).unwrap());
    for r in 0..20 {
        let name = format!("run-{r:04}/config.toml");
        let x = std::fs::read(dirs[0].join(&name)).unwrap();
        assert_eq!(x, std::fs::read(dirs[1].join(&name)).unwrap(), "{name}");
    }
    // A run planned alone is the same run.
    let plan = Plan::new(Campaign::from_file(&file).unwrap()).unwrap();
    let alone = plan.run(13);
    assert_eq!(
        alone.config_toml.as_bytes(),
        std::fs::read(dirs[0].join("run-0013/config.toml")).unwrap()
    );
}

#[test]
fn sensor_seeds_are_derived_per_run_and_reach_the_model() {
    let base = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/imu_tactical.toml");
    let plan = campaign(&format!(
        "base = {:?}\nruns = 5\nseed = 9\nduration_s = 1.0\n",
        base.display().to_string()
    ))
    .unwrap();
    let mut seen = Vec::new();
    for r in 0..5 {
        let rp = plan.run(r);
        assert_eq!(rp.sensor_seeds.len(), 2, "{:?}", rp.sensor_seeds);
        let cfg = SimConfig::from_toml_str(&rp.config_toml).unwrap();
        let built: Vec<u64> = cfg
            .sensors
            .of::<flexdyn_sensors::imu::ImuConfig>()
            .map(|i| i.seed)
            .collect();
        let planned: Vec<u64> = rp.sensor_seeds.values().copied().collect();
        assert_eq!(
            built, planned,
            "run {r}: the model's IMU seeds are the planned ones"
        );
        assert_eq!(plan.run(r).sensor_seeds, rp.sensor_seeds, "deterministic");
        seen.extend(planned);
    }
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(seen.len(), 10, "every run and sensor gets its own seed");
}

/// The error of `text` (a campaign file named `test-campaign.toml`), planned.
fn plan_error(text: &str) -> String {
    match campaign(text) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    }
}

/// 1-based line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("no line contains {needle:?}"))
}

#[test]
fn impossible_values_are_load_errors_naming_the_file_the_field_and_its_line() {
    let criterion = "[[criteria]]\nname = \"c\"\nquantity = \"omega\"\n";
    let normal = "[[dispersions]]\nkey = \"hub.mass_kg\"\ndistribution = \"normal\"\n";
    let uniform = "[[dispersions]]\nkey = \"hub.mass_kg\"\ndistribution = \"uniform\"\n";
    // (the file after `runs`, the field, the words, the line's marker)
    let rows: Vec<(String, &str, &[&str], &str)> = vec![
        // Beyond what a u64 count of nanoseconds holds (2^64 − 1 ns ≈ 1.8447e10 s).
        (
            "seed = 1\nduration_s = 1e300\n".into(),
            "duration_s",
            &["1e300 s", "beyond", "2^64"],
            "duration_s",
        ),
        (
            "seed = 1\nduration_s = 2e10\n".into(),
            "duration_s",
            &["beyond", "2^64"],
            "duration_s",
        ),
        (
            "seed = 1\nduration_s = 1.0\nparticipant_timeout_s = 1e300\n".into(),
            "participant_timeout_s",
            &["beyond", "2^64"],
            "participant_timeout_s",
        ),
        // NaN and Inf anywhere, as the configuration rejects them.
        (
            "seed = 1\nduration_s = 1.0\nsigma_rn = [nan, 0, 0]\n".into(),
            "sigma_rn[0]",
            &["must be finite"],
            "sigma_rn",
        ),
        (
            format!("seed = 1\nduration_s = 1.0\n{criterion}statistic = \"final\"\nbelow = nan\n"),
            "criteria[0].below",
            &["must be finite"],
            "below",
        ),
        (
            format!("seed = 1\nduration_s = 1.0\n{normal}sigma = 1.0\nmean = inf\n"),
            "dispersions[0].mean",
            &["must be finite"],
            "mean",
        ),
        (
            format!("seed = 1\nduration_s = 1.0\n{uniform}low = 1.0\nhigh = inf\n"),
            "dispersions[0].high",
            &["must be finite"],
            "high",
        ),
        (
            format!(
                "seed = 1\nduration_s = 1.0\n{criterion}statistic = \"settling_time\"\n\
                 threshold = -inf\nbelow = 1.0\n"
            ),
            "criteria[0].threshold",
            &["must be finite"],
            "threshold",
        ),
        // A uniform range wider than a float holds.
        (
            format!("seed = 1\nduration_s = 1.0\n{uniform}low = -1e308\nhigh = 1e308\n"),
            "dispersions[0].high",
            &["high - low", "overflows"],
            "high",
        ),
        // A criterion that can never pass: every quantity is a magnitude (≥ 0).
        (
            format!("seed = 1\nduration_s = 1.0\n{criterion}statistic = \"final\"\nbelow = 0.0\n"),
            "criteria[0].below",
            &["must be > 0", "could never pass"],
            "below",
        ),
        // A window that only `max` uses.
        (
            format!(
                "seed = 1\nduration_s = 1.0\n{criterion}statistic = \"final\"\nafter_s = 0.5\n\
                 below = 1.0\n"
            ),
            "criteria[0].after_s",
            &["does not apply to statistic \"final\""],
            "after_s",
        ),
    ];
    for (rest, field, says, marker) in rows {
        let text = format!("runs = 2\n{rest}");
        let e = plan_error(&text);
        let head = format!("test-campaign.toml: {field}: ");
        assert!(e.starts_with(&head), "{field}: {e}");
        for w in says {
            assert!(e.contains(w), "{field}: no `{w}`: {e}");
        }
        let at = format!("(line {}, column ", line_of(&text, marker));
        assert!(e.contains(&at), "{field}: not at {at}: {e}");
        assert!(e.len() < 240, "{field}: {} characters: {e}", e.len());
    }
    // 1e10 s is a whole number of nanoseconds below the bound: planned (nothing runs).
    campaign("runs = 1\nseed = 1\nduration_s = 1e10\n").unwrap();
}

#[test]
fn errors_start_with_the_file_that_holds_the_field() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("campaign_files");
    std::fs::create_dir_all(&dir).unwrap();
    let imu = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/imu_tactical.toml");
    // A misspelled dispersion key is the campaign file's, with or without a base.
    for base in [
        String::new(),
        format!("base = {:?}\n", imu.display().to_string()),
    ] {
        let text = format!(
            "{base}runs = 1\nseed = 1\nduration_s = 1.0\n[[dispersions]]\nkey = \"hub.mas_kg\"\n\
             distribution = \"normal\"\nsigma = 1.0\n"
        );
        let e = plan_error(&text);
        assert!(
            e.starts_with("test-campaign.toml: dispersions[0].key: "),
            "{e}"
        );
        assert!(e.contains("hub.mas_kg does not exist"), "{e}");
        let at = format!("(line {}, column 7)", line_of(&text, "hub.mas_kg"));
        assert!(e.contains(&at), "not at {at}: {e}");
    }
    // A field of an invalid base is the base file's: its name, the field, its line.
    let bad_base = dir.join("bad_base.toml");
    let base_text =
        std::fs::read_to_string(&imu)
            .unwrap()
            .replacen("mass_kg = 750.0", "mass_kg = -1.0", 1);
    std::fs::write(&bad_base, &base_text).unwrap();
    let campaign_file = dir.join("uses_bad_base.toml");
    let error_with_base = |base: &str| {
        let text = format!("base = {base:?}\nruns = 1\nseed = 1\nduration_s = 1.0\n");
        std::fs::write(&campaign_file, text).unwrap();
        Campaign::from_file(&campaign_file).unwrap_err().to_string()
    };
    let e = error_with_base("bad_base.toml");
    let head = format!("{}: hub.mass_kg: must be > 0", bad_base.display());
    assert!(e.starts_with(&head), "{e}");
    let at = format!("(line {}, column", line_of(&base_text, "mass_kg = -1.0"));
    assert!(e.contains(&at), "{e}");
    assert!(
        e.contains("uses_bad_base.toml"),
        "names the campaign too: {e}"
    );
    // A base that cannot be read is the campaign's `base` field.
    let e = error_with_base("no_such_base.toml");
    let head = format!("{}: base: cannot read", campaign_file.display());
    assert!(e.starts_with(&head), "{e}");
    assert!(e.contains("(line 1, column 8)"), "{e}");
}

/// The environment's parameters (issue 19: Cd, facet areas, residual dipole, F10.7, epoch
/// offset; issue 39: the solar irradiance) are dispersed and read back from the built model
/// like the spacecraft's: the drag and solar-pressure effectors report their facets and the
/// irradiance, the residual-dipole effector its moment, NRLMSISE-00 its space weather and the
/// epoch its offset.
#[test]
fn environment_parameters_are_dispersed_and_read_back_from_the_model() {
    let base = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/leo_environment.toml");
    // 20 days keep the OMM within its 30-day element age.
    let offset_max_s = 20.0 * 86_400.0;
    let plan = campaign(&format!(
        "base = {:?}\nruns = 300\nseed = 11\nduration_s = 1.0\n
        [[dispersions]]
        key = \"environment.facets[*].drag_coefficient\"
        distribution = \"uniform\"
        low = 2.0
        high = 2.4
        [[dispersions]]
        key = \"environment.facets[0].area_m2\"
        distribution = \"normal\"
        sigma = 0.2
        [[dispersions]]
        key = \"environment.residual_dipole_m_b_am2\"
        distribution = \"normal\"
        sigma = 0.05
        [[dispersions]]
        key = \"environment.f107_sfu\"
        distribution = \"uniform\"
        low = 70.0
        high = 250.0
        [[dispersions]]
        key = \"epoch.offset_s\"
        distribution = \"uniform\"
        low = 0.0
        high = {offset_max_s:?}
        [[dispersions]]
        key = \"environment.solar_irradiance_1au_w_m2\"
        distribution = \"uniform\"
        low = 1321.0
        high = 1401.0
        ",
        base.display().to_string()
    ))
    .unwrap();
    let n = 300;
    let (mut f107, mut offset, mut cd0, mut area0) = (vec![], vec![], vec![], vec![]);
    for r in 0..n {
        let rp = plan.run(r);
        assert!(rp.valid, "run {r}: {:?}", rp.redraw_reasons);
        let model = readback(&SimConfig::from_toml_str(&rp.config_toml).unwrap()).unwrap();
        for (key, written) in &rp.dispersed {
            // The epoch is held in whole nanoseconds: ½ ns of rounding, then a few ulps of the
            // seconds it is read back in.
            let tol = if key == "epoch.offset_s" {
                0.5e-9 + 4.0 * f64::EPSILON * written.abs()
            } else {
                0.0
            };
            assert!(
                (model[key] - written).abs() <= tol,
                "run {r}: {key} read back {} but {written} was drawn",
                model[key]
            );
        }
        f107.push(model["environment.f107_sfu"]);
        offset.push(model["epoch.offset_s"]);
        cd0.push(model["environment.facets[0].drag_coefficient"]);
        area0.push(model["environment.facets[0].area_m2"]);
        // Untouched: the 81-day mean, the other facets' areas.
        assert_eq!(model["environment.f107a_sfu"], 150.0);
        assert_eq!(model["environment.facets[1].area_m2"], 4.0);
    }
    check_uniform("F10.7 ~ U(70, 250)", &f107, 70.0, 250.0);
    check_uniform("epoch offset ~ U(0, 20 d)", &offset, 0.0, offset_max_s);
    check_uniform("facet 0 Cd ~ U(2.0, 2.4)", &cd0, 2.0, 2.4);
    check_normal("facet 0 area ~ N(4, 0.2)", &area0, 4.0, 0.2);
}

/// Run `r`'s model as built, after checking it is valid and reads back every dispersed value
/// exactly as drawn.
fn read_back_exactly(plan: &Plan, r: u32) -> std::collections::BTreeMap<String, f64> {
    let rp = plan.run(r);
    assert!(rp.valid, "run {r}: {:?}", rp.redraw_reasons);
    let model = readback(&SimConfig::from_toml_str(&rp.config_toml).unwrap()).unwrap();
    for (key, written) in &rp.dispersed {
        assert_eq!(model[key], *written, "run {r}: {key}");
    }
    model
}

/// The sensors' error parameters (issue 20: magnetometer, coarse and fine sun sensors) are
/// dispersed and read back from the built sensors, like the spacecraft's; a key the sensor does
/// not report (its `rate_hz`, which sets the schedule, not the model) is a load error.
#[test]
fn sensor_parameters_are_dispersed_and_read_back_from_the_built_sensors() {
    let base = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/leo_environment.toml");
    let head = format!(
        "base = {:?}\nruns = 300\nseed = 5\nduration_s = 1.0\n",
        base.display().to_string()
    );
    let plan = campaign(&format!(
        "{head}
        [[dispersions]]
        key = \"magnetometers[0].bias_s_t\"
        distribution = \"normal\"
        sigma = 1e-7
        [[dispersions]]
        key = \"magnetometers[0].noise_sigma_t\"
        distribution = \"uniform\"
        low = 1e-8
        high = 1e-7
        [[dispersions]]
        key = \"coarse_sun_sensors[0].scale\"
        distribution = \"normal\"
        sigma = 0.02
        [[dispersions]]
        key = \"fine_sun_sensors[0].bias_rad[1]\"
        distribution = \"normal\"
        sigma = 1e-4
        [[dispersions]]
        key = \"gps_receivers[0].position_bias_e_m[2]\"
        distribution = \"normal\"
        sigma = 2.0
        [[dispersions]]
        key = \"gps_receivers[0].position_sigma_m\"
        distribution = \"uniform\"
        low = 1.0
        high = 5.0
        "
    ))
    .unwrap();
    let (mut bias_x, mut noise, mut scale, mut fss_beta) = (vec![], vec![], vec![], vec![]);
    let (mut gps_bias_z, mut gps_sigma) = (vec![], vec![]);
    for r in 0..300 {
        let model = read_back_exactly(&plan, r);
        bias_x.push(model["magnetometers[0].bias_s_t[0]"]);
        noise.push(model["magnetometers[0].noise_sigma_t"]);
        scale.push(model["coarse_sun_sensors[0].scale"]);
        fss_beta.push(model["fine_sun_sensors[0].bias_rad[1]"]);
        gps_bias_z.push(model["gps_receivers[0].position_bias_e_m[2]"]);
        gps_sigma.push(model["gps_receivers[0].position_sigma_m"]);
        // Untouched: the scenario's values.
        assert_eq!(model["magnetometers[0].lsb_t"], 1e-8);
        assert_eq!(model["fine_sun_sensors[0].bias_rad[0]"], 1.0e-4);
        assert_eq!(model["gps_receivers[0].position_bias_e_m[0]"], 0.5);
    }
    // Normal dispersions are centred on the base value (scenario: 2e-7 T, 1.0, -5e-5 rad).
    check_normal("magnetometer bias x ~ N(2e-7, 1e-7)", &bias_x, 2e-7, 1e-7);
    check_uniform("magnetometer noise ~ U(1e-8, 1e-7)", &noise, 1e-8, 1e-7);
    check_normal("CSS scale ~ N(1, 0.02)", &scale, 1.0, 0.02);
    check_normal("FSS bias beta ~ N(-5e-5, 1e-4)", &fss_beta, -5e-5, 1e-4);
    check_normal("GPS bias z ~ N(0.8, 2)", &gps_bias_z, 0.8, 2.0);
    check_uniform("GPS position sigma ~ U(1, 5)", &gps_sigma, 1.0, 5.0);

    let e = campaign(&format!(
        "{head}[[dispersions]]\nkey = \"magnetometers[0].rate_hz\"\ndistribution = \"normal\"\nsigma = 1.0\n"
    ))
    .unwrap_err();
    assert!(e.contains("dispersions[0].key"), "{e}");
}

/// A base whose orbit comes from a file next to it (`elements_file = "sat.omm"`) plans from any
/// working directory, and each run's config.toml stands alone: the elements are inlined, so a
/// server reading it from the run's folder finds them.
#[test]
fn a_relative_elements_file_is_found_and_inlined_into_each_run() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut leo: toml::Table = std::fs::read_to_string(root.join("scenarios/leo_environment.toml"))
        .unwrap()
        .parse()
        .unwrap();
    let orbit = leo["orbit"].as_table_mut().unwrap();
    let omm = orbit.remove("elements").unwrap();
    let omm = omm.as_str().unwrap().to_owned();
    orbit.insert("elements_file".into(), "sat.omm".into());
    let dir = std::env::temp_dir().join(format!("flexdyn-elements-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("sat.omm"), &omm).unwrap();
    std::fs::write(dir.join("base.toml"), toml::to_string(&leo).unwrap()).unwrap();
    // The campaign file sits elsewhere; its `base` is an absolute path into `dir`.
    let plan = campaign(&format!(
        "base = {:?}\nruns = 2\nseed = 3\nduration_s = 1.0\n
        [[dispersions]]
        key = \"environment.f107_sfu\"
        distribution = \"uniform\"
        low = 100.0
        high = 200.0
        ",
        dir.join("base.toml").display().to_string()
    ))
    .unwrap();
    let rp = plan.run(1);
    assert!(rp.valid, "{:?}", rp.redraw_reasons);
    let run: toml::Table = rp.config_toml.parse().unwrap();
    assert_eq!(run["orbit"].get("elements_file"), None);
    assert_eq!(run["orbit"]["elements"].as_str(), Some(omm.as_str()));
    // Read as a server reads it (relative paths against the run's own folder, here nowhere).
    let cfg = SimConfig::from_toml_str_in(&rp.config_toml, Path::new("/nonexistent")).unwrap();
    let direct = SimConfig::from_toml_str(
        &std::fs::read_to_string(root.join("scenarios/leo_environment.toml")).unwrap(),
    )
    .unwrap();
    assert_eq!(cfg.initial.translation, direct.initial.translation);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The actuators' parameters disperse like any other key and are read back from the built
/// magnetorquers and thrusters (`scenarios/acs_full.toml`).
#[test]
fn actuator_parameters_are_dispersed_and_read_back_from_the_model() {
    let base = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/acs_full.toml");
    let plan = campaign(&format!(
        "base = {:?}\nruns = 300\nseed = 5\nduration_s = 1.0\n
        [[dispersions]]
        key = \"thrusters[*].max_thrust_newton\"
        distribution = \"normal\"
        sigma = 0.05
        [[dispersions]]
        key = \"thrusters[1].isp_s\"
        distribution = \"uniform\"
        low = 200.0
        high = 230.0
        [[dispersions]]
        key = \"magnetorquers[2].max_dipole_am2\"
        distribution = \"normal\"
        sigma = 20.0
        ",
        base.display().to_string()
    ))
    .unwrap();
    let (mut thrust0, mut isp1, mut dipole2) = (vec![], vec![], vec![]);
    for r in 0..300 {
        let model = read_back_exactly(&plan, r);
        thrust0.push(model["thrusters[0].max_thrust_newton"]);
        isp1.push(model["thrusters[1].isp_s"]);
        dipole2.push(model["magnetorquers[2].max_dipole_am2"]);
        // Untouched.
        assert_eq!(model["thrusters[0].isp_s"], 220.0);
        assert_eq!(model["magnetorquers[0].max_dipole_am2"], 400.0);
    }
    check_normal("thruster 0 thrust ~ N(1, 0.05)", &thrust0, 1.0, 0.05);
    check_uniform("thruster 1 Isp ~ U(200, 230)", &isp1, 200.0, 230.0);
    check_normal("rod 2 max dipole ~ N(400, 20)", &dipole2, 400.0, 20.0);
}

/// A random fault (`mtbf_s`, no `seed` in the base) gets a seed per run, written into the run's
/// configuration, so each run samples its own failure time: the built model's start is
/// `start_s` + the time to failure drawn from the planned seed, and the runs differ.
#[test]
fn random_faults_get_a_seed_per_run_and_their_failure_time_from_it() {
    let base = include_str!("../../scenarios/wheels_star_tracker.toml").to_string()
        + "\n[[faults]]\ntarget = \"reaction_wheels.rw2\"\nmode = \"seized\"\nstart_s = 1.0\nmtbf_s = 20.0\n";
    let path =
        std::env::temp_dir().join(format!("flexdyn-random-fault-{}.toml", std::process::id()));
    std::fs::write(&path, base).unwrap();
    let plan = campaign(&format!(
        "base = {:?}\nruns = 5\nseed = 9\nduration_s = 1.0\n",
        path.display().to_string()
    ));
    std::fs::remove_file(&path).unwrap();
    let plan = plan.unwrap();
    let mut starts = Vec::new();
    for r in 0..5 {
        let rp = plan.run(r);
        let seed = rp.sensor_seeds["faults[0].seed"];
        let cfg = SimConfig::from_toml_str(&rp.config_toml).unwrap();
        let start = cfg.faults[0].window.start_ns;
        assert_eq!(
            start,
            1_000_000_000 + flexdyn_faults::failure_delay_ns(20.0, seed)
        );
        assert_eq!(cfg.faults[0].seed, seed);
        starts.push(start);
    }
    starts.sort_unstable();
    starts.dedup();
    assert_eq!(starts.len(), 5, "every run fails at its own time");
}

/// An exponential atmosphere's given band and a cannonball's area and C_R (issue 39) are
/// dispersed and read back from the built model: the environment model reports its band, the
/// cannonball effector its parameters.
#[test]
fn model_constants_are_dispersed_and_read_back_from_the_model() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("campaign_model_constants");
    std::fs::create_dir_all(&dir).unwrap();
    let base = dir.join("base.toml");
    let leo = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/leo_environment.toml"),
    )
    .unwrap();
    // The scenario with its [environment] table (not its facets) replaced.
    let head = &leo[..leo.find("[environment]").unwrap()];
    let tail = &leo[leo.find("[[environment.facets]]").unwrap()..];
    std::fs::write(
        &base,
        format!(
            "{head}[environment]\natmosphere = \"exponential\"\n\
             exponential_base_density_kg_m3 = 1.217\nexponential_scale_height_m = 8500.0\n\
             sun = true\nsolar_pressure = true\nsolar_pressure_model = \"cannonball\"\n\
             cannonball_area_m2 = 4.0\ncannonball_reflectivity_coefficient = 1.2\n\n{tail}"
        ),
    )
    .unwrap();
    let plan = campaign(&format!(
        "base = {:?}\nruns = 20\nseed = 3\nduration_s = 1.0\n
        [[dispersions]]
        key = \"environment.exponential_base_density_kg_m3\"
        distribution = \"uniform\"
        low = 0.6
        high = 1.8
        [[dispersions]]
        key = \"environment.exponential_scale_height_m\"
        distribution = \"normal\"
        sigma = 500.0
        [[dispersions]]
        key = \"environment.cannonball_area_m2\"
        distribution = \"uniform\"
        low = 3.0
        high = 5.0
        [[dispersions]]
        key = \"environment.cannonball_reflectivity_coefficient\"
        distribution = \"uniform\"
        low = 1.0
        high = 1.5
        ",
        base.display().to_string()
    ))
    .unwrap();
    let mut densities = vec![];
    for r in 0..20 {
        let rp = plan.run(r);
        assert!(rp.valid, "run {r}: {:?}", rp.redraw_reasons);
        let model = readback(&SimConfig::from_toml_str(&rp.config_toml).unwrap()).unwrap();
        assert_eq!(rp.dispersed.len(), 4);
        for (key, written) in &rp.dispersed {
            assert_eq!(model[key], *written, "run {r}: {key}");
        }
        densities.push(model["environment.exponential_base_density_kg_m3"]);
    }
    // Twenty uniform draws on [0.6, 1.8] are not all alike.
    assert!(densities.iter().any(|d| (d - densities[0]).abs() > 0.01));
}

/// Issue 37 §3: a flight-code criterion names a stream, mode, event, value and fault the base
/// configuration declares (`scenarios/fdir.toml`'s stream `acs`, its two faults); anything else
/// is a load error naming the field, its line and what the configuration has.
#[test]
fn flight_code_criteria_name_what_the_base_configuration_declares() {
    use flexdyn_campaign::criteria::{FswTarget, Quantity, Statistic};
    let base = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/fdir.toml");
    let head = format!(
        "base = {:?}\nruns = 2\nseed = 1\nduration_s = 10.0\n",
        base.display().to_string()
    );
    let crit = |body: &str| format!("{head}[[criteria]]\nname = \"c\"\n{body}");
    let rows: &[(&str, &str, &[&str], &str)] = &[
        (
            "quantity = \"fsw_mode_entry\"\nstream = \"adcs\"\nmode = \"pointing\"\nbelow = 1.0\n",
            "criteria[0].stream",
            &["\"adcs\" is not a stream the base configuration declares", "acs"],
            "stream =",
        ),
        (
            "quantity = \"fsw_mode_time\"\nstream = \"acs\"\nmode = \"safe\"\nbelow = 1.0\n",
            "criteria[0].mode",
            &["\"safe\" is not a mode of stream \"acs\" (its modes: pointing)"],
            "mode =",
        ),
        (
            "quantity = \"fsw_event_time\"\nstream = \"acs\"\nevent = \"gyro-fail\"\nbelow = 1.0\n",
            "criteria[0].event",
            &["\"gyro-fail\" is not an event", "gyro-failure, wheel-failure"],
            "event =",
        ),
        (
            "quantity = \"fsw_event_latency\"\nstream = \"acs\"\nevent = \"wheel-failure\"\n\
             fault = \"faults[2]\"\nbelow = 1.0\n",
            "criteria[0].fault",
            &["\"faults[2]\"", "has 2 [[faults]] entries"],
            "fault =",
        ),
        (
            "quantity = \"fsw_event_latency\"\nstream = \"acs\"\nevent = \"wheel-failure\"\n\
             fault = \"rw2\"\nbelow = 1.0\n",
            "criteria[0].fault",
            &["not of the form \"faults[k]\""],
            "fault =",
        ),
        (
            "quantity = \"fsw_event_latency\"\nstream = \"acs\"\nevent = \"wheel-failure\"\nbelow = 1.0\n",
            "criteria[0].fault",
            &["missing"],
            "[[criteria]]",
        ),
        (
            "quantity = \"fsw_value\"\nstream = \"acs\"\nvalue = \"rate_b_rad_s[3]\"\n\
             statistic = \"max\"\nbelow = 1.0\n",
            "criteria[0].value",
            &["element 3 of a value of 3"],
            "value =",
        ),
        (
            "quantity = \"fsw_value\"\nstream = \"acs\"\nvalue = \"rate\"\nstatistic = \"max\"\nbelow = 1.0\n",
            "criteria[0].value",
            &["\"rate\" is not a value of stream \"acs\"", "rate_b_rad_s, wheel_momentum_b_nms, fdir_flags"],
            "value =",
        ),
        (
            "quantity = \"fsw_value\"\nstream = \"acs\"\nvalue = \"rate_b_rad_s\"\nbelow = 1.0\n",
            "criteria[0].statistic",
            &["missing", "needs one of"],
            "quantity =",
        ),
        // A vector's length is ≥ 0; one element may be judged against a negative bound.
        (
            "quantity = \"fsw_value\"\nstream = \"acs\"\nvalue = \"rate_b_rad_s\"\n\
             statistic = \"final\"\nbelow = -1.0\n",
            "criteria[0].below",
            &["must be > 0", "could never pass"],
            "below = -1.0",
        ),
        (
            "quantity = \"fsw_event_time\"\nstream = \"acs\"\nevent = \"wheel-failure\"\n\
             statistic = \"max\"\nbelow = 1.0\n",
            "criteria[0].statistic",
            &["does not apply to quantity \"fsw_event_time\"", "one time per run"],
            "statistic =",
        ),
        (
            "quantity = \"omega\"\nstream = \"acs\"\nstatistic = \"max\"\nbelow = 1.0\n",
            "criteria[0].stream",
            &["does not apply to quantity \"omega\""],
            "stream =",
        ),
        (
            "quantity = \"station_error\"\nstation_h_m = [0.0, -100.0, 0.0]\nstatistic = \"max\"\nbelow = 1.0\n",
            "criteria[0].quantity",
            &["a fleet deputy's quantity", "a single spacecraft has no chief"],
            "quantity =",
        ),
        (
            "quantity = \"fsw_modes\"\nstatistic = \"max\"\nbelow = 1.0\n",
            "criteria[0].quantity",
            &["\"fsw_modes\" is not one of", "\"fsw_mode_entry\"", "\"chief_pointing\""],
            "quantity =",
        ),
    ];
    for (body, field, says, marker) in rows {
        let text = crit(body);
        let e = plan_error(&text);
        let head = format!("test-campaign.toml: {field}: ");
        assert!(e.starts_with(&head), "{field}: {e}");
        for w in *says {
            assert!(e.contains(w), "{field}: no `{w}`: {e}");
        }
        let at = format!("line {}, column ", line_of(&text, marker));
        assert!(e.contains(&at), "{field}: not at {at}: {e}");
    }
    // The embedded default declares no stream: said so.
    let e = plan_error(
        "runs = 1\nseed = 1\nduration_s = 1.0\n[[criteria]]\nname = \"c\"\n\
         quantity = \"fsw_event_time\"\nstream = \"acs\"\nevent = \"x\"\nbelow = 1.0\n",
    );
    assert!(
        e.contains("the base configuration has no [[fsw_streams]]"),
        "{e}"
    );

    // Valid ones resolve to the declaration's indices.
    let text = crit(
        "quantity = \"fsw_event_latency\"\nstream = \"acs\"\nevent = \"wheel-failure\"\n\
         fault = \"faults[1]\"\nbelow = 1.0\n\
         [[criteria]]\nname = \"d\"\nquantity = \"fsw_value\"\nstream = \"acs\"\n\
         value = \"wheel_momentum_b_nms[2]\"\nstatistic = \"max\"\nafter_s = 5.0\nbelow = -0.5\n",
    );
    let plan = campaign(&text).unwrap();
    let c = &plan.campaign.criteria;
    assert_eq!(
        (c[0].quantity, c[0].statistic),
        (Quantity::FswEventLatency, Statistic::Once)
    );
    let f = c[0].fsw.as_ref().unwrap();
    assert_eq!(
        f.target,
        FswTarget::Event {
            index: 1,
            fault: Some(1)
        }
    );
    assert_eq!(c[0].unit(), "s");
    let f = c[1].fsw.as_ref().unwrap();
    assert_eq!(
        f.target,
        FswTarget::Value {
            index: 1,
            element: Some(2)
        }
    );
    assert_eq!(
        (c[1].after_s, c[1].below, c[1].unit().as_str()),
        (5.0, -0.5, "N·m·s")
    );
}
