"""Differential fuzz: the Python decoders against the Rust decoders (`flexdyn-decode-verdicts`)
on 20,000 seeded buffers (valid messages of every type, edited, cut, extended, random with a
valid version, oversized). They must agree on accept/reject, on the reason and its numbers or
field, and on every decoded field bit for bit; every accepted buffer must re-encode to itself."""

import math
import random
import struct
import subprocess

from flexdyn import proto
from flexdyn.proto import (CommandMsg, DecodeError, EffectorInput, EffectorState, Header,
                           ImuMsg, MagnetometerMsg, OperatorMsg, StarTrackerMsg, StateMsg,
                           StatusMsg, TimeMsg, CssMsg, FssMsg, EnvironmentMsg, SourceWrench)
from flexdyn.proto import GpsMsg  # protocol 7: the thirteenth decoder, generator arm 11
from flexdyn.proto import FaultCommandMsg, FaultEventMsg  # protocol 8: decoders 14-15, arms 12-13
from flexdyn.proto import RelativeStateMsg  # protocol 9: decoder 16, arm 14
from flexdyn.proto import FswMsg  # protocol 10: decoder 17, arm 15

N = 20_000


class Line:
    def __init__(self):
        self.parts = ["O"]

    def u(self, *v):
        self.parts += [format(int(x), "x") for x in v]
        return self

    def f(self, v):
        self.parts += [format(struct.unpack("<Q", struct.pack("<d", x))[0], "x") for x in v]
        return self

    def h(self, h):
        return self.u(h.protocol_version, h.spacecraft_id, h.tick, h.sim_time_ns, h.seq)

    def __str__(self):
        return " ".join(self.parts)


def state_line(m):
    l = Line().h(m.header)
    for v in (m.sigma_bn, m.q_bn, m.omega_bn_b_rad_s, m.omega_dot_bn_b_rad_s2, m.r_bn_n_m,
              m.v_bn_n_m_s, m.nongrav_accel_bn_n_m_s2, (m.orb_energy_j, m.rot_energy_j),
              m.orb_ang_mom_n, m.rot_ang_mom_c_n, m.torque_b_nm, m.force_b_newton):
        l.f(v)
    l.u(m.command_flags, len(m.effectors))
    for e in m.effectors:
        l.u(e.kind, e.flags, len(e.states)).f(e.states).u(len(e.outputs)).f(e.outputs)
    return str(l)


def imu_line(m):
    return str(Line().h(m.header).f(m.omega_p_rad_s).f(m.accel_p_m_s2).f(m.dtheta_p_rad)
               .f(m.dv_p_m_s).u(m.saturation_flags))


def star_tracker_line(m):
    return str(Line().h(m.header).f(m.q_cn).u(m.valid, m.status_flags))


def magnetometer_line(m):
    return str(Line().h(m.header).f(m.b_s_t).u(m.saturation_flags))


def css_line(m):
    return str(Line().h(m.header).u(m.detector_count).f(m.readings))


def fss_line(m):
    return str(Line().h(m.header).f((m.alpha_rad, m.beta_rad)).u(m.flags))


def environment_line(m):
    l = Line().h(m.header).u(m.tai_ns_1958, m.flags, m.eclipse)
    l.f(m.b_n_t).f(m.b_b_t).f(m.sun_n).f(m.sun_b).f(m.moon_n).f((m.shadow_factor, m.density_kg_m3))
    for s in EnvironmentMsg.SOURCES:
        w = getattr(m, s)
        l.f(w.torque_b_nm).f(w.force_b_newton)
    return str(l)


def command_line(m):
    l = Line().h(m.header).u(m.sender_id, m.kind)
    if m.kind != proto.NO_COMMAND_KIND:
        l.f(m.torque_b_nm).f(m.force_b_newton)
    if m.kind == proto.ACTUATORS:
        l.u(len(m.inputs))
        for i in m.inputs:
            l.u(i.effector_index, len(i.values)).f(i.values)
    return str(l)


def status_line(m):
    return str(Line().h(m.header).u(
        m.mode, m.run_state, m.lateness_p50_ns, m.lateness_p99_ns, m.lateness_max_ns,
        m.overrun_count, m.frames_skipped, m.last_command_tick, m.command_age_ns,
        m.command_stale, m.stale_policy, m.rejected_malformed, m.rejected_bad_version,
        m.rejected_non_finite, m.rejected_wrong_spacecraft, m.rejected_stale_tick,
        m.rejected_unknown_sender, m.rejected_bad_effector_input, m.rejected_wrong_identity,
        m.rejected_operator_refused, m.rejected_fault_refused, m.rejected_fsw_refused,
        m.commands_dropped,
        m.wall_time_unix_ns, m.faults_active, *m.faults_active_bits))


def time_line(m):
    return str(Line().h(m.header).u(m.run_state, m.mode, m.flags, m.frame_ns).f([m.speed])
               .u(m.tai_ns_1958, *m.utc, m.tai_minus_utc_s & 0xFFFFFFFF, m.gps_week,
                  m.gps_ns_of_week, m.met_ns, *m.cuc_tai, *m.tone_met, *m.tone_tai))


