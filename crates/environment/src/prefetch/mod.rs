//! The next environment sample, computed ahead of time on a worker thread, so that the
//! environment models (IGRF, NRLMSISE-00, the ephemerides, the Earth's orientation: about 15 µs
//! per update) never run on the physics thread — and with output bit-identical to computing it
//! there.
//!
//! # Why the result cannot depend on the worker's timing
//! The sample that comes into force at update instant `t₁` is, by definition, the environment
//! at `t₁` for the hub position **predicted** from the state at the previous update `t₀`
//! ([`Request::predicted`]), not for the state actually reached at `t₁`. That request is known at
//! `t₀`, so the physics thread hands it to the worker then and picks the answer up at `t₁`. If
//! the answer is not there yet (a lockstep or batch run faster than the worker, a worker that was
//! descheduled, no worker at all), the physics thread evaluates the **same request** with the
//! same function itself. Both paths run identical floating-point code on identical inputs, so
//! the sample, and every state after it, is the same bit for bit whichever path ran: the worker
//! is only a cache. `crates/vehicle/tests/environment_prefetch.rs` checks this on the LEO scenario.
//!
//! # What the prediction costs
//! [`Request::predicted`] propagates the point-mass Kepler motion by its Taylor series to the
//! third order in Δ = t₁ − t₀ (position, velocity, acceleration and jerk of the two-body
//! problem; Vallado, *Fundamentals of Astrodynamics and Applications*, 4th ed., §2.3, eq. 2-3 and
//! its time derivative). What it leaves out is every other acceleration `a_p` of the hub point
//! B: J2 (up to 2.4e-2 m/s² at 500 km), B's own motion about the centre of mass as the panels
//! vibrate, drag and solar pressure (below 1e-6 m/s²), a commanded force (F/m). The predicted
//! position is then off by at most ½·max|a_p|·Δ² plus the two-body remainder (n⁴·r·Δ⁴/24,
//! 4e-11 m at Δ = 0.1 s in LEO). On the LEO scenario at its 10 Hz update, max|a_p| is
//! 3.7e-2 m/s² and the worst position error 1.8e-4 m (`crates/vehicle/tests/environment_prefetch.rs`). The
//! fields change over kilometres (|∇B| ≈ 3|B|/r ≈ 2e-11 T/m, a density scale height of
//! ≥ 20 km), so the prediction moves B by ~2e-15 T and the density by ~1.5e-9 of itself —
//! against the zero-order hold's own error over the same 100 ms, ~1e-8 T for B (760 m of
//! flight).
//!
//! # The hand-off
//! One request and one answer, in a slot of atomics (no lock, no allocation): the physics thread
//! writes a request and marks it `REQUESTED`; the worker claims it (`WORKING`), evaluates it,
//! writes the sample and marks it `DONE`. The physics
//! thread reads a `DONE` answer whose time and position match its request; anything else
//! (`REQUESTED`, `WORKING`, a stale answer) means "evaluate it here". A request the worker has
//! not claimed is withdrawn then, so it does no useless work; while it is `WORKING` on a stale
//! request, the next one is evaluated on the physics thread too, and nothing waits.
//!
//! # Nobody wakes the worker: it polls
//! The physics thread makes no system call. Waking a parked thread is a `futex` wake, which on
//! this project's 2-vCPU VM costs several microseconds (an inter-processor interrupt through the
//! hypervisor): at a 10 Hz update of a 1 kHz step that was ~70 ns per step, so offloading the
//! models cost the stepping thread more than evaluating them there (`benches/step.rs`, "all @
//! 10 Hz, offloaded"). Instead the worker sleeps between looks at the slot for an eighth of the
//! wall time between the physics thread's recent requests (`poll_period`: 20 µs to 5 ms), so it
//! claims a request within about an eighth of the time the answer has before it is needed, and
//! costs ~200 short wake-ups a second in a real-time run (10 Hz updates).
//!
//! # When requests come faster than a sleep: it spins
//! A sleep shorter than 20 µs is mostly the kernel's timer slack, so a worker that sleeps cannot
//! follow requests less than 160 µs apart. That is a batch or benchmark run of a vehicle whose
//! environment updates every few steps: `scenarios/acs_full.toml` updates it every 10 steps of
//! ~4 µs, and its worker, waking every ~70 µs, answered 2–5 % of the requests
//! (`cargo bench --bench acs_full`); the rest ran on the stepping thread. While requests keep
//! coming that often (`SPIN_WINDOW`), the worker looks at the slot without sleeping
//! (`std::hint::spin_loop`) and yields its core every 20 µs, so a thread woken on that core
//! runs. It spins only with one of a process-wide count of tickets, one fewer than the cores the
//! process may use (one on two cores, none on one): a fleet's workers do not fill the machine.
//! Spinning stops 160 µs after the worker last saw a new request, so a real-time run at the
//! shipped rates or a lockstep run at a participant's usual pace (requests milliseconds apart)
//! does not spin; an update rate above the frame rate in real time, or a participant answering
//! in tens of microseconds, does.
//!
//! A spinning worker needs a core of its own. In some rounds of the bench (most often right
//! after the Basilisk peer had run) the kernel started the worker on the stepping thread's
//! core, and neither the worker's yields nor its sleeps moved it to the idle one: it looked at
//! its slot once per time slice of the stepping thread, every ~4 ms, and answered 1 % of the
//! requests (`perf record -e sched:sched_switch,sched:sched_wakeup_new`). So a worker that
//! comes back to its slot 500 µs (`STARVED`) later than it meant while spinning moves itself to
//! another of its allowed cores (`leave_this_core`), at most once per 10 ms (`SPIN_RETRY`);
//! starved again within that time, or with no other core, it sleeps between looks for 100 ms
//! (`SPIN_REST`).
//!
//! Most often the worker lands there at its first spin: the kernel wakes it from its sleep on
//! the core of the thread it preempts. So the physics thread notes its core at each post
//! (`getcpu` through the vDSO, no system call), and a worker about to spin on that same core
//! moves the same way at once, instead of after the stepping thread's time slice: in the
//! shipped case that slice had cost 84–98 updates in a row evaluated on the stepping thread.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};
use std::thread::{JoinHandle, Thread};
use std::time::{Duration, Instant};

