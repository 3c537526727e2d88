//! Command-link faults: `[[faults]]` entries whose target is `links.<sender id>`, a participant
//! of `server.participants`. They sit where the server takes that participant's commands in (the
//! command book, `flexdyn_server::commands::CommandBook`), never in the physics, and are evaluated
//! at the tick a command answers (t = k · frame period), so in lockstep they act on the same
//! ticks run after run.
//!
//! - `dropped`: the participant's commands are discarded on arrival (and counted). So that no run
//!   can hang, in lockstep a dropped link counts as *answered with nothing* at every tick of its
//!   window: the barrier does not wait for it, and the participant's last command from before the
//!   window stays held, under `server.stale_policy` like any command that stops coming (`hold`
//!   keeps applying it, flagged stale after `stale_after_s`; `zero` drops it then). If every
//!   participant's link is dropped, the server steps on by itself to the window's end (or the
//!   run's), still stopping on request.
//! - `delayed` (`frames` = N): the participant still answers every tick (the barrier is
//!   unchanged), but what is held over frame k → k + 1 is what it held at tick k − N (the
//!   command it sent for k − N, its age N frames); before tick N, nothing. When the window closes
//!   its current command applies again: the commands of the window's last N ticks are never
//!   applied.
//! - `corrupted` (`probability` = p, the bit error rate): each command's payload (its canonical
//!   encoding, the bytes it arrived as) has each bit flipped with probability p ([`damage`]),
//!   then goes through the same decoder and checks as any command (version, layout, finite
//!   values, spacecraft, sender, tick, effector inputs). A rejected one is counted under its
//!   reason (StatusMsg `rejected.*`) and, in lockstep, answers the tick with nothing; one that
//!   passes every check is applied as damaged. Either way it is counted.
//!
//! Every activation and clearance is logged (`tracing`, naming the participant, the fault and
//! the tick), and the counts are in [`LinkStats`] (the run report's `link_faults`).

use super::modes::FaultMode;
use super::window::FaultWindow;
use super::{FaultSpec, Port};
use flexdyn_sensors::rng::NormalRng;

/// The section of a command-link target (`links.<sender id>`).
pub const SECTION: &str = "links";

/// What the link faults did over a run (plain counts; the server copies them to its report).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// `dropped`: commands discarded on arrival.
    pub commands_dropped: u64,
    /// `dropped`: lockstep ticks a participant was counted as answered with nothing.
    pub empty_answers: u64,
    /// `delayed`: frames over which a delayed command was held.
    pub delayed_frames: u64,
    /// `corrupted`: commands damaged.
    pub commands_corrupted: u64,
    /// `corrupted`: damaged commands the checks rejected (also in `rejected.*`).
    pub corrupted_rejected: u64,
}

impl LinkStats {
    /// Whether nothing was counted.
    pub fn is_zero(&self) -> bool {
        *self == Self::default()
    }
}

/// One command-link fault.
#[derive(Debug, Clone)]
pub struct LinkFault {
    /// Its index among the configuration's faults (the FaultEventMsg's `fault_index`).
    pub fault_index: u32,
    /// Its entry (`faults[2]`).
    pub field: String,
    /// The target as written (`links.1`).
    pub target: String,
    /// The participant.
    pub sender_id: u32,
    /// `Dropped`, `Delayed` or `Corrupted`.
    pub mode: FaultMode,
    /// When it is active (in simulation time; evaluated at t = k · frame period).
    pub window: FaultWindow,
    /// Seed of the damage (`corrupted`).
    pub seed: u64,
    /// \[ns\] cleared from here on (a live clear, [`LinkFaults::clear`]); `u64::MAX`: never.
    pub cleared_from_ns: u64,
    /// Active at the last tick evaluated.
    pub active: bool,
}

/// The command-link faults of one server run.
#[derive(Debug, Clone, Default)]
pub struct LinkFaults {
    faults: Vec<LinkFault>,
    frame_ns: u64,
    /// The last tick evaluated.
    evaluated: Option<u64>,
}

