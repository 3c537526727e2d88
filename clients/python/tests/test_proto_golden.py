"""The Python codec against the golden vectors (proto/golden/, pinned by proto/tests/golden.rs):
encoding the table values gives the golden bytes, decoding the golden bytes gives the values."""

import math
import struct

import pytest

from flexdyn import proto
from flexdyn.proto import (CommandMsg, DecodeError, EffectorInput, EffectorState, Header,
                           ImuMsg, MagnetometerMsg, OperatorMsg, StarTrackerMsg, StateMsg,
                           StatusMsg, TimeMsg, CssMsg, FssMsg)

SC = 0x11223344


def bits(x):
    return [struct.pack("<d", v) for v in x]


def test_manifest_lists_every_file(golden_dir):
    rows = [l.split("\t") for l in (golden_dir / "MANIFEST.tsv").read_text().splitlines()
            if l and not l.startswith("#")]
    assert len(rows) == 19
    for name, _message, length, _source in rows:
        assert (golden_dir / f"{name}.bin").stat().st_size == int(length)


def test_state(golden_dir):
    golden = (golden_dir / "state.bin").read_bytes()
    m = StateMsg(
        Header(SC, 0x0102030405060708, 1_500_000_000, 0x102),
        (0.125, -0.25, 0.5), (0.875, 0.25, -0.375, 0.1875),
        (1 / 1024, -2 / 1024, 4 / 1024), (1.5, -3.0, 6.0), (7_000_000.0, -1024.0, 0.5),
        (0.25, 7500.0, -8.0), (0.0, -0.0, 1 / 1_048_576), -2.5e10, 12.5,
        (1.0e12, -2.0, 4.0), (100.0, -0.75, 1.25), (0.0625, -0.125, 0.25), (1.0, -2.0, 3.0),
        proto.COMMAND_FLAG_STALE | proto.COMMAND_FLAG_NO_COMMAND_YET,
        [EffectorState(proto.PANEL_PAIR, 0, [0.5, -0.0625, 1.25, 0.03125], []),
         EffectorState(proto.REACTION_WHEEL, proto.WHEEL_TORQUE_LIMITED | proto.WHEEL_SPEED_LIMITED,
                       [-150.5], [0.25, -0.0078125])])
    assert m.encode() == golden
    back = StateMsg.decode(golden)
    assert back == m
    assert bits(back.nongrav_accel_bn_n_m_s2) == bits(m.nongrav_accel_bn_n_m_s2)  # -0.0 kept
    with pytest.raises(DecodeError) as e:
        StateMsg.decode(golden[:389])
    assert (e.value.reason, e.value.info["needed"]) == ("Length", 395)


def test_imu_and_star_tracker(golden_dir):
    m = ImuMsg(Header(SC, 9, 9_000_000, 10), (1 / 1024, -0.5, 2.0), (0.0, 9.75, -0.125),
               (1 / 1_048_576, -2 / 1_048_576, 4 / 1_048_576), (0.001, -1.5, 3.0),
               proto.SATURATION_GYRO_RATE | proto.SATURATION_DV)
    golden = (golden_dir / "imu.bin").read_bytes()
    assert m.encode() == golden and ImuMsg.decode(golden) == m
    s = StarTrackerMsg(Header(SC, 11, 110_000_000, 12), (0.875, 0.25, -0.375, 0.1875), False,
                       proto.STAR_TRACKER_SUN_EXCLUSION)
    golden = (golden_dir / "star_tracker.bin").read_bytes()
    assert s.encode() == golden and StarTrackerMsg.decode(golden) == s
    bad = bytearray(golden)
    bad[62] = 2
    with pytest.raises(DecodeError) as e:
        StarTrackerMsg.decode(bytes(bad))
    assert e.value.reason == "Malformed"


def test_magnetometer(golden_dir):
    m = MagnetometerMsg(Header(SC, 13, 130_000_000, 1), (2.0**-15, -(2.0**-16), -0.0),
                        proto.MAGNETOMETER_AXIS_1 | proto.MAGNETOMETER_AXIS_3)
    golden = (golden_dir / "magnetometer.bin").read_bytes()
    assert m.encode() == golden
    back = MagnetometerMsg.decode(golden)
    assert back == m and bits(back.b_s_t) == bits(m.b_s_t)  # -0.0 keeps its sign
    with pytest.raises(DecodeError) as e:
        MagnetometerMsg.decode(golden[:-1])
    assert e.value.reason == "Length"


