//! The real-time check of the frame path (issue 24): everything the physics thread does per
//! frame under the hard real-time settings, except the deliberate sleep-then-spin wait for the
//! deadline, runs on a thread where **every system call traps** and every heap allocation is
//! counted; a frame path that allocates, sleeps, does I/O or waits on a lock fails.
//!
//! # Why not `rtsan-standalone`
//! The `rtsan-standalone` crate (LLVM's RealtimeSanitizer, `#[nonblocking]`) links a runtime its
//! build script fetches from GitHub at build time: a prebuilt library from the `rtsan-libs`
//! releases with curl, or else a clone of `llvm-project` to build it. This project's machines
//! and CI cannot reach GitHub (the crate registry only), so that build fails. This test is the
//! equivalent, built from what the kernel offers:
//!
//! - **System calls.** A seccomp-BPF filter (`seccompiler`) on the checked thread only answers
//!   every system call with `SECCOMP_RET_TRAP`, except `exit`, `rt_sigreturn` and
//!   `futex(FUTEX_WAKE)`. The kernel then skips the call and raises SIGSYS on that thread; the
//!   handler notes the call's number (`si_syscall`) in atomics and makes the call return 0, so
//!   the code under test runs on and the check lists every call it made. Blocking is always a
//!   system call (`futex` wait, `clock_nanosleep`, `read`, `poll`, ...), and so is all I/O
//!   (`write`, `sendto`, ...) and every page mapping (`mmap`, `brk`), so all of them fail the
//!   check. `clock_gettime` (`Instant::now`, `SystemTime::now`) is answered in user space by the
//!   vDSO and does not trap, as it should not; on a machine whose clock source has no vDSO
//!   path, it traps, and that is a real finding: every frame reads the clock.
//!   `FUTEX_WAKE` is allowed because it never blocks: it is how the frame hands its telemetry
//!   to a parked telemetry thread (`Thread::unpark`, once per frame at most).
//! - **Allocations.** The counting global allocator of `crates/testkit/src/alloc_counter.rs` (allocations,
//!   reallocations) on the checked thread: most allocations make no system call, so the filter
//!   alone would miss them. (`tests/server_alloc.rs` keeps checking the same with
//!   `assert_no_alloc`.)
//!
//! **Locks.** RTSan fails any `pthread_mutex_lock`, contended or not. Rust's `std::sync::Mutex`
//! on Linux is a futex: taking it uncontended is one atomic compare-and-swap, no system call, so
//! this check sees a lock only when it is contended (the `futex` wait, which it fails; see
//! `a_contended_mutex_fails_the_check`). An uncontended lock on the frame path would pass here
//! and is left to review; the frame path takes none by design (bounded channels' `try_send` /
//! `try_recv`, atomics; see `crates/server/src/physics.rs`), and whether a lock is *ever* contended is
//! what decides if the physics thread waits.
//!
//! The path checked is the loop of `crates/server/src/physics.rs` for real time with the telemetry
//! handed to the telemetry thread (`handoff = "thread"`, what `auto` picks under SCHED_FIFO):
//! the boundary's handoff (`try_send` of the filled frame, `unpark`), the command intake from
//! the bounded channel and the recycling of consumed commands, the server's own
//! [`Stepper`] (held commands, the frame's RK4 steps, the IMU and star tracker, telemetry fill,
//! finiteness check), the acquisition of the next free buffer, and the overrun bookkeeping.
//! The direct handoff (`handoff = "direct"`, the default without SCHED_FIFO) puts through Zenoh
//! on the physics thread, which is I/O by design and not checked here. The checker itself is
//! checked: an allocation, a contended mutex, a sleep and a write, each injected once into a
//! copy of the same path, must each fail it.

#![cfg(all(
    target_os = "linux",
    any(target_arch = "x86_64", target_arch = "aarch64")
))]

#[global_allocator]
static GLOBAL: flexdyn_testkit::alloc_counter::Counting = flexdyn_testkit::alloc_counter::Counting;
use flexdyn_testkit::alloc_counter;