use nalgebra::Vector3;

use super::{sample_from_words, sample_to_words, EnvironmentSample, SAMPLE_WORDS};

/// \[m³/s²\] the Earth's gravitational parameter for the prediction (EGM-96 / WGS-84 value,
/// NIMA TR8350.2, Table 3.4). Only the prediction's third-order term depends on its exact value.
const MU_EARTH_M3_S2: f64 = 3.986_004_418e14;

/// What an update evaluates: the environment at `t_sim_ns` for a hub at `r_bn_n_m` moving at
/// `v_bn_n_m_s` (N).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Request {
    /// \[ns\] simulation time of the sample.
    pub t_sim_ns: u64,
    /// \[m\] position of the hub point B, N components.
    pub r_bn_n_m: Vector3<f64>,
    /// \[m/s\] velocity of B, N components.
    pub v_bn_n_m_s: Vector3<f64>,
}

impl Request {
    /// The request for `t_to_ns` predicted from the state (`r_bn_n_m`, `v_bn_n_m_s`) at
    /// `t_from_ns`: two-body Taylor series to third order in Δ (module docs for its error).
    pub fn predicted(
        t_from_ns: u64,
        r_bn_n_m: &Vector3<f64>,
        v_bn_n_m_s: &Vector3<f64>,
        t_to_ns: u64,
    ) -> Self {
        let dt_s = t_to_ns.saturating_sub(t_from_ns) as f64 * 1e-9;
        let r2 = r_bn_n_m.norm_squared();
        let (a, j) = if r2 > 0.0 {
            // a = −μ r / r³; j = da/dt = −μ/r³ (v − 3 (r·v)/r² r).
            let mu_r3 = MU_EARTH_M3_S2 / (r2 * r2.sqrt());
            let a = -mu_r3 * r_bn_n_m;
            let j = -mu_r3 * (v_bn_n_m_s - 3.0 * r_bn_n_m.dot(v_bn_n_m_s) / r2 * r_bn_n_m);
            (a, j)
        } else {
            (Vector3::zeros(), Vector3::zeros())
        };
        let dt2 = dt_s * dt_s;
        Self {
            t_sim_ns: t_to_ns,
            r_bn_n_m: r_bn_n_m + v_bn_n_m_s * dt_s + a * (0.5 * dt2) + j * (dt2 * dt_s / 6.0),
            v_bn_n_m_s: v_bn_n_m_s + a * dt_s + j * (0.5 * dt2),
        }
    }

    fn to_words(self) -> [u64; REQUEST_WORDS] {
        let (r, v) = (self.r_bn_n_m, self.v_bn_n_m_s);
        [
            self.t_sim_ns,
            r.x.to_bits(),
            r.y.to_bits(),
            r.z.to_bits(),
            v.x.to_bits(),
            v.y.to_bits(),
            v.z.to_bits(),
        ]
    }

    fn from_words(w: &[u64; REQUEST_WORDS]) -> Self {
        let f = |i: usize| f64::from_bits(w[i]);
        Self {
            t_sim_ns: w[0],
            r_bn_n_m: Vector3::new(f(1), f(2), f(3)),
            v_bn_n_m_s: Vector3::new(f(4), f(5), f(6)),
        }
    }
}

const REQUEST_WORDS: usize = 7;
/// The answer: the request it answers, how many words of sample follow, then the sample (its
/// time and each registered model's fields: [`crate::model::part::EnvironmentPart::to_words`]).
/// Only the words a sample uses move, so that without albedo the slot does not move the cap's.
const ANSWER_WORDS: usize = REQUEST_WORDS + 1 + SAMPLE_WORDS;

/// No request outstanding (the slot's request words are the physics thread's to write).
const IDLE: u8 = 0;
/// A request is written and not yet claimed.
const REQUESTED: u8 = 1;
/// The worker is evaluating the request.
const WORKING: u8 = 2;
/// The answer words hold the answer to the request.
const DONE: u8 = 3;

