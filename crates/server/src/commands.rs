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
//!
//! Command-link faults ([`flexdyn_faults::link`]: dropped, delayed, corrupted) act here, at the
//! tick a command answers, so their effect is a function of the tick as well.

use std::ops::Range;

use flexdyn_proto::view::{view_command, CommandKindView, CommandView, ViewError};
use flexdyn_proto::{
    command_flags, CommandKind, CommandMsg, CommandStatus, StalePolicy, NO_COMMAND,
};

use flexdyn_faults::link::{damage, LinkFaults, LinkStats};
use flexdyn_kernel::archive::{Archive, Archived};

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
    /// Discarded: the sender's command link is `dropped` ([`flexdyn_faults::link`]); counted in
    /// [`LinkStats::commands_dropped`].
    LinkDropped,
    /// The sender's command link is `corrupted` and the damaged command failed a check: counted
    /// under `rejected.<reason>`. In lockstep it answers the tick with nothing.
    LinkCorrupted(Damaged),
}

/// Why a damaged command ([`Offer::LinkCorrupted`]) was rejected: its `rejected.*` counter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Damaged {
    /// `rejected.malformed`.
    Malformed,
    /// `rejected.bad_version`.
    BadVersion,
    /// `rejected.non_finite`.
    NonFinite,
    /// `rejected.wrong_spacecraft`.
    WrongSpacecraft,
    /// `rejected.wrong_identity`: its sender id is not its link's.
    WrongIdentity,
    /// `rejected.stale_tick`.
    StaleTick,
    /// `rejected.bad_effector_input`.
    BadEffectorInput,
}

impl Damaged {
    fn of_view(e: ViewError) -> Self {
        match e {
            ViewError::UnknownVersion { .. } => Self::BadVersion,
            ViewError::NonFinite => Self::NonFinite,
            ViewError::Malformed => Self::Malformed,
        }
    }
}

