//! Command bookkeeping on the physics thread: which command each participant holds, whether a
//! lockstep tick is fully answered, staleness, and the wrench to hold over the next frame.
//!
//! Everything here is a deterministic function of the accepted commands and the tick: no wall
//! clock. All storage is allocated in [`CommandBook::new`]; offering a command or computing the
//! held wrench and effector inputs allocates nothing.
//!
//! Effector inputs (`CommandKind::Actuators`) are kept per participant like the wrench: an
//! `Actuators` command replaces the wrench and the inputs of the effectors it lists; the others
//! keep that participant's previous inputs. The inputs applied are the participants' summed in
//! ascending sender-id order, like the wrench, and the stale policy treats both alike.

use std::ops::Range;

use flexdyn_proto::{
    command_flags, CommandKind, CommandMsg, CommandStatus, EffectorInput, StalePolicy, NO_COMMAND,
};

/// What the book did with an offered command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Offer {
    /// Accepted (in lockstep: it answers the current tick).
    Accepted,
    /// Rejected: its tick is not acceptable now (past, future, older than the held command, or a
    /// second answer to the same lockstep tick). Counted as `rejected.stale_tick`.
    StaleTick,
    /// Rejected: the sender is not a configured participant (`rejected.unknown_sender`).
    UnknownSender,
    /// Rejected: an `Actuators` command names an effector that does not exist or takes no
    /// inputs, gives the wrong number of values, or names an effector twice
    /// (`rejected.bad_effector_input`). In lockstep it does not answer the tick.
    BadEffectorInput,
}

#[derive(Clone, Debug)]
struct Slot {
    sender_id: u32,
    /// \[N·m\] the participant's last commanded torque, B components.
    torque_b_nm: [f64; 3],
    /// \[N\] the participant's last commanded force, B components.
    force_b_newton: [f64; 3],
    /// The participant's last commanded effector inputs, flat (laid out by the book's input
    /// ranges).
    inputs: Vec<f64>,
    /// Whether any command has been accepted from this sender.
    has_command: bool,
    /// `header.tick` of the last accepted command.
    last_tick: u64,
    /// Frame boundary (tick) at which the last command was taken by the physics loop.
    received_tick: u64,
    /// Lockstep: answered the current tick.
    answered: bool,
}

/// The wrench held over one frame, with its telemetry flags and status.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Held {
    /// \[N·m\] summed commanded torque about B, B components.
    pub torque_b_nm: [f64; 3],
    /// \[N\] summed commanded force at B, B components.
    pub force_b_newton: [f64; 3],
    /// [`command_flags`] bits for the StateMsg that ends this frame.
    pub flags: u8,
    /// Command bookkeeping for the StatusMsg.
    pub status: CommandStatus,
}

impl Held {
    /// Zero wrench, before any command (the flags of tick 0).
    pub fn initial(policy: StalePolicy) -> Self {
        Self {
            torque_b_nm: [0.0; 3],
            force_b_newton: [0.0; 3],
            flags: command_flags::NO_COMMAND_YET,
            status: CommandStatus {
                last_command_tick: NO_COMMAND,
                command_age_ns: NO_COMMAND,
                command_stale: false,
                stale_policy: policy,
            },
        }
    }
}

/// Per-participant command state, in ascending sender-id order.
#[derive(Clone, Debug)]
pub struct CommandBook {
    slots: Vec<Slot>,
    frame_ns: u64,
    stale_after_ns: u64,
    policy: StalePolicy,
    answered: usize,
    /// Where each effector's inputs sit in the flat input vector (empty range: takes none).
    input_ranges: Vec<Range<usize>>,
    /// Scratch for duplicate detection, one flag per effector.
    seen: Vec<bool>,
    /// The summed inputs of the last [`CommandBook::held`].
    held_inputs: Vec<f64>,
}

