//! `flexdyn gateway`: the device gateway as a flight-code participant of a server.
//!
//! 1. Reads the served vehicle (`flexdyn/<sc>/config`) and resolves the device list against
//!    what it offers; a bad description is a usage error (exit 2) naming the file, the key and
//!    the problem.
//! 2. Opens every endpoint and prints where each driver finds it (`device <name> <where>`,
//!    and `--endpoints-file`).
//! 3. Waits for every driver (a pseudo-terminal's slave held open, a TCP connection), so a
//!    lockstep run does not start before the flight code can hear tick 0.
//! 4. Subscribes, then declares its lockstep token, and answers every tick with the inputs the
//!    drivers set, until the server ends the run.
//! 5. Prints each device's counters (`--report` writes them as TOML too).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use flexdyn_gateway::device::DeviceSet;
use flexdyn_proto::client::cli::{stop_on_signals, usage, CommonArgs};
use flexdyn_proto::client::lockstep::{SensorSchedule, TickReceiver};
use flexdyn_proto::client::participant::Participant;
use flexdyn_proto::client::run_end::RunEnd;
use flexdyn_proto::client::vehicle::{Vehicle, VehicleError};
use flexdyn_proto::{CommandMsg, Header, Mode, Topics};
use zenoh::{Session, Wait};

use crate::catalog::VehicleCatalog;
use crate::gateway::{Gateway, Pacing};
use crate::report;

/// `flexdyn gateway`'s options.
#[derive(Debug, Clone, clap::Args)]
pub struct GatewayArgs {
    /// The device list (TOML): each device's description, its bindings and its endpoint
    /// (book: "Device gateway").
    #[arg(long, value_name = "FILE")]
    pub devices: PathBuf,
    /// Where relative pseudo-terminal links of the device list go.
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub link_dir: PathBuf,
    /// Numeric participant id: commands go to flexdyn/\<sc>/cmd/\<ID>; must be among the server's
    /// participants.
    #[arg(long, value_name = "ID", default_value_t = 1)]
    pub sender_id: u32,
    /// How long to wait for every driver before the first tick (seconds).
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
    pub wait_for_drivers_s: f64,
    /// Also write where each driver finds its device to this file (TOML), once all are open.
    #[arg(long, value_name = "FILE")]
    pub endpoints_file: Option<PathBuf>,
    /// Write each device's counters to this file (TOML) at the end.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Give up if no server answers within this many seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 30.0)]
    pub idle_exit_s: f64,
    /// The Zenoh connection and the spacecraft id.
    #[command(flatten)]
    pub common: CommonArgs,
}