/// A `delayed` link's delay line: the participant's slot as it was at each of the last
/// `ring.len()` ticks held (index `k mod len`), preallocated.
#[derive(Clone, Debug)]
struct DelayLine {
    /// The participant's slot index.
    slot: usize,
    ring: Vec<Slot>,
    /// The tick each entry was taken at.
    ticks: Vec<Option<u64>>,
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

impl Archived for Slot {
    /// The participant's last command and its bookkeeping; its sender id must be the run's (a
    /// fork with other participants does not fit).
    fn archive(&mut self, a: &mut Archive<'_>) {
        let Self {
            sender_id,
            torque_b_nm,
            force_b_newton,
            inputs,
            has_command,
            last_tick,
            received_tick,
            answered,
        } = self;
        a.expect_count("a participant's sender id", *sender_id as usize);
        a.put(torque_b_nm);
        a.put(force_b_newton);
        a.expect_count("a participant's effector inputs", inputs.len());
        a.put(&mut inputs[..]);
        a.put(has_command);
        a.put(last_tick);
        a.put(received_tick);
        a.put(answered);
    }
}

impl Archived for DelayLine {
    fn archive(&mut self, a: &mut Archive<'_>) {
        let Self {
            slot: _,
            ring,
            ticks,
        } = self;
        a.expect_count("a delay line's entries", ring.len());
        for (entry, tick) in ring.iter_mut().zip(ticks.iter_mut()) {
            a.put(entry);
            a.put(tick);
        }
    }
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

/// `Some(BadEffectorInput)` unless the inputs of an `Actuators` command fit the effector layout
/// `ranges` (where each effector's inputs sit in one flat vector): known indices that take
/// exactly that many values, each named once. `seen` is scratch, one flag per effector.
/// Allocates nothing.
fn check_inputs(ranges: &[Range<usize>], seen: &mut [bool], cmd: &CommandMsg) -> Option<Offer> {
    let CommandKind::Actuators { inputs, .. } = &cmd.kind else {
        return None;
    };
    check_input_sizes(
        ranges,
        seen,
        inputs.iter().map(|i| (i.effector_index, i.values.len())),
    )
}

/// [`check_inputs`] for a command read in place (a damaged one).
fn check_view_inputs(
    ranges: &[Range<usize>],
    seen: &mut [bool],
    cmd: &CommandView<'_>,
) -> Option<Offer> {
    let CommandKindView::Actuators { inputs, .. } = cmd.kind() else {
        return None;
    };
    check_input_sizes(
        ranges,
        seen,
        inputs
            .iter()
            .map(|i| (i.effector_index(), i.values().len())),
    )
}

/// [`check_inputs`] on each input's effector index and value count.
fn check_input_sizes(
    ranges: &[Range<usize>],
    seen: &mut [bool],
    inputs: impl Iterator<Item = (u32, usize)>,
) -> Option<Offer> {
    seen.iter_mut().for_each(|s| *s = false);
    for (index, len) in inputs {
        let idx = index as usize;
        match (ranges.get(idx), seen.get_mut(idx)) {
            (Some(r), Some(s)) if !r.is_empty() && r.len() == len && !*s => *s = true,
            _ => return Some(Offer::BadEffectorInput),
        }
    }
    None
}

/// Copies slot `from` into `to` (same input layout) without allocating.
fn copy_slot(to: &mut Slot, from: &Slot) {
    to.sender_id = from.sender_id;
    to.torque_b_nm = from.torque_b_nm;
    to.force_b_newton = from.force_b_newton;
    to.inputs.copy_from_slice(&from.inputs);
    to.has_command = from.has_command;
    to.last_tick = from.last_tick;
    to.received_tick = from.received_tick;
    to.answered = from.answered;
}

impl Archived for Held {
    /// The wrench held over the last frame and the status its telemetry carries.
    fn archive(&mut self, a: &mut Archive<'_>) {
        let Self {
            torque_b_nm,
            force_b_newton,
            flags,
            status,
        } = self;
        a.put(torque_b_nm);
        a.put(force_b_newton);
        a.put(flags);
        let CommandStatus {
            last_command_tick,
            command_age_ns,
            command_stale,
            stale_policy: _,
        } = status;
        a.put(last_command_tick);
        a.put(command_age_ns);
        a.put(command_stale);
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
    /// The command-link faults (none by default).
    links: LinkFaults,
    /// The spacecraft id a damaged command must still carry.
    spacecraft_id: u32,
    /// One per participant with a `delayed` link fault.
    delay: Vec<DelayLine>,
    /// A participant's slot with nothing held (before its first command).
    empty: Slot,
    /// Scratch for a damaged command's bytes.
    scratch: Vec<u8>,
    /// What the link faults did.
    stats: LinkStats,
}

impl CommandBook {
    /// Lists the book's mutable state for a checkpoint: every participant's last command, the
    /// answers of the current tick, the summed inputs, the command-link faults and their delay
    /// lines and statistics. Configuration (participants, frame, staleness, the input layout)
    /// and scratch are the run's. Not on the stepping path.
    pub fn archive(&mut self, a: &mut Archive<'_>) {
        let Self {
            slots,
            frame_ns: _,
            stale_after_ns: _,
            policy: _,
            answered,
            input_ranges: _,
            seen: _,
            held_inputs,
            links,
            spacecraft_id: _,
            delay,
            empty: _,
            scratch: _,
            stats,
        } = self;
        a.section("commands", |a| {
            a.expect_count("participants", slots.len());
            for s in slots.iter_mut() {
                a.put(s);
            }
            let mut n = *answered as u64;
            a.put(&mut n);
            *answered = (n as usize).min(slots.len());
            a.expect_count("summed effector inputs", held_inputs.len());
            a.put(&mut held_inputs[..]);
            links.archive(a);
            a.expect_count("delay lines", delay.len());
            for d in delay.iter_mut() {
                a.put(d);
            }
            let flexdyn_faults::link::LinkStats {
                commands_dropped,
                empty_answers,
                delayed_frames,
                commands_corrupted,
                corrupted_rejected,
            } = stats;
            for v in [
                commands_dropped,
                empty_answers,
                delayed_frames,
                commands_corrupted,
                corrupted_rejected,
            ] {
                a.put(v);
            }
        });
    }

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
        let empty = |sender_id| Slot {
            sender_id,
            torque_b_nm: [0.0; 3],
            force_b_newton: [0.0; 3],
            inputs: vec![0.0; n_inputs],
            has_command: false,
            last_tick: 0,
            received_tick: 0,
            answered: false,
        };
        Self {
            slots: ids.into_iter().map(empty).collect(),
            links: LinkFaults::default(),
            spacecraft_id: 0,
            delay: Vec::new(),
            empty: empty(0),
            scratch: Vec::new(),
            stats: LinkStats::default(),
            frame_ns,
            stale_after_ns,
            policy,
            answered: 0,
            input_ranges: input_ranges.to_vec(),
            seen: vec![false; input_ranges.len()],
            held_inputs: vec![0.0; n_inputs],
        }
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
                // Checked by `check_inputs` before.
                for i in inputs {
                    let r = ranges[i.effector_index as usize].clone();
                    slot.inputs[r].copy_from_slice(&i.values);
                }
            }
            CommandKind::NoCommand => {}
        }
        Self::stamp(slot, cmd.header.tick, k);
    }

