//! Fault intervals for `flexdyn plot`: when each fault was active, from a recording's fault
//! events (`tlm/fault`) or from a `simulate` CSV's `# fault=…` comment lines, and which panels
//! show the faulted component.
//!
//! - A recording: each FaultEventMsg's `edge_ns` is the window's own edge (an activation's
//!   start, a clearance's end), so an activation and the next clearance of the same
//!   `fault_index` bound one interval exactly. A fault still active when the recording ends
//!   runs to its last instant; a clearance with no activation before it (a recording started
//!   while the fault was active) starts at its first.
//! - A `simulate` CSV: one comment line per configured fault, before the header,
//!   `# fault=<index>,<start_ns>,<duration_ns>,<period_ns>,<mode>,<target>` — the fault's
//!   window as the configuration resolves it (a random fault's drawn start included; an empty
//!   duration: until the end of the run; an empty period: once). Lossless: the activations
//!   are [`FaultWindow::activation_at`]'s, expanded over the rows' time span.
//!
//! - A fault already active when the recording began: [`super::prior_faults`] rebuilds the
//!   activation event the recorder missed, placed before the recorded events, so both readings
//!   above take it like any other (a configured fault from its window, so its interval starts
//!   before the data; a live fault with no event in the recording has an unknown target,
//!   [`UNKNOWN_TARGET`], and starts at the recording's first state).
//!
//! A panel names the components it shows ([`super::plot::Panel::components`]: a component
//! `imus.hub`, or a whole section `reaction_wheels` when one panel draws every wheel); a fault
//! is shaded on the panels whose components its target lies in ([`shows`]). The intervals are
//! when the fault was active, not clipped to the data (the drawing clips them to the axes).

use flexdyn_proto::FaultEventMsg;

use flexdyn_faults::modes::MODES;
use flexdyn_faults::{FaultSpec, FaultWindow};

/// The comment key of a fault's window in a `simulate` CSV.
pub const CSV_KEY: &str = "fault";

/// The target of a fault the recording does not name: a live fault injected before the
/// recording began and neither cleared nor re-activated in it ([`super::prior_faults`]). Its
/// `# fault=` line has this (empty) target and the mode [`UNKNOWN_TARGET_MODE`]; `plot` shades
/// it on the panels whose components include it (the attitude figure's), never on a
/// component's.
pub const UNKNOWN_TARGET: &str = "";
/// The mode field of a fault with [`UNKNOWN_TARGET`]: its mode is unknown too, its source is
/// not.
pub const UNKNOWN_TARGET_MODE: &str = "live";

/// Most activations of one fault drawn one by one; a repeating fault with more in the plotted
/// span is shaded as one interval from its first activation on (said in the log).
pub const MAX_INTERVALS: usize = 10_000;

/// One fault's shading: its legend entry and the intervals \[s\] it was active.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultShading {
    /// The fault's index (its `[[faults]]` entry; live faults after the configured ones).
    pub fault_index: u32,
    /// Its target as written (`imus.hub.gyro`).
    pub target: String,
    /// The legend entry: `fault <index>: <target> <mode>`.
    pub label: String,
    /// \[s\] the intervals it was active, in time order.
    pub spans: Vec<(f64, f64)>,
}

/// A mode's name from its wire code (`mode <code>` for a code this build does not know).
pub fn mode_name(code: u32) -> String {
    MODES
        .get(code as usize)
        .map_or_else(|| format!("mode {code}"), |(n, _)| (*n).to_owned())
}

/// \[s\] `ns / 1e9`, one correctly rounded division, as the tables' `t_s` cells.
fn seconds(ns: u64) -> f64 {
    ns as f64 / 1e9
}

fn label(index: u32, target: &str, mode: &str) -> String {
    if target == UNKNOWN_TARGET {
        format!("fault {index}: live, injected before the recording (target unknown)")
    } else {
        format!("fault {index}: {target} {mode}")
    }
}

