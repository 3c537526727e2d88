//! Judging a run: each criterion's value from what the run produced (the observer's states,
//! a deputy's relative states, the flight code's recorded telemetry, the faults' first
//! activations) and whether it passes.
//!
//! - State quantities (`sigma_br`, `sigma_bn`, `omega`, `theta`) and a deputy's (`range`,
//!   `station_error`, `chief_pointing`) are a series, one value per tick, that a statistic
//!   reduces ([`reduce`]).
//! - The flight code's times (`fsw_mode_entry`, `fsw_mode_time`, `fsw_event_time`,
//!   `fsw_event_latency`) are one number per run; `fsw_value` is a series of one declared value.
//!
//! A latency whose fault never activated within the run does not apply to it: it passes, with
//! no value and a note. A mode never entered or an event never raised has no value and fails.

use std::collections::BTreeMap;

use flexdyn_kernel::attitude::{mrp_error, mrp_to_dcm};
use flexdyn_proto::{fsw_flags, FswMsg, RelativeStateMsg, StateMsg};
use flexdyn_vehicle::config::word_as_f64;
use flexdyn_vehicle::world::relative::dcm_hn;
use nalgebra::Vector3;
use serde::{Deserialize, Deserializer, Serialize};

use super::criteria::{Criterion, FswRef, FswTarget, Quantity, Statistic};

/// One criterion's outcome.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CriterionResult {
    /// Its name.
    pub name: String,
    /// The statistic's value; NaN (`null` in `result.json`) when there is none: a mode never
    /// entered, an event never raised, a latency that does not apply.
    #[serde(deserialize_with = "null_as_nan")]
    pub value: f64,
    /// Whether it is below the bound (or does not apply).
    pub passed: bool,
    /// `false` when the criterion does not apply to the run (a latency whose fault did not
    /// activate within it): it then passes, and the per-criterion pass rates leave it out.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub applies: bool,
    /// Why there is no value, or what it was measured from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

fn yes() -> bool {
    true
}

fn is_true(b: &bool) -> bool {
    *b
}

/// `result.json` writes a NaN as `null` (JSON has no NaN): read it back as NaN.
fn null_as_nan<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl CriterionResult {
    /// `c` judged on `value`: it passes when the value is strictly below `c.below` (a NaN
    /// never does).
    pub fn of(c: &Criterion, value: f64) -> Self {
        CriterionResult {
            name: c.name.clone(),
            value,
            passed: value < c.below,
            applies: true,
            note: None,
        }
    }

    fn noted(mut self, note: String) -> Self {
        self.note = Some(note);
        self
    }
}

fn quantity(q: Quantity, s: &StateMsg, sigma_rn: &Vector3<f64>) -> f64 {
    match q {
        Quantity::SigmaBr => mrp_error(&Vector3::from(s.sigma_bn), sigma_rn).norm(),
        Quantity::SigmaBn => Vector3::from(s.sigma_bn).norm(),
        Quantity::Omega => Vector3::from(s.omega_bn_b_rad_s).norm(),
        Quantity::Theta => s
            .effectors
            .iter()
            .filter(|e| e.kind == flexdyn_proto::effector_kind::PANEL_PAIR)
            .flat_map(|e| [e.states.first(), e.states.get(2)])
            .flatten()
            .fold(0.0f64, |m, x| m.max(x.abs())),
        // Not in a StateMsg: read from the relative states or the flight code's telemetry.
        _ => f64::NAN,
    }
}

/// Whether `c` reduces what the run did over its length (a maximum, a settling time, the flight
/// code's times), not its last state alone: in a campaign whose runs start from a checkpoint it
/// sees the ticks from the checkpoint's on, and its result says so.
pub fn reads_the_whole_run(c: &Criterion) -> bool {
    !matches!(c.statistic, Statistic::Final)
}

/// Evaluates `c` over `states` (in tick order).
pub fn evaluate(
    c: &Criterion,
    states: &[StateMsg],
    sigma_rn: [f64; 3],
    frame_s: f64,
) -> CriterionResult {
    let target = Vector3::from(sigma_rn);
    let series: Vec<(f64, f64)> = states
        .iter()
        .map(|s| {
            (
                s.header.sim_time_ns as f64 * 1e-9,
                quantity(c.quantity, s, &target),
            )
        })
        .collect();
    reduce(c, &series, frame_s)
}

