//! CCSDS Space Packet primary headers (CCSDS 133.0-B-2 §4.1) and CUC time codes (CCSDS
//! 301.0-B-4 §3.2). Expected octets are derived bit by bit in the comments from the field
//! layouts the standards give.

use flexdyn_gateway::ccsds::{
    Apid, CcsdsError, CucEpoch, CucFormat, CucTime, PacketTemplate, PacketType, PrimaryHeader,
    SequenceCount, SequenceCounter, SequenceFlags,
};

/// Telemetry, secondary header, APID 0x123, unsegmented, count 5, 10-octet data field:
/// - octets 0–1: version 000, type 0, flag 1, APID 001 0010 0011
///   → 000 0 1 00100100011 = 0000 1001 0010 0011 = 0x09 0x23;
/// - octets 2–3: flags 11, count 00 0000 0000 0101 → 1100 0000 0000 0101 = 0xC0 0x05;
/// - octets 4–5: data length 10 − 1 = 9 → 0x00 0x09.
#[test]
fn a_telemetry_header_has_the_hand_derived_octets() {
    let header = PrimaryHeader {
        packet_type: PacketType::Telemetry,
        secondary_header: true,
        apid: Apid::new(0x123).unwrap(),
        sequence_flags: SequenceFlags::Unsegmented,
        sequence_count: SequenceCount::new(5).unwrap(),
        data_length: 9,
    };
    assert_eq!(header.encode(), [0x09, 0x23, 0xC0, 0x05, 0x00, 0x09]);
    assert_eq!(header.data_field_len(), 10);
    assert_eq!(header.packet_len(), 16);
    assert_eq!(PrimaryHeader::decode(&header.encode()).unwrap(), header);
}

/// Telecommand, no secondary header, APID 2047, first segment, count 16383, 1-octet data field:
/// - octets 0–1: 000 1 0 11111111111 = 0001 0111 1111 1111 = 0x17 0xFF;
/// - octets 2–3: 01 11111111111111 = 0111 1111 1111 1111 = 0x7F 0xFF;
/// - octets 4–5: 1 − 1 = 0 → 0x00 0x00.
#[test]
fn a_telecommand_header_with_every_field_at_its_maximum() {
    let header = PrimaryHeader {
        packet_type: PacketType::Telecommand,
        secondary_header: false,
        apid: Apid::IDLE,
        sequence_flags: SequenceFlags::First,
        sequence_count: SequenceCount::new(16383).unwrap(),
        data_length: 0,
    };
    assert_eq!(header.encode(), [0x17, 0xFF, 0x7F, 0xFF, 0x00, 0x00]);
    assert_eq!(PrimaryHeader::decode(&header.encode()).unwrap(), header);
}

#[test]
fn every_field_combination_round_trips() {
    for (i, flags) in [
        SequenceFlags::Continuation,
        SequenceFlags::First,
        SequenceFlags::Last,
        SequenceFlags::Unsegmented,
    ]
    .into_iter()
    .enumerate()
    {
        for apid in [0, 1, 0x2AA, 0x555, 2047] {
            for count in [0, 1, 0x1555, 0x2AAA, 16383] {
                let header = PrimaryHeader {
                    packet_type: if i % 2 == 0 {
                        PacketType::Telemetry
                    } else {
                        PacketType::Telecommand
                    },
                    secondary_header: apid % 2 == 0,
                    apid: Apid::new(apid).unwrap(),
                    sequence_flags: flags,
                    sequence_count: SequenceCount::new(count).unwrap(),
                    data_length: apid.wrapping_mul(31) ^ count,
                };
                assert_eq!(PrimaryHeader::decode(&header.encode()).unwrap(), header);
            }
        }
    }
}

/// The sequence count is a 14-bit counter, modulo 16384, 16383 is followed by 0.
#[test]
fn the_sequence_count_wraps_after_16383() {
    let mut counter = SequenceCounter::starting_at(SequenceCount::new(16382).unwrap());
    let counts: Vec<u16> = (0..4).map(|_| counter.advance().get()).collect();
    assert_eq!(counts, [16382, 16383, 0, 1]);
    assert_eq!(SequenceCounter::default().advance().get(), 0);
}

#[test]
fn out_of_range_fields_are_refused_with_a_clear_error() {
    let err = Apid::new(2048).unwrap_err();
    assert_eq!(err, CcsdsError::Apid { apid: 2048 });
    assert_eq!(
        err.to_string(),
        "APID 2048 is above 2047 (the 11-bit APID field of the Space Packet primary header)"
    );
    assert_eq!(
        SequenceCount::new(16384).unwrap_err(),
        CcsdsError::SequenceCount { count: 16384 }
    );
}

