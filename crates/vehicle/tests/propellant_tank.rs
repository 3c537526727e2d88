//! Propellant tanks from the configuration file: `scenarios/depletion.toml` builds its tanks
//! and the thrusters that draw from them, its scheduled burns use the closed-form propellant,
//! stepping while firing allocates nothing, and a bad entry gives one error naming its field
//! path, its line and the problem.

use flexdyn_dynamics::dynamic_effectors::thruster::G0_M_S2;
use flexdyn_dynamics::effectors::propellant_tank;
use flexdyn_testkit::alloc_counter::allocations;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

fn scenario_text() -> String {
    std::fs::read_to_string(std::path::Path::new(crate::REPO).join("scenarios/depletion.toml"))
        .unwrap()
}

/// The effector order puts the tanks after the other bodies and before the actuators; the
/// propellant counts in the total mass (950 kg of the reference vehicle + 120 + 8 kg).
#[test]
fn depletion_scenario_builds_tanks_and_fed_thrusters() {
    let cfg = SimConfig::from_toml_str(&scenario_text()).unwrap();
    let sc = cfg.build_spacecraft().unwrap();
    let (pair, tank, thruster) = ("panel_pair", propellant_tank::KIND.name, "thruster");
    let want = [pair, pair, tank, tank, thruster, thruster, thruster];
    assert_eq!(crate::effector_kind_names(&sc), want);
    assert_eq!(cfg.total_mass_kg(), 950.0 + 128.0);
    let names: Vec<_> = sc
        .dynamic_effectors()
        .iter()
        .filter_map(|e| e.propellant_tank())
        .collect();
    assert_eq!(names, ["main", "rcs", "rcs"]);
}

/// The scenario's burns: the engine (22 N, I_sp 230 s, build-up 0.05 s, tail-off 0.08 s) open
/// from 5 s to 65 s; with the lag its thrust integral is F (t − (τ_r − τ_f)(1 − e^(−t/τ_r)))
/// = 22 (60 + 0.03) N s once the tail has died (by 75 s, e^(−10/0.08) is nothing), so "main"
/// loses 22 · 60.03/(230 g₀) kg. The RCS couple, 1 N each at I_sp 220 s for 2 s (no lag),
/// takes 2 · 2/(220 g₀) kg from "rcs". Stepping through the firing allocates nothing.
#[test]
fn depletion_scenario_burns_the_closed_form_propellant_without_allocating() {
    let cfg = SimConfig::from_toml_str(&scenario_text()).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let frames = |s: f64| (s * 100.0).round() as usize;
    for _ in 0..frames(6.0) {
        sim.step_frame();
    }
    let before = allocations();
    for _ in 0..frames(0.5) {
        sim.step_frame();
    }
    assert_eq!(
        allocations() - before,
        0,
        "stepping a firing engine allocated"
    );
    for _ in 0..frames(68.5) {
        sim.step_frame();
    }
    let sc = sim.spacecraft();
    let x = &sc.state().effectors;
    let (main, rcs) = (
        x[sc.effector_ranges()[2].start],
        x[sc.effector_ranges()[3].start],
    );
    let main_want = 22.0 * (60.0 + 0.03) / (230.0 * G0_M_S2);
    let rcs_want = 2.0 * 2.0 / (220.0 * G0_M_S2);
    eprintln!(
        "main used {} kg (closed form {main_want}), rcs used {} kg (closed form {rcs_want})",
        120.0 - main,
        8.0 - rcs
    );
    // Round-off of 75 000 steps adding decrements to 120 kg and 8 kg (steps · ε · m).
    assert!(((120.0 - main) - main_want).abs() <= 75_000.0 * f64::EPSILON * 120.0);
    assert!(((8.0 - rcs) - rcs_want).abs() <= 75_000.0 * f64::EPSILON * 8.0);
}

/// Each bad entry: the scenario's text with one replacement, and what the one error must say.
#[test]
fn propellant_tank_config_errors_name_the_field_line_and_problem() {
    let text = scenario_text();
    let cases = [
        (
            "tank = \"main\"",
            "tank = \"mian\"",
            "thrusters[0].tank",
            "no [[propellant_tanks]] entry is named `mian`",
        ),
        (
            "propellant_mass_kg = 8.0",
            "propellant_mass_kg = -8.0",
            "propellant_tanks[1].propellant_mass_kg",
            "",
        ),
        (
            "radius_m = 0.15",
            "radius_m = 0.15\ndensity_kg_m3 = 1000.0",
            "propellant_tanks[1].density_kg_m3",
            "does not take",
        ),
        (
            "inertia_model = \"constant_volume\"\nradius_m",
            "inertia_model = \"sloshing\"\nradius_m",
            "propellant_tanks[1].inertia_model",
            "constant_volume, constant_density",
        ),
        (
            "density_kg_m3 = 1004.0",
            "density_kg_m3 = 0.0",
            "propellant_tanks[0].density_kg_m3",
            "",
        ),
    ];
    for msg in crate::config_error_cases(&text, &cases) {
        assert!(msg.contains("line"), "no line: {msg}");
    }
}
