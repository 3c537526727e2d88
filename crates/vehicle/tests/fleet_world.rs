//! The world of vehicles (issue 22): each vehicle's motion in a [`World`] is the motion it has
//! alone, bit for bit; and the fleet file's errors name the vehicle and the field.

use std::path::Path;

use flexdyn_testkit::fleets::LEO_PAIR;
use flexdyn_vehicle::sim::Simulation;
use flexdyn_vehicle::world::{FleetConfig, World};

const SCENARIOS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenarios");

/// The LEO pair flown `frames` 100 Hz frames (1 ms steps) as a [`World`], each vehicle's
/// environment on its own prefetch worker if `offload` (the server's way), beside each vehicle
/// flown alone; asserts that every vehicle's state and environment sample are the ones it has
/// alone, bit for bit, and returns the world.
fn fly_beside_alone(offload: bool, frames: usize) -> World {
    let fleet = FleetConfig::from_toml_str_in(LEO_PAIR, Path::new(SCENARIOS)).unwrap();
    let mut world = World::new(&fleet).unwrap();
    if offload {
        for v in world.vehicles_mut() {
            v.sim.offload_environment().unwrap();
        }
    }
    let mut alone: Vec<Simulation> = fleet
        .vehicles
        .iter()
        .map(|v| Simulation::new(&v.cfg).unwrap())
        .collect();
    for _ in 0..frames {
        world.step_frame();
        for sim in &mut alone {
            sim.step_frame();
        }
    }
    for (v, sim) in world.vehicles().iter().zip(&alone) {
        assert_eq!(v.sim.t_sim_ns(), frames as u64 * 10_000_000);
        let (in_world, flown_alone) = (v.sim.spacecraft(), sim.spacecraft());
        assert_eq!(in_world.state(), flown_alone.state(), "{}", v.id);
        assert_eq!(
            in_world.environment(),
            flown_alone.environment(),
            "{}",
            v.id
        );
    }
    world
}

#[test]
fn each_vehicle_moves_as_it_would_alone() {
    // 1.5 s.
    let world = fly_beside_alone(false, 150);
    for v in world.vehicles() {
        // The sample is a real one (the Sun, B and the density are on), not a blank.
        let env = v.sim.spacecraft().environment();
        assert_eq!(env.t_sim_ns, 1_400_000_000);
        assert!(env.density_kg_m3 > 0.0 && env.b_field_n_t.norm() > 1e-5);
    }
    // The two vehicles differ (the deputy is where the fleet file put it, not on the chief).
    let rel = world.relative_state(0, 1).unwrap();
    assert!((rel.range_m - 102.0).abs() < 1.0, "{rel:?}");
    // The Earth's orientation, the Sun and the Moon were evaluated once per update instant for
    // both: the 14 updates after t = 0 (at 100 ms … 1400 ms; the one at t = 0 is made as each
    // vehicle is built, before the world shares) each missed once (the chief, first in fleet
    // order) and hit once (the deputy). The states above are still each vehicle's alone.
    assert_eq!(world.common_environment_counts(), Some((14, 14)));
}

/// The same with every vehicle's environment on its own prefetch worker (the server's way):
/// the workers race for the shared part, and the states stay each vehicle's alone, bit for bit.
#[test]
fn sharing_the_environment_between_workers_changes_no_bit() {
    // 3 s.
    let world = fly_beside_alone(true, 300);
    // 29 update instants (100 ms … 2900 ms), each asked for by two vehicles at least once (by a
    // worker, or by the physics thread when a worker had not answered yet).
    let (hits, misses) = world.common_environment_counts().unwrap();
    assert!(hits + misses >= 58, "{hits} hits, {misses} misses");
    assert!(misses >= 29, "{hits} hits, {misses} misses");
}

