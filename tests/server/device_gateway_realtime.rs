//! The device gateway against a real-time server (issue 38 §3): a device's frames reach its
//! driver at the device's rate on the wall clock, and a command the driver writes reaches the
//! wheel. The driver is this test: it opens the rate sensor's and a wheel drive's
//! pseudo-terminals through their links, timestamps each COBS frame delimiter of the rate
//! sensor (10 Hz, `scenarios/devices/imu.toml`), and writes one torque command to `rw1`
//! (`scenarios/devices/reaction_wheel.toml`), which the server's state then shows applied.

use crate::server_support::{connecting_session, endpoint, wait_until, ServerHandle};

use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use flexdyn_proto::{decode_state, effector_kind, Topics};
use flexdyn_server::ServerSettings;
use flexdyn_vehicle::checkpoint::Source;
use zenoh::Wait;

/// CRC-16/KERMIT (poly 0x1021 reflected, init 0, xorout 0; check value 0x2189 over
/// "123456789"), bit by bit: the wheel drive's check.
fn crc16_kermit(bytes: &[u8]) -> u16 {
    let mut crc = 0u16;
    for &b in bytes {
        crc ^= u16::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0x8408
            } else {
                crc >> 1
            };
        }
    }
    crc
}

#[test]
fn realtime_frames_keep_the_devices_rate_and_commands_reach_the_wheel() {
    assert_eq!(crc16_kermit(b"123456789"), 0x2189);
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("device_gateway_realtime");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let list = dir.join("devices.toml");
    std::fs::write(
        &list,
        format!(
            "[[device]]\nname = \"imu\"\ndescription = \"{0}/imu.toml\"\nbind = {{ imu = \"hub\" }}\n\
             endpoint = {{ pty = \"imu.tty\", baud = 460800 }}\n\n\
             [[device]]\nname = \"rw1\"\ndescription = \"{0}/reaction_wheel.toml\"\n\
             bind = {{ wheel = \"rw1\" }}\nendpoint = {{ pty = \"rw1.tty\", baud = 460800 }}\n",
            root.join("scenarios/devices").display()
        ),
    )
    .unwrap();
    let cfg = Source::of(Some(&root.join("scenarios/wheels_star_tracker.toml")))
        .unwrap()
        .config()
        .unwrap();
    let server = ServerHandle::start(
        ServerSettings {
            duration_ns: Some(8_000_000_000),
            ..ServerSettings::default()
        },
        cfg,
    );
    // The wheel's applied motor torque, by tick, from the server's states.
    let applied: Arc<Mutex<Vec<(u64, f64)>>> = Arc::default();
    let session = connecting_session(server.port);
    let a = applied.clone();
    let topics = Topics::new("sc1").unwrap();
    let _sub = session
        .declare_subscriber(topics.state().to_owned())
        .callback(move |s| {
            let st = decode_state(&s.payload().to_bytes()).unwrap();
            // rw1 is effector 2, after the two panel pairs.
            let w = &st.effectors[2];
            assert_eq!(w.kind, effector_kind::REACTION_WHEEL);
            a.lock().unwrap().push((st.header.tick, w.outputs[0]));
        })
        .wait()
        .unwrap();
    let log = std::fs::File::create(dir.join("gateway.log")).unwrap();
    let mut gw = Command::new(env!("CARGO_BIN_EXE_flexdyn"))
        .arg("gateway")
        .arg("--devices")
        .arg(&list)
        .arg("--link-dir")
        .arg(&dir)
        .args(["--connect", &endpoint(server.port)])
        .stdout(log.try_clone().unwrap())
        .stderr(log)
        .stdin(Stdio::null())
        .spawn()
        .unwrap();
    assert!(wait_until(Duration::from_secs(30), || dir
        .join("rw1.tty")
        .exists()));
    let open = |name: &str| {
        std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(dir.join(name))
            .unwrap()
    };
    let mut imu = open("imu.tty");
    let mut rw1 = open("rw1.tty");
    // Timestamp each frame's delimiter for 3 s of wall time.
    let mut arrivals = Vec::new();
    let start = Instant::now();
    let mut buf = [0u8; 256];
    let mut commanded = false;
    while start.elapsed() < Duration::from_secs(3) {
        let n = imu.read(&mut buf).unwrap();
        let now = Instant::now();
        arrivals.extend(buf[..n].iter().filter(|b| **b == 0).map(|_| now));
        if !commanded && arrivals.len() >= 3 {
            // TORQUE_COMMAND +50 mN m: id 0x10, i16 LE raw 5000 (0.01 mN m), CRC-16/KERMIT LE,
            // in SLIP (none of the octets is END or ESC, checked below).
            let payload = [0x10, 0x88, 0x13];
            let crc = crc16_kermit(&payload).to_le_bytes();
            let frame = [
                0xC0, payload[0], payload[1], payload[2], crc[0], crc[1], 0xC0,
            ];
            assert!(frame[1..6].iter().all(|b| *b != 0xC0 && *b != 0xDB));
            rw1.write_all(&frame).unwrap();
            commanded = true;
        }
    }
    drop(imu);
    // 10 Hz on the wall clock: the intervals between frames are 100 ms (the median within 10
    // ms: the server paces frames at 100 Hz, the gateway adds its latency of 0.5 ms and the
    // 20-octet frame's 0.5 ms on a 460800-baud line to every frame alike).
    let mut gaps: Vec<f64> = arrivals
        .windows(2)
        .map(|w| (w[1] - w[0]).as_secs_f64() * 1e3)
        .collect();
    assert!(gaps.len() >= 25, "{} frames in 3 s", arrivals.len());
    let median = flexdyn_testkit::median_mut(&mut gaps);
    assert!((median - 100.0).abs() < 10.0, "median interval {median} ms");
    // The command reaches the wheel: its applied torque is +0.05 N m (the drive's raw
    // resolution, 1e-5 N m, holds it exactly as a decimal of the wire value).
    assert!(
        wait_until(Duration::from_secs(10), || applied
            .lock()
            .unwrap()
            .iter()
            .any(|(_, t)| (t - 0.05).abs() < 1e-12)),
        "the wheel never applied the commanded torque"
    );
    let report = server.join(Duration::from_secs(30)).unwrap();
    assert_eq!(report.last_tick, 800);
    let _ = gw.wait();
}
