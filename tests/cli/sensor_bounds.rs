//! Every number of every sensor kind, set to what breaks floats: the configuration fuzz test's
//! property, applied systematically to each registered sensor kind (issue 36: a star tracker
//! with `sigma_cross_boresight_rad = 1e155` passed `check-config`, then `simulate` stopped at
//! step 0 on a non-finite quaternion).
//!
//! The kinds come from the registry ([`flexdyn_sensors::KINDS`]), so a kind added later is
//! covered or this test fails: each must appear in a shipped scenario (`scenarios/*.toml`, the
//! smallest file with a `[[<config_array>]]` is taken). For every float of the kind's first
//! entry (each element of an array), each of the values below is written in turn, and:
//!
//! - either `check-config` accepts the file, and `simulate` runs it for 0.2 s, exits 0 and
//!   writes only finite numbers;
//! - or `check-config` rejects it with exit code 2 and one `error:` line that names the file
//!   and the entry's field (`star_trackers[0].sigma_cross_boresight_rad`).
//!
//! The values: the float range's edges (whose squares or sums overflow), a value just beyond
//! the documented bound of a sensor's error terms ([`flexdyn_kernel::validate::MAX_SENSOR_TERM_SI`]:
//! rejected) and exactly at it (accepted wherever the key is an error term, and then finite).

use std::path::{Path, PathBuf};

use flexdyn_kernel::validate::MAX_SENSOR_TERM_SI;

use super::config_fuzz::{all_finite, flexdyn, scratch};
use toml::{Table, Value};

/// The smallest shipped scenario that configures `array` at its top level, parsed.
fn scenario_with(array: &str) -> Option<(PathBuf, Table)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut found: Vec<(u64, PathBuf, Table)> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let path = e.ok()?.path();
            if path.extension()? != "toml" {
                return None;
            }
            let table: Table = std::fs::read_to_string(&path).ok()?.parse().ok()?;
            // A spacecraft configuration (not a campaign or a fleet file) with the array.
            let has = matches!(table.get(array), Some(Value::Array(a)) if !a.is_empty());
            let spacecraft = table.contains_key("simulation") && !table.contains_key("vehicles");
            (has && spacecraft).then(|| (path.metadata().unwrap().len(), path, table))
        })
        .collect();
    found.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)));
    found.into_iter().next().map(|(_, p, t)| (p, t))
}

/// Every float of `v` (a table entry) with its path below the entry (`bias_c_rad[0]`).
fn float_paths(v: &Value, prefix: String, out: &mut Vec<String>) {
    match v {
        Value::Float(_) => out.push(prefix),
        Value::Table(t) => {
            for (k, x) in t {
                let p = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                float_paths(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                float_paths(x, format!("{prefix}[{i}]"), out);
            }
        }
        _ => {}
    }
}

/// The value at `path` (as [`float_paths`] writes it) below `v`.
fn at_mut<'a>(mut v: &'a mut Value, path: &str) -> &'a mut Value {
    for part in path.split('.') {
        let (key, indices) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        v = v.as_table_mut().unwrap().get_mut(key).unwrap();
        for index in indices.split(['[', ']']).filter(|s| !s.is_empty()) {
            v = &mut v.as_array_mut().unwrap()[index.parse::<usize>().unwrap()];
        }
    }
    v
}

/// The values written in turn: the float range's edges, the documented bound's neighbourhood,
/// and the non-finite ones (TOML's `nan` and `inf`).
fn values() -> Vec<f64> {
    vec![
        1e300,
        -1e300,
        1e155,
        f64::MAX,
        f64::MIN,
        MAX_SENSOR_TERM_SI * 10.0,
        -MAX_SENSOR_TERM_SI * 10.0,
        f64::NAN,
        f64::INFINITY,
    ]
}

/// `simulate` runs `file` for 0.2 s, exits 0 and writes only finite numbers.
fn runs_finite(file: &str, case: &str) {
    let sim = flexdyn(&["simulate", "--config", file, "--duration-s", "0.2"]);
    assert_eq!(
        sim.status.code(),
        Some(0),
        "check-config accepted {case}, but simulate failed: {}",
        String::from_utf8_lossy(&sim.stderr)
    );
    if let Err(e) = all_finite(&sim.stdout) {
        panic!("{case}: simulate wrote {e}");
    }
}