/// Without a counting allocator the "allocates nothing" check here would pass for nothing.
#[test]
fn the_allocation_counter_is_installed() {
    alloc_counter::assert_installed();
}

use std::collections::BTreeMap;
use std::io::Write;
use std::sync::atomic::{AtomicBool, AtomicI32, AtomicUsize, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TryRecvError};
use std::sync::{Arc, Mutex, Once};
use std::time::{Duration, Instant};

use flexdyn_proto::client::transport::unix_now_ns;
use flexdyn_proto::{CommandMsg, EffectorInput, Header};
use flexdyn_server::pacing::{FrameEnd, Pacer};
use flexdyn_server::rt::monotonic_ns;
use flexdyn_server::settings::OverrunPolicy;
use flexdyn_server::shared::{Frame, Shared};
use flexdyn_server::stepper::{count_offer, Stepper};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::config::SimConfig;
use flexdyn_vehicle::sim::Simulation;
use seccompiler::{
    BpfProgram, SeccompAction, SeccompCmpArgLen, SeccompCmpOp, SeccompCondition, SeccompFilter,
    SeccompRule, TargetArch,
};

// ---------------------------------------------------------------------------------------------
// The checker: a SIGSYS handler that records, and the filter.

/// Numbers of the first system calls trapped while armed.
static TRAPPED: [AtomicI32; 64] = [const { AtomicI32::new(-1) }; 64];
/// How many system calls were trapped while armed (may exceed `TRAPPED.len()`).
static N_TRAPPED: AtomicUsize = AtomicUsize::new(0);
/// Whether traps are recorded (outside the checked frames they are only skipped).
static ARMED: AtomicBool = AtomicBool::new(false);
/// One check at a time: the recorder is process-wide.
static SERIAL: Mutex<()> = Mutex::new(());

/// The head of `siginfo_t` for SIGSYS (`struct { int si_signo, si_errno, si_code; union {
/// struct { void *_call_addr; int _syscall; unsigned _arch; } _sigsys; ... } }`, the union at
/// offset 16 on 64-bit Linux; `man 2 seccomp`, SECCOMP_RET_TRAP). `libc` has no accessor.
#[repr(C)]
struct SigsysInfo {
    signo: i32,
    errno: i32,
    code: i32,
    _pad: i32,
    call_addr: *mut libc::c_void,
    syscall: i32,
    arch: u32,
}

/// SIGSYS handler: notes the trapped call (when armed) and makes it return 0. Only atomics and
/// a register write: async-signal-safe.
extern "C" fn on_sigsys(_signal: libc::c_int, info: *mut libc::siginfo_t, ctx: *mut libc::c_void) {
    // SAFETY: the kernel passes a valid siginfo for a SIGSYS raised by SECCOMP_RET_TRAP, whose
    // layout `SigsysInfo` mirrors (see there).
    let nr = unsafe { (*info.cast::<SigsysInfo>()).syscall };
    if ARMED.load(Ordering::SeqCst) {
        let i = N_TRAPPED.fetch_add(1, Ordering::SeqCst);
        if let Some(slot) = TRAPPED.get(i) {
            slot.store(nr, Ordering::SeqCst);
        }
    }
    // The call was skipped; its return register holds -ENOSYS. Report success instead, so the
    // code under test carries on (a sleep returns at once, a write "wrote" nothing, a futex wait
    // returns and the lock is tried again).
    // SAFETY: `ctx` is the interrupted thread's `ucontext_t` (SA_SIGINFO); the register is
    // restored from it by rt_sigreturn.
    unsafe { set_return_register(ctx.cast::<libc::ucontext_t>(), 0) };
}

#[cfg(target_arch = "x86_64")]
unsafe fn set_return_register(ctx: *mut libc::ucontext_t, value: i64) {
    (*ctx).uc_mcontext.gregs[libc::REG_RAX as usize] = value;
}

