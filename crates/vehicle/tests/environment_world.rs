//! The world wired end to end from a configuration (`scenarios/leo_environment.toml`'s epoch
//! and OMM orbit): the environment sample the simulation hands the dynamic effectors is the
//! models' chain at the sampled instant, and the spacecraft feels it — the residual-dipole
//! torque is m × [BN]B, and drag takes out of the vehicle's energy exactly the work of the
//! facet force at the sampled density.

use flexdyn_environment::earth_rotation::EarthRotation;
use flexdyn_environment::facets::FacetModel;
use flexdyn_environment::magnetic::Igrf;
use flexdyn_environment::prefetch::Request;
use flexdyn_kernel::attitude::mrp_to_dcm;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::Vector3;

/// The LEO scenario's simulation, gravity, epoch, orbit and initial attitude, with a rigid hub
/// (no panels, so the hub inertia about its centre of mass is the vehicle's) and `environment`
/// as the `[environment]` table.
fn rigid_leo(environment: &str) -> SimConfig {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/leo_environment.toml"
    );
    let leo = std::fs::read_to_string(path).unwrap();
    let head = &leo[..leo.find("[environment]").unwrap()];
    let text = format!(
        "panel_pairs = []\n{head}\n{environment}\n[hub]\nmass_kg = 750.0\n\
         inertia_bc_b_kg_m2 = [[900.0, 10.0, -5.0], [10.0, 800.0, 3.0], [-5.0, 3.0, 600.0]]\n\
         r_bcb_b_m = [0.0, 0.0, 1.0]\n"
    );
    SimConfig::from_toml_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

#[test]
fn residual_dipole_torque_is_m_cross_bn_b_at_the_sampled_field() {
    let cfg = rigid_leo(
        "[environment]\nupdate_hz = 10.0\nmagnetic = \"igrf14\"\n\
         residual_dipole_m_b_am2 = [0.3, -0.2, 0.5]\n",
    );
    let mut sim = Simulation::new(&cfg).unwrap();
    // 1.1 s of 1 ms steps: the update at t = 1.1 s predicts the position for the next one, at
    // 1.2 s, from this state (`environment::prefetch::Request::predicted`); 0.1 s later the
    // next step starts with that update.
    sim.step_n(1100);
    let x = sim.spacecraft().state();
    let t_ns = 1_200_000_000;
    let r_bn_n_m = Request::predicted(sim.t_sim_ns(), &x.r_bn_n, &x.v_bn_n, t_ns).r_bn_n_m;
    sim.step_n(100);
    assert_eq!(sim.t_sim_ns(), t_ns);
    // The prediction is the actual position to ½|J2|Δ² ≤ 1.2e-4 m (a rigid hub, no panels).
    assert!((r_bn_n_m - sim.spacecraft().state().r_bn_n).norm() < 1.2e-4);
    sim.step();
    let sample = *sim.spacecraft().environment();
    assert_eq!(sample.t_sim_ns, t_ns);

    // The chain, rebuilt here from the models: epoch → Earth rotation → r in E → IGRF → N.
    let epoch = cfg.epoch.as_ref().unwrap();
    let times = epoch.times(t_ns);
    let earth = EarthRotation::new(epoch.earth_orientation()).at(&times);
    let year = epoch.utc_calendar(t_ns).decimal_year();
    let b_e_t = Igrf::igrf14(13)
        .unwrap()
        .field_ecef_t(year, &earth.r_e(&r_bn_n_m));
    let b_n_t = earth.dcm_ne() * b_e_t;
    assert!(
        (sample.b_field_n_t - b_n_t).norm() <= 1e-12 * b_n_t.norm(),
        "{:?} vs {b_n_t:?}",
        sample.b_field_n_t
    );
    // At 500 km the field is the surface's 22–67 µT times (6378/6878)³ = 0.80: 18–54 µT.
    let b_ut = sample.b_field_n_t.norm() * 1e6;
    assert!((18.0..54.0).contains(&b_ut), "|B| = {b_ut} µT");
    // The held sample is not the field at the moved spacecraft: the rotation was done with
    // the position predicted for t = 1.2 s, and the sample keeps it (zero-order hold).

    // Torque: ω̇ with the field minus ω̇ with no field, at the same state, is I⁻¹ (m × [BN]B)
    // (a pure couple on a rigid body: no ω × Iω difference, no translation coupling).
    let sc = sim.spacecraft_mut();
    let with_field = sc.hub_outputs().omega_dot_bn_b;
    let mut no_field = sample;
    no_field.b_field_n_t = Vector3::zeros();
    sc.set_environment(&no_field);
    let without = sc.hub_outputs().omega_dot_bn_b;
    let dcm_bn = mrp_to_dcm(&sc.state().sigma_bn);
    let m_b_am2 = Vector3::new(0.3, -0.2, 0.5);
    let torque_b_nm = m_b_am2.cross(&(dcm_bn * sample.b_field_n_t));
    let expected = cfg.hub.inertia_bc_b_kg_m2.try_inverse().unwrap() * torque_b_nm;
    let got = with_field - without;
    assert!(
        (got - expected).norm() <= 1e-9 * expected.norm(),
        "Δω̇ = {got:?}, I⁻¹ (m × B) = {expected:?}"
    );
    // A 0.6 A·m² dipole in ~30 µT: a torque of order 1e-5 N·m.
    assert!(
        (1e-6..1e-4).contains(&torque_b_nm.norm()),
        "{torque_b_nm:?}"
    );
}

