//! `flexdyn-formation-demo`: the deputy's flight code of a two-spacecraft formation served by
//! `flexdyn run --fleet` (docs/guides/fleets.md, "Fleet in the server").
//!
//! It answers the deputy's ticks (`--sc-id`, as sender `--sender-id`) and reads the chief's
//! state too (`--chief`): for each tick it waits for both states of that tick, then commands
//! the deputy's body force that holds the station `--station-m` in the chief's Hill frame and
//! the torque that points the deputy's body x̂ at the chief
//! ([`flexdyn_acs_demo::formation`]). The chief has its own controller
//! (`flexdyn-acs-demo --sc-id <chief>`).

use std::collections::BTreeMap;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::{bail, Context as _};
use clap::Parser;
use flexdyn_acs_demo::formation::{
    com_offset_b, com_state_n, pointing_errors, relative_hill, station_force_b, StationGains,
};
use flexdyn_proto::client::cli::{exit_with, stop_on_signals, CommonArgs};
use flexdyn_proto::client::participant::Participant;
use flexdyn_proto::client::run_end::RunEnd;
use flexdyn_proto::client::vehicle::Vehicle;
use flexdyn_proto::{decode_state, CommandMsg, Header, StateMsg, Topics};
use nalgebra::Vector3;
use zenoh::Wait;

/// Formation demo: the deputy holds a Hill-frame station and points at the chief.
#[derive(Debug, Parser)]
#[command(name = "flexdyn-formation-demo", version)]
struct Args {
    /// The deputy (`--sc-id`) and the connection.
    #[command(flatten)]
    common: CommonArgs,
    /// The chief's id (its keys flexdyn/\<CHIEF>/…).
    #[arg(long)]
    chief: String,
    /// Our sender id (a participant of the deputy in the fleet file).
    #[arg(long, default_value_t = 2)]
    sender_id: u32,
    /// The station ρ* in the chief's Hill frame \[m\]: radial, along-track, cross-track.
    #[arg(long, value_name = "X,Y,Z", value_delimiter = ',', default_values_t = [0.0, -100.0, 0.0],
          allow_hyphen_values = true)]
    station_m: Vec<f64>,
    /// Station-keeping natural frequency ω_c \[rad/s\].
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    omega_c: f64,
    /// Station-keeping damping ratio ζ.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    zeta: f64,
    /// Pointing attitude gain K \[N·m per unit MRP\].
    #[arg(long, default_value_t = 100.0, allow_negative_numbers = true)]
    k_nm: f64,
    /// Pointing rate gain P \[N·m·s/rad\].
    #[arg(long, default_value_t = 300.0, allow_negative_numbers = true)]
    p_nms: f64,
    /// Exit after this many seconds without a state (0 if states came, 1 if none). Without it
    /// the demo stops when the server says the run ended (1 if it failed).
    #[arg(long, allow_negative_numbers = true)]
    idle_exit_s: Option<f64>,
}

/// A vehicle's served configuration: its mass and centre-of-mass offset.
fn mass_properties(
    session: &zenoh::Session,
    topics: &Topics,
    idle: Duration,
) -> anyhow::Result<(f64, Vector3<f64>)> {
    let started = Instant::now();
    loop {
        match Vehicle::query(session, topics, Duration::from_millis(500)) {
            Ok(v) => return Ok(com_offset_b(&v.config()?)),
            Err(flexdyn_proto::client::vehicle::VehicleError::NoAnswer { key, .. }) => {
                if started.elapsed() >= idle {
                    bail!("no answer on {key}: no server, or no such vehicle");
                }
            }
            Err(e) => return Err(e.into()),
        }
    }
}

