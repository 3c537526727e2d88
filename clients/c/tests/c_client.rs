//! C and C++ programs linked against `libflexdyn_client.a`, against a real `flexdyn run`.
//!
//! `cargo test` builds `libflexdyn_client.a` with this test; the test builds the server with
//! `cargo build -p flexdyn --bin flexdyn` in its own profile (a no-op when it is fresh), compiles
//! the programs with the system compilers (`$CC`, else `cc`; `$CXX`, else `g++`) and runs them:
//! - `struct_layouts_agree`: `tests/layout.c` decodes every golden message with the header's
//!   own decoders and through the library, field by field, and compares the struct sizes;
//! - `lockstep_stream_is_bit_identical_across_runs_and_under_sigstop`: `examples/pd_lockstep.c`
//!   flies 2,001 lockstep ticks of `scenarios/wheels_star_tracker.toml` twice, the second time
//!   stopped (SIGSTOP) for 1 s mid-run; both state streams must be the same bytes, every tick
//!   must be there, and its Actuators commands must show in the wheels' applied torque;
//! - `cpp17_example_builds_strictly_and_runs`: `examples/lockstep_monitor.cpp` under `-std=c++17
//!   -Wall -Wextra -Werror -pedantic`, run as a participant that polls every subscription;
//! - `server_loss_is_an_error_code_not_a_hang`: the server is killed (SIGKILL) mid-run; the C
//!   program must exit with its timeout code within seconds;
//! - `the_flight_loop_stops_when_the_server_ends_the_run`: pd_lockstep with a 60 s wait
//!   timeout, so only `FLEXDYN_ENDED` can end it in time, must exit 0 soon after a 300-tick
//!   lockstep server finishes (issue 36; issue 37 §4), every tick answered;
//! - `no_leak_over_10000_ticks`: pd_lockstep built with AddressSanitizer (LeakSanitizer sees
//!   every allocation, the library's Rust ones included: they go through malloc) flies 10,000
//!   ticks, and valgrind's memcheck a 500-tick run (the leak check would take minutes under
//!   valgrind over 10,000); neither may report a definite leak. A deliberately leaked handle
//!   (`tests/leak.c`) must be reported, so the checker is known to see the library's memory;
//! - `commands_outside_lockstep_arrive_as_sent`: `tests/send.c` sends every kind of command,
//!   stamped from a state it waited for, to a Zenoh peer here that decodes them;
//! - `readme_link_line_builds_the_example`: the book's compile-and-link line (docs/guides/flight-code.md), as written;
//! - `fsw_telemetry_from_c_is_recorded_bit_for_bit`: `tests/fsw.c` (C99, C++17 and under
//!   AddressSanitizer) declares the stream `acs` of the served configuration and publishes one
//!   sample per answered tick by name with `flexdyn_fsw_*`, after checking the library's own
//!   refusals; the server refuses none, and `flexdyn export` of its recording shows every sample
//!   with the words sent;
//! - `rate_groups_run_off_the_ticks_and_stop_while_paused`: `examples/rate_groups.c` drives
//!   1/10/100 Hz groups from `flexdyn_wait_tick` against a real-time server, pauses it with
//!   `flexdyn_send_operator`, sees no tick while it is held and resumes it.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use flexdyn_proto::{decode_state, effector_kind, StateMsg};

use flexdyn_testkit::ports;

use flexdyn_testkit::cargo_build::NATIVE_LIBS;

/// The wheel-speed damping of `examples/pd_lockstep.c` [N m s/rad].
const C_WHEEL_NMS: f64 = 1e-4;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp() -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
}

/// The static library that this `cargo test` built with its rlib, in this test's own directory
/// (`target/<profile>/deps/`: cargo copies it up to `target/<profile>/` only for `cargo build`,
/// so the copy there may be stale).
fn static_lib() -> PathBuf {
    let this = std::env::current_exe().expect("the test's path");
    let deps = this.parent().expect("target/<profile>/deps/<test>");
    let lib = deps.join("libflexdyn_client.a");
    assert!(
        lib.is_file(),
        "{} is missing: cargo builds it with this test",
        lib.display()
    );
    lib
}

/// The server, built once per test binary by `cargo build -p flexdyn --bin flexdyn` (a no-op
/// when it is fresh, as in `cargo test --workspace`). Cargo runs with the variables it set for
/// this test removed: build scripts such as ring's rerun when `CARGO_PKG_NAME` & co. differ,
/// and would rebuild the server's dependencies on every run.
fn flexdyn_bin() -> &'static Path {
    static ONCE: OnceLock<PathBuf> = OnceLock::new();
    ONCE.get_or_init(|| {
        flexdyn_testkit::cargo_build::cargo_build(&root(), &["-p", "flexdyn", "--bin", "flexdyn"])
            .lines()
            .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
            .filter(|m| m["reason"] == "compiler-artifact" && m["target"]["name"] == "flexdyn")
            .find_map(|m| m["executable"].as_str().map(PathBuf::from))
            .expect("cargo named no flexdyn executable")
    })
}