#[test]
fn drag_takes_out_the_work_of_the_facet_force() {
    const FACETS: &str = "\n[[environment.facets]]\narea_m2 = 4.0\nnormal_b = [0.6, 0.8, 0.0]\n\
        r_cp_b_m = [0.3, 0.0, 1.0]\ndrag_coefficient = 2.2\nabsorbed = 0.4\nspecular = 0.3\n\
        diffuse = 0.3\n\n[[environment.facets]]\narea_m2 = 4.0\nnormal_b = [-0.6, -0.8, 0.0]\n\
        r_cp_b_m = [-0.3, 0.0, 1.0]\ndrag_coefficient = 2.2\nabsorbed = 0.4\nspecular = 0.3\n\
        diffuse = 0.3\n";
    let air = "[environment]\nupdate_hz = 100.0\natmosphere = \"nrlmsise00\"\nf107_sfu = 150.0\n\
               f107a_sfu = 150.0\nap = 15.0\n";
    let with_drag = rigid_leo(&format!("{air}drag = true\n{FACETS}"));
    let no_drag = rigid_leo(&format!("{air}{FACETS}"));
    let mut a = Simulation::new(&with_drag).unwrap();
    let mut b = Simulation::new(&no_drag).unwrap();
    assert_eq!(a.spacecraft().dynamic_effectors().len(), 1);
    assert_eq!(b.spacecraft().dynamic_effectors().len(), 0);
    let energy = |s: &Simulation| {
        let c = s.spacecraft().conserved();
        c.orb_energy_j + c.rot_energy_j
    };
    // The power of the drag force on B and its torque, F·v_B + τ·ω, at the start: the sample
    // (density, wind) is filled by the first step.
    a.step();
    b.step();
    let facets = FacetModel::new(with_drag.environment.as_ref().unwrap().facets.clone()).unwrap();
    let power_w = |s: &Simulation| {
        let x = s.spacecraft().state();
        let env = s.spacecraft().environment();
        let dcm_bn = mrp_to_dcm(&x.sigma_bn);
        let w = facets.drag_wrench_b(&(dcm_bn * (x.v_bn_n - env.wind_n_m_s)), env.density_kg_m3);
        w.force_b_newton.dot(&(dcm_bn * x.v_bn_n)) + w.torque_b_nm.dot(&x.omega_bn_b)
    };
    let p0_w = power_w(&a);
    let rho = a.spacecraft().environment().density_kg_m3;
    // NRLMSISE-00 at ~500 km with F10.7 = 150: a few 1e-13 kg/m³.
    assert!((1e-13..3e-12).contains(&rho), "density {rho}");
    assert!(p0_w < 0.0, "drag must take energy out: {p0_w} W");
    let e0 = energy(&a) - energy(&b);
    a.step_n(999);
    b.step_n(999);
    let p1_w = power_w(&a);
    let lost_j = energy(&a) - energy(&b) - e0;
    // Work over 0.999 s by the trapezoid rule on the power at both ends; the power changes by
    // parts per thousand over the second (density along 7.6 km of track, a slow rotation).
    let work_j = 0.5 * (p0_w + p1_w) * 0.999;
    eprintln!(
        "drag: density {rho:e} kg/m³, power {p0_w} W, energy lost {lost_j} J, work {work_j} J"
    );
    assert!(
        (lost_j - work_j).abs() <= 0.005 * work_j.abs(),
        "energy lost {lost_j} J, drag work {work_j} J"
    );
}