/// The error of `text` (spacecraft files relative to the scenarios folder).
fn error_of(text: &str) -> String {
    match FleetConfig::from_toml_str_in(text, Path::new(SCENARIOS)) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn fleet_errors_name_the_vehicle_and_the_field() {
    let deputy = |extra: &str| {
        format!(
            "[[vehicles]]\nid = \"chief\"\nspacecraft_file = \"leo_environment.toml\"\n\n\
             [[vehicles]]\nid = \"deputy\"\n{extra}"
        )
    };
    let cases: [(String, &str); 8] = [
        (
            deputy("spacecraft_file = \"leo_environment.toml\"\ncolour = 3\n"),
            "vehicles[1] (\"deputy\").colour: unknown key",
        ),
        (
            deputy("spacecraft_file = \"no_such_file.toml\"\n"),
            "vehicles[1] (\"deputy\").spacecraft_file `",
        ),
        (
            deputy(""),
            "vehicles[1] (\"deputy\").spacecraft_file: missing",
        ),
        (
            deputy(
                "spacecraft_file = \"leo_environment.toml\"\n[vehicles.relative]\nchief = \
                 \"mothership\"\n",
            ),
            "vehicles[1] (\"deputy\").relative.chief: \"mothership\" is not the id of an \
             earlier vehicle",
        ),
        (
            deputy(
                "spacecraft_file = \"leo_environment.toml\"\n[vehicles.relative]\nchief = \
                 \"chief\"\nhill_position_m = [1.0, 2.0]\n",
            ),
            "vehicles[1] (\"deputy\").relative.hill_position_m: must be an array of 3 finite",
        ),
        (
            deputy("spacecraft_file = \"leo_environment.toml\"\nparticipants = [2, 2]\n")
                .replace("id = \"deputy\"", "id = \"chief\""),
            "vehicles[1] (\"chief\").id: \"chief\" is already the id of vehicles[0]",
        ),
        (
            deputy("spacecraft_file = \"leo_environment.toml\"\nparticipants = [2, 2]\n"),
            "vehicles[1] (\"deputy\").participants: sender id 2 is listed twice",
        ),
        (
            // An inline spacecraft configuration without its [gravity] table: the vehicle, then
            // the configuration's own field.
            deputy("[vehicles.spacecraft]\nsimulation = { step_s = 0.001, frame_hz = 100.0 }\n"),
            "vehicles[1] (\"deputy\").spacecraft: ",
        ),
    ];
    for (text, expected) in &cases {
        let msg = error_of(text);
        assert!(
            msg.starts_with(expected),
            "expected `{expected}…`, got `{msg}`"
        );
    }
    // The inline configuration's own error names its field.
    let msg = error_of(&cases[7].0);
    assert!(msg.contains("gravity: missing required key"), "{msg}");
}

#[test]
fn vehicles_that_cannot_share_a_tick_are_refused() {
    let leo = std::fs::read_to_string(format!("{SCENARIOS}/leo_environment.toml")).unwrap();
    let dir = std::env::temp_dir().join(format!("flexdyn-fleet-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("a.toml"), &leo).unwrap();
    std::fs::write(
        dir.join("b.toml"),
        leo.replace("frame_hz = 100.0", "frame_hz = 50.0"),
    )
    .unwrap();
    let fleet_path = dir.join("fleet.toml");
    std::fs::write(
        &fleet_path,
        "[[vehicles]]\nid = \"a\"\nspacecraft_file = \"a.toml\"\n\n[[vehicles]]\nid = \"b\"\n\
         spacecraft_file = \"b.toml\"\n",
    )
    .unwrap();
    let err = FleetConfig::from_file(&fleet_path).unwrap_err().to_string();
    assert!(
        err.starts_with("vehicles[1] (\"b\").spacecraft.simulation.frame_hz: the frame period"),
        "{err}"
    );
    // The same files with one frame rate: read by path, relative to the fleet file's folder.
    std::fs::write(dir.join("b.toml"), &leo).unwrap();
    let fleet = FleetConfig::from_file(&fleet_path).unwrap();
    assert_eq!(fleet.vehicles.len(), 2);
    assert_eq!(fleet.vehicles[1].spacecraft_id, 2);
    std::fs::remove_dir_all(&dir).unwrap();
}
