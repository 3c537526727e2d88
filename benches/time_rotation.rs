//! Per-call cost of the time and Earth-rotation models (issue 19), to choose their update rates.
//!
//! Times, at a 2026 epoch and a t_sim that moves every call:
//! - `SimEpoch::times` (TAI/TT/UT1/ΔAT/GPS week) and `SimEpoch::utc_calendar`;
//! - `CelestialPole::at` (IAU 2006 precession + 77-term IAU 2000B nutation);
//! - `EarthRotation::at_with_pole` (the fast path: sidereal time + 3×3 products, pole held);
//! - `EarthRotation::at` (the whole N → E DCM);
//! - the baseline, in the same run: one RK4 step of the reference spacecraft (2 panel pairs).
//!
//! After criterion's report this prints the medians of 31 batches of 20,000 calls and each
//! one's ratio to the RK4 step.

use flexdyn_dynamics::reference as common;

use std::hint::black_box;
use std::time::Instant;

use criterion::Criterion;
use flexdyn_dynamics::GravityModel;
use flexdyn_environment::earth_rotation::{CelestialPole, EarthRotation};
use flexdyn_environment::epoch::{EarthOrientationParams, EpochScale, SimEpoch};

const BATCHES: usize = 31;
const CALLS: usize = 20_000;

fn median_ns(mut f: impl FnMut(u64)) -> f64 {
    let mut per = Vec::with_capacity(BATCHES);
    let mut k = 0u64;
    for _ in 0..BATCHES {
        let t0 = Instant::now();
        for _ in 0..CALLS {
            k += 1;
            f(k);
        }
        per.push(t0.elapsed().as_nanos() as f64 / CALLS as f64);
    }
    per.sort_by(|a, b| a.total_cmp(b));
    per[BATCHES / 2]
}

fn epoch() -> SimEpoch {
    let eop = EarthOrientationParams {
        ut1_minus_utc_s: 0.05,
        polar_motion_x_rad: 0.1 * flexdyn_environment::epoch::RAD_PER_ARCSEC,
        polar_motion_y_rad: 0.3 * flexdyn_environment::epoch::RAD_PER_ARCSEC,
    };
    SimEpoch::parse("2026-03-20T12:00:00Z", EpochScale::Utc, eop, "epoch.utc").unwrap()
}

fn main() {
    let ep = epoch();
    let rot = EarthRotation::new(ep.earth_orientation());
    // Steps of 1 ms of simulation time per call.
    let dt = 1_000_000u64;

    let mut c = Criterion::default().configure_from_args();
    c.bench_function("epoch_times", |b| {
        let mut k = 0u64;
        b.iter(|| {
            k += dt;
            black_box(ep.times(black_box(k)))
        })
    });
    c.bench_function("epoch_utc_calendar", |b| {
        let mut k = 0u64;
        b.iter(|| {
            k += dt;
            black_box(ep.utc_calendar(black_box(k)))
        })
    });
    c.bench_function("celestial_pole", |b| {
        let mut k = 0u64;
        b.iter(|| {
            k += dt;
            black_box(CelestialPole::at(
                ep.times(black_box(k)).tt_centuries_j2000(),
            ))
        })
    });
    let pole = CelestialPole::at(ep.times(0).tt_centuries_j2000());
    c.bench_function("dcm_en_pole_held", |b| {
        let mut k = 0u64;
        b.iter(|| {
            k += dt;
            black_box(rot.at_with_pole(&pole, &ep.times(black_box(k))))
        })
    });
    c.bench_function("dcm_en_full", |b| {
        let mut k = 0u64;
        b.iter(|| {
            k += dt;
            black_box(rot.at(&ep.times(black_box(k))))
        })
    });
    c.final_summary();

    let mut sc = common::reference(
        GravityModel::PointMass {
            mu_m3_s2: common::MU_EARTH,
        },
        0.0,
    );
    let step = median_ns(|_| {
        sc.step();
        black_box(sc.t_sim_ns());
    });
    let rows: [(&str, f64); 5] = [
        (
            "SimEpoch::times",
            median_ns(|k| {
                black_box(ep.times(black_box(k * dt)));
            }),
        ),
        (
            "SimEpoch::utc_calendar",
            median_ns(|k| {
                black_box(ep.utc_calendar(black_box(k * dt)));
            }),
        ),
        (
            "CelestialPole::at",
            median_ns(|k| {
                black_box(CelestialPole::at(
                    ep.times(black_box(k * dt)).tt_centuries_j2000(),
                ));
            }),
        ),
        (
            "times + at_with_pole (pole held)",
            median_ns(|k| {
                black_box(rot.at_with_pole(&pole, &ep.times(black_box(k * dt))));
            }),
        ),
        (
            "times + EarthRotation::at (full)",
            median_ns(|k| {
                black_box(rot.at(&ep.times(black_box(k * dt))));
            }),
        ),
    ];
    println!("time_rotation (medians of {BATCHES} x {CALLS} calls; t_sim advances 1 ms per call)");
    println!(
        "  {:<34} {step:>9.1} ns  (baseline)",
        "RK4 step, reference spacecraft"
    );
    for (name, ns) in rows {
        println!(
            "  {name:<34} {ns:>9.1} ns  ({:.3} x the RK4 step)",
            ns / step
        );
    }
}
