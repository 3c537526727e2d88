//! `flexdyn campaign summarize DIR`: `summary.csv` (one row per planned run), the pass rate with
//! its Wilson score interval, the worst runs per criterion, the runs that are missing or failed
//! (by index, to rerun with `--index`), and histograms and scatter plots.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::execute::{CriterionResult, RunResult};
use super::plan::RunPlan;
use super::verdict::{Outcome, Verdict};

/// What `summarize` found.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// Runs planned.
    pub planned: u32,
    /// Runs with a result that passed every criterion.
    pub passed: u32,
    /// Runs with a result.
    pub completed: u32,
    /// Planned runs without `result.json`.
    pub missing: Vec<u32>,
    /// Runs whose status is not `ok` (server error, controller exit, invalid draw, a Slurm
    /// task that ended without a result), with their outcome.
    pub failed: Vec<(u32, Outcome, String)>,
    /// The planned runs by outcome (a missing run could not be run): the exit code.
    pub verdict: Verdict,
    /// Wilson 95 % interval of the pass rate over the planned runs.
    pub wilson_95: (f64, f64),
    /// With random faults (`[[faults]]` with `mtbf_s`): the pass rate of the runs in which one
    /// activated, and of the others.
    pub random_failures: Option<FailureSplit>,
    /// The report text (also `summary.txt`).
    pub text: String,
    /// Figures written.
    pub figures: Vec<PathBuf>,
}

/// The pass rates of a campaign with random faults, split by whether a random fault activated
/// within the run (its first activation at or before `duration_s`): `(passed, runs)` of each
/// group, planned runs (a missing run counts as not passed, as in the overall rate).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FailureSplit {
    /// Runs in which a random fault activated.
    pub with_failure: (u32, u32),
    /// Runs in which none did.
    pub without_failure: (u32, u32),
}

/// The 95 % normal quantile z = Φ⁻¹(0.975).
pub const Z_95: f64 = 1.959_963_984_540_054;

/// `k of n passed (x %); Wilson 95 % interval lo %–hi %`.
fn rate_line(k: u32, n: u32) -> String {
    let (lo, hi) = wilson(k, n, Z_95);
    format!(
        "{k} of {n} passed ({:.1} %); Wilson 95 % interval {:.1} %–{:.1} %",
        100.0 * f64::from(k) / f64::from(n.max(1)),
        100.0 * lo,
        100.0 * hi
    )
}

/// Wilson score interval for `k` successes in `n` trials at z (Wilson 1927): centre
/// (p̂ + z²/2n)/(1 + z²/n), half-width z/(1 + z²/n)·√(p̂(1−p̂)/n + z²/4n²).
pub fn wilson(k: u32, n: u32, z: f64) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let (k, n) = (f64::from(k), f64::from(n));
    let p = k / n;
    let d = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / d;
    let half = z / d * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// The vehicle and `k` of `faults[k]` or `<vehicle>.faults[k]` (for ordering the columns).
fn fault_index(key: &str) -> (&str, usize) {
    let (vehicle, fault) = key.rsplit_once('.').unwrap_or(("", key));
    let k = fault
        .trim_start_matches("faults[")
        .trim_end_matches(']')
        .parse()
        .unwrap_or(usize::MAX);
    (vehicle, k)
}

fn io(path: &Path, e: impl std::fmt::Display) -> String {
    format!("{}: {e}", path.display())
}

/// The manifest of the campaign in `dir` and its planned runs.
fn read_manifest(dir: &Path) -> Result<(serde_json::Value, Vec<RunPlan>), String> {
    let manifest_path = dir.join("manifest.json");
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&manifest_path).map_err(|e| io(&manifest_path, e))?,
    )
    .map_err(|e| io(&manifest_path, e))?;
    let plans: Vec<RunPlan> = serde_json::from_value(manifest["run_plans"].clone())
        .map_err(|e| io(&manifest_path, format!("run_plans: {e}")))?;
    Ok((manifest, plans))
}

/// The planned runs of the campaign in `dir` (its `manifest.json`).
pub fn planned_runs(dir: &Path) -> Result<Vec<RunPlan>, String> {
    read_manifest(dir).map(|(_, plans)| plans)
}

