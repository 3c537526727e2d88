//! Encode → decode: a device's out-message read back by a mirror device whose in-message has
//! the same fields, over each framing, gives the values back within each field's resolution.

use std::f64::consts::PI;
use std::path::Path;

use super::tick_time;
use crate::prng::SplitMix64;
use flexdyn_gateway::device::{Catalog, DeviceSet};

/// (type, scale, offset, unit, lowest and highest SI value drawn [rad/s]).
const FIELDS: [(&str, f64, f64, &str, f64, f64); 10] = [
    ("u8", 0.5, -10.0, "deg/s", -0.17, 2.0),
    ("u16", 0.01, 0.0, "deg/s", 0.0, 11.0),
    ("u32", 1e-6, 0.0, "rad/s", 0.0, 4000.0),
    ("u64", 1e-9, 0.0, "rad/s", 0.0, 1e6),
    ("i8", 1.0, 0.0, "rpm", -13.0, 13.0),
    ("i16", 0.1, 0.0, "deg/s", -57.0, 57.0),
    ("i32", 1e-5, 0.0, "rad/s", -21000.0, 21000.0),
    ("i64", 1e-12, 0.0, "rad/s", -1e6, 1e6),
    ("f32", 1.0, 0.0, "deg/s", -1e3, 1e3),
    ("f64", 0.5, 3.0, "rad/s", -1e9, 1e9),
];

fn catalog() -> Catalog {
    let mut c = Catalog::new(super::FRAME_NS);
    let names: Vec<String> = (0..FIELDS.len()).map(|i| format!("x{i}")).collect();
    let fields: Vec<(&str, &str)> = names.iter().map(|n| (n.as_str(), "rad/s")).collect();
    c.add_group("sensor.a", &fields);
    for i in 0..FIELDS.len() {
        c.add_input(&format!("act.y{i}"), "rad/s");
    }
    c
}

/// A description of one message, id 7, with every field of [`FIELDS`]: `out` reads the
/// channels, `in` writes the inputs.
fn description(framing: &str, order: &str, direction: &str) -> String {
    let mut d = format!(
        "byte_order = \"{order}\"\n[framing]\n{framing}\n[id]\ntype = \"u16\"\n\
         [[message]]\nname = \"m\"\ndirection = \"{direction}\"\nid = 7\n"
    );
    if direction == "out" {
        d.push_str("every_s = 0.01\n");
    }
    for (i, (ty, scale, offset, unit, _, _)) in FIELDS.iter().enumerate() {
        let end = if direction == "out" {
            format!("source = \"sensor.a.x{i}\"")
        } else {
            format!("dest = \"act.y{i}\"")
        };
        d.push_str(&format!(
            "[[message.field]]\ntype = \"{ty}\"\nscale = {scale:e}\noffset = {offset:e}\nunit = \"{unit}\"\n{end}\n"
        ));
    }
    // A constant in the middle of the payload, checked on the way in.
    d.push_str("[[message.field]]\nconst_bytes = [0xC0, 0x7E, 0x00, 0xDB]\n");
    d
}

