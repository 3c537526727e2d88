//! The `flexdyn run` binary as a separate process: exit codes and messages of a participant
//! timeout, of missing participants and of bad settings; graceful SIGTERM; batch mode.
//! Every wait is bounded; a child still running at the end is killed.

use crate::server_support;

use std::io::Read;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use flexdyn_proto::{decode_state, encode, CommandMsg, Header, Topics};
use server_support::{connecting_session, port_of, ports, wait_until, Observer, ANY_PORT};
use zenoh::qos::CongestionControl;
use zenoh::Wait;

/// A running `flexdyn` process; stderr is collected by a thread; killed on drop.
struct Server {
    child: Child,
    stderr: Arc<Mutex<String>>,
}

impl Server {
    fn spawn(args: &[&str]) -> Self {
        Self::start(args, "info", false)
    }

    /// Like [`Self::spawn`], but the stderr reader closes its end of the pipe once the server
    /// has reported its endpoint, as a killed `tee` would; later log lines go into a closed pipe.
    fn spawn_closing_stderr(args: &[&str], rust_log: &str) -> Self {
        Self::start(args, rust_log, true)
    }

    fn start(args: &[&str], rust_log: &str, close_after_first_read: bool) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
            .args(args)
            .env("RUST_LOG", rust_log)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn flexdyn");
        let stderr = Arc::new(Mutex::new(String::new()));
        let mut pipe = child.stderr.take().unwrap();
        let sink = stderr.clone();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = pipe.read(&mut buf) {
                if n == 0 {
                    break;
                }
                let mut text = sink.lock().unwrap();
                text.push_str(&String::from_utf8_lossy(&buf[..n]));
                if close_after_first_read && ports::find_zenoh_endpoint(&text).is_some() {
                    break; // drops `pipe`: the read end closes
                }
            }
        });
        Self { child, stderr }
    }

    fn wait(&mut self, timeout: Duration) -> ExitStatus {
        let give_up = Instant::now() + timeout;
        loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                // Let the reader thread drain the pipe.
                std::thread::sleep(Duration::from_millis(50));
                return s;
            }
            assert!(
                Instant::now() < give_up,
                "flexdyn did not exit within {timeout:?}; stderr:\n{}",
                self.stderr()
            );
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    fn stderr(&self) -> String {
        self.stderr.lock().unwrap().clone()
    }

    /// The port the server reports it listens on (it was started with `--listen ANY_PORT`).
    fn port(&mut self) -> u16 {
        let mut found = None;
        let reported = wait_until(Duration::from_secs(60), || {
            found = ports::find_zenoh_endpoint(&self.stderr());
            found.is_some() || self.child.try_wait().unwrap().is_some()
        });
        match found {
            Some(ep) if reported => port_of(&ep),
            _ => panic!(
                "the server reported no endpoint; stderr:\n{}",
                self.stderr()
            ),
        }
    }

    /// Waits (30 s at most) until `obs` has seen the state of `tick`.
    #[track_caller]
    fn await_tick(&self, obs: &Observer, tick: u64) {
        assert!(
            wait_until(Duration::from_secs(30), || obs
                .last_tick()
                .is_some_and(|t| t >= tick)),
            "no telemetry up to tick {tick}; stderr:\n{}",
            self.stderr()
        );
    }

    /// Sends SIGTERM and returns the exit status (30 s at most).
    fn terminate(&mut self) -> ExitStatus {
        let killed = Command::new("kill")
            .args(["-TERM", &self.child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        self.wait(Duration::from_secs(30))
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn lockstep_participant_timeout_exits_nonzero_naming_participant_and_tick() {
    let ep = ANY_PORT;
    let mut server = Server::spawn(&[
        "run",
        "--mode",
        "lockstep",
        "--participants",
        "7",
        "--participant-timeout-s",
        "1",
        "--listen",
        ep,
        "--duration-s",
        "100",
    ]);
    let port = server.port();
    // A participant that answers ticks 0..=4, then goes silent.
    let topics = Topics::new("sc1").unwrap();
    let session = connecting_session(port);
    let publisher = session
        .declare_publisher(topics.cmd(7))
        .congestion_control(CongestionControl::Block)
        .wait()
        .unwrap();
    let _sub = session
        .declare_subscriber(topics.state().to_owned())
        .callback(move |sample| {
            let Ok(s) = decode_state(&sample.payload().to_bytes()) else {
                return;
            };
            let h = s.header;
            if h.tick < 5 {
                let cmd =
                    CommandMsg::no_command(Header::new(h.spacecraft_id, h.tick, 0, h.tick), 7);
                let _ = publisher.put(encode(&cmd)).wait();
            }
        })
        .wait()
        .unwrap();
    let _token = session
        .liveliness()
        .declare_token(topics.participant(7))
        .wait()
        .unwrap();
    let status = server.wait(Duration::from_secs(30));
    let err = server.stderr();
    assert_eq!(status.code(), Some(1), "stderr:\n{err}");
    assert!(
        err.contains("error: lockstep participant 7 did not answer tick 5 within 1 s"),
        "stderr:\n{err}"
    );
}

#[test]
fn lockstep_without_participants_gives_up_after_the_presence_timeout() {
    let ep = ANY_PORT;
    let mut server = Server::spawn(&[
        "run",
        "--mode",
        "lockstep",
        "--participants",
        "3,4",
        "--presence-timeout-s",
        "2",
        "--listen",
        ep,
    ]);
    let port = server.port();
    // While it waits, the status says so.
    let obs = Observer::start(port, &Topics::new("sc1").unwrap());
    assert!(
        wait_until(Duration::from_secs(30), || obs.last_status().is_some_and(
            |s| {
                s.mode == flexdyn_proto::Mode::Lockstep
                    && s.run_state == flexdyn_proto::RunState::Starting
            }
        )),
        "no Starting status; stderr:\n{}",
        server.stderr()
    );
    let status = server.wait(Duration::from_secs(30));
    let err = server.stderr();
    assert_eq!(status.code(), Some(1), "stderr:\n{err}");
    assert!(
        err.contains("participant(s) 3, 4 not present"),
        "stderr:\n{err}"
    );
}

#[test]
fn bad_settings_exit_2_naming_the_setting() {
    let dir = std::env::temp_dir().join(format!("flexdyn-server-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bad_server.toml");
    std::fs::write(
        &file,
        format!(
            "{}\n[server]\ncolour = \"blue\"\n",
            flexdyn_vehicle::config::DEFAULT_CONFIG_TOML
        ),
    )
    .unwrap();
    let file_s = file.to_str().unwrap();
    let secure = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/zenoh/secure-server.json5"
    );
    let listen = ["--listen", ANY_PORT];
    // After the reference text come an empty line, `[server]`, then `colour`.
    let colour_line = flexdyn_vehicle::config::DEFAULT_CONFIG_TOML.lines().count() + 3;
    let colour =
        format!("error: {file_s}: server.colour: unknown key (expected one of: mode, sc_id");
    let colour_at = format!("(line {colour_line}, column ");
    let cases: [(&[&str], &str); 10] = [
        // Binding participants to subjects: the shipped ACL reserves cmd/1 for `fsw`.
        (
            &[
                "run",
                "--zenoh-config",
                secure,
                "--participant-subjects",
                "1=operator",
                listen[0],
                listen[1],
            ],
            "error: server.participant_subjects: access_control lets user `fsw` (subject \
             `flight-code`) put on `flexdyn/sc1/cmd/1`, participant 1's command key; only \
             `operator` may",
        ),
        (
            &[
                "run",
                "--participant-subjects",
                "1=fsw",
                listen[0],
                listen[1],
            ],
            "needs authenticated peers: set transport/auth/usrpwd/dictionary_file",
        ),
        (
            &[
                "run",
                "--zenoh-config",
                secure,
                "--participant-subjects",
                "2=fsw",
                listen[0],
                listen[1],
            ],
            "error: --participant-subjects: sender 2 is not in server.participants [1]",
        ),
        (
            &["run", "--handoff", "inline", listen[0], listen[1]],
            "invalid value 'inline' for '--handoff <HANDOFF>'",
        ),
        (&["run", "--config", file_s], &colour),
        (
            &["run", "--duration-s", "0.015", listen[0], listen[1]],
            "is not a whole number of frames",
        ),
        (
            &["run", "--stale-after-s", "-1", listen[0], listen[1]],
            "error: --stale-after-s: must be > 0",
        ),
        // `--speed`: finite, > 0, and within 1/1000 … 1000 × real time.
        (
            &["run", "--speed", "0", listen[0], listen[1]],
            "error: --speed: must be > 0 (got 0)",
        ),
        (
            &["run", "--speed", "NaN", listen[0], listen[1]],
            "error: --speed: must be finite (got nan)",
        ),
        (
            &["run", "--speed", "5000", listen[0], listen[1]],
            "error: --speed: must be in 0.001..=1000 (× real time; got 5000)",
        ),
    ];
    for (args, want) in cases {
        let mut server = Server::spawn(args);
        let status = server.wait(Duration::from_secs(30));
        let err = server.stderr();
        assert_eq!(status.code(), Some(2), "{args:?}: stderr:\n{err}");
        assert!(err.contains(want), "{args:?}: stderr:\n{err}");
        if args.contains(&"--config") {
            assert!(err.contains(&colour_at), "not at {colour_at}: {err}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sigterm_stops_the_realtime_server_gracefully() {
    let ep = ANY_PORT;
    let mut server = Server::spawn(&["run", "--listen", ep]);
    let port = server.port();
    let topics = Topics::new("sc1").unwrap();
    let obs = Observer::start(port, &topics);
    server.await_tick(&obs, 10);
    let status = server.terminate();
    let err = server.stderr();
    assert_eq!(status.code(), Some(0), "stderr:\n{err}");
    assert!(
        err.contains("SIGTERM") && err.contains("run stopped"),
        "stderr:\n{err}"
    );
    // The last StatusMsg says how the run ended, and its tick is the log's last_tick and the
    // last state on the wire.
    assert!(
        wait_until(Duration::from_secs(5), || obs
            .last_status()
            .is_some_and(|s| s.run_state == flexdyn_proto::RunState::Stopped)),
        "final status: {:?}",
        obs.last_status()
    );
    let last = obs.last_status().unwrap();
    let logged: u64 = err
        .split("last_tick=")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no last_tick in the log:\n{err}"));
    assert_eq!(last.header.tick, logged, "status tick vs log\n{err}");
    assert_eq!(
        obs.last_tick(),
        Some(logged),
        "last state on the wire vs log"
    );
    let published: u64 = err
        .split("states_published=")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap();
    assert_eq!(
        published,
        logged + 1,
        "ticks 0..=last_tick were published\n{err}"
    );
}

/// Commands dropped for a full queue reach StatusMsg (not only the final log line), and each
/// rejection reason is logged at warn, naming the sender, once and then rate-limited.
#[test]
fn dropped_commands_reach_the_status_and_rejections_are_logged() {
    let ep = ANY_PORT;
    let mut server = Server::spawn(&["run", "--listen", ep, "--command-queue", "1"]);
    let port = server.port();
    let topics = Topics::new("sc1").unwrap();
    let obs = Observer::start(port, &topics);
    server.await_tick(&obs, 5);
    let session = connecting_session(port);
    let publisher = session
        .declare_publisher(topics.cmd(1))
        .congestion_control(CongestionControl::Block)
        .wait()
        .unwrap();
    let tick = obs.last_tick().unwrap();
    // A burst far larger than the queue of 1 drained once per 10 ms frame.
    for i in 0..2000u64 {
        let cmd = CommandMsg::wrench(Header::new(1, tick, 0, i), 1, [0.0; 3], [0.0; 3]);
        publisher.put(encode(&cmd)).wait().unwrap();
    }
    // Unknown sender, three times: logged once.
    for i in 0..3u64 {
        let cmd = CommandMsg::wrench(Header::new(1, tick, 0, i), 99, [0.0; 3], [0.0; 3]);
        session.put(topics.cmd(99), encode(&cmd)).wait().unwrap();
    }
    // Another spacecraft.
    let cmd = CommandMsg::wrench(Header::new(7, tick, 0, 0), 1, [0.0; 3], [0.0; 3]);
    publisher.put(encode(&cmd)).wait().unwrap();
    assert!(
        wait_until(Duration::from_secs(10), || obs.last_status().is_some_and(
            |s| s.commands_dropped > 0 && s.rejected.unknown_sender == 3
        )),
        "status: {:?}",
        obs.last_status()
    );
    let dropped_in_status = obs.last_status().unwrap().commands_dropped;
    assert_eq!(server.terminate().code(), Some(0));
    let err = server.stderr();
    let final_status = obs.last_status().unwrap();
    assert!(final_status.commands_dropped >= dropped_in_status);
    assert!(
        err.contains(&format!(
            "commands_dropped={}",
            final_status.commands_dropped
        )),
        "final status {} vs log:\n{err}",
        final_status.commands_dropped
    );
    let warns: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("WARN") && l.contains("rejected a command"))
        .collect();
    let unknown: Vec<&&str> = warns
        .iter()
        .filter(|l| l.contains("reason=\"unknown_sender\"") || l.contains("reason=unknown_sender"))
        .collect();
    assert_eq!(unknown.len(), 1, "unknown_sender logged once:\n{err}");
    assert!(unknown[0].contains("sender=99"), "{}", unknown[0]);
    assert!(
        warns
            .iter()
            .any(|l| l.contains("wrong_spacecraft") && l.contains("sender=1")),
        "wrong_spacecraft logged:\n{err}"
    );
}

#[test]
fn batch_mode_runs_to_the_duration() {
    let ep = ANY_PORT;
    let mut server = Server::spawn(&[
        "run",
        "--mode",
        "batch",
        "--duration-s",
        "20",
        "--listen",
        ep,
    ]);
    let status = server.wait(Duration::from_secs(60));
    let err = server.stderr();
    assert_eq!(status.code(), Some(0), "stderr:\n{err}");
    assert!(
        err.contains("run finished: mode=batch last_tick=2000"),
        "stderr:\n{err}"
    );
    // Where the ticks went (docs/guides/server.md, "Lifecycle and logs"): every field, and a
    // settled rate, since 2000 ticks are more than the 1000 it leaves out.
    let line = err
        .lines()
        .find(|l| l.contains("run finished:"))
        .unwrap_or_default();
    for field in [
        " ticks_us physics=",
        " publish=",
        " wait=",
        " period_p50=",
        " period_p99=",
        " period_max=",
        " settled_ticks_per_s=",
    ] {
        assert!(line.contains(field), "{field} missing: {line}");
    }
}

#[test]
fn help_lists_the_run_subcommand() {
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["run", "--help"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    for flag in [
        "--mode",
        "--participants",
        "--participant-timeout-s",
        "--listen",
        "--connect",
        "--zenoh-config",
        "--sc-id",
        "--duration-s",
        "--overrun-policy",
        "--stale-policy",
    ] {
        assert!(text.contains(flag), "{flag} missing from:\n{text}");
    }
}

/// Every subcommand's help states each option's default once (clap adds `[default: …]` for a
/// default value; a doc comment that says it too printed it twice).
#[test]
fn every_help_states_each_default_once() {
    let help = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
            .args(args)
            .output()
            .unwrap();
        assert!(out.status.success(), "{args:?}");
        String::from_utf8_lossy(&out.stdout).to_string()
    };
    let top = help(&["--help"]);
    let commands: Vec<String> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_owned)
        .collect();
    assert!(
        commands.iter().any(|c| c == "replay") && commands.len() >= 9,
        "{commands:?} from:\n{top}"
    );
    for c in &commands {
        let text = help(&[c, "--help"]);
        // An option's text runs from its `-x, --name` line to the next option's.
        let mut options: Vec<String> = Vec::new();
        for line in text.lines() {
            match options.last_mut() {
                Some(o) if !line.trim_start().starts_with('-') => o.push_str(line),
                _ => options.push(line.to_owned()),
            }
        }
        for option in options.iter().filter(|o| o.trim_start().starts_with('-')) {
            assert!(
                option.matches("[default: ").count() <= 1,
                "`flexdyn {c} --help` states a default twice: {option}"
            );
        }
    }
}

/// `flexdyn 2>&1 | tee log`, then Ctrl-C: the reader of stderr dies first. The server must keep
/// running while it logs into the closed pipe, then stop on SIGTERM with exit 0 and its final
/// status, instead of panicking on EPIPE (exit 101/134).
#[test]
fn a_closed_stderr_reader_never_takes_the_server_down() {
    let ep = ANY_PORT;
    // Log at debug so that writes into the closed pipe happen for sure.
    let mut server =
        Server::spawn_closing_stderr(&["--listen", ep, "--summary-interval-s", "0.05"], "debug");
    let port = server.port();
    let topics = Topics::new("sc1").unwrap();
    let obs = Observer::start(port, &topics);
    server.await_tick(&obs, 30);
    assert!(
        !server.stderr().is_empty(),
        "the server logs at start, before the reader closes"
    );
    // Still alive after logging into the closed pipe for a while.
    std::thread::sleep(Duration::from_millis(300));
    assert!(
        server.child.try_wait().unwrap().is_none(),
        "the server died"
    );
    let status = server.terminate();
    assert_eq!(status.code(), Some(0), "exit status {status:?}");
    // The final status went out: the last one seen is no longer `Running`.
    let last = obs.last_status().expect("status messages");
    assert_ne!(
        last.run_state,
        flexdyn_proto::RunState::Running,
        "final status: {last:?}"
    );
}

#[test]
fn plain_flexdyn_takes_the_run_options_and_usage_errors_are_one_line() {
    // `flexdyn --config X` is `flexdyn run --config X`.
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["--config", "/nonexistent/craft.toml"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(
        err.trim_end(),
        "error: cannot read config file `/nonexistent/craft.toml`: No such file or directory (os error 2)"
    );
    // A usage error is one line, exit 2.
    for args in [
        &["--bogus"][..],
        &["simulate", "--duration-s"],
        &["run", "--mode", "fast"],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains("--help"),
            "{err}"
        );
    }
    // Negative numbers reach the setting's own check.
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["--stale-after-s", "-1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        err.trim_end(),
        "error: --stale-after-s: must be > 0 (got -1)"
    );
    // Logs into a pipe carry no ANSI colour codes.
    let out = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["simulate", "--duration-s", "0.01", "--output", "-"])
        .env("RUST_LOG", "debug")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("DEBUG"), "a debug line was logged: {err}");
    assert!(!err.contains('\u{1b}'), "colour codes in a pipe: {err:?}");
}

/// A fleet file in a fresh temporary folder, its `spacecraft_file`s pointing at the repo's
/// scenarios.
fn fleet_file(name: &str, body: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("flexdyn-fleet-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("fleet.toml");
    let scenarios = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
    std::fs::write(&path, body.replace("SCENARIOS", scenarios)).unwrap();
    path
}

#[test]
fn run_fleet_serves_every_vehicle_and_names_the_vehicle_of_a_bad_field() {
    let pair = fleet_file(
        "pair",
        r#"
[[vehicles]]
id = "chief"
spacecraft_file = "SCENARIOS/reference.toml"
[[vehicles]]
id = "deputy"
spacecraft_file = "SCENARIOS/reference.toml"
[vehicles.relative]
chief = "chief"
hill_position_m = [0.0, -100.0, 0.0]
"#,
    );
    let pair_s = pair.to_str().unwrap();
    let mut server = Server::spawn(&[
        "run",
        "--fleet",
        pair_s,
        "--mode",
        "batch",
        "--duration-s",
        "2",
        "--listen",
        ANY_PORT,
    ]);
    let status = server.wait(Duration::from_secs(60));
    let err = server.stderr();
    assert_eq!(status.code(), Some(0), "stderr:\n{err}");
    for line in [
        "fleet of 2: frames=200",
        "chief: run finished: mode=batch last_tick=200",
        "deputy: run finished: mode=batch last_tick=200",
    ] {
        assert!(err.contains(line), "no `{line}` in stderr:\n{err}");
    }

    let bad = fleet_file(
        "bad",
        r#"
[[vehicles]]
id = "chief"
spacecraft_file = "SCENARIOS/reference.toml"
[[vehicles]]
id = "deputy"
spacecraft_file = "SCENARIOS/reference.toml"
participants = ["two"]
"#,
    );
    let mut server = Server::spawn(&[
        "run",
        "--fleet",
        bad.to_str().unwrap(),
        "--listen",
        ANY_PORT,
    ]);
    let status = server.wait(Duration::from_secs(60));
    let err = server.stderr();
    assert_eq!(status.code(), Some(2), "stderr:\n{err}");
    assert!(
        err.contains("vehicles[1] (\"deputy\").participants: must be a list of sender ids"),
        "stderr:\n{err}"
    );

    // The ids and participants are the fleet file's.
    let mut server = Server::spawn(&["run", "--fleet", pair_s, "--sc-id", "x"]);
    let status = server.wait(Duration::from_secs(60));
    let err = server.stderr();
    assert_eq!(status.code(), Some(2), "stderr:\n{err}");
    assert!(
        err.contains("--sc-id") && err.contains("--fleet"),
        "stderr:\n{err}"
    );
    for p in [pair, bad] {
        let _ = std::fs::remove_dir_all(p.parent().unwrap());
    }
}

/// The log names each configured fault once at start, and each activation as it happens
/// (`scenarios/fdir.toml`: imu_a's gyro stuck from 3 s, rw2 seized from 60 s), in batch mode.
#[test]
fn the_log_names_each_fault_at_start_and_when_it_activates() {
    let mut server = Server::spawn(&[
        "run",
        "--config",
        concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/fdir.toml"),
        "--mode",
        "batch",
        "--duration-s",
        "65",
        "--listen",
        ANY_PORT,
    ]);
    let status = server.wait(Duration::from_secs(120));
    let err = server.stderr();
    assert_eq!(status.code(), Some(0), "stderr:\n{err}");
    let gyro = "stuck_current on imus.imu_a.gyro, from 3 s";
    let wheel = "seized on reaction_wheels.rw2, from 60 s";
    for line in [
        format!("fault 0 configured: {gyro}"),
        format!("fault 1 configured: {wheel}"),
        format!("fault 0 active: {gyro} (t = 3 s)"),
        format!("fault 1 active: {wheel} (t = 60 s)"),
    ] {
        assert_eq!(err.matches(&line).count(), 1, "{line:?} once in:\n{err}");
    }
    // Neither fault ever clears (no duration).
    assert!(!err.contains("cleared"), "stderr:\n{err}");
}
