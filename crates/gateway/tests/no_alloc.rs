//! After construction, the decoders allocate and free nothing: a stream of good, corrupted,
//! truncated and oversize frames and garbage is fed, whole and byte by byte, inside
//! `assert_no_alloc`, whose global allocator counts every (de)allocation made on this thread
//! there (features `warn_debug`/`warn_release`: count and warn, don't abort). Nor do the NMEA
//! writers, into a buffer with room for the sentence. Nor do the shipped devices' `emit_due`,
//! `take_bytes` and `drive`, into an output buffer of `max_output_len` octets.

use assert_no_alloc::{assert_no_alloc, reset_violation_count, violation_count, AllocDisabler};
use flexdyn_gateway::checksum::presets::{CRC16_IBM_SDLC, CRC32C};
use flexdyn_gateway::checksum::{Checksum, Crc};
use flexdyn_gateway::device::{DeviceSet, TickTime, Utc, MAX_READ_CHUNK};
use flexdyn_gateway::framing::cobs::{self, CobsDecoder};
use flexdyn_gateway::framing::hdlc::{HdlcDecoder, HdlcFraming};
use flexdyn_gateway::framing::length::{
    LengthCounts, LengthDecoder, LengthField, LengthFraming, LengthFramingConfig,
};
use flexdyn_gateway::framing::lines::{self, LineDecoder, LineEnding};
use flexdyn_gateway::framing::slip::{self, SlipDecoder};
use flexdyn_gateway::framing::{FrameCheck, StreamDecoder};
use flexdyn_gateway::nmea::{Dgps, FixQuality, Gga, LocalZone, Mode, NmeaStyle, Rmc, Zda};
use flexdyn_gateway::ByteOrder;
use hifitime::Epoch;

mod support;

#[global_allocator]
static ALLOC: AllocDisabler = AllocDisabler;

fn crc(params: flexdyn_gateway::checksum::CrcParams) -> Checksum {
    Checksum::Crc(Box::new(Crc::new(params).unwrap()))
}

/// Encoded frames of payloads 1 to 60 octets, every fifth corrupted in its middle, every
/// seventh cut short, with garbage and an oversize frame between.
fn hostile_stream(encode: &dyn Fn(&[u8], &mut Vec<u8>)) -> Vec<u8> {
    let mut stream = Vec::new();
    for n in 1..=60u8 {
        let payload: Vec<u8> = (0..n).map(|i| i.wrapping_mul(37) ^ n).collect();
        let mut frame = Vec::new();
        encode(&payload, &mut frame);
        if n % 5 == 0 {
            let middle = frame.len() / 2;
            frame[middle] ^= 0x40;
        }
        if n % 7 == 0 {
            frame.truncate(frame.len() / 2);
        }
        stream.extend_from_slice(&frame);
        stream.extend_from_slice(&[0x55, 0x13, 0xF0]);
    }
    encode(&[0x42; 200], &mut stream);
    stream
}

/// Feeds `stream` whole and byte by byte without allocating; returns the frames delivered.
fn frames_without_allocating(decoder: &mut dyn StreamDecoder, stream: &[u8]) -> u64 {
    let mut octets = 0usize;
    reset_violation_count();
    assert_no_alloc(|| {
        decoder.feed(stream, &mut |frame| octets += frame.len());
        for byte in stream.chunks(1) {
            decoder.feed(byte, &mut |frame| octets += frame.len());
        }
    });
    assert_eq!(violation_count(), 0, "the decoder allocated while decoding");
    assert!(octets > 0);
    decoder.counters().frames
}

#[test]
fn decoders_do_not_allocate_after_construction() {
    let hdlc = HdlcFraming {
        fcs: Some(FrameCheck {
            checksum: crc(CRC16_IBM_SDLC),
            order: ByteOrder::LittleEndian,
        }),
        accm: 0xFFFF_FFFF,
    };
    let length = LengthFraming::new(LengthFramingConfig {
        sync: vec![0xEB, 0x90],
        length: LengthField {
            offset_bytes: 2,
            width_bytes: 2,
            order: ByteOrder::BigEndian,
            counts: LengthCounts::Payload,
            adjust: 0,
        },
        check: Some(FrameCheck {
            checksum: crc(CRC32C),
            order: ByteOrder::BigEndian,
        }),
        check_from_bytes: 0,
        max_frame_bytes: 72,
    })
    .unwrap();
    let length_encoder = length.clone();
    let cases: Vec<(Box<dyn StreamDecoder>, Vec<u8>)> = vec![
        (
            Box::new(SlipDecoder::new(64)),
            hostile_stream(&slip::encode),
        ),
        (
            Box::new(CobsDecoder::new(64)),
            hostile_stream(&cobs::encode),
        ),
        (
            Box::new(HdlcDecoder::new(&hdlc, 64)),
            hostile_stream(&|p, out| hdlc.encode(p, out)),
        ),
        (
            Box::new(LengthDecoder::new(length)),
            hostile_stream(&|p, out| {
                // The 200-octet frame is above this framing's maximum: sent as garbage.
                if length_encoder.encode(&[], p, out).is_err() {
                    out.extend_from_slice(p);
                }
            }),
        ),
        (
            Box::new(LineDecoder::new(64)),
            hostile_stream(&|p, out| {
                let text: Vec<u8> = p.iter().map(|b| b'A' + b % 26).collect();
                lines::encode(&text, LineEnding::CrLf, out).unwrap();
            }),
        ),
    ];
    for (mut decoder, stream) in cases {
        assert!(frames_without_allocating(&mut *decoder, &stream) > 0);
    }
}

