//! One RK4 step of the reference spacecraft with 1, 2, 4, 8 and 16 panel pairs, and of the
//! reference spacecraft (2 pairs) with 0, 1, 2, 4 and 8 reaction wheels.
//!
//! Targets (issue 2): ≤ 2 µs per step for 2 pairs on one core, cost linear in the pair count at
//! ≤ 0.5 µs per added pair. Issue 11: ≤ 0.3 µs per added reaction wheel. After criterion's own
//! report this prints a summary of medians (31 batches of 20,000 steps per size) and the
//! least-squares cost per added pair and per added wheel.
//!
//! Issue 19 (environment): the reference spacecraft with each dynamic effector, printed beside
//! the same spacecraft without it and beside the cost of one added panel pair, measured in the
//! same run. The target: a full environment costs less than one panel pair per step.
//!
//! Issue 20 (actuators): the LEO scenario with all its environment on, plus 3 magnetorquer rods
//! (commanded) or 4 thrusters (firing every frame), printed per device beside the same
//! simulation without them and beside one panel pair.
//!
//! Issue 39 (fuel slosh): the reference spacecraft (2 pairs) with 4 linear spring-mass-damper
//! particles or 4 spherical pendulums (damped, so every term runs), printed per device beside
//! the same spacecraft without them and beside one panel pair, measured in the same run.
//! Issue 39 §2 (panel chains): the reference hub with one chain of N = 1 … 10 unequal panels
//! (`reference::unequal_chain`), medians and the least-squares cost per added link, beside the
//! cost of a panel pair; with `FLEXDYN_PEERS_PYTHON`, the 10-link chain against MuJoCo's
//! equivalent tree (`tools/peers/mujoco_chain.py`) in the same run.
//! `FLEXDYN_BENCH_ONLY=chain cargo bench --bench step` runs only these rows (about a minute).
//! Issue 39 §3 (propellant depletion): the reference spacecraft (2 pairs) with 4 thrusters
//! firing every step, each drawing from its own propellant tank, against the same thrusters
//! without tanks, per tank and beside one panel pair; and 4 tanks nothing draws from.
//! `FLEXDYN_BENCH_ONLY=tank cargo bench --bench step` runs only these rows and the pair fit.
//! Issue 39 §4 (Earth albedo): the cost of one environment update's albedo cap and of one
//! coarse-sun detector's sum over it, then the LEO scenario's step with the cap evaluated at
//! every step, and its frame loop (all on at 10 Hz, offloaded, with its coarse sun array), with
//! albedo against without, beside one panel pair. `FLEXDYN_BENCH_ONLY=albedo` runs only these.
//!
//! Peers in the same run: with `FLEXDYN_PEERS_PYTHON` pointing at a Python that has
//! `mujoco==4.0.0` and `bsk==2.12.1` (see `tools/peers/README.md`), the bench then runs
//! `tools/peers/{mujoco,basilisk}_step.py` one after the other — the same spacecraft, RK4 at 1 ms —
//! and prints each peer's median next to flexdyn's, with the ratio.

use flexdyn_dynamics::reference as common;

use flexdyn_testkit::median;
use std::hint::black_box;
use std::time::Instant;

use criterion::{BenchmarkId, Criterion};
use flexdyn_dynamics::dynamic_effectors::gravity_gradient::GravityGradient;
use flexdyn_dynamics::{GravityModel, Spacecraft};

const PAIR_COUNTS: [usize; 5] = [1, 2, 4, 8, 16];
const WHEEL_COUNTS: [usize; 5] = [0, 1, 2, 4, 8];

/// The reference spacecraft (2 pairs) with `n` wheels: a pyramid's axes repeated, each with
/// friction and a commanded motor torque, so every term of the wheel model is evaluated.
fn spacecraft_with_wheels(n: usize) -> Spacecraft {
    let effectors = common::reference_effectors_with_wheels(n, |w| {
        w.viscous_friction_nm_s_rad = 1e-6;
        w.coulomb_friction_nm = 5e-4;
    });
    let mut sc = reference_with(effectors);
    let u: Vec<f64> = (0..n).map(|j| 0.01 * (j as f64 + 1.0)).collect();
    sc.set_effector_inputs(&u).unwrap();
    sc
}

fn spacecraft(pairs: usize) -> Spacecraft {
    let gravity = GravityModel::PointMass {
        mu_m3_s2: common::MU_EARTH,
    };
    let pairs = if pairs == 2 {
        common::reference_pairs(0.0)
    } else {
        common::ring_pairs(pairs, 0.0)
    };
    common::build(
        common::reference_hub(),
        gravity,
        pairs,
        common::reference_initial(),
        1_000_000,
    )
}