/// `c`'s statistic over `series` ((t \[s\], value) in time order) and whether it passes.
pub fn reduce(c: &Criterion, series: &[(f64, f64)], frame_s: f64) -> CriterionResult {
    let value = match c.statistic {
        Statistic::Final | Statistic::Once => series.last().map_or(f64::NAN, |(_, v)| *v),
        Statistic::Max => series
            .iter()
            .filter(|(t, _)| *t >= c.after_s - 1e-9)
            .fold(f64::NEG_INFINITY, |m, (_, v)| m.max(*v)),
        Statistic::SettlingTime { threshold } => {
            // The first time after which every sample stays below the threshold.
            // NaN counts as outside the band.
            let last_out = series
                .iter()
                .rposition(|(_, v)| v.is_nan() || *v >= threshold);
            match last_out {
                None => series.first().map_or(f64::NAN, |(t, _)| *t),
                Some(i) if i + 1 < series.len() => series[i + 1].0,
                Some(i) => series[i].0 + frame_s,
            }
        }
    };
    CriterionResult::of(c, value)
}

/// A deputy's quantity (`range`, `station_error`, `chief_pointing`) tick by tick, from its
/// RelativeStateMsg stream and, for `chief_pointing`, its own and its chief's states (all in
/// tick order).
///
/// `chief_pointing`: the direction from the deputy's centre of mass to the chief's is
/// −r_dc (RelativeStateMsg, H components); \[NH\] = \[HN\]ᵀ is the chief's Hill frame from its
/// published position and velocity (rows x̂ = r/|r|, ẑ = h/|h|, ŷ = ẑ × x̂: Vallado §6.8, as the
/// server computes it, there from the centre of mass: the B point shifts x̂ by |c_B|/|r|, about
/// 1e-7 rad); \[BN\] from the deputy's σ_BN (Schaub & Junkins eq. 3.153). The angle between the
/// axis â and d_B = \[BN\]\[NH\](−r_dc) is atan2(|â × d_B|, â·d_B) (accurate at 0 and π).
pub fn relative_series(
    c: &Criterion,
    relative: &[RelativeStateMsg],
    deputy: &[StateMsg],
    chief: &[StateMsg],
) -> Vec<(f64, f64)> {
    let t_s = |m: &RelativeStateMsg| m.header.sim_time_ns as f64 * 1e-9;
    match c.quantity {
        Quantity::Range => relative.iter().map(|m| (t_s(m), m.range_m)).collect(),
        Quantity::StationError => {
            let station = Vector3::from(c.station_h_m.unwrap_or_default());
            relative
                .iter()
                .map(|m| (t_s(m), (Vector3::from(m.r_dc_h_m) - station).norm()))
                .collect()
        }
        Quantity::ChiefPointing => {
            let axis_b = Vector3::from(c.axis_b.unwrap_or([1.0, 0.0, 0.0]));
            relative
                .iter()
                .map(|m| {
                    let angle = state_at(deputy, m.header.tick)
                        .zip(state_at(chief, m.header.tick))
                        .and_then(|(d, ch)| {
                            let c_hn =
                                dcm_hn(&Vector3::from(ch.r_bn_n_m), &Vector3::from(ch.v_bn_n_m_s))?;
                            let c_bn = mrp_to_dcm(&Vector3::from(d.sigma_bn));
                            let to_chief_b = c_bn * c_hn.transpose() * -Vector3::from(m.r_dc_h_m);
                            Some(
                                axis_b
                                    .cross(&to_chief_b)
                                    .norm()
                                    .atan2(axis_b.dot(&to_chief_b)),
                            )
                        })
                        .unwrap_or(f64::NAN);
                    (t_s(m), angle)
                })
                .collect()
        }
        _ => Vec::new(),
    }
}

/// The state of `tick` in `states` (in tick order): found by binary search, not copied.
fn state_at(states: &[StateMsg], tick: u64) -> Option<&StateMsg> {
    let i = states.binary_search_by_key(&tick, |m| m.header.tick).ok()?;
    states.get(i)
}

