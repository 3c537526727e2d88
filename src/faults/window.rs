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
}