/// The slot shared by the physics thread and the worker.
struct Slot {
    state: AtomicU8,
    /// Answers the physics thread took from the worker (a statistic).
    taken: AtomicU64,
    /// Requests posted by the physics thread (the worker paces its polling by their rate).
    posted: AtomicU64,
    stop: AtomicBool,
    /// The core the physics thread last posted from ([`current_cpu`]; `usize::MAX`: unknown),
    /// so that a worker about to spin can tell it shares that core.
    physics_cpu: AtomicUsize,
    request: [AtomicU64; REQUEST_WORDS],
    answer: [AtomicU64; ANSWER_WORDS],
}

impl Slot {
    fn new() -> Self {
        Self {
            state: AtomicU8::new(IDLE),
            taken: AtomicU64::new(0),
            posted: AtomicU64::new(0),
            stop: AtomicBool::new(false),
            physics_cpu: AtomicUsize::new(usize::MAX),
            request: std::array::from_fn(|_| AtomicU64::new(0)),
            answer: std::array::from_fn(|_| AtomicU64::new(0)),
        }
    }

    /// Physics thread: publishes `req` unless the worker is busy with an older one (then the
    /// physics thread will evaluate `req` itself). Returns whether it was published.
    fn post(&self, req: &Request) -> bool {
        let cur = self.state.load(Ordering::Acquire);
        if cur == WORKING
            || (cur == REQUESTED
                && self
                    .state
                    .compare_exchange(REQUESTED, IDLE, Ordering::AcqRel, Ordering::Acquire)
                    .is_err())
        {
            return false;
        }
        // IDLE or DONE (a stale answer nobody will read): the request words are ours.
        for (cell, w) in self.request.iter().zip(req.to_words()) {
            cell.store(w, Ordering::Relaxed);
        }
        self.state.store(REQUESTED, Ordering::Release);
        true
    }

    /// Physics thread: the worker's answer to `req` if it is ready; withdraws `req` if the
    /// worker has not claimed it yet.
    fn answer(&self, req: &Request) -> Option<EnvironmentSample> {
        match self.state.load(Ordering::Acquire) {
            DONE => {
                let mut w = [0u64; ANSWER_WORDS];
                // The request and the sample's length first; then that many words.
                let head = REQUEST_WORDS + 1;
                for (x, cell) in w[..head].iter_mut().zip(&self.answer) {
                    *x = cell.load(Ordering::Relaxed);
                }
                if w[..REQUEST_WORDS] != req.to_words() {
                    return None;
                }
                let end = head + (w[REQUEST_WORDS] as usize).min(SAMPLE_WORDS);
                for (x, cell) in w[head..end].iter_mut().zip(&self.answer[head..end]) {
                    *x = cell.load(Ordering::Relaxed);
                }
                Some(sample_from_words(&w[head..end]))
            }
            REQUESTED => {
                let _ = self.state.compare_exchange(
                    REQUESTED,
                    IDLE,
                    Ordering::AcqRel,
                    Ordering::Acquire,
                );
                None
            }
            _ => None,
        }
    }

    /// Worker: evaluates the outstanding request with `fill`, if there is one. Returns whether
    /// it did.
    fn serve(&self, fill: &impl Fn(&Request, &mut EnvironmentSample)) -> bool {
        if self
            .state
            .compare_exchange(REQUESTED, WORKING, Ordering::AcqRel, Ordering::Acquire)
            .is_err()
        {
            return false;
        }
        let mut w = [0u64; REQUEST_WORDS];
        for (x, cell) in w.iter_mut().zip(&self.request) {
            *x = cell.load(Ordering::Relaxed);
        }
        let req = Request::from_words(&w);
        let mut sample = EnvironmentSample::NONE;
        fill(&req, &mut sample);
        let mut words = [0u64; ANSWER_WORDS];
        words[..REQUEST_WORDS].copy_from_slice(&req.to_words());
        let n = sample_to_words(&sample, &mut words[REQUEST_WORDS + 1..]);
        words[REQUEST_WORDS] = n as u64;
        let used = REQUEST_WORDS + 1 + n;
        for (cell, x) in self.answer.iter().zip(&words[..used]) {
            cell.store(*x, Ordering::Relaxed);
        }
        self.state.store(DONE, Ordering::Release);
        true
    }
}

/// \[s\] the bounds of the worker's polling period: below 20 µs a sleep is mostly the kernel's
/// timer slack (50 µs by default); above 5 ms a run whose requests slow down (a lockstep run
/// held by its participant) waits at most that long for its first answers at the new pace.
const POLL_MIN: Duration = Duration::from_micros(20);
const POLL_MAX: Duration = Duration::from_millis(5);
/// \[s\] how long without a request before the worker starts polling less often.
const IDLE_BACKOFF: Duration = Duration::from_secs(1);
/// \[s\] the request interval below which a sleep cannot follow the requests: an eighth of it
/// is under [`POLL_MIN`]. While requests keep coming at least this often, the worker spins
/// ([`Pace::spins`]).
const SPIN_WINDOW: Duration = POLL_MIN.saturating_mul(8);
/// \[s\] how long a spinning worker looks at the slot before it yields its core once.
const SPIN_SLICE: Duration = Duration::from_micros(20);
/// \[s\] a worker that comes back to its slot this much later than it meant to (after a spin
/// or a sleep) was kept off its core by a busy thread on it, such as the stepping thread when
/// the kernel started the worker on its core (module docs): its time slices of ~4 ms leave the
/// worker a look now and then. A timer's slack is 50 µs.
const STARVED: Duration = Duration::from_micros(500);

