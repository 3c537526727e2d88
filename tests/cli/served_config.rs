//! Flight code reads the vehicle from the server's `flexdyn/<sc>/config` queryable with its own
//! small reader (`flexdyn_proto::client::vehicle`, no simulator), and learns from it which sensor
//! samples each tick carries (`flexdyn_proto::client::lockstep::SensorSchedule`). For every shipped
//! scenario, that reader must agree with the server's own (`SimConfig`) on every value it reads:
//! the frame rate, the hub, the panel pairs, the wheels, the IMUs and the star trackers with
//! their periods in frames.

use flexdyn_proto::client::lockstep::SensorSchedule;
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_sensors::imu::ImuConfig;
use flexdyn_sensors::star_tracker::StarTrackerConfig;
use flexdyn_vehicle::config::SimConfig;
use nalgebra::{Matrix3, Vector3};

fn m3(rows: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| rows[r][c])
}

#[test]
fn the_clients_reader_agrees_with_the_servers_on_every_scenario() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut checked = 0;
    let mut with_faults = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let Ok(sim) = SimConfig::from_file(&path) else {
            continue; // not a vehicle configuration (campaign.toml)
        };
        let name = path.display();
        let text = std::fs::read_to_string(&path).unwrap();
        let cfg = VehicleConfig::from_toml(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(cfg.simulation.frame_hz, sim.frame_hz, "{name}");
        assert_eq!(cfg.hub.mass_kg, sim.hub.mass_kg, "{name}");
        assert_eq!(
            m3(&cfg.hub.inertia_bc_b_kg_m2),
            sim.hub.inertia_bc_b_kg_m2,
            "{name}"
        );
        assert_eq!(
            Vector3::from(cfg.hub.r_bcb_b_m),
            sim.hub.r_bcb_b_m,
            "{name}"
        );
        assert_eq!(cfg.panel_pairs.len(), sim.panel_pairs.len(), "{name}");
        for (c, (s, _)) in cfg.panel_pairs.iter().zip(&sim.panel_pairs) {
            assert_eq!(c.name, s.name, "{name}");
            assert_eq!(Vector3::from(c.r_h1b_b_m), s.r_h1b_b_m, "{name}");
            assert_eq!(m3(&c.dcm_h1b), s.dcm_h1b, "{name}");
            assert_eq!(c.panel1.l_m, Some(s.l1_m), "{name}");
            for (cp, sp) in [(&c.panel1, &s.panel1), (&c.panel2, &s.panel2)] {
                assert_eq!(cp.mass_kg, sp.mass_kg, "{name}");
                assert_eq!(
                    Vector3::from(cp.inertia_s_kg_m2),
                    sp.inertia_s_kg_m2,
                    "{name}"
                );
                assert_eq!(cp.d_m, sp.d_m, "{name}");
            }
        }
        assert_eq!(
            cfg.first_wheel_index() as usize,
            sim.panel_pairs.len(),
            "{name}"
        );
        assert_eq!(
            cfg.reaction_wheels.len(),
            sim.reaction_wheels.len(),
            "{name}"
        );
        for (c, s) in cfg.reaction_wheels.iter().zip(&sim.reaction_wheels) {
            assert_eq!(c.name, s.name, "{name}");
            let axis = Vector3::from(c.spin_axis_b).normalize();
            assert!((axis - s.spin_axis_b.normalize()).norm() < 1e-15, "{name}");
            assert_eq!(Vector3::from(c.r_wb_b_m), s.r_wb_b_m, "{name}");
            assert_eq!(
                (c.mass_kg, c.j_s_kg_m2, c.j_t_kg_m2, c.max_torque_nm),
                (s.mass_kg, s.j_s_kg_m2, s.j_t_kg_m2, s.max_torque_nm),
                "{name}"
            );
        }
        let sim_imus = sim.sensors.all::<ImuConfig>();
        assert_eq!(cfg.imus.len(), sim_imus.len(), "{name}");
        for (c, s) in cfg.imus.iter().zip(&sim_imus) {
            assert_eq!(c.name, s.name, "{name}");
            assert_eq!(m3(&c.dcm_pb), s.dcm_pb, "{name}");
            assert_eq!(Vector3::from(c.r_sb_b_m), s.r_sb_b_m, "{name}");
        }
        let schedule = SensorSchedule::from_config(&cfg).unwrap();
        let imus: Vec<&str> = sim_imus.iter().map(|i| i.name.as_str()).collect();
        assert_eq!(schedule.imus().collect::<Vec<_>>(), imus, "{name}");
        let sim_trackers = sim.sensors.all::<StarTrackerConfig>();
        let trackers: Vec<(&str, u64)> = sim_trackers
            .iter()
            .map(|s| (s.name.as_str(), s.every_frames))
            .collect();
        assert_eq!(
            schedule.star_trackers().collect::<Vec<_>>(),
            trackers,
            "{name}"
        );
        for (c, s) in cfg.star_trackers.iter().zip(&sim_trackers) {
            assert_eq!(m3(&c.dcm_cb), s.dcm_cb, "{name}");
        }
        // The faults, by index (the monitor names FaultEventMsg/StatusMsg indices with them).
        let faults: Vec<(&str, &str)> = cfg
            .faults
            .iter()
            .map(|f| (f.target.as_str(), f.mode.as_str()))
            .collect();
        let sim_faults: Vec<(&str, &str)> = sim
            .faults
            .iter()
            .map(|f| (f.target.as_str(), f.mode.name()))
            .collect();
        assert_eq!(faults, sim_faults, "{name}");
        with_faults += usize::from(!faults.is_empty());
        checked += 1;
    }
    assert!(checked >= 8, "only {checked} scenarios read");
    assert!(
        with_faults >= 1,
        "no scenario with [[faults]] (scenarios/fdir.toml has some)"
    );
}

