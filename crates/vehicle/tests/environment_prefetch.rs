//! The environment updates moved to a worker thread (`Simulation::offload_environment`, the
//! server's default) change nothing: on the LEO scenario (IGRF-14, NRLMSISE-00, Sun, Moon,
//! conical shadow, drag, solar pressure, gravity gradient, residual dipole), a run with the
//! worker — paced so the worker answers, and flat out so it often does not — is bit-identical to
//! a run without it, state and environment sample at every step.
//!
//! And the prediction each update is evaluated at (`environment::prefetch::Request::predicted`)
//! costs what its documentation bounds: at every 10 Hz update, the sample equals the models
//! evaluated at the actual state to within that bound.

use flexdyn_environment::prefetch::Request;
use flexdyn_environment::EnvironmentSample;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use nalgebra::Vector3;

const STEPS: usize = 3_000;

fn leo() -> Simulation {
    leo_edited(|text| text)
}

fn leo_edited(edit: impl FnOnce(String) -> String) -> Simulation {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/leo_environment.toml"
    );
    let text = edit(std::fs::read_to_string(path).unwrap());
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    Simulation::new(&cfg).unwrap()
}

/// Every step's state (position, velocity, attitude, rate) and held sample, as bits.
fn trace(sim: &mut Simulation, mut pace: impl FnMut(usize)) -> Vec<Vec<u64>> {
    trace_with(sim, |_, k| pace(k))
}

