//! Frame lateness at 1 kHz: the normal scheduler against the hard real-time settings
//! (SCHED_FIFO + `lock_memory` + `physics_cpu` + `cpu_dma_latency`), measured in the same run.
//!
//! Per round, two runs of the server in this process (`flexdyn_server::run`, real time, the
//! reference spacecraft at 1 kHz: one RK4 step per frame, a loopback Zenoh session with no
//! subscriber), each `FLEXDYN_RT_SPAN_S` seconds (default 60), first with the default settings
//! (`normal`), then tuned (`tuned`: `realtime_priority = 50`, `lock_memory`, `physics_cpu` =
//! the last allowed CPU with this process's other threads kept off it, `cpu_dma_latency`).
//! `FLEXDYN_RT_ROUNDS` rounds (default 3). `FLEXDYN_RT_SCENARIO=scenarios/leo_environment.toml`
//! runs that scenario at 1 kHz instead (every environment model and its sensors on). Each run
//! prints:
//! - the lateness of the frame boundaries (wake-up minus deadline): p50, p90, p99, p99.9, max,
//!   and the histogram coarsened to buckets (line `histogram:`);
//! - overruns (frames whose work ended after the next deadline);
//! - page faults of the whole process during the run (minor + major, `/proc/self/stat`: what
//!   `getrusage(RUSAGE_SELF)` sums), and of the physics thread after its first frame;
//! - the physics thread's involuntary context switches (preemptions);
//! - the VM's steal time over the run (`/proc/stat`, the `cpu` line's 8th value): time the
//!   hypervisor ran something else while this VM wanted to run. Lateness under steal is not
//!   the process's doing.
//!
//! And each overrun attributed (line `overruns:` under each run). A sampler thread (on the
//! other CPU in the tuned run) reads every millisecond the steal counter of each CPU (`cpuN`
//! lines of `/proc/stat`), and the physics thread's scheduler statistics
//! (`/proc/self/task/<tid>/schedstat`: time waiting on the run queue; `status`: involuntary
//! switches; `stat`: page faults and the CPU it last ran on). The server logs each overrun
//! frame's start and end (`RunReport::overrun_frames_ns`, same clock); an overrun counts
//! - `steal` if the steal counter of the physics thread's CPU advanced between the last sample
//!   before the frame and the first sample 5 ms after its end (steal is booked at the next
//!   scheduler tick);
//! - `own` if in that window the physics thread was preempted, waited ≥ 100 µs on the run queue
//!   or took a page fault (what the process or the guest's own scheduling causes);
//! - `unseen` if neither. `/proc/stat` counts steal in whole 10 ms ticks of the CPU's running
//!   total, so a stall of a few ms shows in that counter only when it carries the total over a
//!   tick boundary: an `unseen` overrun with no own cause is most likely steal too short to
//!   tick; an `own` one is the process's (or its guest's) to fix.
//!
//! Then the medians over the rounds and the ratios tuned / normal (medians of the per-round
//! ratios). The tuned run needs root (CAP_SYS_NICE, CAP_IPC_LOCK, write access to
//! `/dev/cpu_dma_latency`) and two CPUs; without them it says what was refused.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use flexdyn_proto::client::transport::{zenoh_config, Role, ZenohArgs};
use flexdyn_server::{self as server, rt, RunReport, ServerSettings};
use flexdyn_vehicle::config::{SimConfig, DEFAULT_CONFIG_TOML};

/// One run's figures.
#[derive(Clone, Copy, Debug, Default)]
struct Figures {
    /// \[µs\] lateness p50, p90, p99, p99.9, max.
    lateness_us: [f64; 5],
    /// Frames per lateness bucket of [`BUCKETS_US`] (the histogram, coarsened).
    histogram: [u64; BUCKETS_US.len()],
    overruns: u64,
    process_faults: u64,
    physics_faults: u64,
    physics_involuntary: u64,
    /// \[ms\] steal time over the run, all CPUs.
    steal_ms: f64,
    /// \[ms\] all CPU time over the run (for the steal share).
    cpu_ms: f64,
    /// Overrun attribution (see the module documentation).
    blame: Blame,
}

/// How the logged overruns of a run split (an overrun may count under both `steal` and `own`).
#[derive(Clone, Copy, Debug, Default)]
struct Blame {
    logged: u64,
    steal: u64,
    own: u64,
    preempted: u64,
    run_delay: u64,
    faulted: u64,
    unseen: u64,
    /// \[ms\] steal on the physics CPU over the run (tuned: the pinned CPU).
    physics_cpu_steal_ms: f64,
}

