//! Issue 24 §2: the integrators side by side, measured in the same run.
//!
//! 1. Cost per step of each method (`[simulation] integrator`) on the reference spacecraft (two
//!    panel pairs) with four reaction wheels, point-mass gravity: median of 15 batches of 2,000
//!    steps, and the ratio to RK4.
//! 2. Energy and angular-momentum drift of a free multibody spacecraft (the reference wings with
//!    springs and no damping, four frictionless wheels spinning at 100 rad/s, no wrench, no
//!    gravity) and of the same spacecraft in LEO under point-mass gravity, over
//!    `FLEXDYN_DRIFT_SPAN_S` simulated seconds (default 1e4 s, so the whole bench stays under ~3
//!    minutes on one core; `1e6` is the span, all measured, nothing extrapolated). Each
//!    method runs at its own step, `FLEXDYN_DRIFT_STEP_MS_<NAME>` (`..._RK4`, `..._RK8`; default
//!    RK4 1 ms, RK8 4 ms: comparable wall time per simulated second, 13 stages against 4 and
//!    ~4.5× the cost per step); a step must divide the 10 s sampling interval. The printed drift
//!    is the largest relative error seen up to 1e3 s, 1e4 s, 1e5 s and the end (sampled every
//!    10 s).
//!
//! Target (issue 24): ≤ 1e-10 relative energy error over 1e6 s.

use flexdyn_dynamics::reference as common;

use std::time::Instant;

use flexdyn_dynamics::integrator::{ButcherTableau, METHODS};
use flexdyn_dynamics::{GravityModel, Spacecraft};
use nalgebra::Vector3;

/// The reference wings (k > 0, c = 0) and four frictionless wheels in a pyramid at 100 rad/s.
fn spacecraft(gravity: GravityModel, step_ns: u64, method: &'static ButcherTableau) -> Spacecraft {
    let effectors = common::reference_effectors_with_wheels(4, |_| {});
    let mut sc = Spacecraft::new(
        common::reference_hub(),
        gravity,
        effectors,
        common::reference_initial(),
        step_ns,
    )
    .unwrap();
    sc.set_integrator(method);
    sc
}

fn leo() -> GravityModel {
    GravityModel::PointMass {
        mu_m3_s2: common::MU_EARTH,
    }
}

/// Median ns per step of `method` over 15 batches of 2,000 steps (after 2,000 warm-up steps).
fn ns_per_step(method: &'static ButcherTableau) -> f64 {
    common::median_ns_per_step(&mut spacecraft(leo(), 1_000_000, method), 15, 2_000)
}

/// The step [ns] each method runs at in the drift study: `FLEXDYN_DRIFT_STEP_MS_<NAME>` [ms], or
/// the default (RK4 1 ms, RK8 4 ms). It must divide the 10 s sampling interval.
fn drift_step_ns(method: &ButcherTableau) -> u64 {
    let default_ms = match method.name {
        "rk4" => 1.0,
        "rk8" => 4.0,
        other => panic!("no drift step for integrator {other}: add one"),
    };
    let var = format!("FLEXDYN_DRIFT_STEP_MS_{}", method.name.to_uppercase());
    let ms: f64 = match std::env::var(&var) {
        Ok(s) => s
            .parse()
            .unwrap_or_else(|_| panic!("{var}={s}: not a number of milliseconds")),
        Err(_) => default_ms,
    };
    let step_ns = (ms * 1e6).round() as u64;
    assert!(
        step_ns > 0 && 10_000_000_000 % step_ns == 0,
        "{var}={ms}: the step must divide the 10 s sampling interval"
    );
    step_ns
}

/// The simulated times [s] at which the running maximum is reported (those within the span).
const CHECKPOINTS_S: [u64; 3] = [1_000, 10_000, 100_000];

/// Largest relative drifts (rotational energy, angular momentum about C, orbital energy,
/// orbital angular momentum) up to each checkpoint and to the end, and the wall time [s].
struct Drift {
    at: [[f64; 4]; 3],
    end: [f64; 4],
    wall_s: f64,
}

