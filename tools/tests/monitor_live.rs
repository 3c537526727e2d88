//! `flexdyn-monitor --plain` against a real-time server on the LEO scenario (in this process, on
//! a loopback port the OS chose): the line shows the eclipse state, |B| and the density from the
//! environment message, and every sensor with its rate.

mod support;

use std::process::Command;
use std::time::Duration;

use flexdyn_proto::{eclipse, EnvironmentMsg};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use support::{endpoint, ServerHandle};

#[test]
fn the_monitor_shows_the_eclipse_state_the_field_and_the_sensors() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/leo_environment.toml");
    let cfg = SimConfig::from_file(&path).unwrap();
    // The truth at the start, in this process: the eclipse state the monitor must name. The
    // scenario's first seconds are far from a shadow boundary (checked: ν is exactly 0 or 1).
    let mut env = EnvironmentMsg::default();
    Simulation::new(&cfg).unwrap().environment_into(&mut env);
    assert!(env.shadow_factor == 0.0 || env.shadow_factor == 1.0);
    let expected = match env.eclipse {
        eclipse::SUNLIT => "sunlit",
        _ => "umbra",
    };
    let mut server = ServerHandle::start(ServerSettings::default(), cfg);
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn-monitor"))
        .args(["--connect", &endpoint(server.port), "--plain"])
        .args(["--interval-s", "1", "--duration-s", "3.5"])
        .output()
        .unwrap();
    server.stop();
    server.join(Duration::from_secs(10)).unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    // The last full interval: every stream has been heard for a whole second.
    let line = stdout.lines().last().unwrap();
    let env_part = line
        .split(" | ")
        .find(|p| p.starts_with("env "))
        .unwrap_or_else(|| panic!("no env segment: {line}"));
    assert!(
        env_part.starts_with(&format!("env {expected} nu=")),
        "{line}"
    );
    // |B| at 500 km: between the dipole's equatorial and polar values scaled by (R/r)³,
    // 30 µT·0.80 ≈ 24 µT and 60 µT·0.80 ≈ 48 µT (IGRF's non-dipole terms add a few µT).
    let b_ut: f64 = env_part
        .split("|B|=")
        .nth(1)
        .and_then(|s| s.split("uT").next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no |B|: {line}"));
    assert!((18.0..55.0).contains(&b_ut), "{line}");
    assert!(env_part.contains(" rho="), "{line}");
    // The scenario's three sensors at their configured 10 Hz (±1 message for the interval's
    // edges).
    let sensors = line
        .split(" | ")
        .find(|p| p.starts_with("sensors "))
        .unwrap_or_else(|| panic!("no sensors segment: {line}"));
    for name in ["mag/mag1", "css/css", "fss/fss"] {
        let rate: f64 = sensors
            .split(&format!("{name}="))
            .nth(1)
            .and_then(|s| s.split("/s").next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("no {name}: {line}"));
        assert!((9.0..=11.0).contains(&rate), "{name}: {line}");
    }
}

