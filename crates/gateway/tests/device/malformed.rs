//! Malformed input from a driver is counted exactly, by reason, and never applied; the
//! outcome does not depend on how the input is chunked.

use super::{
    catalog, crc16_kermit, shipped, slip_frame, tick_time, tracker_frame, values, wheel_frame,
};
use crate::prng::SplitMix64;
use flexdyn_gateway::device::{Catalog, Device, DeviceCounters};

/// The wheel's hostile stream, each piece with the reason it is refused.
fn hostile_wheel_stream() -> Vec<u8> {
    let mut s = Vec::new();
    // A good torque command: +10 mN m (applied).
    s.extend(wheel_frame(&[0x10, 0xE8, 0x03]));
    // +50 mN m with its CRC's low octet flipped: bad checksum.
    let mut content = vec![0x10, 0x88, 0x13];
    let crc = crc16_kermit(&content) ^ 0x0001;
    content.extend_from_slice(&crc.to_le_bytes());
    s.extend(slip_frame(&content));
    // Id 0x55, no such message: unknown id.
    s.extend(wheel_frame(&[0x55, 0x00]));
    // Id 0xA0 is the drive's own speed report: not a request it takes (sent without its
    // fields: the full report is longer than any command, so the decoder would drop it as
    // oversize before its id is read).
    s.extend(wheel_frame(&[0xA0]));
    // A torque command one octet too long: bad length.
    s.extend(wheel_frame(&[0x10, 0x88, 0x13, 0x00]));
    // A speed command of NaN (f32 0x7FC00000): bad value.
    s.extend(wheel_frame(&[0x11, 0x00, 0x00, 0xC0, 0x7F]));
    // ESC followed by an octet that may not follow it: bad escape.
    s.extend_from_slice(&[0xC0, 0x10, 0xDB, 0x41, 0x00, 0xC0]);
    // One octet, shorter than the CRC: a bad length at the framing.
    s.extend_from_slice(&[0xC0, 0x01, 0xC0]);
    // 50 octets: above the longest command (5) and its CRC (2): oversize.
    s.push(0xC0);
    s.extend_from_slice(&[0x11; 50]);
    s.push(0xC0);
    s
}

fn expected_wheel_counters() -> DeviceCounters {
    let mut c = DeviceCounters {
        frames_in: vec![1, 0, 0, 0],
        unknown_id: 1,
        unknown_request: 1,
        bad_length: 1,
        bad_value: 1,
        ..DeviceCounters::default()
    };
    // Frames the SLIP decoder delimited: every clean one (the good, bad-CRC, unknown-id,
    // own-message, too-long, NaN and one-octet frames); the bad escape and the oversize frame
    // are rejected inside it.
    c.framing.frames = 7;
    c.framing.bad_checksum = 1;
    c.framing.bad_length = 1;
    c.framing.bad_escape = 1;
    c.framing.oversize = 1;
    c
}

/// Feeds `stream` in chunks of the lengths `chunks` draws; returns out, commands, counters.
fn run(
    device: &mut Device,
    catalog: &Catalog,
    stream: &[u8],
    mut chunk: impl FnMut() -> usize,
) -> (Vec<u8>, Vec<f64>, DeviceCounters) {
    let v = values(catalog, &[("wheel.rw1.speed_rad_s", 100.0)]);
    let mut commands = vec![0.0; catalog.input_count()];
    let mut out = Vec::new();
    let mut rest = stream;
    while !rest.is_empty() {
        let n = chunk().clamp(1, rest.len());
        let (head, tail) = rest.split_at(n);
        device.take_bytes(head, &tick_time(0), &v, &mut commands, &mut out);
        rest = tail;
    }
    device.drive(&tick_time(0), &v, &mut commands);
    (out, commands, device.counters().clone())
}

#[test]
fn hostile_wheel_input_is_counted_by_reason_and_never_applied() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    let rw1 = devices.get_mut("rw1").unwrap();
    let (out, commands, counters) = run(rw1, &cat, &hostile_wheel_stream(), || usize::MAX);
    assert_eq!(counters, expected_wheel_counters());
    assert_eq!(counters.rejected_frames(), 8);
    // Only the good command is applied; the NaN speed command did not start the speed loop.
    assert!((commands[0] - 0.01).abs() < 1e-15, "{commands:?}");
    assert!(commands[1..].iter().all(|&c| c == 0.0), "{commands:?}");
    assert!(out.is_empty());
}

#[test]
fn hostile_tracker_input_is_counted_by_reason() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    let st1 = devices.get_mut("st1").unwrap();
    let request = tracker_frame(&[0x01]);
    let mut corrupted = request.clone();
    corrupted[5] ^= 0x01;
    // The count below assumes no CRC octet is the first sync octet.
    assert!(request[4] != 0xEB && corrupted[5] != 0xEB);
    let mut stream = b"xyz".to_vec(); // 3 garbage octets
    stream.extend(&request); // answered
    stream.extend([0xEB, 0x90, 0xFF]); // LEN 255: oversize; then 90 FF are garbage
    stream.extend(&corrupted); // bad CRC; then its 5 octets after EB are garbage
    stream.extend(&request); // answered
    let v = values(&cat, &[("star_tracker.st1.valid", 1.0)]);
    let mut commands = vec![0.0; cat.input_count()];
    let mut out = Vec::new();
    st1.take_bytes(&stream, &tick_time(0), &v, &mut commands, &mut out);
    let c = st1.counters();
    assert_eq!(c.frames_in, vec![2, 0]);
    assert_eq!(c.frames_out, 2);
    assert_eq!(c.framing.garbage_bytes, 3 + 2 + 5);
    assert_eq!(c.framing.oversize, 1);
    assert_eq!(c.framing.bad_checksum, 1);
    assert_eq!(c.rejected_frames(), 2);
    assert_eq!(out.len(), 2 * 33);
}

#[test]
fn take_bytes_does_not_depend_on_chunking() {
    let cat = catalog();
    let mut stream = hostile_wheel_stream();
    stream.extend(wheel_frame(&[0x20])); // a speed request: answered
    stream.extend(wheel_frame(&[0x11, 0x00, 0x00, 0x7A, 0x44])); // speed mode
    stream.extend(&stream.clone());
    let whole = run(shipped(&cat).get_mut("rw1").unwrap(), &cat, &stream, || {
        usize::MAX
    });
    let bytewise = run(shipped(&cat).get_mut("rw1").unwrap(), &cat, &stream, || 1);
    assert_eq!(whole, bytewise);
    for seed in 0..20 {
        let mut rng = SplitMix64::new(seed);
        let random = run(shipped(&cat).get_mut("rw1").unwrap(), &cat, &stream, || {
            1 + rng.below(9)
        });
        assert_eq!(whole, random, "seed {seed}");
    }
    // The speed requests were answered, the loop is in speed mode.
    assert_eq!(whole.2.frames_out, 2);
    assert_eq!(whole.2.frames_in, vec![2, 2, 2, 0]);
    assert!(whole.1[0] > 0.0 && whole.1[0] <= 0.2);
}
