//! State shared between the physics thread and the I/O side: lock-free counters and the
//! preallocated telemetry buffers that cycle between them.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, Ordering};

use flexdyn_proto::{
    CommandStatus, DecodeError, EffectorState, RejectCounters, RunState, StateMsg,
};

use super::commands::Held;

/// \[bytes\] room reserved for each sensor's encoded message (an `ImuMsg` is 127 bytes), so
/// encoding on the stepping path does not allocate.
pub const SENSOR_PAYLOAD_CAPACITY: usize = 512;

/// One frame's telemetry, filled by the physics thread and published by the I/O thread. A
/// fixed pool of these is allocated at start-up and cycled through two bounded channels
/// (free → physics fills → I/O publishes → free), so the stepping path never allocates.
#[derive(Debug)]
pub struct Frame {
    /// The time message of this tick (published first).
    pub time: flexdyn_proto::TimeMsg,
    /// The state message, `effectors` preallocated to the spacecraft's effector layout.
    pub state: StateMsg,
    /// \[ns since the Unix epoch\] wall clock at the frame boundary, sent as the sample's
    /// attachment (never in the deterministic payload).
    pub boundary_unix_ns: u64,
    /// \[ns\] lateness of the boundary against its real-time deadline (0 outside real time).
    pub lateness_ns: u64,
    /// Command bookkeeping of the frame that ended at this tick.
    pub command: CommandStatus,
    /// The sensors sampled at this tick, as indices into the sensor bank (publication order).
    pub sensors_sampled: Vec<usize>,
    /// Per sensor of the bank, its encoded message when it is in `sensors_sampled`.
    pub sensor_payloads: Vec<Vec<u8>>,
    /// The environment message of this tick, when due (`[environment] telemetry_rate_hz`),
    /// published after the state.
    pub environment: Option<flexdyn_proto::EnvironmentMsg>,
    /// Already published by the thread that finished the frame (`handoff = "direct"`): the
    /// telemetry thread only records it and keeps the books.
    pub published: bool,
    /// The fault activations and clearances seen up to this tick and not yet published
    /// (FaultEventMsg, after the state), within the capacity reserved
    /// ([`Self::with_fault_events`]); more wait for the next frame.
    pub fault_events: Vec<flexdyn_proto::FaultEventMsg>,
    /// The faults active at this tick: count and the bits of indices 0–255 (StatusMsg).
    pub faults_active: (u64, [u64; 4]),
}

impl Frame {
    /// An empty frame whose state has `shape`'s effector layout (see
    /// [`flexdyn_vehicle::sim::Simulation::blank_state`]), with room for the messages of `n_sensors`
    /// sensors.
    pub fn for_state(shape: &StateMsg, n_sensors: usize) -> Self {
        Self {
            time: flexdyn_proto::TimeMsg::default(),
            state: shape.clone(),
            boundary_unix_ns: 0,
            lateness_ns: 0,
            command: Held::initial(flexdyn_proto::StalePolicy::Hold).status,
            sensors_sampled: Vec::with_capacity(n_sensors),
            // Not `vec![..; n]`: a cloned Vec does not keep its capacity.
            sensor_payloads: (0..n_sensors)
                .map(|_| Vec::with_capacity(SENSOR_PAYLOAD_CAPACITY))
                .collect(),
            environment: None,
            published: false,
            fault_events: Vec::new(),
            faults_active: (0, [0; 4]),
        }
    }

    /// Room for `n` fault events per frame (the simulation's
    /// [`flexdyn_faults::Faults::event_capacity`]), so filling them does not allocate.
    pub fn with_fault_events(mut self, n: usize) -> Self {
        self.fault_events = Vec::with_capacity(n);
        self
    }
}

/// Copies the state record `state` (filled by [`flexdyn_vehicle::sim::Simulation::state_into`]) into
/// `out` with the frame's `header` and the command bookkeeping of `held`, without allocating
/// (`out` has the same effector layout: [`Frame::for_state`]).
pub fn fill_state(
    out: &mut StateMsg,
    state: &StateMsg,
    header: flexdyn_proto::Header,
    held: &Held,
) {
    let effectors = std::mem::take(&mut out.effectors);
    *out = StateMsg {
        header,
        wrench_applied: flexdyn_proto::AppliedWrench {
            torque_b_nm: held.torque_b_nm,
            force_b_newton: held.force_b_newton,
        },
        command_flags: held.flags,
        effectors,
        ..*state
    };
    out.effectors
        .resize_with(state.effectors.len(), EffectorState::default);
    for (o, e) in out.effectors.iter_mut().zip(&state.effectors) {
        o.kind = e.kind;
        o.flags = e.flags;
        o.states.clear();
        o.states.extend_from_slice(&e.states);
        o.outputs.clear();
        o.outputs.extend_from_slice(&e.outputs);
    }
}