impl CommandBook {
    /// A book for `participants` (sorted, unique sender ids) on a spacecraft whose effectors'
    /// inputs sit at `input_ranges` of one flat vector.
    pub fn new(
        participants: &[u32],
        frame_ns: u64,
        stale_after_ns: u64,
        policy: StalePolicy,
        input_ranges: &[Range<usize>],
    ) -> Self {
        let mut ids = participants.to_vec();
        ids.sort_unstable();
        ids.dedup();
        let n_inputs = input_ranges.last().map_or(0, |r| r.end);
        Self {
            slots: ids
                .into_iter()
                .map(|sender_id| Slot {
                    sender_id,
                    torque_b_nm: [0.0; 3],
                    force_b_newton: [0.0; 3],
                    inputs: vec![0.0; n_inputs],
                    has_command: false,
                    last_tick: 0,
                    received_tick: 0,
                    answered: false,
                })
                .collect(),
            frame_ns,
            stale_after_ns,
            policy,
            answered: 0,
            input_ranges: input_ranges.to_vec(),
            seen: vec![false; input_ranges.len()],
            held_inputs: vec![0.0; n_inputs],
        }
    }

    /// Whether `inputs` fit the effector layout: known indices that take exactly that many
    /// values, each named once. Allocates nothing.
    fn inputs_fit(&mut self, inputs: &[EffectorInput]) -> bool {
        self.seen.iter_mut().for_each(|s| *s = false);
        for i in inputs {
            let idx = i.effector_index as usize;
            match self.input_ranges.get(idx) {
                Some(r) if !r.is_empty() && r.len() == i.values.len() && !self.seen[idx] => {
                    self.seen[idx] = true;
                }
                _ => return false,
            }
        }
        true
    }

    fn slot_index(&self, sender_id: u32) -> Option<usize> {
        self.slots
            .binary_search_by_key(&sender_id, |s| s.sender_id)
            .ok()
    }

    fn take(slot: &mut Slot, ranges: &[Range<usize>], cmd: &CommandMsg, k: u64) {
        match &cmd.kind {
            CommandKind::Wrench {
                torque_b_nm,
                force_b_newton,
            } => {
                slot.torque_b_nm = *torque_b_nm;
                slot.force_b_newton = *force_b_newton;
            }
            CommandKind::Actuators {
                torque_b_nm,
                force_b_newton,
                inputs,
            } => {
                slot.torque_b_nm = *torque_b_nm;
                slot.force_b_newton = *force_b_newton;
                // Checked by `inputs_fit` before.
                for i in inputs {
                    let r = ranges[i.effector_index as usize].clone();
                    slot.inputs[r].copy_from_slice(&i.values);
                }
            }
            CommandKind::NoCommand => {}
        }
        slot.has_command = true;
        slot.last_tick = cmd.header.tick;
        slot.received_tick = k;
    }

    /// Lockstep: start waiting for the answers to a new tick.
    pub fn begin_tick(&mut self) {
        for s in &mut self.slots {
            s.answered = false;
        }
        self.answered = 0;
    }

    /// Lockstep: whether every participant has answered the current tick.
    pub fn all_answered(&self) -> bool {
        self.answered == self.slots.len()
    }

    /// Lockstep: the lowest sender id that has not answered the current tick.
    pub fn first_unanswered(&self) -> Option<u32> {
        self.slots.iter().find(|s| !s.answered).map(|s| s.sender_id)
    }

    /// Lockstep: offer a command while waiting for the answers to tick `k`. Only a sender's
    /// first command stamped `k` is accepted; `NoCommand` keeps its previous wrench.
    pub fn offer_lockstep(&mut self, cmd: &CommandMsg, k: u64) -> Offer {
        let Some(i) = self.slot_index(cmd.sender_id) else {
            return Offer::UnknownSender;
        };
        if cmd.header.tick != k || self.slots[i].answered {
            return Offer::StaleTick;
        }
        if let Some(offer) = self.check_inputs(cmd) {
            return offer;
        }
        let slot = &mut self.slots[i];
        Self::take(slot, &self.input_ranges, cmd, k);
        slot.answered = true;
        self.answered += 1;
        Offer::Accepted
    }

