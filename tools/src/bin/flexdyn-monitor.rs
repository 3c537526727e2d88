//! `flexdyn-monitor`: the live telemetry and the server status, for operators.
//!
//! In a terminal it is a full-screen UI (ratatui): the summary below, split over lines, and
//! sparklines of |σ_BN|, |ω_BN|, each panel angle |θ1|, |θ2|, the shadow factor (with an
//! environment message) and the server's p99 frame lateness (`q`, Esc or Ctrl-C quits). With `--plain`, or when standard output is not a
//! terminal (a pipe, a log file, CI), it prints one line per interval instead:
//!
//! ```text
//! t=12.340s tick=1234 states/s=100.0 gaps=0 |sigma_bn|=0.1234 |omega|=0.0456rad/s flags=- latency_ms p50=0.120 p99=0.410 | realtime running lateness_us p50=3.1 p99=21.0 max=118.2 overruns=0 skipped=0 cmd_age_ms=10.0 stale=no rejected=0 dropped=0
//! ```
//!
//! With `--vehicles a,b,…` it watches several vehicles (a fleet server's, or several servers'):
//! one such line per vehicle each interval, prefixed `[<id>] `.
//!
//! Before any state arrives it prints `no data: no StateMsg on … yet`, and once states stop it
//! prefixes `no data for N s; last:`, or `running (no status for N s: server gone?)` if the
//! server died. When the server's last status says the run ended (`finished`, `stopped`,
//! `failed`; of every watched vehicle), it prints that interval's line at once, then
//! `run ended: finished at tick N`, and exits 0 (the terminal UI likewise, after restoring
//! the terminal).
//!
//! - `gaps`: StateMsg sequence numbers missing in the interval (lost or dropped frames);
//! - `latency_ms`: frame boundary (the sample's attachment) to receipt here, wall clock;
//! - `flags`: `S` stale command, `Z` zeroed by policy, `N` no command yet;
//! - `wheels`: with reaction wheels, each wheel's speed [rad/s] in effector order, marked `T`
//!   when its motor torque is being clipped and `S` when it is held at its speed limit;
//! - `rods`: with magnetorquers, each rod's applied dipole [A·m²], marked `S` when saturated;
//! - `thrusters`: with thrusters, how many fire now, their pulses and propellant used so far,
//!   and `!min` when a command is below a thruster's minimum on-time;
//! - `env`: with an `[environment]` that publishes its message (`tlm/env`), the eclipse state
//!   (`sunlit`, `penumbra`, `umbra`) with the shadow factor ν, |B| \[µT\] and the density
//!   [kg/m³], each only when its model is on;
//! - `sensors`: every sensor message heard in the interval (`flexdyn/<sc>/tlm/<kind>/<name>`),
//!   as `<kind>/<name>=<messages per second>`;
//! - `rejected`: the server's rejected commands by reason (`stale_tick:2,unknown_sender:1`), and
//!   `dropped` the valid commands it dropped for a full queue;
//! - `faults`: with faults configured or heard of, how many are active (StatusMsg
//!   `faults_active`) and which, by index, target and mode (`faults active=1 [#0 imus.hub.gyro
//!   bias_step]`): the active set is StatusMsg's `faults_active_bits`, the names come from the
//!   served configuration's `[[faults]]` (`flexdyn/<sc>/config`, asked once at start) and from
//!   every fault event heard (`tlm/fault`, live faults included);
//! - `fsw`: each flight-code telemetry stream heard (`flexdyn/<sc>/fsw/<stream>`, which the
//!   server passes on once it has accepted a sample): its current mode and its last event with
//!   the event's severity and time (`fsw acs: mode=fine-pointing last_event=wheel-failure
//!   (error) at t=61.300s`), named by the served configuration's `[[fsw_streams]]`.

use std::io::{IsTerminal as _, Write as _};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use clap::Parser;
use flexdyn_proto::client::fsw::FswDeclaration;
use flexdyn_proto::client::transport::{frame_stamp_ns, mode_name, unix_now_ns};
use flexdyn_proto::{
    command_flags, decode_environment, decode_fault_event, decode_state, decode_status, eclipse,
    effector_kind, environment_flags, magnetorquer_flags, thruster_flags, wheel_flags,
    EffectorState, EnvironmentMsg, RunState, StatusMsg, NO_COMMAND,
};
use flexdyn_tools::{percentile, CommonArgs};
use zenoh::Wait;

/// Live summary of flexdyn telemetry and status.
#[derive(Debug, Parser)]
#[command(name = "flexdyn-monitor", version)]
struct Args {
    #[command(flatten)]
    common: CommonArgs,
    /// Seconds between summary lines.
    #[arg(long, default_value_t = 1.0)]
    interval_s: f64,
    /// Exit after this many seconds: exit 0 if anything was received, exit 1 ("no data") if
    /// nothing was (default: run until SIGINT/SIGTERM).
    #[arg(long)]
    duration_s: Option<f64>,
    /// One summary line per interval on standard output (for logs and CI) instead of the
    /// terminal UI. Implied when standard output is not a terminal.
    #[arg(long)]
    plain: bool,
    /// Watch several vehicles (a fleet server's ids, or the ids of several servers reached
    /// with repeated --connect), comma-separated: one summary per vehicle each interval, each
    /// prefixed `[<id>]`. Default: the --sc-id vehicle alone.
    #[arg(long, value_name = "SC_ID,...", value_delimiter = ',')]
    vehicles: Vec<String>,
}

