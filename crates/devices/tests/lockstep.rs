//! The runtime's tick, without a server: complete ticks built here are handed to
//! [`Gateway::tick`], and a driver living in the test talks to the devices' endpoints.
//!
//! - In lockstep a driver's frames are taken at the tick they are owed, however they were
//!   written: two quaternion requests written at once are answered at ticks 0 and 10, not both
//!   at tick 0 (the second waits in the gateway for the next tick that owes one).
//! - Two messages due at one tick on a UDP device go out as two datagrams.

use std::io::{Read, Write};
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::time::Duration;

use flexdyn_devices::catalog::VehicleCatalog;
use flexdyn_devices::gateway::{Gateway, Pacing};
use flexdyn_gateway::device::DeviceSet;
use flexdyn_proto::client::lockstep::Tick;
use flexdyn_proto::client::vehicle::VehicleConfig;
use flexdyn_proto::{Header, StarTrackerMsg, StateMsg};

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scenarios() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios")
}

fn catalog() -> (VehicleCatalog, VehicleConfig) {
    let text = std::fs::read_to_string(scenarios().join("wheels_star_tracker.toml")).unwrap();
    let cfg = VehicleConfig::from_toml(&text).unwrap();
    (VehicleCatalog::from_config(&cfg), cfg)
}

/// Tick `k` of wheels_star_tracker (100 Hz) with a valid star-tracker sample every 10 ticks.
fn tick(k: u64, cfg: &VehicleConfig) -> Tick {
    let header = Header::new(1, k, k * 10_000_000, k);
    let st = k.is_multiple_of(10).then_some(StarTrackerMsg {
        header,
        q_cn: [1.0, 0.0, 0.0, 0.0],
        valid: true,
        status_flags: 0,
    });
    Tick {
        state: StateMsg {
            header,
            ..StateMsg::default()
        },
        imus: vec![None; cfg.imus.len()],
        star_trackers: vec![st],
        magnetometers: vec![],
        coarse_sun_sensors: vec![],
        fine_sun_sensors: vec![],
        gps_receivers: vec![],
        time: None,
        missing: vec![],
    }
}

/// CRC-16/CCITT-FALSE (check value 0x29B1 over "123456789"), bit by bit.
fn crc16_ccitt_false(bytes: &[u8]) -> u16 {
    let mut crc = 0xFFFFu16;
    for &b in bytes {
        crc ^= u16::from(b) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

#[test]
fn frames_written_ahead_are_taken_at_the_tick_they_are_owed() {
    assert_eq!(crc16_ccitt_false(b"123456789"), 0x29B1);
    let d = dir("lockstep_held");
    let list = d.join("devices.toml");
    std::fs::write(
        &list,
        format!(
            "[[device]]\nname = \"st1\"\ndescription = \"{}\"\nbind = {{ tracker = \"st1\" }}\n\
             endpoint = {{ pty = \"st1.tty\" }}\n",
            scenarios().join("devices/star_tracker.toml").display()
        ),
    )
    .unwrap();
    let (cat, cfg) = catalog();
    let set = DeviceSet::load(&list, cat.catalog()).unwrap();
    let mut gw = Gateway::open(set, cat, &d).unwrap();
    let mut driver = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(d.join("st1.tty"))
        .unwrap();
    assert!(gw.absent().is_empty());
    // Two QUATERNION_REQUESTs at once: EB 90 01 01 + CRC, twice.
    let mut request = vec![0xEB, 0x90, 0x01, 0x01];
    request.extend(crc16_ccitt_false(&request).to_be_bytes());
    driver
        .write_all(&[request.clone(), request].concat())
        .unwrap();
    let answers = |gw: &Gateway| gw.report()[0].engine.frames_out;
    gw.tick(&tick(0, &cfg), Pacing::Lockstep).unwrap();
    assert_eq!(answers(&gw), 1, "tick 0 owes one request");
    for k in 1..10 {
        gw.tick(&tick(k, &cfg), Pacing::Lockstep).unwrap();
        assert_eq!(
            answers(&gw),
            1,
            "tick {k} owes nothing: the second request waits"
        );
    }
    gw.tick(&tick(10, &cfg), Pacing::Lockstep).unwrap();
    assert_eq!(answers(&gw), 2);
    let r = &gw.report()[0];
    assert_eq!((r.late_ticks, r.missing_inputs, r.late_outputs), (0, 0, 0));
    // Both answers reached the driver: 2 × 33 octets.
    let mut got = vec![0u8; 66];
    driver.read_exact(&mut got).unwrap();
    assert_eq!((got[0], got[1], got[2], got[3]), (0xEB, 0x90, 28, 0x81));
}

#[test]
fn two_messages_due_at_one_tick_go_as_two_datagrams() {
    let d = dir("lockstep_udp");
    let driver = UdpSocket::bind("127.0.0.1:0").unwrap();
    driver
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    // A description with two periodic messages of 2 and 3 octets (id + a counter), COBS.
    let description = d.join("two.toml");
    std::fs::write(
        &description,
        "[framing]\nkind = \"cobs\"\n[id]\ntype = \"u8\"\n\
         [[message]]\nname = \"a\"\ndirection = \"out\"\nid = 1\nevery_s = 0.01\n\
         [[message.field]]\nname = \"n\"\ntype = \"u8\"\nsource = \"counter\"\n\
         [[message]]\nname = \"b\"\ndirection = \"out\"\nid = 2\nevery_s = 0.01\n\
         [[message.field]]\nname = \"n\"\ntype = \"u16\"\nsource = \"counter\"\n",
    )
    .unwrap();
    let list = d.join("devices.toml");
    std::fs::write(
        &list,
        format!(
            "[[device]]\nname = \"two\"\ndescription = \"two.toml\"\n\
             endpoint = {{ udp_local = \"127.0.0.1:0\", udp_remote = \"{}\" }}\n",
            driver.local_addr().unwrap()
        ),
    )
    .unwrap();
    let (cat, cfg) = catalog();
    let set = DeviceSet::load(&list, cat.catalog()).unwrap();
    let mut gw = Gateway::open(set, cat, &d).unwrap();
    gw.tick(&tick(0, &cfg), Pacing::Lockstep).unwrap();
    let mut buf = [0u8; 64];
    // COBS of 01 00 (id 1, counter 0): 02 01 01, then the 00 delimiter: 4 octets; of 02 00 00:
    // 02 02 01 01 00: 5 octets.
    let n = driver.recv(&mut buf).unwrap();
    assert_eq!(&buf[..n], &[0x02, 0x01, 0x01, 0x00]);
    let n = driver.recv(&mut buf).unwrap();
    assert_eq!(&buf[..n], &[0x02, 0x02, 0x01, 0x01, 0x00]);
    assert_eq!(gw.report()[0].line.frames_sent, 2);
}
