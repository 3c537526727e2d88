//! Steps the reference spacecraft (or `N` ring pairs) `STEPS` times, for `perf stat` cycle counts:
//! `cargo build --release --example perf_probe && perf stat -e cycles:u,instructions:u target/release/examples/perf_probe 2 200000`.
use flexdyn_dynamics::reference as common;

fn main() {
    let mut args = std::env::args().skip(1);
    let pairs: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(2);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(200_000);
    let gravity = flexdyn_dynamics::GravityModel::PointMass {
        mu_m3_s2: common::MU_EARTH,
    };
    let pp = if pairs == 2 {
        common::reference_pairs(0.0)
    } else {
        common::ring_pairs(pairs, 0.0)
    };
    let mut sc = common::build(
        common::reference_hub(),
        gravity,
        pp,
        common::reference_initial(),
        1_000_000,
    );
    for _ in 0..steps {
        sc.step();
    }
    println!("{:?}", sc.state().omega_bn_b);
}