/// An event's target and mode name ([`UNKNOWN_TARGET_MODE`] when its target is unknown).
fn target_and_mode(e: &FaultEventMsg) -> (String, String) {
    let target = e.target.as_str().unwrap_or_default().to_owned();
    let mode = if target == UNKNOWN_TARGET {
        UNKNOWN_TARGET_MODE.to_owned()
    } else {
        mode_name(e.mode)
    };
    (target, mode)
}

/// Whether a panel showing `component` (`imus.hub`, or a section such as `reaction_wheels`)
/// shows the fault's `target`: the target is the component or lies inside it
/// (`imus.hub.gyro` in `imus.hub`, `reaction_wheels.rw2` in `reaction_wheels`).
pub fn shows(component: &str, target: &str) -> bool {
    target == component
        || target
            .strip_prefix(component)
            .is_some_and(|rest| rest.starts_with('.'))
}

/// The intervals of one vehicle's fault events (in publication order) over data spanning
/// `[t_first_s, t_last_s]`, one shading per fault index, in index order.
pub fn from_events(events: &[FaultEventMsg], t_first_s: f64, t_last_s: f64) -> Vec<FaultShading> {
    let mut out: Vec<FaultShading> = Vec::new();
    // Per fault index: the start [s] of the activation in force.
    let mut open: std::collections::BTreeMap<u32, f64> = Default::default();
    for e in events {
        let (target, mode) = target_and_mode(e);
        let at = seconds(e.edge_ns);
        let i = match out.iter().position(|s| s.fault_index == e.fault_index) {
            Some(i) => i,
            None => {
                out.push(FaultShading {
                    fault_index: e.fault_index,
                    label: label(e.fault_index, &target, &mode),
                    target,
                    spans: Vec::new(),
                });
                out.len() - 1
            }
        };
        if e.active {
            open.entry(e.fault_index).or_insert(at);
        } else {
            let start = open.remove(&e.fault_index).unwrap_or(t_first_s);
            out[i].spans.push((start, at));
        }
    }
    for (index, start) in open {
        if let Some(s) = out.iter_mut().find(|s| s.fault_index == index) {
            s.spans.push((start, t_last_s.max(start)));
        }
    }
    out.sort_by_key(|s| s.fault_index);
    out
}

/// The CSV comment (without `# `) of the configured fault `index`: its resolved window.
pub fn csv_comment(index: usize, spec: &FaultSpec) -> String {
    let opt = |v: Option<u64>| v.map_or(String::new(), |v| v.to_string());
    format!(
        "{CSV_KEY}={index},{},{},{},{},{}",
        spec.window.start_ns,
        opt(spec.window.duration_ns),
        opt(spec.window.period_ns),
        spec.mode.name(),
        spec.target
    )
}

/// The CSV comments (without `# `) of a vehicle's recorded fault events (publication order):
/// one per activation, its window with no period (`flexdyn export`'s state CSV, so that
/// `plot` shades the same intervals from it as from the recording). A clearance with no
/// activation before it starts at `first_ns`; an activation never cleared has no duration.
pub fn event_comments(events: &[FaultEventMsg], first_ns: u64) -> Vec<String> {
    let mut open: std::collections::BTreeMap<u32, &FaultEventMsg> = Default::default();
    let mut out = Vec::new();
    let line = |e: &FaultEventMsg, start_ns: u64, end_ns: Option<u64>| {
        let (target, mode) = target_and_mode(e);
        format!(
            "{CSV_KEY}={},{start_ns},{},,{mode},{target}",
            e.fault_index,
            end_ns.map_or(String::new(), |end| end
                .saturating_sub(start_ns)
                .to_string()),
        )
    };
    for e in events {
        if e.active {
            open.entry(e.fault_index).or_insert(e);
        } else {
            let start_ns = open.remove(&e.fault_index).map_or(first_ns, |a| a.edge_ns);
            out.push(line(e, start_ns, Some(e.edge_ns)));
        }
    }
    out.extend(open.values().map(|a| line(a, a.edge_ns, None)));
    out
}

