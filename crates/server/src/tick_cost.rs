//! Where a lockstep or batch run's ticks went: the mean time per tick spent stepping, publishing
//! and waiting for the answers, the distribution of the tick period, and the tick rate once the
//! run has settled. The run report prints it (`ticks_us …`).
//!
//! The tick period is measured from one tick's publication to the next's, so in lockstep it is
//! the whole round trip: the states going out, the flight code answering, the frame stepped.
//!
//! **Why a settled rate.** The first ticks of a run are slower than the rest. On this project's
//! 2-vCPU VM, a Zenoh ping-pong that starts after 400 ms idle takes 101–105 µs per round trip
//! over its first 1000 and 85–88 µs after (the lockstep bench's ping-pong, run on 2026-12-01
//! with a sleep before its first ping); a lockstep run starts after its participants' start-up,
//! which is such an idle spell, and showed the same shape (first 1000 ticks 97–114 µs, then
//! 88–95 µs). [`TickSummary::settled_ticks_per_s`] leaves the first [`SETTLE_TICKS`] out, as
//! the ping-pong it is compared with leaves out its first 1000 round trips.
//!
//! Recording a tick costs two clock reads' worth of work and one histogram increment: no
//! allocation (the histogram's bounds are fixed at construction), no lock, no system call.

use std::time::Instant;

use hdrhistogram::Histogram;

/// Ticks left out of [`TickSummary::settled_ticks_per_s`] at the start of a run.
pub const SETTLE_TICKS: u64 = 1000;

/// Longest tick period the histogram resolves (longer ones are clamped): 1 hour in ns.
const PERIOD_MAX_NS: u64 = 3_600_000_000_000;

/// Where the stepping thread's time went (wall-clock ns), and when the ticks went out.
#[derive(Clone, Debug)]
pub struct TickCost {
    /// Frames stepped.
    pub frames: u64,
    /// \[ns\] stepping and filling the frames (every vehicle), without the waits and the
    /// hand-outs.
    pub physics_ns: u64,
    /// \[ns\] handing out the frames at the boundaries (the puts, when this thread publishes).
    pub publish_ns: u64,
    /// \[ns\] waiting for the commands (lockstep: the barrier).
    pub wait_ns: u64,
    /// \[ns\] the period from each tick's publication to the next's.
    periods: Histogram<u64>,
    /// The first tick published and when.
    first: Option<(u64, Instant)>,
    /// The tick [`SETTLE_TICKS`] after the first, and when it was published.
    settled: Option<(u64, Instant)>,
    /// The last tick published and when.
    last: Option<(u64, Instant)>,
}

impl Default for TickCost {
    fn default() -> Self {
        Self {
            frames: 0,
            physics_ns: 0,
            publish_ns: 0,
            wait_ns: 0,
            periods: Histogram::new_with_bounds(1, PERIOD_MAX_NS, 3)
                .expect("constant histogram bounds are valid"),
            first: None,
            settled: None,
            last: None,
        }
    }
}

/// A summary of a [`TickCost`] for the run report (per-tick means and periods in µs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickSummary {
    /// Frames stepped.
    pub frames: u64,
    /// \[µs\] mean time per frame stepping and filling.
    pub physics_us: f64,
    /// \[µs\] mean time per frame publishing.
    pub publish_us: f64,
    /// \[µs\] mean time per frame waiting for the answers.
    pub wait_us: f64,
    /// \[µs\] median tick period.
    pub period_p50_us: f64,
    /// \[µs\] 99th percentile of the tick period.
    pub period_p99_us: f64,
    /// \[µs\] longest tick period.
    pub period_max_us: f64,
    /// Ticks per second from the tick [`SETTLE_TICKS`] after the first to the last (`None`
    /// for a run too short to have one after it).
    pub settled_ticks_per_s: Option<f64>,
}