/// The worker's polling period: an eighth of the wall time between the requests posted since its
/// last look ([`poll_period`]), kept while none arrive.
#[derive(Debug, Clone, Copy)]
struct Pace {
    /// The posted count and the time of the last look at which it had changed.
    seen: (u64, Instant),
    poll: Duration,
}

impl Pace {
    fn new(now: Instant) -> Self {
        Pace {
            seen: (0, now),
            poll: Duration::from_millis(1),
        }
    }

    /// Whether the worker should spin rather than sleep before its next look: the requests come
    /// faster than a sleep can follow ([`SPIN_WINDOW`]: the period is at its floor) and the last
    /// one came within that window. A run that pauses stops the spinning within 160 µs.
    fn spins(&self, now: Instant) -> bool {
        self.poll <= POLL_MIN && now.saturating_duration_since(self.seen.1) < SPIN_WINDOW
    }

    /// The sleep before the next look, having seen `posted` requests in all at `now`. Quick to
    /// shorten, slow to lengthen: a new rate's period is taken at once if shorter, and at most
    /// doubles the last one if longer, so a pause between bursts of requests (a batch run
    /// between other work, a lockstep run waiting a moment for its participant) does not leave
    /// the worker asleep when the next burst starts. After [`IDLE_BACKOFF`] without a request
    /// the period doubles at every look, up to [`POLL_MAX`]: a paused run costs the worker ~200
    /// wake-ups a second.
    fn next_poll(&mut self, posted: u64, now: Instant) -> Duration {
        let (before, at) = self.seen;
        let since = now.saturating_duration_since(at);
        if posted != before {
            self.poll = poll_period(since, posted.wrapping_sub(before)).min(self.poll * 2);
            self.seen = (posted, now);
        } else if since > IDLE_BACKOFF {
            self.poll = (self.poll * 2).min(POLL_MAX);
        }
        self.poll
    }
}

/// An eighth of the mean wall time between `n` requests that came within `elapsed`, within
/// [`POLL_MIN`]..=[`POLL_MAX`].
fn poll_period(elapsed: Duration, n: u64) -> Duration {
    let per_request = elapsed / u32::try_from(n).unwrap_or(u32::MAX).max(1);
    (per_request / 8).clamp(POLL_MIN, POLL_MAX)
}

/// The number of workers of this process that may spin at once: one core fewer than the
/// process may use (the stepping thread keeps one busy), none on one core.
fn spin_slots() -> usize {
    static SLOTS: OnceLock<usize> = OnceLock::new();
    *SLOTS.get_or_init(|| {
        std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .saturating_sub(1)
    })
}

/// Workers spinning now, across the process (a fleet has one worker per vehicle).
static SPINNING: AtomicUsize = AtomicUsize::new(0);

/// A worker's leave to spin: one of `slots` counted by `spinning`, given back when dropped.
struct SpinTicket(&'static AtomicUsize);

impl SpinTicket {
    fn take(spinning: &'static AtomicUsize, slots: usize) -> Option<Self> {
        spinning
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| {
                (n < slots).then_some(n + 1)
            })
            .ok()
            .map(|_| SpinTicket(spinning))
    }
}

impl Drop for SpinTicket {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::AcqRel);
    }
}

/// \[s\] after moving off a shared core, a worker that finds itself starved again within this
/// time shares every core it may use with busy threads: it stops spinning for [`SPIN_REST`].
const SPIN_RETRY: Duration = Duration::from_millis(10);
/// \[s\] how long a worker that found every core busy polls by sleeping before it spins again.
const SPIN_REST: Duration = Duration::from_millis(100);

/// Outside Linux the worker does not move (it keeps spinning where the scheduler puts it).
#[cfg(not(target_os = "linux"))]
fn leave_this_core() -> bool {
    false
}

/// The core the calling thread runs on: Linux's `getcpu` through the vDSO, a function call
/// without a system call (tens of nanoseconds). `usize::MAX` outside Linux (never equal to a
/// core, so a worker there never thinks it shares one).
#[cfg(target_os = "linux")]
#[inline]
fn current_cpu() -> usize {
    rustix::thread::sched_getcpu()
}

#[cfg(not(target_os = "linux"))]
#[inline]
fn current_cpu() -> usize {
    usize::MAX
}

/// Moves the calling thread off the core it runs on, if it may run on another: it restricts its
/// allowed cores to the others (the kernel moves it at once), then restores the set it had, so
/// the scheduler stays free to place it later (and a set the server restricted stays so).
/// Returns whether it moved.
///
/// Why: a spinning worker that shares a core with the stepping thread looks at its slot only
/// when the stepping thread's time slice ends, every few milliseconds (module docs).
#[cfg(target_os = "linux")]
fn leave_this_core() -> bool {
    let Ok(allowed) = rustix::thread::sched_getaffinity(None) else {
        return false;
    };
    let mut others = allowed;
    others.unset(rustix::thread::sched_getcpu());
    if others.count() == 0 {
        return false;
    }
    let moved = rustix::thread::sched_setaffinity(None, &others).is_ok();
    // Its own set again; it stays where it is until the scheduler has a reason to move it.
    let _ = rustix::thread::sched_setaffinity(None, &allowed);
    moved
}

