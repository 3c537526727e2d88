//! Hard real time: what the process and the physics thread do, when asked, so that the frame
//! loop is never kept waiting by the kernel (docs/guides/server.md, "Hard real time").
//!
//! Each piece is off unless its setting asks for it, and each one the OS refuses stops the
//! server at start with an error naming the setting, what the OS said and what it needs: a
//! hardware-in-the-loop bench that asked for real time must not quietly run without it.
//! - [`lock_memory`] (`lock_memory`): `mlockall(MCL_CURRENT | MCL_FUTURE)`, so every page
//!   mapped now is resident and every page mapped later is faulted in when it is mapped, not
//!   when the physics thread first touches it; the physics thread then touches its own stack
//!   ([`prefault_stack`]). Needs CAP_IPC_LOCK, or `ulimit -l` (RLIMIT_MEMLOCK) above what the
//!   process maps.
//! - [`keep_off_cpu`] / [`pin_to_cpu`] (`physics_cpu`): the physics thread alone on one CPU,
//!   every other thread of the process (tokio, Zenoh, telemetry, recorder) on the others. Needs
//!   nothing but the CPU in the process's allowed set (`taskset`, cgroup cpuset).
//! - [`DmaLatency`] (`cpu_dma_latency`): `/dev/cpu_dma_latency` held open with 0 written to
//!   it, so no CPU enters a C-state deeper than C0/C1 (wake-up latencies of tens of µs) while
//!   the server runs (kernel docs, `Documentation/power/pm_qos_interface.rst`). Needs write
//!   access to the device (root, or a udev rule).
//! - SCHED_FIFO (`realtime_priority`) is set by the physics thread itself
//!   (`super::set_fifo_priority`).
//!
//! Measurement helpers ([`ThreadUsage`]) read the kernel's per-thread and per-process counters
//! from `/proc` (the same counters `getrusage` sums), outside the frame loop.
//!
//! Everything goes through safe wrappers (`rustix`, `std::fs`): the workspace forbids `unsafe`.

use std::fs::File;
use std::io::Write;
use std::path::Path;

/// Bytes of the physics thread's stack touched at start ([`prefault_stack`]).
pub const PREFAULT_STACK_BYTES: usize = 256 * 1024;

/// Stack size given to the physics thread: the pre-faulted part plus headroom for the thread's
/// own frames below it.
pub const PHYSICS_STACK_BYTES: usize = 2 * 1024 * 1024;

/// The device of the CPU wake-up latency request (PM QoS).
pub const CPU_DMA_LATENCY: &str = "/dev/cpu_dma_latency";

/// Locks every page of the process in RAM, now and as it is mapped (`mlockall(MCL_CURRENT |
/// MCL_FUTURE)`). The error says what the OS refused and what the setting needs.
pub fn lock_memory() -> Result<(), String> {
    use rustix::mm::{mlockall, MlockAllFlags};
    mlockall(MlockAllFlags::CURRENT | MlockAllFlags::FUTURE).map_err(|e| {
        format!(
            "mlockall(MCL_CURRENT | MCL_FUTURE) failed: {e} (needs CAP_IPC_LOCK, or an \
             RLIMIT_MEMLOCK (`ulimit -l`) above the process's size; now {})",
            memlock_limit()
        )
    })
}

/// Undoes [`lock_memory`] (the end of a run; a process that runs the server again locks again).
pub fn unlock_memory() {
    let _ = rustix::mm::munlockall();
}

/// RLIMIT_MEMLOCK as `ulimit -l` reports it, for error messages.
fn memlock_limit() -> String {
    let limit = rustix::process::getrlimit(rustix::process::Resource::Memlock);
    match limit.current {
        None => "unlimited".into(),
        Some(bytes) => format!("{} KiB", bytes / 1024),
    }
}

/// Touches [`PREFAULT_STACK_BYTES`] of the calling thread's stack, one write per page, so the
/// frame loop's deeper calls find their stack pages resident (with [`lock_memory`], they stay
/// so). Call it first thing on the thread.
#[inline(never)]
pub fn prefault_stack() {
    let mut pages = [0u8; PREFAULT_STACK_BYTES];
    for i in (0..PREFAULT_STACK_BYTES).step_by(4096) {
        pages[i] = 1;
    }
    std::hint::black_box(&mut pages);
}

/// The CPUs the calling thread may run on.
pub fn allowed_cpus() -> Result<Vec<usize>, String> {
    let set = rustix::thread::sched_getaffinity(None)
        .map_err(|e| format!("sched_getaffinity failed: {e}"))?;
    Ok((0..rustix::thread::CpuSet::MAX_CPU)
        .filter(|&c| set.is_set(c))
        .collect())
}