#[derive(Default)]
struct Window {
    states: u64,
    gaps: u64,
    last_seq: Option<u64>,
    tick: u64,
    sim_time_ns: u64,
    sigma_norm: f64,
    omega_norm: f64,
    flags: u8,
    /// Reaction wheels of the latest state: (speed rad/s, flags).
    wheels: Vec<(f64, u32)>,
    /// The actuators of the latest state, as summarised for the line (empty without them).
    actuators: String,
    /// Panel pairs of the latest state: (θ1, θ2) rad.
    thetas: Vec<(f64, f64)>,
    latencies_ns: Vec<u64>,
    undecodable: u64,
    status: Option<StatusMsg>,
    /// The latest EnvironmentMsg (None: none heard).
    environment: Option<EnvironmentMsg>,
    /// Sensor messages heard in the interval, by `<kind>/<name>`.
    sensors: std::collections::BTreeMap<String, u64>,
    /// When the last StateMsg arrived (None: never).
    last_state_at: Option<Instant>,
    /// When the last StatusMsg arrived (None: never).
    last_status_at: Option<Instant>,
    /// Fault names (`<target> <mode>`) by fault index: the served configuration's
    /// `[[faults]]`, and each fault event heard.
    fault_names: std::collections::BTreeMap<u32, String>,
    /// The flight code's streams heard, by name: the current mode and the last event.
    fsw: std::collections::BTreeMap<String, FswSeen>,
    /// The served configuration's `[[fsw_streams]]`, by name (empty until it arrives).
    fsw_declared: std::collections::BTreeMap<String, FswDeclaration>,
}

/// What the monitor heard of one flight-code telemetry stream.
#[derive(Clone, Debug, Default, PartialEq)]
struct FswSeen {
    /// The mode of the latest sample that named one (index into the stream's modes).
    mode: Option<u32>,
    /// The latest event: (its index, the sample's sim_time_ns).
    last_event: Option<(u16, u64)>,
}

impl FswSeen {
    /// Takes in a sample: its mode if it names one, its last event if it has any.
    fn note(&mut self, m: &flexdyn_proto::FswMsg) {
        if m.flags & flexdyn_proto::fsw_flags::MODE != 0 {
            self.mode = Some(m.mode);
        }
        if let Some(&e) = m.event_indices().last() {
            self.last_event = Some((e, m.header.sim_time_ns));
        }
    }
}

/// The telemetry segment: ` fsw <stream>: mode=<name> last_event=<name> (<severity>) at
/// t=<s>s` per stream heard, names from its declaration (`#<index>` without one).
fn fsw_str(
    seen: &std::collections::BTreeMap<String, FswSeen>,
    declared: &std::collections::BTreeMap<String, FswDeclaration>,
) -> String {
    let mut out = String::new();
    for (stream, s) in seen {
        let decl = declared.get(stream);
        let mode = s.mode.map_or("-".to_owned(), |m| {
            decl.and_then(|d| d.modes.get(m as usize))
                .cloned()
                .unwrap_or_else(|| format!("#{m}"))
        });
        out.push_str(&format!(" fsw {stream}: mode={mode}"));
        if let Some((e, t_ns)) = s.last_event {
            match decl.and_then(|d| d.events.get(usize::from(e))) {
                Some(ev) => out.push_str(&format!(
                    " last_event={} ({}) at t={:.3}s",
                    ev.name,
                    ev.severity,
                    t_ns as f64 / 1e9
                )),
                None => out.push_str(&format!(" last_event=#{e} at t={:.3}s", t_ns as f64 / 1e9)),
            }
        }
    }
    out
}

/// A fault's name: `<target> <mode>` (the mode's code when this build does not know it).
fn fault_name(target: &str, mode: u32) -> String {
    match flexdyn_proto::FAULT_MODE_NAMES.get(mode as usize) {
        Some(m) => format!("{target} {m}"),
        None => format!("{target} mode {mode}"),
    }
}

/// The fault segment: how many faults are active and which (`#<index> <name>`, `#<index>`
/// alone when no name is known), from StatusMsg's active set; those beyond the set's 256 bits
/// are only counted. Empty when no fault is active or known of.
fn faults_str(s: &StatusMsg, names: &std::collections::BTreeMap<u32, String>) -> String {
    if s.faults_active == 0 && names.is_empty() {
        return String::new();
    }
    let active: Vec<String> = (0..flexdyn_proto::MAX_STATUS_FAULTS as u32)
        .filter(|i| s.faults_active_bits[*i as usize / 64] & (1 << (i % 64)) != 0)
        .map(|i| match names.get(&i) {
            Some(n) => format!("#{i} {n}"),
            None => format!("#{i}"),
        })
        .collect();
    let mut out = format!(" faults active={}", s.faults_active);
    if !active.is_empty() {
        let beyond = s.faults_active.saturating_sub(active.len() as u64);
        out.push_str(&format!(" [{}", active.join("; ")));
        if beyond > 0 {
            out.push_str(&format!("; +{beyond} beyond index 255"));
        }
        out.push(']');
    }
    out
}