impl LinkFaults {
    /// The link faults among `specs` (a configuration's, in file order) on frames of `frame_ns`.
    pub fn new<'a>(specs: impl IntoIterator<Item = &'a FaultSpec>, frame_ns: u64) -> Self {
        let faults = specs
            .into_iter()
            .enumerate()
            .filter_map(|(i, s)| match s.port {
                Port::Link { sender_id } => Some(LinkFault {
                    fault_index: i as u32,
                    field: format!("faults[{i}]"),
                    target: s.target.clone(),
                    sender_id,
                    mode: s.mode,
                    window: s.window,
                    seed: s.seed,
                    cleared_from_ns: u64::MAX,
                    active: false,
                }),
                _ => None,
            })
            .collect();
        Self {
            faults,
            frame_ns,
            evaluated: None,
        }
    }

    /// Lists what the run changed: each fault's live clear and activity, and the last tick
    /// evaluated; the windows, modes and seeds are the configuration's. Not on the stepping
    /// path.
    pub fn archive(&mut self, a: &mut flexdyn_kernel::archive::Archive<'_>) {
        let Self {
            faults,
            frame_ns: _,
            evaluated,
        } = self;
        a.section("link faults", |a| {
            a.expect_count("command-link faults", faults.len());
            for f in faults.iter_mut() {
                let LinkFault {
                    fault_index,
                    field: _,
                    target: _,
                    sender_id,
                    mode: _,
                    window: _,
                    seed: _,
                    cleared_from_ns,
                    active,
                } = f;
                a.expect_count("a command-link fault's index", *fault_index as usize);
                a.expect_count("a command-link fault's participant", *sender_id as usize);
                a.put(cleared_from_ns);
                a.put(active);
            }
            a.put(evaluated);
        });
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.faults.is_empty()
    }

    /// Every link fault, with whether it was active at the last tick evaluated (the hook for
    /// publishing active faults).
    pub fn faults(&self) -> &[LinkFault] {
        &self.faults
    }

    /// The longest delay \[frames\] of `sender_id`'s `delayed` faults (sizes its delay line).
    pub fn max_delay_frames(&self, sender_id: u32) -> Option<u64> {
        self.faults
            .iter()
            .filter(|f| f.sender_id == sender_id)
            .filter_map(|f| match f.mode {
                FaultMode::Delayed { frames } => Some(frames as u64),
                _ => None,
            })
            .max()
    }

    /// A live clear of fault `fault_index` from `from_ns` on (the same clear the fault's events
    /// and the active set show, [`crate::Faults::install`]); nothing if that fault is
    /// not a link fault. Allocation-free.
    pub fn clear(&mut self, fault_index: u32, from_ns: u64) {
        for f in self
            .faults
            .iter_mut()
            .filter(|f| f.fault_index == fault_index)
        {
            f.cleared_from_ns = f.cleared_from_ns.min(from_ns);
            // The tick evaluated last may be the clear's own: look again.
            self.evaluated = None;
        }
    }

    /// Evaluates every window at tick `k` (once per tick; allocation-free unless it logs an
    /// activation or a clearance).
    pub fn at_tick(&mut self, k: u64) {
        if self.faults.is_empty() || self.evaluated == Some(k) {
            return;
        }
        self.evaluated = Some(k);
        let t_ns = k.saturating_mul(self.frame_ns);
        for f in &mut self.faults {
            let active = t_ns < f.cleared_from_ns && f.window.activation_at(t_ns).is_some();
            if active != f.active {
                f.active = active;
                if active {
                    tracing::warn!(
                        participant = f.sender_id,
                        fault = %f.field,
                        target = %f.target,
                        mode = f.mode.name(),
                        tick = k,
                        "command-link fault active"
                    );
                } else {
                    tracing::info!(
                        participant = f.sender_id,
                        fault = %f.field,
                        target = %f.target,
                        mode = f.mode.name(),
                        tick = k,
                        "command-link fault cleared"
                    );
                }
            }
        }
    }

    fn active_for(&self, sender_id: u32) -> impl Iterator<Item = &LinkFault> {
        self.faults
            .iter()
            .filter(move |f| f.active && f.sender_id == sender_id)
    }

    /// Whether `sender_id`'s link is dropped at the tick evaluated.
    pub fn dropped(&self, sender_id: u32) -> bool {
        self.active_for(sender_id)
            .any(|f| f.mode == FaultMode::Dropped)
    }

    /// The delay \[frames\] of `sender_id`'s link at the tick evaluated (the first active
    /// `delayed` fault's).
    pub fn delay_frames(&self, sender_id: u32) -> Option<u64> {
        self.active_for(sender_id).find_map(|f| match f.mode {
            FaultMode::Delayed { frames } => Some(frames as u64),
            _ => None,
        })
    }

    /// `(seed, probability)` of `sender_id`'s link corruption at the tick evaluated.
    pub fn corruption(&self, sender_id: u32) -> Option<(u64, f64)> {
        self.active_for(sender_id).find_map(|f| match f.mode {
            FaultMode::Corrupted { probability } => Some((f.seed, probability)),
            _ => None,
        })
    }
}

