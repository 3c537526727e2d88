//! The four shipped descriptions against frames derived by hand from their ICD comments.

use std::f64::consts::PI;

use super::{catalog, crc16_ccitt_false, shipped, tick_time, tracker_frame, values, wheel_frame};
use flexdyn_gateway::device::Catalog;
use flexdyn_gateway::nmea::Sentence;

fn input(catalog: &Catalog, name: &str) -> usize {
    catalog.input_index(name).unwrap()
}

#[test]
fn validate_star_tracker_answers_a_quaternion_request() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    let st1 = devices.get_mut("st1").unwrap();
    let v = values(
        &cat,
        &[
            ("star_tracker.st1.q_cn[0]", 0.5),
            ("star_tracker.st1.q_cn[1]", -0.5),
            ("star_tracker.st1.q_cn[2]", 0.5),
            ("star_tracker.st1.q_cn[3]", 0.5),
            ("star_tracker.st1.valid", 1.0),
            ("star_tracker.st1.status_flags", 3.0),
        ],
    );
    let now = tick_time(12);
    let mut commands = vec![0.0; cat.input_count()];
    let mut out = Vec::new();
    // Request: id 0x01, no field.
    let taken = st1.take_bytes(&tracker_frame(&[0x01]), &now, &v, &mut commands, &mut out);
    assert_eq!((taken.frames_accepted, taken.due_received), (1, 1));
    // Answer, from the ICD: id 0x81; q in units of 2^-30 (0.5 → 2^29 = 0x20000000, −0.5 →
    // 0xE0000000); valid 1; status 3; tick 12 at 100 Hz = 0.12 s = 120 000 µs = 0x1D4C0;
    // counter 0. 28 payload octets: LEN 0x1C.
    let payload = [
        0x81, 0x20, 0, 0, 0, 0xE0, 0, 0, 0, 0x20, 0, 0, 0, 0x20, 0, 0, 0, 0x01, 0x03, 0, 0, 0, 0,
        0, 0x01, 0xD4, 0xC0, 0x00,
    ];
    assert_eq!(out, tracker_frame(&payload));
    // A second answer: the counter moves to 1.
    out.clear();
    st1.take_bytes(&tracker_frame(&[0x01]), &now, &v, &mut commands, &mut out);
    let mut second = payload;
    second[27] = 1;
    assert_eq!(out, tracker_frame(&second));
    // An invalid solution: valid 0 (the flag channel below 0.5).
    let mut invalid = v.clone();
    invalid[cat.channel_index("star_tracker.st1.valid").unwrap()] = 0.0;
    out.clear();
    st1.take_bytes(
        &tracker_frame(&[0x01]),
        &now,
        &invalid,
        &mut commands,
        &mut out,
    );
    assert_eq!(out[3 + 17], 0);
    assert_eq!(st1.counters().frames_out, 3);
    assert_eq!(st1.counters().frames_in, vec![3, 0]);
    // It sends nothing on its own.
    out.clear();
    assert_eq!(st1.emit_due(&now, &v, &[true; 16], &mut out), 0);
    assert!(out.is_empty());
    assert!(commands.iter().all(|&c| c == 0.0));
}

#[test]
fn validate_reaction_wheel_torque_command_and_speed_answer() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    let rw1 = devices.get_mut("rw1").unwrap();
    let v = values(&cat, &[("wheel.rw1.speed_rad_s", 100.0)]);
    let now = tick_time(0);
    let mut commands = vec![0.0; cat.input_count()];
    let mut out = Vec::new();
    // +10 mN m in units of 0.01 mN m: raw 1000 = 0x03E8, little-endian E8 03.
    rw1.take_bytes(
        &wheel_frame(&[0x10, 0xE8, 0x03]),
        &now,
        &v,
        &mut commands,
        &mut out,
    );
    let torque = commands[input(&cat, "wheel.rw1.torque_nm")];
    assert!((torque - 0.010).abs() < 1e-15, "{torque}");
    assert!(out.is_empty());
    // Speed request → speed report: 100 rad/s = 100 · 60 / 2π rpm as f32, little-endian, then
    // the counter 0 as u16.
    rw1.take_bytes(&wheel_frame(&[0x20]), &now, &v, &mut commands, &mut out);
    let rpm = (100.0 * 60.0 / (2.0 * PI)) as f32;
    let mut payload = vec![0xA0];
    payload.extend_from_slice(&rpm.to_le_bytes());
    payload.extend_from_slice(&[0, 0]);
    assert_eq!(out, wheel_frame(&payload));
    // +300 mN m (raw 30000) is above the declared 200 mN m: clamped to 0.2 N m, counted.
    rw1.take_bytes(
        &wheel_frame(&[0x10, 0x30, 0x75]),
        &now,
        &v,
        &mut commands,
        &mut out,
    );
    assert_eq!(commands[input(&cat, "wheel.rw1.torque_nm")], 0.2);
    assert_eq!(rw1.counters().clamped, 1);
    // The other wheels' inputs are untouched.
    assert_eq!(commands[input(&cat, "wheel.rw2.torque_nm")], 0.0);
}