/// The rejection counters by reason, only the non-zero ones (`0` if none).
fn rejected_by_reason(r: &flexdyn_proto::RejectCounters) -> String {
    let parts: Vec<String> = [
        ("malformed", r.malformed),
        ("bad_version", r.bad_version),
        ("non_finite", r.non_finite),
        ("wrong_spacecraft", r.wrong_spacecraft),
        ("stale_tick", r.stale_tick),
        ("unknown_sender", r.unknown_sender),
        ("bad_effector_input", r.bad_effector_input),
        ("wrong_identity", r.wrong_identity),
        ("operator_refused", r.operator_refused),
        ("fault_refused", r.fault_refused),
        ("fsw_refused", r.fsw_refused),
    ]
    .iter()
    .filter(|(_, n)| *n > 0)
    .map(|(k, n)| format!("{k}:{n}"))
    .collect();
    if parts.is_empty() {
        "0".into()
    } else {
        parts.join(",")
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn flags_str(f: u8) -> String {
    let mut s = String::new();
    if f & command_flags::STALE != 0 {
        s.push('S');
    }
    if f & command_flags::ZEROED_BY_POLICY != 0 {
        s.push('Z');
    }
    if f & command_flags::NO_COMMAND_YET != 0 {
        s.push('N');
    }
    if s.is_empty() {
        s.push('-');
    }
    s
}

/// `[100.0,-52.3T,600.0S]rad/s`: each wheel's speed with `T` (torque-limited) and `S`
/// (speed-limited) marks.
/// The environment segment: the eclipse state with ν, |B| and the density, each only when the
/// message's flags say its model is on.
fn environment_str(env: &EnvironmentMsg) -> String {
    let mut out = String::from(" env");
    if env.flags & environment_flags::SHADOW != 0 {
        let state = match env.eclipse {
            eclipse::SUNLIT => "sunlit",
            eclipse::PENUMBRA => "penumbra",
            eclipse::UMBRA => "umbra",
            _ => "eclipse?",
        };
        out.push_str(&format!(" {state} nu={:.3}", env.shadow_factor));
    }
    if env.flags & environment_flags::MAGNETIC != 0 {
        out.push_str(&format!(" |B|={:.1}uT", norm(env.b_b_t) * 1e6));
    }
    if env.flags & environment_flags::ATMOSPHERE != 0 {
        out.push_str(&format!(" rho={:.2e}kg/m3", env.density_kg_m3));
    }
    if out.len() == " env".len() {
        out.push_str(" (no models on)");
    }
    out
}

/// The sensor segment: each sensor heard in the interval with its message rate.
fn sensors_str(counts: &std::collections::BTreeMap<String, u64>, interval: Duration) -> String {
    if counts.is_empty() {
        return String::new();
    }
    let rates: Vec<String> = counts
        .iter()
        .map(|(k, n)| format!("{k}={:.1}/s", *n as f64 / interval.as_secs_f64()))
        .collect();
    format!(" sensors {}", rates.join(","))
}

fn wheels_str(wheels: &[(f64, u32)]) -> String {
    let parts: Vec<String> = wheels
        .iter()
        .map(|(omega, f)| {
            let mut p = format!("{omega:.1}");
            if f & wheel_flags::TORQUE_LIMITED != 0 {
                p.push('T');
            }
            if f & wheel_flags::SPEED_LIMITED != 0 {
                p.push('S');
            }
            p
        })
        .collect();
    format!("[{}]rad/s", parts.join(","))
}

/// ` rods=[100.0,-400.0S]Am2 thrusters=firing:2/4,pulses=84,propellant_kg=0.0123`: the rods'
/// applied dipoles (`S` saturated) and the thrusters' state, each part only when the vehicle
/// has that kind (empty without actuators).
fn actuators_str(effectors: &[EffectorState]) -> String {
    let out = |e: &EffectorState, i: usize| e.outputs.get(i).copied().unwrap_or(f64::NAN);
    let mut s = String::new();
    let rods: Vec<String> = effectors
        .iter()
        .filter(|e| e.kind == effector_kind::MAGNETORQUER)
        .map(|e| {
            let mark = if e.flags & magnetorquer_flags::SATURATED != 0 {
                "S"
            } else {
                ""
            };
            format!("{:.1}{mark}", out(e, 0))
        })
        .collect();
    if !rods.is_empty() {
        s.push_str(&format!(" rods=[{}]Am2", rods.join(",")));
    }
    let thrusters: Vec<&EffectorState> = effectors
        .iter()
        .filter(|e| e.kind == effector_kind::THRUSTER)
        .collect();
    if !thrusters.is_empty() {
        let firing = thrusters
            .iter()
            .filter(|e| e.flags & thruster_flags::FIRING != 0)
            .count();
        let pulses: f64 = thrusters.iter().map(|e| out(e, 1)).sum();
        let propellant: f64 = thrusters.iter().map(|e| out(e, 2)).sum();
        s.push_str(&format!(
            " thrusters=firing:{firing}/{},pulses={pulses:.0},propellant_kg={propellant:.4}",
            thrusters.len()
        ));
        if thrusters
            .iter()
            .any(|e| e.flags & thruster_flags::BELOW_MIN_ON_TIME != 0)
        {
            s.push_str(",!min");
        }
    }
    s
}

fn run_state_name(s: RunState) -> &'static str {
    match s {
        RunState::Starting => "starting",
        RunState::Running => "running",
        RunState::Stopping => "stopping",
        RunState::Finished => "finished",
        RunState::Failed => "failed",
        RunState::Stopped => "stopped",
        RunState::Paused => "paused",
    }
}

fn line(w: &mut Window, interval: Duration, state_topic: &str) -> String {
    let mut lat = std::mem::take(&mut w.latencies_ns);
    lat.sort_unstable();
    let ms = |v: Option<u64>| v.map_or("-".to_owned(), |ns| format!("{:.3}", ns as f64 * 1e-6));
    let mut out = match w.last_state_at {
        // Never a state: say so, instead of zeros that look like data.
        None => format!(
            "no data: no StateMsg on {state_topic} yet (is the server running and reachable \
             at --connect?)"
        ),
        Some(at) => {
            let age = at.elapsed();
            let mut o = String::new();
            if age > interval {
                o.push_str(&format!("no data for {:.1} s; last: ", age.as_secs_f64()));
            }
            o.push_str(&format!(
                "t={:.3}s tick={} states/s={:.1} gaps={} |sigma_bn|={:.4} |omega|={:.4}rad/s flags={} latency_ms p50={} p99={}",
                w.sim_time_ns as f64 / 1e9,
                w.tick,
                w.states as f64 / interval.as_secs_f64(),
                w.gaps,
                w.sigma_norm,
                w.omega_norm,
                flags_str(w.flags),
                ms(percentile(&lat, 0.5)),
                ms(percentile(&lat, 0.99)),
            ));
            if !w.wheels.is_empty() {
                o.push_str(&format!(" wheels={}", wheels_str(&w.wheels)));
            }
            o.push_str(&w.actuators);
            o
        }
    };
    if w.undecodable > 0 {
        out.push_str(&format!(" undecodable={}", w.undecodable));
    }
    if let Some(env) = &w.environment {
        out.push_str(" |");
        out.push_str(&environment_str(env));
    }
    let sensors = sensors_str(&w.sensors, interval);
    if !sensors.is_empty() {
        out.push_str(" |");
        out.push_str(&sensors);
    }
    match &w.status {
        None => out.push_str(" | no status yet"),
        Some(s) => {
            let us = |ns: u64| ns as f64 * 1e-3;
            let status_age = w.last_status_at.map_or(Duration::ZERO, |t| t.elapsed());
            // A status that stopped coming while it said "running" means the server is gone.
            let state = if status_age > interval.max(Duration::from_millis(500))
                && matches!(s.run_state, RunState::Running | RunState::Starting)
            {
                format!(
                    "{} (no status for {:.1} s: server gone?)",
                    run_state_name(s.run_state),
                    status_age.as_secs_f64()
                )
            } else {
                run_state_name(s.run_state).to_owned()
            };
            out.push_str(&format!(
                " | {} {} lateness_us p50={:.1} p99={:.1} max={:.1} overruns={} skipped={} cmd_age_ms={} stale={} rejected={} dropped={}",
                mode_name(s.mode),
                state,
                us(s.timing.lateness_p50_ns),
                us(s.timing.lateness_p99_ns),
                us(s.timing.lateness_max_ns),
                s.timing.overrun_count,
                s.timing.frames_skipped,
                if s.command.command_age_ns == NO_COMMAND {
                    "none".to_owned()
                } else {
                    format!("{:.1}", s.command.command_age_ns as f64 * 1e-6)
                },
                if s.command.command_stale { "yes" } else { "no" },
                rejected_by_reason(&s.rejected),
                s.commands_dropped,
            ));
            let faults = faults_str(s, &w.fault_names);
            if !faults.is_empty() {
                out.push_str(" |");
                out.push_str(&faults);
            }
        }
    }
    let fsw = fsw_str(&w.fsw, &w.fsw_declared);
    if !fsw.is_empty() {
        out.push_str(" |");
        out.push_str(&fsw);
    }
    w.states = 0;
    w.gaps = 0;
    w.undecodable = 0;
    w.sensors.clear();
    out
}

/// One watched vehicle: its keys, what was heard in the current interval, and the subscribers
/// feeding it (undeclared when it is dropped).
struct Watch {
    topics: flexdyn_proto::Topics,
    window: Arc<Mutex<Window>>,
    _subscribers: [zenoh::pubsub::Subscriber<()>; 6],
}

impl Watch {
    /// Subscribes to the vehicle's state, status, environment, sensor and fault-event keys, and
    /// asks its server for the configured faults' names (in the background: the server may
    /// start later).
    fn declare(session: &zenoh::Session, topics: flexdyn_proto::Topics) -> anyhow::Result<Self> {
        let window = Arc::new(Mutex::new(Window::default()));
        let w = window.clone();
        let _states = session
            .declare_subscriber(topics.state())
            .callback(move |sample| {
                let received = unix_now_ns();
                let mut w = w.lock().unwrap_or_else(|p| p.into_inner());
                match decode_state(&sample.payload().to_bytes()) {
                    Ok(s) => {
                        if let Some(last) = w.last_seq {
                            w.gaps += s.header.seq.saturating_sub(last + 1);
                        }
                        w.last_seq = Some(s.header.seq);
                        w.states += 1;
                        w.tick = s.header.tick;
                        w.sim_time_ns = s.header.sim_time_ns;
                        w.sigma_norm = norm(s.sigma_bn);
                        w.omega_norm = norm(s.omega_bn_b_rad_s);
                        w.flags = s.command_flags;
                        w.wheels.clear();
                        w.wheels.extend(
                            s.effectors
                                .iter()
                                .filter(|e| e.kind == effector_kind::REACTION_WHEEL)
                                .map(|e| (e.states.first().copied().unwrap_or(f64::NAN), e.flags)),
                        );
                        w.actuators = actuators_str(&s.effectors);
                        w.thetas.clear();
                        w.thetas.extend(
                            s.effectors
                                .iter()
                                .filter(|e| e.kind == effector_kind::PANEL_PAIR)
                                .map(|e| {
                                    let th =
                                        |i: usize| e.states.get(i).copied().unwrap_or(f64::NAN);
                                    (th(0), th(2))
                                }),
                        );
                        w.last_state_at = Some(Instant::now());
                        if let Some(stamp) = frame_stamp_ns(&sample) {
                            w.latencies_ns.push(received.saturating_sub(stamp));
                        }
                    }
                    Err(_) => w.undecodable += 1,
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot subscribe to {}: {e}", topics.state()))?;
        let w = window.clone();
        let _status = session
            .declare_subscriber(topics.status())
            .callback(move |sample| {
                if let Ok(s) = decode_status(&sample.payload().to_bytes()) {
                    let mut w = w.lock().unwrap_or_else(|p| p.into_inner());
                    w.status = Some(s);
                    w.last_status_at = Some(Instant::now());
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot subscribe to {}: {e}", topics.status()))?;

        let w = window.clone();
        let env_key = topics.environment();
        let _environment = session
            .declare_subscriber(env_key.as_str())
            .callback(move |sample| {
                if let Ok(e) = decode_environment(&sample.payload().to_bytes()) {
                    w.lock().unwrap_or_else(|p| p.into_inner()).environment = Some(e);
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot subscribe to {env_key}: {e}"))?;
        let w = window.clone();
        // Every sensor key is `flexdyn/<sc>/tlm/<kind>/<name>`: two segments below `tlm`, which
        // the state (`tlm/state`) and environment (`tlm/env`) keys do not have.
        let sensor_keys = format!("flexdyn/{}/tlm/*/*", topics.sc_id());
        let tlm_prefix = format!("flexdyn/{}/tlm/", topics.sc_id());
        let _sensors = session
            .declare_subscriber(sensor_keys.as_str())
            .callback(move |sample| {
                let key = sample.key_expr().as_str();
                let name = key.strip_prefix(tlm_prefix.as_str()).unwrap_or(key);
                let mut w = w.lock().unwrap_or_else(|p| p.into_inner());
                match w.sensors.get_mut(name) {
                    Some(n) => *n += 1,
                    None => {
                        w.sensors.insert(name.to_owned(), 1);
                    }
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot subscribe to {sensor_keys}: {e}"))?;
        let w = window.clone();
        let fault_key = topics.fault_events();
        let _faults = session
            .declare_subscriber(fault_key.as_str())
            .callback(move |sample| {
                if let Ok(e) = decode_fault_event(&sample.payload().to_bytes()) {
                    let name = fault_name(e.target.as_str().unwrap_or("?"), e.mode);
                    let mut w = w.lock().unwrap_or_else(|p| p.into_inner());
                    w.fault_names.insert(e.fault_index, name);
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot subscribe to {fault_key}: {e}"))?;
        let w = window.clone();
        let fsw_key = flexdyn_proto::fsw_wildcard_key(topics.sc_id())
            .map_err(|e| anyhow::anyhow!("the flight-code telemetry key: {e}"))?;
        let fsw_prefix = format!("flexdyn/{}/fsw/", topics.sc_id());
        let _fsw = session
            .declare_subscriber(fsw_key.as_str())
            .callback(move |sample| {
                let key = sample.key_expr().as_str();
                let stream = key.strip_prefix(fsw_prefix.as_str()).unwrap_or(key);
                if let Ok(m) = flexdyn_proto::decode_fsw(&sample.payload().to_bytes()) {
                    let mut w = w.lock().unwrap_or_else(|p| p.into_inner());
                    match w.fsw.get_mut(stream) {
                        Some(seen) => seen.note(&m),
                        None => {
                            let mut seen = FswSeen::default();
                            seen.note(&m);
                            w.fsw.insert(stream.to_owned(), seen);
                        }
                    }
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot subscribe to {fsw_key}: {e}"))?;
        let (w, s, t) = (window.clone(), session.clone(), topics.clone());
        std::thread::spawn(move || {
            use flexdyn_proto::client::vehicle::Vehicle;
            let vehicle = Vehicle::query(&s, &t, Duration::from_secs(60));
            match vehicle.as_ref().map(|v| v.config()) {
                Ok(Ok(c)) => {
                    let mut w = w.lock().unwrap_or_else(|p| p.into_inner());
                    for (i, f) in c.faults.iter().enumerate() {
                        w.fault_names
                            .entry(i as u32)
                            .or_insert_with(|| format!("{} {}", f.target, f.mode));
                    }
                }
                Ok(Err(e)) => tracing::debug!(error = %e, "no fault names from the configuration"),
                Err(e) => tracing::debug!(error = %e, "no configuration served"),
            }
            if let Ok(v) = &vehicle {
                match FswDeclaration::all_from_config_toml(&v.config_toml) {
                    Ok(all) => {
                        let mut w = w.lock().unwrap_or_else(|p| p.into_inner());
                        w.fsw_declared = all.into_iter().map(|d| (d.name.clone(), d)).collect();
                    }
                    Err(e) => tracing::debug!(error = %e, "no telemetry streams declared"),
                }
            }
        });
        Ok(Self {
            topics,
            window,
            _subscribers: [_states, _status, _environment, _sensors, _faults, _fsw],
        })
    }

    /// Whether a state or a status was ever heard.
    fn any_data(&self) -> bool {
        let w = self.window.lock().unwrap_or_else(|p| p.into_inner());
        w.last_state_at.is_some() || w.status.is_some()
    }

    /// How the run ended (the server's last status: finished, stopped or failed) and its last
    /// tick, once the server said so.
    fn ended(&self) -> Option<(RunState, u64)> {
        let w = self.window.lock().unwrap_or_else(|p| p.into_inner());
        w.status
            .filter(|s| s.run_state.ended())
            .map(|s| (s.run_state, s.header.tick))
    }

    /// The interval's summary line (see [`line`](fn@line)), prefixed `[<id>] ` when `prefixed`.
    fn line(&self, interval: Duration, prefixed: bool) -> String {
        let mut w = self.window.lock().unwrap_or_else(|p| p.into_inner());
        let text = line(&mut w, interval, self.topics.state());
        if prefixed {
            format!("[{}] {text}", self.topics.sc_id())
        } else {
            text
        }
    }
}

fn main() -> std::process::ExitCode {
    let args = match flexdyn_tools::parse_args::<Args>() {
        Ok(a) => a,
        Err(code) => return code,
    };
    flexdyn_tools::init_tracing();
    flexdyn_tools::exit_with(run(args))
}

fn run(args: Args) -> anyhow::Result<()> {
    if !(args.interval_s.is_finite() && args.interval_s > 0.0) {
        return Err(flexdyn_tools::usage("--interval-s must be > 0"));
    }
    let ids = if args.vehicles.is_empty() {
        vec![args.common.sc_id.clone()]
    } else {
        args.vehicles.clone()
    };
    let mut topics = Vec::with_capacity(ids.len());
    for id in &ids {
        let t = flexdyn_proto::Topics::new(id)
            .map_err(|e| flexdyn_tools::usage(format!("--vehicles {id:?}: {e}")))?;
        if topics
            .iter()
            .any(|o: &flexdyn_proto::Topics| o.sc_id() == id)
        {
            return Err(flexdyn_tools::usage(format!(
                "--vehicles: {id:?} is listed twice"
            )));
        }
        topics.push(t);
    }
    let session = args.common.open_session()?;
    let mut watches = Vec::with_capacity(topics.len());
    for t in topics {
        watches.push(Watch::declare(&session, t)?);
    }
    for w in &watches {
        tracing::info!(
            state = w.topics.state(),
            status = w.topics.status(),
            "flexdyn-monitor watching (Ctrl-C to stop)"
        );
    }
    let stop = flexdyn_tools::stop_on_signals()?;
    let interval = Duration::from_secs_f64(args.interval_s);
    let tui = !args.plain && std::io::stdout().is_terminal();
    if tui {
        let result = run_tui(&watches, &stop, interval, &args);
        drop(watches);
        let _ = session.close().wait();
        return result;
    }
    let end = args
        .duration_s
        .map(|s| Instant::now() + Duration::from_secs_f64(s.max(0.0)));
    let mut next = Instant::now() + interval;
    loop {
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            break;
        }
        let now = Instant::now();
        if end.is_some_and(|end| now >= end) {
            if !watches.iter().any(Watch::any_data) {
                let keys: Vec<String> = watches
                    .iter()
                    .map(|w| format!("{} or {}", w.topics.state(), w.topics.status()))
                    .collect();
                anyhow::bail!(
                    "no data: nothing received on {} during --duration-s: no server, or it is \
                     not reachable at the --connect endpoint",
                    keys.join(", nor on ")
                );
            }
            break;
        }
        // Sleep in short slices so a signal or the end of the run is noticed promptly.
        std::thread::sleep(
            next.saturating_duration_since(now)
                .min(Duration::from_millis(20)),
        );
        let all_ended = watches.iter().all(|w| w.ended().is_some());
        if Instant::now() < next && !all_ended {
            continue;
        }
        next += interval;
        let several = watches.len() > 1;
        let text: Vec<String> = watches.iter().map(|w| w.line(interval, several)).collect();
        let mut out = std::io::stdout().lock();
        if writeln!(out, "{}", text.join("\n"))
            .and_then(|()| out.flush())
            .is_err()
        {
            // The reader went away (a closed pipe): stop quietly.
            break;
        }
        if all_ended {
            let _ = writeln!(out, "{}", ended_line(&watches));
            break;
        }
    }
    drop(watches);
    session
        .close()
        .wait()
        .map_err(|e| anyhow::anyhow!("closing the Zenoh session: {e}"))?;
    Ok(())
}

/// `run ended: finished at tick 6000` (one vehicle), or `run ended: [a] finished at tick 6000,
/// [b] failed at tick 12` (several): what the monitor prints last when every watched server
/// said its run ended.
fn ended_line(watches: &[Watch]) -> String {
    let several = watches.len() > 1;
    let parts: Vec<String> = watches
        .iter()
        .filter_map(|w| {
            let (state, tick) = w.ended()?;
            let text = format!("{} at tick {tick}", run_state_name(state));
            Some(if several {
                format!("[{}] {text}", w.topics.sc_id())
            } else {
                text
            })
        })
        .collect();
    format!("run ended: {}", parts.join(", "))
}

/// The terminal UI loop: sparkline samples and a redraw every 100 ms, the summary text every
/// `interval`; ends on q/Esc/Ctrl-C, a signal, or `--duration-s`. With several vehicles each
/// summary segment and sparkline title carries its vehicle's id.
fn run_tui(
    watches: &[Watch],
    stop: &std::sync::atomic::AtomicBool,
    interval: Duration,
    args: &Args,
) -> anyhow::Result<()> {
    use flexdyn_tools::monitor_tui::{render, Screen, Series};
    use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind, KeyModifiers};

    let mut terminal = ratatui::try_init()
        .map_err(|e| anyhow::anyhow!("cannot start the terminal UI ({e}); use --plain"))?;
    let end = args
        .duration_s
        .map(|s| Instant::now() + Duration::from_secs_f64(s.max(0.0)));
    let several = watches.len() > 1;
    let ids: Vec<&str> = watches.iter().map(|w| w.topics.sc_id()).collect();
    let tag = |i: usize, title: &str| {
        if several {
            format!("{} {title}", ids[i])
        } else {
            title.to_owned()
        }
    };
    let mut screen = Screen {
        title: format!("flexdyn-monitor {}", ids.join(", ")),
        summary: watches
            .iter()
            .map(|w| format!("waiting for {} …", w.topics.state()))
            .collect(),
        series: Vec::new(),
    };
    let mut next_summary = Instant::now() + interval;
    let mut any_data = false;
    let result = loop {
        if stop.load(std::sync::atomic::Ordering::Relaxed)
            || end.is_some_and(|e| Instant::now() >= e)
        {
            break Ok(());
        }
        if watches.iter().all(|w| w.ended().is_some()) {
            ratatui::restore();
            println!("{}", ended_line(watches));
            return Ok(());
        }
        let summary_due = Instant::now() >= next_summary;
        if summary_due {
            next_summary += interval;
            screen.summary.clear();
        }
        for (i, watch) in watches.iter().enumerate() {
            let mut w = watch.window.lock().unwrap_or_else(|p| p.into_inner());
            any_data |= w.last_state_at.is_some() || w.status.is_some();
            // One sparkline per quantity (and vehicle), added as its data appears: |σ_BN|,
            // |ω_BN|, the p99 lateness, each panel angle, and the shadow factor once an
            // environment message with a shadow model arrives.
            let mut push =
                |title: String, v: f64| match screen.series.iter_mut().find(|s| s.title == title) {
                    Some(s) => s.push(v),
                    None => {
                        let mut s = Series::new(title);
                        s.push(v);
                        screen.series.push(s);
                    }
                };
            if w.last_state_at.is_some() {
                push(tag(i, "|σ_BN| (–)"), w.sigma_norm);
                push(tag(i, "|ω_BN| (rad/s)"), w.omega_norm);
            }
            if let Some(s) = &w.status {
                push(
                    tag(i, "frame lateness p99 (µs)"),
                    s.timing.lateness_p99_ns as f64 * 1e-3,
                );
            }
            for (k, (th1, th2)) in w.thetas.clone().into_iter().enumerate() {
                for (j, th) in [(1, th1), (2, th2)] {
                    push(tag(i, &format!("pair{} |θ{j}| (rad)", k + 1)), th.abs());
                }
            }
            if let Some(env) = w
                .environment
                .as_ref()
                .filter(|e| e.flags & environment_flags::SHADOW != 0)
            {
                push(tag(i, "shadow factor ν (1 sunlit)"), env.shadow_factor);
            }
            if summary_due {
                let text = line(&mut w, interval, watch.topics.state());
                let mut segments = text.split(" | ").map(str::to_owned);
                if let Some(first) = segments.next() {
                    screen.summary.push(if several {
                        format!("[{}] {first}", ids[i])
                    } else {
                        first
                    });
                }
                screen.summary.extend(segments);
                if let (false, Some(s)) = (several, &w.status) {
                    screen.title = format!(
                        "flexdyn-monitor {} — {} {}",
                        ids[i],
                        mode_name(s.mode),
                        run_state_name(s.run_state)
                    );
                }
            }
        }
        if let Err(e) = terminal.draw(|f| render(f, &screen)) {
            break Err(anyhow::anyhow!("terminal: {e}"));
        }
        match event::poll(Duration::from_millis(100)) {
            Ok(true) => {
                if let Ok(Event::Key(k)) = event::read() {
                    let ctrl_c =
                        k.code == KeyCode::Char('c') && k.modifiers.contains(KeyModifiers::CONTROL);
                    if k.kind == KeyEventKind::Press
                        && (matches!(k.code, KeyCode::Char('q') | KeyCode::Esc) || ctrl_c)
                    {
                        break Ok(());
                    }
                }
            }
            Ok(false) => {}
            Err(e) => break Err(anyhow::anyhow!("terminal input: {e}")),
        }
    };
    ratatui::restore();
    if result.is_ok() && end.is_some() && !any_data {
        anyhow::bail!("no data: nothing received during --duration-s: no server, or it is not reachable at the --connect endpoint");
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The telemetry segment names the mode and the last event by the declaration, keeps the
    /// mode of a sample that names none, and falls back to indices without a declaration.
    #[test]
    fn the_flight_code_segment_names_the_mode_and_the_last_event() {
        use flexdyn_proto::{fsw_flags, FswMsg, Header};
        let toml = "[[fsw_streams]]\nname = \"acs\"\nmodes = [\"detumble\", \"pointing\"]\n\
                    events = [{ name = \"gyro-failure\", severity = \"error\" }, { name = \"ok\" }]\n";
        let declared: std::collections::BTreeMap<String, FswDeclaration> =
            FswDeclaration::all_from_config_toml(toml)
                .unwrap()
                .into_iter()
                .map(|d| (d.name.clone(), d))
                .collect();
        let sample = |tick: u64, mode: Option<u32>, events: &[u16]| {
            let mut m = FswMsg {
                header: Header::new(1, tick, tick * 100_000_000, tick),
                flags: if mode.is_some() { fsw_flags::MODE } else { 0 },
                mode: mode.unwrap_or(0),
                event_count: events.len() as u8,
                ..FswMsg::default()
            };
            m.events[..events.len()].copy_from_slice(events);
            m
        };
        let mut seen = FswSeen::default();
        seen.note(&sample(10, Some(1), &[]));
        let mut all = std::collections::BTreeMap::new();
        all.insert("acs".to_owned(), seen.clone());
        assert_eq!(fsw_str(&all, &declared), " fsw acs: mode=pointing");
        // A later sample with two events and no mode: the mode stays, the last event is shown.
        seen.note(&sample(613, None, &[1, 0]));
        all.insert("acs".to_owned(), seen);
        assert_eq!(
            fsw_str(&all, &declared),
            " fsw acs: mode=pointing last_event=gyro-failure (error) at t=61.300s"
        );
        assert_eq!(
            fsw_str(&all, &Default::default()),
            " fsw acs: mode=#1 last_event=#0 at t=61.300s"
        );
    }

    #[test]
    fn rejections_name_every_nonzero_reason() {
        let none = flexdyn_proto::RejectCounters::default();
        assert_eq!(rejected_by_reason(&none), "0");
        let some = flexdyn_proto::RejectCounters {
            malformed: 2,
            wrong_identity: 7,
            ..none
        };
        assert_eq!(rejected_by_reason(&some), "malformed:2,wrong_identity:7");
        // Refused fault commands and flight-code telemetry are reasons too.
        let refused = flexdyn_proto::RejectCounters {
            fault_refused: 1,
            fsw_refused: 3,
            ..none
        };
        assert_eq!(
            rejected_by_reason(&refused),
            "fault_refused:1,fsw_refused:3"
        );
    }

    /// The eclipse state follows the message's `eclipse` code, and each quantity shows only
    /// with its model's flag.
    #[test]
    fn environment_summary_names_the_eclipse_state() {
        let mut env = EnvironmentMsg {
            flags: environment_flags::SHADOW | environment_flags::MAGNETIC,
            eclipse: eclipse::PENUMBRA,
            shadow_factor: 0.4321,
            b_b_t: [3e-6, 0.0, -4e-6],
            density_kg_m3: 1e-12,
            ..Default::default()
        };
        assert_eq!(environment_str(&env), " env penumbra nu=0.432 |B|=5.0uT");
        env.eclipse = eclipse::UMBRA;
        env.shadow_factor = 0.0;
        env.flags |= environment_flags::ATMOSPHERE;
        assert_eq!(
            environment_str(&env),
            " env umbra nu=0.000 |B|=5.0uT rho=1.00e-12kg/m3"
        );
        env.flags = 0;
        assert_eq!(environment_str(&env), " env (no models on)");
    }

    #[test]
    fn sensor_summary_gives_each_sensor_its_rate() {
        let counts = [("css/css".to_owned(), 20), ("imu/hub".to_owned(), 200)]
            .into_iter()
            .collect();
        assert_eq!(
            sensors_str(&counts, Duration::from_secs(2)),
            " sensors css/css=10.0/s,imu/hub=100.0/s"
        );
        assert_eq!(sensors_str(&Default::default(), Duration::from_secs(1)), "");
    }

    /// The active set names each active fault by index; unknown names show the index alone,
    /// and faults beyond the set's 256 bits are counted.
    #[test]
    fn fault_summary_names_the_active_faults() {
        let names = [
            (0, fault_name("imus.hub.gyro", 2)),
            (1, fault_name("reaction_wheels.rw2", 11)),
            (2, fault_name("links.1", 99)),
        ]
        .into_iter()
        .collect();
        let mut s = StatusMsg::default();
        assert_eq!(faults_str(&s, &Default::default()), "");
        assert_eq!(faults_str(&s, &names), " faults active=0");
        s.faults_active = 2;
        s.faults_active_bits[0] = 0b101;
        assert_eq!(
            faults_str(&s, &names),
            " faults active=2 [#0 imus.hub.gyro bias_step; #2 links.1 mode 99]"
        );
        s.faults_active = 4;
        s.faults_active_bits = [0b10, 0, 0, 1 << 63];
        assert_eq!(
            faults_str(&s, &names),
            " faults active=4 [#1 reaction_wheels.rw2 seized; #255; +2 beyond index 255]"
        );
    }

    #[test]
    fn wheel_summary_marks_the_limits() {
        let w = [
            (100.0, 0),
            (-52.34, wheel_flags::TORQUE_LIMITED),
            (
                600.0,
                wheel_flags::TORQUE_LIMITED | wheel_flags::SPEED_LIMITED,
            ),
        ];
        assert_eq!(wheels_str(&w), "[100.0,-52.3T,600.0TS]rad/s");
    }

    #[test]
    fn actuator_summary_counts_firings_and_marks_saturation() {
        let e = |kind, flags, outputs: &[f64]| EffectorState {
            kind,
            flags,
            states: vec![],
            outputs: outputs.to_vec(),
        };
        let effectors = [
            e(effector_kind::REACTION_WHEEL, 0, &[0.0, 0.0]),
            e(effector_kind::MAGNETORQUER, 0, &[100.0]),
            e(
                effector_kind::MAGNETORQUER,
                magnetorquer_flags::SATURATED,
                &[-400.0],
            ),
            e(
                effector_kind::THRUSTER,
                thruster_flags::FIRING,
                &[1.0, 40.0, 0.01, 2.0],
            ),
            e(
                effector_kind::THRUSTER,
                thruster_flags::BELOW_MIN_ON_TIME,
                &[0.0, 44.0, 0.0023, 1.0],
            ),
        ];
        assert_eq!(
            actuators_str(&effectors),
            " rods=[100.0,-400.0S]Am2 thrusters=firing:1/2,pulses=84,propellant_kg=0.0123,!min"
        );
        assert_eq!(actuators_str(&effectors[..1]), "");
    }
}