def operator_line(m):
    return str(Line().h(m.header).u(m.action, m.ticks))


def gps_line(m):
    return str(Line().h(m.header).u(m.valid_sim_time_ns, m.gps_week).f([m.gps_seconds_of_week])
               .f(m.r_be_e_m).f(m.v_be_e_m_s).f(m.r_bn_n_m).f(m.v_bn_n_m_s).u(m.flags))


def fault_event_line(m):
    return str(Line().h(m.header).u(m.fault_index, m.source, m.mode, m.active, m.edge_ns, m.axes)
               .f(m.params).u(*m.target))


def fault_command_line(m):
    return str(Line().h(m.header).u(m.action, m.at_tick, m.fault_index, m.mode).f(m.params)
               .u(m.axes, m.duration_ns, m.seed, *m.target))


def relative_state_line(m):
    return str(Line().h(m.header).u(m.chief_spacecraft_id, m.deputy_spacecraft_id)
               .f(m.r_dc_h_m).f(m.v_dc_h_m_s).f((m.range_m, m.range_rate_m_s)))


def fsw_line(m):
    return str(Line().h(m.header).u(m.flags, m.mode).f(m.q_est_bn).f(m.q_target_rn)
               .f(m.att_var_b_rad2).u(m.event_count, *m.events, len(m.values), *m.values))


DECODERS = [
    (StateMsg.decode, state_line), (ImuMsg.decode, imu_line),
    (StarTrackerMsg.decode, star_tracker_line), (MagnetometerMsg.decode, magnetometer_line),
    (CssMsg.decode, css_line), (FssMsg.decode, fss_line),
    (EnvironmentMsg.decode, environment_line), (CommandMsg.decode, command_line),
    (StatusMsg.decode, status_line), (TimeMsg.decode, time_line),
    (OperatorMsg.decode, operator_line), (Header.decode, lambda h: str(Line().h(h))),
    (GpsMsg.decode, gps_line),
    (FaultEventMsg.decode, fault_event_line), (FaultCommandMsg.decode, fault_command_line),
    (RelativeStateMsg.decode, relative_state_line),
    (FswMsg.decode, fsw_line),
]


def python_lines(buf):
    out = []
    for decode, line in DECODERS:
        try:
            m = decode(buf)
        except DecodeError as e:
            out.append(e.canonical())
            continue
        if decode is not Header.decode and m.encode() != buf:
            out.append("E ReencodeDiffers")
        else:
            out.append(line(m))
    return out