#[test]
fn decoding_refuses_short_input_and_unknown_versions() {
    let err = PrimaryHeader::decode(&[0x09, 0x23, 0xC0]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "a Space Packet primary header needs 6 octets, 3 given"
    );
    // Version bits 001: 0x20 in the first octet.
    let err = PrimaryHeader::decode(&[0x29, 0x23, 0xC0, 0x05, 0x00, 0x09]).unwrap_err();
    assert_eq!(err, CcsdsError::Version { version: 1 });
}

fn agency_cuc_4_2() -> CucFormat {
    CucFormat::new(CucEpoch::Agency, 4, 2, true).unwrap()
}

/// A packet with a CUC secondary header: P-field 0x2E (derived below), 4 + 2 octets of time,
/// then 3 octets of user data: data field 1 + 6 + 3 = 10 octets, data length 9, flag set.
#[test]
fn a_packet_with_a_cuc_secondary_header() {
    let mut secondary = Vec::new();
    agency_cuc_4_2()
        .encode(1_500_000_000, &mut secondary)
        .unwrap();
    let template = PacketTemplate {
        packet_type: PacketType::Telemetry,
        apid: Apid::new(0x123).unwrap(),
        sequence_flags: SequenceFlags::Unsegmented,
    };
    let mut packet = Vec::new();
    let header = template
        .encode(
            SequenceCount::new(5).unwrap(),
            &secondary,
            &[0xDE, 0xAD, 0xBF],
            &mut packet,
        )
        .unwrap();
    assert_eq!(
        packet,
        [0x09, 0x23, 0xC0, 0x05, 0x00, 0x09, 0x2E, 0, 0, 0, 1, 0x80, 0x00, 0xDE, 0xAD, 0xBF]
    );
    assert_eq!(PrimaryHeader::decode(&packet).unwrap(), header);
    let time = CucFormat::from_p_field(packet[6])
        .unwrap()
        .decode(&packet[6..])
        .unwrap();
    assert_eq!(time.to_ns(), 1_500_000_000);
}

#[test]
fn packets_that_the_data_length_cannot_describe_are_refused() {
    let template = PacketTemplate {
        packet_type: PacketType::Telemetry,
        apid: Apid::new(1).unwrap(),
        sequence_flags: SequenceFlags::Unsegmented,
    };
    let count = SequenceCount::default();
    let mut out = Vec::new();
    let err = template.encode(count, &[], &[], &mut out).unwrap_err();
    assert_eq!(err, CcsdsError::EmptyDataField);
    let err = template
        .encode(count, &[], &[0; 65_537], &mut out)
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "packet data field of 65537 octets is above the 65536 the 16-bit data length (octets − 1) can count"
    );
    // A secondary header counts in the data field too.
    let err = template
        .encode(count, &[0; 2], &[0; 65_535], &mut out)
        .unwrap_err();
    assert_eq!(err, CcsdsError::DataFieldTooLong { len_bytes: 65_537 });
    assert!(out.is_empty());
    // 65536 octets is the most: data length 0xFFFF.
    let header = template.encode(count, &[], &[0; 65_536], &mut out).unwrap();
    assert_eq!(header.data_length, 0xFFFF);
    assert_eq!(out.len(), 6 + 65_536);
}

/// P-field (301.0-B-4 §3.2): extension 0, id, coarse − 1 (2 bits), fine (2 bits):
/// - agency epoch 010, 4 coarse, 2 fine: 0 010 11 10 = 0x2E;
/// - 1958 TAI epoch 001, 4 coarse, 3 fine: 0 001 11 11 = 0x1F;
/// - agency epoch, 1 coarse, 0 fine: 0 010 00 00 = 0x20.
#[test]
fn the_p_field_has_the_hand_derived_bits() {
    assert_eq!(agency_cuc_4_2().p_field(), 0x2E);
    assert_eq!(
        CucFormat::new(CucEpoch::Tai1958, 4, 3, true)
            .unwrap()
            .p_field(),
        0x1F
    );
    assert_eq!(
        CucFormat::new(CucEpoch::Agency, 1, 0, true)
            .unwrap()
            .p_field(),
        0x20
    );
    for p_field in [0x2E, 0x1F, 0x20] {
        assert_eq!(CucFormat::from_p_field(p_field).unwrap().p_field(), p_field);
    }
    assert_eq!(CucFormat::from_p_field(0x2E).unwrap(), agency_cuc_4_2());
}

