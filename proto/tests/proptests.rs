//! Property tests of the codec: no input makes a decoder panic, random
//! messages round-trip, and every truncation or extension is an error.

use flexdyn_proto::view::{MessageView, ViewError};
use flexdyn_proto::{
    decode, decode_command, decode_header, decode_imu, decode_magnetometer, decode_operator,
    decode_star_tracker, decode_state, decode_status, decode_time, encode, AppliedWrench,
    CommandKind, CommandMsg, CommandStatus, Conserved, DecodeError, EffectorInput, EffectorState,
    FrameTiming, Header, ImuMsg, Mode, OperatorAction, OperatorMsg, RejectCounters, RunState,
    StalePolicy, StarTrackerMsg, StateMsg, StatusMsg, SysTime, TimeMsg, UtcTime, WireMessage,
    MAX_EFFECTOR_VALUES,
};
use proptest::prelude::*;

/// Any f64 bit pattern, NaN and infinities included.
fn any_bits_f64() -> impl Strategy<Value = f64> + Clone {
    any::<u64>().prop_map(f64::from_bits)
}

fn v3(s: impl Strategy<Value = f64> + Clone) -> impl Strategy<Value = [f64; 3]> {
    [s.clone(), s.clone(), s]
}

fn header() -> impl Strategy<Value = Header> {
    (any::<u32>(), any::<u64>(), any::<u64>(), any::<u64>())
        .prop_map(|(sc, tick, t, seq)| Header::new(sc, tick, t, seq))
}

fn state() -> impl Strategy<Value = StateMsg> {
    state_with(any_bits_f64())
}

/// State messages whose f64 fields are drawn from `floats`.
fn state_with(floats: impl Strategy<Value = f64> + Clone) -> impl Strategy<Value = StateMsg> {
    let f = || floats.clone();
    let values = || prop::collection::vec(f(), 0..=MAX_EFFECTOR_VALUES);
    let effector = (any::<u16>(), any::<u32>(), values(), values()).prop_map(
        |(kind, flags, states, outputs)| EffectorState {
            kind,
            flags,
            states,
            outputs,
        },
    );
    let conserved = (f(), f(), v3(f()), v3(f())).prop_map(|(a, b, c, d)| Conserved {
        orb_energy_j: a,
        rot_energy_j: b,
        orb_ang_mom_n: c,
        rot_ang_mom_c_n: d,
    });
    (
        header(),
        (v3(f()), [f(), f(), f(), f()], v3(f()), v3(f())),
        (v3(f()), v3(f()), v3(f())),
        conserved,
        (v3(f()), v3(f()), any::<u8>()),
        prop::collection::vec(effector, 0..8),
    )
        .prop_map(
            |(header, (sigma, q, w, wd), (r, v, a), conserved, (tq, fo, flags), effectors)| {
                StateMsg {
                    header,
                    sigma_bn: sigma,
                    q_bn: q,
                    omega_bn_b_rad_s: w,
                    omega_dot_bn_b_rad_s2: wd,
                    r_bn_n_m: r,
                    v_bn_n_m_s: v,
                    nongrav_accel_bn_n_m_s2: a,
                    conserved,
                    wrench_applied: AppliedWrench {
                        torque_b_nm: tq,
                        force_b_newton: fo,
                    },
                    command_flags: flags,
                    effectors,
                }
            },
        )
}

fn imu() -> impl Strategy<Value = ImuMsg> {
    let f = any_bits_f64;
    (header(), v3(f()), v3(f()), v3(f()), v3(f()), any::<u8>()).prop_map(
        |(header, w, a, dt, dv, s)| ImuMsg {
            header,
            omega_p_rad_s: w,
            accel_p_m_s2: a,
            dtheta_p_rad: dt,
            dv_p_m_s: dv,
            saturation_flags: s,
        },
    )
}

/// Valid (finite) commands.
fn command() -> impl Strategy<Value = CommandMsg> {
    command_with(any::<f64>) // finite only
}