fn bench_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("rk4_step");
    for n in PAIR_COUNTS {
        let mut sc = spacecraft(n);
        group.bench_with_input(
            BenchmarkId::from_parameter(format!("{n}_pairs")),
            &n,
            |b, _| {
                b.iter(|| {
                    sc.step();
                    black_box(sc.state().omega_bn_b);
                })
            },
        );
    }
    for n in WHEEL_COUNTS {
        let mut sc = spacecraft_with_wheels(n);
        group.bench_with_input(
            BenchmarkId::from_parameter(format!("2_pairs_{n}_wheels")),
            &n,
            |b, _| {
                b.iter(|| {
                    sc.step();
                    black_box(sc.state().omega_bn_b);
                })
            },
        );
    }
    group.finish();
}

/// Runs a peer script; returns (pairs, median ns per step) from its `peer=… pairs=N median_ns_per_step=x` lines.
fn run_peer(python: &str, script: &str) -> Result<Vec<(usize, f64)>, String> {
    run_peer_keyed(python, &[script], "pairs=")
}

/// Runs `python args…`; returns (count, median ns per step) from its lines that carry `key`
/// (`pairs=` or `links=`) and `median_ns_per_step=`.
fn run_peer_keyed(python: &str, args: &[&str], key: &str) -> Result<Vec<(usize, f64)>, String> {
    let script = args[0];
    let out = std::process::Command::new(python)
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run {python} {script}: {e}"))?;
    if !out.status.success() {
        return Err(format!("{script} exited with {}", out.status));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<(usize, f64)> = text
        .lines()
        .filter_map(|line| {
            let field = |key: &str| line.split_whitespace().find_map(|kv| kv.strip_prefix(key));
            Some((
                field(key)?.parse().ok()?,
                field("median_ns_per_step=")?.parse().ok()?,
            ))
        })
        .collect();
    if rows.is_empty() {
        return Err(format!(
            "{script} printed no `{key}… median_ns_per_step=…` lines"
        ));
    }
    Ok(rows)
}

fn peers(flexdyn: &[(f64, f64)]) {
    let Ok(python) = std::env::var("FLEXDYN_PEERS_PYTHON") else {
        println!("\npeers: skipped (set FLEXDYN_PEERS_PYTHON; see tools/peers/README.md)");
        return;
    };
    for (name, script) in [
        ("MuJoCo 4.0.0", "tools/peers/mujoco_step.py"),
        ("Basilisk 2.12.1", "tools/peers/basilisk_step.py"),
    ] {
        match run_peer(&python, script) {
            Err(e) => println!("\npeer {name}: {e}"),
            Ok(rows) => {
                println!("\n{name} (same run, median ns/step) vs flexdyn:");
                println!(
                    "{:>6} {:>14} {:>14} {:>10}",
                    "pairs", "peer ns/step", "flexdyn", "speed-up"
                );
                for (n, peer_ns) in rows {
                    if let Some((_, ns)) = flexdyn.iter().find(|(m, _)| *m as usize == n) {
                        println!("{n:>6} {peer_ns:>14.1} {ns:>14.1} {:>9.1}x", peer_ns / ns);
                    }
                }
            }
        }
    }
}

/// Median ns per step of `sc` over 31 batches of 20,000 steps (after 20,000 warm-up steps).
fn median_ns_per_step(mut sc: Spacecraft) -> f64 {
    common::median_ns_per_step(&mut sc, 31, 20_000)
}

/// Least-squares line through (x, y): (intercept, slope).
fn fit(rows: &[(f64, f64)]) -> (f64, f64) {
    let m = rows.len() as f64;
    let (sx, sy) = rows
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (sxx, sxy) = rows
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x * x, b + x * y));
    let slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
    ((sy - slope * sx) / m, slope)
}

fn wheel_summary() {
    let rows: Vec<(f64, f64)> = WHEEL_COUNTS
        .iter()
        .map(|&n| (n as f64, median_ns_per_step(spacecraft_with_wheels(n))))
        .collect();
    let (intercept, slope) = fit(&rows);
    println!(
        "
rk4_step with reaction wheels, 2 pairs (median of 31 batches x 20000 steps):"
    );
    println!("{:>6} {:>14} {:>14}", "wheels", "median ns/step", "steps/s");
    for (n, ns) in &rows {
        println!("{:>6} {:>14.1} {:>14.0}", n, ns, 1e9 / ns);
    }
    println!(
        "linear fit: {intercept:.1} ns + {slope:.1} ns per wheel (target <= 300 ns per wheel)"
    );
}