/// Compiles and links `sources` (relative to `clients/c`) against the static library.
fn build(
    compiler_var: &str,
    default: &str,
    flags: &[&str],
    sources: &[&str],
    out: &str,
) -> PathBuf {
    let compiler = std::env::var(compiler_var).unwrap_or_else(|_| default.to_owned());
    let exe = tmp().join(out);
    let c_dir = root().join("clients/c");
    let result = Command::new(&compiler)
        .args(flags)
        .args(["-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg("-I")
        .arg(root().join("proto/c/include"))
        .arg("-I")
        .arg(c_dir.join("include"))
        .args(sources.iter().map(|s| c_dir.join(s)))
        .arg(static_lib())
        .args(NATIVE_LIBS)
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| {
            panic!("no compiler: running `{compiler}` failed ({e}); install gcc/g++ or set {compiler_var}")
        });
    assert!(
        result.status.success(),
        "{compiler} failed on {sources:?}:\n{}",
        String::from_utf8_lossy(&result.stderr)
    );
    exe
}

fn build_c(flags: &[&str], source: &str, out: &str) -> PathBuf {
    let mut all = vec!["-std=c99"];
    all.extend_from_slice(flags);
    build("CC", "cc", &all, &[source], out)
}

/// A lockstep server with participant 1 on `scenarios/wheels_star_tracker.toml`, listening on a
/// free loopback port; killed when dropped.
struct Server {
    child: Child,
    endpoint: String,
}

impl Server {
    /// A real-time server on the embedded reference spacecraft (100 Hz), no participant.
    fn start_realtime(duration_s: &str) -> Self {
        let mut cmd = Command::new(flexdyn_bin());
        cmd.args(["run", "--mode", "realtime"])
            .args(["--listen", ports::ANY_PORT, "--duration-s", duration_s])
            .stdout(Stdio::null());
        let mut child = ports::reporting(&mut cmd).spawn().expect("start flexdyn");
        let endpoint = ports::zenoh_endpoint(&mut child);
        Self { child, endpoint }
    }

    fn start(duration_s: &str) -> Self {
        let mut cmd = Command::new(flexdyn_bin());
        cmd.args(["run", "--mode", "lockstep", "--participants", "1"])
            .args(["--listen", ports::ANY_PORT, "--duration-s", duration_s])
            .arg("--config")
            .arg(root().join("scenarios/wheels_star_tracker.toml"))
            .stdout(Stdio::null());
        let mut child = ports::reporting(&mut cmd).spawn().expect("start flexdyn");
        let endpoint = ports::zenoh_endpoint(&mut child);
        Self { child, endpoint }
    }

    /// A lockstep server with participant 1 on `scenario` (under `scenarios/`).
    fn start_scenario(scenario: &str, duration_s: &str) -> Self {
        let mut cmd = Command::new(flexdyn_bin());
        cmd.args(["run", "--mode", "lockstep", "--participants", "1"])
            .args(["--listen", ports::ANY_PORT, "--duration-s", duration_s])
            .arg("--config")
            .arg(root().join("scenarios").join(scenario))
            .stdout(Stdio::null());
        let mut child = ports::reporting(&mut cmd).spawn().expect("start flexdyn");
        let endpoint = ports::zenoh_endpoint(&mut child);
        Self { child, endpoint }
    }

    /// A lockstep server with participant 1 on the configuration file `config`, recording to
    /// `record`.
    fn start_recording(config: &Path, record: &Path, duration_s: &str) -> Self {
        let mut cmd = Command::new(flexdyn_bin());
        cmd.args(["run", "--mode", "lockstep", "--participants", "1"])
            .args(["--listen", ports::ANY_PORT, "--duration-s", duration_s])
            .arg("--config")
            .arg(config)
            .arg("--record")
            .arg(record)
            .stdout(Stdio::null());
        let mut child = ports::reporting(&mut cmd).spawn().expect("start flexdyn");
        let endpoint = ports::zenoh_endpoint(&mut child);
        Self { child, endpoint }
    }

    /// A lockstep fleet server on `scenarios/formation.toml` (chief: participant 1, deputy: 2).
    fn start_fleet(duration_s: &str) -> Self {
        let mut cmd = Command::new(flexdyn_bin());
        cmd.args(["run", "--mode", "lockstep", "--fleet"])
            .arg(root().join("scenarios/formation.toml"))
            .args(["--listen", ports::ANY_PORT, "--duration-s", duration_s])
            .stdout(Stdio::null());
        let mut child = ports::reporting(&mut cmd).spawn().expect("start flexdyn");
        let endpoint = ports::zenoh_endpoint(&mut child);
        Self { child, endpoint }
    }

    fn wait(&mut self, limit: Duration) -> Option<i32> {
        wait_for(&mut self.child, limit).code()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Waits for `child` at most `limit` (killed and failed after that).
fn wait_for(child: &mut Child, limit: Duration) -> std::process::ExitStatus {
    let give_up = Instant::now() + limit;
    loop {
        if let Some(s) = child.try_wait().expect("wait") {
            return s;
        }
        if Instant::now() > give_up {
            let _ = child.kill();
            panic!("process {} still running after {limit:?}", child.id());
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn signal(pid: u32, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &pid.to_string()])
        .status()
        .expect("run kill");
    assert!(ok.success(), "kill {sig} {pid}");
}

/// Starts `exe args`, stdout piped (its `tick <k>` lines), stderr to the test's.
fn spawn(exe: &Path, args: &[&str], env: &[(&str, &str)]) -> Child {
    Command::new(exe)
        .args(args)
        .envs(env.iter().copied())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("start {}: {e}", exe.display()))
}

/// Reads `child`'s stdout until a line equals `line`; the rest is kept reading on a thread.
fn await_line(child: &mut Child, line: &str) {
    let stdout = child.stdout.take().expect("piped stdout");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for l in BufReader::new(stdout).lines().map_while(Result::ok) {
            let _ = tx.send(l);
        }
    });
    let give_up = Instant::now() + Duration::from_secs(60);
    loop {
        let left = give_up.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(l) if l == line => return,
            Ok(_) => {}
            Err(e) => panic!("no `{line}` from the program: {e}"),
        }
    }
}

