//! The environment models' per-call functions allocate nothing once their models are built (the
//! stepping loop's rule). A counting global allocator, per thread, checks it.

use flexdyn_testkit::alloc_counter::allocations;

use std::hint::black_box;

use flexdyn_environment::atmosphere::{
    exponential_density_kg_m3, velocity_relative_to_air_n_m_s, Nrlmsise00Model, SpaceWeather,
};
use flexdyn_environment::ephemeris::{moon_position_n_m, sun_position_n_m};
use flexdyn_environment::facets::{solar_pressure_n_m2, Facet, FacetModel};
use flexdyn_environment::geodetic::{dcm_ned_ecef, geodetic_from_ecef};
use flexdyn_environment::magnetic::{dipole_torque_b_nm, CentredDipole, Igrf};
use flexdyn_environment::shadow::{shadow_factor, ShadowModel};
use nalgebra::Vector3;

#[test]
fn per_call_functions_do_not_allocate() {
    // Built once, outside the counted region.
    let igrf = Igrf::igrf14(13).unwrap();
    let msis = Nrlmsise00Model::new(SpaceWeather {
        f107_sfu: 150.0,
        f107a_sfu: 150.0,
        ap: 15.0,
    })
    .unwrap();
    let facets = FacetModel::new(
        (0..6)
            .map(|i| Facet {
                area_m2: 1.0,
                normal_b: if i % 2 == 0 { 1.0 } else { -1.0 } * Vector3::ith(i / 2, 1.0),
                r_cp_b_m: Vector3::new(0.1, 0.2, 0.3),
                drag_coefficient: 2.2,
                absorbed: 0.6,
                specular: 0.3,
                diffuse: 0.1,
            })
            .collect(),
    )
    .unwrap();
    let r = Vector3::new(6.0e6, 2.0e6, 3.0e6);
    let v = Vector3::new(-2.0e3, 7.0e3, 0.5e3);
    let omega = Vector3::new(0.0, 0.0, 7.292_115e-5);

    let before = allocations();
    for i in 0..100 {
        let t = 0.25 + f64::from(i) * 1e-5;
        let sun = sun_position_n_m(t);
        black_box(moon_position_n_m(t));
        let nu = shadow_factor(ShadowModel::Conical, &r, &sun);
        black_box(shadow_factor(ShadowModel::Cylindrical, &r, &sun));
        let c = igrf.coefficients_at(2025.3);
        let b = c.field_ecef_t(&r);
        black_box(igrf.field_ecef_t(2025.3, &r));
        black_box(CentredDipole::tilted(&c).field_ecef_t(&r));
        black_box(dipole_torque_b_nm(&Vector3::new(0.1, 0.0, 0.0), &b));
        let g = geodetic_from_ecef(&r);
        black_box(dcm_ned_ecef(g.lat_rad, g.lon_rad));
        let rho =
            exponential_density_kg_m3(g.height_m) + msis.state(100, 3600.0, &g).drag_density_kg_m3;
        let v_rel = velocity_relative_to_air_n_m_s(&r, &v, &omega);
        black_box(facets.drag_wrench_b(&v_rel, rho));
        let p = solar_pressure_n_m2((sun - r).norm(), nu, 1361.0);
        black_box(facets.srp_wrench_b(&(sun - r), p));
    }
    let after = allocations();
    assert_eq!(
        after - before,
        0,
        "allocations in the per-call environment functions"
    );
}

/// The stepping hot path with every environment model and dynamic effector on
/// (`scenarios/leo_environment.toml`): 2 s of 1 ms steps, 20 environment updates (10 Hz), no
/// allocation once built.
#[test]
fn stepping_with_every_model_on_allocates_nothing() {
    let path = std::path::Path::new(crate::REPO).join("scenarios/leo_environment.toml");
    let cfg = flexdyn_vehicle::config::SimConfig::from_file(&path).unwrap();
    let mut sim = flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap();
    assert_eq!(sim.spacecraft().dynamic_effectors().len(), 4);
    sim.step();
    let before = allocations();
    sim.step_n(2000);
    let after = allocations();
    assert_eq!(
        after - before,
        0,
        "allocations while stepping with the environment on"
    );
    // The models did run: a field, a Sun, a density.
    let env = sim.spacecraft().environment();
    assert_eq!(env.t_sim_ns, 2_000_000_000);
    assert!(env.b_field_n_t.norm() > 1e-5, "{env:?}");
    assert!(
        env.density_kg_m3 > 0.0 && env.r_sun_b_n_m.norm() > 1e11,
        "{env:?}"
    );
}

/// The same with the updates offloaded to the environment worker (the server's default): the
/// stepping thread posts requests and takes answers without allocating (the worker's own
/// allocations, if any, are on its thread and not counted here).
#[test]
fn stepping_with_offloaded_updates_allocates_nothing() {
    let path = std::path::Path::new(crate::REPO).join("scenarios/leo_environment.toml");
    let cfg = flexdyn_vehicle::config::SimConfig::from_file(&path).unwrap();
    let mut sim = flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap();
    sim.offload_environment().unwrap();
    sim.step();
    let before = allocations();
    for update in 0..20 {
        // Wait for the worker's answer to the request posted at the last update, so the answer
        // path is the one counted (a fixed sleep is not enough on a loaded machine).
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
        while !sim.environment().unwrap().prefetch_answer_ready() {
            assert!(
                std::time::Instant::now() < deadline,
                "the worker did not answer the request before update {update} within 10 s"
            );
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
        // 100 steps of 1 ms: exactly one 10 Hz update (at the last of them, t = 100 ms · (update + 1)).
        sim.step_n(100);
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations while stepping, offloaded");
    // Every one of the 20 updates took the worker's answer (the first update, in `sim.step()`
    // above, was evaluated at the actual state: it has no prediction).
    let taken = sim.environment().unwrap().prefetched_samples();
    assert_eq!(taken, 20, "{taken} of 20 updates came from the worker");
}