/// Commands of every kind whose numbers come from `f`.
fn command_with<S: Strategy<Value = f64> + Clone + 'static>(
    f: impl Fn() -> S,
) -> impl Strategy<Value = CommandMsg> {
    let kind = prop_oneof![
        (v3(f()), v3(f())).prop_map(|(t, fo)| CommandKind::Wrench {
            torque_b_nm: t,
            force_b_newton: fo
        }),
        Just(CommandKind::NoCommand),
        (
            v3(f()),
            v3(f()),
            prop::collection::vec(
                (
                    any::<u32>(),
                    prop::collection::vec(f(), 0..=MAX_EFFECTOR_VALUES)
                ),
                0..6
            )
        )
            .prop_map(|(t, fo, inputs)| CommandKind::Actuators {
                torque_b_nm: t,
                force_b_newton: fo,
                inputs: inputs
                    .into_iter()
                    .map(|(effector_index, values)| EffectorInput {
                        effector_index,
                        values
                    })
                    .collect(),
            }),
    ];
    (header(), any::<u32>(), kind).prop_map(|(header, sender_id, kind)| CommandMsg {
        header,
        sender_id,
        kind,
    })
}

fn status() -> impl Strategy<Value = StatusMsg> {
    let u = any::<u64>;
    let mode = prop_oneof![
        Just(Mode::RealTime),
        Just(Mode::Lockstep),
        Just(Mode::Batch)
    ];
    let run = prop_oneof![
        Just(RunState::Starting),
        Just(RunState::Running),
        Just(RunState::Stopping),
        Just(RunState::Finished),
        Just(RunState::Failed),
        Just(RunState::Stopped),
        Just(RunState::Paused),
    ];
    let policy = prop_oneof![Just(StalePolicy::Hold), Just(StalePolicy::Zero)];
    (
        header(),
        mode,
        run,
        (u(), u(), u(), u(), u()),
        (u(), u(), any::<bool>(), policy),
        (u(), u(), u(), u(), u(), u(), u(), u(), u()),
        (u(), u(), u(), u(), u(), u(), u()),
    )
        .prop_map(
            |(
                header,
                mode,
                run_state,
                t,
                c,
                r,
                (dropped, wall, fault_refused, active, b0, b1, b2),
            )| StatusMsg {
                header,
                mode,
                run_state,
                timing: FrameTiming {
                    lateness_p50_ns: t.0,
                    lateness_p99_ns: t.1,
                    lateness_max_ns: t.2,
                    overrun_count: t.3,
                    frames_skipped: t.4,
                },
                command: CommandStatus {
                    last_command_tick: c.0,
                    command_age_ns: c.1,
                    command_stale: c.2,
                    stale_policy: c.3,
                },
                rejected: RejectCounters {
                    malformed: r.0,
                    bad_version: r.1,
                    non_finite: r.2,
                    wrong_spacecraft: r.3,
                    stale_tick: r.4,
                    unknown_sender: r.5,
                    bad_effector_input: r.6,
                    wrong_identity: r.7,
                    operator_refused: r.8,
                    fault_refused,
                    fsw_refused: !fault_refused,
                },
                commands_dropped: dropped,
                wall_time_unix_ns: wall,
                faults_active: active,
                faults_active_bits: [b0, b1, b2, !b0],
            },
        )
}

/// Time messages with every field drawn at random (the speed as any bit pattern).
fn time() -> impl Strategy<Value = TimeMsg> {
    let u = any::<u64>;
    let run = (0u32..7).prop_map(|t| RunState::from_tag(t).unwrap_or_default());
    let mode = prop_oneof![
        Just(Mode::RealTime),
        Just(Mode::Lockstep),
        Just(Mode::Batch)
    ];
    (
        header(),
        (run, mode, any::<u8>(), u(), any_bits_f64(), u()),
        (any::<u16>(), any::<[u8; 5]>(), any::<u32>()),
        (any::<i32>(), any::<u32>(), u(), u(), any::<[u8; 8]>()),
        any::<[u32; 4]>(),
    )
        .prop_map(|(header, a, (year, ymdhms, ns), b, tone)| TimeMsg {
            header,
            run_state: a.0,
            mode: a.1,
            flags: a.2,
            frame_ns: a.3,
            speed: a.4,
            tai_ns_1958: a.5,
            utc: UtcTime {
                year,
                month: ymdhms[0],
                day: ymdhms[1],
                hour: ymdhms[2],
                minute: ymdhms[3],
                second: ymdhms[4],
                nanosecond: ns,
            },
            tai_minus_utc_s: b.0,
            gps_week: b.1,
            gps_ns_of_week: b.2,
            met_ns: b.3,
            cuc_tai: b.4,
            tone_met: SysTime {
                seconds: tone[0],
                subseconds: tone[1],
            },
            tone_tai: SysTime {
                seconds: tone[2],
                subseconds: tone[3],
            },
        })
}