/// One `# fault=…` comment's fault: index, window, mode, target. `Err` says what is wrong.
pub fn parse_csv_comment(value: &str) -> Result<(u32, FaultWindow, String, String), String> {
    let f: Vec<&str> = value.splitn(6, ',').collect();
    let &[index, start, duration, period, mode, target] = f.as_slice() else {
        return Err(format!(
            "expected {CSV_KEY}=<index>,<start_ns>,<duration_ns>,<period_ns>,<mode>,<target>, \
             got {value:?}"
        ));
    };
    let int = |name: &str, v: &str| {
        v.parse::<u64>()
            .map_err(|e| format!("{name} {v:?}: {e} (a whole number of nanoseconds)"))
    };
    let opt = |name: &str, v: &str| (!v.is_empty()).then(|| int(name, v)).transpose();
    let index = index
        .parse::<u32>()
        .map_err(|e| format!("index {index:?}: {e}"))?;
    let window = FaultWindow {
        start_ns: int("start_ns", start)?,
        duration_ns: opt("duration_ns", duration)?,
        period_ns: opt("period_ns", period)?,
    };
    if window.period_ns == Some(0) {
        return Err("period_ns must be > 0".into());
    }
    Ok((index, window, mode.to_owned(), target.to_owned()))
}

/// The activations of `window` \[s\] over data spanning `[t_first_s, t_last_s]`: each
/// `[start, end]` that reaches into the span, its end clipped to `t_last_s` (the open-ended one
/// ends there); a start before the data is kept (the fault was active from then on).
pub fn window_spans(window: &FaultWindow, t_first_s: f64, t_last_s: f64) -> Vec<(f64, f64)> {
    let s = seconds;
    let last_ns = (t_last_s * 1e9).round().max(0.0) as u64;
    let mut out = Vec::new();
    let mut start_ns = window.start_ns;
    while start_ns <= last_ns {
        let end = window
            .duration_ns
            .map_or(t_last_s, |d| s(start_ns.saturating_add(d)).min(t_last_s));
        if end >= t_first_s {
            out.push((s(start_ns), end));
        }
        let Some(p) = window.period_ns else { break };
        if out.len() == MAX_INTERVALS {
            tracing::warn!(
                activations = MAX_INTERVALS,
                "a repeating fault activates more often than can be drawn one by one; shading \
                 the rest of the run as one interval"
            );
            out.push((s(start_ns.saturating_add(p)), t_last_s));
            break;
        }
        start_ns = start_ns.saturating_add(p);
        if start_ns == u64::MAX {
            break;
        }
    }
    out
}