/// Runs the gateway until the server ends the run (or a signal).
pub fn run(args: &GatewayArgs) -> anyhow::Result<()> {
    if !(args.wait_for_drivers_s.is_finite() && args.wait_for_drivers_s >= 0.0) {
        return Err(usage("--wait-for-drivers-s must be a finite number ≥ 0"));
    }
    if !(args.idle_exit_s.is_finite() && args.idle_exit_s > 0.0) {
        return Err(usage("--idle-exit-s must be a finite number > 0"));
    }
    let topics = args.common.topics()?;
    let stop = stop_on_signals()?;
    let session = args.common.open_session()?;
    let idle = Duration::try_from_secs_f64(args.idle_exit_s)
        .map_err(|_| usage("--idle-exit-s is too large"))?;
    let Some(vehicle) = wait_for_vehicle(&session, &topics, idle, &stop)? else {
        return close(session);
    };
    let cfg = vehicle.config()?;
    let catalog = VehicleCatalog::from_config(&cfg);
    let set =
        DeviceSet::load(&args.devices, catalog.catalog()).map_err(|e| usage(e.to_string()))?;
    let mut gateway = Gateway::open(set, catalog, &args.link_dir)
        .map_err(|(name, e)| anyhow::anyhow!("device {name}: {e}"))?;
    for (name, at) in gateway.endpoints() {
        println!("device {name} {at}");
    }
    if let Some(f) = &args.endpoints_file {
        report::write_endpoints(f, &gateway.endpoints())
            .with_context(|| format!("cannot write {}", f.display()))?;
    }
    if !wait_for_drivers(&mut gateway, args.wait_for_drivers_s, &stop)? {
        return close(session);
    }

    let schedule = SensorSchedule::from_config(&cfg)?;
    let run_end = RunEnd::declare(&session, &topics)
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {}: {e}", topics.status()))?;
    let mut ticks =
        TickReceiver::declare(&session, &topics, schedule, 1024, Duration::from_secs(5)).map_err(
            |e| {
                anyhow::anyhow!(
                    "cannot subscribe to the tick's telemetry under {}: {e}",
                    topics.telemetry_wildcard()
                )
            },
        )?;
    let participant = Participant::declare(&session, &topics, args.sender_id)?;
    tracing::info!(
        sender_id = args.sender_id,
        commands = participant.key(),
        "flexdyn gateway running"
    );

    let mut seq = 0u64;
    let mut buf = Vec::with_capacity(256);
    let mut ended = None;
    let mut pacing = Pacing::Lockstep;
    let mut last_tick_at = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        let slice = match pacing {
            Pacing::Lockstep => Duration::from_millis(20),
            Pacing::RealTime => Duration::ZERO,
        };
        let Some(tick) = ticks
            .recv_timeout(slice)
            .map_err(|e| anyhow::anyhow!("{e}"))?
        else {
            if let Some(end) = run_end.ended() {
                ended = Some(end);
                break;
            }
            if pacing == Pacing::RealTime {
                gateway.service(Duration::from_millis(1))?;
            }
            // A server that publishes neither a tick nor its status (which it keeps doing while
            // paused) for the idle time is gone.
            let silent = run_end.last_heard().is_none_or(|t| t.elapsed() >= idle);
            if last_tick_at.elapsed() >= idle && silent {
                bail!(
                    "no tick and no status from the server for {} s (--idle-exit-s): it is gone",
                    idle.as_secs_f64()
                );
            }
            continue;
        };
        last_tick_at = Instant::now();
        if let Some(t) = &tick.time {
            pacing = match t.mode {
                Mode::Lockstep => Pacing::Lockstep,
                Mode::RealTime | Mode::Batch => Pacing::RealTime,
            };
        }
        gateway.tick(&tick, pacing)?;
        let h = tick.state.header;
        let header = Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, seq);
        let inputs = gateway.catalog().effector_inputs(gateway.commands());
        let cmd = CommandMsg::actuators(header, args.sender_id, [0.0; 3], [0.0; 3], inputs);
        participant
            .send(&cmd, &mut buf)
            .map_err(|e| anyhow::anyhow!("cannot publish the command: {e}"))?;
        seq += 1;
    }
    gateway.drain(Duration::from_millis(200));
    let devices = gateway.report();
    let untimed = gateway.ticks_without_time();
    print!("{}", report::text(&devices, seq, untimed));
    if let Some(f) = &args.report {
        std::fs::write(f, report::toml(&devices, seq, untimed))
            .with_context(|| format!("cannot write {}", f.display()))?;
    }
    drop(participant);
    drop(ticks);
    drop(run_end);
    close(session)?;
    flexdyn_proto::client::run_end::outcome(ended)
}

/// Waits until every device's driver is there; `false` on a stop signal.
fn wait_for_drivers(
    gateway: &mut Gateway,
    limit_s: f64,
    stop: &AtomicBool,
) -> anyhow::Result<bool> {
    let start = Instant::now();
    let mut said = Vec::new();
    loop {
        if stop.load(Ordering::Relaxed) {
            return Ok(false);
        }
        let absent = gateway.absent();
        if absent.is_empty() {
            return Ok(true);
        }
        if absent != said {
            tracing::info!(devices = ?absent, "waiting for the drivers of these devices");
            said = absent.clone();
        }
        if start.elapsed().as_secs_f64() >= limit_s {
            bail!(
                "no driver for {} within {} s (--wait-for-drivers-s)",
                absent.join(", "),
                limit_s
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn wait_for_vehicle(
    session: &Session,
    topics: &Topics,
    idle: Duration,
    stop: &AtomicBool,
) -> anyhow::Result<Option<Vehicle>> {
    let started = Instant::now();
    loop {
        if stop.load(Ordering::Relaxed) {
            return Ok(None);
        }
        match Vehicle::query(session, topics, Duration::from_millis(500)) {
            Ok(v) => return Ok(Some(v)),
            Err(VehicleError::NoAnswer { key, .. }) if started.elapsed() < idle => {
                tracing::debug!(key, "no server yet");
            }
            Err(VehicleError::NoAnswer { key, .. }) => bail!(
                "no answer on {key} within {} s (--idle-exit-s): no server, or it is not \
                 reachable at the --connect endpoint",
                idle.as_secs_f64()
            ),
            Err(e) => return Err(e.into()),
        }
    }
}

fn close(session: Session) -> anyhow::Result<()> {
    session
        .close()
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot close the Zenoh session: {e}"))
}