/// Summarises the campaign in `dir` (written by `plan` and `run`).
pub fn summarize(dir: &Path) -> Result<Summary, String> {
    let manifest_path = dir.join("manifest.json");
    let (manifest, plans) = read_manifest(dir)?;
    let keys: Vec<String> = serde_json::from_value(manifest["dispersed_keys"].clone())
        .map_err(|e| io(&manifest_path, format!("dispersed_keys: {e}")))?;
    let criteria: Vec<String> = serde_json::from_value(manifest["criteria"].clone())
        .map_err(|e| io(&manifest_path, format!("criteria: {e}")))?;
    let axes = criterion_axes(&manifest);
    let mut s = Summary {
        planned: plans.len() as u32,
        ..Summary::default()
    };
    let mut results: Vec<RunResult> = Vec::new();
    for p in &plans {
        let path = dir.join(&p.dir).join("result.json");
        match std::fs::read_to_string(&path) {
            Ok(text) => {
                let r: RunResult = serde_json::from_str(&text).map_err(|e| io(&path, e))?;
                if r.status != "ok" {
                    s.failed.push((r.run, r.outcome, r.status.clone()));
                }
                s.completed += 1;
                if r.passed {
                    s.passed += 1;
                }
                results.push(r);
            }
            Err(_) => s.missing.push(p.run),
        }
    }
    s.verdict = Verdict::of(
        results
            .iter()
            .map(|r| r.outcome)
            .chain(s.missing.iter().map(|_| Outcome::NotRun)),
    );
    // Over a fleet, one hash column per vehicle (`<id>.state_sha256`), in fleet order.
    let vehicles: Vec<String> = manifest["vehicles"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|v| v.as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default();
    // summary.csv
    let mut csv = String::from("run");
    if vehicles.is_empty() {
        csv.push_str(",state_sha256");
    }
    for v in &vehicles {
        write!(csv, ",{v}.state_sha256").ok();
    }
    csv.push_str(",passed");
    for k in &keys {
        write!(csv, ",{k}").ok();
    }
    for c in &criteria {
        write!(csv, ",{c},{c}_passed").ok();
    }
    // The random faults' first activation per run (empty when after the run's end).
    let duration_ns = manifest["duration_s"]
        .as_f64()
        .map_or(u64::MAX, |d| (d * 1e9).round() as u64);
    let random_faults: Vec<String> = {
        let mut v: Vec<String> = plans
            .iter()
            .flat_map(|p| p.random_failures_ns.keys().cloned())
            .collect();
        v.sort_by(|a, b| fault_index(a).cmp(&fault_index(b)));
        v.dedup();
        v
    };
    let failure_in_run = |p: &RunPlan, k: &str| {
        p.random_failures_ns
            .get(k)
            .copied()
            .filter(|t| *t <= duration_ns)
    };
    for k in &random_faults {
        write!(csv, ",{k}.failure_s,{k}.observed_s").ok();
    }
    // Exact: whole seconds and nine decimals of the integer nanoseconds.
    let seconds = |t_ns: u64| format!("{}.{:09}", t_ns / 1_000_000_000, t_ns % 1_000_000_000);
    // Runs whose published first activation is not the planned one (both within the run).
    let mut disagree = Vec::new();
    csv.push_str(",status\n");
    for p in &plans {
        let r = results.iter().find(|r| r.run == p.run);
        let status = r.map_or("missing".to_owned(), |r| r.status.replace([',', '\n'], ";"));
        write!(csv, "{}", p.run).ok();
        if vehicles.is_empty() {
            write!(csv, ",{}", r.map_or("", |r| r.state_sha256.as_str())).ok();
        }
        for v in &vehicles {
            let hash = r.and_then(|r| r.vehicle_state_sha256.get(v));
            write!(csv, ",{}", hash.map_or("", String::as_str)).ok();
        }
        write!(csv, ",{}", r.is_some_and(|r| r.passed)).ok();
        for k in &keys {
            match r.and_then(|r| r.applied.get(k)) {
                Some(v) => write!(csv, ",{v}").ok(),
                None => write!(csv, ",").ok(),
            };
        }
        for c in &criteria {
            match r.and_then(|r| r.criteria.iter().find(|x| &x.name == c)) {
                // No value (a mode never entered, a latency that does not apply): empty.
                Some(x) if x.value.is_nan() => write!(csv, ",,{}", x.passed).ok(),
                Some(x) => write!(csv, ",{},{}", x.value, x.passed).ok(),
                None => write!(csv, ",,").ok(),
            };
        }
        for k in &random_faults {
            let planned = failure_in_run(p, k);
            let observed = r.and_then(|r| r.fault_activations_ns.get(k).copied());
            if r.is_some_and(|r| r.status == "ok") && planned != observed {
                disagree.push((p.run, k, planned, observed));
            }
            let cell = |t: Option<u64>| t.map(seconds).unwrap_or_default();
            write!(csv, ",{},{}", cell(planned), cell(observed)).ok();
        }
        writeln!(csv, ",{status}").ok();
    }
    let csv_path = dir.join("summary.csv");
    std::fs::write(&csv_path, csv).map_err(|e| io(&csv_path, e))?;

    s.wilson_95 = wilson(s.passed, s.planned, Z_95);
    let mut t = String::new();
    // A forked campaign (`start_from`): which checkpoint, what the hashes cover, and the runs
    // that did not start from it.
    if let Some(f) = manifest["start_from"].as_object() {
        let text = |k: &str| f.get(k).and_then(serde_json::Value::as_str);
        let tick = f.get("tick").and_then(serde_json::Value::as_u64);
        let t_s = f.get("t_s").and_then(serde_json::Value::as_f64);
        match (text("file"), text("sha256"), tick, t_s) {
            (Some(file), Some(sha), Some(tick), Some(t_s)) => {
                writeln!(t, "{}", super::fork::line_of(file, sha, tick, t_s)).ok()
            }
            _ => writeln!(
                t,
                "forked (start_from), but the manifest's start_from record is incomplete (it \
                 needs file, sha256, tick and t_s): {}",
                manifest["start_from"]
            )
            .ok(),
        };
        let want = text("sha256").unwrap_or_default();
        for r in results.iter().filter(|r| r.status == "ok") {
            if r.start_from_sha256.is_empty() {
                writeln!(
                    t,
                    "run {}: its result does not record the checkpoint it started from",
                    r.run
                )
                .ok();
            } else if r.start_from_sha256 != want {
                writeln!(
                    t,
                    "run {}: started from a checkpoint with sha256 {}, not the manifest's: the \
                     file changed between the plan and the run, so the run is not a fork of \
                     this campaign's checkpoint",
                    r.run, r.start_from_sha256
                )
                .ok();
            }
        }
    }
    writeln!(
        t,
        "{} of {} planned runs passed ({:.1} %); Wilson 95 % interval {:.1} %–{:.1} % (missing and failed runs count as not passed)",
        s.passed,
        s.planned,
        100.0 * f64::from(s.passed) / f64::from(s.planned.max(1)),
        100.0 * s.wilson_95.0,
        100.0 * s.wilson_95.1
    )
    .ok();
    if !random_faults.is_empty() {
        let mut split = FailureSplit::default();
        for p in &plans {
            let passed = u32::from(results.iter().any(|r| r.run == p.run && r.passed));
            let group = if random_faults.iter().any(|k| failure_in_run(p, k).is_some()) {
                &mut split.with_failure
            } else {
                &mut split.without_failure
            };
            group.0 += passed;
            group.1 += 1;
        }
        writeln!(
            t,
            "random faults ({}): a failure within the run in {} of {} runs",
            random_faults.join(", "),
            split.with_failure.1,
            s.planned
        )
        .ok();
        writeln!(
            t,
            "  runs with a random failure: {}",
            rate_line(split.with_failure.0, split.with_failure.1)
        )
        .ok();
        writeln!(
            t,
            "  runs without: {}",
            rate_line(split.without_failure.0, split.without_failure.1)
        )
        .ok();
        for (run, k, planned, observed) in &disagree {
            let at = |t: &Option<u64>| t.map_or("never".to_owned(), |t| seconds(t) + " s");
            writeln!(
                t,
                "  run {run}: {k} planned at {}, published at {}",
                at(planned),
                at(observed)
            )
            .ok();
        }
        s.random_failures = Some(split);
    } else if manifest["random_faults"] == serde_json::Value::Bool(false) {
        writeln!(
            t,
            "random faults removed (--without-random-faults): compare with the same campaign run \
             with them"
        )
        .ok();
    }
    if !s.missing.is_empty() {
        writeln!(
            t,
            "missing runs (no result.json; rerun with --index): {:?}",
            s.missing
        )
        .ok();
    }
    for (run, outcome, why) in &s.failed {
        match outcome {
            Outcome::NotRun => writeln!(t, "run {run} could not be run: {why}").ok(),
            _ => writeln!(t, "failed run {run}: {why}").ok(),
        };
    }
    let struck = |run: u32| {
        plans
            .iter()
            .find(|p| p.run == run)
            .is_some_and(|p| random_faults.iter().any(|k| failure_in_run(p, k).is_some()))
    };
    for c in &criteria {
        let judged: Vec<(u32, &CriterionResult)> = results
            .iter()
            .filter_map(|r| r.criteria.iter().find(|x| &x.name == c).map(|x| (r.run, x)))
            .collect();
        // Worst first: no value (never entered, never raised) before the largest.
        let mut v: Vec<&(u32, &CriterionResult)> =
            judged.iter().filter(|(_, x)| x.applies).collect();
        v.sort_by(|a, b| b.1.value.total_cmp(&a.1.value));
        let worst: Vec<String> = v
            .iter()
            .take(3)
            .map(|(r, x)| {
                let value = if x.value.is_nan() {
                    format!("none ({})", x.note.as_deref().unwrap_or("no value"))
                } else {
                    format!("{:.6e}", x.value)
                };
                format!("run {r}: {value}{}", if x.passed { "" } else { " (fail)" })
            })
            .collect();
        let fails = v.iter().filter(|x| !x.1.passed).count();
        writeln!(
            t,
            "criterion {c}: {fails} failing; worst: {}",
            worst.join(", ")
        )
        .ok();
        // Its own pass rate over the runs it was judged in and applies to, split like the
        // campaign's when there are random faults.
        let rate = |group: &dyn Fn(u32) -> bool| {
            let n = v.iter().filter(|(r, _)| group(*r)).count() as u32;
            let k = v.iter().filter(|(r, x)| group(*r) && x.passed).count() as u32;
            if n == 0 {
                "no run judged".to_owned()
            } else {
                rate_line(k, n)
            }
        };
        let skipped = judged.len() - v.len();
        let skipped = if skipped > 0 {
            let why = judged
                .iter()
                .find_map(|(_, x)| x.note.as_deref().filter(|_| !x.applies))
                .unwrap_or("");
            format!(
                " (does not apply to {skipped} run{}: {why})",
                if skipped == 1 { "" } else { "s" }
            )
        } else {
            String::new()
        };
        writeln!(t, "  {}{skipped}", rate(&|_| true)).ok();
        if !random_faults.is_empty() {
            writeln!(t, "  runs with a random failure: {}", rate(&struck)).ok();
            writeln!(t, "  runs without: {}", rate(&|r| !struck(r))).ok();
        }
    }
    let text_path = dir.join("summary.txt");
    std::fs::write(&text_path, &t).map_err(|e| io(&text_path, e))?;
    s.text = t;
    s.figures = figures(dir, &results, &keys, &criteria, &axes)?;
    Ok(s)
}

/// A criterion's axis on the campaign figures: its unit and its pass threshold (a run passes
/// when the value is below it).
#[derive(Clone, Debug, PartialEq)]
struct Axis {
    unit: String,
    below: Option<f64>,
}

/// The manifest's `criterion_axes` by criterion name (empty for a manifest written before
/// they were recorded: the figures then have no unit or threshold line).
fn criterion_axes(manifest: &serde_json::Value) -> BTreeMap<String, Axis> {
    let Some(list) = manifest["criterion_axes"].as_array() else {
        return BTreeMap::new();
    };
    list.iter()
        .filter_map(|a| {
            Some((
                a["name"].as_str()?.to_owned(),
                Axis {
                    unit: a["unit"].as_str().unwrap_or("–").to_owned(),
                    below: a["below"].as_f64().filter(|b| b.is_finite()),
                },
            ))
        })
        .collect()
}

/// The colour of a criterion's threshold line (and of nothing else on a campaign figure).
pub const THRESHOLD_RGB: RGBColor = RGBColor(255, 0, 0);
/// The colour of a failed run's point on a scatter figure.
const FAILED_RGB: RGBColor = RGBColor(255, 127, 14);

/// A criterion's histogram: the bins and the x axis.
#[derive(Clone, Debug, PartialEq)]
struct Histogram {
    /// The first bin's lower edge.
    lo: f64,
    /// The bins' width.
    width: f64,
    /// Runs per bin.
    counts: Vec<u32>,
    /// The x axis' range.
    axis: (f64, f64),
    /// Where the threshold line is drawn: at the threshold, or at the axis' edge when the
    /// threshold lies far off the data (`true`).
    threshold_at: Option<(f64, bool)>,
}

/// How much of the x axis the data must keep: an axis stretched to a threshold further off
/// would squeeze the data (issue 36: every run in one bar).
const DATA_SHARE_MIN: f64 = 0.4;

/// The histogram of `values` (finite, at least one) in `bins` bins spanning the data. The
/// axis holds the data with a 5 % margin, and the threshold when that keeps at least
/// [`DATA_SHARE_MIN`] of it for the data; a threshold further off is marked at the axis' edge
/// on its side (its value is in the axis label).
fn histogram(values: &[f64], threshold: Option<f64>, bins: usize) -> Histogram {
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let (lo, hi) = if hi > lo {
        (lo, hi)
    } else {
        (
            lo - 0.5 * lo.abs().max(1e-12),
            hi + 0.5 * hi.abs().max(1e-12),
        )
    };
    let width = (hi - lo) / bins as f64;
    let mut counts = vec![0u32; bins];
    for v in values {
        let b = (((v - lo) / width).max(0.0) as usize).min(bins - 1);
        counts[b] += 1;
    }
    let pad = 0.05 * (hi - lo);
    let (mut a0, mut a1) = (lo - pad, hi + pad);
    let threshold_at = threshold.map(|t| {
        let (t0, t1) = (a0.min(t - pad), a1.max(t + pad));
        if (t0..=t1).contains(&t) && (hi - lo) >= DATA_SHARE_MIN * (t1 - t0) {
            (a0, a1) = (t0, t1);
            (t, false)
        } else if t > hi {
            // Room at the right for the line, inside the axis.
            a1 = hi + 3.0 * pad;
            (hi + 2.0 * pad, true)
        } else {
            a0 = lo - 3.0 * pad;
            (lo - 2.0 * pad, true)
        }
    });
    Histogram {
        lo,
        width,
        counts,
        axis: (a0, a1),
        threshold_at,
    }
}

fn figures(
    dir: &Path,
    results: &[RunResult],
    keys: &[String],
    criteria: &[String],
    axes: &BTreeMap<String, Axis>,
) -> Result<Vec<PathBuf>, String> {
    flexdyn_sinks::plot::register_font().map_err(|e| e.to_string())?;
    let fig_dir = dir.join("figures");
    std::fs::create_dir_all(&fig_dir).map_err(|e| io(&fig_dir, e))?;
    let mut out = Vec::new();
    let font = flexdyn_sinks::plot::FONT_NAME;
    for (ci, c) in criteria.iter().enumerate() {
        let values: Vec<(f64, bool, &RunResult)> = results
            .iter()
            .filter_map(|r| {
                r.criteria
                    .iter()
                    .find(|x| &x.name == c)
                    .map(|x| (x.value, x.passed, r))
            })
            .filter(|(v, _, _)| v.is_finite())
            .collect();
        if values.is_empty() {
            continue;
        }
        let axis = axes.get(c);
        let threshold = axis.and_then(|a| a.below);
        let label = match axis {
            Some(a) => format!("{c} ({})", a.unit),
            None => c.clone(),
        };
        let h = histogram(
            &values.iter().map(|(v, _, _)| *v).collect::<Vec<_>>(),
            threshold,
            12,
        );
        let (lo, hi) = h.axis;
        let (counts, width) = (&h.counts, h.width);
        let path = fig_dir.join(format!("hist_{ci}_{}.png", sanitize(c)));
        {
            let root = BitMapBackend::new(&path, (900, 600)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| io(&path, e))?;
            let max = counts.iter().copied().max().unwrap_or(1);
            let mut chart = ChartBuilder::on(&root)
                .caption(
                    format!("Criterion {c}: distribution over {} runs", values.len()),
                    (font, 24),
                )
                .margin(15)
                .x_label_area_size(45)
                .y_label_area_size(60)
                .build_cartesian_2d(lo..hi, 0u32..max + 1)
                .map_err(|e| io(&path, e))?;
            chart
                .configure_mesh()
                .x_desc(match (threshold, h.threshold_at) {
                    (Some(b), Some((_, true))) => format!(
                        "{label}; red, at the edge: the pass threshold, value < {b} (off the scale)"
                    ),
                    (Some(b), _) => format!("{label}; red: the pass threshold, value < {b}"),
                    _ => label.clone(),
                })
                .y_desc("runs")
                .label_style((font, 16))
                .draw()
                .map_err(|e| io(&path, e))?;
            chart
                .draw_series(counts.iter().enumerate().map(|(i, n)| {
                    let x0 = h.lo + i as f64 * width;
                    Rectangle::new([(x0, 0), (x0 + width, *n)], BLUE.mix(0.6).filled())
                }))
                .map_err(|e| io(&path, e))?;
            if let Some((b, _)) = h.threshold_at {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(b, 0), (b, max + 1)],
                        THRESHOLD_RGB.stroke_width(3),
                    )))
                    .map_err(|e| io(&path, e))?;
            }
            root.present().map_err(|e| io(&path, e))?;
        }
        out.push(path);
        for (ki, k) in keys.iter().enumerate() {
            let pts: Vec<(f64, f64, bool)> = values
                .iter()
                .filter_map(|(v, p, r)| r.applied.get(k).map(|x| (*x, *v, *p)))
                .collect();
            if pts.is_empty() {
                continue;
            }
            let (xl, xh) = pts
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (x, _, _)| {
                    (a.min(*x), b.max(*x))
                });
            let pad = ((xh - xl) * 0.05).max(1e-12 * xl.abs().max(1.0));
            let ypad = 0.0;
            let path = fig_dir.join(format!(
                "scatter_{ci}_{ki}_{}_vs_{}.png",
                sanitize(c),
                sanitize(k)
            ));
            {
                let root = BitMapBackend::new(&path, (900, 600)).into_drawing_area();
                root.fill(&WHITE).map_err(|e| io(&path, e))?;
                let mut chart = ChartBuilder::on(&root)
                    .caption(
                        match h.threshold_at {
                            Some((_, true)) => format!(
                                "{c} against {k} (orange: failed; red line: threshold {}, off the scale)",
                                threshold.unwrap_or_default()
                            ),
                            _ => format!("{c} against {k} (orange: failed; red line: threshold)"),
                        },
                        (font, 22),
                    )
                    .margin(15)
                    .x_label_area_size(45)
                    .y_label_area_size(80)
                    .build_cartesian_2d(xl - pad..xh + pad, lo - ypad..hi + ypad)
                    .map_err(|e| io(&path, e))?;
                chart
                    .configure_mesh()
                    .x_desc(k.as_str())
                    .y_desc(label.as_str())
                    .label_style((font, 16))
                    .draw()
                    .map_err(|e| io(&path, e))?;
                if let Some((b, _)) = h.threshold_at {
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            vec![(xl - pad, b), (xh + pad, b)],
                            THRESHOLD_RGB.stroke_width(3),
                        )))
                        .map_err(|e| io(&path, e))?;
                }
                chart
                    .draw_series(pts.iter().map(|(x, y, p)| {
                        let colour = if *p { BLUE } else { FAILED_RGB };
                        Circle::new((*x, *y), 5, colour.filled())
                    }))
                    .map_err(|e| io(&path, e))?;
                root.present().map_err(|e| io(&path, e))?;
            }
            out.push(path);
        }
    }
    Ok(out)
}

fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixels of `rgb` in a PNG.
    fn pixels_of(path: &Path, rgb: RGBColor) -> usize {
        let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        let bpp = info.line_size / info.width as usize;
        buf[..info.buffer_size()]
            .chunks(bpp)
            .filter(|p| p[..3] == [rgb.0, rgb.1, rgb.2])
            .count()
    }

    #[test]
    fn campaign_figures_carry_the_unit_and_the_threshold_line() {
        // Three runs of a settling-time criterion (s) that passes below 5 s: 2 s and 4 s pass,
        // 7 s fails. The histogram has a vertical red line at 5 s and the scatter a horizontal
        // one; a manifest without criterion_axes (older) gets neither.
        let dir = std::env::temp_dir().join(format!("flexdyn-summary-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let plans: Vec<serde_json::Value> = (0..3)
            .map(|r| {
                serde_json::json!({"run": r, "dir": format!("run-{r:04}"), "run_seed": r,
                    "sensor_seeds": {}, "redraws": 0, "redraw_reasons": [], "valid": true,
                    "dispersed": {"hub.mass_kg": 400.0 + 50.0 * r as f64}})
            })
            .collect();
        for (r, settle) in [2.0, 4.0, 7.0].iter().enumerate() {
            let d = dir.join(format!("run-{r:04}"));
            std::fs::create_dir_all(&d).unwrap();
            let result = RunResult {
                run: r as u32,
                run_seed: r as u64,
                sensor_seeds: BTreeMap::new(),
                redraws: 0,
                applied: [("hub.mass_kg".to_owned(), 400.0 + 50.0 * r as f64)].into(),
                start_tick: 0,
                start_from_sha256: String::new(),
                state_sha256: String::new(),
                vehicle_state_sha256: BTreeMap::new(),
                states: 1,
                fault_activations_ns: BTreeMap::new(),
                criteria: vec![CriterionResult {
                    name: "settle".into(),
                    value: *settle,
                    passed: *settle < 5.0,
                    applies: true,
                    note: None,
                }],
                passed: *settle < 5.0,
                outcome: if *settle < 5.0 {
                    Outcome::Passed
                } else {
                    Outcome::Failed
                },
                status: "ok".into(),
                controller_exit: None,
                controller_exits: BTreeMap::new(),
                wall_s: 0.0,
                sim_s: 10.0,
            };
            std::fs::write(
                d.join("result.json"),
                serde_json::to_string(&result).unwrap(),
            )
            .unwrap();
        }
        let manifest = |axes: bool| {
            let mut m = serde_json::json!({"run_plans": plans, "dispersed_keys": ["hub.mass_kg"],
                "criteria": ["settle"]});
            if axes {
                m["criterion_axes"] =
                    serde_json::json!([{"name": "settle", "unit": "s", "below": 5.0}]);
            }
            std::fs::write(dir.join("manifest.json"), m.to_string()).unwrap();
        };
        manifest(true);
        let s = summarize(&dir).unwrap();
        assert_eq!(s.figures.len(), 2, "{:?}", s.figures);
        for f in &s.figures {
            let red = pixels_of(f, THRESHOLD_RGB);
            // A 3 px line across the plot area (≥ 400 px high or wide).
            assert!(red > 1000, "{}: {red} threshold pixels", f.display());
        }
        assert_eq!(
            criterion_axes(
                &serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap())
                    .unwrap()
            )["settle"],
            Axis {
                unit: "s".into(),
                below: Some(5.0)
            }
        );
        manifest(false);
        let s = summarize(&dir).unwrap();
        for f in &s.figures {
            assert_eq!(pixels_of(f, THRESHOLD_RGB), 0, "{}", f.display());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Issue 36: `scenarios/campaign.toml`'s 20 final pointing errors lie far below the
    /// threshold (0.01); an axis stretched to the threshold put every run in one bar. 20 values
    /// spread over [1e-4, 1e-3) and a threshold 100× beyond the largest: the bins span the data
    /// (at least 5 of 12 hold a run), the axis stops well short of the threshold, which is
    /// marked at its edge.
    #[test]
    fn a_far_threshold_does_not_crush_the_histogram_into_one_bin() {
        let values: Vec<f64> = (0..20).map(|i| 1e-4 + 4.5e-5 * i as f64).collect();
        let top = values[19];
        for threshold in [100.0 * top, -100.0 * top] {
            let h = histogram(&values, Some(threshold), 12);
            let filled = h.counts.iter().filter(|n| **n > 0).count();
            assert!(
                filled >= 5,
                "{threshold}: {filled} non-empty bins {:?}",
                h.counts
            );
            assert_eq!(h.counts.iter().sum::<u32>(), 20);
            let (at, off) = h.threshold_at.unwrap();
            assert!(off && h.axis.0 < at && at < h.axis.1, "{threshold}: {h:?}");
            let span = h.axis.1 - h.axis.0;
            assert!(
                span < 2.0 * (top - values[0]),
                "{threshold}: axis {:?}",
                h.axis
            );
        }
    }

    #[test]
    fn wilson_matches_hand_computed_values() {
        // 18/20 at z = 1.96: p̂ = 0.9, z²/n = 0.19208, d = 1.19208,
        // centre = (0.9 + 0.09604)/1.19208 = 0.835548, half = (1.96/1.19208)·√(0.0045 + 0.002401)
        // = 1.644185 · 0.0830722 = 0.136586 → (0.698962, 0.972134), the published (0.699, 0.972).
        let (lo, hi) = wilson(18, 20, 1.96);
        assert!(
            (lo - 0.698962).abs() < 2e-6 && (hi - 0.972134).abs() < 2e-6,
            "{lo} {hi}"
        );
        // 0 of n stays within [0, 1] and is not a point.
        let (lo, hi) = wilson(0, 10, 1.96);
        assert_eq!(lo, 0.0);
        assert!(hi > 0.2 && hi < 0.35, "{hi}");
    }

    /// Closed forms of Wilson's interval (Wilson 1927, JASA 22:209): with p̂ = 0 the centre and
    /// the half-width are both z²/(2(n + z²)), so the interval is [0, z²/(n + z²)]; with p̂ = 1,
    /// by symmetry, [n/(n + z²), 1]; with p̂ = ½ the centre is ½ and the half-width
    /// z/(1 + z²/n)·√(1/(4n) + z²/(4n²)) = z n/(n + z²)·√(n + z²)/(2n) = z/(2√(n + z²)),
    /// which at n = 10, z = Z_95 (z² = 3.841459) is 1.959964/(2·3.720411) = 0.263407:
    /// (0.236593, 0.763407).
    #[test]
    fn wilson_closed_forms_at_the_extremes_and_at_one_half() {
        let z2 = Z_95 * Z_95;
        for n in [1u32, 4, 8, 50] {
            let nf = f64::from(n);
            let (lo, hi) = wilson(0, n, Z_95);
            assert_eq!(lo, 0.0);
            assert!((hi - z2 / (nf + z2)).abs() < 1e-12, "0 of {n}: {hi}");
            let (lo, hi) = wilson(n, n, Z_95);
            assert!((lo - nf / (nf + z2)).abs() < 1e-12, "{n} of {n}: {lo}");
            assert!((hi - 1.0).abs() < 1e-12);
        }
        let half = Z_95 / (2.0 * (10.0 + z2).sqrt());
        assert!((half - 0.263407).abs() < 1e-6, "{half}");
        let (lo, hi) = wilson(5, 10, Z_95);
        assert!((lo - (0.5 - half)).abs() < 1e-12 && (hi - (0.5 + half)).abs() < 1e-12);
    }
}
