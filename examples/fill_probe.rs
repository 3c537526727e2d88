use std::time::Instant;
fn main() {
    let text = std::fs::read_to_string("scenarios/leo_environment.toml").unwrap();
    let cfg = flexdyn::config::SimConfig::from_toml_str(&text).unwrap();
    let sim = flexdyn::sim::Simulation::new(&cfg).unwrap();
    let env = sim.environment().unwrap().clone();
    let x = sim.spacecraft().state();
    let mut s = *env.sample();
    let mut v = Vec::new();
    for b in 0..31 {
        let t = Instant::now();
        for i in 0..2000u64 {
            env.fill(i * 100_000_000 + b, &x.r_bn_n, &x.v_bn_n, &mut s);
        }
        v.push(t.elapsed().as_secs_f64() * 1e9 / 2000.0);
        std::hint::black_box(&s);
    }
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    println!(
        "fill median {:.0} ns  min {:.0} max {:.0}",
        v[15], v[0], v[30]
    );
}
