//! `[[faults]]` load errors: a fault that targets something that does not exist, a mode the
//! target's kind does not take, a missing, foreign or out-of-range parameter, a bad window or a
//! bad axis is a configuration error naming the entry's field, never a silent no-op. And a
//! valid entry resolves to the documented port, window, axes and seed.

use flexdyn_faults::{failure_delay_ns, FaultMode, FaultWindow, Port};
use flexdyn_vehicle::config::SimConfig;

const ACS_FULL: &str = include_str!("../../scenarios/acs_full.toml");

fn with_faults(entries: &[&str]) -> String {
    let mut text = ACS_FULL.to_string();
    for e in entries {
        text.push_str("\n[[faults]]\n");
        text.push_str(e);
        text.push('\n');
    }
    text
}

#[test]
fn errors_name_the_field_and_the_problem() {
    let ok = "target = \"imus.hub.gyro\"\nmode = \"dropout\"";
    for (entry, field, words) in [
        (
            "target = \"gyros.hub\"\nmode = \"dropout\"",
            "faults[1].target",
            "unknown section \"gyros\"",
        ),
        (
            "target = \"imus.nope.gyro\"\nmode = \"dropout\"",
            "faults[1].target",
            "named \"nope\"",
        ),
        (
            "target = \"imus.hub.temperature\"\nmode = \"dropout\"",
            "faults[1].target",
            "no channel \"temperature\"",
        ),
        (
            "target = \"imus.hub.gyro.x\"\nmode = \"dropout\"",
            "faults[1].target",
            "<section>.<name>[.<channel>]",
        ),
        (
            "target = \"reaction_wheels.rw9\"\nmode = \"seized\"",
            "faults[1].target",
            "named \"rw9\"",
        ),
        (
            "target = \"reaction_wheels.rw2.motor\"\nmode = \"seized\"",
            "faults[1].target",
            "<section>.<name>",
        ),
        (
            "target = \"imus.hub\"\nmode = \"melted\"",
            "faults[1].mode",
            "unknown mode \"melted\"",
        ),
        (
            "target = \"reaction_wheels.rw2\"\nmode = \"bias_step\"\nvalue = 1.0",
            "faults[1].mode",
            "does not apply",
        ),
        (
            "target = \"imus.hub\"\nmode = \"validity_off\"",
            "faults[1].mode",
            "does not apply",
        ),
        (
            "target = \"thrusters.thr_pz1\"\nmode = \"seized\"",
            "faults[1].mode",
            "does not apply",
        ),
        (
            "target = \"magnetorquers.mtq_x\"\nmode = \"stuck_on\"",
            "faults[1].mode",
            "does not apply",
        ),
        (
            "target = \"imus.hub.gyro\"\nmode = \"bias_step\"",
            "faults[1].value",
            "missing",
        ),
        (
            "target = \"imus.hub.gyro\"\nmode = \"scale\"\nfactor = 2.0\nvalue = 1.0",
            "faults[1].value",
            "not a parameter of mode \"scale\"",
        ),
        (
            "target = \"imus.hub.gyro\"\nmode = \"spikes\"\nprobability = 1.5\namplitude = 1.0",
            "faults[1].probability",
            "[0, 1]",
        ),
        (
            "target = \"imus.hub.gyro\"\nmode = \"noise\"\nsigma = -1.0",
            "faults[1].sigma",
            "≥ 0",
        ),
        (
            "target = \"reaction_wheels.rw2\"\nmode = \"torque_limit\"\nfraction = 2.0",
            "faults[1].fraction",
            "[0, 1]",
        ),
        (
            "target = \"imus.hub\"\nmode = \"dropout\"\nperiod_s = 2.0",
            "faults[1].period_s",
            "needs duration_s",
        ),
        (
            "target = \"imus.hub\"\nmode = \"dropout\"\nperiod_s = 1.0\nduration_s = 1.0",
            "faults[1].period_s",
            "longer than duration_s",
        ),
        (
            // acs_full.toml steps at 10 ms: a 5 ms period would alias.
            "target = \"imus.hub\"\nmode = \"dropout\"\nperiod_s = 0.005\nduration_s = 0.001",
            "faults[1].period_s",
            "at least the integration step (10000000 ns)",
        ),
        (
            "target = \"imus.hub\"\nmode = \"dropout\"\nduration_s = 0.0",
            "faults[1].duration_s",
            "> 0",
        ),
        (
            "target = \"imus.hub\"\nmode = \"dropout\"\nstart_s = -1.0",
            "faults[1].start_s",
            "nanoseconds",
        ),
        (
            "target = \"imus.hub.gyro\"\nmode = \"scale\"\nfactor = 2.0\naxes = [4]",
            "faults[1].axes[0]",
            "from 1 to 3",
        ),
        (
            "target = \"imus.hub.gyro\"\nmode = \"scale\"\nfactor = 2.0\naxes = [1.5]",
            "faults[1].axes[0]",
            "integer",
        ),
        (
            "target = \"imus.hub\"\nmode = \"dropout\"\naxes = [1]",
            "faults[1].axes",
            "no axes",
        ),
        (
            "target = \"imus.hub\"\nmode = \"dropout\"\nstrat_s = 1.0",
            "faults[1].strat_s",
            "unknown key",
        ),
        ("mode = \"dropout\"", "faults[1].target", ""),
        (
            "target = \"imus.hub\"\nmode = \"dropout\"\nmtbf_s = 0.0",
            "faults[1].mtbf_s",
            "> 0",
        ),
        // Command links: a participant of server.participants (default [1]), link modes only.
        (
            "target = \"links.7\"\nmode = \"dropped\"",
            "faults[1].target",
            "participant 7 is not in server.participants [1]",
        ),
        (
            "target = \"links.01\"\nmode = \"dropped\"",
            "faults[1].target",
            "links.<sender id>",
        ),
        (
            "target = \"links.1.cmd\"\nmode = \"dropped\"",
            "faults[1].target",
            "links.<sender id>",
        ),
        (
            "target = \"links\"\nmode = \"dropped\"",
            "faults[1].target",
            "links.<sender id>",
        ),
        (
            "target = \"links.1\"\nmode = \"dropout\"",
            "faults[1].mode",
            "does not apply to a command link (it takes dropped, delayed, corrupted)",
        ),
        (
            "target = \"imus.hub\"\nmode = \"dropped\"",
            "faults[1].mode",
            "does not apply",
        ),
        (
            "target = \"reaction_wheels.rw2\"\nmode = \"delayed\"\nframes = 2.0",
            "faults[1].mode",
            "does not apply",
        ),
        (
            "target = \"links.1\"\nmode = \"delayed\"",
            "faults[1].frames",
            "missing",
        ),
        (
            "target = \"links.1\"\nmode = \"delayed\"\nframes = 2.5",
            "faults[1].frames",
            "whole number of frames from 1 to 10000",
        ),
        (
            "target = \"links.1\"\nmode = \"delayed\"\nframes = 0.0",
            "faults[1].frames",
            "whole number of frames from 1 to 10000",
        ),
        (
            "target = \"links.1\"\nmode = \"corrupted\"\nprobability = -0.1",
            "faults[1].probability",
            "[0, 1]",
        ),
    ] {
        let e = SimConfig::from_toml_str(&with_faults(&[ok, entry])).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains(field), "{entry}: {msg}");
        assert!(msg.contains(words), "{entry}: {msg}");
    }
}

