//! The real-time lateness of a fleet's frame boundaries, from the physics thread to every
//! vehicle's telemetry thread, so each vehicle's StatusMsg (`timing.lateness_*`) and run report
//! carry it as a one-vehicle server's do.
//!
//! All vehicles share one frame boundary, so there is one lateness per frame. The physics thread
//! writes it into a ring of atomics (two stores: no lock, no allocation, no system call, no
//! wake-up); each telemetry thread keeps its own read position and drains what is new into its
//! histogram whenever it wakes (at least every 20 ms). The ring holds 4095 frames, 4 s at
//! 1 kHz: a reader lapped by the writer (one stalled for that long) counts what it missed
//! instead of reading torn values.

use std::sync::atomic::{AtomicU64, Ordering};

/// Frames the ring holds (a power of two).
const CAPACITY: u64 = 4096;

/// One writer (the physics thread), any number of readers, each with its own position.
#[derive(Debug)]
pub struct LatenessRing {
    slots: Box<[AtomicU64]>,
    /// Values written so far; value `j` is in slot `j mod CAPACITY` until `j + CAPACITY` is.
    written: AtomicU64,
}

impl Default for LatenessRing {
    fn default() -> Self {
        Self {
            slots: (0..CAPACITY).map(|_| AtomicU64::new(0)).collect(),
            written: AtomicU64::new(0),
        }
    }
}

impl LatenessRing {
    /// Physics thread: appends one frame's lateness \[ns\].
    #[inline]
    pub fn push(&self, lateness_ns: u64) {
        let w = self.written.load(Ordering::Relaxed);
        // Release: a reader that reads this value also sees `written` = w (below).
        self.slots[(w % CAPACITY) as usize].store(lateness_ns, Ordering::Release);
        self.written.store(w + 1, Ordering::Release);
    }

    /// Reader: calls `each` with every value written since `*next` (its position, advanced),
    /// in order, and returns how many were overwritten before it could read them.
    ///
    /// Value `j` is overwritten by value `j + CAPACITY`, which is stored while `written` is
    /// `j + CAPACITY`. A slot read that saw the newer value (Acquire, pairing with the store's
    /// Release) therefore sees `written ≥ j + CAPACITY` after it, and is discarded: only values
    /// with `j + CAPACITY > written` after the read are taken.
    pub fn drain(&self, next: &mut u64, mut each: impl FnMut(u64)) -> u64 {
        let w = self.written.load(Ordering::Acquire);
        let start = (*next).max((w + 1).saturating_sub(CAPACITY));
        let mut missed = start - *next;
        for j in start..w {
            let v = self.slots[(j % CAPACITY) as usize].load(Ordering::Acquire);
            if self.written.load(Ordering::Acquire) >= j + CAPACITY {
                missed += 1;
            } else {
                each(v);
            }
        }
        *next = w;
        missed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_reader_sees_every_value_in_order() {
        let ring = LatenessRing::default();
        let (mut a, mut b) = (0, 0);
        let (mut seen_a, mut seen_b) = (Vec::new(), Vec::new());
        for v in 1..=10 {
            ring.push(v);
        }
        assert_eq!(ring.drain(&mut a, |v| seen_a.push(v)), 0);
        for v in 11..=15 {
            ring.push(v);
        }
        assert_eq!(ring.drain(&mut a, |v| seen_a.push(v)), 0);
        assert_eq!(ring.drain(&mut b, |v| seen_b.push(v)), 0);
        assert_eq!(seen_a, (1..=15).collect::<Vec<_>>());
        assert_eq!(seen_b, seen_a);
        // Nothing new: nothing.
        assert_eq!(ring.drain(&mut a, |_| panic!("no new value")), 0);
    }

    #[test]
    fn a_lapped_reader_counts_what_it_missed_and_reads_the_rest() {
        let ring = LatenessRing::default();
        let mut next = 0;
        let n = CAPACITY + 100;
        for v in 0..n {
            ring.push(v);
        }
        // Values 0..=100 may be overwritten (value 100's slot holds value 100 + CAPACITY as
        // soon as `written` reaches it): 101 missed, the last CAPACITY − 1 read.
        let mut seen = Vec::new();
        assert_eq!(ring.drain(&mut next, |v| seen.push(v)), 101);
        assert_eq!(seen, (101..n).collect::<Vec<_>>());
        assert_eq!(next, n);
    }

    #[test]
    fn a_reader_on_another_thread_sees_no_torn_or_reordered_value() {
        // The writer pushes 0, 1, 2, …; whatever a concurrent reader takes must be strictly
        // increasing by 1 between misses, and taken + missed must be everything.
        let ring = std::sync::Arc::new(LatenessRing::default());
        let total = 200_000u64;
        let w = ring.clone();
        let writer = std::thread::spawn(move || {
            for v in 0..total {
                w.push(v);
            }
        });
        let (mut next, mut taken, mut missed, mut last) = (0, 0u64, 0u64, None::<u64>);
        while next < total {
            missed += ring.drain(&mut next, |v| {
                if let Some(l) = last {
                    assert!(v > l, "{v} after {l}");
                }
                last = Some(v);
                taken += 1;
            });
        }
        writer.join().unwrap();
        assert_eq!(taken + missed, total);
        assert_eq!(last, Some(total - 1));
    }
}