/// \[ns\] a direct publication slower than this is counted as slow (a tenth of a 1 kHz frame).
pub const SLOW_PUBLISH_NS: u64 = 100_000;

/// Counters and flags shared by every thread of a run (atomics only, no locks).
#[derive(Debug, Default)]
pub struct Shared {
    /// Set to ask the physics loop to stop at the next frame boundary.
    pub stop: AtomicBool,
    /// Every fault activation and clearance handed out, per fault index (for the log).
    pub fault_edges: super::fault_log::FaultEdges,
    /// [`RunState`] as its wire tag.
    run_state: AtomicU8,
    /// The last frame boundary reached, noted before its state is published.
    pub tick: AtomicU64,
    malformed: AtomicU64,
    bad_version: AtomicU64,
    non_finite: AtomicU64,
    wrong_spacecraft: AtomicU64,
    stale_tick: AtomicU64,
    unknown_sender: AtomicU64,
    bad_effector_input: AtomicU64,
    wrong_identity: AtomicU64,
    operator_refused: AtomicU64,
    fault_refused: AtomicU64,
    fsw_refused: AtomicU64,
    /// Flight-code telemetry samples accepted (`flexdyn/<sc>/fsw/*`, recorded when recording).
    pub fsw_recorded: AtomicU64,
    /// Fault requests the physics side refused ([`flexdyn_faults::ports::INSTALL_REFUSALS`]),
    /// and the code of the last one, for the telemetry thread's log.
    pub faults_refused_physics: AtomicU64,
    /// See [`Self::faults_refused_physics`].
    pub last_fault_refusal: AtomicU8,
    /// The faults active at the last frame published: their count and the bits of indices
    /// 0–255 ([`flexdyn_proto::StatusMsg::faults_active_bits`]), stored by whoever publishes
    /// the frame (atomics: the physics side never waits for StatusMsg).
    faults_active: AtomicU64,
    faults_active_bits: [AtomicU64; 4],
    /// The operator's hold target (`flexdyn/<sc>/operator`): 0 = none, `h + 1` = hold at the
    /// first frame boundary `k ≥ h` (see [`Self::holds_at`]). Set by the operator callback, read
    /// by whoever steps the frames (one atomic load per frame).
    hold_target: AtomicU64,
    /// Whether the frames are held now, at [`Self::tick`].
    pub held: AtomicBool,
    /// StateMsg samples published (by whichever thread publishes).
    pub published: AtomicU64,
    /// Zenoh `put` failures of telemetry samples.
    pub publish_errors: AtomicU64,
    /// The command bookkeeping of the last state published ([`CommandStatus`] in three
    /// atomics; StatusMsg reads it, a torn read between them is harmless there).
    last_command_tick: AtomicU64,
    command_age_ns: AtomicU64,
    command_stale: AtomicBool,
    /// Valid commands dropped because the command queue was full.
    pub commands_dropped: AtomicU64,
    /// Real time: frames whose work overran the next deadline.
    pub overruns: AtomicU64,
    /// Real time, `skip` policy: deadlines dropped.
    pub frames_skipped: AtomicU64,
    /// Real time: when each of the first overrun frames started and ended.
    pub overrun_log: OverrunLog,
    /// Real time: frames whose telemetry was dropped (no free buffer).
    pub telemetry_dropped: AtomicU64,
    /// Real time: frames the physics thread handed off, and the total and largest time the
    /// handoff took there (ns): with `handoff = "direct"` the put, and either way the channel
    /// to the telemetry thread and its wake-up.
    pub handoffs: AtomicU64,
    /// See [`Self::handoffs`].
    pub handoff_ns_total: AtomicU64,
    /// See [`Self::handoffs`].
    pub handoff_ns_max: AtomicU64,
    /// Handoffs that took longer than [`SLOW_PUBLISH_NS`].
    pub handoffs_slow: AtomicU64,
    /// `stale_tick` rejections per participant (sender id, count), in ascending id order, so
    /// the telemetry thread can name the sender in its warning (the physics thread only counts).
    pub stale_by_participant: Vec<(u32, AtomicU64)>,
    /// What the command-link faults did ([`flexdyn_faults::link::LinkStats`], copied from the
    /// command book after each frame): dropped, empty answers, delayed frames, corrupted,
    /// corrupted and rejected.
    link_stats: [AtomicU64; 5],
}

/// Overrun frames whose times [`OverrunLog`] keeps (the first ones of a run).
pub const OVERRUN_LOG_LEN: usize = 1024;

/// Start and end \[ns, [`super::rt::monotonic_ns`]\] of the first [`OVERRUN_LOG_LEN`] overrun
/// frames, preallocated: noting one is two atomic stores, so the physics thread can do it.
#[derive(Debug)]
pub struct OverrunLog {
    start_ns: Box<[AtomicU64]>,
    end_ns: Box<[AtomicU64]>,
    noted: AtomicU64,
}