def test_sun_sensors(golden_dir):
    c = CssMsg(Header(SC, 13, 130_000_000, 1), 3, (0.5, 0.75, 2.0**-10) + (0.0,) * 13)
    golden = (golden_dir / "css.bin").read_bytes()
    assert c.encode() == golden and CssMsg.decode(golden) == c
    bad = bytearray(golden)
    bad[30] = proto.MAX_CSS_DETECTORS + 1
    with pytest.raises(DecodeError) as e:
        CssMsg.decode(bytes(bad))
    assert e.value.reason == "Malformed"
    f = FssMsg(Header(SC, 13, 130_000_000, 1), 0.125, -0.0625,
               proto.FSS_VALID | proto.FSS_IN_FOV | proto.FSS_SUNLIT)
    golden = (golden_dir / "fss.bin").read_bytes()
    assert f.encode() == golden and FssMsg.decode(golden) == f
    with pytest.raises(DecodeError) as e:
        FssMsg.decode(golden[:-1])
    assert e.value.reason == "Length"
    assert proto.css_key("sc1", "css1") == "flexdyn/sc1/tlm/css/css1"
    assert proto.fss_key("sc1", "fss1") == "flexdyn/sc1/tlm/fss/fss1"


def test_commands(golden_dir):
    w = CommandMsg(Header(SC, 42, 420_000_000, 7), 0xDEADBEEF, proto.WRENCH,
                   (0.0625, -0.125, 0.25), (-1.0, 0.0, 0.5))
    golden = (golden_dir / "command_wrench.bin").read_bytes()
    assert w.encode() == golden and CommandMsg.decode(golden) == w
    a = CommandMsg(Header(SC, 44, 440_000_000, 9), 7, proto.ACTUATORS, (0.5, -0.25, 0.0),
                   (0.0, 0.0, -0.0), [EffectorInput(2, [0.0625]), EffectorInput(5, [-0.03125])])
    golden = (golden_dir / "command_actuators.bin").read_bytes()
    assert a.encode() == golden and CommandMsg.decode(golden) == a
    n = CommandMsg(Header(SC, 43, 430_000_000, 8), 5, proto.NO_COMMAND_KIND)
    golden = (golden_dir / "command_no_command.bin").read_bytes()
    assert n.encode() == golden and CommandMsg.decode(golden) == n
    bad = CommandMsg(Header(SC, 1, 0, 0), 1, proto.WRENCH, (0.0, 0.0, math.nan))
    with pytest.raises(DecodeError) as e:
        CommandMsg.decode(bad.encode())
    assert (e.value.reason, e.value.info["field"]) == ("NonFinite", "kind.torque_b_nm[2]")


def test_status(golden_dir):
    m = StatusMsg(Header(SC, 0x0102030405060708, 1_500_000_000, 99), proto.MODE_LOCKSTEP, 1,
                  1000, 250_000, 3_000_000, 3, 2, 41, 1_000_000, True, proto.STALE_POLICY_ZERO,
                  1, 2, 3, 4, 5, 6, 8, 9, 10, 11, 12, 7, 1_700_000_000_123_456_789,
                  3, (0b101, 0, 0, 1 << 63))
    golden = (golden_dir / "status.bin").read_bytes()
    assert m.encode() == golden and StatusMsg.decode(golden) == m
    assert len(golden) == proto.STATUS_LEN == 243
    assert [i for i in range(300) if m.fault_active(i)] == [0, 2, 255]


