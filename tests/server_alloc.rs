//! The per-frame path allocates and frees nothing: command intake and bookkeeping (wrench and
//! wheel `Actuators` commands, the latter handed back through the recycle channel), then the
//! server's own [`Stepper`] — the code both the physics thread and the direct lockstep core run
//! — holding the commands, integrating the RK4 frame, sampling the IMU and star tracker,
//! filling the telemetry and checking it finite, the tick's note in the run's [`TickCost`]
//! (its period into the histogram), and the buffer hand-off through the bounded channels; and
//! beside it, the check of the flight code's telemetry arriving at 1 kHz (the
//! work of the `flexdyn/<sc>/fsw/*` callback for an accepted sample).
//!
//! `assert_no_alloc`'s global allocator counts (de)allocations made on this thread inside
//! `assert_no_alloc(..)` (features `warn_debug`/`warn_release`: count and warn, don't abort).

use std::sync::mpsc::sync_channel;

use assert_no_alloc::{assert_no_alloc, reset_violation_count, violation_count, AllocDisabler};
use flexdyn_faults::ports::{Installed, LiveRequest};
use flexdyn_proto::{CommandMsg, EffectorInput, FaultAction, FaultCommandMsg, FaultTarget, Header};
use flexdyn_server::shared::Frame;
use flexdyn_server::stepper::Stepper;
use flexdyn_server::tick_cost::TickCost;
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;

#[global_allocator]
static ALLOC: AllocDisabler = AllocDisabler;

/// The reference spacecraft with four reaction wheels, an IMU and a star tracker.
const WHEELS: &str = include_str!("../scenarios/wheels_star_tracker.toml");

#[test]
fn the_frame_path_does_not_allocate() {
    frame_path_does_not_allocate(&SimConfig::from_toml_str(WHEELS).unwrap());
}

/// With faults at both ports, active over most of the measured frames (frames of 10 ms, from
/// 0.5 s): sensor value modes with and without draws, a repeating dropout, validity off, and
/// wheel faults that read the state (friction) and that replace the command (on rw1, which the
/// final check does not look at).
#[test]
fn the_frame_path_does_not_allocate_with_faults() {
    let text = format!(
        "{WHEELS}
[[faults]]
target = \"imus.hub.gyro\"
mode = \"noise\"
sigma = 0.001
start_s = 0.5
[[faults]]
target = \"imus.hub\"
mode = \"stuck_current\"
start_s = 0.5
duration_s = 0.3
period_s = 0.5
[[faults]]
target = \"star_trackers.st1\"
mode = \"dropout\"
start_s = 0.5
duration_s = 0.05
period_s = 0.2
[[faults]]
target = \"star_trackers.st1\"
mode = \"validity_off\"
start_s = 1.0
[[faults]]
target = \"reaction_wheels.rw1\"
mode = \"friction_scale\"
factor = 3.0
start_s = 0.5
[[faults]]
target = \"reaction_wheels.rw1\"
mode = \"torque_limit\"
fraction = 0.5
start_s = 1.0
"
    );
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    assert_eq!(cfg.faults.len(), 6);
    frame_path_does_not_allocate(&cfg);
}

/// Command-link faults, active over part of the measured frames (frames of 10 ms): sender 2's
/// wheel `Actuators` commands through a `corrupted` link over ticks 50–99 (at this bit error
/// rate most are damaged; those that pass the checks are read in place and taken, the others
/// refused), sender 1's wrench through a `delayed` link over ticks 30–79 and a `dropped` one
/// over ticks 120–139; and a spiking gyro. The corrupted window ends before the final check.
#[test]
fn the_frame_path_does_not_allocate_with_link_faults() {
    let text = format!(
        "{WHEELS}
[server]
participants = [1, 2]
[[faults]]
target = \"links.2\"
mode = \"corrupted\"
probability = 0.002
start_s = 0.5
duration_s = 0.5
[[faults]]
target = \"links.1\"
mode = \"delayed\"
frames = 3.0
start_s = 0.3
duration_s = 0.5
[[faults]]
target = \"links.1\"
mode = \"dropped\"
start_s = 1.2
duration_s = 0.2
[[faults]]
target = \"imus.hub.gyro\"
mode = \"spikes\"
probability = 0.2
amplitude = 0.01
start_s = 0.2
"
    );
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    assert_eq!(cfg.faults.len(), 4);
    frame_path_does_not_allocate(&cfg);
}

