//! Campaign throughput: runs per minute and simulated seconds per wall second, for open-loop
//! runs (the observer participant only) and for runs with `flexdyn-acs-demo` in the loop, each
//! with `--jobs 2` against the serial baseline (`--jobs 1`) measured in the same process.
//!
//! `cargo bench -p flexdyn-tools --bench campaign`; environment `FLEXDYN_BENCH_CAMPAIGN_RUNS`
//! (default 8 runs of 10 s each). Every run listens on a port the OS chose (`base_port = 0`).

use flexdyn_testkit::demo_bin;

use std::path::Path;
use std::time::Instant;

use flexdyn_campaign::execute::{execute_many, RunOptions};
use flexdyn_campaign::plan::Plan;
use flexdyn_campaign::spec::Campaign;

fn campaign(runs: u32, controller: Option<&str>) -> Plan {
    let c = controller.map_or(String::new(), |c| format!("controller = '''{c}'''\n"));
    let text = format!(
        "runs = {runs}\nseed = 5\nduration_s = 10.0\nsigma_rn = [0.1, 0.2, -0.1]\n{c}
[[dispersions]]
key = \"hub.inertia_bc_b_kg_m2[0][0]\"
distribution = \"normal\"
sigma = 45.0
[[criteria]]
name = \"pointing\"
quantity = \"sigma_br\"
statistic = \"final\"
below = 0.01
"
    );
    Plan::new(Campaign::from_str_at(&text, Path::new("bench.toml")).unwrap()).unwrap()
}

fn main() {
    let runs: u32 = std::env::var("FLEXDYN_BENCH_CAMPAIGN_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(8);
    let demo = format!(
        "{} --connect {{endpoint}} --sc-id {{sc_id}} --sender-id {{sender_id}} \
         --sigma-rn 0.1,0.2,-0.1 --rate-source truth --log-every-s 0 --idle-exit-s 1",
        demo_bin::acs_demo()
    );
    println!("campaign throughput: {runs} runs of 10 s simulated (100 Hz, reference spacecraft), 2-core machine");
    println!(
        "{:<34} {:>6} {:>10} {:>12} {:>16}",
        "case", "jobs", "wall s", "runs/min", "sim s / wall s"
    );
    let dir = std::env::temp_dir().join(format!("flexdyn-bench-campaign-{}", std::process::id()));
    let mut case = 0u32;
    for (name, controller) in [
        ("open loop (observer only)", None),
        ("lockstep with flexdyn-acs-demo", Some(demo.as_str())),
    ] {
        let plan = campaign(runs, controller);
        let mut serial = 0.0;
        for jobs in [1usize, 2] {
            let out = dir.join(format!("{case}"));
            let planned = plan.write(&out).unwrap();
            let opts = RunOptions {
                dir: out,
                base_port: 0,
                record: false,
            };
            case += 1;
            let indices: Vec<u32> = (0..runs).collect();
            let t = Instant::now();
            let results = execute_many(&plan, &planned, &indices, jobs, &opts);
            let wall = t.elapsed().as_secs_f64();
            assert!(results.iter().all(|r| r.status == "ok"), "a run failed");
            let sim: f64 = results.iter().map(|r| r.sim_s).sum();
            if jobs == 1 {
                serial = wall;
            }
            println!(
                "{name:<34} {jobs:>6} {wall:>10.2} {:>12.1} {:>16.1}{}",
                f64::from(runs) / wall * 60.0,
                sim / wall,
                if jobs > 1 {
                    format!("   speed-up vs serial {:.2}", serial / wall)
                } else {
                    "   (serial baseline)".into()
                }
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