fn summary() -> Vec<(f64, f64)> {
    let (batches, steps) = (31, 20_000);
    let rows: Vec<(f64, f64)> = PAIR_COUNTS
        .iter()
        .map(|&n| (n as f64, median_ns_per_step(spacecraft(n))))
        .collect();
    let (intercept, slope) = fit(&rows);
    println!("\nrk4_step summary (median of {batches} batches x {steps} steps):");
    println!("{:>6} {:>14} {:>14}", "pairs", "median ns/step", "steps/s");
    for (n, ns) in &rows {
        println!("{:>6} {:>14.1} {:>14.0}", n, ns, 1e9 / ns);
    }
    println!("linear fit: {intercept:.1} ns + {slope:.1} ns per pair");
    println!("targets: 2 pairs <= 2000 ns/step, <= 500 ns per added pair");
    rows
}

/// The reference spacecraft (2 pairs) with the gravity gradient of its own gravity model.
fn spacecraft_with_gravity_gradient() -> Spacecraft {
    let mut sc = spacecraft(2);
    let mu_m3_s2 = match *sc.gravity() {
        GravityModel::PointMass { mu_m3_s2 } | GravityModel::J2 { mu_m3_s2, .. } => mu_m3_s2,
        GravityModel::None => unreachable!("the bench spacecraft orbits a planet"),
    };
    sc.add_dynamic_effector(Box::new(GravityGradient { mu_m3_s2 }));
    sc
}

/// Each dynamic effector's cost per step against the same spacecraft without it and against
/// one added panel pair (`pair_ns`, from the same run's fit).
fn environment_summary(pair_ns: f64) {
    let base = median_ns_per_step(spacecraft(2));
    let rows = [(
        "gravity gradient",
        median_ns_per_step(spacecraft_with_gravity_gradient()),
    )];
    println!("\nrk4_step with dynamic effectors, 2 pairs (median of 31 batches x 20000 steps):");
    print_added_cost("effector", base, &rows, pair_ns);
}

/// One row per configuration: its median ns per step, what it adds to `base`, and that as a
/// multiple of one panel pair (`pair_ns`).
fn print_added_cost(label: &str, base: f64, rows: &[(&str, f64)], pair_ns: f64) {
    println!(
        "{:<18} {:>14} {:>12} {:>16}",
        label, "median ns/step", "added ns", "x one panel pair"
    );
    println!("{:<18} {:>14.1} {:>12} {:>16}", "none", base, "-", "-");
    for (name, ns) in rows {
        println!(
            "{:<18} {:>14.1} {:>12.1} {:>16.3}",
            name,
            ns,
            ns - base,
            (ns - base) / pair_ns
        );
    }
}

/// `scenarios/leo_environment.toml` with its `[environment]` table (and facets) replaced by
/// `environment` (empty: no environment; the epoch and the OMM orbit stay).
fn leo_simulation(environment: &str) -> flexdyn_vehicle::sim::Simulation {
    let leo = include_str!("../scenarios/leo_environment.toml");
    let (start, end) = (
        leo.find("[environment]").unwrap(),
        leo.find("[hub]").unwrap(),
    );
    let facets = &leo[leo.find("[[environment.facets]]").unwrap()..end];
    let env = if environment.is_empty() {
        String::new()
    } else {
        format!("{environment}\n{facets}")
    };
    let text = format!("{}{env}{}", &leo[..start], &leo[end..]);
    let cfg = flexdyn_vehicle::config::SimConfig::from_toml_str(&text).unwrap();
    flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap()
}

/// One batch of 5000 `Simulation::step`s (with their environment updates); returns the steps.
fn step_batch(sim: &mut flexdyn_vehicle::sim::Simulation) -> u64 {
    let steps = 5_000;
    sim.step_n(steps);
    steps
}

/// One batch of 50 frames of the server's frame loop: `step_frame`, then the sensors due at
/// the next tick sampled, as `crates/server/src/physics.rs` does; returns the steps.
fn frame_batch(sim: &mut flexdyn_vehicle::sim::Simulation) -> u64 {
    let frames = 500;
    for _ in 0..frames {
        sim.step_frame();
        let tick = sim.t_sim_ns() / sim.frame_ns();
        sim.sample_sensors(|s| s.due(tick));
    }
    frames * sim.steps_per_frame()
}

/// Median ns per step of each simulation over 15 rounds, each round one warm batch of every
/// simulation in turn: the rows of a table are measured interleaved, so a burst of load on the
/// shared machine falls on all of them alike instead of on one row.
fn interleaved_ns_per_step(
    sims: &mut [flexdyn_vehicle::sim::Simulation],
    batch: fn(&mut flexdyn_vehicle::sim::Simulation) -> u64,
) -> Vec<f64> {
    for sim in sims.iter_mut() {
        batch(sim);
    }
    let mut per_step = vec![Vec::with_capacity(15); sims.len()];
    for _ in 0..15 {
        for (sim, samples) in sims.iter_mut().zip(per_step.iter_mut()) {
            let t = Instant::now();
            let steps = batch(sim);
            black_box(sim.spacecraft().state().omega_bn_b);
            samples.push(t.elapsed().as_secs_f64() * 1e9 / steps as f64);
        }
    }
    per_step.into_iter().map(median).collect()
}