/// Runs `cmd` to its end; its stdout, after checking that it succeeded.
fn run_ok(cmd: &mut Command) -> String {
    let out = cmd.output().expect("run the program");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{:?}: {}\n{stdout}{}",
        cmd.get_program(),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// The states a pd_lockstep `state_out` file holds (each behind its u32 LE length).
fn states(file: &Path) -> Vec<StateMsg> {
    let bytes = std::fs::read(file).expect("the state file");
    let mut at = 0;
    let mut out = Vec::new();
    while at < bytes.len() {
        let n = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        out.push(decode_state(&bytes[at + 4..at + 4 + n]).expect("a state the Rust codec reads"));
        at += 4 + n;
    }
    out
}

#[test]
fn struct_layouts_agree() {
    let exe = build_c(&["-O2"], "tests/layout.c", "layout");
    let stdout = run_ok(Command::new(&exe).arg(root().join("proto/golden")));
    assert!(stdout.contains("state: 2 effectors compared"), "{stdout}");
    assert!(stdout.contains("time compared"), "{stdout}");
    assert!(stdout.ends_with("all agree\n"), "{stdout}");
}

/// One pd_lockstep run of ticks 0..=2000, to the server's end of run; with `pause`, SIGSTOP
/// for 1 s at tick 1000.
fn fly(exe: &Path, name: &str, pause: bool) -> PathBuf {
    let mut server = Server::start("20");
    let file = tmp().join(name);
    let file_arg = file.to_string_lossy().into_owned();
    // "-": until the server ends the run (FLEXDYN_ENDED) after tick 2000.
    let mut pd = spawn(exe, &[&server.endpoint, "-", &file_arg], &[]);
    if pause {
        await_line(&mut pd, "tick 1000");
        signal(pd.id(), "-STOP");
        std::thread::sleep(Duration::from_secs(1));
        assert!(
            server.child.try_wait().unwrap().is_none(),
            "the server ended while its participant was stopped"
        );
        signal(pd.id(), "-CONT");
    }
    let status = wait_for(&mut pd, Duration::from_secs(60));
    let mut err = String::new();
    std::io::Read::read_to_string(pd.stderr.as_mut().unwrap(), &mut err).ok();
    assert!(status.success(), "pd_lockstep: {status:?}\n{err}");
    assert_eq!(
        server.wait(Duration::from_secs(30)),
        Some(0),
        "the server's exit"
    );
    file
}

/// Far above any delivery time, far below the program's 60 s wait timeout.
const EXIT_BOUND: Duration = Duration::from_secs(10);

#[test]
fn the_flight_loop_stops_when_the_server_ends_the_run() {
    let exe = build_c(&["-O2"], "examples/pd_lockstep.c", "pd_lockstep_end");
    let mut server = Server::start("3");
    let file = tmp().join("states_end.bin");
    let file_arg = file.to_string_lossy().into_owned();
    // "-": no tick limit; a 60 s wait timeout: a timeout cannot be what ends it in time.
    let mut pd = spawn(&exe, &[&server.endpoint, "-", &file_arg, "60000"], &[]);
    assert_eq!(
        server.wait(Duration::from_secs(60)),
        Some(0),
        "the server's exit"
    );
    let server_done = Instant::now();
    let give_up = server_done + EXIT_BOUND;
    let status = loop {
        if let Some(s) = pd.try_wait().expect("wait") {
            break s;
        }
        if Instant::now() > give_up {
            let _ = pd.kill();
            panic!("pd_lockstep still running {EXIT_BOUND:?} after the server ended");
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    let exit_ms = server_done.elapsed().as_secs_f64() * 1e3;
    let mut out = String::new();
    let mut err = String::new();
    std::io::Read::read_to_string(pd.stdout.as_mut().unwrap(), &mut out).ok();
    std::io::Read::read_to_string(pd.stderr.as_mut().unwrap(), &mut err).ok();
    assert!(status.success(), "pd_lockstep: {status:?}\n{out}{err}");
    assert_eq!(
        out.lines().last(),
        Some("run ended: finished at tick 300, 301 ticks answered"),
        "{out}"
    );
    let ticks: Vec<u64> = states(&file).iter().map(|s| s.header.tick).collect();
    assert_eq!(ticks, (0..=300).collect::<Vec<u64>>());
    eprintln!("pd_lockstep exited {exit_ms:.1} ms after the server's exit (FLEXDYN_ENDED)");
}

#[test]
fn lockstep_stream_is_bit_identical_across_runs_and_under_sigstop() {
    let exe = build_c(&["-O2"], "examples/pd_lockstep.c", "pd_lockstep");
    let plain = fly(&exe, "states_plain.bin", false);
    let paused = fly(&exe, "states_paused.bin", true);
    let a = std::fs::read(&plain).unwrap();
    let b = std::fs::read(&paused).unwrap();
    assert!(
        a == b,
        "the state stream changed when the C program was stopped"
    );

    let states = states(&plain);
    let ticks: Vec<u64> = states.iter().map(|s| s.header.tick).collect();
    assert_eq!(ticks, (0..=2000).collect::<Vec<u64>>());
    // The Actuators answer to tick k - 1 set each wheel's motor torque to -C Omega(k - 1); the
    // state of tick k reports the torque applied over that frame (far below the 0.2 N m limit).
    let mut wheels_checked = 0;
    for pair in states.windows(2) {
        let (prev, next) = (&pair[0], &pair[1]);
        for (e_prev, e_next) in prev.effectors.iter().zip(&next.effectors) {
            if e_prev.kind == effector_kind::REACTION_WHEEL {
                assert_eq!(
                    e_next.outputs[0],
                    -C_WHEEL_NMS * e_prev.states[0],
                    "tick {}",
                    next.header.tick
                );
                wheels_checked += 1;
            }
        }
    }
    assert_eq!(
        wheels_checked,
        4 * 2000,
        "four wheels on every tick after 0"
    );
    // The PD wrench reached the hub: the applied torque of the last tick is not zero.
    assert!(states[2000]
        .wrench_applied
        .torque_b_nm
        .iter()
        .any(|t| *t != 0.0));
}

#[test]
fn cpp17_example_builds_strictly_and_runs() {
    let exe = build(
        "CXX",
        "g++",
        &["-std=c++17", "-O2"],
        &["examples/lockstep_monitor.cpp"],
        "lockstep_monitor",
    );
    let mut server = Server::start("3");
    let stdout = run_ok(Command::new(&exe).args([&server.endpoint, "300"]));
    // Ticks 0..=300: a state and an IMU sample each, the 10 Hz tracker on every 10th tick (31),
    // and the server's last status says Finished (3).
    assert_eq!(
        stdout.trim(),
        "states=301 imus=301 star_trackers=31 run_state=3"
    );
    assert_eq!(server.wait(Duration::from_secs(30)), Some(0));
}

#[test]
fn server_loss_is_an_error_code_not_a_hang() {
    let exe = build_c(&["-O2"], "examples/pd_lockstep.c", "pd_lockstep_loss");
    let mut server = Server::start("1000");
    let mut pd = spawn(&exe, &[&server.endpoint, "100000", "-", "2000"], &[]);
    await_line(&mut pd, "tick 500");
    server.child.kill().expect("kill the server");
    let killed_at = Instant::now();
    let status = wait_for(&mut pd, Duration::from_secs(30));
    let waited = killed_at.elapsed();
    let mut err = String::new();
    std::io::Read::read_to_string(pd.stderr.as_mut().unwrap(), &mut err).ok();
    assert_eq!(status.code(), Some(3), "the timeout exit code: {err}");
    assert!(
        err.contains("no tick on flexdyn/sc1/tlm/** within 2000 ms"),
        "{err}"
    );
    assert!(waited < Duration::from_secs(10), "{waited:?}");
}

#[test]
fn no_leak_over_10000_ticks() {
    let asan = ["-O1", "-g", "-fsanitize=address", "-fno-omit-frame-pointer"];
    let asan_env = [("ASAN_OPTIONS", "detect_leaks=1:exitcode=23")];
    // The checker sees a handle the program never frees.
    let leak = build_c(&asan, "tests/leak.c", "leak_asan");
    let out = Command::new(&leak).envs(asan_env).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(23), "{err}");
    assert!(err.contains("flexdyn_client_new"), "{err}");

    // 10,000 ticks under AddressSanitizer: no leak, no memory error.
    let exe = build_c(&asan, "examples/pd_lockstep.c", "pd_lockstep_asan");
    let mut server = Server::start("100");
    // "-": until the server ends the run after tick 10,000 (the FLEXDYN_ENDED path included).
    let mut pd = spawn(&exe, &[&server.endpoint, "-", "-"], &asan_env);
    let status = wait_for(&mut pd, Duration::from_secs(120));
    let mut err = String::new();
    std::io::Read::read_to_string(pd.stderr.as_mut().unwrap(), &mut err).ok();
    assert!(status.success(), "{status:?}\n{err}");
    assert_eq!(server.wait(Duration::from_secs(30)), Some(0));

    // 500 ticks under valgrind's memcheck: no definite leak, no memory error.
    let plain = build_c(&["-O1", "-g"], "examples/pd_lockstep.c", "pd_lockstep_vg");
    let server = Server::start("100");
    valgrind(&plain, &[server.endpoint.as_str(), "500", "-", "30000"]);
    drop(server);
}

/// The compile-and-link line of the book's "C and C++ flight code: libflexdyn_client"
/// (`docs/guides/flight-code.md`; README.md's until issue 36) works as
/// written, run from the checkout's root with this test's library in place of
/// `target/release/libflexdyn_client.a`, and names the system libraries the tests link.
#[test]
fn readme_link_line_builds_the_example() {
    let readme = std::fs::read_to_string(root().join("docs/guides/flight-code.md")).unwrap();
    let from = readme
        .find("## C and C++ flight code: libflexdyn_client")
        .expect("the book's section");
    let mut words = Vec::new();
    let lines = readme[from..]
        .lines()
        .skip_while(|l| !l.starts_with("cc -std=c99"));
    for line in lines {
        words.extend(
            line.split_whitespace()
                .filter(|w| *w != "\\")
                .map(String::from),
        );
        if !line.trim_end().ends_with('\\') {
            break;
        }
    }
    assert_eq!(words.first().map(String::as_str), Some("cc"), "{words:?}");
    let libs: Vec<&str> = words
        .iter()
        .map(String::as_str)
        .filter(|w| w.starts_with("-l"))
        .collect();
    assert_eq!(libs, NATIVE_LIBS, "the book's system libraries");
    let out = tmp().join("pd_lockstep_readme");
    let args: Vec<String> = words[1..]
        .iter()
        .map(|w| match w.as_str() {
            "target/release/libflexdyn_client.a" => static_lib().to_string_lossy().into_owned(),
            "pd_lockstep" => out.to_string_lossy().into_owned(),
            _ => w.clone(),
        })
        .collect();
    assert!(
        args.iter().any(|a| *a == out.to_string_lossy()),
        "{words:?}"
    );
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_owned());
    run_ok(Command::new(cc).args(&args).current_dir(root()));
    // Linked, it runs: without arguments it prints its usage and exits 2.
    let usage = Command::new(&out).output().unwrap();
    assert_eq!(usage.status.code(), Some(2));
}

/// `tests/send.c` waits for a state on an ordinary subscription, then sends a Wrench, a
/// NoCommand and an Actuators command stamped from it; this test is the peer it connects to
/// (a Zenoh session on a free port that publishes a state until the three commands come) and
/// reads them back with the Rust decoder.
#[test]
fn commands_outside_lockstep_arrive_as_sent() {
    use flexdyn_proto::client::transport::{listening_on, zenoh_config, Role, ZenohArgs};
    use flexdyn_proto::{decode_command, encode, CommandKind, EffectorInput, Header};
    use zenoh::Wait;

    let exe = build_c(&["-O2"], "tests/send.c", "send");
    let args = ZenohArgs {
        listen: vec![ports::ANY_PORT.to_owned()],
        ..ZenohArgs::default()
    };
    let session = zenoh::open(zenoh_config(&args, Role::Server).unwrap())
        .wait()
        .unwrap();
    let endpoint = listening_on(&session).remove(0);
    let commands = session
        .declare_subscriber("flexdyn/sc1/cmd/*")
        .wait()
        .unwrap();
    let mut child = spawn(&exe, &[&endpoint], &[]);
    let state = StateMsg {
        header: Header::new(9, 42, 420_000_000, 17),
        ..StateMsg::default()
    };
    let mut got = Vec::new();
    let give_up = Instant::now() + Duration::from_secs(30);
    while got.len() < 3 && Instant::now() < give_up {
        session
            .put("flexdyn/sc1/tlm/state", encode(&state))
            .wait()
            .unwrap();
        while let Ok(Some(s)) = commands.try_recv() {
            assert_eq!(s.key_expr().as_str(), "flexdyn/sc1/cmd/7");
            got.push(decode_command(&s.payload().to_bytes()).expect("a valid CommandMsg"));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let status = wait_for(&mut child, Duration::from_secs(30));
    let mut err = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).ok();
    assert!(status.success(), "{status:?}\n{err}");
    let (torque, force) = ([0.5, -0.25, 0.125], [1.0, 2.0, 3.0]);
    let expected = [
        CommandKind::Wrench {
            torque_b_nm: torque,
            force_b_newton: force,
        },
        CommandKind::NoCommand,
        CommandKind::Actuators {
            torque_b_nm: torque,
            force_b_newton: force,
            inputs: vec![
                EffectorInput {
                    effector_index: 3,
                    values: vec![-0.0625],
                },
                EffectorInput {
                    effector_index: 5,
                    values: vec![1.5, 2.5],
                },
            ],
        },
    ];
    assert_eq!(got.len(), 3, "{got:?}");
    for (seq, (cmd, kind)) in got.iter().zip(expected).enumerate() {
        // Stamped from the state (its spacecraft id, tick and time), numbered by the library.
        assert_eq!(cmd.header, Header::new(9, 42, 420_000_000, seq as u64));
        assert_eq!((cmd.sender_id, &cmd.kind), (7, &kind));
    }
    session.close().wait().unwrap();
}

/// The numbers after `name=` in `line`, in order.
fn counts(line: &str) -> Vec<u64> {
    line.split_whitespace()
        .filter_map(|w| w.split_once('=').and_then(|(_, v)| v.parse().ok()))
        .collect()
}

#[test]
fn rate_groups_run_off_the_ticks_and_stop_while_paused() {
    let exe = build_c(&["-O2"], "examples/rate_groups.c", "rate_groups");
    let server = Server::start_realtime("60");
    // 300 ticks from a 1 Hz boundary at 100 Hz; the driver pauses the server after its 150th.
    let stdout = run_ok(Command::new(&exe).args([&server.endpoint, "300", "150"]));
    let held: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("held at "))
        .collect();
    let done = stdout
        .lines()
        .find(|l| l.starts_with("done "))
        .unwrap_or_else(|| panic!("no done line:\n{stdout}"));
    // Each group ran exactly as often as K ticks give it: 300/100, 300/10, 300/1.
    let d = counts(done);
    assert_eq!(&d[..4], &[3, 30, 300, 300], "{done}");
    // Three 300 ms stalls while the server was held, every one at the same tick with the same
    // counts: the groups stopped with the simulation.
    assert_eq!(d[4], 3, "{stdout}");
    assert_eq!(held.len(), 3, "{stdout}");
    assert!(held.iter().all(|l| *l == held[0]), "{stdout}");
    let h: u64 = held[0]["held at ".len()..]
        .split(':')
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert_eq!(d[5], h);
    let c = counts(held[0]);
    // Held at tick h after c100 ticks counted from a multiple of 100 (the 150th tick's pause
    // takes effect at the next boundary): the 10 Hz and 1 Hz groups ran on the multiples of 10
    // and 100 among them.
    let c100 = c[2];
    assert!((150..300).contains(&c100), "{stdout}");
    assert_eq!(c[1], (c100 - 1) / 10 + 1, "{stdout}");
    assert_eq!(c[0], (c100 - 1) / 100 + 1, "{stdout}");
    assert_eq!(h % 100, (c100 - 1) % 100, "{stdout}");
    drop(server);
}

/// The typed calls generated from the wire table, against `scenarios/acs_full.toml` in
/// lockstep: every sensor kind of the run, the environment, a live fault and its event, a
/// refused fault, the byte-level refusals (`tests/every_message.c`). Built as C99 and, with the
/// same source, as C++17, both with `-Wall -Wextra -Werror -pedantic`, and run once plain and
/// once under AddressSanitizer.
#[test]
fn every_message_kind_from_c_and_cpp() {
    let asan = ["-O1", "-g", "-fsanitize=address", "-fno-omit-frame-pointer"];
    let builds = [
        build_c(&["-O2"], "tests/every_message.c", "every_message"),
        build(
            "CXX",
            "g++",
            &["-std=c++17", "-O2"],
            &["tests/every_message.cpp"],
            "every_message_cpp",
        ),
        build_c(&asan, "tests/every_message.c", "every_message_asan"),
    ];
    for exe in &builds {
        // 3 s at 10 Hz: ticks 0..=30.
        let mut server = Server::start_scenario("acs_full.toml", "3");
        let out = Command::new(exe)
            .arg(&server.endpoint)
            .env("ASAN_OPTIONS", "detect_leaks=1:exitcode=23")
            .output()
            .expect("run every_message");
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "{exe:?}: {:?}\n{stdout}\n{stderr}",
            out.status
        );
        // 30 answered ticks (the last, 30, needs none but is handed out too: 31); the stuck
        // magnetometer from tick 5 on: 26 samples; one fault event.
        assert_eq!(
            stdout.trim(),
            "ticks 31 imu 31 star 31 mag 31 (stuck 26) css 31 fss 31 env 31 events 1",
            "{exe:?}"
        );
        assert_eq!(server.wait(Duration::from_secs(30)), Some(0));
    }
    // And under valgrind's memcheck: no memory error, no definite leak.
    let plain = build_c(&["-O1", "-g"], "tests/every_message.c", "every_message_vg");
    let server = Server::start_scenario("acs_full.toml", "3");
    let out = valgrind(&plain, &[server.endpoint.as_str()]);
    assert!(
        out.starts_with("ticks 31 imu 31 star 31 mag 31 (stuck 26)"),
        "{out}"
    );
}