/// 0x12345678 s + 0.25 s with 4 coarse and 3 fine octets, no P-field: coarse 12 34 56 78, fine
/// 0.25 · 2²⁴ = 0x400000 → 40 00 00.
#[test]
fn a_cuc_time_code_has_the_hand_derived_octets() {
    let format = CucFormat::new(CucEpoch::Agency, 4, 3, false).unwrap();
    let mut out = Vec::new();
    let time_ns = 0x1234_5678 * 1_000_000_000 + 250_000_000;
    format.encode(time_ns, &mut out).unwrap();
    assert_eq!(out, [0x12, 0x34, 0x56, 0x78, 0x40, 0x00, 0x00]);
    assert_eq!(format.len_bytes(), 7);
    let decoded = format.decode(&out).unwrap();
    assert_eq!(
        decoded,
        CucTime {
            coarse_s: 0x1234_5678,
            fine: 0x40_0000,
            fine_octets: 3
        }
    );
    assert_eq!(decoded.to_ns(), time_ns as u128);
}

/// The fine time counts whole ticks: 1 ns with 1 fine octet (ticks of 1/256 s) is 0 ticks;
/// 999 999 999 ns is ⌊0.999999999 · 256⌋ = 255 ticks = 0xFF.
#[test]
fn the_fine_time_is_truncated_to_whole_ticks() {
    let format = CucFormat::new(CucEpoch::Agency, 2, 1, false).unwrap();
    let mut out = Vec::new();
    format.encode(1, &mut out).unwrap();
    format.encode(999_999_999, &mut out).unwrap();
    assert_eq!(out, [0x00, 0x00, 0x00, 0x00, 0x00, 0xFF]);
}

/// Decoding gives back the time to within one tick, never later than it.
#[test]
fn cuc_round_trips_within_one_tick() {
    for fine_octets in 0..=3u8 {
        let format = CucFormat::new(CucEpoch::Tai1958, 4, fine_octets, true).unwrap();
        let tick_ns = 1e9 / 2f64.powi(8 * i32::from(fine_octets));
        for time_ns in [
            0i64,
            1,
            999_999_999,
            1_000_000_000,
            123_456_789_012,
            4_294_967_295_999_999_999,
        ] {
            let mut out = Vec::new();
            format.encode(time_ns, &mut out).unwrap();
            assert_eq!(out.len(), format.len_bytes());
            let back = format.decode(&out).unwrap().to_ns() as i128;
            let behind = i128::from(time_ns) - back;
            assert!(
                behind >= 0 && (behind as f64) < tick_ns,
                "{fine_octets} fine octets, {time_ns} ns: {back}"
            );
        }
    }
}

#[test]
fn cuc_refuses_what_it_cannot_represent() {
    assert_eq!(
        CucFormat::new(CucEpoch::Agency, 5, 0, true).unwrap_err(),
        CcsdsError::CoarseOctets { octets: 5 }
    );
    assert_eq!(
        CucFormat::new(CucEpoch::Agency, 0, 0, true).unwrap_err(),
        CcsdsError::CoarseOctets { octets: 0 }
    );
    assert_eq!(
        CucFormat::new(CucEpoch::Agency, 4, 4, true).unwrap_err(),
        CcsdsError::FineOctets { octets: 4 }
    );
    let one_octet = CucFormat::new(CucEpoch::Agency, 1, 0, false).unwrap();
    let mut out = Vec::new();
    let err = one_octet.encode(256_000_000_000, &mut out).unwrap_err();
    assert_eq!(
        err.to_string(),
        "256 s since the epoch does not fit 1 octets of CUC coarse time"
    );
    assert_eq!(
        one_octet.encode(-1, &mut out).unwrap_err(),
        CcsdsError::NegativeTime { time_ns: -1 }
    );
    assert!(out.is_empty());
    one_octet.encode(255_999_999_999, &mut out).unwrap();
    assert_eq!(out, [0xFF]);
    assert!(matches!(
        CucFormat::from_p_field(0xAE),
        Err(CcsdsError::PField { p_field: 0xAE, .. })
    ));
    assert!(matches!(
        CucFormat::from_p_field(0x4E),
        Err(CcsdsError::PField { .. })
    ));
    let err = agency_cuc_4_2()
        .decode(&[0x1E, 0, 0, 0, 0, 0, 0])
        .unwrap_err();
    assert!(matches!(err, CcsdsError::PField { p_field: 0x1E, .. }));
    assert!(matches!(
        agency_cuc_4_2().decode(&[0x2E, 0, 0]),
        Err(CcsdsError::TooShort {
            needed_bytes: 7,
            ..
        })
    ));
}