/// Each environment model's and effector's cost per step in the LEO scenario (2 pairs, the OMM
/// orbit), updated at every step (the worst case: `update_hz = 1000`) and, for all of them
/// together, at the scenario's 10 Hz; against the same simulation without `[environment]`
/// and against one panel pair (`pair_ns`, from the same run's fit).
fn world_summary(pair_ns: f64) {
    const WEATHER: &str = "f107_sfu = 150.0\nf107a_sfu = 150.0\nap = 15.0\n";
    let every = |lines: &str| format!("[environment]\nupdate_hz = 1000.0\n{lines}");
    let leo = include_str!("../scenarios/leo_environment.toml");
    let all = &leo[leo.find("[environment]").unwrap()..leo.find("[[environment.facets]]").unwrap()];
    let rows: Vec<(&str, String)> = vec![
        ("igrf14 deg 13", every("magnetic = \"igrf14\"\n")),
        ("dipole tilted", every("magnetic = \"dipole_tilted\"\n")),
        ("exponential", every("atmosphere = \"exponential\"\n")),
        (
            "nrlmsise00",
            every(&format!("atmosphere = \"nrlmsise00\"\n{WEATHER}")),
        ),
        ("sun + shadow", every("sun = true\nshadow = \"conical\"\n")),
        ("moon", every("moon = true\n")),
        ("gravity gradient", every("gravity_gradient = true\n")),
        (
            "expo + drag",
            every("atmosphere = \"exponential\"\ndrag = true\n"),
        ),
        (
            "sun + srp",
            every("sun = true\nshadow = \"conical\"\nsolar_pressure = true\n"),
        ),
        (
            "igrf + dipole",
            every("magnetic = \"igrf14\"\nresidual_dipole_m_b_am2 = [0.1, 0.0, 0.0]\n"),
        ),
        // The constants that match a reference tool (each environment model's `schema.rs`).
        (
            "sun + cannonball",
            every(
                "sun = true\nshadow = \"conical\"\nsolar_pressure = true\n\
                 solar_pressure_model = \"cannonball\"\ncannonball_area_m2 = 4.0\n\
                 cannonball_reflectivity_coefficient = 1.2\n",
            ),
        ),
        (
            "dipole, uniform",
            every(
                "magnetic = \"dipole\"\ndipole_g10_nt = -29350.0\nearth_rotation = \"uniform\"\n",
            ),
        ),
        (
            "expo sphere still",
            every(
                "atmosphere = \"exponential\"\nexponential_altitude = \"spherical\"\n\
                 corotating_wind = false\n",
            ),
        ),
        (
            "all @ 1000 Hz",
            all.replace("update_hz = 10.0", "update_hz = 1000.0"),
        ),
        ("all @ 10 Hz", all.to_string()),
    ];
    // The last row is the server's way: the models update on the environment worker thread,
    // the stepping thread only picks up each sample (`Simulation::offload_environment`;
    // bit-identical).
    let mut offloaded = leo_simulation(all);
    offloaded.offload_environment().unwrap();
    let mut sims: Vec<_> = std::iter::once(leo_simulation(""))
        .chain(rows.iter().map(|(_, env)| leo_simulation(env)))
        .chain(std::iter::once(offloaded))
        .collect();
    let ns = interleaved_ns_per_step(&mut sims, step_batch);
    let taken = sims
        .last()
        .unwrap()
        .environment()
        .unwrap()
        .prefetched_samples();
    let base = ns[0];
    let measured: Vec<(&str, f64)> = rows
        .iter()
        .map(|(name, _)| *name)
        .chain(std::iter::once("all @ 10 Hz, offloaded"))
        .zip(ns[1..].iter().copied())
        .collect();
    println!("\nSimulation::step in scenarios/leo_environment.toml, 2 pairs (median of 15 interleaved x 5000 steps):");
    print_added_cost("environment", base, &measured, pair_ns);
    println!("  (offloaded: {taken} of the updates came from the worker, the rest were evaluated on the stepping thread)");
}

