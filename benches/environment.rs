//! Per-call cost of each environment model (issue 19), against the cost of one panel pair per
//! RK4 step measured in the same run.
//!
//! After criterion's own report this prints, for each model, the median ns per call (31 batches
//! of `BATCH` calls), then a budget: the calls per 1 kHz step at the rates below, the ns per step
//! they cost, and the total as a fraction of one panel pair's ns per step (the least-squares cost
//! per added pair of the reference spacecraft with 1, 2 and 4 ring pairs, as `benches/step.rs`
//! measures it). The target is a total below one pair.
//!
//! The rates are a proposal for the lead, who sets them in the configuration: slow fields
//! (ephemerides, magnetic coefficients, NRLMSISE-00) at 1 Hz, the field and shadow at 10 Hz, the
//! surface forces at every RK4 stage (4 per step).

use flexdyn_dynamics::reference as common;

use flexdyn_testkit::median;
use std::hint::black_box;
use std::time::Instant;

use criterion::Criterion;
use flexdyn_dynamics::{GravityModel, Spacecraft};
use flexdyn_environment::atmosphere::{
    exponential_density_kg_m3, velocity_relative_to_air_n_m_s, Nrlmsise00Model, SpaceWeather,
};
use flexdyn_environment::earth_rotation::OMEGA_EARTH_RAD_S;
use flexdyn_environment::ephemeris::{moon_position_n_m, sun_position_n_m};
use flexdyn_environment::facets::{solar_pressure_n_m2, Facet, FacetModel};
use flexdyn_environment::geodetic::geodetic_from_ecef;
use flexdyn_environment::magnetic::{dipole_torque_b_nm, CentredDipole, Igrf};
use flexdyn_environment::shadow::{shadow_factor, ShadowModel};
use nalgebra::Vector3;

const BATCH: u32 = 2_000;
const BATCHES: usize = 31;

/// The reference hub as a cube of 2 m: six facets, so every facet term is exercised.
fn hub_facets() -> FacetModel {
    FacetModel::new(
        (0..6)
            .map(|i| {
                let n = if i % 2 == 0 { 1.0 } else { -1.0 } * Vector3::ith(i / 2, 1.0);
                Facet {
                    area_m2: 4.0,
                    normal_b: n,
                    r_cp_b_m: Vector3::new(0.0, 0.0, 1.0) + n,
                    drag_coefficient: 2.2,
                    absorbed: 0.6,
                    specular: 0.3,
                    diffuse: 0.1,
                }
            })
            .collect(),
    )
    .expect("valid facets")
}

/// A point of a 500 km orbit that moves a little with `i`, so nothing is constant-folded.
fn r_m(i: u32) -> Vector3<f64> {
    let a = 1e-4 * f64::from(i);
    6.878e6 * Vector3::new(a.cos(), a.sin() * 0.6, a.sin() * 0.8)
}

/// One named model call; `i` varies the input.
struct Model {
    name: &'static str,
    /// Calls per 1 kHz step at the proposed rates.
    calls_per_step: f64,
    call: Box<dyn FnMut(u32)>,
}

fn models() -> Vec<Model> {
    let igrf13 = Igrf::igrf14(13).expect("IGRF-14");
    let igrf8 = Igrf::igrf14(8).expect("IGRF-14");
    let c13 = igrf13.coefficients_at(2025.5);
    let c8 = igrf8.coefficients_at(2025.5);
    let dipole = CentredDipole::tilted(&c13);
    let msis = Nrlmsise00Model::new(SpaceWeather {
        f107_sfu: 150.0,
        f107a_sfu: 150.0,
        ap: 15.0,
    })
    .expect("space weather");
    let facets = hub_facets();
    let facets_srp = facets.clone();
    let omega = Vector3::new(0.0, 0.0, OMEGA_EARTH_RAD_S);
    let sun = sun_position_n_m(0.25);
    let per_stage = 4.0;
    vec![
        Model {
            name: "Sun position (Meeus 25)",
            calls_per_step: 1e-3,
            call: Box::new(|i| {
                black_box(sun_position_n_m(black_box(0.25 + 1e-9 * f64::from(i))));
            }),
        },
        Model {
            name: "Moon position (Meeus 47)",
            calls_per_step: 1e-3,
            call: Box::new(|i| {
                black_box(moon_position_n_m(black_box(0.25 + 1e-9 * f64::from(i))));
            }),
        },
        Model {
            name: "shadow, conical",
            calls_per_step: 1e-2,
            call: Box::new(move |i| {
                black_box(shadow_factor(
                    ShadowModel::Conical,
                    &r_m(i),
                    black_box(&sun),
                ));
            }),
        },
        Model {
            name: "shadow, cylindrical",
            calls_per_step: 0.0,
            call: Box::new(move |i| {
                black_box(shadow_factor(
                    ShadowModel::Cylindrical,
                    &r_m(i),
                    black_box(&sun),
                ));
            }),
        },
        Model {
            name: "IGRF-14 coefficients of a date",
            calls_per_step: 1e-3,
            call: Box::new(move |i| {
                black_box(igrf13.coefficients_at(black_box(2025.5 + 1e-9 * f64::from(i))));
            }),
        },
        Model {
            name: "IGRF-14 field, degree 13",
            calls_per_step: 1e-2,
            call: Box::new(move |i| {
                black_box(c13.field_ecef_t(&r_m(i)));
            }),
        },
        Model {
            name: "IGRF-14 field, degree 8",
            calls_per_step: 0.0,
            call: Box::new(move |i| {
                black_box(c8.field_ecef_t(&r_m(i)));
            }),
        },
        Model {
            name: "tilted dipole field",
            calls_per_step: 0.0,
            call: Box::new(move |i| {
                black_box(dipole.field_ecef_t(&r_m(i)));
            }),
        },
        Model {
            name: "dipole torque m x B",
            calls_per_step: per_stage,
            call: Box::new(|i| {
                black_box(dipole_torque_b_nm(
                    black_box(&Vector3::new(0.1, 0.0, 0.0)),
                    &(r_m(i) * 1e-12),
                ));
            }),
        },
        Model {
            name: "geodetic from ECEF",
            calls_per_step: 1e-2,
            call: Box::new(|i| {
                black_box(geodetic_from_ecef(&r_m(i)));
            }),
        },
        Model {
            name: "exponential density",
            calls_per_step: 0.0,
            call: Box::new(|i| {
                black_box(exponential_density_kg_m3(black_box(500e3 + f64::from(i))));
            }),
        },
        Model {
            name: "NRLMSISE-00 state",
            calls_per_step: 1e-3,
            call: Box::new(move |i| {
                let g = geodetic_from_ecef(&r_m(i));
                black_box(msis.state(172, 29_000.0, &g));
            }),
        },
        Model {
            name: "relative wind",
            calls_per_step: per_stage,
            call: Box::new(move |i| {
                black_box(velocity_relative_to_air_n_m_s(
                    &r_m(i),
                    black_box(&Vector3::new(0.0, 7.6e3, 0.0)),
                    &omega,
                ));
            }),
        },
        Model {
            name: "facet drag wrench (6 facets)",
            calls_per_step: per_stage,
            call: Box::new(move |i| {
                black_box(facets.drag_wrench_b(&(r_m(i) * 1e-3), black_box(3e-12)));
            }),
        },
        Model {
            name: "facet SRP wrench (6 facets)",
            calls_per_step: per_stage,
            call: Box::new(move |i| {
                let p = solar_pressure_n_m2(1.496e11, 1.0, 1361.0);
                black_box(facets_srp.srp_wrench_b(&r_m(i), black_box(p)));
            }),
        },
    ]
}

