//! One RK4 step of the reference spacecraft with 1, 2, 4, 8 and 16 panel pairs.
//!
//! Targets (issue 2): ≤ 2 µs per step for 2 pairs on one core, cost linear in the pair count at
//! ≤ 0.5 µs per added pair. After criterion's own report this prints a summary of medians
//! (31 batches of 20,000 steps per size) and the least-squares cost per added pair.
//!
//! Peers in the same run: with `FLEXDYN_PEERS_PYTHON` pointing at a Python that has
//! `mujoco==4.0.0` and `bsk==2.12.1` (see `tools/peers/README.md`), the bench then runs
//! `tools/peers/{mujoco,basilisk}_step.py` one after the other — the same spacecraft, RK4 at 1 ms —
//! and prints each peer's median next to flexdyn's, with the ratio.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;
use std::time::Instant;

use criterion::{BenchmarkId, Criterion};
use flexdyn::dynamics::{GravityModel, Spacecraft};

const PAIR_COUNTS: [usize; 5] = [1, 2, 4, 8, 16];

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
    group.finish();
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Runs a peer script; returns (pairs, median ns per step) from its `peer=… pairs=N median_ns_per_step=x` lines.
fn run_peer(python: &str, script: &str) -> Result<Vec<(usize, f64)>, String> {
    let out = std::process::Command::new(python)
        .arg(script)
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
                field("pairs=")?.parse().ok()?,
                field("median_ns_per_step=")?.parse().ok()?,
            ))
        })
        .collect();
    if rows.is_empty() {
        return Err(format!(
            "{script} printed no `pairs=… median_ns_per_step=…` lines"
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

fn summary() -> Vec<(f64, f64)> {
    let batches = 31;
    let steps = 20_000;
    let mut rows = Vec::new();
    for n in PAIR_COUNTS {
        let mut sc = spacecraft(n);
        for _ in 0..steps {
            sc.step();
        }
        let per_step: Vec<f64> = (0..batches)
            .map(|_| {
                let t = Instant::now();
                for _ in 0..steps {
                    sc.step();
                }
                black_box(sc.state().omega_bn_b);
                t.elapsed().as_secs_f64() * 1e9 / steps as f64
            })
            .collect();
        rows.push((n as f64, median(per_step)));
    }
    // Least-squares line through (pairs, median ns).
    let m = rows.len() as f64;
    let (sx, sy) = rows
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (sxx, sxy) = rows
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x * x, b + x * y));
    let slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
    let intercept = (sy - slope * sx) / m;
    println!("\nrk4_step summary (median of {batches} batches x {steps} steps):");
    println!("{:>6} {:>14} {:>14}", "pairs", "median ns/step", "steps/s");
    for (n, ns) in &rows {
        println!("{:>6} {:>14.1} {:>14.0}", n, ns, 1e9 / ns);
    }
    println!("linear fit: {intercept:.1} ns + {slope:.1} ns per pair");
    println!("targets: 2 pairs <= 2000 ns/step, <= 500 ns per added pair");
    rows
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bench_step(&mut c);
    c.final_summary();
    let rows = summary();
    peers(&rows);
}