/// An `fsw_` criterion judged on the stream's recorded samples (`samples`, in tick order),
/// the faults' first activations (`activations_ns`, by `<prefix>faults[k]`) and the run's end
/// (`end_ns`, its last tick's time).
pub fn evaluate_fsw(
    c: &Criterion,
    samples: &[FswMsg],
    activations_ns: &BTreeMap<String, u64>,
    prefix: &str,
    end_ns: u64,
    frame_s: f64,
) -> CriterionResult {
    let Some(FswRef { decl, target }) = &c.fsw else {
        return CriterionResult::of(c, f64::NAN).noted("not a flight-code criterion".into());
    };
    // Seconds as the nearest double to ns / 10⁹ (correctly rounded, unlike ns × 1e-9).
    let s = |ns: u64| ns as f64 / 1e9;
    let stream = &decl.name;
    let none = samples.is_empty().then(|| {
        format!("no sample of stream {stream:?} was recorded (is the flight code publishing it?)")
    });
    match (c.quantity, target) {
        (Quantity::FswModeEntry, FswTarget::Mode(m)) => {
            match samples
                .iter()
                .find(|x| x.flags & fsw_flags::MODE != 0 && x.mode == *m)
            {
                Some(x) => CriterionResult::of(c, s(x.header.sim_time_ns)),
                None => CriterionResult::of(c, f64::NAN).noted(
                    none.unwrap_or_else(|| format!("never in mode {:?}", decl.modes[*m as usize])),
                ),
            }
        }
        (Quantity::FswModeTime, FswTarget::Mode(m)) => {
            // Each sample naming a mode holds it until the next one that does; the last one
            // until the run's end.
            let moded: Vec<&FswMsg> = samples
                .iter()
                .filter(|x| x.flags & fsw_flags::MODE != 0)
                .collect();
            let mut in_mode_ns = 0u64;
            for (k, x) in moded.iter().enumerate() {
                if x.mode != *m {
                    continue;
                }
                let until = moded
                    .get(k + 1)
                    .map_or(end_ns, |n| n.header.sim_time_ns)
                    .max(x.header.sim_time_ns);
                in_mode_ns += until - x.header.sim_time_ns;
            }
            let r = CriterionResult::of(c, s(in_mode_ns));
            match none {
                Some(n) => r.noted(n),
                None => r,
            }
        }
        (Quantity::FswEventTime, FswTarget::Event { index, .. }) => {
            match samples.iter().find(|x| x.event_indices().contains(index)) {
                Some(x) => CriterionResult::of(c, s(x.header.sim_time_ns)),
                None => CriterionResult::of(c, f64::NAN).noted(none.unwrap_or_else(|| {
                    format!("no {:?} event", decl.events[*index as usize].name)
                })),
            }
        }
        (
            Quantity::FswEventLatency,
            FswTarget::Event {
                index,
                fault: Some(k),
            },
        ) => {
            let fault = format!("{prefix}faults[{k}]");
            let event = &decl.events[*index as usize].name;
            let Some(&at_ns) = activations_ns.get(&fault) else {
                return CriterionResult {
                    applies: false,
                    passed: true,
                    ..CriterionResult::of(c, f64::NAN)
                }
                .noted(format!("{fault} did not activate within the run"));
            };
            match samples
                .iter()
                .find(|x| x.header.sim_time_ns >= at_ns && x.event_indices().contains(index))
            {
                Some(x) => CriterionResult::of(c, s(x.header.sim_time_ns - at_ns)),
                None => CriterionResult::of(c, f64::NAN).noted(format!(
                    "no {event:?} event after {fault} activated at {}.{:09} s{}",
                    at_ns / 1_000_000_000,
                    at_ns % 1_000_000_000,
                    none.map(|n| format!(" ({n})")).unwrap_or_default()
                )),
            }
        }
        (Quantity::FswValue, FswTarget::Value { index, element }) => {
            let v = &decl.values[*index];
            let series: Vec<(f64, f64)> = samples
                .iter()
                .filter_map(|x| {
                    let words = v.words_of(&x.values)?;
                    let value = match element {
                        Some(k) => word_as_f64(v.ty, *words.get(*k)?),
                        None if words.len() == 1 => word_as_f64(v.ty, words[0]),
                        None => words
                            .iter()
                            .map(|w| word_as_f64(v.ty, *w).powi(2))
                            .sum::<f64>()
                            .sqrt(),
                    };
                    Some((s(x.header.sim_time_ns), value))
                })
                .collect();
            let r = reduce(c, &series, frame_s);
            match none {
                Some(n) => r.noted(n),
                None => r,
            }
        }
        _ => CriterionResult::of(c, f64::NAN).noted("inconsistent criterion".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::Header;

    #[test]
    fn statistics_follow_their_definitions() {
        let states: Vec<StateMsg> = [0.3, 0.2, 0.05, 0.2, 0.01, 0.005]
            .iter()
            .enumerate()
            .map(|(i, s)| StateMsg {
                header: Header::new(1, i as u64, i as u64 * 1_000_000_000, i as u64),
                sigma_bn: [*s, 0.0, 0.0],
                ..StateMsg::default()
            })
            .collect();
        let c = |statistic, after_s, below| {
            Criterion::on_states("x", Quantity::SigmaBn, statistic, after_s, below)
        };
        let r = evaluate(&c(Statistic::Final, 0.0, 0.01), &states, [0.0; 3], 1.0);
        assert_eq!((r.value, r.passed), (0.005, true));
        let r = evaluate(&c(Statistic::Max, 2.0, 0.1), &states, [0.0; 3], 1.0);
        assert_eq!((r.value, r.passed), (0.2, false));
        // Below 0.1 from t = 4 s on (t = 2 s dips but t = 3 s goes back up).
        let r = evaluate(
            &c(Statistic::SettlingTime { threshold: 0.1 }, 0.0, 5.0),
            &states,
            [0.0; 3],
            1.0,
        );
        assert_eq!((r.value, r.passed), (4.0, true));
        // |σ_BR| to a target equal to the state is 0.
        let r = evaluate(
            &Criterion {
                quantity: Quantity::SigmaBr,
                ..c(Statistic::Final, 0.0, 1e-12)
            },
            &states,
            [0.005, 0.0, 0.0],
            1.0,
        );
        assert!(r.value < 1e-15 && r.passed, "{r:?}");
    }

    use flexdyn_vehicle::config::{
        FswEventDecl, FswSeverity, FswStreamDecl, FswValueDecl, FswValueType,
    };

    /// A stream with modes a, b; events e0, e1, e2; values v (f64[3]), n (i64), ok (bool).
    fn decl() -> FswStreamDecl {
        let value = |name: &str, ty, len, offset| FswValueDecl {
            name: name.into(),
            ty,
            len,
            unit: "u".into(),
            offset,
        };
        FswStreamDecl {
            name: "acs".into(),
            modes: vec!["a".into(), "b".into()],
            events: ["e0", "e1", "e2"]
                .iter()
                .map(|n| FswEventDecl {
                    name: (*n).into(),
                    severity: FswSeverity::Info,
                })
                .collect(),
            values: vec![
                value("v", FswValueType::F64, 3, 0),
                value("n", FswValueType::I64, 1, 3),
                value("ok", FswValueType::Bool, 1, 4),
            ],
        }
    }

    /// A sample at tick `k` (k seconds), in `mode` (None: no MODE flag), raising `events`.
    fn sample(k: u64, mode: Option<u32>, events: &[u16], v: [f64; 3], n: i64) -> FswMsg {
        let mut m = FswMsg {
            header: Header::new(1, k, k * 1_000_000_000, k),
            flags: if mode.is_some() { fsw_flags::MODE } else { 0 },
            mode: mode.unwrap_or(0),
            values: vec![v[0].to_bits(), v[1].to_bits(), v[2].to_bits(), n as u64, 1],
            ..FswMsg::default()
        };
        m.event_count = events.len() as u8;
        m.events[..events.len()].copy_from_slice(events);
        m
    }

    fn fsw_criterion(
        quantity: Quantity,
        target: FswTarget,
        statistic: Statistic,
        below: f64,
    ) -> Criterion {
        Criterion {
            fsw: Some(FswRef {
                decl: decl(),
                target,
            }),
            ..Criterion::on_states("c", quantity, statistic, 0.0, below)
        }
    }

    /// Modes a a b b b a (unsaid) b, events e2 at 3 s and 7 s, values growing.
    fn samples() -> Vec<FswMsg> {
        let modes = [
            Some(0),
            Some(0),
            Some(1),
            Some(1),
            Some(1),
            Some(0),
            None,
            Some(1),
        ];
        modes
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let ev: &[u16] = if k == 3 || k == 7 { &[0, 2] } else { &[] };
                sample(
                    k as u64,
                    *m,
                    ev,
                    [3.0 * k as f64, 4.0 * k as f64, 0.0],
                    -(k as i64),
                )
            })
            .collect()
    }

    #[test]
    fn flight_code_times_follow_their_definitions() {
        let s = samples();
        let none = BTreeMap::new();
        let end_ns = 10_000_000_000;
        let judge =
            |c: &Criterion, act: &BTreeMap<String, u64>| evaluate_fsw(c, &s, act, "", end_ns, 1.0);
        // First entry into b: tick 2.
        let c = fsw_criterion(
            Quantity::FswModeEntry,
            FswTarget::Mode(1),
            Statistic::Once,
            2.5,
        );
        let r = judge(&c, &none);
        assert_eq!((r.value, r.passed), (2.0, true));
        // Time in b: [2, 5) and [7, 10 (the end)) = 6 s; the unsaid sample at 6 s keeps a.
        let c = fsw_criterion(
            Quantity::FswModeTime,
            FswTarget::Mode(1),
            Statistic::Once,
            6.0,
        );
        let r = judge(&c, &none);
        assert_eq!((r.value, r.passed), (6.0, false));
        // Time in a: [0, 2) and [5, 7) = 4 s; the two add up to the run.
        let c = fsw_criterion(
            Quantity::FswModeTime,
            FswTarget::Mode(0),
            Statistic::Once,
            6.0,
        );
        assert_eq!(judge(&c, &none).value, 4.0);
        // First e2: 3 s. e1 never: no value, fails, says so.
        let ev = |index, fault| FswTarget::Event { index, fault };
        let c = fsw_criterion(Quantity::FswEventTime, ev(2, None), Statistic::Once, 5.0);
        assert_eq!(judge(&c, &none).value, 3.0);
        let c = fsw_criterion(Quantity::FswEventTime, ev(1, None), Statistic::Once, 5.0);
        let r = judge(&c, &none);
        assert!(r.value.is_nan() && !r.passed && r.applies, "{r:?}");
        assert_eq!(r.note.as_deref(), Some("no \"e1\" event"));
        // Latency from faults[0] at 5.5 s: the first e2 at or after it is at 7 s, 1.5 s.
        let c = fsw_criterion(
            Quantity::FswEventLatency,
            ev(2, Some(0)),
            Statistic::Once,
            2.0,
        );
        let at = |ns: u64| BTreeMap::from([("faults[0]".to_owned(), ns)]);
        let r = judge(&c, &at(5_500_000_000));
        assert_eq!((r.value, r.passed), (1.5, true));
        // An event in the activation's own tick counts, with latency 0.
        assert_eq!(judge(&c, &at(3_000_000_000)).value, 0.0);
        // Activated after the last e2: not detected, fails.
        let r = judge(&c, &at(7_000_000_001));
        assert!(r.value.is_nan() && !r.passed, "{r:?}");
        assert!(r
            .note
            .unwrap()
            .contains("after faults[0] activated at 7.000000001 s"));
        // Never activated: does not apply, passes.
        let r = judge(&c, &none);
        assert!(r.value.is_nan() && r.passed && !r.applies, "{r:?}");
        // No samples at all: named.
        let r = evaluate_fsw(&c, &[], &at(1), "", end_ns, 1.0);
        assert!(r.note.unwrap().contains("no sample of stream \"acs\""));
    }

    #[test]
    fn flight_code_values_reduce_like_states() {
        let s = samples();
        let none = BTreeMap::new();
        let judge = |target, statistic, below| {
            let c = fsw_criterion(Quantity::FswValue, target, statistic, below);
            evaluate_fsw(&c, &s, &none, "", 8_000_000_000, 1.0)
        };
        let value = |index, element| FswTarget::Value { index, element };
        // |v| = 5 k: final 35, max from 0 s 35.
        assert_eq!(judge(value(0, None), Statistic::Final, 36.0).value, 35.0);
        assert_eq!(judge(value(0, Some(1)), Statistic::Final, 36.0).value, 28.0);
        // n = −k: a signed value; its max is 0 (tick 0), below 0.5 passes.
        let r = judge(value(1, None), Statistic::Max, 0.5);
        assert_eq!((r.value, r.passed), (0.0, true));
        // |v| stays below 12 until 2 s: it settles never (it grows): last out + 1 frame = 8 s.
        assert_eq!(
            judge(
                value(0, None),
                Statistic::SettlingTime { threshold: 12.0 },
                9.0
            )
            .value,
            8.0
        );
        // ok = true throughout.
        assert_eq!(judge(value(2, None), Statistic::Max, 2.0).value, 1.0);
    }

    /// A relative state at tick `k` with offset `r_dc_h_m`.
    fn relative(k: u64, r_dc_h_m: [f64; 3]) -> RelativeStateMsg {
        RelativeStateMsg {
            header: Header::new(2, k, k * 1_000_000_000, k),
            r_dc_h_m,
            ..RelativeStateMsg::default()
        }
    }

    #[test]
    fn a_deputys_station_error_and_pointing_at_its_chief() {
        // Station error: |(1, 2, 2) − 0| = 3; against (1, 2, 0): 2.
        let rel = [relative(0, [1.0, 2.0, 2.0])];
        let mut c = Criterion::on_states("s", Quantity::StationError, Statistic::Final, 0.0, 1.0);
        c.station_h_m = Some([0.0; 3]);
        assert_eq!(relative_series(&c, &rel, &[], &[]), vec![(0.0, 3.0)]);
        c.station_h_m = Some([1.0, 2.0, 0.0]);
        assert_eq!(relative_series(&c, &rel, &[], &[]), vec![(0.0, 2.0)]);

        // The chief on the N x axis moving along N y: H = N. The deputy 100 m behind it
        // (along-track −y), so the chief is along +y_N from the deputy. The deputy turned 90°
        // about z_N (σ = tan(22.5°) ẑ): [BN] maps N y to B x, so the chief is along +x_B.
        let chief = StateMsg {
            header: Header::new(1, 0, 0, 0),
            r_bn_n_m: [7.0e6, 0.0, 0.0],
            v_bn_n_m_s: [0.0, 7.5e3, 0.0],
            ..StateMsg::default()
        };
        let deputy = StateMsg {
            header: Header::new(2, 0, 0, 0),
            sigma_bn: [0.0, 0.0, (std::f64::consts::PI / 8.0).tan()],
            ..StateMsg::default()
        };
        let rel = [relative(0, [0.0, -100.0, 0.0])];
        let angle = |axis_b: [f64; 3]| {
            let mut c =
                Criterion::on_states("p", Quantity::ChiefPointing, Statistic::Final, 0.0, 1.0);
            c.axis_b = Some(axis_b);
            relative_series(
                &c,
                &rel,
                std::slice::from_ref(&deputy),
                std::slice::from_ref(&chief),
            )[0]
            .1
        };
        let pi = std::f64::consts::PI;
        assert!(angle([1.0, 0.0, 0.0]).abs() < 1e-15);
        assert!((angle([0.0, 1.0, 0.0]) - pi / 2.0).abs() < 1e-15);
        assert!((angle([-1.0, 0.0, 0.0]) - pi).abs() < 1e-15);
        let (s, c30) = (0.5, 3f64.sqrt() / 2.0);
        assert!((angle([c30, s, 0.0]) - pi / 6.0).abs() < 1e-15);
        assert!((angle([c30, 0.0, -s]) - pi / 6.0).abs() < 1e-15);
        // A tick the deputy has no state for has no value.
        let rel = [relative(1, [0.0, -100.0, 0.0])];
        let mut c = Criterion::on_states("p", Quantity::ChiefPointing, Statistic::Final, 0.0, 1.0);
        c.axis_b = Some([1.0, 0.0, 0.0]);
        assert!(relative_series(&c, &rel, &[deputy], &[chief])[0].1.is_nan());
    }

    /// `result.json` holds a missing value as null and reads it back as NaN; `applies` and
    /// `note` are left out when they say nothing.
    #[test]
    fn results_without_a_value_round_trip_through_json() {
        let c = Criterion::on_states("x", Quantity::Omega, Statistic::Final, 0.0, 1.0);
        let r = CriterionResult::of(&c, 0.5);
        let text = serde_json::to_string(&r).unwrap();
        assert_eq!(text, r#"{"name":"x","value":0.5,"passed":true}"#);
        let r = CriterionResult {
            applies: false,
            ..CriterionResult::of(&c, f64::NAN)
        }
        .noted("why".into());
        let text = serde_json::to_string(&r).unwrap();
        assert_eq!(
            text,
            r#"{"name":"x","value":null,"passed":false,"applies":false,"note":"why"}"#
        );
        let back: CriterionResult = serde_json::from_str(&text).unwrap();
        assert!(back.value.is_nan() && !back.applies && back.note.as_deref() == Some("why"));
    }
}
