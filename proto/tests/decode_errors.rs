//! Decoder error behaviour on hand-made bad inputs.

use flexdyn_proto::{
    decode, decode_command, decode_header, decode_imu, decode_state, decode_status, encode,
    encode_into, CommandKind, CommandMsg, DecodeError, Header, ImuMsg, PanelPairState,
    RejectCounters, StateMsg, StatusMsg, WireMessage, COMMAND_KIND_OFFSET, COMMAND_NO_COMMAND_LEN,
    COMMAND_WRENCH_LEN, HEADER_LEN, IMU_LEN, MAX_MESSAGE_BYTES, MAX_PANEL_PAIRS, STATE_FIXED_LEN,
    STATE_PANEL_COUNT_OFFSET, STATUS_LEN,
};

fn wrench(t: [f64; 3], f: [f64; 3]) -> CommandMsg {
    CommandMsg::wrench(Header::new(1, 2, 3, 4), 9, t, f)
}

fn state_with_panels(n: usize) -> StateMsg {
    StateMsg {
        panels: vec![PanelPairState::default(); n],
        ..Default::default()
    }
}

#[test]
fn unknown_version_is_checked_first() {
    for version in [0u16, 1, 3, 0xFFFF] {
        let mut b = encode(&StatusMsg::default());
        b[..2].copy_from_slice(&version.to_le_bytes());
        assert_eq!(
            decode_status(&b),
            Err(DecodeError::UnknownVersion { found: version })
        );
        // Even with nothing else present, the version is reported.
        assert_eq!(
            decode_imu(&b[..2]),
            Err(DecodeError::UnknownVersion { found: version })
        );
        assert_eq!(
            decode_header(&b[..2]),
            Err(DecodeError::UnknownVersion { found: version })
        );
    }
}

#[test]
fn length_errors() {
    assert_eq!(
        decode_status(&[]),
        Err(DecodeError::Length {
            needed: STATUS_LEN,
            actual: 0
        })
    );
    assert_eq!(
        decode_status(&[1]),
        Err(DecodeError::Length {
            needed: STATUS_LEN,
            actual: 1
        })
    );
    let b = encode(&ImuMsg::default());
    assert_eq!(
        decode_imu(&b[..IMU_LEN - 1]),
        Err(DecodeError::Length {
            needed: IMU_LEN,
            actual: IMU_LEN - 1
        })
    );
    // Command: tag known → exact length; tag missing → shortest command.
    let b = encode(&wrench([0.0; 3], [0.0; 3]));
    assert_eq!(
        decode_command(&b[..40]),
        Err(DecodeError::Length {
            needed: COMMAND_WRENCH_LEN,
            actual: 40
        })
    );
    assert_eq!(
        decode_command(&b[..COMMAND_KIND_OFFSET]),
        Err(DecodeError::Length {
            needed: COMMAND_NO_COMMAND_LEN,
            actual: COMMAND_KIND_OFFSET
        })
    );
    // State: panel count known → exact length.
    let b = encode(&state_with_panels(3));
    assert_eq!(
        decode_state(&b[..b.len() - 1]),
        Err(DecodeError::Length {
            needed: STATE_FIXED_LEN + 96,
            actual: b.len() - 1
        })
    );
    assert_eq!(
        decode_state(&b[..STATE_PANEL_COUNT_OFFSET]),
        Err(DecodeError::Length {
            needed: STATE_FIXED_LEN,
            actual: STATE_PANEL_COUNT_OFFSET
        })
    );
    assert_eq!(
        decode_header(&b[..HEADER_LEN - 1]),
        Err(DecodeError::Length {
            needed: HEADER_LEN,
            actual: HEADER_LEN - 1
        })
    );
}

#[test]
fn trailing_bytes() {
    let mut b = encode(&wrench([1.0; 3], [2.0; 3]));
    b.push(0);
    assert_eq!(
        decode_command(&b),
        Err(DecodeError::TrailingBytes {
            expected: COMMAND_WRENCH_LEN,
            actual: COMMAND_WRENCH_LEN + 1
        })
    );
    // A NoCommand followed by the bytes of a wrench is not a NoCommand.
    let mut b = encode(&wrench([1.0; 3], [2.0; 3]));
    b[COMMAND_KIND_OFFSET] = 1;
    assert_eq!(
        decode_command(&b),
        Err(DecodeError::TrailingBytes {
            expected: COMMAND_NO_COMMAND_LEN,
            actual: COMMAND_WRENCH_LEN
        })
    );
    let mut b = encode(&state_with_panels(1));
    b.extend_from_slice(&[0; 32]);
    assert!(matches!(
        decode_state(&b),
        Err(DecodeError::TrailingBytes { .. })
    ));
}

#[test]
fn too_large() {
    let b = vec![1u8; MAX_MESSAGE_BYTES + 1];
    assert_eq!(
        decode_state(&b),
        Err(DecodeError::TooLarge {
            actual: MAX_MESSAGE_BYTES + 1,
            max: MAX_MESSAGE_BYTES
        })
    );
}

#[test]
fn huge_panel_count_is_rejected_without_allocating() {
    let mut b = encode(&StateMsg::default());
    b[STATE_PANEL_COUNT_OFFSET..STATE_PANEL_COUNT_OFFSET + 8]
        .copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(decode_state(&b), Err(DecodeError::Malformed(_))));
    let count = (MAX_PANEL_PAIRS as u64 + 1).to_le_bytes();
    b[STATE_PANEL_COUNT_OFFSET..STATE_PANEL_COUNT_OFFSET + 8].copy_from_slice(&count);
    assert!(matches!(decode_state(&b), Err(DecodeError::Malformed(_))));
    // The maximum itself is fine.
    let b = encode(&state_with_panels(MAX_PANEL_PAIRS));
    assert_eq!(decode_state(&b).unwrap().panels.len(), MAX_PANEL_PAIRS);
}

