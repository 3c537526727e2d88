//! A campaign that starts every run from one checkpoint (`start_from`), through the binary:
//! `flexdyn campaign checkpoint` flies the base to 4 s of a 5 s run (tick 40 of 50, 80 %), and
//! the forked campaigns start there.
//!
//! The oracle is the uninterrupted run, flown here from t = 0 by the server library with the
//! campaign's own settings and observer (no checkpoint, no resume): its StateMsg payloads from
//! tick 40 on. A forked run whose dispersion changes nothing within the run must hash exactly
//! those; one whose dispersed fault strikes after the checkpoint must publish those bytes up to
//! the fault's frame and differ from the next tick on. Refusals (a dispersed initial state, a
//! fault that could strike before the checkpoint, a missing or damaged checkpoint) must come
//! before any run starts: no output folder is created.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::campaign_support::flexdyn;
use std::time::{Duration, Instant};

use flexdyn_campaign::execute::{single_settings, Observer, RunResult, OBSERVER_ID, SC_ID};
use flexdyn_campaign::spec::Campaign;
use flexdyn_proto::client::transport::{listening_on, zenoh_config, Role, ZenohArgs};
use flexdyn_proto::Topics;
use flexdyn_vehicle::config::SimConfig;
use sha2::{Digest, Sha256};
use zenoh::Wait;

