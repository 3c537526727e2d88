//! A property test over configurations, run through the `flexdyn` binary as a user would.
//!
//! Start from a shipped configuration (the reference, the IMU scenario with a `[server]`
//! table, the LEO environment scenario with every other sensor kind, and the wheels with a star
//! tracker), apply 1–3 random edits — delete a key or element, change a value's type, extend or
//! truncate an array, insert an unknown key, set an extreme or non-finite number — and check:
//!
//! - either `check-config` accepts the file, and then `simulate` runs it for 1 s, exits 0 and
//!   writes only finite numbers;
//! - or `check-config` rejects it with exit code 2 and exactly one `error:` line, which names the
//!   file and then a TOML path (or a line), and names no Rust type (`Raw`, `struct`, `i128`,
//!   `$__`, …).
//!
//! Seeded (ChaCha8), so a failure reproduces; the failing file is left in the scratch directory
//! and its text is printed.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use rand_chacha::ChaCha8Rng;
use rand_core::{RngCore, SeedableRng};
use toml::{Table, Value};

/// Cases per run; `FLEXDYN_FUZZ_CASES` and `FLEXDYN_FUZZ_SEED` explore further by hand.
const CASES: usize = 300;

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Runs the `flexdyn` binary with `args` (warnings only in the log).
pub(crate) fn flexdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(args)
        .env("RUST_LOG", "warn")
        .output()
        .expect("runs the flexdyn binary")
}

/// A scratch directory for the test `name`, kept after the run (failing files stay to read).
pub(crate) fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn bases() -> Vec<Table> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let reference = std::fs::read_to_string(root.join("reference.toml")).unwrap();
    let imu = std::fs::read_to_string(root.join("imu_tactical.toml")).unwrap();
    let imu_server = format!(
        "{imu}\n[server]\nmode = \"lockstep\"\nparticipants = [1, 2]\nduration_s = 10.0\n\
         stale_after_s = 0.2\nsc_id = \"craft-1\"\n"
    );
    // Every sensor kind, the world's environment and wheels (each number of each sensor kind is
    // also set systematically in `sensor_bounds.rs`).
    let sensors = std::fs::read_to_string(root.join("leo_environment.toml")).unwrap();
    let wheels = std::fs::read_to_string(root.join("wheels_star_tracker.toml")).unwrap();
    vec![
        reference.parse().unwrap(),
        imu_server.parse().unwrap(),
        sensors.parse().unwrap(),
        wheels.parse().unwrap(),
    ]
}

/// A path to a value: keys for tables, indices for arrays.
#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