fn drift(gravity: GravityModel, method: &'static ButcherTableau, span_s: f64) -> Drift {
    let step_ns = drift_step_ns(method);
    let mut sc = spacecraft(gravity, step_ns, method);
    let c0 = sc.conserved();
    let rel = |a: f64, b: f64| if b == 0.0 { 0.0 } else { ((a - b) / b).abs() };
    let relv = |a: Vector3<f64>, b: Vector3<f64>| {
        if b.norm() == 0.0 {
            0.0
        } else {
            (a - b).norm() / b.norm()
        }
    };
    let per_sample = 10_000_000_000 / step_ns;
    let samples = (span_s / 10.0).round() as u64;
    let mut worst = [0.0f64; 4];
    let mut at = [[f64::NAN; 4]; 3];
    let t = Instant::now();
    for k in 1..=samples {
        for _ in 0..per_sample {
            sc.step();
        }
        let c = sc.conserved();
        let now = [
            rel(c.rot_energy_j, c0.rot_energy_j),
            relv(c.rot_ang_mom_c_n, c0.rot_ang_mom_c_n),
            rel(c.orb_energy_j, c0.orb_energy_j),
            relv(c.orb_ang_mom_n, c0.orb_ang_mom_n),
        ];
        for (w, n) in worst.iter_mut().zip(now) {
            *w = w.max(n);
        }
        for (slot, &t_s) in at.iter_mut().zip(&CHECKPOINTS_S) {
            if k * 10 == t_s {
                *slot = worst;
            }
        }
    }
    Drift {
        at,
        end: worst,
        wall_s: t.elapsed().as_secs_f64(),
    }
}

fn main() {
    // `cargo bench` passes `--bench`; a filter argument selects nothing here.
    println!("integrators (issue 24): cost per step, reference spacecraft + 4 wheels, LEO");
    println!(
        "{:>8} {:>7} {:>16} {:>12}",
        "method", "stages", "median ns/step", "vs rk4"
    );
    let costs: Vec<(&ButcherTableau, f64)> = METHODS.iter().map(|m| (*m, ns_per_step(m))).collect();
    let rk4_ns = costs[0].1;
    for (m, ns) in &costs {
        println!(
            "{:>8} {:>7} {:>16.0} {:>11.2}x",
            m.name,
            m.stages(),
            ns,
            ns / rk4_ns
        );
    }

    let span_s: f64 = std::env::var("FLEXDYN_DRIFT_SPAN_S")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1e4);
    for (label, gravity) in [
        (
            "free multibody (panels + wheels, no damping)",
            GravityModel::None,
        ),
        ("LEO, point-mass gravity", leo()),
    ] {
        println!(
            "\n{label}: relative drift, max over the run so far (sampled every 10 s), span {span_s:e} s"
        );
        println!(
            "{:>8} {:>8} {:>9} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11}",
            "method",
            "step_s",
            "wall_s",
            "E_rot@1e3s",
            "E_rot@1e4s",
            "E_rot@1e5s",
            "E_rot@end",
            "H_C@end",
            "E_orb@end",
            "H_orb@end"
        );
        for m in METHODS {
            let d = drift(gravity, m, span_s);
            println!(
                "{:>8} {:>8} {:>9.1} {:>11.2e} {:>11.2e} {:>11.2e} {:>11.2e} {:>11.2e} {:>11.2e} {:>11.2e}",
                m.name,
                drift_step_ns(m) as f64 * 1e-9,
                d.wall_s,
                d.at[0][0],
                d.at[1][0],
                d.at[2][0],
                d.end[0],
                d.end[1],
                d.end[2],
                d.end[3],
            );
        }
    }
    println!("\nNaN: checkpoint beyond the span. Target (issue 24): E_rot <= 1e-10 over 1e6 s");
}