/// Median ns per call over `BATCHES` batches of `BATCH` calls (after one warm-up batch).
fn median_ns_per_call(call: &mut dyn FnMut(u32)) -> f64 {
    for i in 0..BATCH {
        call(i);
    }
    median(
        (0..BATCHES)
            .map(|_| {
                let t = Instant::now();
                for i in 0..BATCH {
                    call(i);
                }
                t.elapsed().as_secs_f64() * 1e9 / f64::from(BATCH)
            })
            .collect(),
    )
}

/// Median ns per RK4 step of `sc` (31 batches of 20 000 steps).
fn median_ns_per_step(mut sc: Spacecraft) -> f64 {
    let steps = 20_000;
    for _ in 0..steps {
        sc.step();
    }
    median(
        (0..BATCHES)
            .map(|_| {
                let t = Instant::now();
                for _ in 0..steps {
                    sc.step();
                }
                black_box(sc.state().omega_bn_b);
                t.elapsed().as_secs_f64() * 1e9 / f64::from(steps)
            })
            .collect(),
    )
}

/// ns per added panel pair: the least-squares slope over 1, 2 and 4 ring pairs.
fn ns_per_pair() -> f64 {
    let rows: Vec<(f64, f64)> = [1usize, 2, 4]
        .iter()
        .map(|&n| {
            let sc = common::build(
                common::reference_hub(),
                GravityModel::PointMass {
                    mu_m3_s2: common::MU_EARTH,
                },
                common::ring_pairs(n, 0.0),
                common::reference_initial(),
                1_000_000,
            );
            (n as f64, median_ns_per_step(sc))
        })
        .collect();
    let m = rows.len() as f64;
    let (sx, sy) = rows
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (sxx, sxy) = rows
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x * x, b + x * y));
    for (n, ns) in &rows {
        println!("  rk4 step, {n} ring pair(s): {ns:.1} ns");
    }
    (m * sxy - sx * sy) / (m * sxx - sx * sx)
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("environment");
    group.warm_up_time(std::time::Duration::from_millis(500));
    group.measurement_time(std::time::Duration::from_secs(2));
    for mut model in models() {
        let mut i = 0u32;
        group.bench_function(model.name, |b| {
            b.iter(|| {
                i = i.wrapping_add(1);
                (model.call)(i);
            })
        });
    }
    group.finish();
}

fn summary() {
    println!("\nenvironment models (median of {BATCHES} batches x {BATCH} calls):");
    println!(
        "{:<34} {:>12} {:>14} {:>12}",
        "model", "ns/call", "calls/step", "ns/step"
    );
    let mut total = 0.0;
    for mut model in models() {
        let ns = median_ns_per_call(&mut model.call);
        let per_step = ns * model.calls_per_step;
        total += per_step;
        println!(
            "{:<34} {:>12.1} {:>14} {:>12.2}",
            model.name,
            ns,
            if model.calls_per_step == 0.0 {
                "(alternative)".to_string()
            } else {
                format!("{}", model.calls_per_step)
            },
            per_step
        );
    }
    println!("\nbaseline, same run:");
    let pair = ns_per_pair();
    println!("  one panel pair: {pair:.1} ns per step (least-squares slope)");
    println!(
        "full environment at the rates above: {total:.1} ns per 1 kHz step = {:.2} x one panel pair \
         (target < 1)",
        total / pair
    );
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
    c.final_summary();
    summary();
}
