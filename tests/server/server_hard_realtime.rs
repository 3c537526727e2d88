//! The hard real-time settings (`lock_memory`, `physics_cpu`, `cpu_dma_latency`,
//! `realtime_priority`) do what they say on a real run, and a setting the OS refuses stops the
//! run at start naming the setting. Its own test binary: `mlockall` is process-wide.

use flexdyn_testkit_server::server as server_support;

use std::time::Duration;

use flexdyn_server::{rt, Outcome, ServerError, ServerSettings};
use server_support::{reference_config, ServerHandle};

const WAIT: Duration = Duration::from_secs(30);

/// `Cpus_allowed_list` of every thread of this process named `name` (comm, 15 characters).
fn cpus_of_threads(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    for task in std::fs::read_dir("/proc/self/task").unwrap().flatten() {
        let comm = std::fs::read_to_string(task.path().join("comm")).unwrap_or_default();
        if comm.trim() != name {
            continue;
        }
        let status = std::fs::read_to_string(task.path().join("status")).unwrap_or_default();
        if let Some(l) = status.lines().find(|l| l.starts_with("Cpus_allowed_list:")) {
            out.push(l.split_whitespace().nth(1).unwrap_or("").to_owned());
        }
    }
    out
}

/// \[kB\] locked memory of this process (`VmLck` of `/proc/self/status`).
fn locked_kb() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status.lines().find(|l| l.starts_with("VmLck:")).unwrap();
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

/// Whether this process may do everything the settings ask (root in the test containers).
fn privileged() -> bool {
    rustix::process::geteuid().is_root()
}

#[test]
fn every_setting_applies_and_the_frame_loop_takes_no_page_fault() {
    assert_eq!(locked_kb(), 0, "nothing is locked before the run");
    let allowed = rt::allowed_cpus().unwrap();
    assert!(
        allowed.len() >= 2,
        "this check needs two CPUs (allowed: {allowed:?})"
    );
    let cpu = *allowed.last().unwrap();
    let server = ServerHandle::start(
        ServerSettings {
            duration_ns: Some(2_000_000_000),
            lock_memory: true,
            physics_cpu: Some(cpu),
            cpu_dma_latency: true,
            realtime_priority: 10,
            ..ServerSettings::default()
        },
        reference_config(1000.0),
    );
    // While it runs: the physics thread is on its CPU alone, the telemetry thread off it.
    std::thread::sleep(Duration::from_millis(800));
    let physics = cpus_of_threads("flexdyn-physics");
    let telemetry = cpus_of_threads("flexdyn-telemet");
    let locked_while_running = locked_kb();
    let result = server.join(WAIT);
    if !privileged() {
        // Without the capabilities the run must not start, and must say which setting.
        let e = result.unwrap_err();
        assert!(matches!(e, ServerError::Realtime { .. }), "{e}");
        return;
    }
    let report = result.expect("server run");
    assert_eq!(report.outcome, Outcome::Finished);
    assert_eq!(physics, vec![cpu.to_string()], "physics thread's CPUs");
    assert_eq!(telemetry.len(), 1, "one telemetry thread");
    let others: Vec<usize> = telemetry[0]
        .split(',')
        .flat_map(|r| match r.split_once('-') {
            Some((a, b)) => (a.parse().unwrap()..=b.parse().unwrap()).collect::<Vec<usize>>(),
            None => vec![r.parse().unwrap()],
        })
        .collect();
    assert!(
        !others.contains(&cpu) && !others.is_empty(),
        "telemetry thread on {others:?}"
    );
    // mlockall held the whole process (tens of MB: the binary, Zenoh's buffers, every stack)
    // while running, and was undone at the end.
    assert!(
        locked_while_running > 10_000,
        "VmLck {locked_while_running} kB"
    );
    assert_eq!(locked_kb(), 0, "unlocked after the run");
    // No page fault on the physics thread after its first frame. (On a machine with free
    // memory this holds without lock_memory too; lock_memory is what keeps it under memory
    // pressure, when the kernel would otherwise reclaim the loop's pages.)
    let usage = report.physics_thread.expect("real time reports the thread");
    assert_eq!(usage.page_faults(), 0, "{report}");
    eprintln!("{report}");
}

#[test]
fn a_refused_setting_stops_the_run_at_start_naming_it() {
    let server = ServerHandle::start(
        ServerSettings {
            duration_ns: Some(1_000_000_000),
            physics_cpu: Some(4000),
            ..ServerSettings::default()
        },
        reference_config(100.0),
    );
    let e = server.join(WAIT).unwrap_err();
    assert_eq!(e.exit_code(), 1);
    assert!(
        e.to_string()
            .starts_with("server.physics_cpu: CPU 4000 is not one this process may run on"),
        "{e}"
    );
}