/// Runs `exe` with `args` under valgrind's memcheck (installing it on a fresh machine) and
/// returns its stdout; fails on a memory error or a definite leak.
fn valgrind(exe: &Path, args: &[&str]) -> String {
    let installed = Command::new("sh")
        .arg(root().join("tests/deps/debian_package.sh"))
        .args(["valgrind", "valgrind"])
        .status();
    assert!(
        installed.as_ref().is_ok_and(|s| s.success()),
        "valgrind is needed (Debian: apt-get install valgrind): {installed:?}"
    );
    let supp = root().join("clients/c/tests/valgrind.supp");
    let out = Command::new("valgrind")
        .args([
            "--leak-check=full",
            "--errors-for-leak-kinds=definite",
            "--error-exitcode=99",
        ])
        .arg(format!("--suppressions={}", supp.display()))
        .arg(exe)
        .args(args)
        .output()
        .expect("valgrind");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}\n{err}", out.status);
    assert!(
        err.contains("definitely lost: 0 bytes in 0 blocks")
            || err.contains("no leaks are possible"),
        "{err}"
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A fleet from C (`tests/relative.c`): the chief and the deputy of `scenarios/formation.toml`
/// on two handles in one lockstep, and the deputy's relative state through the generated
/// `flexdyn_subscribe_relative_state` / `flexdyn_poll_relative_state` (range, range rate and
/// the tick-0 Hill position checked in the program); plain and under AddressSanitizer.
#[test]
fn relative_state_of_a_fleet_from_c() {
    let asan = ["-O1", "-g", "-fsanitize=address", "-fno-omit-frame-pointer"];
    for exe in [
        build_c(&["-O2"], "tests/relative.c", "relative"),
        build_c(&asan, "tests/relative.c", "relative_asan"),
    ] {
        // 2 s at 100 Hz: ticks 0..=200, one relative state each.
        let mut server = Server::start_fleet("2");
        let stdout = run_ok(
            Command::new(&exe)
                .arg(&server.endpoint)
                .env("ASAN_OPTIONS", "detect_leaks=1:exitcode=23"),
        );
        // |(3, -95, 2)| = sqrt(9 + 9025 + 4) = 95.068396… m.
        assert_eq!(
            stdout.trim(),
            "relative states 201, range at tick 0 95.068396 m",
            "{exe:?}"
        );
        assert_eq!(server.wait(Duration::from_secs(30)), Some(0));
    }
}

/// The B-dot detumble in C (`examples/bdot_detumble.c`: the magnetometer in, the rods out) on
/// `scenarios/acs_full.toml` in lockstep takes the body from 3°/s to below 1°/s within an hour
/// of simulation (3487.3 s when measured), and the same run twice gives the same state stream,
/// bit for bit. The control run, the same program with the gain 0, leaves the rate at 3°/s, so
/// the rods (and so the magnetometer readings) do the work.
#[test]
fn bdot_detumble_in_c_is_deterministic_and_detumbles() {
    let exe = build_c(&["-O2"], "examples/bdot_detumble.c", "bdot_detumble");
    let fly = |duration_s: &str, gain: &str, file: &str| -> (String, Vec<u8>) {
        let mut server = Server::start_scenario("acs_full.toml", duration_s);
        let path = tmp().join(file);
        let stdout = run_ok(Command::new(&exe).args([
            server.endpoint.as_str(),
            gain,
            &path.to_string_lossy(),
        ]));
        assert_eq!(server.wait(Duration::from_secs(60)), Some(0));
        (stdout, std::fs::read(&path).unwrap())
    };
    let rate_at_end = |stdout: &str| -> f64 {
        let line = stdout
            .lines()
            .find(|l| l.starts_with("final |omega| = "))
            .unwrap_or_else(|| panic!("{stdout}"));
        line["final |omega| = ".len()..]
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let (first, states_1) = fly("3600", "5.4e9", "bdot_1.bin");
    let below_at: f64 = first
        .lines()
        .find_map(|l| l.strip_prefix("below 1.0 deg/s at t = "))
        .and_then(|rest| rest.trim_end_matches(" s").parse().ok())
        .unwrap_or_else(|| panic!("never below 1°/s within 3600 s:\n{first}"));
    assert!(below_at < 3600.0, "{first}");
    assert!(rate_at_end(&first) < 1.0, "{first}");
    let (second, states_2) = fly("3600", "5.4e9", "bdot_2.bin");
    assert_eq!(first, second);
    assert_eq!(states_1.len(), states_2.len());
    assert!(states_1 == states_2, "the two runs' state streams differ");
    // 36,001 states (ticks 0..=36000) of 327 bytes and 13 effectors each.
    assert_eq!(states_1.len() % 36_001, 0);
    let (control, _) = fly("300", "0", "bdot_control.bin");
    assert!(rate_at_end(&control) > 2.9, "{control}");
    eprintln!("{first}{control}");
}

/// The configuration of `tests/fsw.c`: `scenarios/reference.toml` (100 Hz) with the stream
/// `acs` the program publishes.
const FSW_STREAM_TOML: &str = r#"
[[fsw_streams]]
name = "acs"
modes = ["detumble", "point"]
events = [{ name = "gyro_fault", severity = "error" }]
values = [
  { name = "h_b_nms", type = "f64", len = 3, unit = "N·m·s" },
  { name = "flags", type = "i64" },
  { name = "ok", type = "bool" },
]
"#;

/// A CSV `flexdyn export` wrote: its column names and rows, `#` comment lines skipped.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let names = lines
        .next()
        .expect("a header row")
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    (names, rows)
}

/// The cell `name` of `row` as an integer (the exact word: `flexdyn export` writes integers,
/// the FswMsg value words among them, as integers).
fn cell_u64(names: &[String], row: &[String], name: &str) -> u64 {
    let i = names
        .iter()
        .position(|n| n == name)
        .unwrap_or_else(|| panic!("no column {name} in {names:?}"));
    row[i]
        .parse()
        .unwrap_or_else(|e| panic!("{name} = {:?}: {e}", row[i]))
}

/// `tests/fsw.c` against a lockstep server whose configuration declares the stream `acs`,
/// recording: built as C99, as C++17 and as C99 under AddressSanitizer, each run publishes one
/// sample before its answer to each tick 0..99 (the last tick, 100, needs no answer) and checks
/// the library's own refusals (undeclared stream, mode, event and value; wrong length and type;
/// NaN; another spacecraft's stamp; a value left out; a variance without an estimate; a second
/// sample for a tick). Then, independently of the program: the server refused none of what it
/// got (its last StatusMsg in the recording), and `flexdyn export` of the recording has exactly
/// one sample per answered tick, stamped with the tick's time, numbered 0, 1, 2 ..., with the
/// mode, events, flags, quaternions and the value words the program derived from k, bit for bit.
#[test]
fn fsw_telemetry_from_c_is_recorded_bit_for_bit() {
    use flexdyn_proto::fsw_flags;

    let asan = ["-O1", "-g", "-fsanitize=address", "-fno-omit-frame-pointer"];
    let dir = tmp().join("c_client_fsw");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let reference = std::fs::read_to_string(root().join("scenarios/reference.toml")).unwrap();
    let config = dir.join("fsw.toml");
    std::fs::write(&config, format!("{reference}{FSW_STREAM_TOML}")).unwrap();
    let builds = [
        ("c", build_c(&["-O2"], "tests/fsw.c", "fsw")),
        (
            "cpp",
            build(
                "CXX",
                "g++",
                &["-std=c++17", "-O2"],
                &["tests/fsw.cpp"],
                "fsw_cpp",
            ),
        ),
        ("asan", build_c(&asan, "tests/fsw.c", "fsw_asan")),
    ];
    // 1 s at 100 Hz: ticks 0..=100, the last needing no answer.
    const LAST_TICK: u64 = 100;
    for (name, exe) in &builds {
        let record = dir.join(format!("{name}.mcap"));
        let mut server = Server::start_recording(&config, &record, "1");
        let stdout = run_ok(
            Command::new(exe)
                .args([server.endpoint.as_str(), &LAST_TICK.to_string()])
                .env("ASAN_OPTIONS", "detect_leaks=1:exitcode=23"),
        );
        assert_eq!(
            stdout.trim(),
            "published 100 refusals 15 rejected_fsw_refused 0",
            "{name}"
        );
        assert_eq!(server.wait(Duration::from_secs(30)), Some(0), "{name}");

        let csv = dir.join(format!("{name}_csv"));
        run_ok(
            Command::new(flexdyn_bin())
                .arg("export")
                .arg("--csv")
                .arg(&csv)
                .arg(&record),
        );
        // The server's last status: no sample refused, every one recorded.
        let (names, rows) = read_csv(&csv.join("flexdyn_sc1_status.csv"));
        let last = rows.last().expect("status rows");
        let run_state = names.iter().position(|n| n == "run_state").unwrap();
        assert_eq!(last[run_state], "Finished", "{name}");
        assert_eq!(cell_u64(&names, last, "rejected_fsw_refused"), 0, "{name}");
        // One row per answered tick, as sent: every tick checked, 5 (the event) and 99 (the
        // last) among them.
        let (names, rows) = read_csv(&csv.join("flexdyn_sc1_fsw_acs.csv"));
        assert_eq!(rows.len() as u64, LAST_TICK, "{name}: {names:?}");
        let word = |row: &[String], n: &str| cell_u64(&names, row, n);
        let f64_bits = |x: f64| x.to_bits();
        for (k, row) in (0u64..).zip(&rows) {
            assert_eq!(word(row, "tick"), k, "{name}");
            // 100 Hz: tick k is at k × 10 ms; the stream's own counter.
            assert_eq!(word(row, "sim_time_ns"), k * 10_000_000, "{name}");
            assert_eq!(word(row, "seq"), k, "{name}");
            let mut flags = fsw_flags::MODE | fsw_flags::ESTIMATE;
            if k == 3 {
                flags |= fsw_flags::COVARIANCE;
            }
            if k >= 10 {
                flags |= fsw_flags::TARGET;
            }
            assert_eq!(word(row, "flags"), u64::from(flags), "{name} tick {k}");
            assert_eq!(word(row, "mode"), u64::from(k >= 10), "{name} tick {k}");
            let events = if k == 5 { 1 } else { 0 };
            assert_eq!(word(row, "event_count"), events, "{name} tick {k}");
            // The value words: h_b_nms (3 f64), flags (i64), ok (bool), bit for bit.
            let expected = [
                f64_bits(k as f64 * 0.5),
                f64_bits(-(k as f64)),
                f64_bits(0.25),
                (-(k as i64)) as u64,
                k % 2,
            ];
            let got: Vec<u64> = (1..=5).map(|i| word(row, &format!("values_{i}"))).collect();
            assert_eq!(got, expected, "{name} tick {k}");
        }
        // The quaternions and the variance: numbers, compared as numbers (the CSV prints the
        // shortest text that reads back as the same f64).
        let num = |row: &[String], n: &str| -> f64 {
            let i = names
                .iter()
                .position(|c| c == n)
                .unwrap_or_else(|| panic!("{n}"));
            row[i].parse().unwrap()
        };
        let r3 = &rows[3];
        assert_eq!(
            [
                num(r3, "att_var_b_rad2_1"),
                num(r3, "att_var_b_rad2_2"),
                num(r3, "att_var_b_rad2_3")
            ],
            [1e-6, 2e-6, 3e-6]
        );
        let r99 = &rows[99];
        assert_eq!(
            [
                num(r99, "q_est_bn_0"),
                num(r99, "q_est_bn_1"),
                num(r99, "q_target_rn_2"),
                num(r99, "q_target_rn_3")
            ],
            [0.6, 0.8, 0.6, 0.8]
        );
        let e5 = &rows[5];
        assert_eq!(word(e5, "events_1"), 0, "gyro_fault is event 0");
    }
}
