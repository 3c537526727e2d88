//! `[[panel_chains]]` read through the generic component list: the shipped scenario builds, its
//! chains sit between the wheels and the actuators in the effector list with their state and
//! input names, stepping allocates nothing, and the errors name the entry, the panel and the
//! field.

use flexdyn_dynamics::effectors::panel_chain;
use flexdyn_testkit::alloc_counter::allocations;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

fn scenario() -> String {
    std::fs::read_to_string(format!("{}/scenarios/panel_chain.toml", crate::REPO)).unwrap()
}

#[test]
fn the_chain_scenario_builds_and_steps_without_allocating() {
    let cfg = SimConfig::from_toml_str(&scenario()).unwrap();
    let chain_mass: f64 = 40.0 + 32.0 + 25.0 + 18.0 + 40.0 + 32.0 + 25.0;
    assert!((cfg.total_mass_kg() - (750.0 + chain_mass)).abs() < 1e-9);
    assert!(
        cfg.summary().contains("2 panel_chains"),
        "{}",
        cfg.summary()
    );
    let mut sim = Simulation::new(&cfg).unwrap();
    let entries: Vec<_> = sim.spacecraft().effector_entries().collect();
    assert_eq!(entries.len(), 2);
    assert_eq!(entries[0].kind, panel_chain::KIND);
    assert_eq!(entries[0].state_names, &panel_chain::STATE_NAMES[..8]);
    assert_eq!(entries[1].state_names, &panel_chain::STATE_NAMES[..6]);
    assert_eq!(entries[1].input_names, &panel_chain::INPUT_NAMES[..3]);
    // Motor torques commanded like any effector input (4 for wing_px, 3 for wing_mx).
    sim.set_effector_inputs(&[0.5, 0.0, 0.0, 0.1, -0.2, 0.0, 0.0])
        .unwrap();
    let mut msg = sim.blank_state();
    sim.step_frame();
    sim.state_into(&mut msg);
    let before = allocations();
    for _ in 0..20 {
        sim.step_frame();
        sim.state_into(&mut msg);
    }
    assert_eq!(
        allocations() - before,
        0,
        "allocations while stepping chains"
    );
    assert_eq!(
        msg.effectors[0].kind,
        flexdyn_proto::effector_kind::PANEL_CHAIN
    );
    assert_eq!(msg.effectors[0].states.len(), 8);
    assert!(msg.effectors[0].states.iter().all(|v| v.is_finite()));
}

/// The scenario with `n` more panels at the end of its first chain (after its last panel's
/// `theta_dot_rad_s = 0.02`, which it gives a length so that another panel may follow).
fn with_extra_panels(text: &str, n: usize) -> String {
    // Every panel but the chain's last has a length to the next hinge.
    let panel = "\n[[panel_chains.panels]]\nmass_kg = 10.0\ninertia_s_kg_m2 = [6.0, 3.0, 4.0]\n\
                 d_m = 0.5\nk_nm_rad = 40.0\nc_nm_s_rad = 0.5\n";
    let panels = vec![panel; n].join("l_m = 1.2\n");
    text.replacen(
        "theta_dot_rad_s = 0.02\n",
        &format!("theta_dot_rad_s = 0.02\nl_m = 1.2\n{panels}"),
        1,
    )
}

/// Sixteen panels (the model's limit) are carried on the wire since protocol 11: 32 states in
/// the chain's StateMsg entry (`MAX_EFFECTOR_VALUES`), which encode and decode.
#[test]
fn a_sixteen_panel_chain_goes_on_the_wire() {
    assert_eq!(panel_chain::MAX_WIRE_LINKS, 16);
    let cfg = SimConfig::from_toml_str(&with_extra_panels(&scenario(), 12)).unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    sim.step_frame();
    let mut msg = sim.blank_state();
    sim.state_into(&mut msg);
    assert_eq!(msg.effectors[0].states.len(), 32);
    let back: flexdyn_proto::StateMsg =
        flexdyn_proto::decode(&flexdyn_proto::encode(&msg)).unwrap();
    assert_eq!(back, msg);
}

/// The configuration's errors name the entry, the panel and the field.
#[test]
fn bad_chain_entries_are_named() {
    let text = scenario();
    let cases = [
        (
            text.replacen("mass_kg = 25.0", "mass_kg = -25.0", 1),
            "panel_chains[0].panels[2].mass_kg",
        ),
        (
            text.replacen("l_m = 1.4\n", "", 1),
            "panel_chains[0].panels[1].l_m",
        ),
        (
            text.replacen("d_m = 0.65\n", "d_m = 2.0\n", 1),
            "panel_chains[0].panels[1].d_m",
        ),
        (
            text.replacen("k_nm_rad = 60.0", "k_nm_rad = 60.0\nk_nm = 1.0", 1),
            "panel_chains[0].panels[3].k_nm",
        ),
        (
            text.replacen("name = \"wing_mx\"", "name = \"wing_px\"", 1),
            "panel_chains[1].name",
        ),
        (
            // Thirteen more panels (17): beyond the model's 16, which are also the wire's
            // (MAX_EFFECTOR_VALUES = 32 states since protocol 11, two per panel).
            with_extra_panels(&text, 13),
            "panel_chains[0].panels: has 17 panels",
        ),
    ];
    for (toml, field) in cases {
        let e = SimConfig::from_toml_str(&toml).unwrap_err().to_string();
        assert!(e.contains(field), "{field}: {e}");
    }
}

/// A chain may not take a pair's name: both are drawn as `<name>/panel<k>` in the 3D scene.
#[test]
fn a_chain_named_like_a_pair_is_refused() {
    let reference =
        std::fs::read_to_string(format!("{}/scenarios/reference.toml", crate::REPO)).unwrap();
    let text = scenario();
    let chains = &text[text.find("\n[[panel_chains]]").unwrap()..];
    // The reference's pairs are wing_px and wing_mx; so are the chain scenario's chains.
    let e = SimConfig::from_toml_str(&format!("{reference}\n{chains}"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("panel_chains[0].name") && e.contains("`wing_px` is also a panel pair's name"),
        "{e}"
    );
    let renamed = chains
        .replace("\"wing_px\"", "\"boom_px\"")
        .replace("\"wing_mx\"", "\"boom_mx\"");
    SimConfig::from_toml_str(&format!("{reference}\n{renamed}")).unwrap();
}