def test_time(golden_dir):
    # TIME_GOLDEN of proto/tests/golden.rs: 2016-12-31T23:59:60.25 UTC, paused at tick 6.
    m = TimeMsg(Header(SC, 6, 750_000_000, 6), proto.RUN_STATE_PAUSED, proto.MODE_REAL_TIME,
                proto.TIME_EPOCH_VALID | proto.TIME_LEAP_SECOND, 125_000_000, 0.5,
                1_861_920_036_250_000_000, (2016, 12, 31, 23, 59, 60, 250_000_000), 36, 1930,
                17_250_000_000, 750_000_000, bytes([0x1F, 0x6E, 0xFA, 0xA5, 0x24, 0x40, 0, 0]),
                (0, 0x8000_0000), (1_861_920_036, 0))
    golden = (golden_dir / "time.bin").read_bytes()
    assert m.encode() == golden and TimeMsg.decode(golden) == m
    assert m.paused and not m.tone
    bad = bytearray(golden)
    bad[30] = 7
    with pytest.raises(DecodeError) as e:
        TimeMsg.decode(bytes(bad))
    assert e.value.reason == "Malformed"
    with pytest.raises(DecodeError) as e:
        TimeMsg.decode(golden[:-1])
    assert e.value.reason == "Length"
    assert proto.time_key("sc1") == "flexdyn/sc1/tlm/time"


def test_operator(golden_dir):
    # OPERATOR_GOLDEN of proto/tests/golden.rs: run 0x1_0000_0005 ticks.
    m = OperatorMsg(Header(SC, 44, 440_000_000, 3), proto.OPERATOR_RUN_TICKS, 0x1_0000_0005)
    golden = (golden_dir / "operator.bin").read_bytes()
    assert len(golden) == proto.OPERATOR_LEN
    assert m.encode() == golden and OperatorMsg.decode(golden) == m
    bad = bytearray(golden)
    bad[30] = 4
    with pytest.raises(DecodeError) as e:
        OperatorMsg.decode(bytes(bad))
    assert e.value.reason == "Malformed"
    with pytest.raises(DecodeError) as e:
        OperatorMsg.decode(golden + b"\0")
    assert e.value.reason == "TrailingBytes"
    assert proto.operator_key("sc1") == "flexdyn/sc1/operator"


def test_operator_checkpoint(golden_dir):
    # OPERATOR_CHECKPOINT_GOLDEN of proto/tests/golden.rs (protocol 12): save at tick 1000.
    m = OperatorMsg(Header(SC, 44, 440_000_000, 4), proto.OPERATOR_CHECKPOINT, 1000)
    golden = (golden_dir / "operator_checkpoint.bin").read_bytes()
    assert len(golden) == proto.OPERATOR_LEN
    assert golden[30:34] == b"\x03\x00\x00\x00" and golden[34:42] == (1000).to_bytes(8, "little")
    assert m.encode() == golden and OperatorMsg.decode(golden) == m


def test_versions_and_keys():
    with pytest.raises(DecodeError) as e:
        Header.decode(b"\x02\x00" + bytes(40))
    assert (e.value.reason, e.value.info["found"]) == ("UnknownVersion", 2)
    assert proto.star_tracker_key("sc1", "st1") == "flexdyn/sc1/tlm/st/st1"
    assert proto.magnetometer_key("sc1", "mag1") == "flexdyn/sc1/tlm/mag/mag1"
    assert proto.participant_key("sc-1", 7) == "flexdyn/sc-1/participant/7"
    assert proto.command_key("sc-1", 7) == "flexdyn/sc-1/cmd/7"
    assert proto.command_key("sc1", 4294967295) == "flexdyn/sc1/cmd/4294967295"
    for bad in (-1, 2**32, "1"):
        with pytest.raises(ValueError):
            proto.command_key("sc1", bad)
    with pytest.raises(ValueError):
        proto.imu_key("sc1", "a/b")