impl Default for OverrunLog {
    fn default() -> Self {
        let zeros = || (0..OVERRUN_LOG_LEN).map(|_| AtomicU64::new(0)).collect();
        Self {
            start_ns: zeros(),
            end_ns: zeros(),
            noted: AtomicU64::new(0),
        }
    }
}

impl OverrunLog {
    /// Notes an overrun frame (allocation-free; past the capacity it is only counted).
    pub fn note(&self, start_ns: u64, end_ns: u64) {
        let i = self.noted.fetch_add(1, Ordering::Relaxed) as usize;
        if let (Some(s), Some(e)) = (self.start_ns.get(i), self.end_ns.get(i)) {
            s.store(start_ns, Ordering::Relaxed);
            e.store(end_ns, Ordering::Relaxed);
        }
    }

    /// The (start, end) of the overrun frames noted, in order (at most [`OVERRUN_LOG_LEN`]).
    pub fn frames(&self) -> Vec<(u64, u64)> {
        let n = (self.noted.load(Ordering::Relaxed) as usize).min(OVERRUN_LOG_LEN);
        (0..n)
            .map(|i| {
                (
                    self.start_ns[i].load(Ordering::Relaxed),
                    self.end_ns[i].load(Ordering::Relaxed),
                )
            })
            .collect()
    }
}

fn bump(c: &AtomicU64) {
    c.fetch_add(1, Ordering::Relaxed);
}

impl Shared {
    /// Counters for a run whose participants are `participants` (sorted).
    pub fn new(participants: &[u32]) -> Self {
        Self {
            stale_by_participant: participants
                .iter()
                .map(|&id| (id, AtomicU64::new(0)))
                .collect(),
            ..Self::default()
        }
    }

    /// Count a stale-tick command of participant `sender_id` (allocation-free).
    pub fn reject_stale_tick_from(&self, sender_id: u32) {
        bump(&self.stale_tick);
        if let Ok(i) = self
            .stale_by_participant
            .binary_search_by_key(&sender_id, |(id, _)| *id)
        {
            bump(&self.stale_by_participant[i].1);
        }
    }

    /// Count an undecodable command under its reason.
    pub fn reject_decode(&self, e: &DecodeError) {
        match e {
            DecodeError::UnknownVersion { .. } => bump(&self.bad_version),
            DecodeError::NonFinite { .. } => bump(&self.non_finite),
            _ => bump(&self.malformed),
        }
    }

    /// Count a damaged command (a `corrupted` command link) under the reason it was rejected.
    pub fn reject_damaged(&self, why: super::commands::Damaged, sender_id: u32) {
        use super::commands::Damaged;
        match why {
            Damaged::Malformed => bump(&self.malformed),
            Damaged::BadVersion => bump(&self.bad_version),
            Damaged::NonFinite => bump(&self.non_finite),
            Damaged::WrongSpacecraft => bump(&self.wrong_spacecraft),
            Damaged::WrongIdentity => bump(&self.wrong_identity),
            Damaged::StaleTick => self.reject_stale_tick_from(sender_id),
            Damaged::BadEffectorInput => bump(&self.bad_effector_input),
        }
    }

    /// Notes what the command-link faults did so far (allocation-free).
    pub fn note_link_stats(&self, s: &flexdyn_faults::link::LinkStats) {
        let v = [
            s.commands_dropped,
            s.empty_answers,
            s.delayed_frames,
            s.commands_corrupted,
            s.corrupted_rejected,
        ];
        for (c, v) in self.link_stats.iter().zip(v) {
            c.store(v, Ordering::Relaxed);
        }
    }

    /// What the command-link faults did so far.
    pub fn link_stats(&self) -> flexdyn_faults::link::LinkStats {
        let l = |i: usize| self.link_stats[i].load(Ordering::Relaxed);
        flexdyn_faults::link::LinkStats {
            commands_dropped: l(0),
            empty_answers: l(1),
            delayed_frames: l(2),
            commands_corrupted: l(3),
            corrupted_rejected: l(4),
        }
    }

    /// Count a command for another spacecraft.
    pub fn reject_wrong_spacecraft(&self) {
        bump(&self.wrong_spacecraft);
    }

    /// Count a command from an unknown sender.
    pub fn reject_unknown_sender(&self) {
        bump(&self.unknown_sender);
    }

    /// Count an `Actuators` command whose inputs do not fit the effectors.
    pub fn reject_bad_effector_input(&self) {
        bump(&self.bad_effector_input);
    }