#[test]
fn validate_speed_loop_closed_form() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    let rw3 = devices.get_mut("rw3").unwrap();
    let speed = cat.channel_index("wheel.rw3.speed_rad_s").unwrap();
    let torque = input(&cat, "wheel.rw3.torque_nm");
    let now = tick_time(0);
    let mut commands = vec![0.0; cat.input_count()];
    let mut out = Vec::new();
    // Speed command 1000 rpm (f32 0x447A0000, little-endian).
    let v = values(&cat, &[]);
    rw3.take_bytes(
        &wheel_frame(&[0x11, 0x00, 0x00, 0x7A, 0x44]),
        &now,
        &v,
        &mut commands,
        &mut out,
    );
    let setpoint = 1000.0 * 2.0 * PI / 60.0;
    // torque = clamp(0.02 · (setpoint − ω), ±0.2): inside the limit, and saturated both ways.
    for (omega, expected) in [
        (100.0, 0.02 * (setpoint - 100.0)),
        (50.0, 0.2),
        (300.0, -0.2),
        (setpoint, 0.0),
    ] {
        let mut v = values(&cat, &[]);
        v[speed] = omega;
        rw3.drive(&now, &v, &mut commands);
        assert!(
            (commands[torque] - expected).abs() < 1e-12,
            "ω = {omega}: {} vs {expected}",
            commands[torque]
        );
    }
    // A torque command ends speed mode: the loop no longer writes the input.
    rw3.take_bytes(
        &wheel_frame(&[0x10, 0x00, 0x00]),
        &now,
        &v,
        &mut commands,
        &mut out,
    );
    let mut v = values(&cat, &[]);
    v[speed] = 50.0;
    rw3.drive(&now, &v, &mut commands);
    assert_eq!(commands[torque], 0.0);
}

#[test]
fn validate_magnetometer_space_packet_with_cuc_time() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    let mag1 = devices.get_mut("mag1").unwrap();
    let v = values(
        &cat,
        &[
            ("magnetometer.mag1.b_s_t[0]", 1e-5),
            ("magnetometer.mag1.b_s_t[1]", -2e-5),
            ("magnetometer.mag1.b_s_t[2]", 3.5e-5),
        ],
    );
    let group = cat.group_index("magnetometer.mag1").unwrap();
    let mut fresh = vec![false; cat.group_count()];
    let now = tick_time(3);
    let mut out = Vec::new();
    // Not fresh: nothing.
    assert_eq!(mag1.emit_due(&now, &v, &fresh, &mut out), 0);
    fresh[group] = true;
    assert_eq!(mag1.emit_due(&now, &v, &fresh, &mut out), 1);
    // From the ICD. Primary header: 000 0 1 00100100000 → 0x0920; 11 + count 0 → 0xC000;
    // data length 6 + 13 + 2 − 1 = 20 = 0x0014. CUC: 2 000 000 000 s = 0x77359400, then
    // 0.03 s · 65536 = 1966.08 → 1966 = 0x07AE. Fields in 0.1 nT: 1e-5 T = 10 000 nT → 100 000
    // = 0x000186A0; −200 000 = 0xFFFCF2C0; 350 000 = 0x00055730; flags 0.
    let mut expected = vec![
        0x09, 0x20, 0xC0, 0x00, 0x00, 0x14, 0x77, 0x35, 0x94, 0x00, 0x07, 0xAE, 0x00, 0x01, 0x86,
        0xA0, 0xFF, 0xFC, 0xF2, 0xC0, 0x00, 0x05, 0x57, 0x30, 0x00,
    ];
    let crc = crc16_ccitt_false(&expected);
    expected.extend_from_slice(&crc.to_be_bytes());
    assert_eq!(out, expected);
    // The next packet: sequence count 1.
    out.clear();
    mag1.emit_due(&now, &v, &fresh, &mut out);
    assert_eq!(&out[2..4], &[0xC0, 0x01]);
    // Without an epoch there is no TAI: nothing sent, counted.
    out.clear();
    let mut no_epoch = now;
    no_epoch.has_epoch = false;
    assert_eq!(mag1.emit_due(&no_epoch, &v, &fresh, &mut out), 0);
    assert!(out.is_empty());
    assert_eq!(mag1.counters().unsendable, 1);
    assert_eq!(mag1.counters().frames_out, 2);
}