fn device(catalog: &Catalog, description: String) -> flexdyn_gateway::device::Device {
    let list = "[[device]]\nname = \"d\"\ndescription = \"d.toml\"\nendpoint = { tcp_server = \"127.0.0.1:0\" }\n";
    let mut set = DeviceSet::from_str(
        list,
        Path::new("l.toml"),
        |_| Ok(description.clone()),
        catalog,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    set.devices.remove(0)
}

/// [rad/s] the resolution of field `i`: half a raw count in SI.
fn tolerance(i: usize, value: f64) -> f64 {
    let (ty, scale, _, unit, _, _) = FIELDS[i];
    let to_si = match unit {
        "deg/s" => PI / 180.0,
        "rpm" => 2.0 * PI / 60.0,
        _ => 1.0,
    };
    match ty {
        "f32" => value.abs() * 1e-7 + 1e-30,
        "f64" => value.abs() * 1e-15 + 1e-300,
        // Half a count, and the f64 rounding of the scaling itself.
        _ => 0.5 * scale * to_si * (1.0 + 1e-9) + value.abs() * 1e-15,
    }
}

#[test]
fn every_field_type_round_trips_over_every_framing() {
    let framings = [
        "kind = \"sync_length\"\nsync = [0x55, 0xAA]\nheader = [0x01]\nlength = { offset = 3, size = 2, counts = \"frame\", adjust = 0 }\nchecksum = \"CRC-32\"",
        "kind = \"sync_length\"\nsync = [0x1A]\nlength = { offset = 1, size = 1, counts = \"after_field\", adjust = 1 }\nchecksum = \"fletcher16\"\nchecksum_from = 1",
        "kind = \"slip\"\nchecksum = \"xor8\"",
        "kind = \"cobs\"\nchecksum = \"CRC-32C\"",
        "kind = \"hdlc\"\nchecksum = \"CRC-16/X-25\"",
        "kind = \"hdlc\"",
    ];
    let cat = catalog();
    let mut rng = SplitMix64::new(38);
    for framing in framings {
        for order in ["big", "little"] {
            let mut sender = device(&cat, description(framing, order, "out"));
            let mut receiver = device(&cat, description(framing, order, "in"));
            for trial in 0..50 {
                let values: Vec<f64> = FIELDS
                    .iter()
                    .map(|&(_, _, _, _, lo, hi)| {
                        lo + (hi - lo) * (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
                    })
                    .collect();
                let mut wire = Vec::new();
                let fresh = [true];
                assert_eq!(
                    sender.emit_due(&tick_time(trial), &values, &fresh, &mut wire),
                    1
                );
                let mut commands = vec![f64::NAN; FIELDS.len()];
                let mut out = Vec::new();
                let taken =
                    receiver.take_bytes(&wire, &tick_time(trial), &values, &mut commands, &mut out);
                assert_eq!(
                    taken.frames_accepted,
                    1,
                    "{framing} {order}: {:?}",
                    receiver.counters()
                );
                for (i, (&sent, &got)) in values.iter().zip(&commands).enumerate() {
                    assert!(
                        (sent - got).abs() <= tolerance(i, sent),
                        "{framing} {order} field {i} ({}): sent {sent}, got {got}",
                        FIELDS[i].0
                    );
                }
            }
            assert_eq!(sender.counters().clamped, 0);
            assert_eq!(receiver.counters().rejected_frames(), 0);
        }
    }
}

#[test]
fn a_ccsds_telecommand_is_read_by_its_apid() {
    let mut cat = Catalog::new(super::FRAME_NS);
    let dipole = cat.add_input("magnetorquer.mtq1.dipole_am2", "A m^2");
    let description = "[framing]\nkind = \"ccsds\"\nchecksum = \"CRC-16/CCITT-FALSE\"\n\
        [[message]]\nname = \"dipole\"\ndirection = \"in\"\napid = 0x055\n\
        [[message.field]]\ntype = \"i16\"\nunit = \"mA m^2\"\ndest = \"magnetorquer.mtq1.dipole_am2\"\n";
    let mut d = device(&cat, description.to_owned());
    // Telecommand (type 1), no secondary header, APID 0x055: 0x1055; unsegmented, count 0:
    // 0xC000; data length 2 + 2 − 1 = 3. Field −1500 mA m² = 0xFA24; CRC over the 8 octets.
    let mut packet = vec![0x10, 0x55, 0xC0, 0x00, 0x00, 0x03, 0xFA, 0x24];
    packet.extend_from_slice(&super::crc16_ccitt_false(&packet).to_be_bytes());
    let mut commands = [0.0];
    let mut out = Vec::new();
    let taken = d.take_bytes(&packet, &tick_time(0), &[], &mut commands, &mut out);
    assert_eq!(taken.frames_accepted, 1, "{:?}", d.counters());
    assert!((commands[dipole] + 1.5).abs() < 1e-12);
    // Another APID: unknown. A telemetry packet (type 0): a constant that differs.
    let mut other = vec![0x10, 0x56, 0xC0, 0x01, 0x00, 0x03, 0x00, 0x01];
    other.extend_from_slice(&super::crc16_ccitt_false(&other).to_be_bytes());
    let mut telemetry = vec![0x00, 0x55, 0xC0, 0x02, 0x00, 0x03, 0x00, 0x01];
    telemetry.extend_from_slice(&super::crc16_ccitt_false(&telemetry).to_be_bytes());
    d.take_bytes(
        &[other, telemetry].concat(),
        &tick_time(0),
        &[],
        &mut commands,
        &mut out,
    );
    assert_eq!(d.counters().unknown_id, 1);
    assert_eq!(d.counters().bad_constant, 1);
    // Garbage (version bits not 000) and a packet whose CRC is off by one bit: counted, the
    // command not applied.
    let mut bad = vec![0x10, 0x55, 0xC0, 0x03, 0x00, 0x03, 0x00, 0x01];
    let crc = super::crc16_ccitt_false(&bad) ^ 0x0100;
    bad.extend_from_slice(&crc.to_be_bytes());
    let mut stream = vec![0xE0, 0xFF, 0x20];
    stream.extend(&bad);
    d.take_bytes(&stream, &tick_time(0), &[], &mut commands, &mut out);
    let framing = d.counters().framing;
    assert_eq!(framing.bad_checksum, 1);
    // With no sync marker the decoder searches the rejected packet's octets for a header: the
    // bad CRC is 0x8729, so after its first octet (0x10) come 55 C0 (version bits 010, 110:
    // garbage), then 03 00 03 00 01 87 and 00 03 00 01 87 29, headers of 398 and 34 608
    // octets (oversize, above the 10 of this device's longest packet), and 03 00 01 87 29,
    // five octets waiting for a sixth.
    assert_eq!(framing.garbage_bytes, 3 + 2);
    assert_eq!(framing.oversize, 2);
    assert!((commands[dipole] + 1.5).abs() < 1e-12);
    assert!(out.is_empty());
}
