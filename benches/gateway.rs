//! The device gateway's cost (issue 38), measured in one run:
//!
//! 1. **Per frame, four devices** (the star tracker, the rate sensor, a wheel drive and the
//!    magnetometer of `scenarios/gateway_pointing.devices.toml`, every group fresh every frame,
//!    a quaternion request, a torque command and a speed request every 10th frame): the
//!    engine's work per frame (`emit_due`, `take_bytes`, `drive`), against the physics of one
//!    frame of the same spacecraft (`step_frame` of `gateway_pointing.toml`), same run.
//! 2. **Lockstep with flight code in the loop** on `scenarios/wheels_star_tracker.toml`, the
//!    same pointing loop two ways: the C driver `examples/drivers/pointing_driver.c` through
//!    `flexdyn gateway` (pseudo-terminals), and the demo flight code `flexdyn-acs-demo` over the
//!    Zenoh SDK (wheels, star tracker and gyro). Ticks per second of each, and their ratio,
//!    rounds alternating.
//!
//! `cargo build --release -p flexdyn-acs-demo` first (as for the lockstep bench), then
//! `cargo bench --bench gateway`; `FLEXDYN_BENCH_TICKS` (default 3000 lockstep ticks),
//! `FLEXDYN_BENCH_ROUNDS` (default 3).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use flexdyn_devices::catalog::VehicleCatalog;
use flexdyn_gateway::device::{DeviceSet, TickTime};
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_testkit::{demo_bin, median};
use flexdyn_testkit_server::server::{endpoint, ServerHandle};
use flexdyn_vehicle::checkpoint::Source;
use flexdyn_vehicle::sim::Simulation;

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// \[ns\] the engine's work per frame for the four devices.
fn engine_frame_ns(frames: u64) -> f64 {
    let scenarios = root().join("scenarios");
    let text = std::fs::read_to_string(scenarios.join("gateway_pointing.toml")).unwrap();
    let cat = VehicleCatalog::from_config(&VehicleConfig::from_toml(&text).unwrap());
    let set = DeviceSet::load(
        &scenarios.join("gateway_pointing.devices.toml"),
        cat.catalog(),
    )
    .unwrap();
    let mut devices: Vec<_> = set
        .devices
        .into_iter()
        .filter(|d| ["st1", "imu", "rw1", "mag1"].contains(&d.name()))
        .collect();
    assert_eq!(devices.len(), 4);
    let c = cat.catalog();
    let mut values = vec![0.0; c.channel_count()];
    values[c.channel_index("star_tracker.st1.q_cn[0]").unwrap()] = 1.0;
    values[c.channel_index("star_tracker.st1.valid").unwrap()] = 1.0;
    values[c.channel_index("magnetometer.mag1.b_s_t[0]").unwrap()] = 2.1e-5;
    values[c.channel_index("imu.hub.omega_p_rad_s[2]").unwrap()] = 0.01;
    values[c.channel_index("wheel.rw1.speed_rad_s").unwrap()] = 100.0;
    let fresh = vec![true; c.group_count()];
    let mut commands = vec![0.0; c.input_count()];
    let room: usize = devices.iter().map(|d| d.max_output_len()).max().unwrap();
    let mut out = Vec::with_capacity(room);
    // A quaternion request (sync, LEN 1, id, CRC-16/CCITT-FALSE) and a wheel's torque command
    // and speed request (SLIP, CRC-16/KERMIT), as the C driver writes them.
    let request = [0xEB, 0x90, 0x01, 0x01, 0x45, 0x1C];
    let wheel = [
        0xC0, 0x10, 0xE8, 0x03, 0x57, 0x90, 0xC0, 0xC0, 0x20, 0x02, 0x21, 0xC0,
    ];
    let mut now = TickTime {
        has_epoch: true,
        tai_ns_1958: 2_100_000_000_000_000_000,
        ..TickTime::default()
    };
    let t = Instant::now();
    for k in 0..frames {
        now.tick = k;
        now.sim_time_ns = k * 10_000_000;
        for d in devices.iter_mut() {
            out.clear();
            d.emit_due(&now, &values, &fresh, &mut out);
            if k % 10 == 0 {
                let input: &[u8] = match d.name() {
                    "st1" => &request,
                    "rw1" => &wheel,
                    _ => &[],
                };
                out.clear();
                d.take_bytes(input, &now, &values, &mut commands, &mut out);
            }
            d.drive(&now, &values, &mut commands);
        }
    }
    std::hint::black_box((&out, &commands));
    let ns = t.elapsed().as_secs_f64() * 1e9 / frames as f64;
    // Every request must have been taken, or the figure measures the garbage path.
    let st1 = devices.iter().find(|d| d.name() == "st1").unwrap();
    assert_eq!(st1.counters().accepted_frames(), frames.div_ceil(10));
    let rw1 = devices.iter().find(|d| d.name() == "rw1").unwrap();
    assert_eq!(rw1.counters().accepted_frames(), 2 * frames.div_ceil(10));
    ns
}