/// The cost per step of each actuator kind, per device, in `scenarios/leo_environment.toml`
/// with everything on at 10 Hz: 3 rods at a commanded dipole, 4 thrusters firing 5 ms of every
/// 10 ms frame (so the lag's closed forms run in both valve states); against the same simulation
/// without them and against one panel pair (`pair_ns`).
fn actuator_summary(pair_ns: f64) {
    let leo = include_str!("../scenarios/leo_environment.toml");
    let rod = |i: usize| {
        let mut axis = [0.0; 3];
        axis[i] = 1.0;
        format!(
            "\n[[magnetorquers]]\nname = \"mtq{i}\"\naxis_b = {axis:?}\nr_mb_b_m = [0.5, 0.0, 0.5]\n\
             max_dipole_am2 = 400.0\n"
        )
    };
    let thruster = |i: usize| {
        let sign = if i.is_multiple_of(2) { 1.0 } else { -1.0 };
        format!(
            "\n[[thrusters]]\nname = \"thr{i}\"\nr_tb_b_m = [{sign:?}, 0.0, 1.0]\n\
             force_axis_b = [0.0, {sign:?}, 0.0]\nmax_thrust_newton = 1.0\nisp_s = 220.0\n\
             min_on_time_s = 0.002\nrise_time_constant_s = 0.015\ntail_off_time_constant_s = 0.025\n"
        )
    };
    let with = |extra: String, inputs: &[f64]| {
        let cfg =
            flexdyn_vehicle::config::SimConfig::from_toml_str(&format!("{leo}{extra}")).unwrap();
        let mut sim = flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap();
        sim.set_effector_inputs(inputs).unwrap();
        sim
    };
    let mut sims = [
        with(String::new(), &[]),
        with((0..3).map(rod).collect(), &[100.0, -50.0, 20.0]),
        with((0..4).map(thruster).collect(), &[0.005; 4]),
    ];
    let [base, rods, thrusters] = interleaved_ns_per_step(&mut sims, step_batch)[..] else {
        unreachable!("three simulations")
    };
    let per_device = [
        ("magnetorquer", base + (rods - base) / 3.0),
        ("thruster", base + (thrusters - base) / 4.0),
    ];
    println!(
        "\nSimulation::step in scenarios/leo_environment.toml (all on @ 10 Hz), per actuator \
         (3 rods: {rods:.1} ns/step, 4 thrusters firing: {thrusters:.1} ns/step; median of 15 interleaved x 5000 steps):"
    );
    print_added_cost("one device", base, &per_device, pair_ns);
}

/// The cost per step of each sensor kind added with the environment (issue 20), one device each,
/// in `scenarios/leo_environment.toml` (everything on at 10 Hz) with its own sensor entries:
/// the frame loop with that one sensor against the same loop with none, and against one panel
/// pair (`pair_ns`).
fn sensor_summary(pair_ns: f64) {
    let leo = include_str!("../scenarios/leo_environment.toml");
    let start = leo.find("[[magnetometers]]").unwrap();
    let sections = &leo[start..];
    let section = |header: &str| {
        let from = sections.find(header).unwrap();
        let rest = &sections[from + header.len()..];
        let to = rest.find("\n[[").map_or(rest.len(), |i| i + 1);
        format!("{header}{}", &rest[..to])
    };
    let with = |extra: &str| {
        let text = format!("{}\n{extra}", &leo[..start]);
        let cfg = flexdyn_vehicle::config::SimConfig::from_toml_str(&text).unwrap();
        flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap()
    };
    let kinds = [
        ("magnetometer", "[[magnetometers]]"),
        ("coarse sun (6)", "[[coarse_sun_sensors]]"),
        ("fine sun", "[[fine_sun_sensors]]"),
        ("gps receiver", "[[gps_receivers]]"),
    ];
    let mut sims: Vec<_> = std::iter::once(with(""))
        .chain(kinds.iter().map(|(_, header)| with(&section(header))))
        .collect();
    let ns = interleaved_ns_per_step(&mut sims, frame_batch);
    let base = ns[0];
    let rows: Vec<(&str, f64)> = kinds
        .iter()
        .map(|(name, _)| *name)
        .zip(ns[1..].iter().copied())
        .collect();
    println!(
        "\nframe loop in scenarios/leo_environment.toml (all on @ 10 Hz), per sensor, each at its \
         scenario rate (median of 15 interleaved x 500 frames):"
    );
    print_added_cost("one device", base, &rows, pair_ns);
}