#[cfg(target_arch = "aarch64")]
unsafe fn set_return_register(ctx: *mut libc::ucontext_t, value: i64) {
    (*ctx).uc_mcontext.regs[0] = value as u64;
}

fn install_handler() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // SAFETY: a zeroed sigaction is valid; the handler is async-signal-safe (see there).
        unsafe {
            let mut sa: libc::sigaction = std::mem::zeroed();
            sa.sa_sigaction = on_sigsys as *const () as usize;
            sa.sa_flags = libc::SA_SIGINFO;
            libc::sigemptyset(&mut sa.sa_mask);
            assert_eq!(
                libc::sigaction(libc::SIGSYS, &sa, std::ptr::null_mut()),
                0,
                "installing the SIGSYS handler"
            );
        }
    });
}

/// `futex` operation without the PRIVATE and CLOCK_REALTIME flags (FUTEX_CMD_MASK, linux/futex.h).
const FUTEX_CMD_MASK: u64 = 0x7f;
const FUTEX_WAKE: u64 = 1;

/// Traps every system call but `exit` (the checked thread ends), `rt_sigreturn` (the return
/// from the SIGSYS handler) and `futex(FUTEX_WAKE)` (waking a parked thread never blocks).
fn filter() -> BpfProgram {
    let arch = if cfg!(target_arch = "x86_64") {
        TargetArch::x86_64
    } else {
        TargetArch::aarch64
    };
    let wake_only = SeccompRule::new(vec![SeccompCondition::new(
        1,
        SeccompCmpArgLen::Dword,
        SeccompCmpOp::MaskedEq(FUTEX_CMD_MASK),
        FUTEX_WAKE,
    )
    .unwrap()])
    .unwrap();
    let rules: BTreeMap<i64, Vec<SeccompRule>> = [
        (libc::SYS_exit, vec![]),
        (libc::SYS_rt_sigreturn, vec![]),
        (libc::SYS_futex, vec![wake_only]),
    ]
    .into_iter()
    .collect();
    SeccompFilter::new(rules, SeccompAction::Trap, SeccompAction::Allow, arch)
        .unwrap()
        .try_into()
        .unwrap()
}

/// What the checker saw during the checked frames.
#[derive(Debug)]
struct Verdict {
    allocations: usize,
    /// Trapped system calls (the first 64), by name where known.
    syscalls: Vec<String>,
    /// All trapped system calls.
    n_syscalls: usize,
}

impl Verdict {
    fn passes(&self) -> bool {
        self.allocations == 0 && self.n_syscalls == 0
    }
}

fn syscall_name(nr: i32) -> String {
    let nr = i64::from(nr);
    #[cfg(target_arch = "x86_64")]
    let arch_only: &[(i64, &str)] = &[
        (libc::SYS_nanosleep, "nanosleep"),
        (libc::SYS_poll, "poll"),
        (libc::SYS_open, "open"),
    ];
    #[cfg(target_arch = "aarch64")]
    let arch_only: &[(i64, &str)] = &[];
    let known: &[(i64, &str)] = &[
        (libc::SYS_futex, "futex"),
        (libc::SYS_clock_nanosleep, "clock_nanosleep"),
        (libc::SYS_clock_gettime, "clock_gettime"),
        (libc::SYS_write, "write"),
        (libc::SYS_writev, "writev"),
        (libc::SYS_read, "read"),
        (libc::SYS_openat, "openat"),
        (libc::SYS_close, "close"),
        (libc::SYS_mmap, "mmap"),
        (libc::SYS_munmap, "munmap"),
        (libc::SYS_mprotect, "mprotect"),
        (libc::SYS_madvise, "madvise"),
        (libc::SYS_brk, "brk"),
        (libc::SYS_sched_yield, "sched_yield"),
        (libc::SYS_sendto, "sendto"),
        (libc::SYS_sendmsg, "sendmsg"),
        (libc::SYS_rt_sigprocmask, "rt_sigprocmask"),
        (libc::SYS_sigaltstack, "sigaltstack"),
    ];
    known
        .iter()
        .chain(arch_only)
        .find(|(n, _)| *n == nr)
        .map_or_else(|| format!("syscall {nr}"), |(_, name)| (*name).to_owned())
}