/// Worker: looks at `slot` until a request is there, `slice` has passed or the worker is told to
/// stop, without a system call; then yields its core once, so that a thread waiting for it runs.
fn spin_once(slot: &Slot, slice: Duration) {
    let until = Instant::now() + slice;
    let mut looks = 0u32;
    while slot.state.load(Ordering::Acquire) != REQUESTED && !slot.stop.load(Ordering::Relaxed) {
        std::hint::spin_loop();
        looks = looks.wrapping_add(1);
        if looks.is_multiple_of(64) && Instant::now() >= until {
            break;
        }
    }
    std::thread::yield_now();
}

/// A worker's spinning: its ticket, and what it does when it finds itself starved.
#[derive(Default)]
struct Spin {
    ticket: Option<SpinTicket>,
    /// When it last moved off a core it shared.
    moved_at: Option<Instant>,
    /// Until when it polls by sleeping, having found every core it may use busy.
    rest_until: Option<Instant>,
}

impl Spin {
    /// Whether the worker may spin now (taking a ticket if it holds none).
    fn may_spin(&mut self, now: Instant) -> bool {
        if self.rest_until.is_some_and(|t| now < t) {
            return false;
        }
        if self.ticket.is_none() {
            self.ticket = SpinTicket::take(&SPINNING, spin_slots());
        }
        self.ticket.is_some()
    }

    /// Gives the ticket back.
    fn stop(&mut self) {
        self.ticket = None;
    }

    /// The spinning worker was kept off its core: it moves to another core, unless it did so
    /// less than [`SPIN_RETRY`] ago or has no other core to go to; then it rests (the cores it
    /// may use are busy). On two cores a worker starved by another thread than the stepping
    /// thread moves onto the stepping thread's core, where it is starved again at once, and
    /// rests: the stepping thread loses one of the worker's 20 µs slices, as its yields give
    /// the core back.
    fn starved(&mut self, now: Instant) {
        let moved_lately = self
            .moved_at
            .is_some_and(|t| now.saturating_duration_since(t) < SPIN_RETRY);
        if !moved_lately && leave_this_core() {
            self.moved_at = Some(now);
        } else {
            self.stop();
            self.rest_until = Some(now + SPIN_REST);
        }
    }
}

/// Whether the worker runs on the core the physics thread last posted from: spinning there, it
/// would take that core from the stepping thread for a slice, then be kept off it for the
/// stepping thread's time slice (module docs).
fn shares_physics_core(slot: &Slot) -> bool {
    let physics = slot.physics_cpu.load(Ordering::Relaxed);
    physics != usize::MAX && current_cpu() == physics
}

/// The worker thread's loop: serve a request if there is one; otherwise spin or sleep until the
/// next look ([`Pace`], [`Spin`]).
fn work(slot: &Slot, fill: &impl Fn(&Request, &mut EnvironmentSample)) {
    let mut pace = Pace::new(Instant::now());
    let mut spin = Spin::default();
    // When the worker last looked at the slot, and how long it meant to be away after that.
    let mut looked = (Instant::now(), Duration::ZERO);
    while !slot.stop.load(Ordering::Acquire) {
        // Spinning (it holds a ticket) and back much later than it meant: starved on a shared
        // core. A sleeping worker's lateness does not matter to anyone.
        let now = Instant::now();
        if spin.ticket.is_some() && now.saturating_duration_since(looked.0) > looked.1 + STARVED {
            spin.starved(now);
        }
        if slot.serve(fill) {
            looked = (Instant::now(), Duration::ZERO);
            continue;
        }
        let now = Instant::now();
        let poll = pace.next_poll(slot.posted.load(Ordering::Relaxed), now);
        let spin_now = pace.spins(now) && spin.may_spin(now) && {
            if shares_physics_core(slot) {
                // Found on the stepping thread's core before the starvation shows: move now
                // (or, having moved lately, rest: then it sleeps, not spins, from this look on).
                spin.starved(now);
            }
            spin.ticket.is_some()
        };
        let away = if spin_now {
            spin_once(slot, SPIN_SLICE);
            SPIN_SLICE
        } else {
            spin.stop();
            std::thread::park_timeout(poll);
            poll
        };
        looked = (now, away);
    }
}

/// A worker thread that evaluates the next environment sample ahead of time (module docs).
/// Dropping it stops and joins the thread.
pub struct Prefetcher {
    slot: Arc<Slot>,
    thread: Thread,
    handle: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for Prefetcher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Prefetcher")
            .field("thread", &self.thread.name())
            .finish_non_exhaustive()
    }
}

impl Prefetcher {
    /// Starts the worker thread `flexdyn-environment`, which evaluates requests with `fill`.
    pub fn spawn(
        fill: impl Fn(&Request, &mut EnvironmentSample) + Send + 'static,
    ) -> std::io::Result<Self> {
        let slot = Arc::new(Slot::new());
        let worker_slot = slot.clone();
        let handle = std::thread::Builder::new()
            .name("flexdyn-environment".into())
            .spawn(move || {
                work(&worker_slot, &fill);
            })?;
        Ok(Self {
            slot,
            thread: handle.thread().clone(),
            handle: Some(handle),
        })
    }

