//! The server log's account of the faults: each configured fault once at start, and each
//! activation and clearance as it happens, under every driver (physics thread, lockstep core,
//! fleet).
//!
//! Whoever publishes a frame notes its fault events in the vehicle's [`FaultEdges`]
//! ([`super::publish::FramePublisher::publish`], beside the active-fault set: a few atomic adds
//! per event, nothing at all in a frame without events). The vehicle's telemetry thread, which wakes every frame or every
//! 20 ms, sees the count move and writes the log lines ([`FaultLog`]). A fault that activates
//! and clears between two looks is logged with both edges, and a repeated one with its count.

use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

use flexdyn_faults::FaultSpec;
use flexdyn_kernel::numfmt::Num;
use flexdyn_proto::FaultEventMsg;

/// Fault indices the log follows: the width of the active-fault bitset of the StatusMsg.
pub const FAULT_EDGE_SLOTS: usize = 256;

/// One fault index's edges so far.
#[derive(Debug, Default)]
struct Edge {
    activations: AtomicU32,
    clearances: AtomicU32,
    /// \[ns\] simulation time of the last edge.
    last_edge_ns: AtomicU64,
}

/// Per fault index, how many times it activated and cleared, and when it last did (atomics
/// only; allocated once, with the run's counters).
#[derive(Debug)]
pub struct FaultEdges {
    /// Edges noted in all (the telemetry thread looks further only when this moved).
    total: AtomicU64,
    slots: Box<[Edge]>,
}

impl Default for FaultEdges {
    fn default() -> Self {
        Self {
            total: AtomicU64::new(0),
            slots: (0..FAULT_EDGE_SLOTS).map(|_| Edge::default()).collect(),
        }
    }
}

impl FaultEdges {
    /// Notes the edges a frame carries. Allocation- and lock-free.
    pub fn note(&self, events: &[FaultEventMsg]) {
        for ev in events {
            let Some(slot) = usize::try_from(ev.fault_index)
                .ok()
                .and_then(|i| self.slots.get(i))
            else {
                continue;
            };
            let count = if ev.active {
                &slot.activations
            } else {
                &slot.clearances
            };
            count.fetch_add(1, Ordering::Relaxed);
            slot.last_edge_ns.store(ev.edge_ns, Ordering::Relaxed);
            self.total.fetch_add(1, Ordering::Release);
        }
    }

    /// Edges noted so far, every index together.
    pub fn total(&self) -> u64 {
        self.total.load(Ordering::Acquire)
    }

    /// Fault `i`'s (activations, clearances, last edge \[ns\]); zeros past the slots.
    pub fn get(&self, i: usize) -> (u32, u32, u64) {
        self.slots.get(i).map_or((0, 0, 0), |s| {
            (
                s.activations.load(Ordering::Relaxed),
                s.clearances.load(Ordering::Relaxed),
                s.last_edge_ns.load(Ordering::Relaxed),
            )
        })
    }
}

/// `stuck_current on imus.imu_a.gyro, from 3 s` (`, for 2 s`, `, every 10 s` when the window
/// has them).
pub fn describe(spec: &FaultSpec) -> String {
    let s = |ns: u64| Num(ns as f64 / 1e9);
    let mut text = format!(
        "{} on {}, from {} s",
        spec.mode.name(),
        spec.target,
        s(spec.window.start_ns)
    );
    if let Some(d) = spec.window.duration_ns {
        text.push_str(&format!(", for {} s", s(d)));
    }
    if let Some(p) = spec.window.period_ns {
        text.push_str(&format!(", every {} s", s(p)));
    }
    text
}

/// Logs each configured fault once, at start (`vehicle`: a fleet's vehicle id).
pub fn log_configured<'a>(specs: impl IntoIterator<Item = &'a FaultSpec>, vehicle: Option<&str>) {
    for (i, spec) in specs.into_iter().enumerate() {
        match vehicle {
            Some(v) => tracing::info!(
                fault = i,
                "vehicle {v:?}: fault {i} configured: {}",
                describe(spec)
            ),
            None => tracing::info!(fault = i, "fault {i} configured: {}", describe(spec)),
        }
    }
}

