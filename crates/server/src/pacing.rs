//! Real-time frame pacing against absolute deadlines.
//!
//! Frame boundary `k` is due at `t0 + k·period` (the "`start += dt`" pattern): lateness never
//! accumulates, because each deadline is computed from `t0`, not from the previous wake-up. The
//! loop sleeps (`std::thread::sleep`) until `spin` before the deadline, then spins on
//! [`Instant::now`], because the OS (and tokio's millisecond timer) wakes up too late for a
//! 1 kHz frame. See [`OverrunPolicy`] for what happens when a frame overruns.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use super::settings::OverrunPolicy;

/// Longest single sleep, so a stop request is seen quickly even with slow frames.
const MAX_SLEEP: Duration = Duration::from_millis(50);

/// Sleeps until `spin` before `deadline`, then spins until it. Returns early (false) if `stop`
/// is set; true once the deadline has passed.
pub fn wait_until(deadline: Instant, spin: Duration, stop: &AtomicBool) -> bool {
    loop {
        let now = Instant::now();
        if now >= deadline {
            return true;
        }
        if stop.load(Ordering::Relaxed) {
            return false;
        }
        let remaining = deadline - now;
        if remaining > spin {
            std::thread::sleep((remaining - spin).min(MAX_SLEEP));
        } else {
            std::hint::spin_loop();
        }
    }
}

/// Whole periods to drop when a boundary is reached `late_ns` late under the `skip` policy: the
/// number of deadlines entirely missed (0 if less than one period late).
pub fn periods_to_skip(late_ns: u64, period_ns: u64) -> u64 {
    late_ns / period_ns
}

/// The outcome of [`Pacer::end_frame`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameEnd {
    /// The frame's work finished before the next deadline.
    OnTime,
    /// It finished after the next deadline (counted as an overrun).
    Overrun,
    /// `abort` policy: more than `limit` consecutive overruns.
    Abort {
        /// Consecutive overruns so far.
        consecutive: u32,
    },
}

/// Absolute-deadline schedule of the real-time loop.
#[derive(Debug)]
pub struct Pacer {
    t0: Instant,
    /// The boundary due at `t0` (a resumed run's first tick; else 0).
    first_tick: u64,
    period_ns: u64,
    spin: Duration,
    policy: OverrunPolicy,
    limit: u32,
    consecutive: u32,
    /// Total overrun frames.
    pub overruns: u64,
    /// Total deadlines dropped by the `skip` policy.
    pub skipped: u64,
}

impl Pacer {
    /// A schedule whose boundary 0 is due at `t0`.
    pub fn new(
        t0: Instant,
        period_ns: u64,
        spin: Duration,
        policy: OverrunPolicy,
        limit: u32,
    ) -> Self {
        Self {
            t0,
            first_tick: 0,
            period_ns,
            spin,
            policy,
            limit,
            consecutive: 0,
            overruns: 0,
            skipped: 0,
        }
    }

    /// The same schedule with boundary `k` (a resumed run's first) due at `t0` instead of 0.
    pub fn first_tick(mut self, k: u64) -> Self {
        self.first_tick = k;
        self
    }

    /// When boundary `k` is due.
    pub fn deadline(&self, k: u64) -> Instant {
        let frames = k.saturating_sub(self.first_tick);
        self.t0 + Duration::from_nanos(frames.saturating_mul(self.period_ns))
    }

    /// Waits for boundary `k` and returns its lateness in ns (0 if the wait ended exactly on
    /// time), or `None` if `stop` was set. Under `skip`, whole periods already missed are
    /// dropped first.
    pub fn wait_boundary(&mut self, k: u64, stop: &AtomicBool) -> Option<u64> {
        if self.policy == OverrunPolicy::Skip {
            let now = Instant::now();
            let due = self.deadline(k);
            if now > due {
                let late_ns = u64::try_from((now - due).as_nanos()).unwrap_or(u64::MAX);
                let n = periods_to_skip(late_ns, self.period_ns);
                if n > 0 {
                    self.t0 += Duration::from_nanos(n.saturating_mul(self.period_ns));
                    self.skipped += n;
                }
            }
        }
        let due = self.deadline(k);
        if !wait_until(due, self.spin, stop) {
            return None;
        }
        let late = Instant::now().saturating_duration_since(due);
        Some(u64::try_from(late.as_nanos()).unwrap_or(u64::MAX))
    }

    /// After a hold at boundary `k` that ends now: moves the schedule so that boundary `k + 1`
    /// is due one period from now (the frames missed while held are not caught up).
    pub fn resume_after(&mut self, k: u64) {
        let now = Instant::now();
        let due = self.deadline(k);
        if now > due {
            self.t0 += now - due;
        }
    }