    /// [`Self::take`] for a command read in place (a damaged one).
    fn take_view(slot: &mut Slot, ranges: &[Range<usize>], cmd: &CommandView<'_>, k: u64) {
        match cmd.kind() {
            CommandKindView::Wrench {
                torque_b_nm,
                force_b_newton,
            } => {
                slot.torque_b_nm = torque_b_nm;
                slot.force_b_newton = force_b_newton;
            }
            CommandKindView::Actuators {
                torque_b_nm,
                force_b_newton,
                inputs,
            } => {
                slot.torque_b_nm = torque_b_nm;
                slot.force_b_newton = force_b_newton;
                // Checked by `check_view_inputs` before.
                for input in inputs.iter() {
                    let r = ranges[input.effector_index() as usize].clone();
                    slot.inputs[r]
                        .iter_mut()
                        .zip(input.values().iter())
                        .for_each(|(to, v)| *to = v);
                }
            }
            CommandKindView::NoCommand => {}
        }
        Self::stamp(slot, cmd.header().tick, k);
    }

    /// Marks `slot` as holding the command of tick `tick`, taken at boundary `k`.
    fn stamp(slot: &mut Slot, tick: u64, k: u64) {
        slot.has_command = true;
        slot.last_tick = tick;
        slot.received_tick = k;
    }

    /// The book with the command-link faults `links` on the spacecraft `spacecraft_id` (a
    /// damaged command must still carry it). Allocates the delay lines.
    pub fn with_links(mut self, links: LinkFaults, spacecraft_id: u32) -> Self {
        self.delay = self
            .slots
            .iter()
            .enumerate()
            .filter_map(|(slot, s)| {
                let n = links.max_delay_frames(s.sender_id)? as usize + 1;
                Some(DelayLine {
                    slot,
                    ring: vec![s.clone(); n],
                    ticks: vec![None; n],
                })
            })
            .collect();
        self.scratch = Vec::with_capacity(flexdyn_proto::MAX_MESSAGE_BYTES);
        self.links = links;
        self.spacecraft_id = spacecraft_id;
        self
    }

    /// What the command-link faults did so far.
    pub fn link_stats(&self) -> LinkStats {
        self.stats
    }

    /// A live clear of fault `fault_index` from `from_ns` on, if it is a command-link fault
    /// ([`LinkFaults::clear`]).
    pub fn clear_link_fault(&mut self, fault_index: u32, from_ns: u64) {
        self.links.clear(fault_index, from_ns);
    }

    /// The command-link faults (with which are active at the last tick evaluated).
    pub fn links(&self) -> &LinkFaults {
        &self.links
    }