#[test]
fn every_number_of_every_sensor_kind_is_rejected_in_one_line_or_runs_finite() {
    let dir = scratch("sensor_bounds");
    let mut report = Vec::new();
    for kind in flexdyn_sensors::KINDS {
        let array = kind.config_array;
        let (scenario, base) = scenario_with(array).unwrap_or_else(|| {
            panic!(
                "no shipped scenario configures `[[{array}]]` ({}): ship one, so that its bounds \
                 are tested here",
                kind.noun
            )
        });
        let mut fields = Vec::new();
        float_paths(
            &base[array].as_array().unwrap()[0],
            String::new(),
            &mut fields,
        );
        assert!(!fields.is_empty(), "{array}[0] has no float keys");
        let (mut accepted, mut rejected) = (0, 0);
        for field in &fields {
            for value in values() {
                let mut doc = Value::Table(base.clone());
                let entry = &mut doc.as_table_mut().unwrap()[array].as_array_mut().unwrap()[0];
                *at_mut(entry, field) = Value::Float(value);
                let text = toml::to_string(doc.as_table().unwrap()).unwrap();
                let path = dir.join(format!("{array}-{}.toml", fields.len() * 100 + accepted));
                std::fs::write(&path, &text).unwrap();
                let file = path.to_str().unwrap();
                let case = format!(
                    "{array}[0].{field} = {value:e} in a copy of {}",
                    scenario.display()
                );
                let check = flexdyn(&["check-config", file]);
                let err = String::from_utf8_lossy(&check.stderr).to_string();
                match check.status.code() {
                    Some(0) => {
                        accepted += 1;
                        let term = field.split('[').next().unwrap();
                        assert!(
                            !(value.abs() == MAX_SENSOR_TERM_SI * 10.0
                                && kind.config.error_terms.iter().any(|(t, _)| *t == term)),
                            "{case}: accepted beyond the bound of an error term"
                        );
                        runs_finite(file, &case);
                    }
                    Some(2) => {
                        rejected += 1;
                        assert_eq!(err.lines().count(), 1, "{case}: {err}");
                        let line = err.lines().next().unwrap();
                        let key = field.split(['.', '[']).next().unwrap();
                        assert!(
                            line.starts_with(&format!("error: {file}: {array}[0].{key}")),
                            "{case}: the error does not name the file and the field: {line}"
                        );
                    }
                    other => panic!("{case}: check-config exited {other:?}: {err}"),
                }
            }
        }
        report.push(format!(
            "{array} ({}): {} fields, {accepted} accepted and ran finite, {rejected} rejected",
            scenario.file_name().unwrap().to_string_lossy(),
            fields.len()
        ));
    }
    eprintln!("{}", report.join("\n"));
}

/// At the bound, an error term is accepted and the run stays finite: the bound is not tighter
/// than it needs to be, and it is enough. Each kind lists its error terms (noise and bias, in
/// their unit, with their lengths) in [`flexdyn_sensors::params::SensorConfigReader::error_terms`].
#[test]
fn every_error_term_at_its_bound_is_accepted_and_runs_finite() {
    let dir = scratch("sensor_bounds");
    for kind in flexdyn_sensors::KINDS {
        let array = kind.config_array;
        let (scenario, base) = scenario_with(array).expect("a scenario (see the test above)");
        assert!(
            !kind.config.error_terms.is_empty(),
            "{array}: a sensor kind names its noise and bias terms"
        );
        for &(term, len) in kind.config.error_terms {
            let mut doc = Value::Table(base.clone());
            let entry = &mut doc.as_table_mut().unwrap()[array].as_array_mut().unwrap()[0];
            let (t, key) = match term.rsplit_once('.') {
                Some((t, k)) => (
                    entry
                        .as_table_mut()
                        .unwrap()
                        .entry(t)
                        .or_insert_with(|| Value::Table(Table::new()))
                        .as_table_mut()
                        .unwrap(),
                    k,
                ),
                None => (entry.as_table_mut().unwrap(), term),
            };
            let value = match len {
                1 => Value::Float(MAX_SENSOR_TERM_SI),
                n => Value::Array(vec![Value::Float(MAX_SENSOR_TERM_SI); n]),
            };
            t.insert(key.to_owned(), value);
            let text = toml::to_string(doc.as_table().unwrap()).unwrap();
            let path = dir.join(format!("{array}-at-bound.toml"));
            std::fs::write(&path, &text).unwrap();
            let file = path.to_str().unwrap();
            let case = format!(
                "{array}[0].{term} at {MAX_SENSOR_TERM_SI:e} in a copy of {}",
                scenario.display()
            );
            let check = flexdyn(&["check-config", file]);
            assert_eq!(
                check.status.code(),
                Some(0),
                "{case}: {}",
                String::from_utf8_lossy(&check.stderr)
            );
            runs_finite(file, &case);
        }
    }
}

/// Every error term of every sensor kind can be dispersed by a campaign: the built model reports
/// it by its configuration path (`imus[0].gyro.bias_rad_s[2]`), so a dispersion of it is read
/// back and verified (`result.json`'s `applied`). A new user found `imus[0].gyro.bias_rad_s`
/// refused although the documentation said IMU parameters could be dispersed.
#[test]
fn every_error_term_of_every_sensor_kind_is_read_back_for_a_campaign() {
    for kind in flexdyn_sensors::KINDS {
        let array = kind.config_array;
        let (scenario, _) = scenario_with(array).expect("a scenario (see the first test)");
        let cfg = flexdyn_vehicle::config::SimConfig::from_file(&scenario).unwrap();
        let model = flexdyn_campaign::readback::readback(&cfg).unwrap();
        for &(term, len) in kind.config.error_terms {
            let keys: Vec<String> = match len {
                1 => vec![format!("{array}[0].{term}")],
                n => (0..n).map(|i| format!("{array}[0].{term}[{i}]")).collect(),
            };
            for key in keys {
                assert!(
                    model.contains_key(&key),
                    "{key} is not read back, so a campaign refuses to disperse it ({})",
                    scenario.display()
                );
            }
        }
    }
}
