//! flexdyn's one CSV dialect, and its one writer ([`CsvTable`]), for `flexdyn simulate`,
//! `flexdyn export` and `flexdyn plot`.
//!
//! A row is a decoded message as named columns: `t_s` first, then the wire field names, which
//! carry their units (`omega_bn_b_rad_s_1`, `r_bn_n_m_2`, `conserved_rot_energy_j`), vectors
//! 1-based (`sigma_bn_1..3`; a quaternion `q_bn_0..3`, scalar first), nested structs prefixed by
//! their field (`conserved_rot_energy_j`, `wrench_applied_torque_b_nm_1`,
//! `rejected_malformed`), header fields unprefixed (`tick`, `seq`). Effectors are named by kind
//! and their 1-based index among effectors of that kind: `pair1_theta1`, `rw2_omega_rad_s`,
//! `rw2_motor_torque_nm`, `rw2_flags`. A message that `simulate` writes beside the state
//! (an IMU sample, a star-tracker sample, the scheduled wrench) contributes its fields without
//! its header, prefixed by what it is: `imu_<name>_omega_p_rad_s_1`, `st_<name>_q_cn_0`,
//! `wrench_schedule_torque_b_nm_1` ([`prefixed_columns`]).
//!
//! Numbers are written in the shortest form that reads back to the same f64 ([`Num`]), integers
//! (ticks, flags, booleans as 0/1) as integers, and a column a row does not have is left empty.

use std::collections::HashMap;
use std::io::{self, Write};

use flexdyn_proto::StateMsg;
use serde::Serialize;
use serde_json::Value;

use super::columns::{push_cells, push_columns};
use super::topics::Decoded;
use flexdyn_dynamics::kinds::wire_names;
use flexdyn_kernel::numfmt::Num;

/// One cell.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    /// A number (integers are exact up to 2⁵³, as in JSON). NaN stands for a non-finite value.
    Num(f64),
    /// An unsigned integer (ticks, sequence numbers, nanoseconds, flags, booleans).
    Int(u64),
    /// A name (enum variants).
    Text(String),
}

impl Cell {
    /// The cell as a number (`None` for text).
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Cell::Num(x) => Some(*x),
            Cell::Int(i) => Some(*i as f64),
            Cell::Text(_) => None,
        }
    }
}

impl std::fmt::Display for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Cell::Num(x) => write!(f, "{}", Num(*x)),
            Cell::Int(i) => write!(f, "{i}"),
            Cell::Text(s) => f.write_str(s),
        }
    }
}

/// One named cell of a row.
pub type Column = (String, Cell);

/// Appends the columns of `v` named under `prefix`. An array is numbered from 1, or from 0
/// when it is a quaternion (its field name starts with `q_`: scalar first, `q_bn_0` = β0).
pub(crate) fn push_value(prefix: &str, v: &Value, out: &mut Vec<Column>) {
    match v {
        // serde_json writes a non-finite f64 as null (the wire structs have no optional
        // field): keep the column, as NaN.
        Value::Null => out.push((prefix.to_owned(), Cell::Num(f64::NAN))),
        Value::Bool(b) => out.push((prefix.to_owned(), Cell::Int(u64::from(*b)))),
        Value::Number(n) => out.push((
            prefix.to_owned(),
            match n.as_u64() {
                Some(i) => Cell::Int(i),
                None => Cell::Num(n.as_f64().unwrap_or(f64::NAN)),
            },
        )),
        Value::String(s) => out.push((prefix.to_owned(), Cell::Text(s.clone()))),
        Value::Array(items) => push_array(prefix, 1, items, out),
        Value::Object(map) => {
            for (k, item) in map {
                let name = match (k.as_str(), prefix.is_empty()) {
                    ("header", _) => prefix.to_owned(),
                    (_, true) => k.clone(),
                    (_, false) => format!("{prefix}_{k}"),
                };
                match item {
                    Value::Array(items) if k.starts_with("q_") => push_array(&name, 0, items, out),
                    _ => push_value(&name, item, out),
                }
            }
        }
    }
}