#[test]
fn a_valid_entry_resolves_to_its_port_window_axes_and_seed() {
    let cfg = SimConfig::from_toml_str(&with_faults(&[
        "target = \"imus.hub.dtheta\"\nmode = \"bias_step\"\nvalue = 0.5\naxes = [1, 3]\n\
         start_s = 1.5\nduration_s = 0.25\nperiod_s = 2.0",
        "target = \"reaction_wheels.rw2\"\nmode = \"torque_limit\"\nfraction = 0.25\nseed = 11",
    ]))
    .unwrap();
    assert_eq!(cfg.faults.len(), 2);
    let f = &cfg.faults[0];
    assert_eq!(f.mode, FaultMode::BiasStep { value: 0.5 });
    // The IMU's channels are gyro, accel, dtheta, dv.
    assert!(matches!(
        f.port,
        Port::Sensor {
            channel: Some(2),
            ..
        }
    ));
    assert_eq!(f.axes, 0b101);
    assert_eq!(
        f.window,
        FaultWindow {
            start_ns: 1_500_000_000,
            duration_ns: Some(250_000_000),
            period_ns: Some(2_000_000_000),
        }
    );
    // The default seed is the entry's index.
    assert_eq!(f.seed, 0);
    let w = &cfg.faults[1];
    assert_eq!(w.mode, FaultMode::TorqueLimit { fraction: 0.25 });
    assert_eq!(w.seed, 11);
    assert_eq!(w.window, FaultWindow::from(0));
    // The port is the index of rw2 among the effectors.
    let Port::Actuator { effector } = w.port else {
        panic!("{:?}", w.port)
    };
    let names: Vec<String> = flexdyn_vehicle::sim::Simulation::new(&cfg)
        .unwrap()
        .spacecraft()
        .effector_entries()
        .map(|e| e.name.to_string())
        .collect();
    assert_eq!(names[effector], "rw2");
}

