//! `flexdyn-monitor`: prints one line per interval summarising the live telemetry and the
//! server status, for operators.
//!
//! ```text
//! t=12.340s tick=1234 states/s=100.0 gaps=0 |sigma_bn|=0.1234 |omega|=0.0456rad/s flags=- latency_ms p50=0.120 p99=0.410 | realtime running lateness_us p50=3.1 p99=21.0 max=118.2 overruns=0 skipped=0 cmd_age_ms=10.0 stale=no rejected=0
//! ```
//!
//! - `gaps`: StateMsg sequence numbers missing in the interval (lost or dropped frames);
//! - `latency_ms`: frame boundary (the sample's attachment) to receipt here, wall clock;
//! - `flags`: `S` stale command, `Z` zeroed by policy, `N` no command yet.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use clap::Parser;
use flexdyn::server::{frame_stamp_ns, mode_name};
use flexdyn_proto::{command_flags, decode_state, decode_status, RunState, StatusMsg, NO_COMMAND};
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
    /// Exit after this many seconds (default: run until killed).
    #[arg(long)]
    duration_s: Option<f64>,
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
    latencies_ns: Vec<u64>,
    undecodable: u64,
    status: Option<StatusMsg>,
}

fn unix_now_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
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

fn run_state_name(s: RunState) -> &'static str {
    match s {
        RunState::Starting => "starting",
        RunState::Running => "running",
        RunState::Stopping => "stopping",
        RunState::Finished => "finished",
        RunState::Failed => "failed",
    }
}

fn line(w: &mut Window, interval: Duration) -> String {
    let mut lat = std::mem::take(&mut w.latencies_ns);
    lat.sort_unstable();
    let ms = |v: Option<u64>| v.map_or("-".to_owned(), |ns| format!("{:.3}", ns as f64 * 1e-6));
    let mut out = format!(
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
    );
    if w.undecodable > 0 {
        out.push_str(&format!(" undecodable={}", w.undecodable));
    }
    match &w.status {
        None => out.push_str(" | no status yet"),
        Some(s) => {
            let us = |ns: u64| ns as f64 * 1e-3;
            out.push_str(&format!(
                " | {} {} lateness_us p50={:.1} p99={:.1} max={:.1} overruns={} skipped={} cmd_age_ms={} stale={} rejected={}",
                mode_name(s.mode),
                run_state_name(s.run_state),
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
                s.rejected.total(),
            ));
        }
    }
    w.states = 0;
    w.gaps = 0;
    w.undecodable = 0;
    out
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
    let topics = args.common.topics()?;
    let session = args.common.open_session()?;
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
                w.lock().unwrap_or_else(|p| p.into_inner()).status = Some(s);
            }
        })
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot subscribe to {}: {e}", topics.status()))?;

    eprintln!(
        "flexdyn-monitor: watching {} and {} (Ctrl-C to stop)",
        topics.state(),
        topics.status()
    );
    let interval = Duration::from_secs_f64(args.interval_s);
    let end = args
        .duration_s
        .map(|s| Instant::now() + Duration::from_secs_f64(s.max(0.0)));
    let mut next = Instant::now() + interval;
    loop {
        let now = Instant::now();
        if let Some(end) = end {
            if now >= end {
                return Ok(());
            }
        }
        std::thread::sleep(next.saturating_duration_since(now));
        next += interval;
        let text = line(
            &mut window.lock().unwrap_or_else(|p| p.into_inner()),
            interval,
        );
        println!("{text}");
    }
}
