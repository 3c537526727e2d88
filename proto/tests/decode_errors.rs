//! Decoder error behaviour on hand-made bad inputs.

use flexdyn_proto::{
    decode, decode_command, decode_header, decode_imu, decode_operator, decode_star_tracker,
    decode_state, decode_status, decode_time, effector_kind, encode, encode_into, CommandKind,
    CommandMsg, DecodeError, EffectorInput, EffectorState, Header, ImuMsg, OperatorAction,
    OperatorMsg, RejectCounters, StarTrackerMsg, StateMsg, StatusMsg, TimeMsg, WireMessage,
    COMMAND_ACTUATORS_FIXED_LEN, COMMAND_KIND_OFFSET, COMMAND_NO_COMMAND_LEN, COMMAND_WRENCH_LEN,
    EFFECTOR_STATE_FIXED_LEN, HEADER_LEN, IMU_LEN, MAX_EFFECTORS, MAX_EFFECTOR_VALUES,
    MAX_MESSAGE_BYTES, OPERATOR_LEN, STAR_TRACKER_LEN, STATE_EFFECTOR_COUNT_OFFSET,
    STATE_FIXED_LEN, STATUS_LEN, TIME_LEN,
};

fn wrench(t: [f64; 3], f: [f64; 3]) -> CommandMsg {
    CommandMsg::wrench(Header::new(1, 2, 3, 4), 9, t, f)
}

/// A state with `n` panel-pair effectors (4 states each: 22 + 32 = 54 bytes per effector).
fn state_with_panels(n: usize) -> StateMsg {
    StateMsg {
        effectors: vec![
            EffectorState {
                kind: effector_kind::PANEL_PAIR,
                flags: 0,
                states: vec![0.0; 4],
                outputs: vec![],
            };
            n
        ],
        ..Default::default()
    }
}

fn actuators(inputs: Vec<EffectorInput>) -> CommandMsg {
    CommandMsg::actuators(Header::new(1, 2, 3, 4), 9, [0.0; 3], [0.0; 3], inputs)
}

fn input(effector_index: u32, values: &[f64]) -> EffectorInput {
    EffectorInput {
        effector_index,
        values: values.to_vec(),
    }
}

