//! Where a lockstep or batch run's ticks went: the mean time per tick spent stepping, publishing
//! and waiting for the answers, the distribution of the tick period, and the tick rate once the
//! run has settled. The run report prints it (`ticks_us …`).
//!
//! The tick period is measured from one tick's publication to the next's, so in lockstep it is
//! the whole round trip: the states going out, the flight code answering, the frame stepped. A
//! tick the operator held counts from its release ([`TickCost::released`]): neither the period
//! nor the settled rate holds the pause.
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

use super::telemetry::{ns_histogram, p50_p99_max};

/// Ticks left out of [`TickSummary::settled_ticks_per_s`] at the start of a run.
pub const SETTLE_TICKS: u64 = 1000;

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
    /// \[ns\] the period from each tick's publication (or its release from a hold) to the
    /// next's.
    periods: Histogram<u64>,
    /// \[ns\] time spent held by the operator since the settled tick.
    held_since_settled_ns: u64,
    /// The first tick published and when.
    first: Option<(u64, Instant)>,
    /// The tick [`SETTLE_TICKS`] after the first, and when it was published.
    settled: Option<(u64, Instant)>,
    /// The last tick published and when (or when it was released from a hold).
    last: Option<(u64, Instant)>,
}

impl Default for TickCost {
    fn default() -> Self {
        Self {
            frames: 0,
            physics_ns: 0,
            publish_ns: 0,
            wait_ns: 0,
            periods: ns_histogram(),
            held_since_settled_ns: 0,
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
    /// Ticks per second from the tick [`SETTLE_TICKS`] after the first to the last, without
    /// the operator's holds (`None` for a run too short to have one after it).
    pub settled_ticks_per_s: Option<f64>,
}

impl std::fmt::Display for TickSummary {
    /// ` ticks_us physics=… publish=… wait=… period_p50=… period_p99=… period_max=…`, then
    /// ` settled_ticks_per_s=…` when there is one: the run report's tail.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            " ticks_us physics={:.1} publish={:.1} wait={:.1} period_p50={:.1} period_p99={:.1} \
             period_max={:.1}",
            self.physics_us,
            self.publish_us,
            self.wait_us,
            self.period_p50_us,
            self.period_p99_us,
            self.period_max_us
        )?;
        if let Some(r) = self.settled_ticks_per_s {
            write!(f, " settled_ticks_per_s={r:.0}")?;
        }
        Ok(())
    }
}

impl TickCost {
    /// Notes that tick `k`'s states started going out at `at`.
    #[inline]
    pub fn published(&mut self, k: u64, at: Instant) {
        if let Some((_, before)) = self.last {
            self.periods
                .saturating_record(ns_between(before, at).max(1));
        }
        match self.first {
            None => self.first = Some((k, at)),
            Some((k0, _)) if k == k0 + SETTLE_TICKS => self.settled = Some((k, at)),
            Some(_) => {}
        }
        self.last = Some((k, at));
    }

    /// Notes that the tick last published was released from an operator's hold at `at`: the
    /// next period starts here, and the held time stays out of the settled rate.
    #[inline]
    pub fn released(&mut self, at: Instant) {
        if let Some((k, since)) = self.last {
            if self.settled.is_some() {
                self.held_since_settled_ns = self
                    .held_since_settled_ns
                    .saturating_add(ns_between(since, at));
            }
            self.last = Some((k, at));
        }
    }

