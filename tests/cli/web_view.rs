//! `flexdyn view`'s web page in a real browser (issue 36): a recording made offline is served
//! with `flexdyn view --file` on a port the OS picks, and Debian's Chromium, headless, opens
//! `http://127.0.0.1:PORT/`. The page is a Foxglove-WebSocket client of that same port; the
//! test reads the page's own state from its DOM (`--dump-dom`: the latest tick shown, the run
//! state, the eclipse) and checks a screenshot of it (`--screenshot`) is not blank.
//!
//! Chromium comes from `tests/deps/debian_package.sh` (`apt-get install -y chromium` as root)
//! when `/usr/bin/chromium` is missing; without it the test fails saying what to install.

use flexdyn_testkit::ports;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Instant;

use flexdyn_proto::{decode_state, decode_status};
use flexdyn_sinks::reader::read_recording;

const CHROMIUM: &str = "/usr/bin/chromium";
/// Seconds of simulation recorded (played back at 1×).
const RECORDED_S: &str = "4";
/// Real time the page holds its load event (`?hold=MS`): longer than the replay plus a restart,
/// so the page sees the replay's end whenever it connects.
const HOLD_MS: u64 = 7000;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("web_view");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

struct Guard(Child);

impl Drop for Guard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `/usr/bin/chromium`, installed through `tests/deps/debian_package.sh` when missing.
fn chromium() -> &'static Path {
    let path = Path::new(CHROMIUM);
    if !path.exists() {
        let script = root().join("tests/deps/debian_package.sh");
        let status = Command::new("sh")
            .arg(&script)
            .args([CHROMIUM, "chromium"])
            .status();
        eprintln!("{}: {status:?}", script.display());
    }
    assert!(
        path.exists(),
        "this test needs Debian's Chromium at {CHROMIUM}: install it with \
         `apt-get install chromium` (as root: tests/deps/debian_package.sh does it)"
    );
    path
}

/// What an element `<TAG id="ID" …>TEXT<` of the dumped DOM holds.
fn element_text<'a>(dom: &'a str, id: &str) -> Option<&'a str> {
    let at = dom.find(&format!("id=\"{id}\""))?;
    let rest = &dom[at..];
    let start = rest.find('>')? + 1;
    let end = rest[start..].find('<')? + start;
    Some(&rest[start..end])
}

