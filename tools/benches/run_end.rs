//! A run that ends for everyone (issue 37 §4): the time from the lockstep server's last tick to
//! each client's exit, against the target of 100 ms.
//!
//! Each measurement is one lockstep run of the reference spacecraft (0.5 s at 100 Hz, ticks
//! 0..=50) on a server in this process, with one client as a child process:
//! - `flexdyn-acs-demo` (the Rust client), the participant, without `--idle-exit-s`;
//! - `flexdyn-monitor --plain` watching, with the demo as the participant;
//! - `pd_lockstep` (clients/c/examples: the C library's `flexdyn_lockstep_wait` until it returns
//!   `FLEXDYN_ENDED`), built here with `cc` against `libflexdyn_client.a`;
//! - a Python `LockstepParticipant` whose `wait()` returns on the end (the project's venv,
//!   `target/python-venv`, which `cargo test --workspace --release` makes).
//!
//! A session in this process stamps the arrival of the last tick's StateMsg and of the server's
//! last StatusMsg (the end-of-run notice, `run_state` finished); a thread per child stamps its
//! exit (`wait()` returning). Printed per client: the median and the largest over the runs of
//! exit − last tick and exit − notice, and the median's ratio to the 100 ms target.
//!
//! `cargo bench -p flexdyn-tools --bench run_end`; `FLEXDYN_BENCH_RUN_END_RUNS` (default 7).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use flexdyn_proto::{decode_state, decode_status, Mode, Topics};
use flexdyn_server::ServerSettings;
use flexdyn_testkit::demo_bin;
use flexdyn_testkit::median_mut;
use flexdyn_testkit_server::{connecting_session, endpoint, reference_config, ServerHandle};
use zenoh::Wait;

/// The run's last tick: 0.5 s at 100 Hz.
const LAST_TICK: u64 = 50;
/// \[ms\] the target.
const TARGET_MS: f64 = 100.0;

/// The Python participant: answers every tick with a zero wrench until the run ends.
const PYTHON_PARTICIPANT: &str = "
import sys, flexdyn
with flexdyn.Client(sys.argv[1]) as client:
    with flexdyn.LockstepParticipant(
            client, sender_id=1,
            on_state=lambda s: ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))) as p:
        p.wait()
";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// What `cargo build -p package` produced that ends with `suffix` (`.a`).
fn cargo_artifact(package: &str, suffix: &str) -> PathBuf {
    flexdyn_testkit::cargo_build::cargo_build(&root(), &["-p", package])
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["reason"] == "compiler-artifact")
        .flat_map(|m| {
            m["filenames"]
                .as_array()
                .cloned()
                .unwrap_or_default()
                .into_iter()
                .filter_map(|f| f.as_str().map(PathBuf::from))
                .collect::<Vec<_>>()
        })
        .find(|f| f.to_string_lossy().ends_with(suffix))
        .unwrap_or_else(|| panic!("cargo built no {suffix} for {package}"))
}

/// `clients/c/examples/pd_lockstep.c` linked against the C client library.
fn build_pd_lockstep() -> PathBuf {
    let lib = cargo_artifact("flexdyn-client", "libflexdyn_client.a");
    let exe = Path::new(env!("CARGO_TARGET_TMPDIR")).join("run_end_pd_lockstep");
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(&compiler)
        .args(["-std=c99", "-O2", "-I"])
        .arg(root().join("proto/c/include"))
        .arg("-I")
        .arg(root().join("clients/c/include"))
        .arg(root().join("clients/c/examples/pd_lockstep.c"))
        .arg(&lib)
        .args(flexdyn_testkit::cargo_build::NATIVE_LIBS)
        .arg("-o")
        .arg(&exe)
        .status()
        .unwrap_or_else(|e| panic!("cannot run {compiler} ({e}): install gcc or set CC"));
    assert!(status.success(), "{compiler} failed on pd_lockstep.c");
    exe
}

/// The project's Python venv, if `cargo test --workspace --release` has made it.
fn venv_python() -> Option<PathBuf> {
    let python = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()?
        .join("python-venv/bin/python");
    python.is_file().then_some(python)
}

/// A client of a run: its command line, given the server's endpoint, and whether the demo must
/// be the participant beside it (a watcher).
struct Client {
    name: &'static str,
    command: Box<dyn Fn(&str) -> Command>,
    watcher: bool,
}

fn demo(connect: &str) -> Command {
    let mut c = Command::new(demo_bin::acs_demo());
    c.args(["--connect", connect, "--sender-id", "1"]).args([
        "--rate-source",
        "truth",
        "--log-every-s",
        "0",
    ]);
    c
}

fn spawn(mut cmd: Command) -> Child {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn a client")
}

/// Stamps a child's exit.
fn exit_stamp(mut child: Child) -> std::sync::mpsc::Receiver<(Instant, bool)> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let ok = child.wait().is_ok_and(|s| s.success());
        let _ = tx.send((Instant::now(), ok));
    });
    rx
}