/// The reference spacecraft (2 pairs) with `particles` spring-mass slosh particles and
/// `pendulums` slosh pendulums, each displaced from rest, on axes that differ per device.
fn spacecraft_with_slosh(particles: usize, pendulums: usize) -> Spacecraft {
    use flexdyn_dynamics::effectors::slosh_linear::{SloshLinear, SloshLinearParams};
    use flexdyn_dynamics::effectors::slosh_pendulum::{SloshPendulum, SloshPendulumParams};
    use nalgebra::Vector3;
    let mut effectors = common::reference_effectors_with_wheels(0, |_| {});
    let axis = |j: usize| {
        let az = (45.0 + 90.0 * j as f64).to_radians();
        Vector3::new(az.cos(), az.sin(), 0.0)
    };
    for j in 0..particles {
        let p = SloshLinearParams {
            name: format!("slosh{j}"),
            r_pb_b_m: axis(j) * 0.5 - Vector3::z() * 0.3,
            p_hat_b: axis(j + 1),
            mass_kg: 20.0,
            k_n_m: 50.0,
            c_n_s_m: 0.5,
            rho_m: 0.02,
            rho_dot_m_s: 0.0,
        };
        effectors.push(Box::new(
            SloshLinear::new(p, &format!("slosh_linear[{j}]")).unwrap(),
        ));
    }
    for j in 0..pendulums {
        let p = SloshPendulumParams {
            name: format!("pendulum{j}"),
            r_pb_b_m: axis(j) * 0.5,
            hang_axis_b: -Vector3::z(),
            l_m: 0.25,
            mass_kg: 20.0,
            c_nm_s_rad: 0.05,
            phi_rad: 0.05,
            phi_dot_rad_s: 0.0,
            theta_rad: -0.03,
            theta_dot_rad_s: 0.0,
        };
        effectors.push(Box::new(
            SloshPendulum::new(p, &format!("slosh_pendulums[{j}]")).unwrap(),
        ));
    }
    reference_with(effectors)
}

/// The reference spacecraft (2 pairs) with `thrusters` 1 N thrusters held open (duty 1, on
/// axes that differ per device), each drawing from its own 50 kg tank when `fed`, and `idle`
/// more tanks nothing draws from.
fn spacecraft_with_tanks(thrusters: usize, fed: bool, idle: usize) -> Spacecraft {
    use flexdyn_dynamics::dynamic_effectors::thruster::{
        Thruster, ThrusterCommand, ThrusterParams,
    };
    use flexdyn_dynamics::effectors::propellant_tank::{
        PropellantTank, PropellantTankParams, TankInertiaModel,
    };
    use nalgebra::Vector3;
    let mut effectors = common::reference_effectors_with_wheels(0, |_| {});
    let at = |j: usize| {
        let az = (45.0 + 90.0 * j as f64).to_radians();
        Vector3::new(az.cos(), az.sin(), 0.2)
    };
    let tanks = if fed { thrusters } else { 0 } + idle;
    for j in 0..tanks {
        let p = PropellantTankParams {
            name: format!("tank{j}"),
            r_tcb_b_m: at(j) * 0.6,
            propellant_mass_kg: 50.0,
            inertia: TankInertiaModel::ConstantDensity {
                density_kg_m3: 1004.0,
            },
        };
        effectors.push(Box::new(
            PropellantTank::new(p, &format!("propellant_tanks[{j}]")).unwrap(),
        ));
    }
    let mut sc = reference_with(effectors);
    for j in 0..thrusters {
        let p = ThrusterParams {
            name: format!("thr{j}"),
            r_tb_b_m: at(j),
            force_axis_b: at(j + 1).normalize(),
            max_thrust_newton: 1.0,
            isp_s: 220.0,
            min_on_time_s: 0.0,
            rise_time_constant_s: 0.0,
            tail_off_time_constant_s: 0.0,
            command: ThrusterCommand::DutyCycle,
            tank: fed.then(|| format!("tank{j}")),
        };
        let t = Thruster::new(p, &format!("thrusters[{j}]"), 10_000_000, 1_000_000).unwrap();
        sc.add_dynamic_effector(Box::new(t));
    }
    sc.set_effector_inputs(&vec![1.0; thrusters]).unwrap();
    sc
}

/// The propellant tank's cost per step (issue 39 §3), per tank (4 of each case), against the
/// same spacecraft without tanks and against one panel pair (`pair_ns`, same run): a tank its
/// firing thruster draws from (the feed, the mass flow and the depletion terms of both), and a
/// tank nothing draws from (its mass properties only).
fn tank_summary(pair_ns: f64) {
    let base = median_ns_per_step(spacecraft_with_tanks(4, false, 0));
    let fed = median_ns_per_step(spacecraft_with_tanks(4, true, 0));
    let idle = median_ns_per_step(spacecraft_with_tanks(4, false, 4));
    println!(
        "\nrk4_step with propellant tanks, 2 pairs + 4 firing thrusters, per tank (4 fed: \
         {fed:.1} ns/step, 4 idle: {idle:.1} ns/step; median of 31 batches x 20000 steps):"
    );
    let rows = [
        ("tank, fed", base + (fed - base) / 4.0),
        ("tank, idle", base + (idle - base) / 4.0),
    ];
    print_added_cost("one tank", base, &rows, pair_ns);
}