/// One headless Chromium run on the page at `port` held `hold_ms` (`?hold=`): the DOM it
/// dumps, and the screenshot written to `shot`. Panics if Chromium fails or the page is not
/// there.
fn browse(browser: &Path, port: u16, hold_ms: u64, shot: &Path) -> String {
    let _ = std::fs::remove_file(shot);
    let profile = tmp(&format!("chromium-profile-{port}"));
    let url = format!("http://127.0.0.1:{port}/?hold={hold_ms}");
    let out = Command::new(browser)
        .args([
            "--headless=new",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--virtual-time-budget=2000",
            "--window-size=1200,800",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg("--dump-dom")
        .arg(&url)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success() && dom.contains("<canvas id=\"scene\""),
        "chromium {url}: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    dom
}

/// The port of the `view: open http://127.0.0.1:PORT/` line `child` logs (stderr piped with
/// [`ports::reporting`]).
fn page_port(child: &mut Child) -> u16 {
    let marker = "view: open http://127.0.0.1:";
    let reported = ports::reported(child, marker);
    let port: u16 = reported[marker.len()..]
        .strip_suffix('/')
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no port in {reported:?}"));
    assert_ne!(port, 0);
    port
}

/// `seconds` of `scenarios/<scenario>` run in batch mode and recorded to `<scenario>.mcap`.
fn record_offline(scenario: &str, seconds: &str) -> PathBuf {
    let file = tmp(&format!("{scenario}.mcap"));
    let _ = std::fs::remove_file(&file);
    let status = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .args(["run", "--mode", "batch", "--duration-s", seconds])
        .args(["--listen", ports::ANY_PORT])
        .arg("--config")
        .arg(root().join("scenarios").join(scenario))
        .arg("--record")
        .arg(&file)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(
        status.success(),
        "flexdyn run --record {scenario}: {status}"
    );
    file
}

/// `flexdyn view --file FILE` on a port the OS picks (stopped when dropped), and that port.
fn serve_file(file: &Path) -> (Guard, u16) {
    let mut viewer = Guard(
        ports::reporting(
            Command::new(env!("CARGO_BIN_EXE_flexdyn"))
                .args(["view", "--file"])
                .arg(file)
                .args(["--bind", "127.0.0.1:0", "--duration-s", "60"]),
        )
        .stdout(Stdio::null())
        .spawn()
        .unwrap(),
    );
    let port = page_port(&mut viewer.0);
    (viewer, port)
}

/// `flexdyn run --view` serves the same page for its own live run (issue 36: "and from the
/// server when asked"): a real-time run of the LEO scenario, the page held 2.5 s, shows a tick
/// of the run (> 0: data came) and the run state `Running`.
#[test]
fn the_server_serves_the_page_of_its_own_run_when_asked() {
    let browser = chromium();
    let mut server = Guard(
        ports::reporting(
            Command::new(env!("CARGO_BIN_EXE_flexdyn"))
                .args(["run", "--duration-s", "30", "--listen", ports::ANY_PORT])
                .args(["--view", "127.0.0.1:0", "--config"])
                .arg(root().join("scenarios/leo_environment.toml")),
        )
        .stdout(Stdio::null())
        .spawn()
        .unwrap(),
    );
    let port = page_port(&mut server.0);
    let dom = browse(browser, port, 2500, &tmp("live.png"));
    assert_eq!(element_text(&dom, "conn"), Some("connected"), "{dom}");
    let tick: u64 = element_text(&dom, "tick")
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("the page shows no tick:\n{dom}"));
    assert!(tick > 0, "no data reached the page");
    assert_eq!(element_text(&dom, "run-state"), Some("Running"), "{dom}");
    eprintln!("flexdyn run --view: the page showed tick {tick}, Running");
    drop(server);
}

#[test]
fn a_browser_shows_a_replay_on_the_viewers_own_port() {
    let browser = chromium();
    let started = Instant::now();
    // A recording made offline, as tests/cli/recording_files.rs makes them: the LEO scenario
    // (panels, the Sun, the magnetic field, the eclipse).
    let file = record_offline("leo_environment.toml", RECORDED_S);
    let rec = read_recording(&file).unwrap();
    let ticks: HashSet<u64> = rec
        .samples
        .iter()
        .filter(|s| s.key == "flexdyn/sc1/tlm/state")
        .map(|s| decode_state(&s.payload).unwrap().header.tick)
        .collect();
    let last_tick = *ticks.iter().max().expect("states in the recording");
    let run_states: Vec<String> = rec
        .samples
        .iter()
        .filter(|s| s.key == "flexdyn/sc1/status")
        .map(|s| {
            let status = decode_status(&s.payload).unwrap();
            serde_json::to_value(status.run_state)
                .unwrap()
                .as_str()
                .expect("a run state serializes as its name")
                .to_owned()
        })
        .collect();
    let final_run_state = run_states
        .last()
        .expect("a StatusMsg in the recording")
        .clone();

    // The viewer on a port the OS picks; its one log line names the page and the protocol.
    let (viewer, port) = serve_file(&file);

    let shot = tmp("page.png");
    let dom = browse(browser, port, HOLD_MS, &shot);

    // The page's own state: connected, the latest tick it drew is the recording's last one
    // (it saw the replay's end), and the run state is the recording's last StatusMsg's.
    assert_eq!(element_text(&dom, "conn"), Some("connected"), "{dom}");
    let tick_text = element_text(&dom, "tick").unwrap_or_default();
    let tick: u64 = tick_text
        .parse()
        .unwrap_or_else(|_| panic!("the page shows no tick ({tick_text:?}):\n{dom}"));
    assert!(ticks.contains(&tick), "tick {tick} is not in the recording");
    assert_eq!(tick, last_tick, "the page did not reach the replay's end");
    assert_eq!(
        element_text(&dom, "run-state"),
        Some(final_run_state.as_str())
    );
    let eclipse = element_text(&dom, "eclipse").unwrap_or_default();
    assert!(
        ["sunlit", "penumbra", "umbra"]
            .iter()
            .any(|e| eclipse.starts_with(e)),
        "eclipse: {eclipse:?}"
    );
    assert_eq!(element_text(&dom, "faults"), Some("none"));

    // The screenshot: 1200×800 and far from blank.
    let decoder =
        png::Decoder::new(std::fs::File::open(&shot).expect("chromium wrote no screenshot"));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert!(channels >= 3, "{:?}", info.color_type);
    let pixels = &buf[..info.buffer_size()];
    let colours: HashSet<[u8; 3]> = pixels
        .chunks_exact(channels)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    eprintln!(
        "web view: tick {tick} (last {last_tick}), run state {final_run_state}, eclipse {eclipse}; \
         screenshot {}x{}, {} distinct colours; {:.1} s",
        info.width,
        info.height,
        colours.len(),
        started.elapsed().as_secs_f64()
    );
    assert_eq!((info.width, info.height), (1200, 800));
    assert!(
        colours.len() >= 200,
        "a nearly blank page: {} colours",
        colours.len()
    );
    drop(viewer);
}

/// Issue 37 §2: the page shows the flight code's mode and its last event, named by the served
/// configuration's `[[fsw_streams]]`. A recording written here with the recorder's sink:
/// `scenarios/fdir.toml`'s vehicle, 2 s of states at 10 Hz, and its stream `acs` every tick in
/// mode 0 (`pointing`), with `gyro-failure` at 0.5 s and `wheel-failure`, `wheels-reconfigured`
/// at 1.5 s; replayed with `flexdyn view --file`.
#[test]
fn a_browser_shows_the_flight_codes_mode_and_last_event() {
    use flexdyn_proto::{encode, fsw_flags, FswMsg, Header, RunState, StateMsg, StatusMsg};
    let browser = chromium();
    let config_toml = std::fs::read_to_string(root().join("scenarios/fdir.toml")).unwrap();
    let cfg = flexdyn_vehicle::config::SimConfig::from_toml_str(&config_toml).unwrap();
    let decl = cfg.fsw_stream("acs").expect("fdir.toml declares acs");
    let event = |name: &str| decl.event_index(name).unwrap();
    let file = tmp("fsw_view.mcap");
    let mut sink = crate::mcap_support::sink_for(&file, &config_toml);
    let frame_ns = 100_000_000;
    for tick in 0..=20u64 {
        let header = Header::new(1, tick, tick * frame_ns, tick);
        let t_ns = tick * frame_ns;
        let state = StateMsg {
            header,
            q_bn: [1.0, 0.0, 0.0, 0.0],
            ..StateMsg::default()
        };
        sink.write("flexdyn/sc1/tlm/state", &encode(&state), Some(1), t_ns)
            .unwrap();
        let events: Vec<u16> = match tick {
            5 => vec![event("gyro-failure")],
            15 => vec![event("wheel-failure"), event("wheels-reconfigured")],
            _ => vec![],
        };
        let mut fsw = FswMsg {
            header,
            flags: fsw_flags::MODE,
            mode: 0,
            event_count: events.len() as u8,
            values: vec![0; decl.words()],
            ..FswMsg::default()
        };
        fsw.events[..events.len()].copy_from_slice(&events);
        sink.write("flexdyn/sc1/fsw/acs", &encode(&fsw), Some(1), t_ns)
            .unwrap();
    }
    let status = StatusMsg {
        header: Header::new(1, 20, 20 * frame_ns, 0),
        run_state: RunState::Finished,
        ..StatusMsg::default()
    };
    sink.write(
        "flexdyn/sc1/status",
        &encode(&status),
        Some(1),
        20 * frame_ns,
    )
    .unwrap();
    sink.finish().unwrap();

    let (_viewer, port) = serve_file(&file);
    let dom = browse(browser, port, 4000, &tmp("fsw_page.png"));
    assert_eq!(element_text(&dom, "tick"), Some("20"), "{dom}");
    // The recording's one StatusMsg, at its last instant: its channel is advertised before the
    // replay plays it (a channel opened by its first message lost it).
    assert_eq!(element_text(&dom, "run-state"), Some("Finished"), "{dom}");
    assert_eq!(
        element_text(&dom, "fsw"),
        Some("acs: pointing · wheels-reconfigured (warning) at 1.500 s"),
        "{dom}"
    );
}

/// Issue 39: the page draws the panel chains and the propellant tanks it is served. Offline
/// recordings of `scenarios/panel_chain.toml` and `scenarios/depletion.toml`, replayed with
/// `flexdyn view --file`; the page says what it drew (`#drawn`). The chains: the hub and the
/// 4 + 3 chain panels, each placed through its `/tf` frames (a frame the page cannot resolve
/// makes it fall back to its default layout: the hub box alone, as there are no pairs). The
/// tanks: the hub and the two pairs' four panels, and per tank its shell (`/scene`) and the
/// propellant in it (`/actuators`; the engine fires after the recorded seconds, so both are
/// full and drawn).
#[test]
fn a_browser_draws_the_chains_and_the_tanks() {
    let browser = chromium();
    for (scenario, drawn) in [
        ("panel_chain.toml", "8 boxes, 0 spheres"),
        ("depletion.toml", "5 boxes, 4 spheres"),
    ] {
        let file = record_offline(scenario, "1");
        let (viewer, port) = serve_file(&file);
        let dom = browse(browser, port, 3000, &tmp(&format!("{scenario}.png")));
        assert_eq!(element_text(&dom, "drawn"), Some(drawn), "{scenario}");
        drop(viewer);
    }
}