def test_environment(golden_dir):
    # ENVIRONMENT_GOLDEN of proto/tests/golden.rs (dyadic values, one -0.0, penumbra).
    from flexdyn.proto import EnvironmentMsg, SourceWrench
    m = EnvironmentMsg(
        Header(SC, 17, 170_000_000, 2), 0x0102030405060708,
        proto.ENVIRONMENT_EPOCH_VALID | proto.ENVIRONMENT_MAGNETIC | proto.ENVIRONMENT_SUN
        | proto.ENVIRONMENT_SHADOW | proto.ENVIRONMENT_ATMOSPHERE | proto.ENVIRONMENT_ALBEDO,
        proto.ECLIPSE_PENUMBRA,
        (2.0**-15, -(2.0**-16), 2.0**-17), (-0.0, 2.0**-14, -(2.0**-18)), (0.5, -0.5, 0.75),
        (0.25, 1.0, -0.125), (-1.0, 0.375, 0.0625), 0.625, 2.0**-40,
        SourceWrench((2.0**-20, -(2.0**-21), 2.0**-22), (2.0**-30, 0.0, -(2.0**-31))),
        SourceWrench((1.5, -2.5, 3.5), (4.0, -8.0, 16.0)),
        SourceWrench((2.0**-24, 2.0**-25, 2.0**-26), (-(2.0**-24), -(2.0**-25), -(2.0**-26))),
        SourceWrench((0.125, -0.25, 2.0**-7), (0.0, 0.0, 0.0)), 0.171875)
    golden = (golden_dir / "environment.bin").read_bytes()
    assert len(golden) == proto.ENVIRONMENT_LEN
    assert m.encode() == golden
    back = EnvironmentMsg.decode(golden)
    assert back == m and bits(back.b_b_t) == bits(m.b_b_t)  # -0.0 keeps its sign
    assert back.eclipse_name == "penumbra"
    assert proto.environment_key("sc1") == "flexdyn/sc1/tlm/env"
    with pytest.raises(DecodeError) as e:
        EnvironmentMsg.decode(golden[:-1])
    assert e.value.reason == "Length"


def test_gps(golden_dir):
    # GPS_GOLDEN of proto/tests/golden.rs (protocol 7; dyadic values, one -0.0).
    from flexdyn.proto import GpsMsg
    m = GpsMsg(Header(SC, 13, 130_000_000, 1), 30_000_000, 2394, 86_400.5, (1.5, -2.0, 0.25),
               (0.5, -0.0, 4.0), (8.0, 0.125, -1.0), (3.0, -0.5, 1024.0),
               proto.GPS_FIX | proto.GPS_ECEF | proto.GPS_INERTIAL)
    golden = (golden_dir / "gps.bin").read_bytes()
    assert len(golden) == proto.GPS_LEN == 147
    assert m.encode() == golden
    back = GpsMsg.decode(golden)
    assert back == m and bits(back.v_be_e_m_s) == bits(m.v_be_e_m_s)  # -0.0 keeps its sign
    assert back.flags == 0x07
    assert proto.gps_key("sc1", "gps1") == "flexdyn/sc1/tlm/gps/gps1"
    with pytest.raises(DecodeError) as e:
        GpsMsg.decode(golden[:-1])
    assert e.value.reason == "Length"


def test_fault_event_and_command(golden_dir):
    # FAULT_EVENT_GOLDEN and FAULT_COMMAND_GOLDEN of proto/tests/golden.rs (protocol 8).
    from flexdyn.proto import FaultCommandMsg, FaultEventMsg
    ev = FaultEventMsg(Header(SC, 44, 440_000_000, 1), 3, proto.FAULT_SOURCE_LIVE, 2, True,
                       440_000_000, 0b101, (0.25, 0.0), b"imus.hub.gyro" + bytes(115))
    golden = (golden_dir / "fault_event.bin").read_bytes()
    assert len(golden) == proto.FAULT_EVENT_LEN == 199
    assert ev.encode() == golden and FaultEventMsg.decode(golden) == ev
    assert ev.target_str == "imus.hub.gyro" and ev.mode_name == "bias_step"
    bad = bytearray(golden)
    bad[42] = 2
    with pytest.raises(DecodeError) as e:
        FaultEventMsg.decode(bytes(bad))
    assert e.value.reason == "Malformed"
    # The text rule: "imus.hub.gyro", NULs, then 0x80 is refused; 128 bytes without a NUL pass.
    bad = bytearray(golden)
    bad[71 + 127] = 0x80
    with pytest.raises(DecodeError) as e:
        FaultEventMsg.decode(bytes(bad))
    assert e.value.reason == "Malformed"
    bad[71:199] = b"x" * 128
    assert FaultEventMsg.decode(bytes(bad)).target_str == "x" * 128
    # The SDK's builder gives the golden command from names.
    cmd = proto.fault_command(SC, "reaction_wheels.rw2", "torque_limit", at_tick=0x1_0000_0005,
                              duration_ns=2_000_000_000, seed=7, seq=2, tick=44, fraction=0.5)
    cmd.header.sim_time_ns = 440_000_000
    golden = (golden_dir / "fault_command.bin").read_bytes()
    assert len(golden) == proto.FAULT_COMMAND_LEN == 214
    assert cmd.encode() == golden and FaultCommandMsg.decode(golden) == cmd
    bad = bytearray(golden)
    bad[58:66] = struct.pack("<d", float("nan"))
    with pytest.raises(DecodeError) as e:
        FaultCommandMsg.decode(bytes(bad))
    assert e.value.reason == "NonFinite" and e.value.canonical() == "E NonFinite params[1]"
    bad[86 + 20] = 0x80  # after "reaction_wheels.rw2" and its NUL: the text rule comes first
    with pytest.raises(DecodeError) as e:
        FaultCommandMsg.decode(bytes(bad))
    assert e.value.reason == "Malformed"
    with pytest.raises(ValueError):
        proto.fault_command(SC, "imus.hub.gyro", "bias_step", value=1.0, factor=2.0)
    assert proto.fault_key("sc1") == "flexdyn/sc1/fault"
    assert proto.fault_event_key("sc1") == "flexdyn/sc1/tlm/fault"