fn push_array(prefix: &str, first: usize, items: &[Value], out: &mut Vec<Column>) {
    for (i, item) in items.iter().enumerate() {
        push_value(&format!("{prefix}_{}", i + first), item, out);
    }
}

fn push_effectors(effectors: &[flexdyn_proto::EffectorState], out: &mut Vec<Column>) {
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

/// \[s\] a header time as the `t_s` cell: `ns / 1e9`, one correctly rounded division, so
/// 30 ms prints as `0.03`.
fn t_s_cell(sim_time_ns: u64) -> Column {
    ("t_s".to_owned(), Cell::Num(sim_time_ns as f64 / 1e9))
}

/// The row of one decoded message: `t_s` first, then its fields.
pub fn row(decoded: &Decoded) -> Vec<Column> {
    match decoded {
        Decoded::State(state) => state_row(state),
        Decoded::Command(cmd) => {
            let mut out = vec![t_s_cell(cmd.header.sim_time_ns)];
            let mut json = decoded.to_json();
            if let Value::Object(map) = &mut json {
                map.shift_remove("kind");
            }
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
            out
        }
        _ => {
            let mut out = vec![t_s_cell(decoded.header().sim_time_ns)];
            match decoded {
                // A sensor sample is decoded to JSON by its kind.
                Decoded::Sensor { json, .. } => push_value("", json, &mut out),
                Decoded::Status(m) => push_columns("", m, &[], &mut out),
                Decoded::Time(m) => push_columns("", m, &[], &mut out),
                Decoded::Operator(m) => push_columns("", m, &[], &mut out),
                Decoded::Environment(m) => push_columns("", m, &[], &mut out),
                Decoded::FaultEvent(m) => push_columns("", m, &[], &mut out),
                Decoded::FaultCommand(m) => push_columns("", m, &[], &mut out),
                Decoded::RelativeState(m) => push_columns("", m, &[], &mut out),
                Decoded::Fsw(m) => push_columns("", m, &[], &mut out),
                Decoded::State(_) | Decoded::Command(_) => {
                    push_value("", &decoded.to_json(), &mut out)
                }
            }
            out
        }
    }
}

/// The row of a state record: `t_s`, the header, the physical fields, the command bookkeeping,
/// then the effectors.
pub fn state_row(state: &StateMsg) -> Vec<Column> {
    let mut out = vec![t_s_cell(state.header.sim_time_ns)];
    push_columns("", state, &["effectors"], &mut out);
    push_effectors(&state.effectors, &mut out);
    out
}

/// [`state_row`]'s cells, in its order, each with an empty name ([`push_cells`]): appended to
/// `out`.
pub fn state_cells(state: &StateMsg, out: &mut Vec<Column>) {
    out.push((
        String::new(),
        Cell::Num(state.header.sim_time_ns as f64 / 1e9),
    ));
    push_cells(state, &["effectors"], out);
    for e in &state.effectors {
        let flags = (String::new(), Cell::Int(e.flags.into()));
        match wire_names(e.kind, e.states.len(), e.outputs.len()) {
            // As `push_effectors`: each value beside its name, so as many as there are names.
            Some((_, states, outputs)) => {
                let values = states
                    .iter()
                    .zip(&e.states)
                    .chain(outputs.iter().zip(&e.outputs));
                out.extend(values.map(|(_, x)| (String::new(), Cell::Num(*x))));
            }
            None => {
                out.push((String::new(), Cell::Int(e.kind.into())));
                let values = e.states.iter().chain(&e.outputs);
                out.extend(values.map(|x| (String::new(), Cell::Num(*x))));
            }
        }
        out.push(flags);
    }
}

/// [`prefixed_columns`]'s cells, in its order, each with an empty name: appended to `out`.
pub fn prefixed_cells<T: Serialize>(msg: &T, out: &mut Vec<Column>) {
    push_cells(msg, &["header"], out);
}

/// Prefix of `simulate`'s environment columns (`env_b_n_t_1`, `env_drag_torque_b_nm_1`): the
/// fields of the EnvironmentMsg without its header.
pub const ENVIRONMENT_COLUMN_PREFIX: &str = "env";

/// The fields of `msg` without its header, each column named `<prefix>_<field>`: what
/// `simulate` writes beside the state for a sensor sample (`imu_hub_omega_p_rad_s_1`,
/// `st_st1_valid`) or another record (`wrench_schedule_torque_b_nm_1`).
pub fn prefixed_columns<T: Serialize>(prefix: &str, msg: &T) -> Vec<Column> {
    let mut out = Vec::new();
    push_columns(prefix, msg, &["header"], &mut out);
    out
}

/// Calls `f` with every floating-point value of `state` (the physical fields, the applied
/// wrench, every effector state and output), allocating nothing.
fn for_each_f64(state: &StateMsg, mut f: impl FnMut(f64)) {
    let c = &state.conserved;
    let w = &state.wrench_applied;
    let vectors: [&[f64]; 11] = [
        &state.sigma_bn,
        &state.q_bn,
        &state.omega_bn_b_rad_s,
        &state.omega_dot_bn_b_rad_s2,
        &state.r_bn_n_m,
        &state.v_bn_n_m_s,
        &state.nongrav_accel_bn_n_m_s2,
        &c.orb_ang_mom_n,
        &c.rot_ang_mom_c_n,
        &w.torque_b_nm,
        &w.force_b_newton,
    ];
    vectors.iter().flat_map(|v| v.iter()).for_each(|x| f(*x));
    f(c.orb_energy_j);
    f(c.rot_energy_j);
    for e in &state.effectors {
        e.states.iter().chain(&e.outputs).for_each(|x| f(*x));
    }
}

/// The column of the first non-finite value of `state` ([`state_row`]'s name, e.g.
/// `omega_bn_b_rad_s_2`, `rw1_omega_rad_s`, `conserved_rot_energy_j`), or `None` when every
/// value is finite. Allocates only when it finds one, so the server runs it on every frame.
pub fn first_non_finite(state: &StateMsg) -> Option<String> {
    let mut finite = true;
    for_each_f64(state, |x| finite &= x.is_finite());
    if finite {
        return None;
    }
    first_non_finite_column(&state_row(state)).map(str::to_owned)
}

/// The name of the first cell of `row` that is a non-finite number.
pub fn first_non_finite_column(row: &[Column]) -> Option<&str> {
    row.iter()
        .find(|(_, c)| matches!(c, Cell::Num(x) if !x.is_finite()))
        .map(|(n, _)| n.as_str())
}

/// A CSV table in flexdyn's dialect: the header once, then rows placed by column name, a
/// column a row does not have left empty. The one writer of `simulate` and `export`.
pub struct CsvTable<W: Write> {
    out: io::BufWriter<W>,
    index: HashMap<String, usize>,
    cells: Vec<String>,
}

impl<W: Write> CsvTable<W> {
    /// Writes the header (`columns` in order; names are unique) and returns the table.
    pub fn new(out: W, columns: &[String]) -> io::Result<Self> {
        Self::with_comments(out, &[], columns)
    }

    /// As [`Self::new`], after one `# <comment>` line per comment (e.g. `epoch_utc=…`, what
    /// `t_s = 0` is). Readers skip the leading `#` lines (`flexdyn plot` does; pandas:
    /// `comment="#"`).
    pub fn with_comments(out: W, comments: &[String], columns: &[String]) -> io::Result<Self> {
        let mut out = io::BufWriter::new(out);
        for c in comments {
            writeln!(out, "# {c}")?;
        }
        writeln!(out, "{}", columns.join(","))?;
        Ok(Self {
            out,
            index: columns
                .iter()
                .enumerate()
                .map(|(i, c)| (c.clone(), i))
                .collect(),
            cells: vec![String::new(); columns.len()],
        })
    }

    /// Writes one row. A column that is not in the header is an error (`InvalidInput`), so
    /// nothing is dropped silently.
    pub fn write_row(&mut self, row: &[Column]) -> io::Result<()> {
        self.cells.iter_mut().for_each(String::clear);
        for (name, cell) in row {
            let Some(&i) = self.index.get(name) else {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("column {name} is not in the CSV header"),
                ));
            };
            use std::fmt::Write as _;
            let _ = write!(self.cells[i], "{cell}");
        }
        self.write_cells()
    }

    /// Writes one row from cells given by their column's position in the header (the order of
    /// the columns it was created with), a column not given left empty: [`Self::write_row`]
    /// for a writer that knows where its cells go, without looking up a name per cell. A
    /// position past the header is an error (`InvalidInput`).
    pub fn write_positioned<'c>(
        &mut self,
        cells: impl IntoIterator<Item = (usize, &'c Cell)>,
    ) -> io::Result<()> {
        self.cells.iter_mut().for_each(String::clear);
        let columns = self.cells.len();
        for (i, cell) in cells {
            let Some(text) = self.cells.get_mut(i) else {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("column {i} is past the CSV header's {columns}"),
                ));
            };
            use std::fmt::Write as _;
            let _ = write!(text, "{cell}");
        }
        self.write_cells()
    }

    /// The cells as one CSV line.
    fn write_cells(&mut self) -> io::Result<()> {
        for (i, c) in self.cells.iter().enumerate() {
            if i > 0 {
                self.out.write_all(b",")?;
            }
            self.out.write_all(c.as_bytes())?;
        }
        self.out.write_all(b"\n")
    }

    /// Flushes the buffered rows.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexdyn_proto::{effector_kind, EffectorState, StateMsg};

    /// `state_cells` is `state_row` without the names: the same cells in the same order, for
    /// known and unknown effector kinds, and a non-finite value kept as NaN.
    #[test]
    fn state_cells_are_the_state_rows_cells_without_names() {
        let mut s = StateMsg {
            omega_bn_b_rad_s: [0.1, f64::INFINITY, -0.2],
            ..StateMsg::default()
        };
        s.header.sim_time_ns = 30_000_000;
        s.effectors = vec![
            EffectorState {
                kind: effector_kind::REACTION_WHEEL,
                flags: 1,
                states: vec![42.0],
                outputs: vec![0.5, -0.25],
            },
            EffectorState {
                kind: 77,
                flags: 2,
                states: vec![5.0, 6.0],
                outputs: vec![7.0],
            },
        ];
        let named = state_row(&s);
        let mut cells = Vec::new();
        state_cells(&s, &mut cells);
        assert!(cells.iter().all(|(n, _)| n.is_empty()));
        let text = |row: &[Column]| row.iter().map(|(_, c)| c.to_string()).collect::<Vec<_>>();
        assert_eq!(text(&cells), text(&named));
        assert!(cells
            .iter()
            .any(|(_, c)| matches!(c, Cell::Num(x) if x.is_nan())));
    }

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

    #[test]
    fn the_finite_scan_visits_every_number_of_the_row() {
        // Every Num cell of a state row except t_s (derived from an integer) is a value the
        // allocation-free scan must see; a field added to StateMsg but not to the scan fails.
        let mut s = StateMsg {
            effectors: vec![EffectorState {
                kind: effector_kind::REACTION_WHEEL,
                flags: 1,
                states: vec![1.0, 2.0],
                outputs: vec![3.0, 4.0],
            }],
            ..StateMsg::default()
        };
        let nums = state_row(&s)
            .iter()
            .filter(|(n, c)| n != "t_s" && matches!(c, Cell::Num(_)))
            .count();
        let mut visited = 0;
        for_each_f64(&s, |_| visited += 1);
        assert_eq!(visited, nums);
        assert_eq!(first_non_finite(&s), None);
        s.omega_bn_b_rad_s[1] = f64::NAN;
        assert_eq!(first_non_finite(&s).as_deref(), Some("omega_bn_b_rad_s_2"));
        s.omega_bn_b_rad_s[1] = 0.0;
        s.effectors[0].outputs[1] = f64::INFINITY;
        assert_eq!(
            first_non_finite(&s).as_deref(),
            Some("rw1_friction_torque_nm")
        );
    }
}
