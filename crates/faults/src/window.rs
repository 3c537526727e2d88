//! When a fault is active: from `start_ns`, for `duration_ns` (or to the end of the run),
//! repeating every `period_ns` if given. All in integer nanoseconds of simulation time.

/// A fault's activity window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultWindow {
    /// \[ns\] first activation.
    pub start_ns: u64,
    /// \[ns\] length of each activation; `None`: until the end of the run.
    pub duration_ns: Option<u64>,
    /// \[ns\] repetition period (> duration); `None`: one activation.
    pub period_ns: Option<u64>,
}

impl FaultWindow {
    /// A window that opens at `start_ns` and stays open.
    pub const fn from(start_ns: u64) -> Self {
        Self {
            start_ns,
            duration_ns: None,
            period_ns: None,
        }
    }

    /// The start \[ns\] of the activation in force at `t_ns`, or `None` if inactive then:
    /// active on `[start + n·period, start + n·period + duration)` for n = 0, 1, … (n = 0 only
    /// without a period).
    #[inline]
    pub fn activation_at(&self, t_ns: u64) -> Option<u64> {
        let since = t_ns.checked_sub(self.start_ns)?;
        let (n, phase) = match self.period_ns {
            Some(p) => (since / p, since % p),
            None => (0, since),
        };
        match self.duration_ns {
            Some(d) if phase >= d => None,
            _ => Some(self.start_ns + n * self.period_ns.unwrap_or(0)),
        }
    }

    /// The starts \[ns\] of the activations that begin in `(after_ns, upto_ns]`, in order:
    /// `start + n·period` for n = 0, 1, … (n = 0 only without a period). A window shorter than
    /// the gap between two looks, or a repeating fault's activations in between, are all here.
    pub fn starts_in(&self, after_ns: u64, upto_ns: u64) -> impl Iterator<Item = u64> {
        let (start, period) = (self.start_ns, self.period_ns);
        // The first n with start + n·period > after_ns.
        let n_first = match (after_ns.checked_sub(start), period) {
            (None, _) => 0,
            (Some(_), None) => 1, // the single activation began at or before after_ns
            (Some(since), Some(p)) => since / p + 1,
        };
        // The last n with start + n·period ≤ upto_ns (none if the window opens later).
        let n_last = match (upto_ns.checked_sub(start), period) {
            (None, _) => None,
            (Some(_), None) => Some(0),
            (Some(since), Some(p)) => Some(since / p),
        };
        let range = match n_last {
            Some(last) if last >= n_first => n_first..=last,
            #[allow(clippy::reversed_empty_ranges)]
            _ => 1..=0,
        };
        range.map(move |n| start + n * period.unwrap_or(0))
    }

    /// The start \[ns\] of the last activation that began at or before `t_ns`, whether or not
    /// it is still active then (`None` before the first): [`Self::activation_at`] wherever that
    /// is `Some`. For a reader that knows the fault was active up to a frame before `t_ns`
    /// (a recording's StatusMsg active set, which may lag its tick).
    pub fn last_start_at(&self, t_ns: u64) -> Option<u64> {
        let since = t_ns.checked_sub(self.start_ns)?;
        Some(self.start_ns + self.period_ns.map_or(0, |p| since / p * p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_shot_repeating_and_open_ended() {
        let once = FaultWindow {
            start_ns: 10,
            duration_ns: Some(5),
            period_ns: None,
        };
        assert_eq!(once.activation_at(9), None);
        assert_eq!(once.activation_at(10), Some(10));
        assert_eq!(once.activation_at(14), Some(10));
        assert_eq!(once.activation_at(15), None);
        assert_eq!(once.activation_at(1000), None);
        let rep = FaultWindow {
            period_ns: Some(20),
            ..once
        };
        assert_eq!(rep.activation_at(31), Some(30));
        assert_eq!(rep.activation_at(35), None);
        assert_eq!(rep.activation_at(50), Some(50));
        assert_eq!(FaultWindow::from(7).activation_at(u64::MAX), Some(7));
    }

    /// The starts in a span agree with `activation_at` looked at every nanosecond: a start is
    /// where the activation in force changes to a new one.
    #[test]
    fn starts_in_a_span_are_the_activations_that_begin_there() {
        let windows = [
            FaultWindow {
                start_ns: 10,
                duration_ns: Some(5),
                period_ns: None,
            },
            FaultWindow {
                start_ns: 10,
                duration_ns: Some(3),
                period_ns: Some(7),
            },
            FaultWindow::from(0),
            FaultWindow::from(25),
        ];
        for w in windows {
            for after in 0..40u64 {
                for upto in after..60u64 {
                    let got: Vec<u64> = w.starts_in(after, upto).collect();
                    let mut want = Vec::new();
                    let mut prev = w.activation_at(after);
                    for t in after + 1..=upto {
                        let now = w.activation_at(t);
                        if let Some(s) = now {
                            if prev != now {
                                want.push(s);
                            }
                        }
                        prev = now;
                    }
                    assert_eq!(got, want, "{w:?} in ({after}, {upto}]");
                }
            }
        }
        // A window opening at 0 begins in no span after it (it began at the first look).
        assert_eq!(FaultWindow::from(0).starts_in(0, 100).count(), 0);
    }

    /// The last start agrees with the activation in force wherever there is one, and between
    /// activations names the one just ended.
    #[test]
    fn the_last_start_is_the_activation_in_force_or_the_one_just_ended() {
        let once = FaultWindow {
            start_ns: 10,
            duration_ns: Some(5),
            period_ns: None,
        };
        let rep = FaultWindow {
            period_ns: Some(20),
            ..once
        };
        for w in [once, rep, FaultWindow::from(7)] {
            for t in 0..100 {
                if let Some(s) = w.activation_at(t) {
                    assert_eq!(w.last_start_at(t), Some(s), "{w:?} at {t}");
                }
            }
        }
        assert_eq!(once.last_start_at(9), None);
        assert_eq!(once.last_start_at(500), Some(10));
        // [30, 35) ended at 35; the next starts at 50.
        assert_eq!(rep.last_start_at(40), Some(30));
        assert_eq!(rep.last_start_at(50), Some(50));
    }
}