    /// Lockstep: start waiting for the answers to tick `k`. A participant whose link is
    /// `dropped` at `k` counts as answered with nothing: the barrier does not wait for it.
    pub fn begin_tick(&mut self, k: u64) {
        self.links.at_tick(k);
        self.answered = 0;
        for s in &mut self.slots {
            s.answered = !self.links.is_empty() && self.links.dropped(s.sender_id);
            if s.answered {
                self.answered += 1;
                self.stats.empty_answers += 1;
            }
        }
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
        if !self.links.is_empty() {
            self.links.at_tick(k);
            if self.links.dropped(cmd.sender_id) {
                self.stats.commands_dropped += 1;
                return Offer::LinkDropped;
            }
        }
        if cmd.header.tick != k || self.slots[i].answered {
            return Offer::StaleTick;
        }
        if let Some((seed, p)) = self.corruption(cmd.sender_id) {
            // The damaged command answers the tick whatever the checks say (no run waits for a
            // command its link cannot deliver).
            self.slots[i].answered = true;
            self.answered += 1;
            return self.offer_damaged(i, cmd, k, seed, p, true);
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

    /// `(seed, probability)` if `sender_id`'s link is corrupted at the tick evaluated.
    fn corruption(&self, sender_id: u32) -> Option<(u64, f64)> {
        if self.links.is_empty() {
            return None;
        }
        self.links.corruption(sender_id)
    }

    /// Slot `i`'s command `cmd` at tick `k` through a corrupted link ([`flexdyn_faults::link`]):
    /// its encoding damaged, decoded and checked like any command (`lockstep` selects the tick
    /// rule), and taken if it passes.
    fn offer_damaged(
        &mut self,
        i: usize,
        cmd: &CommandMsg,
        k: u64,
        seed: u64,
        probability: f64,
        lockstep: bool,
    ) -> Offer {
        self.stats.commands_corrupted += 1;
        flexdyn_proto::encode_into(cmd, &mut self.scratch);
        damage(&mut self.scratch, seed, k, probability);
        let slot = &self.slots[i];
        // Read in place: decoding a damaged Actuators command would allocate its inputs here,
        // on the stepping thread.
        // The header read once, beside the view.
        let reject = match view_command(&self.scratch).map(|d| (d, d.header())) {
            Err(e) => Err(Damaged::of_view(e)),
            Ok((_, h)) if h.spacecraft_id != self.spacecraft_id => Err(Damaged::WrongSpacecraft),
            Ok((d, _)) if d.sender_id() != slot.sender_id => Err(Damaged::WrongIdentity),
            Ok((_, h))
                if (lockstep && h.tick != k)
                    || (!lockstep
                        && (h.tick > k || (slot.has_command && h.tick < slot.last_tick))) =>
            {
                Err(Damaged::StaleTick)
            }
            Ok((d, _)) => match check_view_inputs(&self.input_ranges, &mut self.seen, &d) {
                Some(_) => Err(Damaged::BadEffectorInput),
                None => Ok(d),
            },
        };
        match reject {
            Ok(d) => {
                Self::take_view(&mut self.slots[i], &self.input_ranges, &d, k);
                Offer::Accepted
            }
            Err(why) => {
                self.stats.corrupted_rejected += 1;
                Offer::LinkCorrupted(why)
            }
        }
    }

    /// Real time / batch: offer a command at frame boundary `k`. Accepted unless its tick is in
    /// the future (`> k`) or older than the sender's held command (re-ordered or replayed).
    pub fn offer_latest(&mut self, cmd: &CommandMsg, k: u64) -> Offer {
        let Some(i) = self.slot_index(cmd.sender_id) else {
            return Offer::UnknownSender;
        };
        if !self.links.is_empty() {
            self.links.at_tick(k);
            if self.links.dropped(cmd.sender_id) {
                self.stats.commands_dropped += 1;
                return Offer::LinkDropped;
            }
            if let Some((seed, p)) = self.links.corruption(cmd.sender_id) {
                return self.offer_damaged(i, cmd, k, seed, p, false);
            }
        }
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
        check_inputs(&self.input_ranges, &mut self.seen, cmd)
    }

    /// The summed effector inputs of the last [`Self::held`], flat.
    pub fn held_inputs(&self) -> &[f64] {
        &self.held_inputs
    }

    /// The wrench to hold over frame `k` → `k + 1`: every participant's held command summed in
    /// ascending sender-id order. A command taken more than `stale_after` (simulation time) ago
    /// is stale; with [`StalePolicy::Zero`] it contributes zero. The effector inputs are summed
    /// the same way into [`Self::held_inputs`].
    ///
    /// A participant whose link is `delayed` by N frames at `k` contributes its slot as it was
    /// at tick k − N (nothing before tick N): [`flexdyn_faults::link`].
    pub fn held(&mut self, k: u64) -> Held {
        self.held_inputs.iter_mut().for_each(|u| *u = 0.0);
        if !self.delay.is_empty() {
            self.links.at_tick(k);
            for d in &mut self.delay {
                let n = d.ring.len();
                let at = (k % n as u64) as usize;
                copy_slot(&mut d.ring[at], &self.slots[d.slot]);
                d.ticks[at] = Some(k);
            }
        }
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
        for (i, s) in self.slots.iter().enumerate() {
            let s = match self.delay.iter().find(|d| d.slot == i) {
                Some(d) => match self.links.delay_frames(s.sender_id) {
                    Some(n) => {
                        self.stats.delayed_frames += 1;
                        let back = k.checked_sub(n);
                        let at = back.map_or(0, |b| (b % d.ring.len() as u64) as usize);
                        if back.is_some() && d.ticks[at] == back {
                            &d.ring[at]
                        } else {
                            &self.empty
                        }
                    }
                    None => s,
                },
                None => s,
            };
            if !s.has_command {
                continue;
            }
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

/// The checks made in the Zenoh command callback, before a command is queued for the physics
/// thread: a flood of commands that cannot be applied is counted under its reason instead of
/// filling the queue, so `commands_dropped` counts valid commands only.
///
/// `published` is the last tick whose state the server has published (the physics thread notes
/// a tick before it publishes it, so a participant answering a state always finds its tick
/// noted). A command may be queued if
/// - its effector inputs fit the layout (else `bad_effector_input`), and
/// - real time and batch: its tick has been published and is not older than the sender's last
///   queued command (else `stale_tick`);
/// - lockstep: its tick is the one published, and the sender has not answered it yet (else
///   `stale_tick`).
///
/// The book (which takes queued commands at a boundary `k ≥ published`) makes the same checks
/// again and so never takes a command the gate refused. In lockstep the two agree exactly. In
/// real time the gate decides a command for a tick not yet published when it arrives; without
/// it, such a command was taken or refused depending on whether it reached the queue before or
/// after the physics thread's next boundary, a race the gate removes.
#[derive(Clone, Debug)]
pub struct Gate {
    lockstep: bool,
    input_ranges: Vec<Range<usize>>,
    seen: Vec<bool>,
    /// Per participant, in ascending sender-id order: the tick of its last queued command.
    last_queued: Vec<(u32, Option<u64>)>,
}

impl Gate {
    /// A gate for `participants` (sorted, unique) on a spacecraft whose effectors' inputs sit at
    /// `input_ranges`; `lockstep` selects the lockstep tick rule.
    pub fn new(participants: &[u32], input_ranges: &[Range<usize>], lockstep: bool) -> Self {
        Self {
            lockstep,
            input_ranges: input_ranges.to_vec(),
            seen: vec![false; input_ranges.len()],
            last_queued: participants.iter().map(|&id| (id, None)).collect(),
        }
    }

    fn slot(&self, sender_id: u32) -> Option<usize> {
        self.last_queued
            .binary_search_by_key(&sender_id, |(id, _)| *id)
            .ok()
    }

    /// Whether `cmd` may be queued now that `published` is the last tick published:
    /// [`Offer::Accepted`], or the reason the book would reject it.
    pub fn check(&mut self, cmd: &CommandMsg, published: u64) -> Offer {
        let Some(i) = self.slot(cmd.sender_id) else {
            return Offer::UnknownSender;
        };
        let tick = cmd.header.tick;
        let last = self.last_queued[i].1;
        let stale = if self.lockstep {
            tick != published || last == Some(tick)
        } else {
            tick > published || last.is_some_and(|l| tick < l)
        };
        if stale {
            return Offer::StaleTick;
        }
        check_inputs(&self.input_ranges, &mut self.seen, cmd).unwrap_or(Offer::Accepted)
    }

    /// Notes that the command of `sender_id` for `tick` (accepted by [`Self::check`]) is in the
    /// queue.
    pub fn queued(&mut self, sender_id: u32, tick: u64) {
        if let Some(i) = self.slot(sender_id) {
            self.last_queued[i].1 = Some(tick);
        }
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
        b.begin_tick(0);
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
        b.begin_tick(0);
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

    fn actuators(sender: u32, tick: u64, index: u32, values: usize) -> CommandMsg {
        CommandMsg::actuators(
            Header::new(1, tick, 0, 0),
            sender,
            [0.0; 3],
            [0.0; 3],
            vec![flexdyn_proto::EffectorInput {
                effector_index: index,
                values: vec![0.1; values],
            }],
        )
    }

    #[test]
    fn the_gate_refuses_ticks_not_published_and_inputs_that_do_not_fit() {
        // Effector 0 takes no input (a panel pair), effector 1 takes one (a wheel).
        let ranges = [0..0, 0..1];
        let mut g = Gate::new(&[1, 2], &ranges, false);
        assert_eq!(g.check(&wrench(1, 11, 1.0), 10), Offer::StaleTick);
        assert_eq!(g.check(&wrench(1, u64::MAX, 1.0), 10), Offer::StaleTick);
        let ok = wrench(1, 10, 1.0);
        assert_eq!(g.check(&ok, 10), Offer::Accepted);
        g.queued(1, 10);
        assert_eq!(g.check(&wrench(1, 9, 1.0), 10), Offer::StaleTick, "older");
        assert_eq!(
            g.check(&wrench(1, 10, 1.0), 10),
            Offer::Accepted,
            "same tick"
        );
        assert_eq!(
            g.check(&wrench(2, 3, 1.0), 10),
            Offer::Accepted,
            "own order"
        );
        assert_eq!(g.check(&wrench(3, 10, 1.0), 10), Offer::UnknownSender);
        assert_eq!(g.check(&actuators(1, 10, 1, 1), 10), Offer::Accepted);
        for (index, values) in [(0, 1), (1, 2), (1, 0), (7, 1)] {
            assert_eq!(
                g.check(&actuators(1, 10, index, values), 10),
                Offer::BadEffectorInput,
                "effector {index} with {values} values"
            );
        }
        let mut twice = actuators(1, 10, 1, 1);
        if let CommandKind::Actuators { inputs, .. } = &mut twice.kind {
            inputs.push(inputs[0].clone());
        }
        assert_eq!(g.check(&twice, 10), Offer::BadEffectorInput);

        let mut g = Gate::new(&[1, 2], &[], true);
        assert_eq!(g.check(&wrench(1, 4, 1.0), 5), Offer::StaleTick);
        assert_eq!(g.check(&wrench(1, 6, 1.0), 5), Offer::StaleTick);
        let answer = none(1, 5);
        assert_eq!(g.check(&answer, 5), Offer::Accepted);
        g.queued(1, 5);
        assert_eq!(g.check(&none(1, 5), 5), Offer::StaleTick, "second answer");
        assert_eq!(g.check(&none(2, 5), 5), Offer::Accepted);
        assert_eq!(g.check(&none(1, 6), 6), Offer::Accepted);
    }

    proptest::proptest! {
        /// Whatever arrives, in whatever order against the boundaries, the book takes every
        /// command the gate let through (so the gate refuses only what cannot be applied, and a
        /// full queue only ever drops a command that would have been applied).
        #[test]
        fn the_book_takes_every_command_the_gate_lets_through(
            lockstep: bool,
            events in proptest::collection::vec((0u8..4, 1u32..=3, -3i64..=3, 0u8..5), 1..200),
        ) {
            let ranges = [0..0, 0..1];
            let participants = [1, 2];
            let mut gate = Gate::new(&participants, &ranges, lockstep);
            let mut book = CommandBook::new(&participants, 10, 1000, StalePolicy::Hold, &ranges);
            let mut queue = std::collections::VecDeque::new();
            // The physics thread is at boundary `k`; `published` is the tick it noted last
            // (it notes `k`, then takes the queue at `k`, then steps to `k + 1`).
            let (mut k, mut published) = (0u64, 0u64);
            book.begin_tick(0);
            for (what, sender, delta, shape) in events {
                if what <= 1 {
                    published = k;
                }
                if what == 0 {
                    while let Some(cmd) = queue.pop_front() {
                        let offer = if lockstep {
                            book.offer_lockstep(&cmd, k)
                        } else {
                            book.offer_latest(&cmd, k)
                        };
                        proptest::prop_assert_eq!(offer, Offer::Accepted, "{:?} at {}", cmd, k);
                    }
                    if !lockstep || book.all_answered() {
                        k += 1;
                        book.begin_tick(k);
                    }
                }
                if what <= 1 {
                    continue;
                }
                let tick = published.saturating_add_signed(delta);
                let cmd = match shape {
                    0 => none(sender, tick),
                    1 => wrench(sender, tick, 1.0),
                    2 => actuators(sender, tick, 1, 1),
                    3 => actuators(sender, tick, 0, 1),
                    _ => actuators(sender, tick, 1, 3),
                };
                if gate.check(&cmd, published) == Offer::Accepted {
                    gate.queued(cmd.sender_id, cmd.header.tick);
                    queue.push_back(cmd);
                }
            }
        }
    }
}
