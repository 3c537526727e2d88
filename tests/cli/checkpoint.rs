//! Checkpoints of `flexdyn simulate` (issue 40 §2), run as a user runs them: a run resumed from
//! a checkpoint writes, after the checkpoint's instant, exactly the rows of the uninterrupted
//! run (every byte of every row); a fork resumes with another configuration and matches that
//! configuration's own uninterrupted run; a damaged, foreign or mismatched checkpoint is refused
//! with an error naming the file and the reason.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn flexdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(args)
        .output()
        .expect("runs the flexdyn binary")
}

fn ok(o: &Output, what: &str) {
    assert!(
        o.status.success(),
        "{what}: exit {:?}\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
}

fn scratch(name: &str) -> PathBuf {
    let dir =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("checkpoint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn scenario(name: &str) -> String {
    format!("{}/scenarios/{name}.toml", env!("CARGO_MANIFEST_DIR"))
}

/// A CSV's comment lines, its header line and its data rows.
struct Csv {
    comments: Vec<String>,
    header: String,
    rows: Vec<String>,
}

fn read_csv(path: &Path) -> Csv {
    let text = std::fs::read_to_string(path).unwrap();
    let (comments, rest): (Vec<&str>, Vec<&str>) = text.lines().partition(|l| l.starts_with('#'));
    Csv {
        comments: comments.into_iter().map(String::from).collect(),
        header: rest[0].to_string(),
        rows: rest[1..].iter().map(|s| s.to_string()).collect(),
    }
}

/// The rows strictly after `t_s` (by the `sim_time_ns` column, exact).
fn rows_after(csv: &Csv, t_ns: u64) -> Vec<String> {
    let col = csv
        .header
        .split(',')
        .position(|c| c == "sim_time_ns")
        .expect("a sim_time_ns column");
    csv.rows
        .iter()
        .filter(|r| r.split(',').nth(col).unwrap().parse::<u64>().unwrap() > t_ns)
        .cloned()
        .collect()
}

/// Runs `config` (`None`: the embedded default) for `duration_s`, writing a checkpoint at
/// `at_s`, then resumes from it; asserts that the resumed CSV's rows are every row of the
/// uninterrupted one after `at_s`, byte for byte, with the same comments and header.
fn resume_matches(name: &str, config: Option<&str>, duration_s: &str, log_s: &str, at_s: &str) {
    let full = scratch(&format!("{name}-full.csv"));
    let resumed = scratch(&format!("{name}-resumed.csv"));
    let ckpt = scratch(&format!("{name}.ckpt"));
    let mut args = vec!["simulate"];
    if let Some(c) = config {
        args.extend(["--config", c]);
    }
    args.extend(["--duration-s", duration_s, "--log-every-s", log_s]);
    let mut first = args.clone();
    let full_s = full.to_str().unwrap();
    let ckpt_s = ckpt.to_str().unwrap();
    first.extend([
        "-o",
        full_s,
        "--checkpoint-at-s",
        at_s,
        "--checkpoint",
        ckpt_s,
    ]);
    ok(
        &flexdyn(&first),
        &format!("{name}: the run that writes the checkpoint"),
    );
    // The resume names no configuration: it is the checkpoint's.
    let resumed_s = resumed.to_str().unwrap();
    let second = [
        "simulate",
        "--duration-s",
        duration_s,
        "--log-every-s",
        log_s,
        "-o",
        resumed_s,
        "--resume",
        ckpt_s,
    ];
    ok(&flexdyn(&second), &format!("{name}: the resumed run"));
    let (a, b) = (read_csv(&full), read_csv(&resumed));
    assert_eq!(a.comments, b.comments, "{name}: comments");
    assert_eq!(a.header, b.header, "{name}: header");
    let t_ns = (at_s.parse::<f64>().unwrap() * 1e9).round() as u64;
    let expected = rows_after(&a, t_ns);
    // Rows every log_s from at_s (excluded) to duration_s (included).
    let n = ((duration_s.parse::<f64>().unwrap() - at_s.parse::<f64>().unwrap())
        / log_s.parse::<f64>().unwrap())
    .round() as usize;
    assert_eq!(expected.len(), n, "{name}: rows after the checkpoint");
    assert_eq!(b.rows.len(), n, "{name}: rows of the resumed run");
    for (i, (x, y)) in expected.iter().zip(&b.rows).enumerate() {
        assert_eq!(x, y, "{name}: row {i} after the checkpoint differs");
    }
}

#[test]
fn a_resumed_run_writes_the_uninterrupted_rows_bit_for_bit() {
    // The reference (two dual-hinged panel pairs, no world).
    resume_matches("reference", None, "2", "0.01", "0.73");
    // Every sensor kind but the GPS, wheels, thrusters, magnetorquers, the environment
    // (IGRF, Sun, Moon, shadow, drag and SRP facets) and flight-code streams.
    resume_matches("acs_full", Some(&scenario("acs_full")), "30", "0.1", "12.3");
    // The same with Earth albedo on the coarse sun sensors: the environment's held sample
    // carries the visible cap.
    let with_albedo = std::fs::read_to_string(scenario("acs_full"))
        .unwrap()
        .replace(
            "[environment]\n",
            "[environment]\nalbedo = \"lambertian\"\n",
        );
    let albedo_cfg = scratch("acs_full_albedo.toml");
    std::fs::write(&albedo_cfg, with_albedo).unwrap();
    resume_matches(
        "acs_full_albedo",
        Some(albedo_cfg.to_str().unwrap()),
        "20",
        "0.1",
        "9.9",
    );
    // A GPS with latency, and the environment record.
    resume_matches(
        "leo_environment",
        Some(&scenario("leo_environment")),
        "12",
        "0.05",
        "7.1",
    );
    // Faults: an IMU stuck since 3 s is held through the checkpoint (its held values are
    // state), a wheel seizes after it.
    resume_matches("fdir", Some(&scenario("fdir")), "70", "0.5", "5");
    // A tank drained by thrusters, resumed mid-burn (5 … 65 s), with schedule rows after the
    // checkpoint (65, 70, 72 s) found by time in the resumed run's own schedule.
    resume_matches("depletion", Some(&scenario("depletion")), "75", "0.5", "30");
    // Appended bodies with their own states: slosh particles and a panel chain.
    resume_matches("slosh", Some(&scenario("slosh")), "4", "0.01", "1.5");
    resume_matches(
        "panel_chain",
        Some(&scenario("panel_chain")),
        "3",
        "0.01",
        "1.2",
    );
}

#[test]
fn a_checkpoint_of_a_resumed_run_resumes_too() {
    // 0 → 10 s: checkpoint A at 4 s. Resume A, checkpoint B at 7 s. Resume B: the rows after
    // 7 s are the uninterrupted run's.
    let cfg = scenario("acs_full");
    let full = scratch("chain-full.csv");
    let (a, b) = (scratch("chain-a.ckpt"), scratch("chain-b.ckpt"));
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let base = ["simulate", "--duration-s", "10", "--log-every-s", "0.1"];
    let mut first: Vec<String> = base.iter().map(|x| x.to_string()).collect();
    first.extend(["--config".into(), cfg, "-o".into(), s(&full)]);
    first.extend([
        "--checkpoint-at-s".into(),
        "4".into(),
        "--checkpoint".into(),
        s(&a),
    ]);
    let args = |v: &[String]| flexdyn(&v.iter().map(String::as_str).collect::<Vec<_>>());
    ok(&args(&first), "the first run");
    let mut second: Vec<String> = base.iter().map(|x| x.to_string()).collect();
    second.extend([
        "-o".into(),
        s(&scratch("chain-mid.csv")),
        "--resume".into(),
        s(&a),
    ]);
    second.extend([
        "--checkpoint-at-s".into(),
        "7".into(),
        "--checkpoint".into(),
        s(&b),
    ]);
    ok(&args(&second), "the run resumed from A");
    let last = scratch("chain-last.csv");
    let mut third: Vec<String> = base.iter().map(|x| x.to_string()).collect();
    third.extend(["-o".into(), s(&last), "--resume".into(), s(&b)]);
    ok(&args(&third), "the run resumed from B");
    let expected = rows_after(&read_csv(&full), 7_000_000_000);
    assert_eq!(expected.len(), 30);
    assert_eq!(read_csv(&last).rows, expected);
}

#[test]
fn a_fork_disperses_only_what_comes_after_the_checkpoint() {
    // fdir: rw2 seizes at 60 s. Fork at 5 s with a configuration where it seizes at 20 s: the
    // fork's rows after 5 s are those of that configuration run from t = 0 (up to 20 s the two
    // configurations fly the same, so the checkpoint is that run's state too).
    let original = std::fs::read_to_string(scenario("fdir")).unwrap();
    let marker = "target = \"reaction_wheels.rw2\"\nmode = \"seized\"\nstart_s = 60.0";
    assert!(
        original.contains(marker),
        "scenarios/fdir.toml's rw2 seizure moved"
    );
    let forked = original.replace(
        marker,
        "target = \"reaction_wheels.rw2\"\nmode = \"seized\"\nstart_s = 20.0",
    );
    let fork_cfg = scratch("fdir_fork.toml");
    std::fs::write(&fork_cfg, forked).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let ckpt = scratch("fdir-fork.ckpt");
    let run = |v: &[&str]| flexdyn(v);
    let fdir = scenario("fdir");
    let common = ["simulate", "--duration-s", "40", "--log-every-s", "0.5"];
    let (orig_csv, fork_full, fork_resumed) = (
        scratch("fdir-orig.csv"),
        scratch("fdir-fork-full.csv"),
        scratch("fdir-fork-resumed.csv"),
    );
    let mut a = common.to_vec();
    let (o, c) = (s(&orig_csv), s(&ckpt));
    a.extend([
        "--config",
        &fdir,
        "-o",
        &o,
        "--checkpoint-at-s",
        "5",
        "--checkpoint",
        &c,
    ]);
    ok(&run(&a), "the original run");
    let mut b = common.to_vec();
    let (fc, ff) = (s(&fork_cfg), s(&fork_full));
    b.extend(["--config", &fc, "-o", &ff]);
    ok(&run(&b), "the forked configuration from t = 0");
    let mut f = common.to_vec();
    let fr = s(&fork_resumed);
    f.extend(["--config", &fc, "-o", &fr, "--resume", &c]);
    let out = run(&f);
    ok(&out, "the fork");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("a fork"), "the fork is announced: {err}");
    let fork_rows = read_csv(&fork_resumed).rows;
    assert_eq!(fork_rows, rows_after(&read_csv(&fork_full), 5_000_000_000));
    // And it is a different run from the original after 20 s (the seizure moved).
    let orig_rows = rows_after(&read_csv(&orig_csv), 5_000_000_000);
    assert_eq!(fork_rows.len(), orig_rows.len());
    assert_eq!(
        fork_rows[..30],
        orig_rows[..30],
        "5 … 20 s: the same flight"
    );
    assert_ne!(fork_rows.last(), orig_rows.last(), "after 20 s: rw2 seized");
}

/// Runs a resume of `ckpt` with rows every `log_s` and returns its stderr, asserting exit
/// code 2 and no output.
fn refused(ckpt: &Path, log_s: &str, extra: &[&str]) -> String {
    let mut args = vec![
        "simulate",
        "--duration-s",
        "2",
        "--log-every-s",
        log_s,
        "-o",
        "-",
        "--resume",
        ckpt.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = flexdyn(&args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "refused with exit 2: {err}");
    assert!(o.stdout.is_empty(), "nothing written");
    assert!(
        err.contains(&format!("checkpoint `{}`", ckpt.display())) || err.contains("error: --"),
        "the error names the file (or the option): {err}"
    );
    err
}

#[test]
fn a_damaged_foreign_or_mismatched_checkpoint_is_refused_naming_file_and_reason() {
    let good = scratch("good.ckpt");
    let s = good.to_str().unwrap();
    let o = flexdyn(&[
        "simulate",
        "--duration-s",
        "1",
        "--log-every-s",
        "0.01",
        "-o",
        scratch("good.csv").to_str().unwrap(),
        "--checkpoint-at-s",
        "0.5",
        "--checkpoint",
        s,
    ]);
    ok(&o, "the run that writes the checkpoint");
    let bytes = std::fs::read(&good).unwrap();
    let variant = |name: &str, b: &[u8]| {
        let p = scratch(name);
        std::fs::write(&p, b).unwrap();
        p
    };

    // One bit flipped in the state: the checksum.
    let mut flipped = bytes.clone();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 0x10;
    let e = refused(&variant("flipped.ckpt", &flipped), "0.01", &[]);
    assert!(e.contains("SHA-256 does not match"), "{e}");
    // Cut short.
    let e = refused(
        &variant("short.ckpt", &bytes[..bytes.len() - 100]),
        "0.01",
        &[],
    );
    assert!(e.contains("cut short"), "{e}");
    // Not a checkpoint at all.
    let e = refused(&variant("csv.ckpt", b"t_s,x\n0,1\n"), "0.01", &[]);
    assert!(e.contains("not a flexdyn checkpoint"), "{e}");
    // Another format version (checked before the checksum).
    let mut v2 = bytes.clone();
    v2[8] = 2;
    let e = refused(&variant("v2.ckpt", &v2), "0.01", &[]);
    assert!(e.contains("format version 2"), "{e}");
    // A configuration with another step (acs_full steps 10 ms, the reference 1 ms).
    let e = refused(&good, "0.01", &["--config", &scenario("acs_full")]);
    assert!(e.contains("RK4 step of 1000000 ns; this run has"), "{e}");
    // Same step and frame, another vehicle (the reference has no environment or wheels): the
    // first section that differs is named.
    let e = refused(&good, "0.01", &["--config", &scenario("panel_chain")]);
    assert!(e.contains("does not fit this run"), "{e}");
    assert!(
        e.contains("world / vehicle sc1 / vehicle / spacecraft"),
        "{e}"
    );
    // Rows at another interval than the checkpoint's.
    let e = refused(&good, "0.02", &[]);
    assert!(
        e.contains("--log-every-s") && e.contains("every 0.01 s"),
        "{e}"
    );

    // A refused run leaves an existing output as it was: a resume that does not fit, a
    // checkpoint instant off the rows or at t = 0, for simulate and for fleet.
    let keep = scratch("keep.csv");
    let k = keep.to_str().unwrap();
    let before = "t_s,x\n0,1\n";
    let fleet = scratch("keep_fleet.toml");
    std::fs::write(
        &fleet,
        format!(
            "[[vehicles]]\nid = \"a\"\nspacecraft_file = \"{}\"\n",
            scenario("reference")
        ),
    )
    .unwrap();
    let f = fleet.to_str().unwrap();
    let chain = scenario("panel_chain");
    let cases: [&[&str]; 5] = [
        &["simulate", "--config", &chain, "--resume", s],
        &[
            "simulate",
            "--checkpoint-at-s",
            "0.015",
            "--checkpoint",
            "x.ckpt",
        ],
        &[
            "simulate",
            "--checkpoint-at-s",
            "0",
            "--checkpoint",
            "x.ckpt",
        ],
        &["fleet", f, "--resume", s],
        &[
            "fleet",
            f,
            "--checkpoint-at-s",
            "0.015",
            "--checkpoint",
            "x.ckpt",
        ],
    ];
    for case in cases {
        std::fs::write(&keep, before).unwrap();
        let mut args = case.to_vec();
        args.extend(["--duration-s", "1", "--log-every-s", "0.01", "-o", k]);
        let o = flexdyn(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{case:?}: {err}");
        assert_eq!(
            std::fs::read_to_string(&keep).unwrap(),
            before,
            "{case:?} left the output as it was"
        );
    }
}

#[test]
fn a_resumed_fleet_writes_the_uninterrupted_rows_bit_for_bit() {
    // Two LEO spacecraft with their environments (sharing the Earth's orientation, the Sun and
    // the Moon), the deputy relative to the chief: checkpoint at 7.5 s, resume, compare.
    let scenarios = format!("{}/scenarios/", env!("CARGO_MANIFEST_DIR"));
    let fleet = scratch("leo_pair.toml");
    let text = flexdyn_testkit::fleets::LEO_PAIR.replace(
        "spacecraft_file = \"",
        &format!("spacecraft_file = \"{scenarios}"),
    );
    std::fs::write(&fleet, text).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (full, resumed, ckpt) = (
        scratch("fleet-full.csv"),
        scratch("fleet-resumed.csv"),
        scratch("fleet.ckpt"),
    );
    let (fl, fu, re, ck) = (s(&fleet), s(&full), s(&resumed), s(&ckpt));
    let base = ["fleet", &fl, "--duration-s", "12", "--log-every-s", "0.5"];
    let mut first = base.to_vec();
    first.extend(["-o", &fu, "--checkpoint-at-s", "7.5", "--checkpoint", &ck]);
    ok(&flexdyn(&first), "the fleet run that writes the checkpoint");
    let mut second = base.to_vec();
    second.extend(["-o", &re, "--resume", &ck]);
    ok(&flexdyn(&second), "the resumed fleet");
    let a = std::fs::read_to_string(&full).unwrap();
    let b = std::fs::read_to_string(&resumed).unwrap();
    let (a_lines, b_lines): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    assert_eq!(a_lines[0], b_lines[0], "header");
    let after: Vec<&str> = a_lines[1..]
        .iter()
        .copied()
        .filter(|l| l.split(',').next().unwrap().parse::<f64>().unwrap() > 7.5)
        .collect();
    assert_eq!(after.len(), 9, "rows at 8, 8.5, …, 12 s");
    assert_eq!(&b_lines[1..], &after[..]);
    // A simulate checkpoint is not a fleet's.
    let single = scratch("single.ckpt");
    ok(
        &flexdyn(&[
            "simulate",
            "--duration-s",
            "1",
            "-o",
            &s(&scratch("single.csv")),
            "--checkpoint-at-s",
            "0.5",
            "--checkpoint",
            &s(&single),
        ]),
        "a simulate checkpoint",
    );
    let mut wrong = base.to_vec();
    let si = s(&single);
    wrong.extend(["-o", "-", "--resume", &si]);
    let o = flexdyn(&wrong);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("the front end `simulate`; this run has `fleet`"),
        "{err}"
    );
}

#[test]
fn a_forks_schedule_rows_after_the_checkpoint_apply_at_their_own_times() {
    // depletion: the engine burns from 5 s and stops at 65 s. The fork stops it at 45 s. From a
    // checkpoint at 30 s the fork's rows equal that configuration flown from t = 0: the rows
    // applied by 30 s are found by time in the fork's own schedule, and its 45 s row applies at
    // 45 s.
    let original = std::fs::read_to_string(scenario("depletion")).unwrap();
    let marker = "t_s = 65.0\neffector = \"engine\"\ninputs = [0.0]";
    assert!(
        original.contains(marker),
        "scenarios/depletion.toml's engine cut-off moved"
    );
    let fork_cfg = scratch("depletion_cut_45s.toml");
    std::fs::write(
        &fork_cfg,
        original.replace(marker, "t_s = 45.0\neffector = \"engine\"\ninputs = [0.0]"),
    )
    .unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (ckpt, full, fork) = (
        scratch("depletion-30s.ckpt"),
        scratch("depletion-cut-full.csv"),
        scratch("depletion-cut-fork.csv"),
    );
    let (c, fc, fu, fo) = (s(&ckpt), s(&fork_cfg), s(&full), s(&fork));
    let dep = scenario("depletion");
    let base = ["simulate", "--duration-s", "60", "--log-every-s", "0.5"];
    let mut a = base.to_vec();
    let orig_csv = s(&scratch("depletion-orig.csv"));
    a.extend(["--config", &dep, "-o", &orig_csv]);
    a.extend(["--checkpoint-at-s", "30", "--checkpoint", &c]);
    ok(&flexdyn(&a), "the original run");
    let mut b = base.to_vec();
    b.extend(["--config", &fc, "-o", &fu]);
    ok(&flexdyn(&b), "the fork's configuration from t = 0");
    let mut f = base.to_vec();
    f.extend(["--config", &fc, "-o", &fo, "--resume", &c]);
    ok(&flexdyn(&f), "the fork");
    let fork_rows = read_csv(&fork).rows;
    assert_eq!(fork_rows.len(), 60);
    assert_eq!(fork_rows, rows_after(&read_csv(&full), 30_000_000_000));
    let orig_rows = rows_after(&read_csv(Path::new(&orig_csv)), 30_000_000_000);
    // Rows at 30.5 … 44.5 s (the 45 s row already shows the fork's engine off).
    assert_eq!(fork_rows[..29], orig_rows[..29], "30 … 45 s: the same burn");
    assert_ne!(
        fork_rows[35], orig_rows[35],
        "after 45 s: the fork's engine is off"
    );
}