def gen_buffer(r):
    def f64():
        k = r.randrange(8)
        if k == 0:
            return struct.unpack("<d", r.getrandbits(64).to_bytes(8, "little"))[0]
        if k == 1:
            return r.choice([math.nan, math.inf, -math.inf, -0.0])
        return r.uniform(-4096, 4096)

    def fin():
        x = f64()
        return x if math.isfinite(x) else 1.5

    def v(n, g=f64):
        return tuple(g() for _ in range(n))

    def header():
        return Header(r.getrandbits(32), r.getrandbits(64), r.getrandbits(64), r.getrandbits(64))

    k = r.randrange(16)
    if k == 0:
        b = StateMsg(header(), v(3), v(4), v(3), v(3), v(3), v(3), v(3), f64(), f64(), v(3), v(3),
                     v(3), v(3), r.getrandbits(8),
                     [EffectorState(r.getrandbits(16), r.getrandbits(32), list(v(r.randrange(9))),
                                    list(v(r.randrange(9)))) for _ in range(r.randrange(6))]).encode()
    elif k == 1:
        b = ImuMsg(header(), v(3), v(3), v(3), v(3), r.getrandbits(8)).encode()
    elif k == 2:
        b = StarTrackerMsg(header(), v(4), r.random() < 0.5, r.getrandbits(8)).encode()
    elif k == 5:
        b = MagnetometerMsg(header(), v(3), r.getrandbits(8)).encode()
    elif k == 8:  # counts up to 17: the last is above the maximum (Malformed)
        b = CssMsg(header(), r.randrange(18), v(proto.MAX_CSS_DETECTORS)).encode()
    elif k == 9:
        b = FssMsg(header(), f64(), f64(), r.getrandbits(8)).encode()
    elif k == 3:
        g = fin if r.randrange(4) else f64
        kind = r.randrange(3)
        b = CommandMsg(header(), r.getrandbits(32), kind, v(3, g), v(3, g),
                       [EffectorInput(r.getrandbits(32), list(v(r.randrange(9), g)))
                        for _ in range(r.randrange(5))] if kind == proto.ACTUATORS else []).encode()
    elif k == 4:
        b = StatusMsg(header(), r.randrange(3), r.randrange(6), *(r.getrandbits(64) for _ in range(7)),
                      r.random() < 0.5, r.randrange(2), *(r.getrandbits(64) for _ in range(14)),
                      tuple(r.getrandbits(64) for _ in range(4))).encode()
    elif k == 6:
        b = TimeMsg(header(), r.randrange(7), r.randrange(3), r.getrandbits(8), r.getrandbits(64),
                    f64(), r.getrandbits(64),
                    (r.getrandbits(16), *(r.getrandbits(8) for _ in range(5)), r.getrandbits(32)),
                    r.getrandbits(31) - 2**30, r.getrandbits(32), r.getrandbits(64),
                    r.getrandbits(64), r.getrandbits(64).to_bytes(8, "little"),
                    (r.getrandbits(32), r.getrandbits(32)),
                    (r.getrandbits(32), r.getrandbits(32))).encode()
    elif k == 7:
        b = OperatorMsg(header(), r.randrange(3), r.getrandbits(64)).encode()
    elif k == 10:
        def wrench():
            return SourceWrench(v(3), v(3))
        b = EnvironmentMsg(header(), r.getrandbits(64), r.getrandbits(8), r.getrandbits(8), v(3),
                           v(3), v(3), v(3), v(3), f64(), f64(), wrench(), wrench(), wrench(),
                           wrench()).encode()
    elif k == 11:
        b = GpsMsg(header(), r.getrandbits(64), r.getrandbits(32), f64(), v(3), v(3), v(3), v(3),
                   r.getrandbits(8)).encode()
    elif k == 12:
        b = FaultEventMsg(header(), r.getrandbits(32), r.randrange(3), r.randrange(18),
                          r.random() < 0.5, r.getrandbits(64), r.getrandbits(32), v(2),
                          r.getrandbits(1024).to_bytes(128, "little")).encode()
    elif k == 13:
        g = fin if r.randrange(4) else f64
        b = FaultCommandMsg(header(), r.randrange(2), r.getrandbits(64), r.getrandbits(32),
                            r.randrange(18), v(2, g), r.getrandbits(32), r.getrandbits(64),
                            r.getrandbits(64), b"imus.hub.gyro" + bytes(115)).encode()
    elif k == 14:
        b = RelativeStateMsg(header(), r.getrandbits(32), r.getrandbits(32), v(3), v(3), f64(),
                             f64()).encode()
    elif k == 15:  # event counts up to 9 (the last above the maximum), 0..257 values
        g = fin if r.randrange(4) else f64
        b = FswMsg(header(), r.getrandbits(8), r.getrandbits(32), v(4, g), v(4, g), v(3, g),
                   r.randrange(10), tuple(r.getrandbits(16) for _ in range(8)),
                   [r.getrandbits(64) for _ in range(r.randrange(12) if r.randrange(8) else 257)]
                   ).encode()
    b = bytearray(b)
    k = r.randrange(10)
    if k in (3, 4, 5):
        for _ in range(1 + r.randrange(8)):
            b[r.randrange(len(b))] = r.getrandbits(8)
    elif k == 6:
        del b[r.randrange(len(b)):]
    elif k == 7:
        b += bytes(r.getrandbits(8) for _ in range(1 + r.randrange(16)))
    elif k == 8:
        b = bytearray(struct.pack("<H", proto.PROTOCOL_VERSION)
                      + bytes(r.getrandbits(8) for _ in range(r.randrange(600))))
    elif k == 9:
        if r.randrange(20) == 0:
            b = bytearray(b"\x03" * (proto.MAX_MESSAGE_BYTES + 1 + r.randrange(8)))
        else:
            at = r.choice([319, 86, 333, 140])
            if len(b) >= at + 8:
                b[at:at + 8] = struct.pack("<Q", r.choice([1025, 9, 2**64 - 1, 2**40]))
    return bytes(b)


def test_python_and_rust_decoders_agree_on_20000_buffers(verdicts_bin):
    r = random.Random(0xF1E5D)
    buffers = [gen_buffer(r) for _ in range(N)]
    stream = b"".join(struct.pack("<I", len(b)) + b for b in buffers)
    rust = subprocess.run([str(verdicts_bin)], input=stream, capture_output=True, check=True)
    rust_lines = rust.stdout.decode().splitlines()
    assert len(rust_lines) == 17 * N
    reasons = {}
    names = ["state", "imu", "star_tracker", "magnetometer", "css", "fss", "environment",
             "command", "status", "time", "operator", "header", "gps", "fault_event",
             "fault_command", "relative_state", "fsw"]
    for i, b in enumerate(buffers):
        for j, got in enumerate(python_lines(b)):
            want = rust_lines[17 * i + j]
            assert got == want, f"buffer {i} ({len(b)} bytes), {names[j]}: Python {got!r} vs Rust {want!r}"
            key = want.split()[1] if want.startswith("E") else "accepted"
            reasons[key] = reasons.get(key, 0) + 1
    print(f"{N} buffers x 17 decoders: {reasons}")
    for k in ("accepted", "Length", "TrailingBytes", "TooLarge", "UnknownVersion", "NonFinite",
              "Malformed"):
        assert reasons.get(k, 0) > 0, k