fn set_cpus(cpus: impl IntoIterator<Item = usize>) -> Result<(), String> {
    let mut set = rustix::thread::CpuSet::new();
    for c in cpus {
        set.set(c);
    }
    rustix::thread::sched_setaffinity(None, &set)
        .map_err(|e| format!("sched_setaffinity failed: {e}"))
}

/// The CPUs the process could use before [`keep_off_cpu`] first moved a thread off one (the
/// calling thread's allowed set if it never did).
static PROCESS_CPUS: std::sync::OnceLock<Vec<usize>> = std::sync::OnceLock::new();

fn process_cpus() -> Result<Vec<usize>, String> {
    match PROCESS_CPUS.get() {
        Some(cpus) => Ok(cpus.clone()),
        None => allowed_cpus(),
    }
}

/// Checks that `cpu` can be given to the physics thread alone: it is one of the process's
/// CPUs (before any thread was kept off it) and is not the only one (the other threads need
/// one).
pub fn check_physics_cpu(cpu: usize) -> Result<(), String> {
    let allowed = process_cpus()?;
    if !allowed.contains(&cpu) {
        return Err(format!(
            "CPU {cpu} is not one this process may run on (allowed: {allowed:?})"
        ));
    }
    if allowed.len() < 2 {
        return Err(format!(
            "CPU {cpu} is the only CPU this process may run on: the I/O threads need another"
        ));
    }
    Ok(())
}

/// Moves the calling thread off `cpu`, onto the rest of its allowed set; threads it starts
/// afterwards inherit that mask. Called before the tokio runtime and the Zenoh session start
/// (`flexdyn run` does), it keeps every I/O thread off the physics thread's CPU.
pub fn keep_off_cpu(cpu: usize) -> Result<(), String> {
    check_physics_cpu(cpu)?;
    let all = process_cpus()?;
    let _ = PROCESS_CPUS.set(all.clone());
    set_cpus(all.into_iter().filter(|&c| c != cpu))
}

/// Pins the calling thread to `cpu` alone.
pub fn pin_to_cpu(cpu: usize) -> Result<(), String> {
    set_cpus([cpu])
}

/// An open `/dev/cpu_dma_latency` holding a 0 µs request: the request lasts while this value
/// lives (the kernel drops it when the file is closed).
#[derive(Debug)]
pub struct DmaLatency {
    _file: File,
}

impl DmaLatency {
    /// Requests 0 µs wake-up latency through [`CPU_DMA_LATENCY`].
    pub fn hold() -> Result<Self, String> {
        Self::hold_at(Path::new(CPU_DMA_LATENCY))
    }

    /// Writes the request (a native-endian `i32`, 0) to `path` and keeps it open.
    pub fn hold_at(path: &Path) -> Result<Self, String> {
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(|e| {
                format!(
                    "cannot open {} for writing: {e} (needs root or write access to the device)",
                    path.display()
                )
            })?;
        file.write_all(&0i32.to_ne_bytes())
            .map_err(|e| format!("cannot write 0 to {}: {e}", path.display()))?;
        Ok(Self { _file: file })
    }
}

/// Counters of one thread (or the whole process) since it started: what `getrusage` reports,
/// read from `/proc`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ThreadUsage {
    /// Page faults served without I/O.
    pub minor_faults: u64,
    /// Page faults that needed I/O.
    pub major_faults: u64,
    /// Times the thread gave up the CPU itself (sleeps, blocking waits).
    pub voluntary_switches: u64,
    /// Times the thread was preempted.
    pub involuntary_switches: u64,
}

impl ThreadUsage {
    /// The calling thread's counters (`/proc/thread-self`), zeros if unreadable.
    pub fn this_thread() -> Self {
        Self::read(Path::new("/proc/thread-self"))
    }

    /// The process's counters (`/proc/self`: every thread, live or ended), zeros if
    /// unreadable.
    pub fn this_process() -> Self {
        Self::read(Path::new("/proc/self"))
    }

    fn read(dir: &Path) -> Self {
        let mut u = Self::default();
        // Into a buffer on the stack: the reading allocates nothing, so it does not fault in
        // heap pages itself (it is called on the physics thread, off its frames).
        let mut buf = [0u8; 4096];
        // stat: "pid (comm) state ppid ..."; after the ')' field 3 is the state, so minflt
        // (field 10) and majflt (field 12) are the 8th and 10th after it (proc(5)).
        if let Some(stat) = read_small(&dir.join("stat"), &mut buf) {
            if let Some((_, rest)) = stat.rsplit_once(')') {
                let mut f = rest.split_whitespace();
                u.minor_faults = f.nth(7).and_then(|s| s.parse().ok()).unwrap_or(0);
                u.major_faults = f.nth(1).and_then(|s| s.parse().ok()).unwrap_or(0);
            }
        }
        if let Some(status) = read_small(&dir.join("status"), &mut buf) {
            for line in status.lines() {
                let value = |l: &str| l.split_whitespace().nth(1)?.parse().ok();
                if line.starts_with("voluntary_ctxt_switches:") {
                    u.voluntary_switches = value(line).unwrap_or(0);
                } else if line.starts_with("nonvoluntary_ctxt_switches:") {
                    u.involuntary_switches = value(line).unwrap_or(0);
                }
            }
        }
        u
    }

