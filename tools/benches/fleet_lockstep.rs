//! Fleet lockstep scaling: ticks/s of `flexdyn run --fleet` in lockstep with 1, 2, 4, 8 and 16
//! vehicles, each closed by its own `flexdyn-acs-demo` process (issue 22).
//!
//! Every vehicle is the reference spacecraft at 100 Hz frames (10 RK4 steps per frame), the
//! deputies spaced along-track behind the first; vehicle `v<i>` is answered by sender `i + 1`.
//! The fleet server runs in this process (`server::fleet::run`, what `flexdyn run --fleet`
//! calls), the controllers are child processes. Each round measures every fleet size in turn
//! (so a change of machine load hits every size alike); the medians are printed with
//! - the ratio to the 1-vehicle rate (the target: ≥ 0.5 at 8 vehicles on 2 cores);
//! - the physics time per vehicle and frame (the fleet physics thread's stepping and telemetry
//!   fill, timed by the server itself) and the share of the wall time it takes.
//!
//! `cargo bench -p flexdyn-tools --bench fleet_lockstep`; environment: `FLEXDYN_BENCH_TICKS`
//! (default 2000 ticks per measurement), `FLEXDYN_BENCH_ROUNDS` (default 3),
//! `FLEXDYN_BENCH_FLEETS` (default `1,2,4,8,16`). Ports: the OS's.

use flexdyn_testkit::demo_bin;
use flexdyn_testkit::median_mut;
use flexdyn_testkit_server as support;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use flexdyn_proto::Mode;
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::world::FleetConfig;
use support::{endpoint, ChildGuard, FleetServerHandle};

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// `n` reference spacecraft, `v1 … v<n-1>` 50 m apart behind `v0`.
fn fleet(n: usize) -> FleetConfig {
    let mut text = String::new();
    for i in 0..n {
        text.push_str(&format!(
            "[[vehicles]]\nid = \"v{i}\"\nspacecraft_file = \"scenarios/reference.toml\"\n\
             participants = [{}]\n",
            i + 1
        ));
        if i > 0 {
            text.push_str(&format!(
                "[vehicles.relative]\nchief = \"v0\"\nhill_position_m = [0.0, {}.0, 0.0]\n",
                -50 * i as i64
            ));
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    FleetConfig::from_toml_str_in(&text, &root).unwrap()
}

/// One fleet run of `ticks` frames.
struct Measured {
    ticks_per_s: f64,
    /// \[µs\] physics per vehicle and frame.
    physics_us: f64,
    /// Shares of the wall time on the physics thread: physics, publishing, waiting for the
    /// answers.
    shares: [f64; 3],
}

fn fleet_rate(n: usize, ticks: usize) -> Measured {
    let fleet = fleet(n);
    let frame_ns = fleet.vehicles[0].cfg.frame_ns;
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        duration_ns: Some(ticks as u64 * frame_ns),
        summary_interval: Duration::from_secs(3600),
        presence_timeout: Duration::from_secs(120),
        ..ServerSettings::default()
    };
    let server = FleetServerHandle::start(settings, fleet);
    let port = server.port;
    let _ctrls: Vec<ChildGuard> = (0..n)
        .map(|i| {
            ChildGuard::spawn(Command::new(demo_bin::acs_demo()).args([
                "--connect",
                &endpoint(port),
                "--sc-id",
                &format!("v{i}"),
                "--sender-id",
                &(i + 1).to_string(),
                "--log-every-s",
                "0",
                "--rate-source",
                "truth",
            ]))
        })
        .collect();
    let report = server
        .join(Duration::from_secs(600))
        .expect("fleet lockstep run");
    let wall_s = report.vehicles[0].1.wall_s;
    let share = |ns: u64| ns as f64 * 1e-9 / wall_s;
    Measured {
        ticks_per_s: report.frames as f64 / wall_s,
        physics_us: report.physics_ns_per_vehicle_frame() * 1e-3,
        shares: [
            share(report.physics_ns),
            share(report.publish_ns),
            share(report.wait_ns),
        ],
    }
}

fn main() {
    // `cargo bench` passes `--bench`; ignore arguments.
    let ticks = env_usize("FLEXDYN_BENCH_TICKS", 2000);
    let rounds = env_usize("FLEXDYN_BENCH_ROUNDS", 3).max(1);
    let sizes: Vec<usize> = std::env::var("FLEXDYN_BENCH_FLEETS")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![1, 2, 4, 8, 16]);
    println!(
        "fleet lockstep benchmark: {rounds} rounds x {ticks} ticks, fleets {sizes:?}, one \
         acs-demo process per vehicle, reference spacecraft (10 RK4 steps per frame), loopback \
         TCP, {} CPUs",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let mut rates = vec![Vec::new(); sizes.len()];
    let mut phys = vec![Vec::new(); sizes.len()];
    let mut shares = vec![[Vec::new(), Vec::new(), Vec::new()]; sizes.len()];
    for r in 0..rounds {
        for (j, &n) in sizes.iter().enumerate() {
            let m = fleet_rate(n, ticks);
            println!(
                "round {r}: {n:>2} vehicles: {:.0} ticks/s, physics {:.1} us per vehicle frame; \
                 wall time: physics {:.0} %, publishing {:.0} %, waiting for answers {:.0} %",
                m.ticks_per_s,
                m.physics_us,
                m.shares[0] * 100.0,
                m.shares[1] * 100.0,
                m.shares[2] * 100.0
            );
            rates[j].push(m.ticks_per_s);
            phys[j].push(m.physics_us);
            for (s, x) in shares[j].iter_mut().zip(m.shares) {
                s.push(x);
            }
        }
    }
    let base = median_mut(&mut rates[0].clone());
    println!(
        "| vehicles | ticks/s (median) | ratio to {} | physics us per vehicle frame | wall time: \
         physics / publishing / waiting for answers |",
        sizes[0]
    );
    println!("|---|---|---|---|---|");
    for (j, &n) in sizes.iter().enumerate() {
        let rate = median_mut(&mut rates[j]);
        let [a, b, c] = &mut shares[j];
        println!(
            "| {n} | {rate:.0} | {:.3} | {:.1} | {:.0} % / {:.0} % / {:.0} % |",
            rate / base,
            median_mut(&mut phys[j]),
            median_mut(a) * 100.0,
            median_mut(b) * 100.0,
            median_mut(c) * 100.0
        );
    }
}