/// `$body*hh\r\n`, hh the XOR of body's characters (NMEA 0183).
fn sentence(body: &str) -> String {
    let x = body.bytes().fold(0u8, |a, b| a ^ b);
    format!("${body}*{x:02X}\r\n")
}

#[test]
fn validate_gps_nmea_sentences_at_one_hertz() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    let gps1 = devices.get_mut("gps1").unwrap();
    // On the equator at the prime meridian, on the ellipsoid, moving north at 7 km/s.
    let v = values(
        &cat,
        &[
            ("gps.gps1.r_be_e_m[0]", 6_378_137.0),
            ("gps.gps1.v_be_e_m_s[2]", 7000.0),
            ("gps.gps1.valid", 1.0),
        ],
    );
    // Sentences go with the receiver's solutions: when its group publishes.
    let mut fresh = vec![false; cat.group_count()];
    let mut out = Vec::new();
    assert_eq!(gps1.emit_due(&tick_time(0), &v, &fresh, &mut out), 0);
    fresh[cat.group_index("gps.gps1").unwrap()] = true;
    assert_eq!(gps1.emit_due(&tick_time(0), &v, &fresh, &mut out), 3);
    // No GPS week in the solution: stamped with the tick's UTC.
    // 7000 m/s = 7000 · 3600 / 1852 kn = 13 606.91 kn; course north = 0°; 2026-11-30 12:00:00.
    let expected = [
        sentence("GPGGA,120000.00,0000.0000,N,00000.0000,E,1,08,1.0,0.0,M,0.0,M,,"),
        sentence("GPRMC,120000.00,A,0000.0000,N,00000.0000,E,13606.9,0.0,301126,,,A"),
        sentence("GPZDA,120000.00,30,11,2026,,"),
    ]
    .concat();
    assert_eq!(String::from_utf8(out.clone()).unwrap(), expected);
    // The crate's reader accepts each (envelope, checksum, field count).
    for line in expected.split_inclusive("\r\n") {
        Sentence::parse(line).unwrap().expect_fields().unwrap();
    }
    // Not again within every_s = 1 s (100 ticks), even on a fresh solution; due at tick 100.
    out.clear();
    for tick in 1..100 {
        assert_eq!(gps1.emit_due(&tick_time(tick), &v, &fresh, &mut out), 0);
    }
    assert_eq!(gps1.emit_due(&tick_time(100), &v, &fresh, &mut out), 3);
    // A solution with its GPS time is stamped with it, in UTC: week 2447, 129 617.8 s is
    // 2026-11-30 12:00:17.8 GPS (days from 1980-01-06 = 7 · 2447 + 1, 129 617.8 s = 1 d
    // 12 h 0 min 17.8 s), and GPS − UTC = 18 s since 2017: 11:59:59.80 UTC.
    out.clear();
    let mut timed = v.clone();
    timed[cat.channel_index("gps.gps1.gps_week").unwrap()] = 2447.0;
    timed[cat.channel_index("gps.gps1.gps_seconds_of_week").unwrap()] = 129_617.8;
    assert_eq!(gps1.emit_due(&tick_time(200), &timed, &fresh, &mut out), 3);
    let text = String::from_utf8(out.clone()).unwrap();
    assert!(text.starts_with("$GPGGA,115959.80,"), "{text}");
    assert!(text.contains("$GPZDA,115959.80,30,11,2026,,"), "{text}");
    // An invalid solution: fix quality 0, status V, mode N.
    out.clear();
    let mut invalid = v.clone();
    invalid[cat.channel_index("gps.gps1.valid").unwrap()] = 0.0;
    gps1.emit_due(&tick_time(300), &invalid, &fresh, &mut out);
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains(",E,0,08,"), "{text}");
    assert!(text.contains("120003.00,V,"), "{text}");
    assert!(text.contains(",N*"), "{text}");
}

#[test]
fn shipped_devices_declare_lockstep_inputs_latency_and_room() {
    let cat = catalog();
    let devices = shipped(&cat);
    assert_eq!(devices.len(), 8);
    let st1 = &devices["st1"];
    // due_every_s = 0.1 at 100 Hz: every 10 ticks from tick 0.
    assert_eq!(
        (0..=20).map(|t| st1.inputs_due(t)).collect::<Vec<_>>(),
        (0..=20).map(|t| u32::from(t % 10 == 0)).collect::<Vec<_>>()
    );
    assert_eq!(st1.timeout(), std::time::Duration::from_millis(500));
    assert_eq!(st1.latency_ns(), 2_000_000);
    assert_eq!(devices["gps1"].inputs_due(0), 0);
    assert_eq!(devices["rw2"].inputs_due(30), 1);
    // The star tracker's answer is 33 octets (2 sync + 1 LEN + 28 + 2 CRC); a 4096-octet read
    // holds at most 1 + 4096/6 requests of 6 octets.
    assert_eq!(st1.max_output_len(), (1 + 4096 / 6) * 33);
    assert!(devices["gps1"].max_output_len() >= 3 * 82);
}