/// Runs `warm` frames of `h` unchecked, then `frames` frames with the filter applied and the
/// recorder armed, on a fresh thread; `inject` goes into the middle checked frame.
fn check(mut h: Harness, warm: u64, frames: u64, inject: Inject) -> Verdict {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    install_handler();
    let program = filter();
    let verdict = std::thread::scope(|s| {
        s.spawn(|| {
            for k in 0..warm {
                h.frame(k, Inject::Nothing);
            }
            seccompiler::apply_filter(&program).expect("seccomp filter refused");
            N_TRAPPED.store(0, Ordering::SeqCst);
            ARMED.store(true, Ordering::SeqCst);
            let allocations_before = alloc_counter::allocations();
            for k in warm..warm + frames {
                let what = if k == warm + frames / 2 {
                    inject
                } else {
                    Inject::Nothing
                };
                h.frame(k, what);
            }
            let allocations = alloc_counter::allocations() - allocations_before;
            ARMED.store(false, Ordering::SeqCst);
            let n_syscalls = N_TRAPPED.load(Ordering::SeqCst);
            (allocations, n_syscalls)
            // From here the thread's own exit (sigaltstack, munmap, ...) traps unrecorded.
        })
        .join()
        .expect("the checked thread panicked")
    });
    let (allocations, n_syscalls) = verdict;
    let syscalls = TRAPPED
        .iter()
        .take(n_syscalls.min(TRAPPED.len()))
        .map(|a| syscall_name(a.load(Ordering::SeqCst)))
        .collect();
    h.finish();
    Verdict {
        allocations,
        syscalls,
        n_syscalls,
    }
}

// ---------------------------------------------------------------------------------------------
// The frame path.

/// What to add to the frame path (the checker's own test).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Inject {
    Nothing,
    /// A small heap allocation (no system call: only the counting allocator sees it).
    Allocation,
    /// Taking a mutex another thread holds.
    ContendedMutex,
    /// `std::thread::sleep(100 µs)`.
    Sleep,
    /// A log line written to stderr.
    Write,
}