    /// Page faults of both kinds.
    pub fn page_faults(&self) -> u64 {
        self.minor_faults + self.major_faults
    }

    /// What happened between `before` and `self`.
    pub fn since(&self, before: &Self) -> Self {
        Self {
            minor_faults: self.minor_faults.saturating_sub(before.minor_faults),
            major_faults: self.major_faults.saturating_sub(before.major_faults),
            voluntary_switches: self
                .voluntary_switches
                .saturating_sub(before.voluntary_switches),
            involuntary_switches: self
                .involuntary_switches
                .saturating_sub(before.involuntary_switches),
        }
    }
}

/// The text of a small file (up to `buf`'s size), read into `buf`.
fn read_small<'a>(path: &Path, buf: &'a mut [u8]) -> Option<&'a str> {
    use std::io::Read;
    let mut file = File::open(path).ok()?;
    let mut n = 0;
    while n < buf.len() {
        match file.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(_) => return None,
        }
    }
    std::str::from_utf8(&buf[..n]).ok()
}

/// \[ns\] monotonic time (`Instant`, CLOCK_MONOTONIC: the vDSO, no system call) since a
/// process-wide origin, the first call. The overrun log ([`super::shared::OverrunLog`]) is in
/// this clock, so a bench sampling other counters meanwhile can line them up with the overruns.
pub fn monotonic_ns() -> u64 {
    static ORIGIN: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    let origin = *ORIGIN.get_or_init(std::time::Instant::now);
    u64::try_from(origin.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dma_latency_writes_a_zero_i32_and_names_the_path_it_cannot_open() {
        let dir = std::env::temp_dir().join(format!("flexdyn-dma-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("cpu_dma_latency");
        std::fs::write(&path, b"xxxxxxxx").unwrap();
        let held = DmaLatency::hold_at(&path).unwrap();
        // Written from the start of the file, native endian, 4 bytes.
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..4], &0i32.to_ne_bytes());
        drop(held);
        let missing = dir.join("absent/cpu_dma_latency");
        let e = DmaLatency::hold_at(&missing).unwrap_err();
        assert!(e.contains(&missing.display().to_string()), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn affinity_keeps_threads_off_the_physics_cpu_and_refuses_foreign_cpus() {
        std::thread::spawn(|| {
            let allowed = allowed_cpus().unwrap();
            assert!(!allowed.is_empty());
            let e = check_physics_cpu(4000).unwrap_err();
            assert!(e.contains("CPU 4000 is not one"), "{e}");
            if allowed.len() < 2 {
                assert!(check_physics_cpu(allowed[0]).is_err());
                return;
            }
            let cpu = allowed[allowed.len() - 1];
            keep_off_cpu(cpu).unwrap();
            assert!(!allowed_cpus().unwrap().contains(&cpu));
            // A thread started now inherits the mask; pinning takes it to the one CPU.
            std::thread::spawn(move || {
                assert!(!allowed_cpus().unwrap().contains(&cpu));
                set_cpus(allowed_cpus().unwrap()).unwrap();
            })
            .join()
            .unwrap();
            pin_to_cpu(allowed[0]).unwrap();
            assert_eq!(allowed_cpus().unwrap(), vec![allowed[0]]);
        })
        .join()
        .unwrap();
    }

    #[test]
    fn thread_usage_counts_the_faults_of_touching_new_pages() {
        std::thread::spawn(|| {
            let before = ThreadUsage::this_thread();
            // 64 fresh pages, each first touched here: at least one fault each, unless the
            // process's memory is locked (then none happen here; checked elsewhere). 64 MiB is
            // above glibc's largest dynamic mmap threshold (32 MiB), so the buffer is a fresh
            // mapping: a smaller one can come from heap pages another test already touched
            // (the full --lib run saw 0 faults with 256 KiB).
            let mut v = vec![0u8; 64 << 20];
            for i in (0..64 * 4096).step_by(4096) {
                v[i] = 1;
            }
            std::hint::black_box(&v);
            let d = ThreadUsage::this_thread().since(&before);
            assert!(d.page_faults() >= 1, "{d:?}");
            std::thread::sleep(std::time::Duration::from_millis(2));
            let d = ThreadUsage::this_thread().since(&before);
            assert!(
                d.voluntary_switches >= 1,
                "a sleep is a voluntary switch: {d:?}"
            );
        })
        .join()
        .unwrap();
    }
}