/// \[ns\] the physics of one frame of gateway_pointing.toml.
fn physics_frame_ns(frames: u64) -> f64 {
    let cfg = Source::of(Some(&root().join("scenarios/gateway_pointing.toml")))
        .unwrap()
        .config()
        .unwrap();
    let mut sim = Simulation::new(&cfg).unwrap();
    let mut state = sim.blank_state();
    let t = Instant::now();
    for _ in 0..frames {
        sim.step_frame();
        sim.state_into(&mut state);
    }
    std::hint::black_box(&state);
    t.elapsed().as_secs_f64() * 1e9 / frames as f64
}

fn lockstep_server(ticks: usize) -> ServerHandle {
    ServerHandle::lockstep_on(
        &root().join("scenarios/wheels_star_tracker.toml"),
        vec![1],
        ticks as u64 * 10_000_000,
    )
}

/// Ticks per second of the C driver through the gateway.
fn gateway_rate(driver: &Path, ticks: usize, dir: &Path) -> f64 {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).unwrap();
    let server = lockstep_server(ticks);
    let mut gw = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .arg("gateway")
        .arg("--devices")
        .arg(root().join("scenarios/wheels_star_tracker.devices.toml"))
        .arg("--link-dir")
        .arg(dir)
        .args(["--connect", &endpoint(server.port)])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let give_up = Instant::now() + Duration::from_secs(60);
    while !dir.join("rw4.tty").exists() {
        assert!(Instant::now() < give_up, "the gateway made no links");
        std::thread::sleep(Duration::from_millis(5));
    }
    let mut drv = Command::new(driver)
        .arg(dir)
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let report = server.join(Duration::from_secs(600)).unwrap();
    let _ = drv.wait();
    let _ = gw.wait();
    report.last_tick as f64 / report.wall_s
}

/// Ticks per second of the demo flight code over the Zenoh SDK, the same loop.
fn sdk_rate(ticks: usize) -> f64 {
    let server = lockstep_server(ticks);
    let mut demo = Command::new(demo_bin::acs_demo())
        .args(["--connect", &endpoint(server.port), "--sender-id", "1"])
        .args(["--k-nm", "10", "--p-nms", "150", "--actuator", "wheels"])
        .args(["--attitude-source", "star-tracker", "--star-tracker", "st1"])
        .args([
            "--rate-source",
            "gyro",
            "--imu",
            "hub",
            "--log-every-s",
            "0",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let report = server.join(Duration::from_secs(600)).unwrap();
    let _ = demo.wait();
    report.last_tick as f64 / report.wall_s
}

fn main() {
    let ticks = env_usize("FLEXDYN_BENCH_TICKS", 3000);
    let rounds = env_usize("FLEXDYN_BENCH_ROUNDS", 3).clamp(1, 11);
    let tmp = std::env::temp_dir().join(format!("flexdyn-gateway-bench-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let driver = tmp.join("pointing_driver");
    flexdyn_testkit::c_program::compile_c99(
        &root().join("examples/drivers/pointing_driver.c"),
        &driver,
        &["-lm"],
    );
    println!("gateway benchmark: {rounds} rounds; lockstep {ticks} ticks of wheels_star_tracker");
    let (mut eng, mut phys, mut gw, mut sdk, mut ratio) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for r in 0..rounds {
        let e = engine_frame_ns(200_000);
        let p = physics_frame_ns(20_000);
        let g = gateway_rate(&driver, ticks, &tmp.join("links"));
        let s = sdk_rate(ticks);
        println!(
            "round {r}: engine {e:.0} ns/frame (4 devices), physics {p:.0} ns/frame ({:.3} of it); \
             lockstep C driver via gateway {g:.0} ticks/s, SDK {s:.0} ticks/s ({:.2}x)",
            e / p,
            g / s
        );
        eng.push(e);
        phys.push(p);
        gw.push(g);
        sdk.push(s);
        ratio.push(g / s);
    }
    let (e, p) = (median(eng), median(phys));
    println!(
        "median: gateway engine {e:.0} ns per frame with 4 devices = {:.3} x the physics of the \
         frame ({p:.0} ns); lockstep {:.0} ticks/s through the gateway vs {:.0} ticks/s over \
         the Zenoh SDK: ratio {:.2}",
        e / p,
        median(gw),
        median(sdk),
        median(ratio)
    );
    let _ = std::fs::remove_dir_all(&tmp);
}