    /// Real time / batch: offer a command at frame boundary `k`. Accepted unless its tick is in
    /// the future (`> k`) or older than the sender's held command (re-ordered or replayed).
    pub fn offer_latest(&mut self, cmd: &CommandMsg, k: u64) -> Offer {
        let Some(i) = self.slot_index(cmd.sender_id) else {
            return Offer::UnknownSender;
        };
        let slot = &self.slots[i];
        if cmd.header.tick > k || (slot.has_command && cmd.header.tick < slot.last_tick) {
            return Offer::StaleTick;
        }
        if let Some(offer) = self.check_inputs(cmd) {
            return offer;
        }
        Self::take(&mut self.slots[i], &self.input_ranges, cmd, k);
        Offer::Accepted
    }

    /// `Some(BadEffectorInput)` if `cmd` carries inputs that do not fit the layout.
    fn check_inputs(&mut self, cmd: &CommandMsg) -> Option<Offer> {
        match &cmd.kind {
            CommandKind::Actuators { inputs, .. } if !self.inputs_fit(inputs) => {
                Some(Offer::BadEffectorInput)
            }
            _ => None,
        }
    }

    /// The summed effector inputs of the last [`Self::held`], flat.
    pub fn held_inputs(&self) -> &[f64] {
        &self.held_inputs
    }