/// The reference hub, orbit and 1 ms step with `effectors` appended.
fn reference_with(effectors: Vec<Box<dyn flexdyn_dynamics::StateEffector>>) -> Spacecraft {
    Spacecraft::new(
        common::reference_hub(),
        GravityModel::PointMass {
            mu_m3_s2: common::MU_EARTH,
        },
        effectors,
        common::reference_initial(),
        1_000_000,
    )
    .unwrap()
}

/// Each slosh model's cost per step, per device (4 of each), against the same spacecraft
/// without them and against one panel pair (`pair_ns`, from the same run's fit).
fn slosh_summary(pair_ns: f64) {
    let base = median_ns_per_step(spacecraft_with_slosh(0, 0));
    let linear = median_ns_per_step(spacecraft_with_slosh(4, 0));
    let pendulum = median_ns_per_step(spacecraft_with_slosh(0, 4));
    println!(
        "\nrk4_step with fuel slosh, 2 pairs, per device (4 particles: {linear:.1} ns/step, \
         4 pendulums: {pendulum:.1} ns/step; median of 31 batches x 20000 steps):"
    );
    let rows = [
        ("slosh_linear", base + (linear - base) / 4.0),
        ("slosh_pendulum", base + (pendulum - base) / 4.0),
    ];
    print_added_cost("one device", base, &rows, pair_ns);
}

/// The N-link chains (issue 39 §2): cost per added link, and the 10-link chain against MuJoCo's
/// tree in the same run. `pair_ns` is the cost of one added panel pair, when measured.
fn chain_summary(pair_ns: Option<f64>) {
    const LINKS: std::ops::RangeInclusive<usize> = 1..=10;
    let (batches, steps) = (11, 5_000);
    let gravity = GravityModel::PointMass {
        mu_m3_s2: common::MU_EARTH,
    };
    let base = common::median_ns_per_step(
        &mut common::build(
            common::reference_hub(),
            gravity,
            Vec::new(),
            common::reference_initial(),
            1_000_000,
        ),
        batches,
        steps,
    );
    let rows: Vec<(f64, f64)> = LINKS
        .map(|n| {
            let mut sc = common::reference_with_chain(gravity, n, 0.0);
            (
                n as f64,
                common::median_ns_per_step(&mut sc, batches, steps),
            )
        })
        .collect();
    let (intercept, slope) = fit(&rows);
    println!(
        "\nrk4_step, reference hub + one N-link chain of unequal panels (median of {batches} \
         batches x {steps} steps; rigid hub alone {base:.1} ns):"
    );
    println!(
        "{:>6} {:>14} {:>16}",
        "links", "median ns/step", "ns over the hub"
    );
    for (n, ns) in &rows {
        println!("{n:>6} {ns:>14.1} {:>16.1}", ns - base);
    }
    let pair_ns = pair_ns.unwrap_or_else(|| pair_ns_alone(batches, steps));
    println!(
        "linear fit: {intercept:.1} ns + {slope:.1} ns per link; one panel pair adds \
         {pair_ns:.1} ns, so a link costs {:.2} pairs",
        slope / pair_ns
    );
    let Ok(python) = std::env::var("FLEXDYN_PEERS_PYTHON") else {
        println!("MuJoCo chain: skipped (set FLEXDYN_PEERS_PYTHON; see tools/peers/README.md)");
        return;
    };
    match run_peer_keyed(
        &python,
        &["tools/peers/mujoco_chain.py", "--links", "10"],
        "links=",
    ) {
        Err(e) => println!("MuJoCo chain: {e}"),
        Ok(peer) => {
            let ns = rows[rows.len() - 1].1;
            for (n, peer_ns) in peer {
                println!(
                    "{n}-link chain, same run: MuJoCo 4.0.0 {peer_ns:.1} ns/step, flexdyn \
                     {ns:.1} ns/step: {:.1}x",
                    peer_ns / ns
                );
            }
        }
    }
}

/// Alone (`FLEXDYN_BENCH_ONLY=chain`, `tank` or `albedo`), one added pair is measured here: the slope of
/// the medians over 1, 2, 4 and 8 pairs.
fn pair_ns_alone(batches: usize, steps: usize) -> f64 {
    let pairs: Vec<(f64, f64)> = [1, 2, 4, 8]
        .iter()
        .map(|&n| {
            let ns = common::median_ns_per_step(&mut spacecraft(n), batches, steps);
            (n as f64, ns)
        })
        .collect();
    fit(&pairs).1
}

/// Median ns per call of `f` over 31 batches of `calls` calls.
fn median_ns_per_call(calls: usize, mut f: impl FnMut(usize)) -> f64 {
    let samples: Vec<f64> = (0..31)
        .map(|_| {
            let t = Instant::now();
            for i in 0..calls {
                f(i);
            }
            t.elapsed().as_secs_f64() * 1e9 / calls as f64
        })
        .collect();
    median(samples)
}