/// One reading of the sampler thread.
#[derive(Clone, Debug, Default)]
struct Sample {
    /// \[ns\] `rt::monotonic_ns`.
    t_ns: u64,
    /// Steal ticks of each CPU (`cpuN` lines of `/proc/stat`), indexed by N.
    steal_ticks: Vec<u64>,
    /// The physics thread's run-queue wait \[ns\] (schedstat's 2nd field).
    run_delay_ns: u64,
    /// Its involuntary context switches.
    involuntary: u64,
    /// Its minor + major page faults.
    faults: u64,
    /// The CPU it last ran on.
    cpu: usize,
}

/// The task id of this process's thread named `name`, if any.
fn thread_id(name: &str) -> Option<String> {
    std::fs::read_dir("/proc/self/task")
        .ok()?
        .flatten()
        .find(|t| std::fs::read_to_string(t.path().join("comm")).is_ok_and(|c| c.trim() == name))
        .map(|t| t.file_name().to_string_lossy().into_owned())
}

/// Reads one sample of the thread `tid` (`None` once it is gone).
fn sample(tid: &str) -> Option<Sample> {
    let task = format!("/proc/self/task/{tid}");
    let schedstat = std::fs::read_to_string(format!("{task}/schedstat")).ok()?;
    let status = std::fs::read_to_string(format!("{task}/status")).ok()?;
    let stat = std::fs::read_to_string(format!("{task}/stat")).ok()?;
    let proc_stat = std::fs::read_to_string("/proc/stat").ok()?;
    let mut s = Sample {
        t_ns: rt::monotonic_ns(),
        run_delay_ns: schedstat.split_whitespace().nth(1)?.parse().ok()?,
        ..Sample::default()
    };
    for line in proc_stat.lines() {
        let mut f = line.split_whitespace();
        let Some(cpu) = f.next().and_then(|c| c.strip_prefix("cpu")) else {
            continue;
        };
        let Ok(n) = cpu.parse::<usize>() else {
            continue; // the all-CPU line
        };
        if s.steal_ticks.len() <= n {
            s.steal_ticks.resize(n + 1, 0);
        }
        s.steal_ticks[n] = f.nth(7).and_then(|v| v.parse().ok()).unwrap_or(0);
    }
    s.involuntary = status
        .lines()
        .find_map(|l| l.strip_prefix("nonvoluntary_ctxt_switches:"))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(0);
    // stat after "(comm)": state is field 3; minflt 10, majflt 12, processor 39 (proc(5)).
    let rest: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let field = |n: usize| rest.get(n - 3).and_then(|v| v.parse::<u64>().ok());
    s.faults = field(10)? + field(12)?;
    s.cpu = usize::try_from(field(39)?).ok()?;
    Some(s)
}