    /// The wrench to hold over frame `k` → `k + 1`: every participant's held command summed in
    /// ascending sender-id order. A command taken more than `stale_after` (simulation time) ago
    /// is stale; with [`StalePolicy::Zero`] it contributes zero. The effector inputs are summed
    /// the same way into [`Self::held_inputs`].
    pub fn held(&mut self, k: u64) -> Held {
        self.held_inputs.iter_mut().for_each(|u| *u = 0.0);
        let mut out = Held {
            torque_b_nm: [0.0; 3],
            force_b_newton: [0.0; 3],
            flags: 0,
            status: CommandStatus {
                last_command_tick: NO_COMMAND,
                command_age_ns: NO_COMMAND,
                command_stale: false,
                stale_policy: self.policy,
            },
        };
        let mut any = false;
        for s in self.slots.iter().filter(|s| s.has_command) {
            let age_ns = k
                .saturating_sub(s.received_tick)
                .saturating_mul(self.frame_ns);
            let stale = age_ns > self.stale_after_ns;
            if !any {
                out.status.last_command_tick = s.last_tick;
                out.status.command_age_ns = age_ns;
                any = true;
            } else {
                out.status.last_command_tick = out.status.last_command_tick.max(s.last_tick);
                out.status.command_age_ns = out.status.command_age_ns.max(age_ns);
            }
            if stale {
                out.flags |= command_flags::STALE;
                out.status.command_stale = true;
                if self.policy == StalePolicy::Zero {
                    out.flags |= command_flags::ZEROED_BY_POLICY;
                    continue;
                }
            }
            for i in 0..3 {
                out.torque_b_nm[i] += s.torque_b_nm[i];
                out.force_b_newton[i] += s.force_b_newton[i];
            }
            for (u, v) in self.held_inputs.iter_mut().zip(&s.inputs) {
                *u += v;
            }
        }
        if !any {
            out.flags |= command_flags::NO_COMMAND_YET;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::Header;

    fn wrench(sender: u32, tick: u64, tz: f64) -> CommandMsg {
        CommandMsg::wrench(
            Header::new(1, tick, 0, 0),
            sender,
            [0.0, 0.0, tz],
            [tz, 0.0, 0.0],
        )
    }

    fn none(sender: u32, tick: u64) -> CommandMsg {
        CommandMsg::no_command(Header::new(1, tick, 0, 0), sender)
    }

    #[test]
    fn lockstep_needs_every_participant_once() {
        let mut b = CommandBook::new(&[2, 1], 10, 100, StalePolicy::Hold, &[]);
        b.begin_tick();
        assert_eq!(b.first_unanswered(), Some(1));
        assert_eq!(b.offer_lockstep(&wrench(2, 5, 1.0), 5), Offer::Accepted);
        assert_eq!(b.offer_lockstep(&wrench(2, 5, 9.0), 5), Offer::StaleTick);
        assert_eq!(b.offer_lockstep(&wrench(1, 4, 1.0), 5), Offer::StaleTick);
        assert_eq!(b.offer_lockstep(&wrench(1, 6, 1.0), 5), Offer::StaleTick);
        assert_eq!(
            b.offer_lockstep(&wrench(3, 5, 1.0), 5),
            Offer::UnknownSender
        );
        assert!(!b.all_answered());
        assert_eq!(b.first_unanswered(), Some(1));
        assert_eq!(b.offer_lockstep(&wrench(1, 5, 0.5), 5), Offer::Accepted);
        assert!(b.all_answered());
        let h = b.held(5);
        assert_eq!(h.torque_b_nm, [0.0, 0.0, 1.5]);
        assert_eq!(h.force_b_newton, [1.5, 0.0, 0.0]);
        assert_eq!(h.flags, 0);
        assert_eq!(h.status.last_command_tick, 5);
        assert_eq!(h.status.command_age_ns, 0);
        // NoCommand keeps the previous wrench.
        b.begin_tick();
        assert_eq!(b.offer_lockstep(&none(1, 6), 6), Offer::Accepted);
        assert_eq!(b.offer_lockstep(&wrench(2, 6, 2.0), 6), Offer::Accepted);
        assert_eq!(b.held(6).torque_b_nm, [0.0, 0.0, 2.5]);
    }

    #[test]
    fn no_command_yet_flag() {
        let mut b = CommandBook::new(&[1], 10, 100, StalePolicy::Hold, &[]);
        let h = b.held(3);
        assert_eq!(h.flags, command_flags::NO_COMMAND_YET);
        assert_eq!(h.status.last_command_tick, NO_COMMAND);
        assert_eq!(
            h,
            Held {
                ..Held::initial(StalePolicy::Hold)
            }
        );
    }

    #[test]
    fn latest_value_staleness_hold_and_zero() {
        for policy in [StalePolicy::Hold, StalePolicy::Zero] {
            // frame 10 ns, stale after 25 ns: fresh for ages 0, 10, 20; stale from 30.
            let mut b = CommandBook::new(&[1], 10, 25, policy, &[]);
            assert_eq!(b.offer_latest(&wrench(1, 3, 1.0), 4), Offer::Accepted);
            assert_eq!(b.offer_latest(&wrench(1, 9, 1.0), 4), Offer::StaleTick);
            assert_eq!(b.offer_latest(&wrench(1, 2, 1.0), 4), Offer::StaleTick);
            for k in 4..=6 {
                let h = b.held(k);
                assert_eq!(h.flags, 0, "k={k}");
                assert_eq!(h.torque_b_nm[2], 1.0);
            }
            let h = b.held(7);
            assert_eq!(h.status.command_age_ns, 30);
            assert!(h.status.command_stale);
            match policy {
                StalePolicy::Hold => {
                    assert_eq!(h.flags, command_flags::STALE);
                    assert_eq!(h.torque_b_nm[2], 1.0);
                }
                StalePolicy::Zero => {
                    assert_eq!(
                        h.flags,
                        command_flags::STALE | command_flags::ZEROED_BY_POLICY
                    );
                    assert_eq!(h.torque_b_nm[2], 0.0);
                }
            }
            // A NoCommand refreshes the age and keeps the wrench.
            assert_eq!(b.offer_latest(&none(1, 7), 7), Offer::Accepted);
            let h = b.held(7);
            assert_eq!(h.flags, 0);
            assert_eq!(h.torque_b_nm[2], 1.0);
        }
    }
}