/// `--vehicles a,b`: two real-time servers (two vehicles, each on its own port, reached with two
/// `--connect`s) give one line per vehicle each interval, prefixed with its id, each with that
/// vehicle's own data: the reference spacecraft with no sensors, and the LEO scenario with its
/// environment and sensors.
#[test]
fn the_monitor_gives_each_vehicle_its_own_line() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let leo = SimConfig::from_file(&root.join("scenarios/leo_environment.toml")).unwrap();
    let reference = SimConfig::from_file(&root.join("scenarios/reference.toml")).unwrap();
    let settings = |sc_id: &str| ServerSettings {
        sc_id: sc_id.into(),
        ..ServerSettings::default()
    };
    let mut a = ServerHandle::start(settings("chief"), reference);
    let mut b = ServerHandle::start(settings("deputy"), leo);
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn-monitor"))
        .args([
            "--connect",
            &endpoint(a.port),
            "--connect",
            &endpoint(b.port),
        ])
        .args(["--vehicles", "chief,deputy", "--plain"])
        .args(["--interval-s", "1", "--duration-s", "3.5"])
        .output()
        .unwrap();
    for s in [&mut a, &mut b] {
        s.stop();
        s.join(Duration::from_secs(10)).unwrap();
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    let lines: Vec<&str> = stdout.lines().collect();
    // Three whole intervals, two lines each, in the order given.
    assert!(
        lines.len() >= 6 && lines.len().is_multiple_of(2),
        "{stdout}"
    );
    let (chief, deputy) = (lines[lines.len() - 2], lines[lines.len() - 1]);
    assert!(chief.starts_with("[chief] t="), "{chief}");
    assert!(deputy.starts_with("[deputy] t="), "{deputy}");
    // Each line is its own vehicle's: only the LEO vehicle has an environment and sensors.
    assert!(
        !chief.contains(" | env ") && !chief.contains(" | sensors "),
        "{chief}"
    );
    assert!(
        deputy.contains(" | env ") && deputy.contains("mag/mag1="),
        "{deputy}"
    );
    for l in [chief, deputy] {
        assert!(l.contains(" realtime running "), "{l}");
    }

    // An id listed twice is a usage error naming it.
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn-monitor"))
        .args(["--vehicles", "chief,chief", "--plain", "--duration-s", "0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("\"chief\" is listed twice"), "{stderr}");
}

/// The fault segment (issue 21): a real-time server on the wheel scenario with three
/// configured faults — #0 the gyro biased from the start (activated before the monitor
/// listens: only the served configuration names it), #1 a wheel seized at 1000 s (never active
/// here), #2 another wheel torque-limited from 0.5 s — and a live fault put on
/// `flexdyn/sc1/fault` while the monitor runs (#3, named only by its fault event). The last
/// line lists exactly the active ones, by index, target and mode.
#[test]
fn the_monitor_names_the_active_faults() {
    use flexdyn_proto::{encode, FaultAction, FaultCommandMsg, FaultTarget, Header, AT_NEXT_TICK};
    use zenoh::Wait;

    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scenario =
        std::fs::read_to_string(root.join("scenarios/wheels_star_tracker.toml")).unwrap();
    let fault = |target: &str, mode: &str, start_s: f64| {
        format!("\n[[faults]]\ntarget = \"{target}\"\n{mode}\nstart_s = {start_s}\n")
    };
    let cfg = SimConfig::from_toml_str(&format!(
        "{scenario}{}{}{}",
        fault("imus.hub.gyro", "mode = \"bias_step\"\nvalue = 0.1", 0.0),
        fault("reaction_wheels.rw2", "mode = \"seized\"", 1000.0),
        fault(
            "reaction_wheels.rw3",
            "mode = \"torque_limit\"\nfraction = 0.5",
            0.5
        ),
    ))
    .unwrap();
    let mut server = ServerHandle::start(ServerSettings::default(), cfg);
    let monitor = Command::new(env!("CARGO_BIN_EXE_flexdyn-monitor"))
        .args(["--connect", &endpoint(server.port), "--plain"])
        .args(["--interval-s", "1", "--duration-s", "4.5"])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let operator = support::connecting_session(server.port);
    let live = FaultCommandMsg {
        header: Header::new(1, 0, 0, 0),
        action: FaultAction::Inject,
        at_tick: AT_NEXT_TICK,
        fault_index: 0,
        mode: 4, // scale
        params: [2.0, 0.0],
        axes: 0,
        duration_ns: 0,
        seed: 0,
        target: FaultTarget::new("imus.hub.accel").unwrap(),
    };
    operator
        .put("flexdyn/sc1/fault", encode(&live))
        .wait()
        .unwrap();
    let out = monitor.wait_with_output().unwrap();
    let _ = operator.close().wait();
    server.stop();
    server.join(Duration::from_secs(10)).unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    let line = stdout.lines().last().unwrap();
    let faults = line
        .split(" | ")
        .find(|p| p.starts_with("faults "))
        .unwrap_or_else(|| panic!("no faults segment: {line}"));
    assert_eq!(
        faults,
        "faults active=3 [#0 imus.hub.gyro bias_step; #2 reaction_wheels.rw3 torque_limit; \
         #3 imus.hub.accel scale]",
        "{line}"
    );
}