#[test]
fn unknown_version_is_checked_first() {
    for version in [0u16, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 0xFFFF] {
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
    // State: every count readable → exact length (3 effectors of 22 + 4·8 bytes).
    let b = encode(&state_with_panels(3));
    assert_eq!(
        b.len(),
        STATE_FIXED_LEN + 3 * (EFFECTOR_STATE_FIXED_LEN + 32)
    );
    assert_eq!(
        decode_state(&b[..b.len() - 1]),
        Err(DecodeError::Length {
            needed: b.len(),
            actual: b.len() - 1
        })
    );
    // Effector count missing → the fixed part.
    assert_eq!(
        decode_state(&b[..STATE_EFFECTOR_COUNT_OFFSET]),
        Err(DecodeError::Length {
            needed: STATE_FIXED_LEN,
            actual: STATE_EFFECTOR_COUNT_OFFSET
        })
    );
    // Cut inside the second effector's state count → up to that count.
    let second = STATE_FIXED_LEN + EFFECTOR_STATE_FIXED_LEN + 32;
    assert_eq!(
        decode_state(&b[..second + 8]),
        Err(DecodeError::Length {
            needed: second + 14,
            actual: second + 8
        })
    );
    // Actuators: inputs walked.
    let b = encode(&actuators(vec![input(0, &[1.0]), input(3, &[2.0])]));
    assert_eq!(b.len(), COMMAND_ACTUATORS_FIXED_LEN + 2 * 20);
    assert_eq!(
        decode_command(&b[..b.len() - 3]),
        Err(DecodeError::Length {
            needed: b.len(),
            actual: b.len() - 3
        })
    );
    assert_eq!(
        decode_command(&b[..COMMAND_ACTUATORS_FIXED_LEN - 1]),
        Err(DecodeError::Length {
            needed: COMMAND_ACTUATORS_FIXED_LEN,
            actual: COMMAND_ACTUATORS_FIXED_LEN - 1
        })
    );
    let b = encode(&StarTrackerMsg::default());
    assert_eq!(
        decode_star_tracker(&b[..STAR_TRACKER_LEN - 1]),
        Err(DecodeError::Length {
            needed: STAR_TRACKER_LEN,
            actual: STAR_TRACKER_LEN - 1
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
fn huge_counts_are_rejected_without_allocating() {
    let at = STATE_EFFECTOR_COUNT_OFFSET;
    let mut b = encode(&StateMsg::default());
    b[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(decode_state(&b), Err(DecodeError::Malformed(_))));
    let count = (MAX_EFFECTORS as u64 + 1).to_le_bytes();
    b[at..at + 8].copy_from_slice(&count);
    assert!(matches!(decode_state(&b), Err(DecodeError::Malformed(_))));
    // The maximum itself is fine.
    let b = encode(&state_with_panels(MAX_EFFECTORS));
    assert_eq!(decode_state(&b).unwrap().effectors.len(), MAX_EFFECTORS);
    // An effector's value count above the maximum.
    let mut s = state_with_panels(1);
    s.effectors[0].states = vec![0.0; MAX_EFFECTOR_VALUES + 1];
    assert!(matches!(
        decode_state(&encode(&s)),
        Err(DecodeError::Malformed(m)) if m.contains("effectors[].states count 33")
    ));
    s.effectors[0].states = vec![0.0; MAX_EFFECTOR_VALUES];
    s.effectors[0].outputs = vec![0.0; MAX_EFFECTOR_VALUES];
    assert_eq!(decode_state(&encode(&s)).unwrap(), s);
    // Inputs: too many entries, too many values.
    let mut b = encode(&actuators(vec![]));
    b[86..94].copy_from_slice(&(MAX_EFFECTORS as u64 + 1).to_le_bytes());
    assert!(matches!(decode_command(&b), Err(DecodeError::Malformed(_))));
    let c = actuators(vec![input(0, &[0.0; MAX_EFFECTOR_VALUES + 1])]);
    assert!(matches!(
        decode_command(&encode(&c)),
        Err(DecodeError::Malformed(m)) if m.contains("inputs[].values count 33")
    ));
}

#[test]
fn malformed_enum_tags_and_bools() {
    // TimeMsg: its run state and mode tags, and its fixed length.
    let time = encode(&TimeMsg::default());
    assert_eq!(time.len(), TIME_LEN);
    for (offset, value) in [(30usize, 7u8), (34, 3)] {
        let mut b = time.clone();
        b[offset] = value;
        assert!(
            matches!(decode_time(&b), Err(DecodeError::Malformed(_))),
            "time tag at {offset}"
        );
    }
    assert!(matches!(
        decode_time(&time[..TIME_LEN - 1]),
        Err(DecodeError::Length { .. })
    ));
    let mut long = time.clone();
    long.push(0);
    assert!(matches!(
        decode_time(&long),
        Err(DecodeError::TrailingBytes { .. })
    ));
    // OperatorMsg (protocol 6): its action tag (0..=3 since protocol 12), fixed length 42.
    let op = encode(&OperatorMsg::new(
        Header::new(1, 2, 3, 4),
        OperatorAction::RunTicks,
        5,
    ));
    assert_eq!(op.len(), OPERATOR_LEN);
    for (offset, value) in [(30usize, 4u8), (33, 0x80)] {
        let mut b = op.clone();
        b[offset] = value;
        assert!(
            matches!(decode_operator(&b), Err(DecodeError::Malformed(_))),
            "operator tag byte at {offset}"
        );
    }
    assert_eq!(
        decode_operator(&op[..OPERATOR_LEN - 1]),
        Err(DecodeError::Length {
            needed: OPERATOR_LEN,
            actual: OPERATOR_LEN - 1
        })
    );
    let mut long = op.clone();
    long.push(0);
    assert_eq!(
        decode_operator(&long),
        Err(DecodeError::TrailingBytes {
            expected: OPERATOR_LEN,
            actual: OPERATOR_LEN + 1
        })
    );
    let mut old = op.clone();
    old[0] = 5;
    assert_eq!(
        decode_operator(&old),
        Err(DecodeError::UnknownVersion { found: 5 })
    );
    // A command is not an operator message (and vice versa): the lengths differ.
    assert!(decode_operator(&encode(&wrench([0.0; 3], [0.0; 3]))).is_err());
    assert!(decode_command(&op).is_err());
    let mut b = encode(&wrench([0.0; 3], [0.0; 3]));
    b[COMMAND_KIND_OFFSET] = 3;
    assert!(matches!(decode_command(&b), Err(DecodeError::Malformed(_))));
    // The star tracker's `valid` must be 0 or 1.
    let mut b = encode(&StarTrackerMsg::default());
    b[62] = 2;
    assert!(matches!(
        decode_star_tracker(&b),
        Err(DecodeError::Malformed(_))
    ));

    let good = encode(&StatusMsg::default());
    for (offset, value) in [(30usize, 3u8), (34, 7), (95, 2)] {
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
    let bad = actuators(vec![input(0, &[1.0]), input(1, &[f64::NAN])]);
    let field = "kind.inputs[].values[]";
    assert_eq!(bad.validate(), Err(DecodeError::NonFinite { field }));
    assert_eq!(
        decode_command(&encode(&bad)),
        Err(DecodeError::NonFinite { field })
    );
    let mut bad = actuators(vec![input(0, &[1.0])]);
    if let CommandKind::Actuators { torque_b_nm, .. } = &mut bad.kind {
        torque_b_nm[1] = f64::INFINITY;
    }
    assert_eq!(
        decode_command(&encode(&bad)),
        Err(DecodeError::NonFinite {
            field: "kind.torque_b_nm[1]"
        })
    );
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
    assert_eq!(buf.len(), STATE_FIXED_LEN + 2 * 54);
    encode_into(&ImuMsg::default(), &mut buf);
    assert_eq!(buf, encode(&ImuMsg::default()));
    assert_eq!(buf.as_ptr(), ptr, "no reallocation");
}

#[test]
fn header_new_sets_version() {
    let h = Header::new(1, 2, 3, 4);
    assert_eq!(h.protocol_version, flexdyn_proto::PROTOCOL_VERSION);
    assert_eq!(Header::default().protocol_version, 12);
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
    c.bad_effector_input = 2;
    assert_eq!(c.total(), 8);
    c.wrong_identity = 3;
    assert_eq!(c.total(), 11);
    c.operator_refused = 4;
    assert_eq!(c.total(), 15);
    c.stale_tick = u64::MAX;
    assert_eq!(c.total(), u64::MAX);
}

/// The text rule ("Decoder rules", step 4): a target ends at its first NUL and the padding after
/// it is NUL; a FaultCommandMsg with `imus.hub.gyro`, NULs, then 0x80 is refused, not applied.
#[test]
fn text_after_its_nul_is_malformed() {
    use flexdyn_proto::{
        decode_fault_command, decode_fault_event, FaultAction, FaultCommandMsg, FaultEventMsg,
        FaultTarget, FAULT_TARGET_LEN,
    };
    let cmd = FaultCommandMsg {
        header: Header::new(1, 4, 0, 0),
        action: FaultAction::Inject,
        target: FaultTarget::new("imus.hub.gyro").unwrap(),
        ..Default::default()
    };
    let good = encode(&cmd);
    assert_eq!(decode_fault_command(&good).unwrap(), cmd);
    let target_at = 86;
    let mut bad = good.clone();
    bad[target_at + FAULT_TARGET_LEN - 1] = 0x80;
    match decode_fault_command(&bad) {
        Err(DecodeError::Malformed(m)) => assert!(
            m.contains("target: byte 127 is 0x80") && m.contains("at byte 13"),
            "{m}"
        ),
        other => panic!("{other:?}"),
    }
    // Step 4 (the text) is reported before step 5 (a non-finite parameter).
    bad[50..58].copy_from_slice(&f64::NAN.to_le_bytes());
    assert!(matches!(
        decode_fault_command(&bad),
        Err(DecodeError::Malformed(_))
    ));
    // A byte right after the NUL, and a target with no NUL at all (128 bytes of text).
    let mut bad = good.clone();
    bad[target_at + 14] = b'x';
    assert!(matches!(
        decode_fault_command(&bad),
        Err(DecodeError::Malformed(_))
    ));
    let mut full = good;
    full[target_at..target_at + FAULT_TARGET_LEN].fill(b'a');
    assert_eq!(
        decode_fault_command(&full).unwrap().target.as_str(),
        Some("a".repeat(FAULT_TARGET_LEN).as_str())
    );
    let ev = FaultEventMsg {
        header: Header::new(1, 4, 0, 0),
        target: FaultTarget::new("reaction_wheels.rw2").unwrap(),
        ..Default::default()
    };
    let mut bad = encode(&ev);
    bad[71 + 100] = 1;
    assert!(matches!(
        decode_fault_event(&bad),
        Err(DecodeError::Malformed(_))
    ));
}