/// Earth albedo on the coarse sun sensors (issue 39 §4): the cost of one environment update's
/// cap (`Albedo::cap`, (A3)–(A6), on the environment worker in the server) and of one
/// detector's sum (`AlbedoCap::irradiance_fraction`, (A7), on the physics thread); then per
/// step, in `scenarios/leo_environment.toml`: the cap evaluated at every step on the stepping
/// thread (the worst case, `update_hz = 1000`), and the frame loop of its 6-detector array with
/// everything on at 10 Hz and the environment offloaded (the server's way), with albedo against
/// without; each against one panel pair (`pair_ns`, measured here when `None`).
fn albedo_summary(pair_ns: Option<f64>) {
    use flexdyn_environment::albedo::Albedo;
    use nalgebra::Vector3;
    let albedo = Albedo {
        coefficient: 0.3,
        earth_radius_m: 6_378_137.0,
        irradiance_1au_w_m2: 1361.0,
    };
    // B on a 500 km circle (a different point per call), the Sun 1 au away off its plane.
    let r_b = |i: usize| {
        let a = i as f64 * 1e-3;
        6_878e3 * Vector3::new(a.cos(), a.sin(), 0.1)
    };
    let sun = Vector3::new(1.2e11, 0.5e11, 0.6e11);
    let cap_ns = median_ns_per_call(10_000, |i| {
        black_box(albedo.cap(black_box(&r_b(i)), &sun));
    });
    let cap = albedo.cap(&r_b(0), &sun).unwrap();
    let detector_ns = median_ns_per_call(100_000, |i| {
        let n = Vector3::new(-1.0, (i % 7) as f64 * 0.1, 0.2).normalize();
        black_box(cap.irradiance_fraction(black_box(&n), 0.17));
    });
    println!(
        "
Earth albedo: one cap (8 x 16 elements) {cap_ns:.1} ns per environment update; one \
         detector's sum {detector_ns:.1} ns per array sample (median of 31 batches)"
    );
    let every = |lines: &str| format!("[environment]\nupdate_hz = 1000.0\n{lines}");
    let sun_shadow = every("sun = true\nshadow = \"conical\"\n");
    let with_albedo = every("sun = true\nshadow = \"conical\"\nalbedo = \"lambertian\"\n");
    let mut sims = vec![leo_simulation(&sun_shadow), leo_simulation(&with_albedo)];
    let ns = interleaved_ns_per_step(&mut sims, step_batch);
    let pair_ns = pair_ns.unwrap_or_else(|| pair_ns_alone(11, 5_000));
    println!(
        "Simulation::step in scenarios/leo_environment.toml, sun + shadow updated every step on \
         the stepping thread (median of 15 interleaved x 5000 steps):"
    );
    print_added_cost("environment", ns[0], &[("+ albedo", ns[1])], pair_ns);
    // The scenario as shipped (its coarse sun sensors among its sensors), all on at 10 Hz,
    // offloaded, with and without albedo.
    let leo = include_str!("../scenarios/leo_environment.toml");
    let frame_loop = |text: &str| {
        let cfg = flexdyn_vehicle::config::SimConfig::from_toml_str(text).unwrap();
        let mut sim = flexdyn_vehicle::sim::Simulation::new(&cfg).unwrap();
        sim.offload_environment().unwrap();
        sim
    };
    let on = leo.replacen("sun = true\n", "sun = true\nalbedo = \"lambertian\"\n", 1);
    let mut sims = vec![frame_loop(leo), frame_loop(&on)];
    let ns = interleaved_ns_per_step(&mut sims, frame_batch);
    println!(
        "frame loop of scenarios/leo_environment.toml (all on @ 10 Hz, offloaded; its sensors \
         with one 6-detector coarse sun array @ 10 Hz) (median of 15 interleaved x 500 frames):"
    );
    print_added_cost("environment", ns[0], &[("+ albedo", ns[1])], pair_ns);
}

fn main() {
    match std::env::var("FLEXDYN_BENCH_ONLY").as_deref() {
        Ok("chain") => return chain_summary(None),
        Ok("albedo") => return albedo_summary(None),
        Ok("tank") => return tank_summary(pair_ns_alone(11, 5_000)),
        _ => {}
    }
    let mut c = Criterion::default().configure_from_args();
    bench_step(&mut c);
    c.final_summary();
    let rows = summary();
    wheel_summary();
    environment_summary(fit(&rows).1);
    slosh_summary(fit(&rows).1);
    tank_summary(fit(&rows).1);
    world_summary(fit(&rows).1);
    actuator_summary(fit(&rows).1);
    sensor_summary(fit(&rows).1);
    chain_summary(Some(fit(&rows).1));
    albedo_summary(Some(fit(&rows).1));
    peers(&rows);
}