/// Live faults (protocol 8): requests resolved off the measured region (as the fault callback
/// does on the Zenoh thread), installed on the stepping path into the reserved slots (a gyro
/// bias, a seized wheel, then clears of a configured and a live fault), their boxes handed to
/// the recycle channel; the events they and the configured faults cause are noted and moved
/// into the frames, all inside the measured region.
#[test]
fn installing_live_faults_and_noting_their_events_does_not_allocate() {
    let text = format!(
        "{WHEELS}
[[faults]]
target = \"star_trackers.st1\"
mode = \"dropout\"
start_s = 0.5
duration_s = 0.05
period_s = 0.2
"
    );
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    let resolver = cfg.live_fault_resolver().unwrap();
    let cmd = |action, at_tick, target: &str, mode, params, index| FaultCommandMsg {
        header: Header::new(1, 0, 0, 0),
        action,
        at_tick,
        fault_index: index,
        mode,
        params,
        axes: 0,
        duration_ns: 0,
        seed: 3,
        target: FaultTarget::new(target).unwrap(),
    };
    let live = vec![
        (
            20,
            cmd(FaultAction::Inject, 30, "imus.hub.gyro", 2, [0.1, 0.0], 0),
        ),
        (
            40,
            cmd(
                FaultAction::Inject,
                41,
                "reaction_wheels.rw1",
                11,
                [0.0; 2],
                0,
            ),
        ),
        (90, cmd(FaultAction::Clear, 95, "", 0, [0.0; 2], 0)),
        (100, cmd(FaultAction::Clear, 120, "", 0, [0.0; 2], 1)),
    ];
    let requests = live
        .into_iter()
        .map(|(k, c)| (k, resolver.resolve(&c).unwrap()))
        .collect();
    frame_path_with_live_faults(&cfg, requests);
}

fn frame_path_does_not_allocate(cfg: &SimConfig) {
    frame_path_with_live_faults(cfg, Vec::new());
}

/// Issue 37: the flight code's telemetry arriving at 1 kHz, one sample per frame of a 1 kHz
/// server, each judged by the server's telemetry intake ([`FswIntake::check`], what the
/// subscriber's callback runs) beside the frame path, as on the Zenoh thread that in
/// lockstep's direct hand-off both takes the samples and steps the frames. Every sample is
/// accepted (a mode, an event every 50th tick, an estimate with variances, 7 value words), and
/// neither the intake nor the frame path allocates.
#[test]
fn the_frame_path_does_not_allocate_with_telemetry_at_1_khz() {
    use flexdyn_proto::{encode, fsw_flags, FswMsg, Topics};
    use flexdyn_server::fsw::FswIntake;
    let text = format!(
        "{}\n[[fsw_streams]]\nname = \"acs\"\nmodes = [\"detumble\", \"pointing\"]\n\
         events = [{{ name = \"target-chosen\" }}]\n\
         values = [{{ name = \"rate_b_rad_s\", type = \"f64\", len = 3 }}, \
         {{ name = \"wheel_momentum_b_nms\", type = \"f64\", len = 3 }}, \
         {{ name = \"sun_visible\", type = \"bool\" }}]\n",
        WHEELS.replace("frame_hz = 100.0 ", "frame_hz = 1000.0 ")
    );
    let cfg = SimConfig::from_toml_str(&text).unwrap();
    assert_eq!(cfg.frame_ns, 1_000_000, "frames of 1 ms");
    let topics = Topics::new("sc1").unwrap();
    let intake = FswIntake::new(&topics, cfg.fsw_streams.clone(), 1, cfg.frame_ns, None).unwrap();
    let key = flexdyn_proto::fsw_key("sc1", "acs").unwrap();
    // Encoded up front, as they arrive from the wire.
    let samples: Vec<Vec<u8>> = (0..200u64)
        .map(|k| {
            let mut m = FswMsg {
                header: Header::new(1, k, k * cfg.frame_ns, k),
                flags: fsw_flags::MODE | fsw_flags::ESTIMATE | fsw_flags::COVARIANCE,
                mode: u32::from(k >= 100),
                q_est_bn: [1.0, 0.0, 0.0, 0.0],
                att_var_b_rad2: [1e-10; 3],
                values: vec![1e-3f64.to_bits(), 0, 0, 0, 0, 0, 1],
                ..FswMsg::default()
            };
            if k % 50 == 0 {
                m.event_count = 1;
            }
            encode(&m)
        })
        .collect();
    let mut accepted = 0u32;
    frame_path_with(&cfg, Vec::new(), &mut |k| {
        if intake.check(&key, &samples[k as usize], k) == Ok(Some(0)) {
            accepted += 1;
        }
    });
    assert_eq!(accepted, 200, "every sample accepted, ticks 0..199");
}