fn run(args: Args) -> anyhow::Result<()> {
    let deputy = args.common.topics()?;
    let chief = Topics::new(&args.chief).context("--chief")?;
    if args.station_m.len() != 3 {
        bail!("--station-m takes three numbers");
    }
    let station = Vector3::new(args.station_m[0], args.station_m[1], args.station_m[2]);
    let gains = StationGains {
        omega_c: args.omega_c,
        zeta: args.zeta,
    };
    let idle = Duration::from_secs_f64(args.idle_exit_s.unwrap_or(3600.0).max(0.1));
    let stop = stop_on_signals()?;
    let session = args.common.open_session()?;
    let (mass_kg, r_cb_deputy) = mass_properties(&session, &deputy, idle)?;
    let (_, r_cb_chief) = mass_properties(&session, &chief, idle)?;

    // The end of the run (the deputy's server's last status), then both states, tagged (true:
    // the chief's), through one channel.
    let run_end = RunEnd::declare(&session, &deputy)
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {}: {e}", deputy.status()))?;
    let (tx, rx) = mpsc::channel::<(bool, StateMsg)>();
    let mut subs = Vec::new();
    for (is_chief, key) in [(true, chief.state()), (false, deputy.state())] {
        let tx = tx.clone();
        subs.push(
            session
                .declare_subscriber(key.to_owned())
                .callback(move |s| {
                    if let Ok(st) = decode_state(&s.payload().to_bytes()) {
                        let _ = tx.send((is_chief, st));
                    }
                })
                .wait()
                .map_err(|e| anyhow::anyhow!("cannot subscribe to {key}: {e}"))?,
        );
    }
    let participant = Participant::declare(&session, &deputy, args.sender_id)?;
    tracing::info!(chief = %args.chief, deputy = deputy.sc_id(), ?station, "flexdyn-formation-demo running");

    let (mut chiefs, mut deputies) = (BTreeMap::new(), BTreeMap::new());
    let mut buf = Vec::with_capacity(128);
    let mut seq = 0u64;
    let mut received = 0u64;
    let mut last_at = Instant::now();
    let mut ended = None;
    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
        if last_at.elapsed() >= idle {
            if received == 0 {
                bail!("no state within {} s", idle.as_secs_f64());
            }
            break;
        }
        // Every 20 ms: once the server said the run ended, the queued states are taken and
        // the demo stops when no more come.
        let Ok((is_chief, st)) = rx.recv_timeout(Duration::from_millis(20)) else {
            if let Some(end) = run_end.ended() {
                tracing::info!(
                    tick = end.tick,
                    "the server reports the run {}: exiting",
                    end.word()
                );
                ended = Some(end);
                break;
            }
            continue;
        };
        received += 1;
        last_at = Instant::now();
        let k = st.header.tick;
        if is_chief {
            chiefs.insert(k, st);
        } else {
            deputies.insert(k, st);
        }
        let (Some(c), Some(d)) = (chiefs.get(&k), deputies.get(&k)) else {
            continue;
        };
        let v3 = Vector3::from;
        let (r_c, v_c) = com_state_n(
            &v3(c.r_bn_n_m),
            &v3(c.v_bn_n_m_s),
            &v3(c.sigma_bn),
            &v3(c.omega_bn_b_rad_s),
            &r_cb_chief,
        );
        let sigma_bn = v3(d.sigma_bn);
        let omega_bn_b = v3(d.omega_bn_b_rad_s);
        let (r_d, v_d) = com_state_n(
            &v3(d.r_bn_n_m),
            &v3(d.v_bn_n_m_s),
            &sigma_bn,
            &omega_bn_b,
            &r_cb_deputy,
        );
        let (force_b, torque_b) = match relative_hill(&r_c, &v_c, &r_d, &v_d) {
            Some((rho, rho_dot, hn, omega_hn_n)) => {
                let f = station_force_b(gains, mass_kg, &rho, &rho_dot, &station, &hn, &sigma_bn);
                let z_n = hn.row(2).transpose();
                let t = pointing_errors(&r_c, &r_d, &z_n, &omega_hn_n, &sigma_bn, &omega_bn_b)
                    .map_or(Vector3::zeros(), |(s, w)| -args.k_nm * s - args.p_nms * w);
                (f, t)
            }
            None => (Vector3::zeros(), Vector3::zeros()),
        };
        let h = d.header;
        let cmd = CommandMsg::wrench(
            Header::new(h.spacecraft_id, h.tick, h.sim_time_ns, seq),
            args.sender_id,
            torque_b.into(),
            force_b.into(),
        );
        seq += 1;
        participant
            .send(&cmd, &mut buf)
            .map_err(|e| anyhow::anyhow!("cannot publish the command: {e}"))?;
        chiefs = chiefs.split_off(&(k + 1));
        deputies = deputies.split_off(&(k + 1));
    }
    drop(participant);
    drop(subs);
    drop(run_end);
    session
        .close()
        .wait()
        .map_err(|e| anyhow::anyhow!("closing the session: {e}"))?;
    flexdyn_proto::client::run_end::outcome(ended)
}

fn main() -> std::process::ExitCode {
    let args = match flexdyn_proto::client::logging::parse_args::<Args>() {
        Ok(a) => a,
        Err(code) => return code,
    };
    flexdyn_proto::client::logging::init_tracing();
    exit_with(run(args))
}