#[test]
fn nmea_writers_do_not_allocate_into_a_buffer_with_room() {
    let style = NmeaStyle::default();
    let time = Epoch::from_gregorian_utc(2026, 11, 30, 12, 0, 0, 123_456_789);
    let gga = Gga {
        time,
        latitude_deg: -33.9,
        longitude_deg: 151.2,
        fix_quality: FixQuality::Differential,
        satellites: 11,
        hdop: 0.8,
        altitude_msl_m: 58.0,
        geoid_separation_m: 22.3,
        dgps: Some(Dgps {
            age_s: 2.0,
            station_id: 17,
        }),
    };
    let rmc = Rmc {
        time,
        valid: true,
        latitude_deg: -33.9,
        longitude_deg: 151.2,
        speed_knots: 7.5,
        course_deg: 270.0,
        magnetic_variation_deg: Some(12.6),
        mode: Some(Mode::Autonomous),
    };
    let zda = Zda {
        time,
        local_zone: Some(LocalZone {
            hours: 10,
            minutes: 0,
        }),
    };
    let mut out = String::with_capacity(1024);
    reset_violation_count();
    assert_no_alloc(|| {
        for _ in 0..10 {
            out.clear();
            gga.write(&style, &mut out).unwrap();
            rmc.write(&style, &mut out).unwrap();
            zda.write(&style, &mut out).unwrap();
        }
    });
    assert_eq!(violation_count(), 0, "an NMEA writer allocated");
    assert_eq!(out.matches("\r\n").count(), 3);
}

#[test]
fn devices_do_not_allocate_after_construction() {
    let catalog = support::catalog();
    let mut set = DeviceSet::load(&support::shipped_list(), &catalog).unwrap();
    let mut values = vec![0.0; catalog.channel_count()];
    values[catalog.channel_index("gps.gps1.r_be_e_m[0]").unwrap()] = 4.0e6;
    values[catalog.channel_index("gps.gps1.r_be_e_m[2]").unwrap()] = 5.0e6;
    values[catalog.channel_index("gps.gps1.v_be_e_m_s[1]").unwrap()] = 7.0e3;
    values[catalog.channel_index("gps.gps1.valid").unwrap()] = 1.0;
    values[catalog.channel_index("star_tracker.st1.q_cn[0]").unwrap()] = 1.0;
    values[catalog.channel_index("magnetometer.mag1.b_s_t[0]").unwrap()] = 2e-5;
    values[catalog.channel_index("wheel.rw1.speed_rad_s").unwrap()] = 100.0;
    let fresh = vec![true; catalog.group_count()];
    // Driver input: star-tracker requests and wheel commands (SLIP, CRC-16/KERMIT) between
    // garbage, in one stream every device reads (each decodes its own framing, counts the rest).
    let mut input = Vec::new();
    let request = [0xEB, 0x90, 0x01, 0x01];
    let crc16_ccitt_false =
        Crc::new(flexdyn_gateway::checksum::presets::CRC16_CCITT_FALSE).unwrap();
    let kermit = Crc::new(flexdyn_gateway::checksum::presets::CRC16_KERMIT).unwrap();
    for n in 0..40u8 {
        input.extend_from_slice(&request);
        input.extend_from_slice(&(crc16_ccitt_false.checksum(&request) as u16).to_be_bytes());
        let speed = [0x11, 0x00, 0x00, 0x7A, 0x44];
        for payload in [&[0x20][..], &speed[..], &[0x10, n, 0x01][..]] {
            let mut content = payload.to_vec();
            content.extend_from_slice(&(kermit.checksum(payload) as u16).to_le_bytes());
            slip::encode(&content, &mut input);
        }
        input.extend_from_slice(&[n, 0xC0, 0x55, 0xDB, 0x00, 0x7E]);
    }
    assert!(input.len() <= MAX_READ_CHUNK);
    let mut commands = vec![0.0; catalog.input_count()];
    for device in &mut set.devices {
        let mut out = Vec::with_capacity(device.max_output_len());
        let mut frames = 0;
        reset_violation_count();
        assert_no_alloc(|| {
            for tick in 0..300u64 {
                let now = TickTime {
                    tick,
                    sim_time_ns: tick * 10_000_000,
                    has_epoch: true,
                    tai_ns_1958: 2_000_000_000_000_000_000 + tick * 10_000_000,
                    utc: Utc {
                        year: 2026,
                        month: 11,
                        day: 30,
                        hour: 23,
                        minute: 59,
                        second: 58 + (tick / 100) as u8,
                        nanosecond: (tick % 100) as u32 * 10_000_000,
                    },
                    gps_week: 2447,
                    gps_ns_of_week: tick * 10_000_000,
                    met_ns: tick * 10_000_000,
                };
                out.clear();
                frames += device.emit_due(&now, &values, &fresh, &mut out);
                out.clear();
                let chunk = &input[(tick as usize * 37) % input.len()..];
                let taken = device.take_bytes(chunk, &now, &values, &mut commands, &mut out);
                frames += taken.frames_accepted as usize;
                device.drive(&now, &values, &mut commands);
            }
        });
        assert_eq!(violation_count(), 0, "device {} allocated", device.name());
        assert!(frames > 0, "device {} did nothing", device.name());
    }
}
