//! The device gateway end to end (issue 38): a lockstep server in this process, `flexdyn
//! gateway` as its participant 1, a recording participant 2, and on the far side of the
//! gateway's pseudo-terminals and sockets programs that know nothing of flexdyn:
//!
//! - `examples/drivers/pointing_driver.c`, a C program written as flight drivers are (open(2),
//!   termios, its own CRCs and framings from the device descriptions' ICD comments, no flexdyn
//!   header), closes a pointing loop on `scenarios/wheels_star_tracker.toml` twice with
//!   identical state streams;
//! - the same driver writing malformed frames of every kind before each command is counted
//!   exactly by the gateway, and its state stream equals the clean run's;
//! - Python's `pynmea2` parses every NMEA sentence of the GPS receiver and `spacepackets` (with
//!   `fastcrc`'s CRC) every Space Packet of the magnetometer, and their values match what the
//!   server's receiver and magnetometer published at the same instants.

use crate::server_support::{connecting_session, endpoint, ServerHandle};

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use flexdyn_proto::{decode_gps, decode_magnetometer, decode_state, decode_time, Topics};
use flexdyn_testkit::python::venv_python;
use flexdyn_testkit_server::participants::{digest, Recorder};
use zenoh::Wait;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("device_gateway")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The C driver, compiled once with the strictest warnings, after checking that it includes no
/// flexdyn header.
fn driver() -> &'static Path {
    static EXE: OnceLock<PathBuf> = OnceLock::new();
    EXE.get_or_init(|| {
        let src = root().join("examples/drivers/pointing_driver.c");
        let text = std::fs::read_to_string(&src).unwrap();
        for line in text
            .lines()
            .filter(|l| l.trim_start().starts_with("#include"))
        {
            assert!(
                line.contains('<') && !line.to_lowercase().contains("flexdyn"),
                "the driver must use system headers only: {line}"
            );
        }
        let exe = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pointing_driver");
        flexdyn_testkit::c_program::compile_c99(&src, &exe, &["-lm"]);
        exe
    })
}

/// A child killed when dropped.
struct Guard(Child);

