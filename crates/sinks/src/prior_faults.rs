//! Faults already active when a recording began. A recorder started after a fault's
//! activation never saw its FaultEventMsg; what it does hold is the vehicle's StatusMsg active
//! set (`faults_active_bits`, fault indices 0–255) and the vehicle's served configuration (its
//! `flexdyn/<sc-id>` metadata, whose `config_toml` has the `[[faults]]` entries). From them
//! [`fault_events`] rebuilds the activation event each such fault would have had, so that
//! `plot` and `export` ([`super::fault_spans`]) shade and list it like a recorded one.
//!
//! Fault `i` was active before the recording when a StatusMsg of tick `k` (time `t`) shows bit
//! `i` set while the first recorded event of `i` (if any) comes at a tick after `k + 1` (the
//! active set is read just after the tick, so it may already hold frame `k + 1`'s activations),
//! or when the first recorded event of `i` is a clearance (of edge `e`: active at `e − 1` ns).
//! The earliest such instant is the evidence; then:
//! - a configured fault (index below the number of `[[faults]]` the recorded configuration
//!   resolves to, in the server's order: [`flexdyn_vehicle::config::SimConfig::faults`], a random
//!   `mtbf_s` fault's start drawn from its seed as the server drew it): its activation began at
//!   its window's last start at or before the evidence
//!   ([`flexdyn_faults::FaultWindow::last_start_at`]: the window's own
//!   [`flexdyn_faults::FaultWindow::activation_at`] where the fault is active then, and still the
//!   right start when StatusMsg's active set lags its tick by a frame), with the
//!   configuration's target and mode (a window not yet begun then, which only a configuration
//!   other than the one that ran can give: the recording's first state). Its interval ends at
//!   its first recorded clearance, or with the data.
//! - a live fault (index at or above that number): the recording does not hold its start. When
//!   some event of it is recorded (its clearance), that event names it and it runs from the
//!   recording's first state ([`super::fault_spans::from_events`]); when none is, its target is
//!   unknown too: it gets [`UNKNOWN_TARGET`] and starts at the first state. A target is never
//!   guessed.
//!
//! When the recording has no configuration for the vehicle, or it does not resolve here (a
//! relative file path in it, a newer flexdyn's keys), nothing is rebuilt and a warning says
//! why: the faults are then shaded from their first recorded event only.

use std::collections::BTreeMap;

use flexdyn_proto::{FaultEventMsg, FaultSource, FaultTarget, Header, MAX_STATUS_FAULTS};

use super::fault_spans::UNKNOWN_TARGET;
use super::reader::Recording;
use super::topics::{classify, Decoded, TopicKind};
use flexdyn_faults::FaultSpec;
use flexdyn_vehicle::config::SimConfig;

/// One vehicle's faults as a recording holds them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VehicleFaults {
    /// The activations the recording missed (by fault index), then the recorded events in file
    /// order: what [`super::fault_spans::from_events`] and
    /// [`super::fault_spans::event_comments`] read.
    pub events: Vec<FaultEventMsg>,
    /// \[ns\] the time of the vehicle's first StateMsg (the start of its data; 0 without one).
    pub first_state_ns: u64,
}

/// A StatusMsg's tick, time \[ns\] and active set.
type Status = (u64, u64, [u64; 4]);

/// What the samples of one vehicle say about its faults, before any rebuilding.
#[derive(Default)]
struct Seen {
    /// The recorded events, in file order.
    events: Vec<FaultEventMsg>,
    /// Each StatusMsg's tick, time and active set, in file order.
    statuses: Vec<Status>,
    first_state_ns: Option<u64>,
}

/// Every vehicle's faults in `rec`, by string spacecraft id (vehicles with a StateMsg, fault
/// event or StatusMsg).
pub fn fault_events(rec: &Recording) -> BTreeMap<String, VehicleFaults> {
    let mut seen: BTreeMap<String, Seen> = BTreeMap::new();
    for s in &rec.samples {
        let Some(topic) = classify(&s.key) else {
            continue;
        };
        let kind = topic.kind;
        let first_state = kind == TopicKind::State
            && seen
                .get(topic.sc_id)
                .is_none_or(|v| v.first_state_ns.is_none());
        // Only the first state of each vehicle is decoded.
        if !(first_state || matches!(kind, TopicKind::Status | TopicKind::FaultEvent)) {
            continue;
        }
        let v = seen.entry(topic.sc_id.to_owned()).or_default();
        match Decoded::decode(kind, &s.payload) {
            Ok(Decoded::State(m)) => {
                v.first_state_ns.get_or_insert(m.header.sim_time_ns);
            }
            Ok(Decoded::Status(m)) => {
                v.statuses
                    .push((m.header.tick, m.header.sim_time_ns, m.faults_active_bits))
            }
            Ok(Decoded::FaultEvent(m)) => v.events.push(m),
            _ => {}
        }
    }
    let configs: BTreeMap<String, String> = rec
        .vehicles()
        .into_iter()
        .map(|v| (v.sc_id, v.config_toml))
        .collect();
    seen.into_iter()
        .map(|(sc, v)| {
            let first_state_ns = v.first_state_ns.unwrap_or(0);
            let evidence = active_before(&v.statuses, &v.events);
            let mut events = if evidence.is_empty() {
                Vec::new()
            } else {
                rebuild(&sc, configs.get(&sc), &evidence, &v.events, first_state_ns)
            };
            events.extend(v.events);
            (
                sc,
                VehicleFaults {
                    events,
                    first_state_ns,
                },
            )
        })
        .collect()
}