/// The telemetry thread's side: what it has logged so far, and the configured faults' names.
#[derive(Debug)]
pub struct FaultLog {
    /// A fleet's vehicle id, which each line then starts with.
    vehicle: Option<String>,
    /// Per configured fault: its description ([`describe`]); a live fault is named by its index.
    names: Vec<String>,
    /// The total last looked at.
    total_seen: u64,
    /// Per index: the (activations, clearances) already logged.
    seen: Vec<(u32, u32)>,
}

impl FaultLog {
    /// A log of the faults `specs` configures.
    pub fn new<'a>(specs: impl IntoIterator<Item = &'a FaultSpec>) -> Self {
        Self {
            vehicle: None,
            names: specs.into_iter().map(describe).collect(),
            total_seen: 0,
            seen: vec![(0, 0); FAULT_EDGE_SLOTS],
        }
    }

    /// Each line naming fleet vehicle `id`.
    pub fn for_vehicle(mut self, id: &str) -> Self {
        self.vehicle = Some(id.to_owned());
        self
    }

    /// Logs the edges noted in `edges` since the last call.
    pub fn catch_up(&mut self, edges: &FaultEdges) {
        let total = edges.total();
        if total == self.total_seen {
            return;
        }
        self.total_seen = total;
        for (i, seen) in self.seen.iter_mut().enumerate() {
            let (on, off, last_ns) = edges.get(i);
            if (on, off) == *seen {
                continue;
            }
            let name = self
                .names
                .get(i)
                .map_or_else(|| "a live fault".to_owned(), Clone::clone);
            let t_s = Num(last_ns as f64 / 1e9);
            let who = self
                .vehicle
                .as_ref()
                .map_or_else(String::new, |v| format!("vehicle {v:?}: "));
            // Activations first: a fault that came and went between two looks reads in order.
            for (edge, now, before) in [("active", on, seen.0), ("cleared", off, seen.1)] {
                let n = now.saturating_sub(before);
                let times = if n > 1 {
                    format!(" ({n} times)")
                } else {
                    String::new()
                };
                if n > 0 {
                    tracing::info!(
                        fault = i,
                        "{who}fault {i} {edge}{times}: {name} (t = {t_s} s)"
                    );
                }
            }
            *seen = (on, off);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::{FaultEventMsg, Header};

    fn event(index: u32, active: bool, edge_ns: u64) -> FaultEventMsg {
        FaultEventMsg {
            header: Header::new(1, 0, edge_ns, 0),
            fault_index: index,
            active,
            edge_ns,
            ..FaultEventMsg::default()
        }
    }

    #[test]
    fn edges_are_counted_per_index_and_out_of_range_ones_are_ignored() {
        let edges = FaultEdges::default();
        edges.note(&[event(0, true, 3_000_000_000), event(5, true, 1)]);
        edges.note(&[
            event(0, false, 4_500_000_000),
            event(0, true, 5_000_000_000),
        ]);
        edges.note(&[event(FAULT_EDGE_SLOTS as u32, true, 7)]);
        assert_eq!(edges.total(), 4);
        assert_eq!(edges.get(0), (2, 1, 5_000_000_000));
        assert_eq!(edges.get(5), (1, 0, 1));
        assert_eq!(edges.get(FAULT_EDGE_SLOTS), (0, 0, 0));
        let mut log = FaultLog::new(&[]);
        log.catch_up(&edges);
        assert_eq!(
            (log.seen[0], log.seen[5], log.total_seen),
            ((2, 1), (1, 0), 4)
        );
        // Nothing new: nothing looked at.
        log.catch_up(&edges);
        assert_eq!(log.total_seen, 4);
    }
}
