//! Recordings checked from outside: the `flexdyn` binary writes them (`run --record`, `record`,
//! `replay`, `export`) and independent readers check them — Python's `mcap` package (PyPI,
//! `tests/py/check_recording.py`, in its own venv `<target>/python-mcap-venv`) and the CSV
//! files.

use crate::mcap_support::{first_json_messages, sink_for};
use crate::py_support;
use flexdyn_testkit::ports;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use flexdyn_proto::decode_state;
use flexdyn_sinks::reader::read_recording;
use sha2::{Digest, Sha256};

/// The pinned independent reader (with its zstd and lz4 dependencies).
const MCAP_PY: &str = "mcap==1.6.0";

fn flexdyn() -> Command {
    Command::new(env!("CARGO_BIN_EXE_flexdyn"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("recording_files");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn check_with_python(file: &Path, extra: &[&str]) -> String {
    let python = py_support::venv_python("python-mcap-venv", &[MCAP_PY.into()], MCAP_PY);
    py_support::run(
        Command::new(python)
            .arg(root().join("tests/py/check_recording.py"))
            .arg(file)
            .args(extra),
        "check_recording.py",
    )
}

/// A finished batch run of the wheel scenario recorded by the server itself.
fn batch_recording(name: &str) -> PathBuf {
    batch_recording_of(name, "wheels_star_tracker.toml")
}

/// 5 s of `scenarios/<scenario>` in batch mode, recorded to `name`.
fn batch_recording_of(name: &str, scenario: &str) -> PathBuf {
    let file = tmp(name);
    let _ = std::fs::remove_file(&file);
    py_support::run(
        flexdyn()
            .args(["run", "--mode", "batch", "--duration-s", "5"])
            .args(["--listen", ports::ANY_PORT])
            .arg("--config")
            .arg(root().join("scenarios").join(scenario))
            .arg("--record")
            .arg(&file),
        "flexdyn run --mode batch --record",
    );
    file
}

fn sha_by_key(file: &Path) -> BTreeMap<String, (usize, String)> {
    let rec = read_recording(file).unwrap();
    assert!(rec.truncated.is_none(), "{:?}", rec.truncated);
    let mut h: BTreeMap<String, (usize, Sha256)> = BTreeMap::new();
    for s in &rec.samples {
        let e = h.entry(s.key.clone()).or_insert_with(|| (0, Sha256::new()));
        e.0 += 1;
        e.1.update(&s.payload);
    }
    h.into_iter()
        .map(|(k, (n, d))| {
            (
                k,
                (n, d.finalize().iter().map(|b| format!("{b:02x}")).collect()),
            )
        })
        .collect()
}

struct Guard(Child);

impl Drop for Guard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn spawn(cmd: &mut Command) -> Guard {
    Guard(
        cmd.stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    )
}

/// A `flexdyn run`/`replay` started with `--listen ANY_PORT`, and the endpoint it reports.
fn spawn_listening(cmd: &mut Command) -> (Guard, String) {
    let mut guard = Guard(ports::reporting(cmd).stdout(Stdio::null()).spawn().unwrap());
    let endpoint = ports::zenoh_endpoint(&mut guard.0);
    (guard, endpoint)
}

fn wait_exit(child: &mut Guard, timeout: Duration) -> std::process::ExitStatus {
    let give_up = Instant::now() + timeout;
    loop {
        if let Some(s) = child.0.try_wait().unwrap() {
            return s;
        }
        assert!(Instant::now() < give_up, "the process did not exit in time");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn python_mcap_reads_every_channel_of_a_server_recording() {
    let file = batch_recording("batch.mcap");
    let out = check_with_python(&file, &[]);
    eprintln!("{out}");
    assert!(out.contains("OK clean: "), "{out}");

    // The CSV export has one row per recorded sample, and the state rows' σ are the payloads'.
    let dir = tmp("export");
    let _ = std::fs::remove_dir_all(&dir);
    py_support::run(
        flexdyn().arg("export").arg(&file).arg("--csv").arg(&dir),
        "flexdyn export",
    );
    let rec = read_recording(&file).unwrap();
    let states: Vec<_> = rec
        .samples
        .iter()
        .filter(|s| s.key == "flexdyn/sc1/tlm/state")
        .map(|s| decode_state(&s.payload).unwrap())
        .collect();
    assert_eq!(states.len(), 501, "5 s at 100 Hz, ticks 0..=500");
    let csv = std::fs::read_to_string(dir.join("flexdyn_sc1_tlm_state.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (c_t, c_s2, c_rw) = (col("t_s"), col("sigma_bn_2"), col("rw4_omega_rad_s"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), states.len());
    for (row, st) in rows.iter().zip(&states) {
        assert_eq!(
            row[c_t].parse::<f64>().unwrap(),
            st.header.sim_time_ns as f64 / 1e9,
            "t_s is sim_time_ns / 1e9 (docs/guides/configuration.md, \"CSV output\")"
        );
        assert_eq!(row[c_s2].parse::<f64>().unwrap(), st.sigma_bn[1]);
        assert_eq!(row[c_rw].parse::<f64>().unwrap(), st.effectors[5].states[0]);
    }
    for name in [
        "flexdyn_sc1_tlm_imu_hub.csv",
        "flexdyn_sc1_tlm_st_st1.csv",
        "flexdyn_sc1_status.csv",
    ] {
        assert!(dir.join(name).is_file(), "{name}");
    }
}

#[test]
fn a_recorder_killed_mid_run_leaves_every_finished_chunk_readable() {
    let (mut server, endpoint) = spawn_listening(
        flexdyn()
            .args(["run", "--duration-s", "10"])
            .args(["--listen", ports::ANY_PORT]),
    );
    let file = tmp("killed.mcap");
    let _ = std::fs::remove_file(&file);
    let mut recorder = spawn(
        flexdyn()
            .args(["record", "--connect", &endpoint, "-o"])
            .arg(&file),
    );
    std::thread::sleep(Duration::from_millis(3500));
    recorder.0.kill().unwrap(); // SIGKILL
    let _ = recorder.0.wait();
    let rec = read_recording(&file).unwrap();
    assert!(
        rec.truncated.is_some(),
        "a killed recorder cannot have closed the file"
    );
    let ticks: Vec<u64> = rec
        .samples
        .iter()
        .filter(|s| s.key == "flexdyn/sc1/tlm/state")
        .map(|s| decode_state(&s.payload).unwrap().header.tick)
        .collect();
    // Chunks are flushed every second: after 3.5 s at 100 Hz at least ~2 s are on disk.
    assert!(
        ticks.len() >= 150,
        "only {} states readable: {:?}",
        ticks.len(),
        rec.truncated
    );
    assert!(
        ticks.windows(2).all(|w| w[1] == w[0] + 1),
        "the readable states are not contiguous"
    );
    let out = check_with_python(&file, &["--truncated"]);
    eprintln!("{out} ({} states in Rust)", ticks.len());
    server.0.kill().unwrap();
    let _ = server.0.wait();
}

#[test]
fn a_replayed_recording_records_to_the_same_payloads() {
    let original = batch_recording("original.mcap");
    let again = tmp("again.mcap");
    let _ = std::fs::remove_file(&again);
    // The book's pair (docs/guides/recording.md), on a free port instead of 7447: the replay listens like the server
    // and waits for a subscriber; the recorder connects to it. (That the replay listens on
    // 7447 by default, where the tools connect, is the `replay` module's unit test.)
    let (mut replay, endpoint) = spawn_listening(
        flexdyn()
            .arg("replay")
            .arg(&original)
            .args(["--listen", ports::ANY_PORT]),
    );
    let mut recorder = spawn(
        flexdyn()
            .args(["record", "--connect", &endpoint, "--output"])
            .arg(&again),
    );
    assert!(wait_exit(&mut replay, Duration::from_secs(60)).success());
    std::thread::sleep(Duration::from_millis(500));
    // SIGINT: a clean stop writes the summary.
    Command::new("kill")
        .args(["-INT", &recorder.0.id().to_string()])
        .status()
        .unwrap();
    assert!(wait_exit(&mut recorder, Duration::from_secs(30)).success());
    let a = sha_by_key(&original);
    let b = sha_by_key(&again);
    eprintln!("original {a:?}\nreplayed {b:?}");
    assert_eq!(a["flexdyn/sc1/tlm/state"].0, 501);
    assert_eq!(a, b, "the replayed payloads differ from the recorded ones");
    // The replayed file is a complete recording too.
    let out = check_with_python(&again, &[]);
    assert!(out.contains("OK clean: "), "{out}");
}

/// Resolves a Foxglove message path's field part (`.a.b[0].c`) in a JSON message.
fn resolve<'a>(msg: &'a serde_json::Value, fields: &str) -> Option<&'a serde_json::Value> {
    let mut v = msg;
    for part in fields.split('.').filter(|p| !p.is_empty()) {
        let (name, indices) = part.split_once('[').map_or((part, ""), |(n, i)| (n, i));
        v = v.get(name)?;
        for idx in indices.split('[').filter(|i| !i.is_empty()) {
            v = v.get(idx.trim_end_matches(']').parse::<usize>().ok()?)?;
        }
    }
    Some(v)
}

#[test]
fn the_shipped_foxglove_layout_names_only_recorded_topics_and_fields() {
    // The ACS scenario: wheels, sensors and the actuators' arrows are all recorded; with a
    // fault, so are its events (`tlm/fault`) and the active set in StatusMsg.
    let config = tmp("layout.toml");
    let scenario = std::fs::read_to_string(root().join("scenarios/acs_full.toml")).unwrap();
    std::fs::write(
        &config,
        format!(
            "{scenario}\n[[faults]]\ntarget = \"imus.hub.gyro\"\nmode = \"bias_step\"\n\
             value = 0.01\nstart_s = 1.0\nduration_s = 1.0\n"
        ),
    )
    .unwrap();
    let file = batch_recording_of("layout.mcap", config.to_str().unwrap());
    let mut first = first_json_messages(&std::fs::read(&file).unwrap());
    // The flight code's telemetry (issue 37) is not in a batch recording: a recording of one
    // sample of the stream `acs` that acs_full.toml declares, written by the recorder's sink.
    first.extend(fsw_decoded_messages(&scenario));
    let layout: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("docs/foxglove/flexdyn-layout.json")).unwrap(),
    )
    .unwrap();
    let mut checked = 0;
    for (id, panel) in layout["configById"].as_object().unwrap() {
        let mut paths: Vec<String> = panel["paths"]
            .as_array()
            .map(|a| {
                a.iter()
                    .map(|p| p["value"].as_str().unwrap().to_owned())
                    .collect()
            })
            .unwrap_or_default();
        if let Some(t) = panel["topicPath"].as_str() {
            paths.push(t.to_owned());
        }
        if let Some(topics) = panel["topics"].as_object() {
            paths.extend(topics.keys().cloned());
        }
        for path in paths {
            // The topic is the longest recorded topic the path starts with.
            let (topic, msg) = first
                .iter()
                .filter(|(t, _)| path.starts_with(t.as_str()))
                .max_by_key(|(t, _)| t.len())
                .unwrap_or_else(|| panic!("{id}: no recorded topic for {path}"));
            let fields = &path[topic.len()..];
            assert!(
                resolve(msg, fields).is_some(),
                "{id}: {path}: no field {fields} in {topic}"
            );
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} paths checked");
    // The fault and flight-code panels are among them (a layout without them fails here).
    for panel in [
        "RawMessages!faults",
        "StateTransitions!faults",
        "RawMessages!fsw",
        "StateTransitions!fsw",
    ] {
        assert!(layout["configById"].get(panel).is_some(), "no {panel}");
    }
    assert!(first.contains_key("/flexdyn/sc1/tlm/fault"));
}

/// The first JSON message of each decoded channel of a recording that holds one sample of
/// the flight code's stream `acs` (a mode, an event, an estimate and every declared value),
/// written by [`McapSink`] for a vehicle configured by `config_toml`.
fn fsw_decoded_messages(config_toml: &str) -> BTreeMap<String, serde_json::Value> {
    use flexdyn_proto::{encode, fsw_flags, FswMsg, Header};
    let cfg = flexdyn_vehicle::config::SimConfig::from_toml_str(config_toml).unwrap();
    let words = cfg
        .fsw_stream("acs")
        .expect("acs_full.toml declares acs")
        .words();
    let file = tmp("layout_fsw.mcap");
    let mut sink = sink_for(&file, config_toml);
    let msg = FswMsg {
        header: Header::new(1, 10, 100_000_000, 10),
        flags: fsw_flags::MODE | fsw_flags::ESTIMATE | fsw_flags::TARGET,
        mode: 1,
        q_est_bn: [1.0, 0.0, 0.0, 0.0],
        q_target_rn: [1.0, 0.0, 0.0, 0.0],
        event_count: 1,
        values: vec![0; words],
        ..FswMsg::default()
    };
    sink.write("flexdyn/sc1/fsw/acs", &encode(&msg), Some(1), 100_000_000)
        .unwrap();
    sink.finish().unwrap();
    let first = first_json_messages(&std::fs::read(&file).unwrap());
    assert!(
        first.contains_key("/flexdyn/sc1/fsw/acs"),
        "{:?}",
        first.keys()
    );
    first
}

/// `flexdyn record` of a synthetic publisher whose StateMsg sequence numbers 0..100 skip
/// `skipped`: the exit code, the summary line, and the file's `flexdyn.recorder` metadata.
fn record_states(name: &str, skipped: &[u64]) -> (Option<i32>, String, BTreeMap<String, String>) {
    use flexdyn_proto::client::transport::{zenoh_config, Role, ZenohArgs};
    use flexdyn_proto::{encode, Header, StateMsg};
    use std::io::Read;
    use zenoh::Wait;

    let file = tmp(name);
    let _ = std::fs::remove_file(&file);
    let args = ZenohArgs {
        listen: vec![ports::ANY_PORT.into()],
        ..ZenohArgs::default()
    };
    let session = zenoh::open(zenoh_config(&args, Role::Server).unwrap())
        .wait()
        .unwrap();
    let endpoint = flexdyn_proto::client::transport::listening_on(&session).remove(0);
    let publisher = session
        .declare_publisher("flexdyn/gaps/tlm/state")
        .wait()
        .unwrap();
    let mut recorder = Guard(
        flexdyn()
            .args(["record", "--sc-id", "gaps", "--connect", &endpoint, "-o"])
            .arg(&file)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let give_up = Instant::now() + Duration::from_secs(20);
    while !publisher.matching_status().wait().unwrap().matching() {
        assert!(Instant::now() < give_up, "the recorder never subscribed");
        std::thread::sleep(Duration::from_millis(20));
    }
    for seq in (0..100u64).filter(|s| !skipped.contains(s)) {
        let state = StateMsg {
            header: Header::new(7, seq, seq * 10_000_000, seq),
            ..StateMsg::default()
        };
        publisher.put(encode(&state)).wait().unwrap();
    }
    std::thread::sleep(Duration::from_millis(500));
    Command::new("kill")
        .args(["-INT", &recorder.0.id().to_string()])
        .status()
        .unwrap();
    let status = wait_exit(&mut recorder, Duration::from_secs(30));
    let mut stderr = String::new();
    recorder
        .0
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    let rec = read_recording(&file).unwrap();
    let states = rec
        .samples
        .iter()
        .filter(|s| s.key == "flexdyn/gaps/tlm/state")
        .count();
    assert_eq!(states, 100 - skipped.len(), "{stderr}");
    let meta = rec.metadata["flexdyn.recorder"].clone();
    (status.code(), stderr, meta)
}

/// A recording never claims to be complete when it is not: the publisher's sequence numbers
/// show what is missing, per key, in the metadata, the summary line and the exit code (3).
#[test]
fn a_recording_with_a_sequence_gap_says_it_is_incomplete() {
    let (code, stderr, meta) = record_states("gap.mcap", &[40, 41, 42]);
    eprintln!("{stderr}{meta:?}");
    assert_eq!(code, Some(3), "{stderr}");
    let last = stderr.lines().last().unwrap_or_default();
    assert!(
        last.ends_with(
            "dropped 0; INCOMPLETE: 3 telemetry messages missing (sequence-number gaps: \
             flexdyn/gaps/tlm/state 3)"
        ),
        "{stderr}"
    );
    assert_eq!(meta["missing_samples"], "3");
    assert_eq!(meta["missing_samples.flexdyn/gaps/tlm/state"], "3");
    assert_eq!(meta["complete"], "false");

    let (code, stderr, meta) = record_states("whole.mcap", &[]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stderr
            .lines()
            .last()
            .unwrap_or_default()
            .ends_with("dropped 0; complete"),
        "{stderr}"
    );
    assert_eq!(meta["missing_samples"], "0");
    assert_eq!(meta["complete"], "true");
}

/// A replay that nobody subscribes to says so and fails, instead of claiming it replayed
/// every sample; told not to wait, it replays and counts the samples nobody received.
#[test]
fn a_replay_without_subscribers_says_so() {
    let original = batch_recording("unheard.mcap");
    let out = flexdyn()
        .arg("replay")
        .arg(&original)
        .args(["--listen", ports::ANY_PORT, "--wait-subscriber-s", "1"])
        .env("RUST_LOG", "info")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    // The error names the endpoint the replay really listened on, not the `:0` it was given.
    let listen = ports::find_zenoh_endpoint(&err).expect("the replay reports its endpoint");
    assert_ne!(ports::port_of(&listen), 0);
    let last = err.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("error: no subscriber matched any of the recording's ")
            && last.contains(&format!("the replay listens on {listen}")),
        "{err}"
    );
    let out = flexdyn()
        .arg("replay")
        .arg(&original)
        .args(["--listen", ports::ANY_PORT, "--wait-subscriber-s", "0"])
        .args(["--start-delay-s", "0", "--as-fast-as-possible"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let n = read_recording(&original).unwrap().samples.len();
    assert!(
        err.lines()
            .last()
            .unwrap_or_default()
            .starts_with(&format!("replayed {n} samples in "))
            && err.contains(&format!(
                "; {n} of them while no subscriber matched their key (nobody received those)"
            )),
        "{err}"
    );
}

/// Under CPU load (more busy threads than cores) a recorder next to a 1 kHz real-time server
/// reports exactly what its file misses: the gaps the test counts in the file's sequence
/// numbers, key by key, are the metadata's, the summary's and the exit code's.
#[test]
fn a_recording_under_load_reports_exactly_what_it_misses() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;

    let config = tmp("rt_1khz.toml");
    std::fs::write(
        &config,
        flexdyn_vehicle::config::DEFAULT_CONFIG_TOML
            .replace("frame_hz = 100.0 ", "frame_hz = 1000.0 "),
    )
    .unwrap();
    let (_server, endpoint) = spawn_listening(
        flexdyn()
            .args(["run", "--duration-s", "12", "--listen", ports::ANY_PORT])
            .arg("--config")
            .arg(&config),
    );
    let file = tmp("loaded.mcap");
    let _ = std::fs::remove_file(&file);
    let mut recorder = Guard(
        flexdyn()
            .args(["record", "--connect", &endpoint, "--duration-s", "6"])
            .arg("--output")
            .arg(&file)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let stop = Arc::new(AtomicBool::new(false));
    let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
    let hogs: Vec<_> = (0..cores + 1)
        .map(|_| {
            let stop = stop.clone();
            std::thread::spawn(move || {
                let mut x = 0u64;
                while !stop.load(Ordering::Relaxed) {
                    x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
                }
                x
            })
        })
        .collect();
    std::thread::sleep(Duration::from_secs(5));
    stop.store(true, Ordering::Relaxed);
    for h in hogs {
        h.join().unwrap();
    }
    let status = wait_exit(&mut recorder, Duration::from_secs(30));
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut recorder.0.stderr.take().unwrap(), &mut stderr).unwrap();
    let rec = read_recording(&file).unwrap();
    // The test's own count: per telemetry key, the jumps of header.seq.
    let mut last: BTreeMap<&str, u64> = BTreeMap::new();
    let mut gaps: BTreeMap<String, u64> = BTreeMap::new();
    for s in &rec.samples {
        let seq = match s.key.as_str() {
            "flexdyn/sc1/tlm/state" => decode_state(&s.payload).unwrap().header.seq,
            "flexdyn/sc1/status" => flexdyn_proto::decode_status(&s.payload).unwrap().header.seq,
            "flexdyn/sc1/tlm/time" => flexdyn_proto::decode_time(&s.payload).unwrap().header.seq,
            _ => continue,
        };
        if let Some(prev) = last.insert(&s.key, seq) {
            if seq > prev + 1 {
                *gaps.entry(s.key.clone()).or_default() += seq - prev - 1;
            }
        }
    }
    let states = rec
        .samples
        .iter()
        .filter(|s| s.key == "flexdyn/sc1/tlm/state")
        .count();
    let missing: u64 = gaps.values().sum();
    eprintln!(
        "under load: {states} states recorded, {missing} messages missing {gaps:?}\n{stderr}"
    );
    // 6 s at 1 kHz, less the recorder's start.
    assert!(states > 3000, "{stderr}");
    let meta = &rec.metadata["flexdyn.recorder"];
    assert_eq!(meta["missing_samples"], missing.to_string());
    for (key, n) in &gaps {
        assert_eq!(meta[&format!("missing_samples.{key}")], n.to_string());
    }
    assert_eq!(meta["complete"], (missing == 0).to_string());
    let last_line = stderr.lines().last().unwrap_or_default();
    if missing == 0 {
        assert_eq!(status.code(), Some(0), "{stderr}");
        assert!(last_line.ends_with("dropped 0; complete"), "{stderr}");
    } else {
        assert_eq!(status.code(), Some(3), "{stderr}");
        assert!(
            last_line.contains(&format!("INCOMPLETE: {missing} telemetry messages missing")),
            "{stderr}"
        );
    }
}

/// The environment message of `scenarios/leo_environment.toml` (`telemetry_rate_hz = 10`) is
/// recorded raw and decoded: the independent `mcap` reader decodes every raw EnvironmentMsg by
/// the README's offsets and finds it equal to the JSON channel's, and `export` writes one row
/// per message.
#[test]
fn python_mcap_decodes_the_environment_channel() {
    let file = batch_recording_of("environment.mcap", "leo_environment.toml");
    let out = check_with_python(&file, &[]);
    eprintln!("{out}");
    assert!(out.contains("OK clean: "), "{out}");
    // 5 s at 10 Hz: ticks 0, 10, …, 500.
    assert!(
        out.contains("environment messages: 51 raw = decoded"),
        "{out}"
    );
    let dir = tmp("export-env");
    let _ = std::fs::remove_dir_all(&dir);
    py_support::run(
        flexdyn().arg("export").arg(&file).arg("--csv").arg(&dir),
        "flexdyn export",
    );
    let csv = std::fs::read_to_string(dir.join("flexdyn_sc1_tlm_env.csv")).unwrap();
    let mut lines = csv.lines().skip_while(|l| l.starts_with('#'));
    let header = lines.next().unwrap();
    for col in [
        "b_n_t_1",
        "shadow_factor",
        "eclipse",
        "gravity_gradient_torque_b_nm_1",
        "residual_dipole_torque_b_nm_3",
    ] {
        assert!(header.split(',').any(|h| h == col), "{col} in {header}");
    }
    assert_eq!(lines.count(), 51);

    // The scenario's GPS receiver (issue 20) goes through the same generic sensor loop: 1 Hz
    // with 0.2 s latency, so in 5 s (ticks 0..=500) it publishes at ticks 20, 120, …, 420,
    // each carrying the solution valid 0.2 s earlier.
    let csv = std::fs::read_to_string(dir.join("flexdyn_sc1_tlm_gps_gps1.csv")).unwrap();
    let mut lines = csv.lines().skip_while(|l| l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("{name} in {header:?}"))
    };
    let (tick, sim_t, valid, week, flags) = (
        col("tick"),
        col("sim_time_ns"),
        col("valid_sim_time_ns"),
        col("gps_week"),
        col("flags"),
    );
    col("r_be_e_m_1");
    col("v_bn_n_m_s_3");
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let ticks: Vec<&str> = rows.iter().map(|r| r[tick]).collect();
    assert_eq!(ticks, ["20", "120", "220", "320", "420"]);
    for r in &rows {
        let (t, v): (u64, u64) = (r[sim_t].parse().unwrap(), r[valid].parse().unwrap());
        assert_eq!(t - v, 200_000_000);
        assert_eq!((r[week], r[flags]), ("2446", "7"));
    }
}

/// Several vehicles in one recording (issue 22: `record` must handle them): two servers, each a
/// vehicle under its own id on its own port, recorded by one `flexdyn record` connected to both.
/// The file describes both vehicles, holds each one's contiguous state stream with its own
/// spacecraft id, and `plot --relative-to` draws one relative to the other from it.
#[test]
fn one_recording_holds_several_vehicles() {
    let scenario = |name: &str| root().join("scenarios").join(name);
    let (mut chief, e1) = spawn_listening(
        flexdyn()
            .args([
                "run",
                "--duration-s",
                "8",
                "--sc-id",
                "chief",
                "--spacecraft-id",
                "1",
            ])
            .args(["--listen", ports::ANY_PORT, "--config"])
            .arg(scenario("reference.toml")),
    );
    let (mut deputy, e2) = spawn_listening(
        flexdyn()
            .args([
                "run",
                "--duration-s",
                "8",
                "--sc-id",
                "deputy",
                "--spacecraft-id",
                "2",
            ])
            .args(["--listen", ports::ANY_PORT, "--config"])
            .arg(scenario("leo_environment.toml")),
    );
    let file = tmp("two_vehicles.mcap");
    let _ = std::fs::remove_file(&file);
    let status = flexdyn()
        .args([
            "record",
            "--connect",
            &e1,
            "--connect",
            &e2,
            "--duration-s",
            "3",
            "-o",
        ])
        .arg(&file)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    for server in [&mut chief, &mut deputy] {
        server.0.kill().unwrap();
        let _ = server.0.wait();
    }
    let rec = read_recording(&file).unwrap();
    assert!(rec.truncated.is_none(), "{:?}", rec.truncated);
    let mut described: Vec<String> = rec.vehicles().into_iter().map(|v| v.sc_id).collect();
    described.sort();
    assert_eq!(described, ["chief", "deputy"]);
    for (sc, id) in [("chief", 1), ("deputy", 2)] {
        let key = format!("flexdyn/{sc}/tlm/state");
        let states: Vec<_> = rec
            .samples
            .iter()
            .filter(|s| s.key == key)
            .map(|s| decode_state(&s.payload).unwrap())
            .collect();
        // About 3 s at 100 Hz, each stream contiguous and stamped with its vehicle's id.
        assert!(states.len() >= 150, "{sc}: {} states", states.len());
        assert!(states
            .windows(2)
            .all(|w| w[1].header.tick == w[0].header.tick + 1));
        assert!(states.iter().all(|s| s.header.spacecraft_id == id), "{sc}");
    }
    // Both scenarios step 100 Hz frames from t = 0, so the recorded instants coincide.
    crate::plots::plot_relative_motion(&file, "two_vehicles_plots");
}

/// The 3D channels of a recording draw the panel chains and the propellant tanks (issue 39): a
/// batch run of `scenarios/panel_chain.toml` records a frame per chain panel in `/tf` and a box
/// in each of them in `/scene`; one of `scenarios/depletion.toml` records each tank's shell in
/// `/scene` and, with every state, the propellant sphere inside it in `/actuators` (full at
/// the start: the engine fires from 5 s, after the run, so the two spheres are one size).
#[test]
fn a_recording_draws_the_chains_and_the_tanks() {
    let chains = first_json_messages(
        &std::fs::read(batch_recording_of("chains.mcap", "panel_chain.toml")).unwrap(),
    );
    let frames: Vec<String> = chains["/flexdyn/sc1/tf"]["transforms"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["child_frame_id"].as_str().unwrap().to_owned())
        .collect();
    let expected: Vec<String> = (1..=4)
        .map(|k| format!("sc1/wing_px/panel{k}"))
        .chain((1..=3).map(|k| format!("sc1/wing_mx/panel{k}")))
        .collect();
    for f in &expected {
        assert!(frames.contains(f), "no transform to {f}: {frames:?}");
    }
    let boxes: Vec<&str> = chains["/flexdyn/sc1/scene"]["entities"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| !e["cubes"].as_array().unwrap().is_empty())
        .map(|e| e["frame_id"].as_str().unwrap())
        .collect();
    assert_eq!(boxes.len(), 1 + expected.len(), "{boxes:?}");
    assert!(expected.iter().all(|f| boxes.contains(&f.as_str())));

    let tanks = first_json_messages(
        &std::fs::read(batch_recording_of("tanks.mcap", "depletion.toml")).unwrap(),
    );
    let sphere_of = |update: &serde_json::Value, id: &str| -> f64 {
        let e = update["entities"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["id"] == id)
            .unwrap_or_else(|| panic!("no entity {id}"));
        e["spheres"][0]["size"]["x"].as_f64().unwrap()
    };
    for k in 0..2 {
        let shell = sphere_of(&tanks["/flexdyn/sc1/scene"], &format!("sc1/tank{k}"));
        let fill = sphere_of(
            &tanks["/flexdyn/sc1/actuators"],
            &format!("sc1/propellant{k}"),
        );
        assert!(shell > 0.0 && fill == shell, "tank {k}: {fill} in {shell}");
    }
}