impl Drop for Guard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Waits for `child` (bounded), returning whether it exited 0.
fn wait(child: &mut Child, limit: Duration, what: &str) -> bool {
    let give_up = Instant::now() + limit;
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s.success();
        }
        assert!(
            Instant::now() < give_up,
            "{what} still running after {limit:?}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// A lockstep server on `scenario` for `duration_s`, participants 1 (the gateway) and 2 (a
/// recorder of every state).
fn server(scenario: &str, duration_s: f64) -> ServerHandle {
    ServerHandle::lockstep_on(
        &root().join("scenarios").join(scenario),
        vec![1, 2],
        (duration_s * 1e9).round() as u64,
    )
}

/// `flexdyn gateway` on `list`, links under `dir`, its report into `dir/report.toml`.
fn gateway(port: u16, list: &Path, dir: &Path) -> Guard {
    let log = std::fs::File::create(dir.join("gateway.log")).unwrap();
    Guard(
        Command::new(env!("CARGO_BIN_EXE_flexdyn"))
            .arg("gateway")
            .arg("--devices")
            .arg(list)
            .arg("--link-dir")
            .arg(dir)
            .args(["--connect", &endpoint(port), "--wait-for-drivers-s", "120"])
            .arg("--report")
            .arg(dir.join("report.toml"))
            .stdin(Stdio::null())
            .stdout(log.try_clone().unwrap())
            .stderr(log)
            .spawn()
            .expect("start flexdyn gateway"),
    )
}

fn wait_for_file(path: &Path) {
    let give_up = Instant::now() + Duration::from_secs(60);
    while !path.exists() {
        assert!(
            Instant::now() < give_up,
            "{} never appeared",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// One flight of the C driver.
struct Flight {
    /// Every state payload, by tick.
    states: Vec<(u64, Vec<u8>)>,
    /// The driver's last lines (its summary).
    driver: String,
    /// The gateway's counters, by device.
    report: toml::Table,
}

impl Flight {
    fn counter(&self, device: &str, name: &str) -> i64 {
        self.report["device"][device][name]
            .as_integer()
            .unwrap_or_else(|| panic!("no counter {device}.{name} in {:#?}", self.report))
    }

    /// A `key=value` of the driver's summary line (the one starting with `prefix`).
    fn driver_value(&self, prefix: &str, key: &str) -> f64 {
        let line = self
            .driver
            .lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` line in {}", self.driver));
        line.split_whitespace()
            .find_map(|kv| kv.strip_prefix(&format!("{key}=")))
            .unwrap_or_else(|| panic!("no {key} in {line}"))
            .parse()
            .unwrap()
    }
}

/// Flies `pointing_driver` (with `args`) on wheels_star_tracker.toml for `duration_s`.
fn fly(name: &str, duration_s: f64, args: &[&str]) -> Flight {
    let dir = tmp(name);
    let topics = Topics::new("sc1").unwrap();
    let server = server("wheels_star_tracker.toml", duration_s);
    let recorder = Recorder::start(server.port, &topics, 2);
    let list = root().join("scenarios/wheels_star_tracker.devices.toml");
    let mut gw = gateway(server.port, &list, &dir);
    for link in ["st1", "imu", "rw1", "rw2", "rw3", "rw4"] {
        wait_for_file(&dir.join(format!("{link}.tty")));
    }
    let out = Command::new(driver())
        .arg(&dir)
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("run the driver");
    let driver = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "the driver failed: {driver}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = server
        .join(Duration::from_secs(300))
        .expect("the lockstep run");
    assert_eq!(report.last_tick, (duration_s * 100.0).round() as u64);
    let log = dir.join("gateway.log");
    assert!(
        wait(&mut gw.0, Duration::from_secs(30), "flexdyn gateway"),
        "the gateway failed: {}",
        std::fs::read_to_string(&log).unwrap_or_default()
    );
    let text = std::fs::read_to_string(dir.join("report.toml")).unwrap();
    let mut states = recorder.states.lock().unwrap().clone();
    states.sort_by_key(|(t, _)| *t);
    Flight {
        states,
        driver,
        report: text.parse().unwrap(),
    }
}

/// The truth pointing error [deg]: the rotation angle 4 atan |σ_BN| (target σ_RN = 0).
fn pointing_deg(state: &[u8]) -> f64 {
    let s = decode_state(state).unwrap().sigma_bn;
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    (4.0 * n.atan()).to_degrees()
}

const DEVICES: [&str; 6] = ["st1", "imu", "rw1", "rw2", "rw3", "rw4"];

#[test]
fn a_c_driver_points_the_spacecraft_through_the_devices_bit_identically_twice() {
    const DURATION_S: f64 = 250.0;
    let a = fly("pointing_a", DURATION_S, &[]);
    let b = fly("pointing_b", DURATION_S, &[]);
    let ticks = (DURATION_S * 100.0) as usize + 1;
    assert_eq!(a.states.len(), ticks);
    assert_eq!(
        digest(&a.states),
        digest(&b.states),
        "the two lockstep streams differ"
    );
    // σ_BN(0) = (0.1, −0.05, 0.08): |σ| = √0.0189 = 0.137477, 4 atan|σ| = 0.546486 rad =
    // 31.311°. The loop brings it under 2°.
    let start = pointing_deg(&a.states[0].1);
    assert!((start - 31.311).abs() < 0.001, "start {start}°");
    let end = pointing_deg(&a.states.last().unwrap().1);
    assert!(
        end < 2.0,
        "pointing error at the end {end}° (started at {start}°)"
    );
    // One cycle per 0.1 s from tick 0 to the last tick: 2501; each device answered every one,
    // nothing was rejected, no tick waited out a time-out.
    let cycles = (DURATION_S * 10.0) as i64 + 1;
    assert_eq!(a.driver_value("cycles=", "cycles") as i64, cycles);
    assert_eq!(a.counter("st1", "in_quaternion_request"), cycles);
    assert_eq!(a.counter("imu", "frames_out"), cycles);
    for w in ["rw1", "rw2", "rw3", "rw4"] {
        assert_eq!(a.counter(w, "in_torque_command"), cycles, "{w}");
        assert_eq!(a.counter(w, "in_speed_request"), cycles, "{w}");
        assert_eq!(a.counter(w, "frames_out"), cycles, "{w}");
    }
    for d in DEVICES {
        for c in [
            "rejected_total",
            "garbage_bytes",
            "late_ticks",
            "line_frames_unheard",
        ] {
            assert_eq!(a.counter(d, c), 0, "{d}.{c}");
        }
    }
}

#[test]
fn a_hostile_driver_is_counted_exactly_and_never_applied() {
    const DURATION_S: f64 = 20.0;
    let clean = fly("clean", DURATION_S, &[]);
    let hostile = fly("hostile", DURATION_S, &["--hostile"]);
    assert_eq!(
        digest(&clean.states),
        digest(&hostile.states),
        "malformed input changed the run"
    );
    let cycles = (DURATION_S * 10.0) as i64 + 1;
    // What the driver wrote before each command (its --hostile tally), as the decoders count
    // it (crates/gateway/src/framing: a rejected frame's octets after its first are scanned
    // again for a sync, so they count as garbage when they hold none):
    // - tracker, every 50th cycle (cycles 0, 50, …: 5 of 201): a flood of 4096 octets, none of
    //   them 0xEB → 4096 garbage octets each;
    // - tracker, every cycle: 7 garbage octets (no 0xEB) → 7; a request EB 90 01 01 45 1C
    //   (CRC-16/CCITT-FALSE of EB 90 01 01 = 0x451C) with the last octet flipped (1C ^ 5A =
    //   46) → one bad check, then its 5 octets after EB, 90 01 01 45 46 → 5 garbage (none is
    //   0xEB); a frame of LEN 0 → framed, then too short for an id (bad
    //   payload length);
    // - each wheel, every cycle: C0 10 E8 cut short, closed by the next frame's opening END →
    //   a frame whose 2 octets are shorter than id + CRC (bad payload length at the framing:
    //   counted as a bad check, as the CRC over nothing cannot match); a torque command with
    //   the CRC's high octet flipped → bad check; a command two octets short → bad payload
    //   length; a 301-octet frame → oversize, dropped whole.
    let n = |k| hostile.driver_value("hostile", k) as i64;
    let floods = (cycles + 49) / 50;
    assert_eq!(n("flood_bytes"), 4096 * floods);
    assert_eq!(n("garbage_bytes"), 7 * cycles);
    assert_eq!(
        hostile.counter("st1", "garbage_bytes"),
        4096 * floods + (7 + 5) * cycles
    );
    assert_eq!(hostile.counter("st1", "rejected_checksum"), cycles);
    assert_eq!(hostile.counter("st1", "rejected_payload_length"), cycles);
    assert_eq!(hostile.counter("st1", "rejected_total"), 2 * cycles);
    assert_eq!(hostile.counter("st1", "in_quaternion_request"), cycles);
    for w in ["rw1", "rw2", "rw3", "rw4"] {
        assert_eq!(hostile.counter(w, "rejected_checksum"), 2 * cycles, "{w}");
        assert_eq!(hostile.counter(w, "rejected_payload_length"), cycles, "{w}");
        assert_eq!(hostile.counter(w, "rejected_oversize"), cycles, "{w}");
        assert_eq!(hostile.counter(w, "rejected_total"), 4 * cycles, "{w}");
        assert_eq!(hostile.counter(w, "in_torque_command"), cycles, "{w}");
        assert_eq!(hostile.counter(w, "in_speed_request"), cycles, "{w}");
    }
    assert_eq!(n("partial"), 4 * cycles);
    assert_eq!(n("bad_crc"), 5 * cycles);
    assert_eq!(n("bad_length"), 5 * cycles);
    assert_eq!(n("oversize"), 4 * cycles);
    for d in DEVICES {
        assert_eq!(hostile.counter(d, "late_ticks"), 0, "{d}");
    }
}

/// The NMEA and Space Packet reader: opens the GPS receiver's pty raw and takes the
/// magnetometer's datagrams until the gateway closes the line, then parses every sentence
/// with pynmea2 and every packet header with spacepackets (CRC by fastcrc), as JSON.
const READER_PY: &str = r#"
import errno, json, os, select, socket, sys, time, tty
import pynmea2
from fastcrc import crc16
from spacepackets.ccsds.spacepacket import SpacePacketHeader

link = sys.argv[1]
udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
udp.bind(("127.0.0.1", 0))
print(udp.getsockname()[1], flush=True)
while not os.path.exists(link):
    time.sleep(0.005)
fd = os.open(link, os.O_RDWR | os.O_NOCTTY)
tty.setraw(fd)
text, packets = b"", []
while True:
    ready, _, _ = select.select([fd, udp], [], [], 60)
    if not ready:
        break
    if udp in ready:
        packets.append(udp.recv(65536))
    if fd in ready:
        try:
            chunk = os.read(fd, 4096)
        except OSError as e:
            if e.errno == errno.EIO:
                break
            raise
        if not chunk:
            break
        text += chunk
udp.setblocking(False)
while True:
    try:
        packets.append(udp.recv(65536))
    except BlockingIOError:
        break
out = {"sentences": [], "packets": []}
for line in text.decode("ascii").split("\r\n"):
    if not line:
        continue
    m = pynmea2.parse(line)  # raises on a bad checksum or a malformed sentence
    s = {"type": m.sentence_type, "raw": line}
    if m.sentence_type == "GGA":
        s.update(t=m.timestamp.isoformat(), lat=m.latitude, lon=m.longitude,
                 alt=float(m.altitude), qual=int(m.gps_qual), sats=int(m.num_sats))
    elif m.sentence_type == "RMC":
        s.update(t=m.timestamp.isoformat(), status=m.status, lat=m.latitude,
                 lon=m.longitude, date=m.datestamp.isoformat())
    elif m.sentence_type == "ZDA":
        s.update(t=m.timestamp.isoformat(), date="%04d-%02d-%02d" % (m.year, m.month, m.day))
    out["sentences"].append(s)
for p in packets:
    h = SpacePacketHeader.unpack(p)
    out["packets"].append({
        "apid": h.apid, "seq": h.seq_count, "type": int(h.packet_type),
        "sec": bool(h.sec_header_flag), "version": h.ccsds_version,
        "packet_len": h.packet_len, "len": len(p),
        "crc_ok": crc16.ibm_3740(p[:-2]) == int.from_bytes(p[-2:], "big"),
        "body": p[6:-2].hex()})
print(json.dumps(out))
"#;

/// WGS-84 geodetic → ECEF, the closed form (NIMA TR8350.2 eq. 4-14), written here so the
/// check does not share the gateway's inverse.
fn ecef(lat_deg: f64, lon_deg: f64, h_m: f64) -> [f64; 3] {
    let a = 6_378_137.0;
    let f = 1.0 / 298.257_223_563;
    let e2 = f * (2.0 - f);
    let (sl, cl) = lat_deg.to_radians().sin_cos();
    let (so, co) = lon_deg.to_radians().sin_cos();
    let n = a / (1.0 - e2 * sl * sl).sqrt();
    [
        (n + h_m) * cl * co,
        (n + h_m) * cl * so,
        (n * (1.0 - e2) + h_m) * sl,
    ]
}

/// Seconds of the day of an ISO `hh:mm:ss[.ffffff]`.
fn seconds_of_day(t: &str) -> f64 {
    // pynmea2's times are aware (UTC): drop the zone.
    let t = t.split('+').next().unwrap();
    let p: Vec<f64> = t.split(':').map(|x| x.parse().unwrap()).collect();
    p[0] * 3600.0 + p[1] * 60.0 + p[2]
}

#[test]
fn nmea_and_space_packets_pass_independent_parsers_and_match_the_sensors() {
    const DURATION_S: f64 = 10.0;
    let dir = tmp("readers");
    let python = venv_python(
        Path::new(env!("CARGO_TARGET_TMPDIR")),
        "python-devices-venv",
        &["pynmea2==1.19.0".into(), "spacepackets==0.32.0".into()],
        "pynmea2==1.19.0 spacepackets==0.32.0",
    );
    // The truth: the receiver's solutions, the magnetometer's samples and the time service,
    // by tick, from a subscriber declared before the run starts.
    let topics = Topics::new("sc1").unwrap();
    let server = server("gateway_pointing.toml", DURATION_S);
    let seen: Arc<Mutex<BTreeMap<String, Vec<Vec<u8>>>>> = Arc::default();
    let session = connecting_session(server.port);
    let s = seen.clone();
    let _sub = session
        .declare_subscriber(topics.telemetry_wildcard())
        .callback(move |sample| {
            let key = sample
                .key_expr()
                .as_str()
                .rsplit('/')
                .take(2)
                .collect::<Vec<_>>();
            let key = format!("{}/{}", key[1], key[0]);
            s.lock()
                .unwrap()
                .entry(key)
                .or_default()
                .push(sample.payload().to_bytes().into_owned());
        })
        .wait()
        .unwrap();
    let recorder = Recorder::start(server.port, &topics, 2);
    // The reader binds its UDP port first; the device list then sends the packets there.
    let mut reader = Guard(
        Command::new(&python)
            .arg("-c")
            .arg(READER_PY)
            .arg(dir.join("gps1.tty"))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let mut lines = BufReader::new(reader.0.stdout.take().unwrap()).lines();
    let port: u16 = lines.next().unwrap().unwrap().trim().parse().unwrap();
    let list = dir.join("readers.devices.toml");
    let scenarios = root().join("scenarios");
    std::fs::write(
        &list,
        format!(
            "[[device]]\nname = \"gps1\"\ndescription = \"{}\"\nbind = {{ gps = \"gps1\" }}\n\
             endpoint = {{ pty = \"gps1.tty\", baud = 9600 }}\n\n\
             [[device]]\nname = \"mag1\"\ndescription = \"{}\"\nbind = {{ mag = \"mag1\" }}\n\
             endpoint = {{ udp_local = \"127.0.0.1:0\", udp_remote = \"127.0.0.1:{port}\" }}\n",
            scenarios.join("devices/gps_nmea.toml").display(),
            scenarios.join("devices/magnetometer.toml").display(),
        ),
    )
    .unwrap();
    let mut gw = gateway(server.port, &list, &dir);
    let report = server
        .join(Duration::from_secs(120))
        .expect("the lockstep run");
    assert_eq!(report.last_tick, 1000);
    assert!(wait(&mut gw.0, Duration::from_secs(30), "flexdyn gateway"));
    let json = lines.next().expect("the reader's JSON").unwrap();
    let mut err = String::new();
    std::io::Read::read_to_string(reader.0.stderr.as_mut().unwrap(), &mut err).unwrap();
    assert!(
        wait(&mut reader.0, Duration::from_secs(30), "the reader"),
        "{err}"
    );
    drop(recorder);
    let out: serde_json::Value = serde_json::from_str(&json).unwrap();
    let seen = seen.lock().unwrap();

    // GPS: a solution every second, published 0.2 s after it is valid (ticks 20, 120, …, 920).
    let fixes: Vec<_> = seen["gps/gps1"]
        .iter()
        .map(|b| decode_gps(b).unwrap())
        .collect();
    assert_eq!(fixes.len(), 10);
    let sentences = out["sentences"].as_array().unwrap();
    assert_eq!(
        sentences.len(),
        3 * fixes.len(),
        "GGA, RMC and ZDA per solution"
    );
    // The scenario's epoch is 2026-11-24T06:00:00 UTC: a fix valid at simulation time t is
    // stamped 06:00:00 + t, on 2026-11-24.
    for (fix, s) in fixes.iter().zip(sentences.chunks(3)) {
        let t_s = 6.0 * 3600.0 + fix.valid_sim_time_ns as f64 * 1e-9;
        let [gga, rmc, zda] = [&s[0], &s[1], &s[2]];
        assert_eq!(
            [&gga["type"], &rmc["type"], &zda["type"]],
            ["GGA", "RMC", "ZDA"]
        );
        for m in [gga, rmc, zda] {
            let got = seconds_of_day(m["t"].as_str().unwrap());
            assert!((got - t_s).abs() < 0.005, "{} at {t_s} s", m["raw"]);
        }
        assert_eq!(rmc["date"], "2026-11-24");
        assert_eq!(zda["date"], "2026-11-24");
        assert_eq!(
            (gga["qual"].as_i64(), rmc["status"].as_str()),
            (Some(1), Some("A"))
        );
        // The position printed (4 decimals of arc minutes: ≤ 0.093 m of latitude, 0.1 m of
        // height) is the receiver's ECEF solution.
        let r = ecef(
            gga["lat"].as_f64().unwrap(),
            gga["lon"].as_f64().unwrap(),
            gga["alt"].as_f64().unwrap(),
        );
        let d: f64 = (0..3)
            .map(|i| (r[i] - fix.r_be_e_m[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(
            d < 0.3,
            "{} is {d} m from the receiver's solution",
            gga["raw"]
        );
    }

    // Magnetometer: a packet per sample, 10 Hz from tick 0 to the last tick (101).
    let samples: Vec<_> = seen["mag/mag1"]
        .iter()
        .map(|b| decode_magnetometer(b).unwrap())
        .collect();
    let times: BTreeMap<u64, u64> = seen["tlm/time"]
        .iter()
        .map(|b| decode_time(b).unwrap())
        .map(|t| (t.header.tick, t.tai_ns_1958))
        .collect();
    let packets = out["packets"].as_array().unwrap();
    assert_eq!(samples.len(), 101);
    assert_eq!(packets.len(), samples.len());
    for (i, (p, m)) in packets.iter().zip(&samples).enumerate() {
        assert_eq!(p["apid"], 0x120);
        assert_eq!(p["seq"], i as u64);
        assert_eq!(
            (
                p["type"].as_i64(),
                p["sec"].as_bool(),
                p["version"].as_i64()
            ),
            (Some(0), Some(true), Some(0))
        );
        // 6 header + 6 CUC + 3 × 4 + 1 + 2 CRC octets; the data length field is that − 7.
        assert_eq!(
            (p["len"].as_i64(), p["packet_len"].as_i64()),
            (Some(27), Some(27))
        );
        assert_eq!(p["crc_ok"], true, "{p}");
        let body = p["body"].as_str().unwrap();
        let octets: Vec<u8> = (0..body.len())
            .step_by(2)
            .map(|k| u8::from_str_radix(&body[k..k + 2], 16).unwrap())
            .collect();
        // CUC 4 + 2: TAI seconds since 1958 and 2⁻¹⁶ s, truncated, of the sample's tick.
        let tai_ns = times[&m.header.tick];
        let coarse = u32::from_be_bytes(octets[0..4].try_into().unwrap());
        let fine = u16::from_be_bytes(octets[4..6].try_into().unwrap());
        assert_eq!(u64::from(coarse), tai_ns / 1_000_000_000);
        assert_eq!(
            u64::from(fine),
            (tai_ns % 1_000_000_000) * 65_536 / 1_000_000_000
        );
        for axis in 0..3 {
            let raw = i32::from_be_bytes(octets[6 + 4 * axis..10 + 4 * axis].try_into().unwrap());
            let b_nt = m.b_s_t[axis] * 1e9;
            assert!(
                (f64::from(raw) * 0.1 - b_nt).abs() <= 0.05 + 1e-9,
                "axis {axis}: {raw} vs {b_nt} nT"
            );
        }
        assert_eq!(octets[18], m.saturation_flags);
    }
}