/// A random fault starts at `start_s` + a time to failure drawn from its seed: the same for the
/// same seed (bit for bit, load after load), another for another seed, and over many seeds
/// exponential with mean MTBF: the sample mean of n = 4000 draws is within 4σ/√n = 0.063 MTBF
/// of it (σ = MTBF), and P(T < MTBF) = 1 − e⁻¹ = 0.632 within 4·√(p(1 − p)/n) = 0.031.
#[test]
fn random_faults_draw_an_exponential_failure_time_from_their_seed() {
    let entry = |seed: u64| {
        format!(
            "target = \"reaction_wheels.rw2\"\nmode = \"seized\"\nstart_s = 10.0\n\
             mtbf_s = 500.0\nseed = {seed}"
        )
    };
    let start = |seed: u64| {
        SimConfig::from_toml_str(&with_faults(&[&entry(seed)]))
            .unwrap()
            .faults[0]
            .window
            .start_ns
    };
    assert_eq!(start(3), start(3));
    assert_eq!(start(3), 10_000_000_000 + failure_delay_ns(500.0, 3));
    assert_ne!(start(3), start(4));
    let n = 4000;
    let draws: Vec<f64> = (0..n)
        .map(|s| failure_delay_ns(500.0, s) as f64 * 1e-9)
        .collect();
    let mean = draws.iter().sum::<f64>() / n as f64;
    assert!((mean - 500.0).abs() < 0.063 * 500.0, "mean {mean}");
    let below = draws.iter().filter(|t| **t < 500.0).count() as f64 / n as f64;
    assert!((below - (1.0 - (-1.0_f64).exp())).abs() < 0.031, "{below}");
}

/// A command-link target resolves to the participant's sender id, checked against the file's
/// `server.participants`; the server checks it again against its final participants (the
/// command line may change them), naming the same field.
#[test]
fn a_link_target_is_a_participant_of_the_server() {
    let text = with_faults(&["target = \"links.2\"\nmode = \"delayed\"\nframes = 3.0"]).replace(
        "[simulation]",
        "[server]\nparticipants = [1, 2]\n\n[simulation]",
    );
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    assert_eq!(cfg.faults[0].port, Port::Link { sender_id: 2 });
    assert_eq!(cfg.faults[0].mode, FaultMode::Delayed { frames: 3.0 });
    let mut settings = flexdyn_server::ServerSettings::from_table(&cfg.server).unwrap();
    settings.check_link_faults(&cfg).unwrap();
    settings.participants = vec![1];
    let e = settings.check_link_faults(&cfg).unwrap_err().to_string();
    assert!(e.contains("faults[0].target"), "{e}");
    assert!(
        e.contains("participant 2 is not in server.participants [1]"),
        "{e}"
    );
}