fn collect_paths(v: &Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match v {
        Value::Table(t) => {
            for (k, x) in t {
                prefix.push(Step::Key(k.clone()));
                out.push(prefix.clone());
                collect_paths(x, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                prefix.push(Step::Index(i));
                out.push(prefix.clone());
                collect_paths(x, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn get_mut<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    let mut cur = v;
    for s in path {
        cur = match (s, cur) {
            (Step::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Step::Index(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(cur)
}

fn pick<'a, T>(rng: &mut ChaCha8Rng, xs: &'a [T]) -> &'a T {
    &xs[(rng.next_u64() % xs.len() as u64) as usize]
}

fn extreme(rng: &mut ChaCha8Rng) -> Value {
    let floats = [
        1e300,
        -1e300,
        1e-300,
        0.0,
        -0.0,
        -1.0,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e20,
        f64::MAX,
        f64::MIN_POSITIVE,
        3.5,
    ];
    if rng.next_u64().is_multiple_of(5) {
        Value::Integer(*pick(rng, &[i64::MAX, i64::MIN, -1, 0, 1 << 40]))
    } else {
        Value::Float(*pick(rng, &floats))
    }
}

fn other_type(rng: &mut ChaCha8Rng) -> Value {
    match rng.next_u64() % 6 {
        0 => Value::String("junk".into()),
        1 => Value::Boolean(true),
        2 => Value::Datetime("1979-05-27T07:32:00Z".parse().unwrap()),
        3 => Value::Table(Table::new()),
        4 => Value::Array(vec![Value::Float(1.0), Value::String("x".into())]),
        _ => Value::Integer(7),
    }
}

/// Applies one random edit; returns a description.
fn edit(doc: &mut Value, rng: &mut ChaCha8Rng) -> String {
    let mut paths = Vec::new();
    collect_paths(doc, &mut Vec::new(), &mut paths);
    let path = pick(rng, &paths).clone();
    let (parent_path, last) = path.split_at(path.len() - 1);
    let kind = rng.next_u64() % 6;
    let parent = get_mut(doc, parent_path).expect("parent exists");
    match (kind, &last[0], parent) {
        (0, Step::Key(k), Value::Table(t)) => {
            t.remove(k);
            format!("delete {path:?}")
        }
        (0, Step::Index(i), Value::Array(a)) => {
            a.remove(*i);
            format!("remove {path:?}")
        }
        (1, _, p) => {
            let v = other_type(rng);
            let d = format!("retype {path:?} to {v:?}");
            *get_mut(p, last).unwrap() = v;
            d
        }
        (2, _, p) => {
            let target = get_mut(p, last).unwrap();
            match target {
                Value::Array(a) if !a.is_empty() && rng.next_u64().is_multiple_of(2) => {
                    a.pop();
                    format!("truncate {path:?}")
                }
                Value::Array(a) => {
                    let extra = a.last().cloned().unwrap_or(Value::Float(0.0));
                    a.push(extra);
                    format!("extend {path:?}")
                }
                other => {
                    *other = extreme(rng);
                    format!("extreme {path:?} = {other:?}")
                }
            }
        }
        (3, _, p) => {
            let target = get_mut(p, last).unwrap();
            match target {
                Value::Table(t) => {
                    t.insert("bogus_key".into(), Value::Float(1.0));
                    format!("insert bogus_key into {path:?}")
                }
                other => {
                    *other = extreme(rng);
                    format!("extreme {path:?} = {other:?}")
                }
            }
        }
        (_, _, p) => {
            let v = extreme(rng);
            let d = format!("extreme {path:?} = {v:?}");
            *get_mut(p, last).unwrap() = v;
            d
        }
    }
}

/// `error: FILE: ` then a TOML path (`a.b[1].c:`), or a message with a line number.
fn names_file_and_field(line: &str, file: &str) -> bool {
    let Some(rest) = line.strip_prefix(&format!("error: {file}: ")) else {
        return false;
    };
    let path_end = rest.find(": ").unwrap_or(0);
    let path = &rest[..path_end];
    let is_path = !path.is_empty()
        && path
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | '[' | ']' | '"'));
    is_path || rest.contains("line ")
}

/// Every number `simulate` wrote is finite: `Err` names the first that is not. Lines starting
/// with `#` are the file's metadata (the epoch), the next is the header; an empty field is a
/// sensor that did not sample on that row.
pub(crate) fn all_finite(stdout: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(stdout);
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().ok_or("no header")?.split(',').collect();
    for (row, line) in lines.enumerate() {
        for (column, field) in header.iter().zip(line.split(',')) {
            if !field.is_empty() && !field.parse::<f64>().is_ok_and(f64::is_finite) {
                return Err(format!("`{field}` in column {column} of row {row}"));
            }
        }
    }
    Ok(())
}

#[test]
fn random_edits_are_accepted_and_run_finite_or_rejected_in_one_clear_line() {
    let dir = scratch("config_fuzz");
    let bases = bases();
    let cases = env_u64("FLEXDYN_FUZZ_CASES", CASES as u64) as usize;
    let mut rng = ChaCha8Rng::seed_from_u64(env_u64("FLEXDYN_FUZZ_SEED", 0x00f1_e0d1));
    let (mut accepted, mut rejected) = (0, 0);
    for case in 0..cases {
        let mut doc = Value::Table(bases[case % bases.len()].clone());
        let n_edits = 1 + (rng.next_u64() % 3) as usize;
        let edits: Vec<String> = (0..n_edits).map(|_| edit(&mut doc, &mut rng)).collect();
        let Value::Table(t) = &doc else {
            unreachable!()
        };
        let Ok(text) = toml::to_string(t) else {
            continue; // not representable as TOML (e.g. a key after a sub-table): skip
        };
        let path = dir.join(format!("case{case}.toml"));
        std::fs::write(&path, &text).unwrap();
        let file = path.to_str().unwrap();
        let context = || format!("case {case}, edits {edits:?}, file {file}:\n{text}");

        let check = flexdyn(&["check-config", file]);
        let err = String::from_utf8_lossy(&check.stderr).to_string();
        match check.status.code() {
            Some(0) => {
                accepted += 1;
                let sim = flexdyn(&[
                    "simulate",
                    "--config",
                    file,
                    "--duration-s",
                    "1",
                    "--log-every-s",
                    "0.1",
                ]);
                let serr = String::from_utf8_lossy(&sim.stderr);
                assert_eq!(
                    sim.status.code(),
                    Some(0),
                    "accepted but simulate failed: {serr}\n{}",
                    context()
                );
                if let Err(e) = all_finite(&sim.stdout) {
                    panic!("non-finite {e} written\n{}", context());
                }
            }
            Some(2) => {
                rejected += 1;
                assert_eq!(err.lines().count(), 1, "{err}\n{}", context());
                let line = err.lines().next().unwrap();
                assert!(
                    names_file_and_field(line, file),
                    "does not name the file and a TOML path or line: {line}\n{}",
                    context()
                );
                for leak in ["Raw", "struct", "i128", "$__", "f64", "u64", "Option<"] {
                    assert!(
                        !line.contains(leak),
                        "leaks `{leak}`: {line}\n{}",
                        context()
                    );
                }
            }
            other => panic!("check-config exited {other:?}: {err}\n{}", context()),
        }
    }
    eprintln!("{cases} cases: {accepted} accepted and ran finite, {rejected} rejected");
    // The property must have been exercised both ways.
    assert!(accepted >= cases / 20, "only {accepted} accepted");
    assert!(rejected >= cases / 2, "only {rejected} rejected");
}