/// One run with `client`: (exit − last tick, exit − end notice) in ms.
fn one_run(client: &Client) -> (f64, f64) {
    let settings = ServerSettings {
        mode: Mode::Lockstep,
        participants: vec![1],
        duration_ns: Some(LAST_TICK * 10_000_000),
        summary_interval: Duration::from_secs(3600),
        ..ServerSettings::default()
    };
    let server = ServerHandle::start(settings, reference_config(100.0));
    let topics = Topics::new("sc1").unwrap();
    let watch = connecting_session(server.port);
    let last_tick: Arc<Mutex<Option<Instant>>> = Arc::default();
    let notice: Arc<Mutex<Option<Instant>>> = Arc::default();
    let l = last_tick.clone();
    let _states = watch
        .declare_subscriber(topics.state().to_owned())
        .callback(move |s| {
            if decode_state(&s.payload().to_bytes()).is_ok_and(|m| m.header.tick == LAST_TICK) {
                *l.lock().unwrap() = Some(Instant::now());
            }
        })
        .wait()
        .unwrap();
    let n = notice.clone();
    let _status = watch
        .declare_subscriber(topics.status().to_owned())
        .callback(move |s| {
            if decode_status(&s.payload().to_bytes()).is_ok_and(|m| m.run_state.ended()) {
                n.lock().unwrap().get_or_insert(Instant::now());
            }
        })
        .wait()
        .unwrap();
    let connect = endpoint(server.port);
    let exited = exit_stamp(spawn((client.command)(&connect)));
    // A watcher's run needs the participant; started once the watcher is up (its subscribers
    // must be there before the run can end).
    let participant = client.watcher.then(|| {
        std::thread::sleep(Duration::from_millis(500));
        exit_stamp(spawn(demo(&connect)))
    });
    let report = server
        .join(Duration::from_secs(60))
        .expect("the lockstep run");
    assert_eq!(report.last_tick, LAST_TICK);
    let (t_exit, ok) = exited
        .recv_timeout(Duration::from_secs(20))
        .unwrap_or_else(|_| panic!("{} did not exit within 20 s of the end", client.name));
    assert!(ok, "{} exited with an error", client.name);
    if let Some(p) = participant {
        let _ = p.recv_timeout(Duration::from_secs(20));
    }
    let ms = |t: Option<Instant>| {
        let t = t.unwrap_or_else(|| panic!("{}: the watcher missed the end", client.name));
        t_exit.saturating_duration_since(t).as_secs_f64() * 1e3
    };
    let r = (ms(*last_tick.lock().unwrap()), ms(*notice.lock().unwrap()));
    let _ = watch.close().wait();
    r
}

fn main() {
    let runs: usize = std::env::var("FLEXDYN_BENCH_RUN_END_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(7)
        .max(1);
    let monitor = PathBuf::from(env!("CARGO_BIN_EXE_flexdyn-monitor"));
    let pd = build_pd_lockstep();
    let mut clients = vec![
        Client {
            name: "flexdyn-acs-demo (Rust)",
            command: Box::new(demo),
            watcher: false,
        },
        Client {
            name: "flexdyn-monitor --plain",
            command: Box::new(move |connect| {
                let mut c = Command::new(&monitor);
                c.args(["--connect", connect, "--plain", "--interval-s", "0.5"]);
                c
            }),
            watcher: true,
        },
        Client {
            name: "pd_lockstep (C library)",
            command: Box::new(move |connect| {
                let mut c = Command::new(&pd);
                c.args([connect, "-", "-"]);
                c
            }),
            watcher: false,
        },
    ];
    match venv_python() {
        Some(python) => clients.push(Client {
            name: "LockstepParticipant (Python)",
            command: Box::new(move |connect| {
                let mut c = Command::new(&python);
                c.args(["-c", PYTHON_PARTICIPANT, connect]);
                c
            }),
            watcher: false,
        }),
        None => println!(
            "Python: not measured here: target/python-venv is missing (`cargo test --workspace \
             --release` makes it; tests/cli/python_sdk.rs)"
        ),
    }
    println!(
        "run end: {runs} lockstep runs of ticks 0..={LAST_TICK} per client; from the last tick's \
         state (and from the end-of-run status) to the client's exit; target {TARGET_MS} ms"
    );
    for client in &clients {
        let (mut from_tick, mut from_notice) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            let (a, b) = one_run(client);
            from_tick.push(a);
            from_notice.push(b);
        }
        let worst = from_tick.iter().copied().fold(0.0, f64::max);
        let (m, mn) = (median_mut(&mut from_tick), median_mut(&mut from_notice));
        println!(
            "{:<30} median {m:7.1} ms after the last tick (max {worst:7.1}), {mn:7.1} ms after \
             the end-of-run status; ratio to the target {:.2}",
            client.name,
            m / TARGET_MS
        );
    }
}