/// The shading of a `simulate` CSV fault over data spanning `[t_first_s, t_last_s]`.
pub fn from_window(
    index: u32,
    window: &FaultWindow,
    mode: &str,
    target: &str,
    t_first_s: f64,
    t_last_s: f64,
) -> FaultShading {
    FaultShading {
        fault_index: index,
        target: target.to_owned(),
        label: label(index, target, mode),
        spans: window_spans(window, t_first_s, t_last_s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::{FaultTarget, Header};

    fn event(index: u32, active: bool, edge_ns: u64, target: &str) -> FaultEventMsg {
        FaultEventMsg {
            header: Header::new(1, 0, edge_ns, 0),
            fault_index: index,
            mode: 11,
            active,
            edge_ns,
            target: FaultTarget::truncated(target),
            ..FaultEventMsg::default()
        }
    }

    #[test]
    fn events_pair_into_intervals_and_open_ones_run_to_the_edges_of_the_data() {
        let ev = [
            // Cleared before any activation was recorded: from the first instant.
            event(2, false, 500_000_000, "links.1"),
            event(0, true, 1_000_000_000, "imus.hub.gyro"),
            event(1, true, 1_500_000_000, "reaction_wheels.rw2"),
            event(0, false, 2_000_000_000, "imus.hub.gyro"),
            event(0, true, 3_000_000_000, "imus.hub.gyro"),
        ];
        let s = from_events(&ev, 0.1, 9.0);
        assert_eq!(s.len(), 3);
        assert_eq!(s[0].spans, vec![(1.0, 2.0), (3.0, 9.0)]);
        assert_eq!(s[0].label, "fault 0: imus.hub.gyro seized");
        assert_eq!(s[1].spans, vec![(1.5, 9.0)]);
        assert_eq!(s[2].spans, vec![(0.1, 0.5)]);
    }

    /// Export's comments, read back as windows, give the recording's intervals.
    #[test]
    fn event_comments_read_back_to_the_events_intervals() {
        let ev = [
            event(2, false, 500_000_000, "links.1"),
            event(0, true, 1_000_000_000, "imus.hub.gyro"),
            event(0, false, 2_000_000_000, "imus.hub.gyro"),
            event(0, true, 3_000_000_000, "imus.hub.gyro"),
        ];
        let lines = event_comments(&ev, 100_000_000);
        assert_eq!(
            lines,
            [
                "fault=2,100000000,400000000,,seized,links.1",
                "fault=0,1000000000,1000000000,,seized,imus.hub.gyro",
                "fault=0,3000000000,,,seized,imus.hub.gyro",
            ]
        );
        let mut spans = Vec::new();
        for l in &lines {
            let (i, w, _, _) = parse_csv_comment(l.strip_prefix("fault=").unwrap()).unwrap();
            spans.push((i, window_spans(&w, 0.1, 9.0)));
        }
        let from_ev = from_events(&ev, 0.1, 9.0);
        assert_eq!(spans[0], (2, from_ev[1].spans.clone()));
        assert_eq!(
            [spans[1].1.clone(), spans[2].1.clone()].concat(),
            from_ev[0].spans
        );
    }

    #[test]
    fn a_target_is_shown_by_its_component_and_its_section_only() {
        assert!(shows("imus.hub", "imus.hub.gyro"));
        assert!(shows("imus.hub", "imus.hub"));
        assert!(!shows("imus.hub", "imus.hub2.gyro"));
        assert!(shows("reaction_wheels", "reaction_wheels.rw2"));
        assert!(!shows("reaction_wheels", "magnetorquers.m1"));
        assert!(shows("links", "links.1"));
    }

    #[test]
    fn a_csv_comment_round_trips_and_expands_to_the_windows_activations() {
        let spec = FaultSpec {
            target: "imus.hub.gyro".into(),
            mode: flexdyn_faults::FaultMode::BiasStep { value: 0.1 },
            window: FaultWindow {
                start_ns: 100_000_000,
                duration_ns: Some(50_000_000),
                period_ns: Some(200_000_000),
            },
            axes: 0,
            seed: 0,
            port: flexdyn_faults::Port::Link { sender_id: 1 },
            source: flexdyn_proto::FaultSource::Config,
        };
        let c = csv_comment(3, &spec);
        assert_eq!(
            c,
            "fault=3,100000000,50000000,200000000,bias_step,imus.hub.gyro"
        );
        let (i, w, mode, target) = parse_csv_comment(c.strip_prefix("fault=").unwrap()).unwrap();
        assert_eq!(
            (i, w, mode.as_str(), target.as_str()),
            (3, spec.window, "bias_step", "imus.hub.gyro")
        );
        // Activations [0.1, 0.15], [0.3, 0.35], [0.5, 0.55]; the last clipped to the data.
        assert_eq!(
            window_spans(&w, 0.0, 0.52),
            vec![(0.1, 0.15), (0.3, 0.35), (0.5, 0.52)]
        );
        let open = FaultWindow::from(250_000_000);
        assert_eq!(window_spans(&open, 0.0, 0.6), vec![(0.25, 0.6)]);
        assert!(window_spans(&open, 0.0, 0.2).is_empty());
        for bad in ["1,2,3", "x,0,,,m,t", "0,-1,,,m,t", "0,0,1,0,m,t"] {
            assert!(parse_csv_comment(bad).is_err(), "{bad}");
        }
    }
}