def test_relative_state(golden_dir):
    # RELATIVE_STATE_GOLDEN of proto/tests/golden.rs (protocol 9; dyadic values, one -0.0).
    from flexdyn.proto import RelativeStateMsg
    m = RelativeStateMsg(Header(SC, 1000, 10_000_000_000, 1000), 1, SC, (0.5, -100.0, 2.25),
                         (0.125, -0.0, -3.5), 100.03125, -0.25)
    golden = (golden_dir / "relative_state.bin").read_bytes()
    assert len(golden) == proto.RELATIVE_STATE_LEN == 102
    assert m.encode() == golden
    back = RelativeStateMsg.decode(golden)
    assert back == m and bits(back.v_dc_h_m_s) == bits(m.v_dc_h_m_s)  # -0.0 keeps its sign
    assert proto.relative_state_key("deputy", "chief") == "flexdyn/deputy/tlm/rel/chief"
    with pytest.raises(DecodeError) as e:
        RelativeStateMsg.decode(golden[:-1])
    assert e.value.reason == "Length"
    with pytest.raises(DecodeError) as e:
        RelativeStateMsg.decode(b"\x08\x00" + golden[2:])
    assert e.value.reason == "UnknownVersion"


def test_fsw(golden_dir):
    # FSW_GOLDEN of proto/tests/golden.rs (protocol 10): every optional field, two events, three
    # value words: an f64 (-1.5), an i64 (-2) and a bool (true).
    from flexdyn.proto import FswMsg
    words = [struct.unpack("<Q", struct.pack("<d", -1.5))[0], (-2) & 0xFFFFFFFFFFFFFFFF, 1]
    m = FswMsg(Header(SC, 1000, 10_000_000_000, 7),
               proto.FSW_MODE | proto.FSW_ESTIMATE | proto.FSW_TARGET | proto.FSW_COVARIANCE, 2,
               (0.5, -0.5, 0.5, -0.5), (1.0, 0.0, -0.0, 0.0), (0.25, 0.125, 2.0 ** -20), 2,
               (3, 0x0102, 0, 0, 0, 0, 0, 0), words)
    golden = (golden_dir / "fsw.bin").read_bytes()
    assert len(golden) == proto.FSW_FIXED_LEN + 3 * 8 == 172
    assert m.encode() == golden
    back = FswMsg.decode(golden)
    assert back == m and bits(back.q_target_rn) == bits(m.q_target_rn)  # -0.0 keeps its sign
    assert proto.fsw_key("sc1", "acs") == "flexdyn/sc1/fsw/acs"
    bad = bytearray(golden)
    bad[123] = 9
    with pytest.raises(DecodeError) as e:
        FswMsg.decode(bytes(bad))
    assert e.value.reason == "Malformed"
    bad = bytearray(golden)
    bad[35:43] = struct.pack("<d", math.nan)
    with pytest.raises(DecodeError) as e:
        FswMsg.decode(bytes(bad))
    assert e.value.reason == "NonFinite" and e.value.info["field"] == "q_est_bn[0]"