#[test]
fn malformed_enum_tags_and_bools() {
    let mut b = encode(&wrench([0.0; 3], [0.0; 3]));
    b[COMMAND_KIND_OFFSET] = 2;
    assert!(matches!(decode_command(&b), Err(DecodeError::Malformed(_))));

    let good = encode(&StatusMsg::default());
    for (offset, value) in [(30usize, 3u8), (34, 6), (95, 2)] {
        let mut b = good.clone();
        b[offset] = value;
        assert!(
            matches!(decode_status(&b), Err(DecodeError::Malformed(_))),
            "tag at {offset}"
        );
        let mut b = good.clone();
        b[offset + 3] = 0x80;
        assert!(
            matches!(decode_status(&b), Err(DecodeError::Malformed(_))),
            "high tag byte at {offset}"
        );
    }
    let mut b = good.clone();
    b[94] = 2; // command_stale must be 0 or 1
    assert!(matches!(decode_status(&b), Err(DecodeError::Malformed(_))));
}

#[test]
fn non_finite_commands() {
    let cases = [
        (
            wrench([f64::NAN, 0.0, 0.0], [0.0; 3]),
            "kind.torque_b_nm[0]",
        ),
        (
            wrench([0.0, 0.0, f64::INFINITY], [0.0; 3]),
            "kind.torque_b_nm[2]",
        ),
        (
            wrench([0.0; 3], [0.0, f64::NEG_INFINITY, 0.0]),
            "kind.force_b_newton[1]",
        ),
        (
            wrench([0.0, f64::NAN, 0.0], [f64::NAN; 3]),
            "kind.torque_b_nm[1]",
        ),
    ];
    for (cmd, field) in cases {
        assert_eq!(cmd.validate(), Err(DecodeError::NonFinite { field }));
        assert_eq!(
            decode_command(&encode(&cmd)),
            Err(DecodeError::NonFinite { field })
        );
    }
    // Extreme finite values are fine.
    let ok = wrench([f64::MAX, f64::MIN, f64::MIN_POSITIVE], [-0.0, 5e-324, 0.0]);
    assert_eq!(decode_command(&encode(&ok)), Ok(ok));
}

#[test]
fn non_command_messages_carry_non_finite_values() {
    let s = StateMsg {
        omega_bn_b_rad_s: [f64::NAN, f64::INFINITY, f64::NEG_INFINITY],
        ..Default::default()
    };
    let back = decode_state(&encode(&s)).unwrap();
    assert!(back.omega_bn_b_rad_s[0].is_nan());
    assert_eq!(
        back.omega_bn_b_rad_s[1..],
        [f64::INFINITY, f64::NEG_INFINITY]
    );
}

#[test]
fn wrong_type_is_caught_by_length() {
    // Feeding a StatusMsg to the IMU decoder cannot silently succeed.
    let b = encode(&StatusMsg::default());
    assert!(matches!(
        decode_imu(&b),
        Err(DecodeError::TrailingBytes { .. })
    ));
    assert!(matches!(
        decode::<StatusMsg>(&encode(&ImuMsg::default())),
        Err(DecodeError::Length { .. })
    ));
}

#[test]
fn decode_header_reads_any_message() {
    let h = Header::new(77, 88, 99, 1010);
    let cmd = CommandMsg {
        header: h,
        sender_id: 1,
        kind: CommandKind::NoCommand,
    };
    assert_eq!(decode_header(&encode(&cmd)), Ok(h));
    let st = StateMsg {
        header: h,
        ..Default::default()
    };
    assert_eq!(decode_header(&encode(&st)), Ok(h));
}

#[test]
fn encode_into_reuses_the_buffer() {
    let mut buf = Vec::with_capacity(1024);
    let ptr = buf.as_ptr();
    encode_into(&state_with_panels(2), &mut buf);
    assert_eq!(buf.len(), STATE_FIXED_LEN + 64);
    encode_into(&ImuMsg::default(), &mut buf);
    assert_eq!(buf, encode(&ImuMsg::default()));
    assert_eq!(buf.as_ptr(), ptr, "no reallocation");
}

#[test]
fn header_new_sets_version() {
    let h = Header::new(1, 2, 3, 4);
    assert_eq!(h.protocol_version, flexdyn_proto::PROTOCOL_VERSION);
    assert_eq!(Header::default().protocol_version, 2);
    assert_eq!(StateMsg::default().q_bn, [1.0, 0.0, 0.0, 0.0]);
}

#[test]
fn reject_counters_record() {
    let mut c = RejectCounters::default();
    c.record(&DecodeError::UnknownVersion { found: 9 });
    c.record(&DecodeError::NonFinite { field: "x" });
    c.record(&DecodeError::Length {
        needed: 1,
        actual: 0,
    });
    c.record(&DecodeError::TrailingBytes {
        expected: 1,
        actual: 2,
    });
    c.record(&DecodeError::TooLarge { actual: 1, max: 0 });
    c.record(&DecodeError::Malformed(String::new()));
    assert_eq!((c.bad_version, c.non_finite, c.malformed), (1, 1, 4));
    assert_eq!(c.total(), 6);
    c.stale_tick = u64::MAX;
    assert_eq!(c.total(), u64::MAX);
}