/// A mutex another thread holds while the injected frame takes it.
struct Holder {
    lock: Arc<Mutex<()>>,
    held: Arc<AtomicBool>,
    /// Set by the frame just before it takes the lock.
    wanted: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Holder {
    /// Holds the mutex from now until `hold` after the frame asks for it (so the frame waits
    /// whatever the machine's load).
    fn start(hold: Duration) -> Self {
        let lock = Arc::new(Mutex::new(()));
        let held = Arc::new(AtomicBool::new(false));
        let wanted = Arc::new(AtomicBool::new(false));
        let (l, h, w) = (lock.clone(), held.clone(), wanted.clone());
        let thread = std::thread::spawn(move || {
            let guard = l.lock().unwrap();
            h.store(true, Ordering::SeqCst);
            while !w.load(Ordering::SeqCst) {
                std::thread::sleep(Duration::from_millis(1));
            }
            std::thread::sleep(hold);
            drop(guard);
        });
        while !held.load(Ordering::SeqCst) {
            std::hint::spin_loop();
        }
        Self {
            lock,
            held,
            wanted,
            thread: Some(thread),
        }
    }
}

/// The physics thread's per-frame work and the I/O side it talks to: a stepper, the bounded
/// command channel, a fixed pool of telemetry buffers cycled through two bounded channels, a
/// telemetry thread that parks between frames (as `crates/server/src/telemetry.rs` does), the shared
/// counters and the overrun bookkeeping.
struct Harness {
    w: Stepper,
    shared: Arc<Shared>,
    cmd_tx: SyncSender<CommandMsg>,
    cmd_rx: Receiver<CommandMsg>,
    recycle_tx: SyncSender<CommandMsg>,
    free_rx: Receiver<Box<Frame>>,
    full_tx: Option<SyncSender<Box<Frame>>>,
    pending: Option<Box<Frame>>,
    pacer: Pacer,
    /// Actuators commands with heap vectors, built beforehand as the Zenoh callback builds
    /// them (popped one per frame).
    wheel_commands: Vec<CommandMsg>,
    telemetry: Option<std::thread::JoinHandle<()>>,
    telemetry_thread: std::thread::Thread,
    holder: Option<Holder>,
    stderr: std::io::Stderr,
}

const POOL: usize = 4;

impl Harness {
    fn new(frames: u64, inject: Inject) -> Self {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/wheels_star_tracker.toml");
        let cfg = SimConfig::from_file(&path).unwrap();
        let sim = Simulation::new(&cfg).unwrap();
        assert!(sim.n_imus() > 0 && !sim.star_trackers().is_empty());
        let shape = sim.blank_state();
        let n_sensors = sim.sensors().len();
        let settings = ServerSettings {
            participants: vec![1, 2],
            ..ServerSettings::default()
        };
        let shared = Arc::new(Shared::new(&settings.participants));
        let w = Stepper::new(sim, &settings);
        let (cmd_tx, cmd_rx) = sync_channel::<CommandMsg>(settings.command_queue);
        let (recycle_tx, recycle_rx) = sync_channel::<CommandMsg>(4 * settings.command_queue);
        let (free_tx, free_rx) = sync_channel::<Box<Frame>>(POOL);
        let (full_tx, full_rx) = sync_channel::<Box<Frame>>(POOL);
        for _ in 0..POOL {
            free_tx
                .send(Box::new(Frame::for_state(&shape, n_sensors)))
                .unwrap();
        }
        // The telemetry thread's part: return each frame to the pool, free the consumed
        // commands, park in between (never waiting inside the channel).
        let telemetry = std::thread::spawn(move || loop {
            while recycle_rx.try_recv().is_ok() {}
            match full_rx.try_recv() {
                Ok(f) => {
                    let _ = free_tx.send(f);
                }
                Err(TryRecvError::Empty) => std::thread::park_timeout(Duration::from_millis(5)),
                Err(TryRecvError::Disconnected) => return,
            }
        });
        let telemetry_thread = telemetry.thread().clone();
        let wheel_commands = (0..frames + 1)
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
        let mut w = w;
        let mut pending = free_rx.try_recv().ok();
        if let Some(f) = pending.as_mut() {
            w.fill(f, 0);
        }
        Self {
            w,
            shared,
            cmd_tx,
            cmd_rx,
            recycle_tx,
            free_rx,
            full_tx: Some(full_tx),
            pending,
            // A 1 ns period: every frame overruns, so the overrun log is written every frame.
            pacer: Pacer::new(Instant::now(), 1, settings.spin, OverrunPolicy::CatchUp, 0),
            wheel_commands,
            telemetry: Some(telemetry),
            telemetry_thread,
            holder: (inject == Inject::ContendedMutex)
                .then(|| Holder::start(Duration::from_millis(10))),
            stderr: std::io::stderr(),
        }
    }