/// [`trace`], calling `before` with the simulation before each step.
fn trace_with(
    sim: &mut Simulation,
    mut before: impl FnMut(&mut Simulation, usize),
) -> Vec<Vec<u64>> {
    (0..STEPS)
        .map(|k| {
            before(sim, k);
            sim.step();
            let x = sim.spacecraft().state();
            let s = sim.environment().unwrap().sample();
            [x.r_bn_n, x.v_bn_n, x.sigma_bn, x.omega_bn_b]
                .iter()
                .chain([s.b_field_n_t, s.r_sun_b_n_m, s.wind_n_m_s].iter())
                .flat_map(|v| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
                .chain([
                    s.density_kg_m3.to_bits(),
                    s.shadow_factor.to_bits(),
                    s.t_sim_ns,
                ])
                .chain(s.albedo.iter().flat_map(|cap| {
                    cap.weight
                        .iter()
                        .chain(&cap.cos_eta)
                        .chain(cap.nadir_n.iter())
                        .map(|w| w.to_bits())
                        .collect::<Vec<_>>()
                }))
                .collect()
        })
        .collect()
}

#[test]
fn offloaded_updates_are_bit_identical_to_updates_on_the_stepping_thread() {
    let mut inline = leo();
    assert!(!inline.environment().unwrap().is_offloaded());
    let reference = trace(&mut inline, |_| {});
    assert_eq!(inline.environment().unwrap().prefetched_samples(), 0);

    // Paced: after each update the worker gets 2 ms, so (nearly) every sample is its answer.
    let mut paced = leo();
    paced.offload_environment().unwrap();
    assert!(paced.environment().unwrap().is_offloaded());
    let steps_per_update = 100; // 10 Hz updates, 1 kHz steps (the scenario's)
    let got = trace(&mut paced, |k| {
        if k % steps_per_update == 1 {
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
    });
    let taken = paced.environment().unwrap().prefetched_samples();
    let updates = (STEPS / steps_per_update) as u64;
    assert!(
        taken >= updates / 2,
        "only {taken} of {updates} updates came from the worker: the test would not exercise it"
    );
    first_difference(&reference, &got, "paced worker");

    // Flat out: whichever of the worker and the stepping thread gets there first.
    let mut racing = leo();
    racing.offload_environment().unwrap();
    let got = trace(&mut racing, |_| {});
    first_difference(&reference, &got, "racing worker");
}

/// With Earth albedo on, the cap (its 128 weights, the rings and the frame) comes through the
/// worker's slot bit for bit too.
#[test]
fn offloaded_albedo_caps_are_bit_identical() {
    let with_albedo =
        |text: String| text.replacen("sun = true\n", "sun = true\nalbedo = \"lambertian\"\n", 1);
    let mut inline = leo_edited(with_albedo);
    let reference = trace(&mut inline, |_| {});
    let cap = inline
        .environment()
        .unwrap()
        .sample()
        .albedo
        .expect("a cap");
    assert!(
        cap.weight.iter().any(|w| *w > 0.0),
        "the scenario starts over lit ground"
    );
    let mut racing = leo_edited(with_albedo);
    racing.offload_environment().unwrap();
    let got = trace(&mut racing, |k| {
        if k % 100 == 1 {
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
    });
    assert!(racing.environment().unwrap().prefetched_samples() > 0);
    first_difference(&reference, &got, "worker with albedo");
}

/// The environment record read at every frame boundary (`Simulation::environment_into`, what
/// the server publishes and `simulate` writes) evaluates the update due at that instant ahead
/// of the next step; the step then takes that evaluation instead of running the models again:
/// one evaluation per update instant, and the run is bit-identical to one that reads nothing.
#[test]
fn the_environment_record_and_the_next_update_share_one_evaluation() {
    let mut quiet = leo();
    let reference = trace(&mut quiet, |_| {});
    let mut read = leo();
    let mut msg = flexdyn_proto::EnvironmentMsg::default();
    let mut records = Vec::new();
    // 10 steps a frame, an update every 100 steps (10 Hz): read at every frame boundary, so
    // that every tenth read falls on an update instant and the others on held samples.
    let got = trace_with(&mut read, |sim, k| {
        if k % 10 == 0 {
            sim.environment_into(&mut msg);
            records.push((msg.header.sim_time_ns, msg.b_n_t));
        }
    });
    first_difference(&reference, &got, "reading the environment record");
    let updates = (STEPS / 100) as u64;
    assert_eq!(records.len(), STEPS / 10);
    assert_eq!(quiet.environment().unwrap().updates_evaluated(), updates);
    assert_eq!(read.environment().unwrap().updates_evaluated(), updates);
    // The record at an update instant is that update's sample: the field the next 100 steps
    // hold (the trace's columns 12..15 are the held B field).
    for (i, (t_ns, b)) in records.iter().enumerate().step_by(10) {
        assert_eq!(*t_ns, (i as u64) * 10_000_000);
        let held: Vec<u64> = b.iter().map(|c| c.to_bits()).collect();
        assert_eq!(held, reference[i * 10][12..15], "record {i}");
    }
}

fn first_difference(a: &[Vec<u64>], b: &[Vec<u64>], what: &str) {
    assert_eq!(a.len(), b.len());
    if let Some(k) = (0..a.len()).find(|&k| a[k] != b[k]) {
        panic!("{what}: step {k} differs from the run without a worker");
    }
}

#[test]
fn the_predicted_update_is_within_its_documented_bound_of_the_actual_state() {
    // The prediction's error bound (prefetch module docs): δr ≤ ½·max|a_p|·Δ², a_p being every
    // acceleration of the hub point B but the Earth's point mass (J2, and B's own motion about
    // the centre of mass as the panels vibrate). a_p is measured here from the trajectory
    // itself: the finite difference of v over each step, plus μ r/r³.
    const MU: f64 = 3.986_004_415e14; // the scenario's [gravity] mu_m3_s2
    let mut sim = leo();
    let step_s = 1e-3;
    let dt_s = 0.1;
    let mut prev: Option<(u64, Vector3<f64>, Vector3<f64>)> = None;
    let mut a_p_max: f64 = 0.0;
    let (mut worst_dr_m, mut worst_b_t, mut worst_rho_rel, mut worst_sun) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut updates = 0;
    for _ in 0..STEPS {
        let t = sim.spacecraft().t_sim_ns();
        let x = sim.spacecraft().state();
        let (r, v) = (x.r_bn_n, x.v_bn_n);
        sim.step();
        let v_next = sim.spacecraft().state().v_bn_n;
        a_p_max = a_p_max.max(((v_next - v) / step_s + MU * r / r.norm().powi(3)).norm());
        let env = sim.environment().unwrap();
        let s = *env.sample();
        if s.t_sim_ns != t || t == 0 {
            if t == 0 {
                prev = Some((t, r, v));
            }
            continue; // no update at this step (or the first, exact one)
        }
        updates += 1;
        let (t0, r0, v0) = prev.replace((t, r, v)).unwrap();
        let predicted = Request::predicted(t0, &r0, &v0, t);
        worst_dr_m = worst_dr_m.max((predicted.r_bn_n_m - r).norm());
        let mut exact = EnvironmentSample::NONE;
        env.fill(t, &r, &v, &mut exact);
        worst_b_t = worst_b_t.max((s.b_field_n_t - exact.b_field_n_t).norm());
        worst_rho_rel = worst_rho_rel.max((s.density_kg_m3 / exact.density_kg_m3 - 1.0).abs());
        let sun_dir = |q: &EnvironmentSample| q.r_sun_b_n_m.normalize();
        worst_sun = worst_sun.max((sun_dir(&s) - sun_dir(&exact)).norm());
    }
    eprintln!(
        "max |a_p| {a_p_max:.3e} m/s2; worst over {updates} updates: position {worst_dr_m:.3e} m, \
         B {worst_b_t:.3e} T, density {worst_rho_rel:.3e} (relative), Sun direction {worst_sun:.3e}"
    );
    // Updates at 100 ms, 200 ms, … 2.9 s (the one at t = 0 is exact).
    assert_eq!(updates, STEPS / 100 - 1);
    let dr_bound_m = 0.5 * a_p_max * dt_s * dt_s * 1.05;
    assert!(
        worst_dr_m > 0.0,
        "the prediction is not the actual state: the check can fail"
    );
    assert!(
        worst_dr_m <= dr_bound_m,
        "{worst_dr_m:e} m > {dr_bound_m:e} m"
    );
    // The fields over δr: |∇B| ≤ 4|B|/r (degree ≤ 2 terms dominate: (n+2)|B_n|/r) with |B| ≤
    // 60 µT; the NRLMSISE-00 density scale height at 500 km is ≥ 20 km; the Sun is 1.47e11 m
    // away. Each plus a few ulps of rounding.
    let r_m = 6.87e6;
    assert!(
        worst_b_t <= 4.0 * 60e-6 / r_m * dr_bound_m + 1e-19,
        "B off by {worst_b_t:e} T"
    );
    assert!(
        worst_rho_rel <= dr_bound_m / 20e3 + 1e-15,
        "density off by {worst_rho_rel:e}"
    );
    assert!(
        worst_sun <= dr_bound_m / 1.47e11 + 1e-15,
        "Sun off by {worst_sun:e}"
    );
}