/// Samples the physics thread every millisecond from its start until `stop`.
fn sampler(stop: Arc<AtomicBool>) -> std::thread::JoinHandle<Vec<Sample>> {
    std::thread::spawn(move || {
        let mut out = Vec::with_capacity(200_000);
        let mut tid = None;
        while !stop.load(Ordering::Relaxed) {
            if tid.is_none() {
                tid = thread_id("flexdyn-physics");
            }
            if let Some(s) = tid.as_deref().and_then(sample) {
                out.push(s);
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        out
    })
}

/// \[ns\] run-queue wait in an overrun's window that counts as a cause: every wake-up from the
/// frame's sleep waits a few µs on the run queue, which is not one.
const RUN_DELAY_NS: u64 = 100_000;

/// Steal is booked at the scheduler tick after the CPU runs again: look this long past a frame.
const STEAL_LAG_NS: u64 = 5_000_000;

/// Splits the overrun frames by what the samples show around each (see the module docs).
fn attribute(frames: &[(u64, u64)], samples: &[Sample], physics_cpu: Option<usize>) -> Blame {
    let mut b = Blame {
        logged: frames.len() as u64,
        ..Blame::default()
    };
    let cpu_steal = |s: &Sample, cpu: usize| s.steal_ticks.get(cpu).copied().unwrap_or(0);
    if let (Some(first), Some(last)) = (samples.first(), samples.last()) {
        let cpu = physics_cpu.unwrap_or(last.cpu);
        b.physics_cpu_steal_ms =
            cpu_steal(last, cpu).saturating_sub(cpu_steal(first, cpu)) as f64 * TICK_MS;
    }
    for &(start, end) in frames {
        let before = samples.iter().rev().find(|s| s.t_ns <= start);
        let after = samples.iter().find(|s| s.t_ns >= end);
        let late = samples
            .iter()
            .find(|s| s.t_ns >= end + STEAL_LAG_NS)
            .or(after);
        let (Some(before), Some(after), Some(late)) = (before, after, late) else {
            b.unseen += 1;
            continue;
        };
        // The CPU(s) the thread ran on around the frame.
        let cpus = physics_cpu.map_or([before.cpu, after.cpu], |c| [c, c]);
        let stolen = cpus
            .iter()
            .any(|&c| cpu_steal(late, c) > cpu_steal(before, c));
        let preempted = after.involuntary > before.involuntary;
        let waited_ns = after.run_delay_ns.saturating_sub(before.run_delay_ns);
        let delayed = waited_ns >= RUN_DELAY_NS;
        let faulted = after.faults > before.faults;
        b.steal += u64::from(stolen);
        b.preempted += u64::from(preempted);
        b.run_delay += u64::from(delayed);
        b.faulted += u64::from(faulted);
        let own = preempted || delayed || faulted;
        b.own += u64::from(own);
        b.unseen += u64::from(!own && !stolen);
        if b.logged <= 10 {
            println!(
                "        overrun frame {:.0} µs, window {:.1} ms: run-queue wait {:.0} µs, \
                 involuntary {}, faults {}, steal ticks {}",
                (end - start) as f64 * 1e-3,
                (after.t_ns - before.t_ns) as f64 * 1e-6,
                waited_ns as f64 * 1e-3,
                after.involuntary - before.involuntary,
                after.faults - before.faults,
                cpus.iter()
                    .map(|&c| cpu_steal(late, c).saturating_sub(cpu_steal(before, c)))
                    .max()
                    .unwrap_or(0)
            );
        }
    }
    b
}

/// (steal, total) of the `cpu` line of `/proc/stat`, in USER_HZ ticks.
fn cpu_ticks() -> (u64, u64) {
    let stat = std::fs::read_to_string("/proc/stat").unwrap_or_default();
    let line = stat.lines().next().unwrap_or_default();
    let v: Vec<u64> = line
        .split_whitespace()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    // user nice system idle iowait irq softirq steal guest guest_nice (proc(5)); guest time is
    // already in user.
    let steal = v.get(7).copied().unwrap_or(0);
    let total = v.iter().take(8).sum();
    (steal, total)
}

/// USER_HZ: 100 on every Linux ABI flexdyn builds for.
const TICK_MS: f64 = 10.0;

/// The reference configuration at 1 kHz, or with `FLEXDYN_RT_SCENARIO` (a scenario file, e.g.
/// `scenarios/leo_environment.toml` for every environment model and sensor on) that scenario
/// with its `[simulation] frame_hz` set to 1000.
fn config() -> SimConfig {
    let Ok(path) = std::env::var("FLEXDYN_RT_SCENARIO") else {
        let text = DEFAULT_CONFIG_TOML.replace("frame_hz = 100.0 ", "frame_hz = 1000.0 ");
        return SimConfig::from_toml_str(&text).expect("reference configuration at 1 kHz");
    };
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("FLEXDYN_RT_SCENARIO {}: {e}", path.display()));
    let mut table: toml::Table = text
        .parse()
        .unwrap_or_else(|e| panic!("FLEXDYN_RT_SCENARIO {}: {e}", path.display()));
    if let Some(toml::Value::Table(sim)) = table.get_mut("simulation") {
        sim.insert("frame_hz".into(), toml::Value::Float(1000.0));
    }
    SimConfig::from_toml_str_in(&table.to_string(), path.parent().unwrap())
        .unwrap_or_else(|e| panic!("FLEXDYN_RT_SCENARIO {} at 1 kHz: {e}", path.display()))
}

/// Runs the server for `span` in a fresh thread (so a CPU mask set for the tuned run does not
/// outlive it): its own tokio runtime and Zenoh session, started after the mask is set.
fn run(
    settings: ServerSettings,
    keep_off: Option<usize>,
) -> Result<(RunReport, Vec<Sample>), String> {
    std::thread::spawn(move || {
        if let Some(cpu) = keep_off {
            rt::keep_off_cpu(cpu)?;
        }
        // Started after the mask: it samples from the other CPU.
        let stop = Arc::new(AtomicBool::new(false));
        let samples = sampler(stop.clone());
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .map_err(|e| e.to_string())?;
        let report = runtime.block_on(async move {
            let args = ZenohArgs {
                listen: vec!["tcp/127.0.0.1:0".into()],
                ..ZenohArgs::default()
            };
            let zcfg = zenoh_config(&args, Role::Server).map_err(|e| e.to_string())?;
            let session = zenoh::open(zcfg).await.map_err(|e| e.to_string())?;
            let r = server::run(session.clone(), settings, config(), std::future::pending()).await;
            let _ = session.close().await;
            r.map_err(|e| e.to_string())
        });
        stop.store(true, Ordering::Relaxed);
        let samples = samples.join().map_err(|_| "the sampler panicked")?;
        Ok((report?, samples))
    })
    .join()
    .map_err(|_| "the run panicked".to_string())?
}

/// \[µs\] lower edges of the printed lateness buckets; the last is open-ended.
const BUCKETS_US: [u64; 7] = [0, 1, 10, 50, 100, 500, 1000];

fn measure(settings: ServerSettings, keep_off: Option<usize>) -> Result<Figures, String> {
    let faults_before = rt::ThreadUsage::this_process();
    let (steal0, total0) = cpu_ticks();
    let physics_cpu = settings.physics_cpu;
    let (report, samples) = run(settings, keep_off)?;
    let (steal1, total1) = cpu_ticks();
    let faults = rt::ThreadUsage::this_process().since(&faults_before);
    let h = report.lateness.as_ref().ok_or("no lateness histogram")?;
    let us = |q: f64| h.value_at_quantile(q) as f64 * 1e-3;
    let physics = report.physics_thread.unwrap_or_default();
    Ok(Figures {
        lateness_us: [us(0.5), us(0.9), us(0.99), us(0.999), h.max() as f64 * 1e-3],
        histogram: std::array::from_fn(|k| {
            let low_ns = BUCKETS_US[k] * 1000;
            let high_ns = BUCKETS_US.get(k + 1).map_or(u64::MAX, |&e| e * 1000 - 1);
            h.count_between(low_ns, high_ns.min(h.max().max(low_ns)))
        }),
        overruns: report.timing.overrun_count,
        process_faults: faults.page_faults(),
        physics_faults: physics.page_faults(),
        physics_involuntary: physics.involuntary_switches,
        steal_ms: steal1.saturating_sub(steal0) as f64 * TICK_MS,
        cpu_ms: total1.saturating_sub(total0) as f64 * TICK_MS,
        blame: attribute(&report.overrun_frames_ns, &samples, physics_cpu),
    })
}

/// The histogram line under a run's row: frames per lateness bucket.
fn print_histogram(f: &Figures) {
    let cells: Vec<String> = BUCKETS_US
        .iter()
        .enumerate()
        .map(|(k, low)| match BUCKETS_US.get(k + 1) {
            Some(high) => format!("{low}-{high} µs {}", f.histogram[k]),
            None => format!(">= {low} µs {}", f.histogram[k]),
        })
        .collect();
    println!("        histogram: {}", cells.join(" | "));
}

fn print_row(name: &str, f: &Figures) {
    let l = f.lateness_us;
    println!(
        "{name:<7} {:>7.1} {:>7.1} {:>7.1} {:>8.1} {:>9.1} {:>8} {:>9} {:>9} {:>8} {:>9.0} ({:.2} %)",
        l[0],
        l[1],
        l[2],
        l[3],
        l[4],
        f.overruns,
        f.process_faults,
        f.physics_faults,
        f.physics_involuntary,
        f.steal_ms,
        if f.cpu_ms > 0.0 {
            100.0 * f.steal_ms / f.cpu_ms
        } else {
            0.0
        }
    );
    let b = &f.blame;
    println!(
        "        overruns: {} logged; steal on the physics CPU {}; own {} (preempted {}, \
         run-queue wait >= 100 µs {}, page fault {}); unseen {}; physics CPU steal {:.0} ms",
        b.logged,
        b.steal,
        b.own,
        b.preempted,
        b.run_delay,
        b.faulted,
        b.unseen,
        b.physics_cpu_steal_ms
    );
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

fn env_u64(name: &str, default: u64) -> u64 {
    match std::env::var(name) {
        Ok(v) => v.parse().unwrap_or_else(|_| {
            eprintln!("{name}={v:?} is not a whole number; using {default}");
            default
        }),
        Err(_) => default,
    }
}

fn main() {
    // `cargo bench` passes `--bench`; a filter argument selects nothing here.
    let span_s = env_u64("FLEXDYN_RT_SPAN_S", 60).max(1);
    let rounds = env_u64("FLEXDYN_RT_ROUNDS", 3).max(1);
    let normal = ServerSettings {
        duration_ns: Some(span_s * 1_000_000_000),
        summary_interval: Duration::from_secs(3600),
        ..ServerSettings::default()
    };
    let cpu = rt::allowed_cpus().ok().and_then(|c| c.last().copied());
    let tuned = ServerSettings {
        realtime_priority: 50,
        lock_memory: true,
        physics_cpu: cpu,
        cpu_dma_latency: true,
        ..normal.clone()
    };
    println!(
        "scenario: {} at 1 kHz",
        std::env::var("FLEXDYN_RT_SCENARIO").unwrap_or_else(|_| "scenarios/reference.toml".into())
    );
    println!(
        "realtime_lateness: 1 kHz, 1 RK4 step per frame, {rounds} round(s) x {span_s} s per \
         configuration; tuned = SCHED_FIFO 50 + lock_memory + physics_cpu {} + cpu_dma_latency",
        cpu.map_or("none".into(), |c| c.to_string())
    );
    println!(
        "{:<7} {:>7} {:>7} {:>7} {:>8} {:>9} {:>8} {:>9} {:>9} {:>8} {:>9}",
        "",
        "p50 µs",
        "p90 µs",
        "p99 µs",
        "p99.9 µs",
        "max µs",
        "overruns",
        "proc_pf",
        "phys_pf",
        "phys_ivcsw",
        "steal ms"
    );
    let mut all: Vec<(Figures, Option<Figures>)> = Vec::new();
    let started = Instant::now();
    for round in 0..rounds {
        println!("round {}", round + 1);
        let n = match measure(normal.clone(), None) {
            Ok(f) => f,
            Err(e) => {
                println!("normal run failed: {e}");
                return;
            }
        };
        print_row("normal", &n);
        print_histogram(&n);
        let t = match measure(tuned.clone(), cpu) {
            Ok(f) => {
                print_row("tuned", &f);
                print_histogram(&f);
                Some(f)
            }
            Err(e) => {
                println!("tuned   refused: {e}");
                None
            }
        };
        all.push((n, t));
    }
    let col = |pick: &dyn Fn(&Figures) -> f64, tuned: bool| {
        median(
            all.iter()
                .filter_map(|(n, t)| if tuned { t.as_ref() } else { Some(n) })
                .map(pick)
                .collect(),
        )
    };
    let ratio = |pick: &dyn Fn(&Figures) -> f64| {
        median(
            all.iter()
                .filter_map(|(n, t)| t.as_ref().map(|t| pick(t) / pick(n)))
                .filter(|r| r.is_finite())
                .collect(),
        )
    };
    println!(
        "\nmedians over {} round(s) ({:.0} s in all):",
        all.len(),
        started.elapsed().as_secs_f64()
    );
    type Pick = (&'static str, fn(&Figures) -> f64);
    let picks: [Pick; 13] = [
        ("lateness p50 [µs]", |f| f.lateness_us[0]),
        ("lateness p90 [µs]", |f| f.lateness_us[1]),
        ("lateness p99 [µs]", |f| f.lateness_us[2]),
        ("lateness p99.9 [µs]", |f| f.lateness_us[3]),
        ("lateness max [µs]", |f| f.lateness_us[4]),
        ("overruns", |f| f.overruns as f64),
        ("page faults, process", |f| f.process_faults as f64),
        ("page faults, physics thread", |f| f.physics_faults as f64),
        ("physics involuntary switches", |f| {
            f.physics_involuntary as f64
        }),
        ("steal [ms]", |f| f.steal_ms),
        ("overruns with steal seen", |f| f.blame.steal as f64),
        ("overruns with an own cause", |f| f.blame.own as f64),
        ("overruns, no cause seen", |f| f.blame.unseen as f64),
    ];
    println!(
        "{:<30} {:>12} {:>12} {:>14}",
        "", "normal", "tuned", "tuned/normal"
    );
    for (name, pick) in picks {
        println!(
            "{name:<30} {:>12.1} {:>12.1} {:>14.3}",
            col(&pick, false),
            col(&pick, true),
            ratio(&pick)
        );
    }
    println!(
        "target (issue 24): tuned overruns 0 and p99 <= 50 µs, or else every tuned overrun \
         without an own cause (preemption, run-queue wait, page fault of the physics thread)"
    );
}