/// \[s\] the run, and the checkpoint at 80 % of it.
const DURATION_S: f64 = 5.0;
const CHECKPOINT_S: f64 = 4.0;
/// acs_full's frame (10 Hz) and RK4 step.
const FRAME_NS: u64 = 100_000_000;
const STEP_NS: u64 = 10_000_000;
const K: u64 = 40;
const LAST_TICK: u64 = 50;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A fresh folder with the base (`scenarios/acs_full.toml` with rw1 seizing at 1000 s, after
/// the runs end) and the campaign that flies it from t = 0, open loop, one run.
fn setup(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let base = format!(
        "{}\n[[faults]]\ntarget = \"reaction_wheels.rw1\"\nmode = \"seized\"\nstart_s = 1000.0\n",
        include_str!("../../scenarios/acs_full.toml")
    );
    std::fs::write(dir.join("base.toml"), base).unwrap();
    std::fs::write(
        dir.join("nominal.toml"),
        format!("base = \"base.toml\"\nruns = 1\nseed = 1\nduration_s = {DURATION_S:?}\n"),
    )
    .unwrap();
    dir
}

/// A campaign forked from `detumbled.ckpt` with `dispersions` (TOML) and a max-rate criterion.
fn forked(dir: &Path, name: &str, runs: u32, dispersions: &str) -> PathBuf {
    let text = format!(
        "start_from = \"detumbled.ckpt\"\nruns = {runs}\nseed = 7\nduration_s = {DURATION_S:?}\n\
         {dispersions}\n[[criteria]]\nname = \"rate\"\nquantity = \"omega\"\nstatistic = \"max\"\n\
         below = 1.0\n"
    );
    let file = dir.join(name);
    std::fs::write(&file, text).unwrap();
    file
}

fn take_checkpoint(dir: &Path) -> PathBuf {
    let ckpt = dir.join("detumbled.ckpt");
    let out = flexdyn(&[
        "campaign",
        "checkpoint",
        dir.join("nominal.toml").to_str().unwrap(),
        "--at-s",
        &CHECKPOINT_S.to_string(),
        "-o",
        ckpt.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(stderr(&out).contains("at tick 40"), "{}", stderr(&out));
    // The campaign file is in the same folder: its start_from is the file name.
    assert!(
        stderr(&out).contains("start_from = \"detumbled.ckpt\" (relative to the campaign file)"),
        "{}",
        stderr(&out)
    );
    ckpt
}

/// The StateMsg payloads of the nominal campaign's base flown from t = 0 to the end, by tick:
/// the server library with the campaign's settings, answered by the campaign's observer.
fn uninterrupted(dir: &Path) -> Vec<(u64, Vec<u8>)> {
    let c = Campaign::from_file(&dir.join("nominal.toml")).unwrap();
    let cfg = SimConfig::from_toml_str_in(&c.base_toml, &c.base_dir()).unwrap();
    fly_from_zero(&c, cfg, None)
}

/// The StateMsg payloads of `cfg` flown from t = 0 to the end with campaign `c`'s settings (no
/// checkpoint, no resume), by tick, recorded to `record` if given.
fn fly_from_zero(c: &Campaign, cfg: SimConfig, record: Option<PathBuf>) -> Vec<(u64, Vec<u8>)> {
    let mut settings = single_settings(c);
    settings.record = record;
    let args = ZenohArgs {
        listen: vec!["tcp/127.0.0.1:0".into()],
        connect: vec![],
        zenoh_config: None,
    };
    let session = zenoh::open(zenoh_config(&args, Role::Server).unwrap())
        .wait()
        .unwrap();
    let endpoint = listening_on(&session).into_iter().next().unwrap();
    let server = std::thread::spawn(move || {
        tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()
            .unwrap()
            .block_on(flexdyn_server::run(
                session,
                settings,
                cfg,
                std::future::pending::<()>(),
            ))
            .map(|r| r.last_tick)
    });
    let obs = Observer::start(&endpoint, &Topics::new(SC_ID).unwrap(), OBSERVER_ID).unwrap();
    let last = server.join().unwrap().unwrap();
    assert_eq!(last, LAST_TICK);
    let give_up = Instant::now() + Duration::from_secs(10);
    loop {
        let mut states = obs.states.lock().unwrap().clone();
        if states.len() as u64 == LAST_TICK + 1 || Instant::now() > give_up {
            states.sort_by_key(|(t, _)| *t);
            let ticks: Vec<u64> = states.iter().map(|(t, _)| *t).collect();
            assert_eq!(ticks, (0..=LAST_TICK).collect::<Vec<_>>());
            return states;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn sha256_hex<'a>(payloads: impl Iterator<Item = &'a [u8]>) -> String {
    let mut h = Sha256::new();
    for p in payloads {
        h.update(p);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

fn run(file: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "campaign",
        "run",
        file.to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
        "--base-port",
        "0",
    ];
    args.extend_from_slice(extra);
    flexdyn(&args)
}

fn result(out: &Path, run: u32) -> RunResult {
    let path = out.join(format!("run-{run:04}")).join("result.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// (1) and (2): a no-op dispersion hashes the uninterrupted run's states from tick K; a fault
/// dispersed after K changes the stream from the tick after it strikes, and not before.
#[test]
fn forked_runs_continue_the_uninterrupted_run_from_the_checkpoint() {
    let dir = setup("campaign_fork");
    let ckpt = take_checkpoint(&dir);
    let reference = uninterrupted(&dir);
    let from_k = || reference.iter().filter(|(t, _)| *t >= K);
    let want = sha256_hex(from_k().map(|(_, p)| p.as_slice()));
    // The whole-run hash differs from the one from K: the comparison below can fail.
    assert_ne!(
        want,
        sha256_hex(reference.iter().map(|(_, p)| p.as_slice()))
    );

    // (1) The fault is moved, but within [900, 950) s: after the end of every run.
    let noop = forked(
        &dir,
        "noop.toml",
        3,
        "[[dispersions]]\nkey = \"faults[0].start_s\"\ndistribution = \"uniform\"\n\
         low = 900.0\nhigh = 950.0\n",
    );
    let out = dir.join("noop-out");
    let o = run(&noop, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let file_sha = sha256_hex(std::iter::once(std::fs::read(&ckpt).unwrap().as_slice()));
    assert!(
        stderr(&o).contains(&format!("(sha256 {file_sha}) at tick {K}")),
        "{}",
        stderr(&o)
    );
    let mut moved = Vec::new();
    for i in 0..3 {
        let r = result(&out, i);
        assert_eq!(r.status, "ok");
        assert_eq!(r.start_tick, K);
        assert_eq!(r.start_from_sha256, file_sha, "run {i}");
        assert_eq!(r.states, LAST_TICK - K + 1);
        assert_eq!(r.state_sha256, want, "run {i}");
        let note = r.criteria[0].note.as_deref().unwrap_or_default();
        assert!(note.contains("seen from tick 40 (t = 4 s)"), "{note}");
        moved.push(r.applied["faults[0].start_s"]);
    }
    assert!(
        moved.iter().all(|t| (900.0..950.0).contains(t)),
        "{moved:?}"
    );
    assert!(
        moved[0] != moved[1],
        "the dispersion drew one value: {moved:?}"
    );
    // The manifest and the summary record the fork.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["start_from"]["sha256"], file_sha.as_str());
    assert_eq!(manifest["start_from"]["tick"], K);
    let sum = flexdyn(&["campaign", "summarize", out.to_str().unwrap()]);
    assert!(
        stderr(&sum).contains(&format!(
            "forked: every run starts from checkpoint {} (sha256 {file_sha}) at tick {K}",
            ckpt.display()
        )),
        "{}",
        stderr(&sum)
    );
    // A run whose result names another checkpoint (the file replaced between the plan and
    // the run) is flagged.
    let r1 = out.join("run-0001").join("result.json");
    let text = std::fs::read_to_string(&r1).unwrap();
    std::fs::write(&r1, text.replace(&file_sha, &"0".repeat(64))).unwrap();
    let sum = flexdyn(&["campaign", "summarize", out.to_str().unwrap()]);
    assert!(
        stderr(&sum).contains(&format!(
            "run 1: started from a checkpoint with sha256 {}, not the manifest's",
            "0".repeat(64)
        )),
        "{}",
        stderr(&sum)
    );
    assert!(
        !stderr(&sum).contains("run 0: started from"),
        "{}",
        stderr(&sum)
    );

    // (2) The seizure is dispersed within (4.3, 4.9) s, after the checkpoint.
    let fault = forked(
        &dir,
        "fault.toml",
        3,
        "[[dispersions]]\nkey = \"faults[0].start_s\"\ndistribution = \"uniform\"\n\
         low = 4.3\nhigh = 4.9\n",
    );
    let out = dir.join("fault-out");
    let o = run(&fault, &out, &["--record"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut hashes = Vec::new();
    for i in 0..3 {
        let r = result(&out, i);
        assert_eq!(r.status, "ok");
        let start_ns = (r.applied["faults[0].start_s"] * 1e9).round() as u64;
        assert!((4_300_000_000..4_900_000_000).contains(&start_ns));
        let struck_ns = r.fault_activations_ns["faults[0]"];
        assert!(
            (start_ns..start_ns + FRAME_NS).contains(&struck_ns),
            "run {i}: planned {start_ns} ns, struck {struck_ns} ns"
        );
        // A fault is looked at once per step, at its start: the first step it acts on starts
        // at the first step boundary at or after its edge, and the first state it changes is
        // the tick after that boundary.
        let first_step_ns = struck_ns.div_ceil(STEP_NS) * STEP_NS;
        let first_changed = first_step_ns / FRAME_NS + 1;
        let forked = recorded_states(&out.join(format!("run-{i:04}")));
        assert_eq!(forked.first().map(|(t, _)| *t), Some(K), "run {i}");
        assert_eq!(forked.len() as u64, LAST_TICK - K + 1, "run {i}");
        for (tick, payload) in &forked {
            let same = reference[*tick as usize].1 == *payload;
            assert_eq!(
                same,
                *tick < first_changed,
                "run {i}, tick {tick}: the seizure struck at {struck_ns} ns"
            );
        }
        assert_eq!(
            r.state_sha256,
            sha256_hex(forked.iter().map(|(_, p)| p.as_slice()))
        );
        hashes.push(r.state_sha256);
    }
    hashes.dedup();
    assert_eq!(hashes.len(), 3, "three fault times, three streams");
}

/// The StateMsg payloads of a run's recording (`<run_dir>/recording.mcap`), by tick.
fn recorded_states(run_dir: &Path) -> Vec<(u64, Vec<u8>)> {
    let state_key = Topics::new(SC_ID).unwrap().state().to_owned();
    let rec = flexdyn_sinks::reader::read_recording(&run_dir.join("recording.mcap")).unwrap();
    let mut states: Vec<(u64, Vec<u8>)> = rec
        .samples
        .iter()
        .filter(|s| s.key == state_key)
        .map(|s| {
            let m = flexdyn_proto::decode_state(&s.payload).unwrap();
            (m.header.tick, s.payload.clone())
        })
        .collect();
    states.sort_by_key(|(t, _)| *t);
    states
}

/// The payloads recorded in `file` under `key`, in log-time order, with their \[ns\] log time.
fn recorded(file: &Path, key: &str) -> Vec<(u64, Vec<u8>)> {
    let rec = flexdyn_sinks::reader::read_recording(file).unwrap();
    let mut out: Vec<(u64, Vec<u8>)> = rec
        .samples
        .iter()
        .filter(|s| s.key == key)
        .map(|s| (s.log_time_ns, s.payload.clone()))
        .collect();
    out.sort_by_key(|(t, _)| *t);
    out
}

/// (4) A random fault (`mtbf_s`) that opens after the checkpoint gets each run's own seed, and
/// the run is the flight of its own configuration: a noise fault on the star tracker, whose
/// generator the checkpoint holds with the base's seed, draws from the run's seed. Each forked
/// run's states from tick K and its star tracker's samples from the checkpoint on are those
/// of its run-NNNN/config.toml flown from t = 0 by the server library.
#[test]
fn a_random_fault_after_the_checkpoint_draws_from_each_runs_own_seed() {
    let dir = setup("campaign_fork_random_fault");
    // faults[1]: noise on st1 from a failure time after 4.05 s (mean 0.1 s later).
    let mut base = std::fs::read_to_string(dir.join("base.toml")).unwrap();
    base.push_str(
        "\n[[faults]]\ntarget = \"star_trackers.st1\"\nmode = \"noise\"\nsigma = 0.01\n\
         start_s = 4.05\nmtbf_s = 0.1\nseed = 5\n",
    );
    std::fs::write(dir.join("base.toml"), base).unwrap();
    take_checkpoint(&dir);
    let file = forked(&dir, "random.toml", 3, "");
    let out = dir.join("random-out");
    let o = run(&file, &out, &["--record"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let c = Campaign::from_file(&file).unwrap();
    let st1 = Topics::new(SC_ID).unwrap().star_tracker("st1").unwrap();
    let t_k = K * FRAME_NS;
    let mut streams = Vec::new();
    for i in 0..3 {
        let r = result(&out, i);
        assert_eq!(r.status, "ok", "run {i}");
        let struck = r.fault_activations_ns.get("faults[1]").copied();
        assert!(
            struck.is_some_and(|t| t > 4_050_000_000),
            "run {i}: the noise fault struck at {struck:?} ns"
        );
        let run_dir = out.join(format!("run-{i:04}"));
        let text = std::fs::read_to_string(run_dir.join("config.toml")).unwrap();
        let cfg = SimConfig::from_toml_str_in(&text, &c.base_dir()).unwrap();
        let whole = dir.join(format!("whole-{i}.mcap"));
        let states = fly_from_zero(&c, cfg, Some(whole.clone()));
        let want = sha256_hex(
            states
                .iter()
                .filter(|(t, _)| *t >= K)
                .map(|(_, p)| p.as_slice()),
        );
        assert_eq!(r.state_sha256, want, "run {i}");
        let forked = recorded(&run_dir.join("recording.mcap"), &st1);
        let from_zero: Vec<_> = recorded(&whole, &st1)
            .into_iter()
            .filter(|(t, _)| *t >= forked.first().map_or(t_k, |f| f.0))
            .collect();
        assert!(forked.len() >= 5, "run {i}: {} st1 samples", forked.len());
        assert!(forked.iter().all(|(t, _)| *t >= t_k));
        assert_eq!(forked.len(), from_zero.len(), "run {i}");
        for (f, z) in forked.iter().zip(&from_zero) {
            assert_eq!(f, z, "run {i}: the st1 sample at {} ns", f.0);
        }
        streams.push(forked);
    }
    // Three seeds, three noise streams.
    assert_ne!(streams[0], streams[1]);
    assert_ne!(streams[1], streams[2]);
    // Without the random faults the runs would not fit the checkpoint, which holds their state.
    let out = dir.join("without-out");
    let o = run(&file, &out, &["--without-random-faults"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("start_from") && e.contains("--without-random-faults would remove 1 fault(s)"),
        "{e}"
    );
    assert!(!out.exists());
}

/// (5) What does not fit a fork or its checkpoint, each refused as invalid input (exit 2)
/// before anything runs: a `base` beside `start_from` that is not the checkpoint's
/// configuration, a checkpoint at or after the end of the runs, a flight-code latency from a
/// fault that opened before the checkpoint; and `campaign checkpoint` of a forked campaign, of
/// a fleet, or at a time that is not a frame boundary within the run. A checkpoint that
/// cannot be written (a missing directory) or whose run stops early is an error (exit 1), and
/// never leaves an older file in its place.
#[test]
fn a_fork_and_its_checkpoint_refuse_what_does_not_fit() {
    let dir = setup("campaign_fork_fit");
    // faults[1]: a star-tracker dropout at 2 s, before the checkpoint.
    let mut base = std::fs::read_to_string(dir.join("base.toml")).unwrap();
    base.push_str(
        "\n[[faults]]\ntarget = \"star_trackers.st1\"\nmode = \"dropout\"\nstart_s = 2.0\n\
         duration_s = 0.5\n",
    );
    std::fs::write(dir.join("base.toml"), base).unwrap();
    let ckpt = take_checkpoint(&dir);
    let refused = |name: &str, text: &str, wants: &[&str]| {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        let out = dir.join(format!("{name}-out"));
        let o = run(&file, &out, &[]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {e}");
        assert!(e.contains(file.to_str().unwrap()), "{name}: {e}");
        for w in wants {
            assert!(e.contains(w), "{name}: wants {w:?} in {e}");
        }
        assert!(!out.exists(), "{name}: refused after the output was made");
    };
    let head = |duration_s: f64| {
        format!(
            "start_from = \"detumbled.ckpt\"\nruns = 2\nseed = 1\nduration_s = {duration_s:?}\n"
        )
    };
    // The unmodified acs_full is not the checkpoint's configuration.
    std::fs::write(
        dir.join("other.toml"),
        include_str!("../../scenarios/acs_full.toml"),
    )
    .unwrap();
    refused(
        "other_base.toml",
        &format!("base = \"other.toml\"\n{}", head(DURATION_S)),
        &[
            "base",
            "other.toml",
            "is not the configuration the checkpoint",
        ],
    );
    refused(
        "short.toml",
        &head(CHECKPOINT_S),
        &["start_from", "at t = 4 s, at or after the end of the runs"],
    );
    refused(
        "latency.toml",
        &format!(
            "{}[[criteria]]\nname = \"recovery\"\nquantity = \"fsw_event_latency\"\n\
             stream = \"acs\"\nevent = \"target-chosen\"\nfault = \"faults[1]\"\nbelow = 1.0\n",
            head(DURATION_S)
        ),
        &[
            "criteria[0].fault",
            "recovery: faults[1] opens at t = 2 s, not after the checkpoint",
        ],
    );

    // campaign checkpoint: invalid input, nothing written.
    let checkpoint = |campaign: &Path, at_s: &str, output: &Path| {
        flexdyn(&[
            "campaign",
            "checkpoint",
            campaign.to_str().unwrap(),
            "--at-s",
            at_s,
            "-o",
            output.to_str().unwrap(),
        ])
    };
    let nominal = dir.join("nominal.toml");
    let new = dir.join("new.ckpt");
    let invalid = |campaign: &Path, at_s: &str, wants: &[&str]| {
        let o = checkpoint(campaign, at_s, &new);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{at_s}: {e}");
        for w in wants {
            assert!(e.contains(w), "wants {w:?} in {e}");
        }
        assert!(!new.exists());
    };
    std::fs::write(dir.join("forked.toml"), head(DURATION_S)).unwrap();
    invalid(
        &dir.join("forked.toml"),
        "2",
        &["start_from", "already starts from a checkpoint"],
    );
    std::fs::write(
        dir.join("fleet.toml"),
        format!(
            "[[vehicles]]\nid = \"chief\"\nspacecraft_file = {:?}\n",
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("scenarios/imu_tactical.toml")
                .display()
                .to_string()
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("over_fleet.toml"),
        "fleet = \"fleet.toml\"\nruns = 1\nseed = 1\nduration_s = 1.0\n",
    )
    .unwrap();
    invalid(
        &dir.join("over_fleet.toml"),
        "0.5",
        &[
            "fleet",
            "a campaign over a fleet cannot start from a checkpoint yet",
        ],
    );
    for at_s in ["0", "4.05", "5", "6"] {
        invalid(
            &nominal,
            at_s,
            &["--at-s", "must be a whole number of frames (frame = 0.1 s)"],
        );
    }

    // Not written: exit 1, and no older file left to pass for the new one.
    let o = checkpoint(&nominal, "2", &dir.join("no-such-dir").join("new.ckpt"));
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("does not exist"), "{}", stderr(&o));
    std::fs::write(
        dir.join("stops.toml"),
        "base = \"base.toml\"\nruns = 1\nseed = 1\n\
        duration_s = 5.0\ncontroller = \"true\"\n",
    )
    .unwrap();
    std::fs::copy(&ckpt, &new).unwrap();
    let o = checkpoint(&dir.join("stops.toml"), "2", &new);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(!new.exists(), "the older checkpoint is still there");
}

/// (3) What the checkpoint already fixed cannot be dispersed, a fault cannot be moved to before
/// it, and a missing or damaged checkpoint is refused: each before any run starts, naming the
/// campaign file, the field and why.
#[test]
fn a_fork_refuses_what_the_checkpoint_already_fixed() {
    let dir = setup("campaign_fork_refusals");
    take_checkpoint(&dir);
    let refused = |name: &str, dispersions: &str, wants: &[&str]| {
        let file = forked(&dir, name, 2, dispersions);
        let out = dir.join(format!("{name}-out"));
        let o = run(&file, &out, &[]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {e}");
        assert!(e.contains(file.to_str().unwrap()), "{name}: {e}");
        for w in wants {
            assert!(e.contains(w), "{name}: wants {w:?} in {e}");
        }
        assert!(!out.exists(), "{name}: refused after the output was made");
    };
    refused(
        "attitude.toml",
        "[[dispersions]]\nkey = \"initial.sigma_bn\"\ndistribution = \"normal\"\nsigma = 0.01\n",
        &[
            "dispersions[0].key",
            "initial.sigma_bn[0] is the state at t = 0",
            "tick 40",
        ],
    );
    refused(
        "mass.toml",
        "[[dispersions]]\nkey = \"hub.mass_kg\"\ndistribution = \"normal\"\nsigma = 1.0\n",
        &[
            "dispersions[0].key",
            "hub.mass_kg acts on the flight from t = 0",
        ],
    );
    refused(
        "early_fault.toml",
        "[[dispersions]]\nkey = \"faults[0].start_s\"\ndistribution = \"uniform\"\n\
         low = 3.5\nhigh = 4.5\n",
        &[
            "dispersions[0].key",
            "low = 3.5 s can draw a start at or before the checkpoint",
        ],
    );
    refused(
        "normal_fault.toml",
        "[[dispersions]]\nkey = \"faults[0].start_s\"\ndistribution = \"normal\"\nsigma = 0.1\n",
        &["a normal distribution can draw a start at or before the checkpoint"],
    );
    // A missing file, and one cut short.
    let ckpt = std::fs::read(dir.join("detumbled.ckpt")).unwrap();
    std::fs::rename(dir.join("detumbled.ckpt"), dir.join("kept.ckpt")).unwrap();
    refused(
        "missing.toml",
        "",
        &["start_from", "detumbled.ckpt", "cannot read it"],
    );
    std::fs::write(dir.join("detumbled.ckpt"), &ckpt[..ckpt.len() / 2]).unwrap();
    refused(
        "damaged.toml",
        "",
        &["start_from", "detumbled.ckpt", "cut short"],
    );
    // A checkpoint of a run with other participants (this one has a controller, sender 1) does
    // not fit: the server's resume check, asked at plan time.
    std::fs::write(dir.join("detumbled.ckpt"), &ckpt).unwrap();
    let with_controller = forked(&dir, "controller.toml", 2, "controller = \"true\"\n");
    let out = dir.join("controller-out");
    let o = run(&with_controller, &out, &[]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("start_from") && e.contains("participant"), "{e}");
    assert!(!out.exists());
}

/// (1) in lockstep with flight code: the reference spacecraft under `flexdyn-acs-demo` (on the
/// true attitude and rate, so its commands are a function of each tick's telemetry alone, which
/// is what a participant must be for a resume to be bit for bit; docs/guides/checkpoints.md).
/// The oracle is the same campaign flown whole from t = 0 with `--record`: its recorded states
/// from the checkpoint's tick on (the recording holds the bytes the server published; the
/// forked runs' hash is over the same bytes as the observer received them).
#[test]
fn forked_runs_with_flight_code_continue_the_uninterrupted_run() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("campaign_fork_fsw");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // A link dropout after the end of the runs: its window is what the forks disperse.
    let base = format!(
        "{}\n[[faults]]\ntarget = \"links.1\"\nmode = \"dropped\"\nstart_s = 1000.0\n\
         duration_s = 0.5\n",
        include_str!("../../scenarios/reference.toml")
    );
    std::fs::write(dir.join("base.toml"), base).unwrap();
    let controller = format!(
        "controller = \"{} --connect {{endpoint}} --sc-id {{sc_id}} --sender-id {{sender_id}} \
         --sigma-rn 0.1,0.2,-0.1 --rate-source truth --log-every-s 0 --idle-exit-s 5\"\n",
        flexdyn_testkit::demo_bin::acs_demo()
    );
    // 2 s at 100 Hz: ticks 0..=200, the checkpoint at 1.6 s (tick 160, 80 %).
    let campaign = |head: &str| {
        format!(
            "{head}\nruns = 2\nseed = 3\nduration_s = 2.0\nsigma_rn = [0.1, 0.2, -0.1]\n\
             {controller}[[dispersions]]\nkey = \"faults[0].start_s\"\ndistribution = \
             \"uniform\"\nlow = 900.0\nhigh = 950.0\n"
        )
    };
    std::fs::write(dir.join("whole.toml"), campaign("base = \"base.toml\"")).unwrap();
    std::fs::write(
        dir.join("forked.toml"),
        campaign("start_from = \"detumbled.ckpt\""),
    )
    .unwrap();
    let o = flexdyn(&[
        "campaign",
        "checkpoint",
        dir.join("whole.toml").to_str().unwrap(),
        "--at-s",
        "1.6",
        "-o",
        dir.join("detumbled.ckpt").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("at tick 160"), "{}", stderr(&o));

    let whole = dir.join("whole-out");
    let o = run(&dir.join("whole.toml"), &whole, &["--record"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let states = recorded_states(&whole.join("run-0000"));
    assert_eq!(
        states.iter().map(|(t, _)| *t).collect::<Vec<_>>(),
        (0..=200).collect::<Vec<_>>()
    );
    // The recording is the stream the observer hashed.
    assert_eq!(
        sha256_hex(states.iter().map(|(_, p)| p.as_slice())),
        result(&whole, 0).state_sha256
    );
    let want = sha256_hex(
        states
            .iter()
            .filter(|(t, _)| *t >= 160)
            .map(|(_, p)| p.as_slice()),
    );

    let forked = dir.join("forked-out");
    let o = run(&dir.join("forked.toml"), &forked, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for i in 0..2 {
        let r = result(&forked, i);
        assert_eq!(r.status, "ok");
        assert_eq!(r.start_tick, 160);
        assert_eq!(r.states, 41);
        assert_eq!(r.controller_exit.as_deref(), Some("exit 0"));
        assert_eq!(r.state_sha256, want, "run {i}");
    }
}
