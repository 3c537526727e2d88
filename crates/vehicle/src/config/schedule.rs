//! Time-tabled inputs: the row times shared by `[[wrench_schedule]]` and
//! `[[effector_input_schedule]]`, and the effector-input schedule itself.
//!
//! `[[effector_input_schedule]]` is to the effectors what `[[wrench_schedule]]` is to the hub: a
//! piecewise-constant function of time, here of one effector's inputs (a reaction wheel's motor
//! torque), so `flexdyn simulate` can drive the wheels with no flight code attached. Each row
//! sets the inputs of the effector it names from `t_s` on, until that effector's next row;
//! before its first row an effector's scheduled inputs are zero. The server applies the same
//! schedule and adds the flight code's `Actuators` inputs to it, as it adds the commanded
//! wrench to the wrench schedule ([`crate::sim::Simulation`]).

use std::collections::HashMap;

use super::{check_max_time, whole_ns, ConfigError, SourceMap};
use flexdyn_dynamics::{ParamError, Spacecraft};
use flexdyn_kernel::numfmt::Num;
use flexdyn_kernel::schema::TableReader;

/// Keys of an `[[effector_input_schedule]]` row.
pub(super) const KEYS: [&str; 3] = ["t_s", "effector", "inputs"];

/// One `[[effector_input_schedule]]` row as written.
pub(super) struct RawInputRow {
    t_s: f64,
    effector: String,
    inputs: Vec<f64>,
}

impl RawInputRow {
    /// Pass 2: the row's keys and types.
    pub(super) fn read(t: &TableReader<'_, '_>) -> Result<Self, ConfigError> {
        Ok(Self {
            t_s: t.f64("t_s")?,
            effector: t.string("effector")?,
            inputs: t.float_list("inputs")?,
        })
    }
}

/// One row of the effector-input schedule, resolved against the built spacecraft.
#[derive(Debug, Clone, PartialEq)]
pub struct EffectorInputSegment {
    /// \[ns\] time from which the inputs apply (until the same effector's next row).
    pub t_start_ns: u64,
    /// The effector's index in the spacecraft's effector order (panel pairs, reaction wheels,
    /// the appended bodies of the generic list: panel chains, slosh bodies, propellant tanks;
    /// then the actuators), as in `StateMsg.effectors` and `Actuators` commands.
    pub effector_index: usize,
    /// Its inputs, one per [`flexdyn_dynamics::StateEffector::input_names`] (a wheel: the motor
    /// torque, N·m, about +ĝ_s).
    pub inputs: Vec<f64>,
}

/// Checks the time `t_s` of schedule row `field` (its `.t_s`): ≥ 0, within the simulation time,
/// a whole number of RK4 steps, and strictly after `prev_ns` (the previous row of the same
/// sequence) when there is one; `order` builds the error for a row out of order. Returns the
/// time in nanoseconds.
pub(super) fn row_time_ns(
    map: &SourceMap,
    field: &str,
    t_s: f64,
    step_ns: u64,
    prev_ns: Option<u64>,
    order: impl Fn(&str, String) -> ConfigError,
) -> Result<u64, ConfigError> {
    if t_s < 0.0 {
        return Err(map.param_error(ParamError::Negative {
            field: field.to_string(),
            value: t_s,
        }));
    }
    check_max_time(map, field, t_s)?;
    let t_ns = match whole_ns(t_s) {
        Some(ns) if ns % step_ns == 0 => ns,
        _ => {
            return Err(map.timing(
                field,
                format!(
                    "t_s = {} s is not a whole number of steps (step = {step_ns} ns)",
                    Num(t_s)
                ),
            ))
        }
    };
    if let Some(prev) = prev_ns.filter(|prev| t_ns <= *prev) {
        return Err(order(
            field,
            format!(
                "t_s = {} s is not after the previous row's ({} s): t_s must be strictly increasing",
                Num(t_s),
                Num(prev as f64 / 1e9)
            ),
        ));
    }
    Ok(t_ns)
}

/// Pass 4: resolves each row's effector by name on the built spacecraft `sc` and checks its
/// time (whole steps, strictly increasing per effector) and its input count (the effector
/// kind's). Values are finite already (pass 3). The result is sorted by time, rows of equal
/// time in file order.
pub(super) fn resolve(
    rows: &[RawInputRow],
    sc: &Spacecraft,
    step_ns: u64,
    map: &SourceMap,
) -> Result<Vec<EffectorInputSegment>, ConfigError> {
    let effectors: Vec<_> = sc.effector_entries().collect();
    let mut last_ns: HashMap<usize, u64> = HashMap::new();
    let mut out = Vec::with_capacity(rows.len());
    for (i, row) in rows.iter().enumerate() {
        let path = format!("effector_input_schedule[{i}]");
        let field = format!("{path}.effector");
        let matches: Vec<usize> = (0..effectors.len())
            .filter(|&k| effectors[k].name == row.effector)
            .collect();
        let effector_index = match matches.as_slice() {
            [k] => *k,
            [] => {
                let takes: Vec<String> = effectors
                    .iter()
                    .filter(|e| !e.input_names.is_empty())
                    .map(|e| format!("`{}`", e.name))
                    .collect();
                let listed = if takes.is_empty() {
                    "this spacecraft has no effector that takes inputs".to_string()
                } else {
                    format!("effectors that take inputs: {}", takes.join(", "))
                };
                return Err(map.invalid(
                    &field,
                    format!("no effector is named `{}` ({listed})", row.effector),
                ));
            }
            several => {
                let kinds: Vec<&str> = several.iter().map(|k| effectors[*k].kind.name).collect();
                return Err(map.invalid(
                    &field,
                    format!(
                        "`{}` names more than one effector ({}): give them distinct names",
                        row.effector,
                        kinds.join(" and ")
                    ),
                ));
            }
        };
        let e = &effectors[effector_index];
        let names = e.input_names;
        if names.is_empty() {
            let mut kinds: Vec<String> = effectors
                .iter()
                .filter(|e| !e.input_names.is_empty())
                .map(|e| format!("{}s", e.kind.name.replace('_', " ")))
                .collect();
            kinds.dedup();
            let listed = if kinds.is_empty() {
                "this spacecraft has none that do".to_string()
            } else {
                format!("effectors that do: {}", kinds.join(", "))
            };
            return Err(map.invalid(
                &field,
                format!(
                    "the {} `{}` takes no inputs ({listed})",
                    e.kind.name.replace('_', " "),
                    row.effector
                ),
            ));
        }
        if row.inputs.len() != names.len() {
            return Err(map.invalid(
                &format!("{path}.inputs"),
                format!(
                    "expected {} value{} ({}) for the {} `{}`, got {}",
                    names.len(),
                    if names.len() == 1 { "" } else { "s" },
                    names.join(", "),
                    e.kind.name.replace('_', " "),
                    row.effector,
                    row.inputs.len()
                ),
            ));
        }
        let t_start_ns = row_time_ns(
            map,
            &format!("{path}.t_s"),
            row.t_s,
            step_ns,
            last_ns.get(&effector_index).copied(),
            |field, problem| {
                map.invalid(
                    field,
                    format!("{problem} for the rows of effector `{}`", row.effector),
                )
            },
        )?;
        last_ns.insert(effector_index, t_start_ns);
        out.push(EffectorInputSegment {
            t_start_ns,
            effector_index,
            inputs: row.inputs.clone(),
        });
    }
    // Stable: rows of equal time keep their file order.
    out.sort_by_key(|s| s.t_start_ns);
    Ok(out)
}