    /// Called when the work toward boundary `k` (commands, integration, telemetry fill) is
    /// done: an overrun if boundary `k` is already past.
    pub fn end_frame(&mut self, k: u64) -> FrameEnd {
        if Instant::now() <= self.deadline(k) {
            self.consecutive = 0;
            return FrameEnd::OnTime;
        }
        self.overruns += 1;
        self.consecutive = self.consecutive.saturating_add(1);
        if self.policy == OverrunPolicy::Abort && self.consecutive > self.limit {
            return FrameEnd::Abort {
                consecutive: self.consecutive,
            };
        }
        FrameEnd::Overrun
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_resumed_schedule_is_due_from_its_first_tick() {
        let t0 = Instant::now();
        let p =
            Pacer::new(t0, 1_000_000, Duration::ZERO, OverrunPolicy::CatchUp, 10).first_tick(500);
        // Boundary 500 is due at t0 (not 0.5 s later), 503 three periods after.
        assert_eq!(p.deadline(500), t0);
        assert_eq!(p.deadline(503), t0 + Duration::from_millis(3));
    }

    #[test]
    fn skip_counts_whole_missed_periods() {
        assert_eq!(periods_to_skip(0, 1000), 0);
        assert_eq!(periods_to_skip(999, 1000), 0);
        assert_eq!(periods_to_skip(1000, 1000), 1);
        assert_eq!(periods_to_skip(3500, 1000), 3);
    }

    #[test]
    fn deadlines_are_absolute() {
        let t0 = Instant::now();
        let p = Pacer::new(t0, 1_000_000, Duration::ZERO, OverrunPolicy::CatchUp, 0);
        assert_eq!(p.deadline(0), t0);
        assert_eq!(p.deadline(1000), t0 + Duration::from_secs(1));
    }

    #[test]
    fn waits_and_counts_overruns() {
        let stop = AtomicBool::new(false);
        let period_ns = 2_000_000;
        let t0 = Instant::now();
        let mut p = Pacer::new(
            t0,
            period_ns,
            Duration::from_micros(200),
            OverrunPolicy::Abort,
            1,
        );
        let late = p.wait_boundary(1, &stop).unwrap();
        assert!(Instant::now() >= t0 + Duration::from_nanos(period_ns));
        assert!(late < 1_000_000_000);
        // Pretend the work for boundary 2 took three periods.
        std::thread::sleep(Duration::from_nanos(3 * period_ns));
        assert_eq!(p.end_frame(2), FrameEnd::Overrun);
        assert_eq!(p.end_frame(2), FrameEnd::Abort { consecutive: 2 });
        assert_eq!(p.overruns, 2);
        // A stop request ends a wait early.
        stop.store(true, Ordering::Relaxed);
        assert_eq!(p.wait_boundary(1_000_000, &stop), None);
    }

    #[test]
    fn a_resume_re_anchors_the_schedule() {
        let period_ns = 1_000_000;
        let t0 = Instant::now();
        let mut p = Pacer::new(t0, period_ns, Duration::ZERO, OverrunPolicy::CatchUp, 0);
        // Held at boundary 2 for 20 periods.
        std::thread::sleep(Duration::from_millis(22));
        let before = Instant::now();
        p.resume_after(2);
        let after = Instant::now();
        let next = p.deadline(3);
        assert!(next >= before + Duration::from_nanos(period_ns), "{next:?}");
        assert!(next <= after + Duration::from_nanos(period_ns), "{next:?}");
        // Boundary 2 itself is now "now": not late.
        assert!(p.deadline(2) >= before && p.deadline(2) <= after);
        // Released before the deadline: the schedule stays.
        let mut q = Pacer::new(
            after + Duration::from_secs(1),
            period_ns,
            Duration::ZERO,
            OverrunPolicy::CatchUp,
            0,
        );
        let d = q.deadline(5);
        q.resume_after(0);
        assert_eq!(q.deadline(5), d);
    }

    #[test]
    fn skip_moves_the_schedule() {
        let stop = AtomicBool::new(false);
        let period_ns = 1_000_000;
        let t0 = Instant::now();
        let mut p = Pacer::new(
            t0,
            period_ns,
            Duration::from_micros(100),
            OverrunPolicy::Skip,
            0,
        );
        std::thread::sleep(Duration::from_millis(5));
        let late = p.wait_boundary(1, &stop).unwrap();
        assert!(p.skipped >= 3, "skipped {}", p.skipped);
        assert!(late < 2 * period_ns, "late {late}");
    }
}