/// The frame path over 200 frames, installing each live request before stepping its frame.
fn frame_path_with_live_faults(cfg: &SimConfig, live: Vec<(u64, LiveRequest)>) {
    frame_path_with(cfg, live, &mut |_| {});
}

/// The frame path over 200 frames, installing each live request before stepping its frame
/// and running `beside(k)` before frame k (inside the measured region from frame 1).
fn frame_path_with(
    cfg: &SimConfig,
    mut live: Vec<(u64, LiveRequest)>,
    beside: &mut dyn FnMut(u64),
) {
    let sim = Simulation::new(cfg).unwrap();
    assert!(sim.n_imus() > 0);
    assert!(!sim.star_trackers().is_empty());
    let shape = sim.blank_state();
    let n_sensors = sim.sensors().len();
    let n_events = sim.faults().event_capacity();
    let live_count = live.len();
    live.reverse();
    let (fault_recycle_tx, fault_recycle_rx) = sync_channel::<Installed>(16);
    let mut events_seen = 0usize;
    let settings = ServerSettings {
        participants: vec![1, 2],
        ..ServerSettings::default()
    };
    let mut w = Stepper::new(sim, &settings);
    let (cmd_tx, cmd_rx) = sync_channel::<CommandMsg>(16);
    let (free_tx, free_rx) = sync_channel::<Box<Frame>>(2);
    let (full_tx, full_rx) = sync_channel::<Box<Frame>>(2);
    for _ in 0..2 {
        free_tx
            .send(Box::new(
                Frame::for_state(&shape, n_sensors).with_fault_events(n_events),
            ))
            .unwrap();
    }
    // Sender 2 commands the four wheels (effectors 2–5). Its Actuators commands own heap
    // vectors: they are built here, as the Zenoh callback thread builds them, and after use the
    // physics side hands them to the recycle channel, as the server does, to be freed by the
    // I/O side (here: after the measured region).
    let mut wheel_commands: Vec<CommandMsg> = (0..200u64)
        .rev()
        .map(|k| {
            let inputs = (0..4)
                .map(|j| EffectorInput {
                    effector_index: 2 + j,
                    values: vec![0.01 * f64::from(j + 1)],
                })
                .collect();
            CommandMsg::actuators(Header::new(1, k, 0, k), 2, [0.0; 3], [0.0; 3], inputs)
        })
        .collect();
    let (recycle_tx, recycle_rx) = sync_channel::<CommandMsg>(512);
    let mut ticks = TickCost::default();
    let mut frame_once = |k: u64| {
        beside(k);
        ticks.published(k, std::time::Instant::now());
        let wrench = CommandMsg::wrench(Header::new(1, k, 0, k), 1, [0.0, 0.0, 0.01], [0.0; 3]);
        cmd_tx.try_send(wrench).unwrap();
        cmd_tx.try_send(wheel_commands.pop().unwrap()).unwrap();
        w.book.begin_tick(k);
        while let Ok(cmd) = cmd_rx.try_recv() {
            w.book.offer_lockstep(&cmd, k);
            recycle_tx.try_send(cmd).unwrap();
        }
        assert!(w.book.all_answered());
        while live.last().is_some_and(|(at, _)| *at == k) {
            let (_, req) = live.pop().unwrap();
            let installed = w.install_fault(req, k).unwrap();
            fault_recycle_tx.try_send(installed).unwrap();
        }
        w.step(k);
        let mut f = free_rx.try_recv().unwrap();
        w.fill(&mut f, k + 1);
        events_seen += f.fault_events.len();
        w.check_finite(k + 1, true).unwrap();
        full_tx.try_send(f).unwrap();
        // The I/O side returns the buffer.
        free_tx.try_send(full_rx.try_recv().unwrap()).unwrap();
    };
    // Warm up (first-use thread-locals, lazily sized buffers).
    frame_once(0);
    reset_violation_count();
    assert_no_alloc(|| {
        for k in 1..200 {
            frame_once(k);
        }
    });
    assert_eq!(violation_count(), 0, "the frame path allocated");
    // Frames 0 to 199 were stepped.
    ticks.frames = 200;
    let periods = ticks.summary().unwrap();
    assert!(periods.period_max_us > 0.0, "{periods:?}");
    let links = w.book.link_stats();
    if w.book
        .links()
        .faults()
        .iter()
        .any(|f| f.target == "links.2")
    {
        // The corrupted window did damage commands, and some of them passed the checks.
        assert_eq!(links.commands_corrupted, 50, "{links:?}");
        assert!(links.corrupted_rejected < 50, "{links:?}");
    }
    // The wheels were commanded (torques 0.01–0.04 N·m held), and the recycled commands are
    // freed here, on the "I/O side".
    let s = w.sim.state_msg();
    assert_eq!(s.effectors[3].outputs[0], 0.02);
    assert_eq!(recycle_rx.try_iter().count(), 400);
    assert_eq!(fault_recycle_rx.try_iter().count(), live_count);
    if live_count > 0 {
        // The dropout's activations and clearances, the two live faults' activations and
        // their clears: all noted on the measured path.
        assert!(events_seen >= 8, "{events_seen} events");
        assert_eq!(w.sim.faults().events_lost, 0);
    }
}