#[test]
fn validate_gga_position_of_the_classic_example() {
    // The textbook GGA (NMEA Revealed; DePriest): 4807.038,N 01131.000,E, 545.4 m. The ECEF
    // position comes from the closed-form forward map (NIMA TR8350.2 eq. 4-14), independent
    // of the receiver's inverse (Bowring's iteration).
    use flexdyn_environment::geodetic::{ecef_from_geodetic, Geodetic};
    let r = ecef_from_geodetic(&Geodetic {
        lat_rad: (48.0 + 7.038 / 60.0_f64).to_radians(),
        lon_rad: (11.0 + 31.0 / 60.0_f64).to_radians(),
        height_m: 545.4,
    });
    let cat = catalog();
    let mut devices = shipped(&cat);
    let gps1 = devices.get_mut("gps1").unwrap();
    let v = values(
        &cat,
        &[
            ("gps.gps1.r_be_e_m[0]", r.x),
            ("gps.gps1.r_be_e_m[1]", r.y),
            ("gps.gps1.r_be_e_m[2]", r.z),
            ("gps.gps1.valid", 1.0),
        ],
    );
    let mut fresh = vec![false; cat.group_count()];
    fresh[cat.group_index("gps.gps1").unwrap()] = true;
    let mut out = Vec::new();
    gps1.emit_due(&tick_time(0), &v, &fresh, &mut out);
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.starts_with("$GPGGA,120000.00,4807.0380,N,01131.0000,E,1,08,1.0,545.4,M,0.0,M,,*"),
        "{text}"
    );
}

#[test]
fn the_answer_counter_wraps_at_its_fields_width() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    let st1 = devices.get_mut("st1").unwrap();
    let v = values(&cat, &[]);
    let mut commands = vec![0.0; cat.input_count()];
    let mut out = Vec::new();
    // 258 answers: counters 0, 1, …, 255, 0, 1 (a u8 field).
    for _ in 0..258 {
        out.clear();
        st1.take_bytes(
            &tracker_frame(&[0x01]),
            &tick_time(0),
            &v,
            &mut commands,
            &mut out,
        );
    }
    assert_eq!(out[3 + 27], 1);
}

#[test]
fn each_frame_of_a_call_is_delimited_for_datagram_endpoints() {
    let cat = catalog();
    let mut devices = shipped(&cat);
    // Two speed requests in one read: two answers (SLIP: END, 7 payload octets + 2 CRC with
    // no octet to escape at speed 0, END = 11 octets each), each its own frame.
    let rw1 = devices.get_mut("rw1").unwrap();
    let mut input = wheel_frame(&[0x20]);
    input.extend(wheel_frame(&[0x20]));
    let v = values(&cat, &[]);
    let mut commands = vec![0.0; cat.input_count()];
    let mut out = Vec::new();
    rw1.take_bytes(&input, &tick_time(0), &v, &mut commands, &mut out);
    let ends = rw1.frame_ends().to_vec();
    assert_eq!(ends.len(), 2);
    assert_eq!(*ends.last().unwrap(), out.len());
    let first = &out[..ends[0]];
    let second = &out[ends[0]..ends[1]];
    for f in [first, second] {
        assert_eq!((f[0], f[f.len() - 1]), (0xC0, 0xC0), "{f:02X?}");
    }
    // The GPS receiver: GGA, RMC and ZDA, each ending in CR LF.
    let gps1 = devices.get_mut("gps1").unwrap();
    let mut fresh = vec![false; cat.group_count()];
    fresh[cat.group_index("gps.gps1").unwrap()] = true;
    let v = values(
        &cat,
        &[
            ("gps.gps1.r_be_e_m[0]", 6_378_137.0),
            ("gps.gps1.valid", 1.0),
        ],
    );
    out.clear();
    assert_eq!(gps1.emit_due(&tick_time(0), &v, &fresh, &mut out), 3);
    let ends = gps1.frame_ends().to_vec();
    assert_eq!(ends.len(), 3);
    let mut start = 0;
    for (end, kind) in ends.iter().zip(["GGA", "RMC", "ZDA"]) {
        let s = std::str::from_utf8(&out[start..*end]).unwrap();
        assert!(
            s.starts_with(&format!("$GP{kind},")) && s.ends_with("\r\n"),
            "{s}"
        );
        start = *end;
    }
}
