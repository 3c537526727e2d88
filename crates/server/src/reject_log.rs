//! Rate-limited warnings for rejected commands, so flight code that sends bad commands is told
//! in the log, not only in a 10 s total.
//!
//! The first rejection of each reason from each sender is logged at `warn` with the reason, the
//! sender and what was wrong. After that, the same (reason, sender) is logged at most once per
//! [`RejectLog::EVERY`], with the number rejected since its last line. It runs on the Zenoh
//! callback (decode, spacecraft and sender checks) and on the telemetry thread (stale ticks,
//! which the physics thread only counts), never on the physics thread.

use std::collections::HashMap;
use std::fmt::Display;
use std::time::{Duration, Instant};

struct Entry {
    last_logged: Instant,
    since_logged: u64,
}

/// Per (reason, sender) rate limiter of rejection warnings.
#[derive(Default)]
pub struct RejectLog {
    entries: HashMap<(&'static str, Option<u32>), Entry>,
    /// What is rejected and the one StatusMsg counter every reason counts in (`None`: a
    /// command, counted under its reason).
    counted_in: Option<(&'static str, &'static str)>,
}

impl RejectLog {
    /// A log of rejected `what` (`flight-code telemetry`), whose every reason counts in
    /// `StatusMsg.rejected.<counter>`.
    pub fn counted_in(what: &'static str, counter: &'static str) -> Self {
        Self {
            counted_in: Some((what, counter)),
            ..Self::default()
        }
    }

    /// Shortest interval between two lines for one (reason, sender).
    pub const EVERY: Duration = Duration::from_secs(10);

    /// Records `n` rejections of `reason` (the `StatusMsg.rejected` counter name) from `sender`
    /// (`None` when the command could not be decoded far enough to know it); logs per the
    /// module rules. Returns whether a line was logged.
    pub fn record(
        &mut self,
        reason: &'static str,
        sender: Option<u32>,
        n: u64,
        detail: &dyn Display,
    ) -> bool {
        let now = Instant::now();
        let sender_s = sender.map_or_else(|| "unknown".to_owned(), |s| s.to_string());
        match self.entries.get_mut(&(reason, sender)) {
            None => {
                match self.counted_in {
                    None => tracing::warn!(
                        reason,
                        sender = %sender_s,
                        "rejected a command: {detail} (counted in StatusMsg.rejected.{reason}; \
                         further ones from this sender are logged at most every {} s)",
                        Self::EVERY.as_secs()
                    ),
                    Some((what, counter)) => tracing::warn!(
                        reason,
                        "rejected {what}: {detail} (reason {reason}, counted in \
                         StatusMsg.rejected.{counter}; further ones for this reason are logged \
                         at most every {} s)",
                        Self::EVERY.as_secs()
                    ),
                }
                self.entries.insert(
                    (reason, sender),
                    Entry {
                        last_logged: now,
                        since_logged: n.saturating_sub(1),
                    },
                );
                true
            }
            Some(e) => {
                e.since_logged += n;
                if now.duration_since(e.last_logged) >= Self::EVERY {
                    tracing::warn!(
                        reason,
                        sender = %sender_s,
                        rejected = e.since_logged,
                        "rejected commands since the last warning: {detail}"
                    );
                    e.last_logged = now;
                    e.since_logged = 0;
                    true
                } else {
                    false
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_of_each_reason_and_sender_then_rate_limited() {
        let mut log = RejectLog::default();
        assert!(log.record("stale_tick", Some(1), 1, &"x"));
        assert!(!log.record("stale_tick", Some(1), 1, &"x"));
        assert!(log.record("stale_tick", Some(2), 1, &"x"));
        assert!(log.record("unknown_sender", Some(1), 1, &"x"));
        assert!(log.record("malformed", None, 3, &"x"));
        assert!(!log.record("malformed", None, 1, &"x"));
        // Once the interval has passed, the next one logs with the count since.
        log.entries
            .get_mut(&("stale_tick", Some(1)))
            .unwrap()
            .last_logged -= RejectLog::EVERY;
        assert!(log.record("stale_tick", Some(1), 1, &"x"));
        assert_eq!(log.entries[&("stale_tick", Some(1))].since_logged, 0);
    }
}