fn operator() -> impl Strategy<Value = OperatorMsg> {
    let action = prop_oneof![
        Just(OperatorAction::Pause),
        Just(OperatorAction::Resume),
        Just(OperatorAction::RunTicks),
        Just(OperatorAction::Checkpoint)
    ];
    (header(), action, any::<u64>()).prop_map(|(h, a, n)| OperatorMsg::new(h, a, n))
}

/// Run every decoder; the only requirement is that none panics.
fn decode_all(bytes: &[u8]) {
    let _ = decode_time(bytes);
    let _ = decode_operator(bytes);
    let _ = decode_magnetometer(bytes);
    let _ = decode_state(bytes);
    let _ = decode_imu(bytes);
    let _ = decode_command(bytes);
    let _ = decode_status(bytes);
    let _ = decode_star_tracker(bytes);
    let _ = decode_header(bytes);
    let _ = flexdyn_proto::decode_fault_event(bytes);
    let _ = flexdyn_proto::decode_fault_command(bytes);
}

/// encode → decode → encode gives the same bytes (bitwise, so NaN payloads
/// count), and every strict prefix and every one-byte extension is an error.
fn round_trip_and_truncate<M: WireMessage + std::fmt::Debug>(msg: &M) -> Result<(), TestCaseError> {
    let bytes = encode(msg);
    let back: M = decode(&bytes).map_err(|e| TestCaseError::fail(format!("{e}")))?;
    prop_assert_eq!(&encode(&back), &bytes);
    for cut in 0..bytes.len() {
        let r = decode::<M>(&bytes[..cut]);
        prop_assert!(
            matches!(r, Err(DecodeError::Length { .. })),
            "prefix of {} bytes: {:?}",
            cut,
            r.map(|_| ())
        );
    }
    let mut longer = bytes.clone();
    longer.push(0);
    prop_assert!(
        matches!(decode::<M>(&longer), Err(DecodeError::TrailingBytes { .. })),
        "extended"
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        decode_all(&bytes);
    }

    /// Past the version check: random bytes behind a valid version.
    #[test]
    fn arbitrary_bytes_with_valid_version_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        let mut b = flexdyn_proto::PROTOCOL_VERSION.to_le_bytes().to_vec();
        b.extend_from_slice(&bytes);
        decode_all(&b);
    }

    /// Random bodies of exactly the right length reach bincode: the result is a
    /// message, Malformed or NonFinite, never a panic or a length error.
    #[test]
    fn right_length_random_bodies(body in prop::collection::vec(any::<u8>(), 241)) {
        let mut b = flexdyn_proto::PROTOCOL_VERSION.to_le_bytes().to_vec();
        b.extend_from_slice(&body);
        for r in [
            decode_imu(&b[..flexdyn_proto::IMU_LEN]).map(|_| ()),
            decode_status(&b[..flexdyn_proto::STATUS_LEN]).map(|_| ()),
            decode_star_tracker(&b[..flexdyn_proto::STAR_TRACKER_LEN]).map(|_| ()),
            decode_time(&b[..flexdyn_proto::TIME_LEN]).map(|_| ()),
            decode_operator(&b[..flexdyn_proto::OPERATOR_LEN]).map(|_| ()),
            flexdyn_proto::decode_fault_event(&b[..flexdyn_proto::FAULT_EVENT_LEN]).map(|_| ()),
        ] {
            prop_assert!(matches!(r, Ok(()) | Err(DecodeError::Malformed(_))), "{:?}", r);
        }
        let mut c = b[..flexdyn_proto::COMMAND_WRENCH_LEN].to_vec();
        c[flexdyn_proto::COMMAND_KIND_OFFSET..flexdyn_proto::COMMAND_KIND_OFFSET + 4].copy_from_slice(&[0; 4]);
        let r = decode_command(&c);
        prop_assert!(matches!(r, Ok(_) | Err(DecodeError::NonFinite { .. })), "{:?}", r);
    }

    /// Valid messages with random bytes overwritten never panic any decoder.
    #[test]
    fn mutated_messages_never_panic(
        msg in state(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        let mut b = encode(&msg);
        for (i, v) in &edits {
            let at = i.index(b.len());
            b[at] = *v;
        }
        decode_all(&b);
    }

    #[test]
    fn mutated_commands_never_panic(
        msg in command(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        let mut b = encode(&msg);
        for (i, v) in &edits {
            let at = i.index(b.len());
            b[at] = *v;
        }
        decode_all(&b);
    }

    #[test]
    fn state_round_trip(msg in state()) {
        round_trip_and_truncate(&msg)?;
    }

    #[test]
    fn imu_round_trip(msg in imu()) {
        round_trip_and_truncate(&msg)?;
    }

    #[test]
    fn command_round_trip(msg in command()) {
        round_trip_and_truncate(&msg)?;
        prop_assert_eq!(decode_command(&encode(&msg)), Ok(msg));
    }

    #[test]
    fn star_tracker_round_trip(
        header in header(),
        q in [any::<f64>(), any::<f64>(), any::<f64>(), any::<f64>()],
        valid in any::<bool>(),
        status_flags in any::<u8>(),
    ) {
        let msg = StarTrackerMsg { header, q_cn: q, valid, status_flags };
        round_trip_and_truncate(&msg)?;
        prop_assert_eq!(decode_star_tracker(&encode(&msg)), Ok(msg));
    }

    #[test]
    fn time_round_trip(msg in time()) {
        round_trip_and_truncate(&msg)?;
        let back = decode_time(&encode(&msg)).unwrap();
        // Bitwise: the speed may be a NaN.
        prop_assert_eq!(back.speed.to_bits(), msg.speed.to_bits());
        prop_assert_eq!(TimeMsg { speed: 0.0, ..back }, TimeMsg { speed: 0.0, ..msg });
    }

    #[test]
    fn operator_round_trip(msg in operator()) {
        round_trip_and_truncate(&msg)?;
        prop_assert_eq!(decode_operator(&encode(&msg)), Ok(msg));
    }

    /// Valid time and operator messages with random bytes overwritten: a message, or Malformed
    /// (an enum tag out of range), never a panic or another error (their lengths are fixed).
    #[test]
    fn mutated_time_and_operator_messages(
        t in time(),
        o in operator(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
    ) {
        let (mut bt, mut bo) = (encode(&t), encode(&o));
        for (i, v) in &edits {
            let at = i.index(bt.len());
            bt[at] = *v;
            let at = i.index(bo.len());
            bo[at] = *v;
        }
        decode_all(&bt);
        decode_all(&bo);
        let version_ok = |b: &[u8]| b[..2] == flexdyn_proto::PROTOCOL_VERSION.to_le_bytes();
        if version_ok(&bt) {
            let r = decode_time(&bt).map(|_| ());
            prop_assert!(matches!(r, Ok(()) | Err(DecodeError::Malformed(_))), "{:?}", r);
        }
        if version_ok(&bo) {
            let r = decode_operator(&bo).map(|_| ());
            prop_assert!(matches!(r, Ok(()) | Err(DecodeError::Malformed(_))), "{:?}", r);
        }
    }

    #[test]
    fn status_round_trip(msg in status()) {
        round_trip_and_truncate(&msg)?;
        prop_assert_eq!(decode_status(&encode(&msg)), Ok(msg));
    }

    /// Finite state messages compare equal after a round trip.
    #[test]
    fn finite_state_round_trip_eq(msg in state_with(any::<f64>())) {
        prop_assert_eq!(decode_state(&encode(&msg)), Ok(msg));
    }

    #[test]
    fn finite_imu_round_trip_eq(msg in imu().prop_filter("finite", |m| {
        [m.omega_p_rad_s, m.accel_p_m_s2, m.dtheta_p_rad, m.dv_p_m_s].iter().flatten().all(|x| x.is_finite())
    })) {
        prop_assert_eq!(decode_imu(&encode(&msg)), Ok(msg));
    }

    /// Any non-finite component in a wrench is rejected with NonFinite.
    #[test]
    fn non_finite_command_rejected(
        msg in command(),
        slot in 0usize..6,
        bad in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
    ) {
        let (mut t, mut f) = match msg.kind {
            CommandKind::Wrench { torque_b_nm, force_b_newton }
            | CommandKind::Actuators { torque_b_nm, force_b_newton, .. } => (torque_b_nm, force_b_newton),
            CommandKind::NoCommand => ([0.0; 3], [0.0; 3]),
        };
        if slot < 3 { t[slot] = bad } else { f[slot - 3] = bad }
        let cmd = CommandMsg::wrench(msg.header, msg.sender_id, t, f);
        let r = decode_command(&encode(&cmd));
        prop_assert!(matches!(r, Err(DecodeError::NonFinite { .. })), "{:?}", r);
    }
}

/// A message's view (its allocation-free reading) against its decoder: the same message, bit
/// for bit (NaN payloads included: the owned message from the view encodes to the same bytes as
/// the decoded one, and both to the input), for the bytes the decoder accepts; the same class of
/// error for the others.
fn view_agrees<'a, V>(bytes: &'a [u8]) -> Result<(), TestCaseError>
where
    V: MessageView<'a> + std::fmt::Debug,
    V::Msg: std::fmt::Debug,
{
    match (decode::<V::Msg>(bytes), V::read(bytes)) {
        (Ok(m), Ok(v)) => {
            let decoded = encode(&m);
            prop_assert_eq!(&encode(&v.to_msg()), &decoded);
            prop_assert_eq!(decoded.as_slice(), bytes);
        }
        (Err(e), Err(v)) => prop_assert_eq!(v, ViewError::of(&e), "{}", e),
        (d, v) => prop_assert!(false, "decode {:?} but view {:?}", d, v),
    }
    Ok(())
}

/// Every message's view against its decoder on the same bytes.
fn every_view_agrees(bytes: &[u8]) -> Result<(), TestCaseError> {
    use flexdyn_proto::view::*;
    view_agrees::<StateView>(bytes)?;
    view_agrees::<ImuView>(bytes)?;
    view_agrees::<StarTrackerView>(bytes)?;
    view_agrees::<MagnetometerView>(bytes)?;
    view_agrees::<CssView>(bytes)?;
    view_agrees::<FssView>(bytes)?;
    view_agrees::<GpsView>(bytes)?;
    view_agrees::<CommandView>(bytes)?;
    view_agrees::<TimeView>(bytes)?;
    view_agrees::<EnvironmentView>(bytes)?;
    view_agrees::<OperatorView>(bytes)?;
    view_agrees::<FaultEventView>(bytes)?;
    view_agrees::<FaultCommandView>(bytes)?;
    view_agrees::<RelativeStateView>(bytes)?;
    view_agrees::<StatusView>(bytes)?;
    view_agrees::<FswView>(bytes)?;
    Ok(())
}

/// The shortest encoding of every message (its whole length when fixed).
const MIN_LENS: [usize; 16] = [
    <StateMsg as WireMessage>::MIN_LEN,
    <ImuMsg as WireMessage>::MIN_LEN,
    <StarTrackerMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::MagnetometerMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::CssMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::FssMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::GpsMsg as WireMessage>::MIN_LEN,
    <CommandMsg as WireMessage>::MIN_LEN,
    <TimeMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::EnvironmentMsg as WireMessage>::MIN_LEN,
    <OperatorMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::FaultEventMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::FaultCommandMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::RelativeStateMsg as WireMessage>::MIN_LEN,
    <StatusMsg as WireMessage>::MIN_LEN,
    <flexdyn_proto::FswMsg as WireMessage>::MIN_LEN,
];

/// Bytes framed as one of the messages: the protocol version, then as many bytes as the
/// message's shortest encoding, mostly 0 and 1 (so that enum tags, bools, counts and text
/// padding are often valid and the accepting path is taken), the rest any byte.
fn framed() -> impl Strategy<Value = Vec<u8>> {
    let byte = prop_oneof![6 => Just(0u8), 1 => Just(1u8), 2 => any::<u8>()];
    (0..MIN_LENS.len())
        .prop_flat_map(move |i| prop::collection::vec(byte.clone(), MIN_LENS[i] - 2))
        .prop_map(|body| {
            let mut bytes = flexdyn_proto::PROTOCOL_VERSION.to_le_bytes().to_vec();
            bytes.extend(body);
            bytes
        })
}

/// `bytes` with each bit flipped with probability `p` (xorshift64* from `seed`), as a
/// `corrupted` command link damages a command.
fn damage(bytes: &mut [u8], seed: u64, p: f64) {
    let mut s = seed | 1;
    for b in bytes.iter_mut() {
        for bit in 0..8 {
            // xorshift64*: a uniform u in [0, 1) per bit.
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            let u = (s.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64;
            if u < p {
                *b ^= 1 << bit;
            }
        }
    }
}

/// Every view against its decoder on `bytes`, then on `bytes` damaged, then truncated and
/// extended by `cut` bytes.
fn damaged_views_agree(
    mut bytes: Vec<u8>,
    seed: u64,
    p: f64,
    cut: usize,
) -> Result<(), TestCaseError> {
    every_view_agrees(&bytes)?;
    damage(&mut bytes, seed, p);
    every_view_agrees(&bytes)?;
    let short = bytes.len().saturating_sub(cut);
    every_view_agrees(&bytes[..short])?;
    bytes.extend(std::iter::repeat_n(0u8, cut));
    every_view_agrees(&bytes)
}

/// A FswMsg with any bits in its floats (NaN, infinities), up to 9 events (one beyond the
/// maximum) and up to 12 value words.
fn fsw_sample() -> impl Strategy<Value = flexdyn_proto::FswMsg> {
    (
        header(),
        any::<u8>(),
        any::<u32>(),
        prop::array::uniform4(any_bits_f64()),
        prop::array::uniform4(any_bits_f64()),
        prop::array::uniform3(any_bits_f64()),
        0u8..10,
        prop::array::uniform8(any::<u16>()),
        prop::collection::vec(any::<u64>(), 0..12),
    )
        .prop_map(
            |(
                header,
                flags,
                mode,
                q_est_bn,
                q_target_rn,
                att_var_b_rad2,
                event_count,
                events,
                values,
            )| {
                flexdyn_proto::FswMsg {
                    header,
                    flags,
                    mode,
                    q_est_bn,
                    q_target_rn,
                    att_var_b_rad2,
                    event_count,
                    events,
                    values,
                }
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2048))]

    #[test]
    fn every_view_agrees_with_its_decoder_on_arbitrary_bytes(
        bytes in prop::collection::vec(any::<u8>(), 0..300)
    ) {
        every_view_agrees(&bytes)?;
    }

    /// Bytes framed as each message in turn (version and length right, the body mostly 0 and
    /// 1), then damaged, truncated or extended.
    #[test]
    fn every_view_agrees_with_its_decoder_on_framed_bytes(
        bytes in framed(),
        seed in any::<u64>(),
        p in prop_oneof![Just(0.0), 1e-4..0.05f64],
        cut in 0usize..8,
    ) {
        damaged_views_agree(bytes, seed, p, cut)?;
    }

    /// Commands of every kind (any bit pattern in the numbers: NaN, infinities), then damaged
    /// as a `corrupted` link damages them (a bit flipped with probability p, p from 10⁻⁴ to 1/2),
    /// then truncated or extended.
    #[test]
    fn every_view_agrees_with_its_decoder_on_damaged_commands(
        msg in command_with(any_bits_f64),
        seed in any::<u64>(),
        p in prop_oneof![Just(0.0), 1e-4..0.5f64],
        cut in 0usize..8,
    ) {
        damaged_views_agree(encode(&msg), seed, p, cut)?;
    }

    /// Flight-code samples with any field values, then damaged, truncated or extended.
    #[test]
    fn every_view_agrees_with_its_decoder_on_damaged_samples(
        msg in fsw_sample(),
        seed in any::<u64>(),
        p in prop_oneof![Just(0.0), 1e-4..0.05f64],
        cut in 0usize..8,
    ) {
        damaged_views_agree(encode(&msg), seed, p, cut)?;
    }

    /// State messages (effectors with states and outputs, any bits in the floats), then
    /// damaged, truncated or extended.
    #[test]
    fn every_view_agrees_with_its_decoder_on_damaged_states(
        msg in state(),
        seed in any::<u64>(),
        p in prop_oneof![Just(0.0), 1e-4..0.05f64],
        cut in 0usize..8,
    ) {
        damaged_views_agree(encode(&msg), seed, p, cut)?;
    }

    /// Status and time messages (enums, bools, nested structs), then damaged, truncated or
    /// extended.
    #[test]
    fn every_view_agrees_with_its_decoder_on_damaged_status_and_time(
        status in status(),
        time in time(),
        seed in any::<u64>(),
        p in prop_oneof![Just(0.0), 1e-4..0.05f64],
        cut in 0usize..8,
    ) {
        damaged_views_agree(encode(&status), seed, p, cut)?;
        damaged_views_agree(encode(&time), seed, p, cut)?;
    }
}

/// The text rule, byte by byte, in the view and the decoder alike (the case: a target,
/// NULs, then a 0x80 byte is refused; a target that fills all 128 bytes has no padding and is
/// accepted; a NUL first and text after it is refused).
#[test]
fn the_views_apply_the_text_rule_as_the_decoders_do() {
    use flexdyn_proto::view::{view_fault_command, view_fault_event};
    use flexdyn_proto::{
        FaultCommandMsg, FaultEventMsg, FaultTarget, FAULT_COMMAND_TARGET_OFFSET,
        FAULT_EVENT_TARGET_OFFSET,
    };
    let command = FaultCommandMsg {
        target: FaultTarget::new("imus.hub.gyro").unwrap(),
        ..FaultCommandMsg::default()
    };
    let event = FaultEventMsg {
        target: FaultTarget::new("imus.hub.gyro").unwrap(),
        ..FaultEventMsg::default()
    };
    let cases = [
        (encode(&command), FAULT_COMMAND_TARGET_OFFSET),
        (encode(&event), FAULT_EVENT_TARGET_OFFSET),
    ];
    for (good, at) in cases {
        let classes = |b: &[u8]| {
            let v = view_fault_command(b)
                .map(|_| ())
                .or_else(|_| view_fault_event(b).map(|_| ()));
            let d = flexdyn_proto::decode_fault_command(b)
                .map(|_| ())
                .or_else(|_| flexdyn_proto::decode_fault_event(b).map(|_| ()));
            (v.is_ok(), d.is_ok())
        };
        assert_eq!(classes(&good), (true, true));
        let mut after_nul = good.clone();
        after_nul[at + 20] = 0x80;
        assert_eq!(classes(&after_nul), (false, false), "a byte after the NUL");
        let mut nul_first = good.clone();
        nul_first[at] = 0;
        assert_eq!(
            classes(&nul_first),
            (false, false),
            "text after a leading NUL"
        );
        let mut full = good.clone();
        full[at..at + 128].fill(b'x');
        assert_eq!(classes(&full), (true, true), "128 bytes of text");
    }
}
