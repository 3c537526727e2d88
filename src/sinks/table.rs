//! Decoded messages as flat rows of named columns, for CSV export and plots.
//!
//! Column names follow `flexdyn simulate`: `t_s` first, then the wire field names (which carry
//! their units, e.g. `omega_bn_b_rad_s_1`), vectors 1-based (`sigma_bn_1..3`; a quaternion
//! `q_bn_0..3`, scalar first), nested structs prefixed by their field (`conserved_rot_energy_j`,
//! `rejected_malformed`), header fields unprefixed (`tick`, `seq`). Effectors are named by kind
//! as in `simulate`: `pair1_theta1`, `rw2_omega_rad_s`, `rw2_motor_torque_nm`, `rw2_flags`.

use serde_json::Value;

use super::topics::Decoded;
use crate::dynamics::effectors::wire_names;

/// One cell.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    /// A number (integers are exact up to 2⁵³, as in JSON).
    Num(f64),
    /// An unsigned integer (ticks, sequence numbers, nanoseconds).
    Int(u64),
    /// A name (enum variants).
    Text(String),
}

impl std::fmt::Display for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Cell::Num(x) => write!(f, "{x}"),
            Cell::Int(i) => write!(f, "{i}"),
            Cell::Text(s) => f.write_str(s),
        }
    }
}

fn push_value(prefix: &str, v: &Value, out: &mut Vec<(String, Cell)>) {
    let name = |k: &str| {
        if prefix.is_empty() {
            k.to_owned()
        } else {
            format!("{prefix}_{k}")
        }
    };
    match v {
        Value::Null => {}
        Value::Bool(b) => out.push((prefix.to_owned(), Cell::Int(u64::from(*b)))),
        Value::Number(n) => out.push((
            prefix.to_owned(),
            match n.as_u64() {
                Some(i) => Cell::Int(i),
                None => Cell::Num(n.as_f64().unwrap_or(f64::NAN)),
            },
        )),
        Value::String(s) => out.push((prefix.to_owned(), Cell::Text(s.clone()))),
        Value::Array(items) => {
            // Quaternions are scalar-first and 0-based (q_bn_0 = β0), vectors 1-based.
            let base = usize::from(!prefix.starts_with("q_"));
            for (i, item) in items.iter().enumerate() {
                push_value(&format!("{prefix}_{}", i + base), item, out);
            }
        }
        Value::Object(map) => {
            for (k, item) in map {
                if k == "header" {
                    push_value(prefix, item, out);
                } else {
                    push_value(&name(k), item, out);
                }
            }
        }
    }
}

fn push_effectors(effectors: &[flexdyn_proto::EffectorState], out: &mut Vec<(String, Cell)>) {
    let mut per_kind: Vec<(u16, usize)> = Vec::new();
    for (k, e) in effectors.iter().enumerate() {
        let count = match per_kind.iter_mut().find(|(kind, _)| *kind == e.kind) {
            Some((_, n)) => {
                *n += 1;
                *n
            }
            None => {
                per_kind.push((e.kind, 1));
                1
            }
        };
        match wire_names(e.kind, e.states.len(), e.outputs.len()) {
            Some((kind, states, outputs)) => {
                let p = format!("{}{count}", kind.column_prefix);
                for (n, x) in states.iter().zip(&e.states) {
                    out.push((format!("{p}_{n}"), Cell::Num(*x)));
                }
                for (n, x) in outputs.iter().zip(&e.outputs) {
                    out.push((format!("{p}_{n}"), Cell::Num(*x)));
                }
                out.push((format!("{p}_flags"), Cell::Int(e.flags.into())));
            }
            None => {
                let p = format!("effector{k}");
                out.push((format!("{p}_kind"), Cell::Int(e.kind.into())));
                for (i, x) in e.states.iter().enumerate() {
                    out.push((format!("{p}_state_{}", i + 1), Cell::Num(*x)));
                }
                for (i, x) in e.outputs.iter().enumerate() {
                    out.push((format!("{p}_output_{}", i + 1), Cell::Num(*x)));
                }
                out.push((format!("{p}_flags"), Cell::Int(e.flags.into())));
            }
        }
    }
}

