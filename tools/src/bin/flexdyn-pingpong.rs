//! `flexdyn-pingpong`: plain Zenoh round trips between two processes, the yardstick of the
//! lockstep benchmark.
//!
//! ```sh
//! flexdyn-pingpong pong --listen tcp/127.0.0.1:17500 &
//! flexdyn-pingpong ping --connect tcp/127.0.0.1:17500 --count 10000
//! ```

use std::time::Duration;

use clap::{Parser, Subcommand};
use flexdyn_proto::{COMMAND_WRENCH_LEN, EFFECTOR_STATE_FIXED_LEN, STATE_FIXED_LEN};
use flexdyn_tools::{percentile, pingpong, CommonArgs};

/// Zenoh ping-pong over the flexdyn transport settings.
#[derive(Debug, Parser)]
#[command(name = "flexdyn-pingpong", version)]
struct Args {
    #[command(flatten)]
    common: CommonArgs,
    #[command(subcommand)]
    role: RoleCmd,
}

#[derive(Debug, Subcommand)]
enum RoleCmd {
    /// Echo every ping (runs until killed or --duration-s).
    Pong {
        /// Reply size in bytes (default: a CommandMsg).
        #[arg(long, default_value_t = COMMAND_WRENCH_LEN)]
        reply_size: usize,
        /// Exit after this many seconds.
        #[arg(long)]
        duration_s: Option<f64>,
        /// Answer from a receive loop on the main thread (the demo controller's structure)
        /// instead of inside the Zenoh callback.
        #[arg(long)]
        recv_loop: bool,
    },
    /// Measure round trips and print p50/p99 and round trips per second.
    Ping {
        /// Ping size in bytes (default: a StateMsg with two panel pairs, 435 bytes).
        #[arg(long, default_value_t = STATE_FIXED_LEN + 2 * (EFFECTOR_STATE_FIXED_LEN + 32))]
        size: usize,
        /// Unmeasured round trips first.
        #[arg(long, default_value_t = 1000)]
        warmup: usize,
        /// Measured round trips.
        #[arg(long, default_value_t = 10000)]
        count: usize,
        /// Seconds to wait for the pong and for each reply.
        #[arg(long, default_value_t = 10.0)]
        timeout_s: f64,
    },
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
    let topics = args.common.topics()?;
    let session = args.common.open_session()?;
    match args.role {
        RoleCmd::Pong {
            reply_size,
            duration_s,
            recv_loop,
        } => {
            let end =
                duration_s.map(|s| std::time::Instant::now() + Duration::from_secs_f64(s.max(0.0)));
            let signalled = flexdyn_tools::stop_on_signals()?;
            let stop = || {
                signalled.load(std::sync::atomic::Ordering::Relaxed)
                    || end.is_some_and(|e| std::time::Instant::now() >= e)
            };
            if recv_loop {
                pingpong::pong(&session, &topics, reply_size, stop)
            } else {
                pingpong::pong_in_callback(&session, &topics, reply_size, stop)
            }
        }
        RoleCmd::Ping {
            size,
            warmup,
            count,
            timeout_s,
        } => {
            let mut rtts = pingpong::ping(
                &session,
                &topics,
                size,
                warmup,
                count.max(1),
                Duration::from_secs_f64(timeout_s),
            )?;
            let total: Duration = rtts.iter().sum();
            rtts.sort_unstable();
            let us = |d: Option<Duration>| d.map_or(0.0, |d| d.as_secs_f64() * 1e6);
            println!(
                "round_trips={} rtt_us p50={:.1} p99={:.1} max={:.1} round_trips_per_s={:.0}",
                rtts.len(),
                us(percentile(&rtts, 0.5)),
                us(percentile(&rtts, 0.99)),
                us(rtts.last().copied()),
                rtts.len() as f64 / total.as_secs_f64()
            );
            Ok(())
        }
    }
}