/// What flight code reads of the served configuration names the same effector indices the
/// server lists: the chains, slosh bodies and propellant tanks after the wheels, the rods after
/// them, the thrusters after the rods, in file order; in every scenario with appended bodies of
/// the generic list.
#[test]
fn flight_code_finds_the_actuators_at_the_servers_indices() {
    for scenario in ["acs_full", "slosh", "panel_chain", "depletion"] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(format!("scenarios/{scenario}.toml"));
        let text = std::fs::read_to_string(&path).unwrap();
        let vehicle = flexdyn_proto::client::vehicle::VehicleConfig::from_toml(&text).unwrap();
        let sc = SimConfig::from_toml_str(&text)
            .unwrap()
            .build_spacecraft()
            .unwrap();
        let entries: Vec<_> = sc.effector_entries().collect();
        let kinds_at = |first: u32, n: usize| -> Vec<&str> {
            entries[first as usize..first as usize + n]
                .iter()
                .map(|e| e.kind.name)
                .collect()
        };
        assert!(
            kinds_at(vehicle.first_chain_index(), vehicle.panel_chains.len())
                .iter()
                .all(|k| *k == "panel_chain"),
            "{scenario}"
        );
        let slosh = kinds_at(
            vehicle.first_slosh_index(),
            vehicle.slosh_linear.len() + vehicle.slosh_pendulums.len(),
        );
        let (linear, pendulums) = slosh.split_at(vehicle.slosh_linear.len());
        assert!(linear.iter().all(|k| *k == "slosh_linear"), "{scenario}");
        assert!(
            pendulums.iter().all(|k| *k == "slosh_pendulum"),
            "{scenario}"
        );
        assert!(
            kinds_at(vehicle.first_tank_index(), vehicle.propellant_tanks.len())
                .iter()
                .all(|k| *k == "propellant_tank"),
            "{scenario}"
        );
        let first_rod = vehicle.first_magnetorquer_index() as usize;
        let first_thruster = vehicle.first_thruster_index() as usize;
        for (k, rod) in vehicle.magnetorquers.iter().enumerate() {
            let e = &entries[first_rod + k];
            assert_eq!((e.kind.name, e.name), ("magnetorquer", rod.name.as_str()));
        }
        for (k, t) in vehicle.thrusters.iter().enumerate() {
            let e = &entries[first_thruster + k];
            assert_eq!(
                (e.kind.name, e.name),
                ("thruster", t.name.as_str()),
                "{scenario}"
            );
        }
        assert_eq!(
            first_thruster + vehicle.thrusters.len(),
            entries.len(),
            "{scenario}"
        );
        if scenario == "acs_full" {
            assert_eq!(
                (vehicle.magnetorquers.len(), vehicle.thrusters.len()),
                (3, 4)
            );
            assert!(vehicle
                .thrusters
                .iter()
                .all(|t| t.command.is_none() && t.min_on_time_s == 0.02));
        }
        if scenario == "slosh" {
            assert!(!vehicle.slosh_linear.is_empty() && !vehicle.slosh_pendulums.is_empty());
        }
        if scenario == "depletion" {
            assert_eq!(vehicle.propellant_tanks.len(), 2);
            assert_eq!(vehicle.thrusters[0].tank.as_deref(), Some("main"));
        }
    }
}
