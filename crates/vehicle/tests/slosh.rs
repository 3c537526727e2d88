//! Fuel slosh from the configuration file: `scenarios/slosh.toml` builds its two tanks from their
//! fill levels, stepping them allocates nothing, and a bad entry gives one error naming its
//! field path, its line and the problem.

use flexdyn_dynamics::effectors::{slosh_linear, slosh_pendulum};
use flexdyn_dynamics::slosh_tank::CylindricalTank;
use flexdyn_testkit::alloc_counter::allocations;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::Vector3;

fn scenario_text() -> String {
    std::fs::read_to_string(std::path::Path::new(crate::REPO).join("scenarios/slosh.toml")).unwrap()
}

fn tank(fill_height_m: f64, x_m: f64) -> CylindricalTank {
    CylindricalTank {
        radius_m: 0.4,
        fill_height_m,
        density_kg_m3: 1004.0,
        r_bottom_b_m: Vector3::new(x_m, 0.0, -0.5),
        axis_b: Vector3::z(),
    }
}

/// The parameters read back from the built effectors are those of the tanks' first modes.
#[test]
fn slosh_scenario_takes_its_parameters_from_the_fill_levels() {
    let cfg = SimConfig::from_toml_str(&scenario_text()).unwrap();
    let sc = cfg.build_spacecraft().unwrap();
    assert_eq!(
        crate::effector_kind_names(&sc),
        [
            "panel_pair",
            "panel_pair",
            slosh_linear::KIND.name,
            slosh_pendulum::KIND.name
        ]
    );
    let read_back = |i: usize| {
        let mut out = Vec::new();
        let r = sc.effector_ranges()[i].clone();
        sc.effectors()[i].parameters(&sc.state().effectors[r], &mut out);
        move |key: &str| {
            out.iter()
                .find(|(k, _)| k == key)
                .unwrap_or_else(|| panic!("no parameter {key}"))
                .1
        }
    };
    let linear = tank(0.5, 0.6).first_mode();
    let p = read_back(2);
    assert_eq!(p("mass_kg"), linear.slosh_mass_kg);
    assert_eq!(p("k_n_m"), linear.k_n_m(0.02));
    assert_eq!(p("r_pb_b_m[2]"), -0.5 + linear.slosh_height_m);
    assert_eq!(p("rho_m"), 0.01);
    let pendulum = tank(0.3, -0.6).first_mode();
    let p = read_back(3);
    assert_eq!(p("mass_kg"), pendulum.slosh_mass_kg);
    assert_eq!(p("l_m"), pendulum.pendulum_length_m);
    assert_eq!(p("r_pb_b_m[2]"), -0.5 + pendulum.hinge_height_m);
    assert_eq!(p("hang_axis_b[2]"), -1.0);
    // The slosh masses count in the vehicle's total mass (the summary's).
    assert_eq!(
        cfg.total_mass_kg(),
        950.0 + linear.slosh_mass_kg + pendulum.slosh_mass_kg
    );
    // 89.9 kg and 80.8 kg, as the scenario's header says.
    assert!((linear.slosh_mass_kg - 89.93).abs() < 0.01);
    assert!((pendulum.slosh_mass_kg - 80.85).abs() < 0.01);
}

/// Stepping frames of the slosh scenario allocates nothing.
#[test]
fn stepping_slosh_allocates_nothing() {
    let cfg = SimConfig::from_toml_str(&scenario_text()).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    sim.step_frame();
    let before = allocations();
    for _ in 0..20 {
        sim.step_frame();
    }
    assert_eq!(allocations() - before, 0, "slosh stepping allocated");
    let x = &sim.spacecraft().state().effectors;
    assert!(x[8..].iter().all(|v| v.is_finite()));
    assert!(x[8] != 0.01, "the particle did not move");
}

/// Each bad entry: the scenario's text with one replacement, and what the one error must say.
#[test]
fn slosh_config_errors_name_the_field_line_and_problem() {
    let text = scenario_text();
    let cases = [
        (
            "settling_accel_m_s2 = 0.02 }",
            "settling_accel_m_s2 = 0.02 }\nmass_kg = 3.0",
            "slosh_linear[0].mass_kg",
            "not both",
        ),
        (
            "fill_height_m = 0.3,",
            "fill_height_m = -0.3,",
            "slosh_pendulums[0].tank.fill_height_m",
            "",
        ),
        (
            "radius_m = 0.4, fill_height_m = 0.5",
            "radius = 0.4, fill_height_m = 0.5",
            "slosh_linear[0].tank.radius",
            "unknown key",
        ),
        (
            "p_hat_b = [1.0, 0.0, 0.0]",
            "p_hat_b = [0.0, 0.0, 1.0]",
            "slosh_linear[0].p_hat_b",
            "perpendicular",
        ),
        (
            "theta_rad = -0.03\n",
            "theta_rad = -1.5\n",
            "slosh_pendulums[0].theta_rad",
            "singular",
        ),
        (
            "c_nm_s_rad = 0.0 ",
            "c_nm_s_rad = -1.0 ",
            "slosh_pendulums[0].c_nm_s_rad",
            "",
        ),
    ];
    for msg in crate::config_error_cases(&text, &cases) {
        assert!(!msg.contains("Slosh"), "names a Rust type: {msg}");
    }
}