    /// Notes how long a handoff on the physics thread took.
    pub fn note_handoff(&self, ns: u64) {
        self.handoffs.fetch_add(1, Ordering::Relaxed);
        if ns > SLOW_PUBLISH_NS {
            self.handoffs_slow.fetch_add(1, Ordering::Relaxed);
        }
        self.handoff_ns_total.fetch_add(ns, Ordering::Relaxed);
        self.handoff_ns_max.fetch_max(ns, Ordering::Relaxed);
    }

    /// Count an operator command the server did not apply.
    pub fn reject_operator(&self) {
        bump(&self.operator_refused);
    }

    /// Count a fault command the server did not apply.
    pub fn reject_fault(&self) {
        bump(&self.fault_refused);
    }

    /// Count a flight-code telemetry sample the server did not record.
    pub fn reject_fsw(&self) {
        bump(&self.fsw_refused);
    }

    /// Count a fault request the physics side refused, with its reason's code
    /// (allocation- and lock-free).
    pub fn reject_fault_physics(&self, code: u8) {
        self.last_fault_refusal.store(code, Ordering::Relaxed);
        bump(&self.faults_refused_physics);
        bump(&self.fault_refused);
    }

    /// Notes the faults active at the frame just published (allocation- and lock-free).
    pub fn set_faults_active(&self, count: u64, bits: &[u64; 4]) {
        self.faults_active.store(count, Ordering::Relaxed);
        for (a, b) in self.faults_active_bits.iter().zip(bits) {
            a.store(*b, Ordering::Relaxed);
        }
    }

    /// The faults active at the last frame published: (count, bits), as StatusMsg carries them.
    pub fn faults_active(&self) -> (u64, [u64; 4]) {
        let l = |c: &AtomicU64| c.load(Ordering::Relaxed);
        (
            l(&self.faults_active),
            [
                l(&self.faults_active_bits[0]),
                l(&self.faults_active_bits[1]),
                l(&self.faults_active_bits[2]),
                l(&self.faults_active_bits[3]),
            ],
        )
    }

    /// The operator's hold target: hold at the first frame boundary at or after this tick.
    pub fn hold_target(&self) -> Option<u64> {
        self.hold_target.load(Ordering::Acquire).checked_sub(1)
    }

    /// Sets (or, with `None`, clears) the hold target.
    pub fn set_hold_target(&self, target: Option<u64>) {
        let v = target.map_or(0, |h| h.saturating_add(1));
        self.hold_target.store(v, Ordering::Release);
    }

    /// Whether the frame of tick `k` is to be held (allocation- and lock-free: one load).
    pub fn holds_at(&self, k: u64) -> bool {
        self.hold_target().is_some_and(|h| k >= h)
    }

    /// Count a command whose `sender_id` is not the one its key names.
    pub fn reject_wrong_identity(&self) {
        bump(&self.wrong_identity);
    }

    /// Notes the command bookkeeping of the state just published.
    pub fn set_last_command(&self, c: &CommandStatus) {
        self.last_command_tick
            .store(c.last_command_tick, Ordering::Relaxed);
        self.command_age_ns
            .store(c.command_age_ns, Ordering::Relaxed);
        self.command_stale.store(c.command_stale, Ordering::Relaxed);
    }

    /// The command bookkeeping of the last state published (before any: no command yet).
    pub fn last_command(&self, policy: flexdyn_proto::StalePolicy) -> CommandStatus {
        if self.published.load(Ordering::Relaxed) == 0 {
            return super::commands::Held::initial(policy).status;
        }
        CommandStatus {
            last_command_tick: self.last_command_tick.load(Ordering::Relaxed),
            command_age_ns: self.command_age_ns.load(Ordering::Relaxed),
            command_stale: self.command_stale.load(Ordering::Relaxed),
            stale_policy: policy,
        }
    }

    /// The rejection counters so far.
    pub fn rejected(&self) -> RejectCounters {
        let l = |c: &AtomicU64| c.load(Ordering::Relaxed);
        RejectCounters {
            malformed: l(&self.malformed),
            bad_version: l(&self.bad_version),
            non_finite: l(&self.non_finite),
            wrong_spacecraft: l(&self.wrong_spacecraft),
            stale_tick: l(&self.stale_tick),
            unknown_sender: l(&self.unknown_sender),
            bad_effector_input: l(&self.bad_effector_input),
            wrong_identity: l(&self.wrong_identity),
            operator_refused: l(&self.operator_refused),
            fault_refused: l(&self.fault_refused),
            fsw_refused: l(&self.fsw_refused),
        }
    }

    /// Sets the life-cycle state.
    pub fn set_run_state(&self, s: RunState) {
        // Every tag fits a u8 (seven states).
        self.run_state.store(s.tag() as u8, Ordering::Release);
    }

    /// The life-cycle state.
    pub fn run_state(&self) -> RunState {
        RunState::from_tag(self.run_state.load(Ordering::Acquire).into())
            .unwrap_or(RunState::Failed)
    }
}