    /// The summary, `None` before a tick was published and a frame stepped (so always in real
    /// time, whose loop notes no ticks).
    pub fn summary(&self) -> Option<TickSummary> {
        if self.frames == 0 || self.first.is_none() {
            return None;
        }
        let per_frame = |ns: u64| ns as f64 * 1e-3 / self.frames as f64;
        let us = |ns: u64| ns as f64 * 1e-3;
        let (p50, p99, max) = p50_p99_max(&self.periods);
        let settled_ticks_per_s = match (self.settled, self.last) {
            (Some((k0, t0)), Some((k1, t1))) if k1 > k0 => {
                // Every hold from the settled tick on lies within t1 - t0 (t1 is the last
                // publication or release, at or after each of those releases).
                let span = t1.saturating_duration_since(t0);
                let held = std::time::Duration::from_nanos(self.held_since_settled_ns);
                let s = span.saturating_sub(held).as_secs_f64();
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

/// \[ns\] from `a` to `b` (0 if `b` is earlier, `u64::MAX` past 584 years).
#[inline]
pub fn ns_between(a: Instant, b: Instant) -> u64 {
    u64::try_from(b.saturating_duration_since(a).as_nanos()).unwrap_or(u64::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// Publishes ticks `0..=last` at `t0` plus the running sum of `period_us(k)` (the period
    /// after tick `k`).
    fn publish_all(c: &mut TickCost, t0: Instant, last: u64, period_us: impl Fn(u64) -> u64) {
        let mut at = t0;
        for k in 0..=last {
            c.published(k, at);
            at += Duration::from_micros(period_us(k));
        }
        c.frames = last;
    }

    /// Ticks published at known instants: the slow first ticks are out of the settled rate,
    /// which starts exactly at tick SETTLE_TICKS, and the percentiles are the intervals given.
    #[test]
    fn the_settled_rate_leaves_the_first_ticks_out() {
        let mut c = TickCost::default();
        // 200 µs apart up to tick SETTLE_TICKS, 1000 µs from it to the next, then 100 µs.
        let period_us = |k: u64| match k {
            k if k < SETTLE_TICKS => 200,
            k if k == SETTLE_TICKS => 1000,
            _ => 100,
        };
        publish_all(&mut c, Instant::now(), SETTLE_TICKS + 3000, period_us);
        let s = c.summary().unwrap();
        // From tick SETTLE_TICKS to SETTLE_TICKS + 3000: 3000 periods, 1000 µs + 2999 · 100 µs
        // = 300 900 µs. A window starting one tick late would see 2999 periods in 299 900 µs
        // (10 000/s), one starting a tick early 3001 in 301 100 µs (9966.8/s).
        let rate = s.settled_ticks_per_s.unwrap();
        let want = 3000.0 / 0.3009;
        assert!((rate - want).abs() < 1e-6, "{rate} against {want}");
        // 1000 periods of 200 µs, one of 1000 µs and 2999 of 100 µs: the median is 100 µs, the
        // 99th percentile (the 3960th of 4000) 200 µs, the longest 1000 µs (3 significant
        // digits: hdrhistogram reads the top of a bucket, within 0.1 %).
        assert!((s.period_p50_us - 100.0).abs() < 0.1, "{}", s.period_p50_us);
        assert!((s.period_p99_us - 200.0).abs() < 0.2, "{}", s.period_p99_us);
        assert!(
            (s.period_max_us - 1000.0).abs() < 1.0,
            "{}",
            s.period_max_us
        );
    }

    /// The settled rate needs a tick after the settled one: ticks 0 to SETTLE_TICKS have none,
    /// ticks 0 to SETTLE_TICKS + 1 have one; a run without frames has no summary.
    #[test]
    fn the_settled_rate_starts_after_the_settling_ticks() {
        assert!(TickCost::default().summary().is_none());
        let t0 = Instant::now();
        let mut c = TickCost::default();
        publish_all(&mut c, t0, SETTLE_TICKS, |_| 100);
        assert_eq!(c.summary().unwrap().settled_ticks_per_s, None);
        let mut c = TickCost::default();
        publish_all(&mut c, t0, SETTLE_TICKS + 1, |_| 100);
        let rate = c.summary().unwrap().settled_ticks_per_s.unwrap();
        assert!((rate - 10_000.0).abs() < 1e-6, "{rate}");
    }

    /// An operator's hold, before the settled tick and after it, is in neither the periods
    /// nor the settled rate.
    #[test]
    fn holds_are_left_out() {
        let mut c = TickCost::default();
        let mut at = Instant::now();
        for k in 0..=SETTLE_TICKS + 2000 {
            c.published(k, at);
            if k == 500 || k == SETTLE_TICKS + 700 {
                // Held for a second, then released.
                at += Duration::from_secs(1);
                c.released(at);
            }
            at += Duration::from_micros(100);
        }
        c.frames = SETTLE_TICKS + 2000;
        let s = c.summary().unwrap();
        let rate = s.settled_ticks_per_s.unwrap();
        assert!((rate - 10_000.0).abs() < 1e-6, "{rate}");
        assert!((s.period_max_us - 100.0).abs() < 0.1, "{}", s.period_max_us);
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