    /// Hands `req` to the worker (physics thread; no allocation, no lock, no system call:
    /// atomics only; the worker polls, see the module docs).
    #[inline]
    pub fn post(&self, req: &Request) {
        self.slot
            .physics_cpu
            .store(current_cpu(), Ordering::Relaxed);
        self.slot.post(req);
        self.slot.posted.fetch_add(1, Ordering::Relaxed);
    }

    /// The worker's answer to `req`, if it is ready (physics thread; `None`: evaluate it here).
    #[inline]
    pub fn answer(&self, req: &Request) -> Option<EnvironmentSample> {
        let a = self.slot.answer(req);
        if a.is_some() {
            self.slot.taken.fetch_add(1, Ordering::Relaxed);
        }
        a
    }

    /// Whether an answer is waiting to be taken (it may still be stale: [`Self::answer`]
    /// checks it against the request).
    pub fn answer_ready(&self) -> bool {
        self.slot.state.load(Ordering::Acquire) == DONE
    }

    /// How many answers [`Self::answer`] has returned (the rest were evaluated by the caller).
    pub fn answers_taken(&self) -> u64 {
        self.slot.taken.load(Ordering::Relaxed)
    }
}

impl Drop for Prefetcher {
    fn drop(&mut self) {
        self.slot.stop.store(true, Ordering::Release);
        self.thread.unpark();
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic stand-in for the models: every field a function of the request.
    fn fill(req: &Request, out: &mut EnvironmentSample) {
        *out = EnvironmentSample::NONE;
        out.t_sim_ns = req.t_sim_ns;
        out.b_field_n_t = req.r_bn_n_m * 1e-12;
        out.density_kg_m3 = req.v_bn_n_m_s.norm() * 1e-15;
        out.shadow_factor = 0.5;
        // An albedo cap, so that the slot's words carry one too.
        let albedo = crate::albedo::Albedo {
            coefficient: 0.3,
            earth_radius_m: 6.378e6,
            irradiance_1au_w_m2: 1361.0,
        };
        out.albedo = albedo.cap(&req.r_bn_n_m, &Vector3::new(1.5e11, 2.0e10, 0.0));
    }

    fn request(t: u64) -> Request {
        Request {
            t_sim_ns: t,
            r_bn_n_m: Vector3::new(7.0e6, 1.0, 2.0),
            v_bn_n_m_s: Vector3::new(3.0, 7.5e3, 4.0),
        }
    }

    fn direct(req: &Request) -> EnvironmentSample {
        let mut s = EnvironmentSample::NONE;
        fill(req, &mut s);
        s
    }

    /// A worker compares its core with the one the physics thread last posted from (which
    /// `post` records): that core is shared; an unknown one, or another, is not. The test
    /// thread is held on its core meanwhile, so that the cores it reads agree.
    #[cfg(target_os = "linux")]
    #[test]
    fn the_core_the_physics_thread_posts_from_is_the_one_a_worker_must_leave() {
        let allowed = rustix::thread::sched_getaffinity(None).expect("affinity");
        let mut here = rustix::thread::CpuSet::new();
        here.set(current_cpu());
        rustix::thread::sched_setaffinity(None, &here).expect("pin the test thread");
        let prefetcher = Prefetcher::spawn(fill).expect("worker");
        let slot = &prefetcher.slot;
        let unknown = shares_physics_core(slot);
        prefetcher.post(&request(10));
        let posted_from = slot.physics_cpu.load(Ordering::Relaxed);
        let same = shares_physics_core(slot);
        slot.physics_cpu.store(current_cpu() + 1, Ordering::Relaxed);
        let other = shares_physics_core(slot);
        let core = current_cpu();
        let _ = rustix::thread::sched_setaffinity(None, &allowed);
        assert!(!unknown, "no post yet: no core to leave");
        assert_eq!(posted_from, core, "post records the posting core");
        assert!(same, "the posting core is shared");
        assert!(!other, "another core is not");
    }

    #[test]
    fn a_served_request_is_answered_with_exactly_what_the_physics_thread_would_compute() {
        let slot = Slot::new();
        let req = request(100);
        assert!(slot.post(&req));
        assert!(slot.serve(&fill));
        assert_eq!(slot.answer(&req), Some(direct(&req)));
        // Read twice (telemetry, then the update): the same answer.
        assert_eq!(slot.answer(&req), Some(direct(&req)));
    }

    /// The cap's words travel only with a cap: an answer without one after an answer with one
    /// reads no cap (the stale words behind the head are not read).
    #[test]
    fn a_sample_without_a_cap_after_one_with_a_cap_has_none() {
        // Posted, served by `f` and picked up.
        let round = |slot: &Slot, req: &Request, f: &dyn Fn(&Request, &mut EnvironmentSample)| {
            assert!(slot.post(req) && slot.serve(&f));
            slot.answer(req).expect("the worker's answer")
        };
        let slot = Slot::new();
        let with_cap = request(100);
        let answer = round(&slot, &with_cap, &fill);
        assert!(answer.albedo.is_some());
        assert_eq!(answer, direct(&with_cap));
        let without = request(200);
        let no_cap = |req: &Request, out: &mut EnvironmentSample| {
            fill(req, out);
            out.albedo = None;
        };
        let answer = round(&slot, &without, &no_cap);
        assert_eq!(answer.albedo, None);
        assert_eq!(answer.b_field_n_t, direct(&without).b_field_n_t);
    }

    #[test]
    fn an_answer_to_another_request_is_never_taken() {
        let slot = Slot::new();
        assert!(slot.post(&request(100)));
        assert!(slot.serve(&fill));
        assert_eq!(slot.answer(&request(200)), None);
        let mut moved = request(100);
        moved.r_bn_n_m.x += 1e-9;
        assert_eq!(slot.answer(&moved), None);
    }

    #[test]
    fn an_unclaimed_request_is_withdrawn_and_never_served() {
        let slot = Slot::new();
        let req = request(100);
        assert!(slot.post(&req));
        assert_eq!(slot.answer(&req), None, "not served yet: evaluate here");
        assert!(!slot.serve(&fill), "withdrawn");
        // The next request goes out normally.
        assert!(slot.post(&request(200)));
        assert!(slot.serve(&fill));
        assert_eq!(slot.answer(&request(200)), Some(direct(&request(200))));
    }

    #[test]
    fn a_busy_worker_is_not_given_a_new_request() {
        let slot = Slot::new();
        assert!(slot.post(&request(100)));
        slot.state.store(WORKING, Ordering::Release); // claimed, still evaluating
        assert!(!slot.post(&request(200)));
        assert_eq!(slot.answer(&request(200)), None);
    }

    #[test]
    fn the_prediction_follows_a_circular_orbit_to_its_truncation_error() {
        // A circular orbit of radius r: x = r cos(n t), y = r sin(n t); n = sqrt(μ/r³).
        let r = 6_878_137.0;
        let n = (MU_EARTH_M3_S2 / (r * r * r)).sqrt();
        let dt_s = 0.1;
        let req = Request::predicted(
            0,
            &Vector3::new(r, 0.0, 0.0),
            &Vector3::new(0.0, r * n, 0.0),
            100_000_000,
        );
        let truth = Vector3::new(r * (n * dt_s).cos(), r * (n * dt_s).sin(), 0.0);
        // The first neglected term, r·(n·Δ)⁴/24, is 5e-11 m; allow the rounding of r (1e-9 m).
        let bound = r * (n * dt_s).powi(4) / 24.0 + 1e-8;
        assert!(bound < 1e-7);
        assert!(
            (req.r_bn_n_m - truth).norm() <= bound,
            "{} m",
            (req.r_bn_n_m - truth).norm()
        );
        // The third-order term matters: without it the error is r (nΔ)³/6, 1e-6 m.
        let second = r * (n * dt_s).powi(3) / 6.0;
        assert!(second > 10.0 * bound);
    }

    #[test]
    fn the_worker_polls_at_an_eighth_of_the_request_interval_within_bounds() {
        let ms = Duration::from_millis;
        // 100 ms between requests (10 Hz updates in real time): capped at 5 ms.
        assert_eq!(poll_period(ms(200), 2), POLL_MAX);
        // 1.6 ms between requests: 200 µs.
        assert_eq!(poll_period(ms(16), 10), Duration::from_micros(200));
        // 80 µs between requests (a batch run): 10 µs, raised to 20 µs.
        assert_eq!(poll_period(Duration::from_micros(800), 10), POLL_MIN);
        // The pace: 1 ms at first; a faster rate is followed at once, a slower one at most
        // doubles the period per look; idle for over 1 s, it doubles per look up to 5 ms.
        let us = Duration::from_micros;
        let t0 = Instant::now();
        let mut pace = Pace::new(t0);
        assert_eq!(pace.next_poll(0, t0 + ms(10)), ms(1));
        // 4 requests since t0, 13.2 ms ago: 3.3 ms each, an eighth is 412.5 µs.
        assert_eq!(
            pace.next_poll(4, t0 + us(13_200)),
            us(412) + Duration::from_nanos(500)
        );
        // 8 in the next 800 µs: 100 µs each, 20 µs at once.
        assert_eq!(pace.next_poll(12, t0 + us(14_000)), POLL_MIN);
        // One after a 100 ms gap: an eighth would be 12.5 ms; at most 40 µs now.
        assert_eq!(pace.next_poll(13, t0 + us(114_000)), us(40));
        // Quiet for 1 s: kept; then doubled per look.
        assert_eq!(pace.next_poll(13, t0 + us(1_114_000)), us(40));
        assert_eq!(pace.next_poll(13, t0 + us(1_114_001)), us(80));
        let looks: Vec<Duration> = (2..8)
            .map(|k| pace.next_poll(13, t0 + us(1_114_000 + k)))
            .collect();
        assert_eq!(
            looks,
            [us(160), us(320), us(640), us(1280), us(2560), POLL_MAX]
        );
    }

    #[test]
    fn the_worker_spins_only_while_requests_come_faster_than_a_sleep_can_follow() {
        let us = Duration::from_micros;
        let t0 = Instant::now();
        let mut pace = Pace::new(t0);
        // Requests 40 µs apart (acs_full.toml's 10 steps of ~4 µs): the period is at its floor,
        // and the worker spins until 160 µs after the last one.
        let mut t = t0;
        for k in 1..=5 {
            t = t0 + us(40 * k);
            pace.next_poll(k, t);
        }
        assert!(pace.spins(t));
        assert!(pace.spins(t + us(159)));
        assert!(!pace.spins(t + us(160)), "a paused run stops the spinning");
        // Requests 170 µs apart: an eighth is above the floor; the worker sleeps.
        let mut pace = Pace::new(t0);
        for k in 1..=5 {
            t = t0 + us(170 * k);
            pace.next_poll(k, t);
        }
        assert_eq!(pace.poll, us(21) + Duration::from_nanos(250));
        assert!(!pace.spins(t));
        // One request after a 100 ms gap, fast again: the period at most doubles from the
        // floor, so the worker does not spin until a second fast request brings it back.
        let mut pace = Pace::new(t0);
        pace.next_poll(1, t0 + us(40));
        pace.next_poll(2, t0 + us(80));
        assert!(pace.spins(t0 + us(80)));
        pace.next_poll(3, t0 + us(100_080));
        assert!(!pace.spins(t0 + us(100_080)));
        pace.next_poll(4, t0 + us(100_120));
        assert!(pace.spins(t0 + us(100_120)));
    }

    #[test]
    fn no_more_workers_spin_than_there_are_tickets() {
        static SPINNING_HERE: AtomicUsize = AtomicUsize::new(0);
        let a = SpinTicket::take(&SPINNING_HERE, 2).expect("the first of two");
        let b = SpinTicket::take(&SPINNING_HERE, 2).expect("the second of two");
        assert!(
            SpinTicket::take(&SPINNING_HERE, 2).is_none(),
            "a third of two"
        );
        drop(a);
        let c = SpinTicket::take(&SPINNING_HERE, 2).expect("a ticket given back");
        drop((b, c));
        assert_eq!(SPINNING_HERE.load(Ordering::Acquire), 0);
        // One core: nobody spins.
        assert!(SpinTicket::take(&SPINNING_HERE, 0).is_none());
    }

    #[test]
    fn a_spinning_worker_stops_looking_when_a_request_comes_or_its_slice_ends() {
        let slot = Slot::new();
        // Nothing requested: back after its slice.
        let t0 = Instant::now();
        spin_once(&slot, Duration::from_millis(2));
        assert!(t0.elapsed() >= Duration::from_millis(2));
        // A request waiting: back at once (well before a 10 s slice).
        assert!(slot.post(&request(7)));
        let t0 = Instant::now();
        spin_once(&slot, Duration::from_secs(10));
        assert!(t0.elapsed() < Duration::from_secs(5));
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn a_starved_worker_moves_once_then_rests_if_starved_again_soon() {
        // Moving needs a second core; on one, a starved worker rests at once.
        let cores = rustix::thread::sched_getaffinity(None).unwrap().count();
        let t0 = Instant::now();
        let mut spin = Spin::default();
        spin.starved(t0);
        if cores < 2 {
            assert_eq!(
                (spin.moved_at, spin.rest_until),
                (None, Some(t0 + SPIN_REST))
            );
            return;
        }
        assert_eq!(spin.moved_at, Some(t0), "the first time it moves");
        assert_eq!(spin.rest_until, None);
        // Starved again 11 ms later: the move helped for a while; it moves again.
        let t1 = t0 + Duration::from_millis(11);
        spin.starved(t1);
        assert_eq!((spin.moved_at, spin.rest_until), (Some(t1), None));
        // Again within 10 ms of that move: every core is busy; it rests for 100 ms.
        let t2 = t1 + Duration::from_millis(3);
        spin.starved(t2);
        assert_eq!(spin.rest_until, Some(t2 + SPIN_REST));
        assert!(spin.ticket.is_none());
        assert!(!spin.may_spin(t2 + Duration::from_millis(99)));
        assert!(spin.ticket.is_none(), "no ticket is taken while resting");
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn leaving_this_core_moves_the_thread_and_gives_back_its_cores() {
        let allowed = rustix::thread::sched_getaffinity(None).unwrap();
        let moved = leave_this_core();
        let after = rustix::thread::sched_getaffinity(None).unwrap();
        assert!(
            (0..rustix::thread::CpuSet::MAX_CPU).all(|c| after.is_set(c) == allowed.is_set(c)),
            "the allowed cores are given back"
        );
        // A thread may always restrict its own cores (no privilege needed), so with two it
        // moves; where it runs afterwards is the scheduler's to change, so it is not checked.
        assert_eq!(moved, allowed.count() >= 2);
    }

    #[test]
    fn the_worker_thread_answers_and_stops_when_dropped() {
        let p = Prefetcher::spawn(fill).unwrap();
        let req = request(5);
        p.post(&req);
        let t0 = std::time::Instant::now();
        let mut got = None;
        while got.is_none() && t0.elapsed() < std::time::Duration::from_secs(10) {
            got = p.answer(&req);
            // `answer` withdraws a request the worker has not claimed yet; post it again.
            if got.is_none() {
                p.post(&req);
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
        }
        assert_eq!(got, Some(direct(&req)));
        drop(p); // joins: the test would hang here if the worker ignored the stop
    }
}
