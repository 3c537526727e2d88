//! What a recording misses, counted from the publishers' sequence numbers.
//!
//! The server numbers each telemetry topic's messages +1 per message (`header.seq`, see
//! `proto/README.md`, "Header"): a StateMsg and the IMU samples of a frame carry its tick, a
//! star tracker counts its updates, StatusMsg counts itself. A recorder that sees `seq` jump
//! from `a` to `b > a + 1` on one key has missed the `b − a − 1` messages between them, wherever
//! they were lost: not published (real time without a free telemetry buffer), dropped on the way
//! (Zenoh's congestion control "drop" in real time), or dropped by the recorder's own queue.
//!
//! Only the server's telemetry keys are counted. A command's `seq` is its sender's own number,
//! which the server does not require to be consecutive, so a jump there proves nothing. Missing
//! messages before the first one heard (a recorder started mid-run) or after the last are not
//! counted: the recording starts and ends where it does. A `seq` that goes back starts a new
//! stream on that key (a server restarted under the same `sc_id`, or a replay started again).

use std::collections::HashMap;

use super::topics::TopicKind;

/// The last sequence number heard on each key.
#[derive(Clone, Debug, Default)]
pub struct SeqGaps {
    last_seq: HashMap<String, u64>,
}

impl SeqGaps {
    /// Whether messages of `kind` carry a publisher's consecutive sequence number.
    pub fn counts(kind: TopicKind) -> bool {
        match kind {
            TopicKind::State
            | TopicKind::Sensor(_)
            | TopicKind::Status
            | TopicKind::Time
            | TopicKind::Environment
            | TopicKind::FaultEvent
            | TopicKind::RelativeState => true,
            // The flight code's counters are its own, and the server records only the samples
            // that pass its checks: a jump there is a refusal, counted in StatusMsg.
            TopicKind::Command | TopicKind::Operator | TopicKind::FaultCommand | TopicKind::Fsw => {
                false
            }
        }
    }

    /// Notes a message of `kind` with sequence number `seq` on `key`; returns how many messages
    /// the jump from the key's previous one shows missing (0 for the first, or a new stream).
    pub fn observe(&mut self, key: &str, kind: TopicKind, seq: u64) -> u64 {
        if !Self::counts(kind) {
            return 0;
        }
        let Some(last) = self.last_seq.get_mut(key) else {
            self.last_seq.insert(key.to_owned(), seq);
            return 0;
        };
        let gap = seq.saturating_sub(*last).saturating_sub(1);
        *last = seq;
        gap
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topics::classify;
    use std::collections::BTreeMap;

    #[test]
    fn jumps_count_what_is_missing_per_key_and_only_on_telemetry() {
        let mut g = SeqGaps::default();
        let mut missing: BTreeMap<&str, u64> = BTreeMap::new();
        let state = "flexdyn/sc1/tlm/state";
        let imu = "flexdyn/sc1/tlm/imu/imu1";
        let st = "flexdyn/sc1/tlm/st/st1";
        let status = "flexdyn/sc1/status";
        let cmd = "flexdyn/sc1/cmd/1";
        let heard = [
            // A recorder joining at 500 misses nothing before it; 503..=505 are missing.
            (
                state,
                TopicKind::State,
                [500, 501, 502, 506, 507].as_slice(),
            ),
            (imu, classify(imu).unwrap().kind, &[7, 9]),
            (st, classify(st).unwrap().kind, &[0, 1, 2, 3]),
            (status, TopicKind::Status, &[4, 5, 8]),
            // A server restarted under the same id: a new stream (no gap at 0), then 1 missing.
            (state, TopicKind::State, &[0, 2]),
            // Commands number themselves as their sender likes.
            (cmd, TopicKind::Command, &[0, 10, 1000, 3]),
        ];
        for (key, kind, seqs) in heard {
            for &seq in seqs {
                *missing.entry(key).or_default() += g.observe(key, kind, seq);
            }
        }
        assert_eq!(
            missing,
            BTreeMap::from([(cmd, 0), (imu, 1), (st, 0), (state, 4), (status, 2)])
        );
    }
}