impl TickCost {
    /// Notes that tick `k`'s states started going out at `at`.
    #[inline]
    pub fn published(&mut self, k: u64, at: Instant) {
        if let Some((_, before)) = self.last {
            let ns =
                u64::try_from(at.saturating_duration_since(before).as_nanos()).unwrap_or(u64::MAX);
            self.periods.saturating_record(ns.max(1));
        }
        match self.first {
            None => self.first = Some((k, at)),
            Some((k0, _)) if k == k0 + SETTLE_TICKS => self.settled = Some((k, at)),
            Some(_) => {}
        }
        self.last = Some((k, at));
    }

    /// The summary, `None` before a frame was stepped.
    pub fn summary(&self) -> Option<TickSummary> {
        if self.frames == 0 {
            return None;
        }
        let per_frame = |ns: u64| ns as f64 * 1e-3 / self.frames as f64;
        let us = |ns: u64| ns as f64 * 1e-3;
        let (p50, p99, max) = if self.periods.is_empty() {
            (0, 0, 0)
        } else {
            (
                self.periods.value_at_quantile(0.5),
                self.periods.value_at_quantile(0.99),
                self.periods.max(),
            )
        };
        let settled_ticks_per_s = match (self.settled, self.last) {
            (Some((k0, t0)), Some((k1, t1))) if k1 > k0 => {
                let s = t1.saturating_duration_since(t0).as_secs_f64();
                (s > 0.0).then(|| (k1 - k0) as f64 / s)
            }
            _ => None,
        };
        Some(TickSummary {
            frames: self.frames,
            physics_us: per_frame(self.physics_ns),
            publish_us: per_frame(self.publish_ns),
            wait_us: per_frame(self.wait_ns),
            period_p50_us: us(p50),
            period_p99_us: us(p99),
            period_max_us: us(max),
            settled_ticks_per_s,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// Ticks published at known instants: the slow first ticks are out of the settled rate,
    /// and the periods' percentiles are the intervals given.
    #[test]
    fn the_settled_rate_leaves_the_first_ticks_out() {
        let t0 = Instant::now();
        let mut c = TickCost::default();
        let mut at = t0;
        // SETTLE_TICKS ticks 200 µs apart, then 3000 ticks 100 µs apart.
        for k in 0..=SETTLE_TICKS + 3000 {
            c.published(k, at);
            at += Duration::from_micros(if k < SETTLE_TICKS { 200 } else { 100 });
        }
        c.frames = SETTLE_TICKS + 3000;
        let s = c.summary().unwrap();
        // From tick SETTLE_TICKS to SETTLE_TICKS + 3000: 3000 periods of 100 µs.
        let rate = s.settled_ticks_per_s.unwrap();
        assert!((rate - 10_000.0).abs() < 1e-6, "{rate}");
        // 1000 periods of 200 µs and 3000 of 100 µs: the median is 100 µs, p99 200 µs (3
        // significant digits).
        assert!((s.period_p50_us - 100.0).abs() < 0.1, "{}", s.period_p50_us);
        assert!((s.period_p99_us - 200.0).abs() < 0.2, "{}", s.period_p99_us);
        assert!((s.period_max_us - 200.0).abs() < 0.2, "{}", s.period_max_us);
    }

    /// A run shorter than the settling has no settled rate; one without frames no summary.
    #[test]
    fn short_runs_have_no_settled_rate() {
        let mut c = TickCost::default();
        assert!(c.summary().is_none());
        let t0 = Instant::now();
        for k in 0..SETTLE_TICKS {
            c.published(k, t0 + Duration::from_micros(k));
        }
        c.frames = SETTLE_TICKS - 1;
        assert_eq!(c.summary().unwrap().settled_ticks_per_s, None);
    }

    /// The means are per frame stepped.
    #[test]
    fn means_are_per_frame() {
        let mut c = TickCost {
            frames: 4,
            physics_ns: 8_000,
            publish_ns: 4_000,
            wait_ns: 400_000,
            ..TickCost::default()
        };
        c.published(0, Instant::now());
        let s = c.summary().unwrap();
        assert_eq!((s.physics_us, s.publish_us, s.wait_us), (2.0, 1.0, 100.0));
    }
}