/// Per fault index active before the recording, the earliest instant \[ns\] it is seen active
/// with no activation of it recorded at or before then (see the module's rule).
fn active_before(statuses: &[Status], events: &[FaultEventMsg]) -> BTreeMap<u32, u64> {
    let mut out: BTreeMap<u32, u64> = BTreeMap::new();
    let mut note = |index: u32, t: u64| {
        out.entry(index)
            .and_modify(|e| *e = (*e).min(t))
            .or_insert(t);
    };
    // Each index's first recorded event.
    let mut first: BTreeMap<u32, &FaultEventMsg> = BTreeMap::new();
    for e in events {
        first.entry(e.fault_index).or_insert(e);
    }
    for (&index, e) in &first {
        if !e.active {
            note(index, e.edge_ns.saturating_sub(1));
        }
    }
    for &(tick, t, bits) in statuses {
        for index in 0..MAX_STATUS_FAULTS as u32 {
            let set = bits
                .get(index as usize / 64)
                .is_some_and(|w| w >> (index % 64) & 1 == 1);
            if set
                && first
                    .get(&index)
                    .is_none_or(|e| e.header.tick > tick.saturating_add(1))
            {
                note(index, t);
            }
        }
    }
    out
}

/// The activation events of the faults in `evidence` (index → the instant seen active), from
/// the vehicle's recorded configuration `config_toml` (see the module's rule).
fn rebuild(
    sc: &str,
    config_toml: Option<&String>,
    evidence: &BTreeMap<u32, u64>,
    recorded: &[FaultEventMsg],
    first_state_ns: u64,
) -> Vec<FaultEventMsg> {
    let specs: Vec<FaultSpec> = match config_toml.map(|t| SimConfig::from_toml_str(t)) {
        Some(Ok(cfg)) => cfg.faults,
        Some(Err(e)) => {
            tracing::warn!(sc_id = %sc, error = %e, "faults were active before the recording began, but the recorded configuration does not resolve here; they are shaded from their first recorded event only");
            return Vec::new();
        }
        None => {
            tracing::warn!(sc_id = %sc, "faults were active before the recording began, but the recording holds no configuration of this vehicle; they are shaded from their first recorded event only");
            return Vec::new();
        }
    };
    let mut out = Vec::new();
    for (&index, &seen_ns) in evidence {
        let event = |start_ns: u64| FaultEventMsg {
            header: Header::new(0, 0, start_ns, 0),
            fault_index: index,
            active: true,
            edge_ns: start_ns,
            ..FaultEventMsg::default()
        };
        match specs.get(index as usize) {
            Some(spec) => {
                let start_ns = spec
                    .window
                    .last_start_at(seen_ns)
                    .unwrap_or(first_state_ns.min(seen_ns));
                out.push(FaultEventMsg {
                    source: spec.source,
                    mode: spec.mode.index() as u32,
                    axes: spec.axes,
                    params: spec.mode.params(),
                    target: FaultTarget::truncated(&spec.target),
                    ..event(start_ns)
                });
            }
            // A live fault some recorded event names: that event is its shading's start.
            None if recorded.iter().any(|e| e.fault_index == index) => {}
            None => out.push(FaultEventMsg {
                source: FaultSource::Live,
                target: FaultTarget::truncated(UNKNOWN_TARGET),
                ..event(first_state_ns)
            }),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// \[ns\] the frame of these tests.
    const FRAME_NS: u64 = 10;

    /// An event at the boundary after `edge_ns` (its tick).
    fn event(index: u32, active: bool, edge_ns: u64) -> FaultEventMsg {
        let tick = edge_ns.div_ceil(FRAME_NS);
        FaultEventMsg {
            header: Header::new(1, tick, tick * FRAME_NS, 0),
            fault_index: index,
            active,
            edge_ns,
            ..FaultEventMsg::default()
        }
    }

    /// A status at `tick` showing `indices` active.
    fn status(tick: u64, indices: &[usize]) -> Status {
        let mut b = [0; 4];
        for i in indices {
            b[i / 64] |= 1 << (i % 64);
        }
        (tick, tick * FRAME_NS, b)
    }

    /// Seen active before any activation of it (a status, or a first event that is a
    /// clearance), at the earliest such instant; an activation recorded up to a frame after a
    /// status explains that status's bit.
    #[test]
    fn evidence_is_an_active_bit_or_a_clearance_with_no_activation_before_it() {
        let statuses = [
            status(30, &[0, 2, 4, 70]),
            status(40, &[0, 1, 2, 4, 70, 255]),
        ];
        let events = [
            // 1: activated at 350, before the status at 400 that shows it.
            event(1, true, 350),
            // 4: activated in the frame after the first status, whose active set already
            // holds it (read just after its tick): not active before.
            event(4, true, 305),
            // 2: cleared at 380 (active before), then a new activation.
            event(2, false, 380),
            event(2, true, 390),
            // 3: cleared at 500, no status shows it: active at 499.
            event(3, false, 500),
            // 0: activated at 450, after both statuses that show it: an earlier activation.
            event(0, true, 450),
        ];
        let got = active_before(&statuses, &events);
        assert_eq!(
            got,
            BTreeMap::from([(0, 300), (2, 300), (3, 499), (70, 300), (255, 400)])
        );
        assert!(active_before(&[status(0, &[])], &[event(1, true, 0)]).is_empty());
    }
}