/// Damages a command payload answering tick `tick` under a `corrupted` fault of seed `seed` and
/// bit error rate `probability`: one uniform u per bit from
/// [`NormalRng`] seeded with `seed ⊕ (tick · 0x9e37_79b9_7f4a_7c15)` (wrapping; the golden-ratio
/// constant spreads consecutive ticks), bytes in order, bit 0 (least significant) first; the
/// bit is flipped when u < `probability`. So `probability` = 1 inverts every bit and 0 none;
/// the damage depends on the seed and the tick only, not on when the command arrived.
pub fn damage(bytes: &mut [u8], seed: u64, tick: u64, probability: f64) {
    let mut rng = NormalRng::new(seed ^ tick.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    for b in bytes {
        for bit in 0..8 {
            if rng.uniform01() < probability {
                *b ^= 1 << bit;
            }
        }
    }
}

/// The sender id of a command-link target's name part (`"1"` of `links.1`): a decimal `u32`
/// written without sign or leading zeros, as `server.participants` lists it.
pub(crate) fn sender_of(name: &str) -> Option<u32> {
    let canonical = !name.is_empty()
        && name.bytes().all(|b| b.is_ascii_digit())
        && (name == "0" || !name.starts_with('0'));
    canonical.then(|| name.parse().ok()).flatten()
}

/// The first link fault of `specs` whose participant is not in `participants`, as its
/// `(field, problem)`: the server checks its final participants (after command-line overrides)
/// against the configuration's link faults with this.
pub fn unknown_participant(specs: &[FaultSpec], participants: &[u32]) -> Option<(String, String)> {
    specs.iter().enumerate().find_map(|(i, s)| match s.port {
        Port::Link { sender_id } if !participants.contains(&sender_id) => Some((
            format!("faults[{i}].target"),
            format!(
                "\"{}\": participant {sender_id} is not in server.participants {participants:?}",
                s.target
            ),
        )),
        _ => None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damage_at_the_extremes_and_its_determinism() {
        let healthy: Vec<u8> = (0..=255).collect();
        let mut all = healthy.clone();
        damage(&mut all, 3, 7, 1.0);
        assert!(all.iter().zip(&healthy).all(|(a, h)| *a == !*h));
        let mut none = healthy.clone();
        damage(&mut none, 3, 7, 0.0);
        assert_eq!(none, healthy);
        // p = ½ on 2048 bits: the flips are Binomial(2048, ½), mean 1024, σ ≈ 22.6.
        let flips = |seed, tick| {
            let mut b = healthy.clone();
            damage(&mut b, seed, tick, 0.5);
            let n: u32 = b
                .iter()
                .zip(&healthy)
                .map(|(a, h)| (a ^ h).count_ones())
                .sum();
            (b, n)
        };
        let (a, n) = flips(3, 7);
        assert!((1024 - 5 * 23..=1024 + 5 * 23).contains(&n), "{n} flips");
        assert_eq!(flips(3, 7).0, a, "same seed and tick, same damage");
        assert_ne!(flips(3, 8).0, a, "another tick");
        assert_ne!(flips(4, 7).0, a, "another seed");
    }

    #[test]
    fn sender_ids_are_written_as_participants_lists_them() {
        assert_eq!(sender_of("1"), Some(1));
        assert_eq!(sender_of("0"), Some(0));
        assert_eq!(sender_of("4294967295"), Some(u32::MAX));
        for bad in ["", "01", "+1", "-1", "x", "4294967296", "1.0"] {
            assert_eq!(sender_of(bad), None, "{bad:?}");
        }
    }
}