/// Fleet mode: one physics thread steps every vehicle ([`WorldStepper`]), with one barrier over
/// every participant of every vehicle. Three vehicles (the wheel scenario twice, the second 100 m
/// behind the first, the first with a repeating gyro fault and a wheel fault whose events each
/// frame carries; the reference spacecraft), sender 9 answering all three: the per-frame work
/// (offers, step, fill with the fault events and the pair's relative state, finite check)
/// allocates nothing.
#[test]
fn the_fleet_frame_path_does_not_allocate() {
    use flexdyn_server::world::WorldStepper;
    use flexdyn_vehicle::world::{FleetConfig, World};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let faulty =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("server_alloc_fleet_a.toml");
    std::fs::write(
        &faulty,
        format!(
            "{}\n[[faults]]\ntarget = \"imus.hub.gyro\"\nmode = \"noise\"\nsigma = 0.01\n\
             start_s = 0.3\nduration_s = 0.2\nperiod_s = 0.5\n\n[[faults]]\n\
             target = \"reaction_wheels.rw1\"\nmode = \"friction_scale\"\nfactor = 3.0\n\
             start_s = 0.7\nduration_s = 0.4\n",
            std::fs::read_to_string(root.join("scenarios/wheels_star_tracker.toml")).unwrap()
        ),
    )
    .unwrap();
    let fleet = FleetConfig::from_toml_str_in(
        &format!(
            r#"
[[vehicles]]
id = "a"
spacecraft_file = "{}"
participants = [1, 9]
[[vehicles]]
id = "b"
spacecraft_file = "scenarios/wheels_star_tracker.toml"
participants = [2, 9]
[vehicles.relative]
chief = "a"
hill_position_m = [0.0, -100.0, 0.0]
[[vehicles]]
id = "c"
spacecraft_file = "scenarios/reference.toml"
participants = [9]
"#,
            faulty.display()
        ),
        root,
    )
    .unwrap();
    let settings: Vec<ServerSettings> = fleet
        .vehicles
        .iter()
        .map(|v| ServerSettings {
            participants: v.participants.clone(),
            spacecraft_id: v.spacecraft_id,
            ..ServerSettings::default()
        })
        .collect();
    // With the (a, b) pair's relative state, filled with the frames.
    let world = World::new(&fleet).unwrap();
    let pairs = world.relative_pairs().to_vec();
    assert_eq!(pairs, [(0, 1)]);
    let mut f = WorldStepper::new(world.into_vehicles(), &settings).with_relative_pairs(&pairs);
    let (cmd_tx, cmd_rx) = sync_channel::<(usize, CommandMsg)>(16);
    let frame_once = |f: &mut WorldStepper, k: u64| {
        for (v, senders) in [(0usize, [1u32, 9]), (1, [2, 9]), (2, [9, 9])] {
            for s in senders.iter().take(if v == 2 { 1 } else { 2 }) {
                let id = u32::try_from(v + 1).unwrap();
                let cmd =
                    CommandMsg::wrench(Header::new(id, k, 0, k), *s, [0.0, 0.0, 0.01], [0.0; 3]);
                cmd_tx.try_send((v, cmd)).unwrap();
            }
        }
        f.begin_tick(k);
        while let Ok((v, cmd)) = cmd_rx.try_recv() {
            f.offer_lockstep(v, &cmd, k);
        }
        assert!(f.all_answered(), "tick {k}: {:?}", f.first_unanswered());
        f.step(k);
        f.fill(k + 1).unwrap();
    };
    frame_once(&mut f, 0);
    // Vehicle a's active-fault count at ticks 40, 90, 120, and the events its frames carried.
    let (mut active_at, mut events) = ([u64::MAX; 3], 0);
    reset_violation_count();
    assert_no_alloc(|| {
        for k in 1..200 {
            frame_once(&mut f, k);
            let a = f.vehicles[0]
                .frame
                .as_deref()
                .expect("a fleet vehicle's own buffer");
            events += a.fault_events.len();
            if let Some(i) = [40, 90, 120].iter().position(|t| *t == k + 1) {
                active_at[i] = a.faults_active.0;
            }
        }
    });
    assert_eq!(violation_count(), 0, "the fleet frame path allocated");
    // The faults came and went meanwhile: the gyro on [0.3, 0.5) s every 0.5 s (4 activations
    // and 4 clearances by 2 s), the wheel on [0.7, 1.1) s.
    assert_eq!(active_at, [1, 2, 0], "active faults at ticks 40, 90, 120");
    assert_eq!(events, 10, "fault events filled into vehicle a's frames");
    // Every vehicle stepped 200 frames.
    for v in &f.vehicles {
        let frame = v.frame.as_deref().expect("a fleet vehicle's own buffer");
        assert_eq!(frame.state.header.tick, 200, "{}", v.id);
    }
    // And the pair's relative state is that of tick 200 (b started 100 m behind a).
    let rel = &f.pairs[0].msg;
    assert_eq!((rel.header.tick, rel.chief_spacecraft_id), (200, 1));
    assert!(rel.range_m > 50.0 && rel.range_m < 150.0, "{rel:?}");
}