    /// One frame, boundary `k` to `k + 1`, as `PhysicsCtx::frame_loop` runs it in real time with
    /// the thread handoff, without the wait for boundary `k`.
    fn frame(&mut self, k: u64, inject: Inject) {
        // 1. Boundary k: hand the filled state of tick k to the telemetry thread.
        let frame_start_ns = monotonic_ns();
        self.shared.tick.store(k, Ordering::Release);
        let stamp = unix_now_ns();
        if let Some(mut f) = self.pending.take() {
            f.boundary_unix_ns = stamp;
            f.lateness_ns = 0;
            let t = Instant::now();
            let full_tx = self.full_tx.as_ref().expect("running");
            if full_tx.try_send(f).is_err() {
                panic!("telemetry thread ended");
            }
            self.telemetry_thread.unpark();
            self.shared
                .note_handoff(u64::try_from(t.elapsed().as_nanos()).unwrap_or(u64::MAX));
        }
        // Meanwhile the I/O side has queued this frame's commands (the Zenoh callback's part).
        let wrench = CommandMsg::wrench(Header::new(1, k, 0, k), 1, [0.0, 0.0, 0.01], [0.0; 3]);
        let _ = self.cmd_tx.try_send(wrench);
        if let Some(c) = self.wheel_commands.pop() {
            let _ = self.cmd_tx.try_send(c);
        }
        // 2. Commands for tick k.
        while let Ok(cmd) = self.cmd_rx.try_recv() {
            count_offer(
                &self.shared,
                self.w.book.offer_latest(&cmd, k),
                cmd.sender_id,
            );
            let _ = self.recycle_tx.try_send(cmd);
        }
        self.inject(inject);
        // 3. Integrate the frame; 4. fill the state of tick k + 1.
        self.w.step(k);
        self.pending = match self.free_rx.try_recv() {
            Ok(f) => Some(f),
            Err(TryRecvError::Empty) => {
                self.shared
                    .telemetry_dropped
                    .fetch_add(1, Ordering::Relaxed);
                None
            }
            Err(TryRecvError::Disconnected) => panic!("pool gone"),
        };
        if let Some(f) = self.pending.as_mut() {
            self.w.fill(f, k + 1);
        }
        self.w.check_finite(k + 1, self.pending.is_some()).unwrap();
        if self.pacer.end_frame(k + 1) == FrameEnd::Overrun {
            self.shared.overrun_log.note(frame_start_ns, monotonic_ns());
        }
    }

    fn inject(&mut self, inject: Inject) {
        match inject {
            Inject::Nothing => {}
            Inject::Allocation => {
                std::hint::black_box(vec![0u8; 32]);
            }
            Inject::ContendedMutex => {
                let h = self.holder.as_ref().expect("holder started");
                assert!(h.held.load(Ordering::SeqCst), "the holder holds the lock");
                h.wanted.store(true, Ordering::SeqCst);
                drop(h.lock.lock());
            }
            Inject::Sleep => std::thread::sleep(Duration::from_micros(100)),
            Inject::Write => {
                let _ = self.stderr.write_all(b"frame log line\n");
            }
        }
    }

    /// Stops the telemetry thread (and the mutex holder).
    fn finish(&mut self) {
        self.full_tx = None;
        self.telemetry_thread.unpark();
        if let Some(t) = self.telemetry.take() {
            t.join().unwrap();
        }
        if let Some(mut h) = self.holder.take() {
            if let Some(t) = h.thread.take() {
                t.join().unwrap();
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The tests.

const WARM: u64 = 50;
const FRAMES: u64 = 400;

fn checked(inject: Inject) -> Verdict {
    let v = check(Harness::new(WARM + FRAMES, inject), WARM, FRAMES, inject);
    println!("{inject:?}: {v:?}");
    v
}

#[test]
fn the_frame_path_makes_no_system_call_and_no_allocation() {
    let v = checked(Inject::Nothing);
    assert!(
        v.passes(),
        "the frame path is not real-time safe over {FRAMES} frames: {v:?}"
    );
}

#[test]
fn an_allocation_fails_the_check() {
    let v = checked(Inject::Allocation);
    assert!(!v.passes());
    assert!(v.allocations >= 1, "{v:?}");
}

#[test]
fn a_contended_mutex_fails_the_check() {
    let v = checked(Inject::ContendedMutex);
    assert!(!v.passes());
    assert!(v.syscalls.iter().any(|s| s == "futex"), "{v:?}");
}

#[test]
fn a_sleep_fails_the_check() {
    let v = checked(Inject::Sleep);
    assert!(!v.passes());
    assert!(
        v.syscalls
            .iter()
            .any(|s| s == "clock_nanosleep" || s == "nanosleep"),
        "{v:?}"
    );
}

#[test]
fn a_write_fails_the_check() {
    let v = checked(Inject::Write);
    assert!(!v.passes());
    assert!(v.syscalls.iter().any(|s| s == "write"), "{v:?}");
}