/// The row of one decoded message: `t_s` first, then its fields.
pub fn row(decoded: &Decoded) -> Vec<(String, Cell)> {
    let mut out = vec![(
        "t_s".to_owned(),
        Cell::Num(decoded.header().sim_time_ns as f64 * 1e-9),
    )];
    let mut json = decoded.to_json();
    match (decoded, &mut json) {
        (Decoded::State(state), Value::Object(map)) => {
            map.remove("effectors");
            push_value("", &json, &mut out);
            push_effectors(&state.effectors, &mut out);
        }
        (Decoded::Command(cmd), Value::Object(map)) => {
            map.remove("kind");
            push_value("", &json, &mut out);
            use flexdyn_proto::CommandKind;
            let (name, wrench, inputs) = match &cmd.kind {
                CommandKind::Wrench {
                    torque_b_nm,
                    force_b_newton,
                } => ("Wrench", Some((torque_b_nm, force_b_newton)), &[][..]),
                CommandKind::NoCommand => ("NoCommand", None, &[][..]),
                CommandKind::Actuators {
                    torque_b_nm,
                    force_b_newton,
                    inputs,
                } => (
                    "Actuators",
                    Some((torque_b_nm, force_b_newton)),
                    inputs.as_slice(),
                ),
            };
            out.push(("kind".to_owned(), Cell::Text(name.to_owned())));
            if let Some((t, f)) = wrench {
                for (i, x) in t.iter().enumerate() {
                    out.push((format!("torque_b_nm_{}", i + 1), Cell::Num(*x)));
                }
                for (i, x) in f.iter().enumerate() {
                    out.push((format!("force_b_newton_{}", i + 1), Cell::Num(*x)));
                }
            }
            for input in inputs {
                for (i, x) in input.values.iter().enumerate() {
                    out.push((
                        format!("input_effector{}_{}", input.effector_index, i + 1),
                        Cell::Num(*x),
                    ));
                }
            }
        }
        _ => push_value("", &json, &mut out),
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::{effector_kind, EffectorState, StateMsg};

    #[test]
    fn a_state_row_names_its_columns_like_simulate() {
        let mut s = StateMsg {
            sigma_bn: [0.1, 0.2, 0.3],
            q_bn: [1.0, 0.0, 0.0, 0.0],
            ..StateMsg::default()
        };
        s.header.sim_time_ns = 1_500_000_000;
        s.header.tick = 7;
        s.effectors = vec![
            EffectorState {
                kind: effector_kind::PANEL_PAIR,
                flags: 0,
                states: vec![0.1, 0.2, 0.3, 0.4],
                outputs: vec![],
            },
            EffectorState {
                kind: effector_kind::REACTION_WHEEL,
                flags: 3,
                states: vec![100.0],
                outputs: vec![0.01, -0.001],
            },
            EffectorState {
                kind: 77,
                flags: 0,
                states: vec![5.0],
                outputs: vec![],
            },
        ];
        let r = row(&Decoded::State(s));
        let get = |n: &str| {
            r.iter()
                .find(|(k, _)| k == n)
                .map(|(_, c)| c.clone())
                .unwrap_or_else(|| panic!("no column {n}: {r:?}"))
        };
        assert_eq!(r[0].0, "t_s");
        assert_eq!(get("t_s"), Cell::Num(1.5));
        assert_eq!(get("tick"), Cell::Int(7));
        assert_eq!(get("sigma_bn_3"), Cell::Num(0.3));
        assert_eq!(get("q_bn_0"), Cell::Num(1.0));
        assert_eq!(get("omega_bn_b_rad_s_1"), Cell::Num(0.0));
        assert_eq!(get("conserved_rot_energy_j"), Cell::Num(0.0));
        assert_eq!(get("pair1_theta2"), Cell::Num(0.3));
        assert_eq!(get("rw1_omega_rad_s"), Cell::Num(100.0));
        assert_eq!(get("rw1_friction_torque_nm"), Cell::Num(-0.001));
        assert_eq!(get("rw1_flags"), Cell::Int(3));
        assert_eq!(get("effector2_state_1"), Cell::Num(5.0));
        // Column names are unique.
        let mut names: Vec<_> = r.iter().map(|(k, _)| k.clone()).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), r.len());
    }
}
