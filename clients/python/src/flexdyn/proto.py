"""The flexdyn wire protocol, version 9, in pure Python.

Every message of ``proto/README.md`` as a dataclass with ``encode()`` and ``decode(bytes)``.
Decoding follows the README's decoder rules in the same order and raises :class:`DecodeError`
with the same reasons as the Rust crate's ``DecodeError``:

1. more than ``MAX_MESSAGE_BYTES`` -> ``TooLarge``;
2. fewer than 2 bytes -> ``Length``; first two bytes (u16 LE) != 9 -> ``UnknownVersion``;
3. the total length from the layout (fixed; command tag at 34; walked counts, each bounded
   first) -> ``Length`` (needed = length implied by the counts read so far), ``Malformed``
   (unknown tag, count above its maximum), ``TrailingBytes``;
4. fields in wire order: an enum tag out of range or a bool byte other than 0/1 -> ``Malformed``;
   a text field (a fault ``target``) with a byte other than NUL after its first NUL ->
   ``Malformed``;
5. CommandMsg: a non-finite torque, force or input value -> ``NonFinite`` naming the field;
   FaultCommandMsg: a non-finite parameter -> ``NonFinite``; CssMsg: a detector count above
   ``MAX_CSS_DETECTORS`` -> ``Malformed``.

Units are in the field names (SI; ``_nm`` newton-metres, ``_newton`` newtons); frames too
(``_b`` body, ``_n`` inertial, ``_p`` IMU platform, ``_c`` star-tracker case).
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field
from typing import ClassVar, List, Optional, Tuple

PROTOCOL_VERSION = 9
HEADER_LEN = 30
STATE_FIXED_LEN = 327
STATE_EFFECTOR_COUNT_OFFSET = 319
EFFECTOR_STATE_FIXED_LEN = 22
EFFECTOR_INPUT_FIXED_LEN = 12
IMU_LEN = 127
STAR_TRACKER_LEN = 64
MAGNETOMETER_LEN = 55
COMMAND_KIND_OFFSET = 34
COMMAND_WRENCH_LEN = 86
COMMAND_NO_COMMAND_LEN = 38
COMMAND_ACTUATORS_FIXED_LEN = 94
STATUS_LEN = 235
TIME_LEN = 122
# Sun sensors (protocol 6)
CSS_LEN = 159
FSS_LEN = 47
MAX_CSS_DETECTORS = 16
OPERATOR_LEN = 42
ENVIRONMENT_LEN = 368
# GPS receiver (protocol 7)
GPS_LEN = 147
# Fault injection (protocol 8).
FAULT_EVENT_LEN = 199
# A fleet deputy's relative state (protocol 9)
RELATIVE_STATE_LEN = 102
FAULT_COMMAND_LEN = 214
FAULT_TARGET_LEN = 128
MAX_STATUS_FAULTS = 256
FAULT_SOURCE_CONFIG = 0
FAULT_SOURCE_LIVE = 1
FAULT_SOURCE_RANDOM = 2
FAULT_INJECT = 0
FAULT_CLEAR = 1
AT_NEXT_TICK = 2**64 - 1
# The fault modes by code (proto/README.md, "Fault modes"): name and parameter names.
FAULT_MODES = (
    ("stuck_current", ()), ("stuck_value", ("value",)), ("bias_step", ("value",)),
    ("bias_ramp", ("rate_per_s",)), ("scale", ("factor",)), ("noise", ("sigma",)),
    ("spikes", ("probability", "amplitude")), ("dropout", ()), ("validity_off", ()),
    ("friction_scale", ("factor",)), ("torque_limit", ("fraction",)), ("seized", ()),
    ("command_ignored", ()), ("stuck_on", ()), ("stuck_off", ()), ("thrust_scale", ("factor",)),
    ("dead", ()), ("dipole_scale", ("factor",)),
    # Command links: configuration only (a live fault command with these codes is refused).
    ("dropped", ()), ("delayed", ("frames",)), ("corrupted", ("probability",)),
)
MAX_EFFECTORS = 1024
MAX_EFFECTOR_VALUES = 8
MAX_MESSAGE_BYTES = 65536
NO_COMMAND = 2**64 - 1

# CommandMsg kinds
WRENCH, NO_COMMAND_KIND, ACTUATORS = 0, 1, 2
# EffectorState.kind
PANEL_PAIR, REACTION_WHEEL, MAGNETORQUER, THRUSTER = 1, 2, 3, 4
# Flags
COMMAND_FLAG_STALE, COMMAND_FLAG_ZEROED_BY_POLICY, COMMAND_FLAG_NO_COMMAND_YET = 0x1, 0x2, 0x4
SATURATION_GYRO_RATE, SATURATION_ACCEL, SATURATION_DTHETA, SATURATION_DV = 0x1, 0x2, 0x4, 0x8
STAR_TRACKER_SUN_EXCLUSION, STAR_TRACKER_RATE_LIMIT = 0x1, 0x2
MAGNETOMETER_AXIS_1, MAGNETOMETER_AXIS_2, MAGNETOMETER_AXIS_3 = 0x1, 0x2, 0x4
# FssMsg.flags (protocol 6)
FSS_VALID, FSS_IN_FOV, FSS_SUNLIT = 0x1, 0x2, 0x4
WHEEL_TORQUE_LIMITED, WHEEL_SPEED_LIMITED = 0x1, 0x2
MAGNETORQUER_SATURATED = 0x1
THRUSTER_FIRING, THRUSTER_BELOW_MIN_ON_TIME, THRUSTER_COMMAND_CLIPPED = 0x1, 0x2, 0x4
# StatusMsg enums
MODE_REAL_TIME, MODE_LOCKSTEP, MODE_BATCH = 0, 1, 2
RUN_STATE_NAMES = ("Starting", "Running", "Stopping", "Finished", "Failed", "Stopped", "Paused")
RUN_STATE_RUNNING, RUN_STATE_PAUSED = 1, 6
# TimeMsg.flags and the CUC P-field of TimeMsg.cuc_tai (proto/README.md, "TimeMsg")
TIME_EPOCH_VALID, TIME_TONE, TIME_LEAP_SECOND = 0x1, 0x2, 0x4
CUC_PFIELD_TAI_4_3 = 0x1F
STALE_POLICY_HOLD, STALE_POLICY_ZERO = 0, 1
# OperatorMsg.action (protocol 6)
OPERATOR_PAUSE, OPERATOR_RESUME, OPERATOR_RUN_TICKS = 0, 1, 2
# EnvironmentMsg.flags (models on) and EnvironmentMsg.eclipse (protocol 6)
ENVIRONMENT_EPOCH_VALID, ENVIRONMENT_MAGNETIC, ENVIRONMENT_SUN = 0x1, 0x2, 0x4
ENVIRONMENT_MOON, ENVIRONMENT_SHADOW, ENVIRONMENT_ATMOSPHERE = 0x8, 0x10, 0x20
ECLIPSE_SUNLIT, ECLIPSE_PENUMBRA, ECLIPSE_UMBRA = 0, 1, 2
# GpsMsg.flags (protocol 7)
GPS_FIX, GPS_ECEF, GPS_INERTIAL = 0x1, 0x2, 0x4

_HEADER = struct.Struct("<HIQQQ")


class DecodeError(ValueError):
    """Why a buffer is not a message. ``reason`` is the Rust ``DecodeError`` variant name:
    ``Length`` (``needed``, ``actual``), ``TrailingBytes`` (``expected``, ``actual``),
    ``TooLarge`` (``actual``), ``UnknownVersion`` (``found``), ``NonFinite`` (``field``) or
    ``Malformed`` (``detail``)."""

    def __init__(self, reason: str, **info: object) -> None:
        self.reason = reason
        self.info = info
        super().__init__(f"{reason}: {info}")

    def canonical(self) -> str:
        """The verdict line of ``flexdyn-decode-verdicts`` for this error."""
        i = self.info
        if self.reason == "Length":
            return f"E Length {i['needed']} {i['actual']}"
        if self.reason == "TrailingBytes":
            return f"E TrailingBytes {i['expected']} {i['actual']}"
        if self.reason == "TooLarge":
            return f"E TooLarge {i['actual']}"
        if self.reason == "UnknownVersion":
            return f"E UnknownVersion {i['found']}"
        if self.reason == "NonFinite":
            return f"E NonFinite {i['field']}"
        return "E Malformed"


def _check_size_and_version(buf: bytes, min_len: int) -> None:
    if len(buf) > MAX_MESSAGE_BYTES:
        raise DecodeError("TooLarge", actual=len(buf), max=MAX_MESSAGE_BYTES)
    if len(buf) < 2:
        raise DecodeError("Length", needed=min_len, actual=len(buf))
    (version,) = struct.unpack_from("<H", buf, 0)
    if version != PROTOCOL_VERSION:
        raise DecodeError("UnknownVersion", found=version)


def _check_total(expected: int, buf: bytes) -> None:
    if len(buf) < expected:
        raise DecodeError("Length", needed=expected, actual=len(buf))
    if len(buf) > expected:
        raise DecodeError("TrailingBytes", expected=expected, actual=len(buf))


class _Walker:
    """Bounded cursor over count prefixes (rule 3)."""

    def __init__(self, buf: bytes, at: int) -> None:
        self.buf, self.at = buf, at

    def skip(self, n: int) -> None:
        if self.at + n > len(self.buf):
            raise DecodeError("Length", needed=self.at + n, actual=len(self.buf))
        self.at += n

    def count(self, maximum: int, what: str) -> int:
        if self.at + 8 > len(self.buf):
            raise DecodeError("Length", needed=self.at + 8, actual=len(self.buf))
        (n,) = struct.unpack_from("<Q", self.buf, self.at)
        if n > maximum:
            raise DecodeError("Malformed", detail=f"{what} count {n} exceeds maximum {maximum}")
        self.at += 8
        return n

    def values(self, what: str) -> None:
        self.skip(8 * self.count(MAX_EFFECTOR_VALUES, what))


@dataclass
class Header:
    """Common header, the first 30 bytes of every message."""

    spacecraft_id: int = 0
    tick: int = 0
    sim_time_ns: int = 0  # [ns] simulation time of `tick`
    seq: int = 0
    protocol_version: int = PROTOCOL_VERSION

    def encode(self) -> bytes:
        return _HEADER.pack(
            self.protocol_version, self.spacecraft_id, self.tick, self.sim_time_ns, self.seq
        )

    @staticmethod
    def unpack(buf: bytes) -> "Header":
        v, sc, tick, t, seq = _HEADER.unpack_from(buf, 0)
        return Header(sc, tick, t, seq, v)

    @staticmethod
    def decode(buf: bytes) -> "Header":
        """The header of any message (size, version and the first 30 bytes are checked)."""
        _check_size_and_version(buf, HEADER_LEN)
        if len(buf) < HEADER_LEN:
            raise DecodeError("Length", needed=HEADER_LEN, actual=len(buf))
        return Header.unpack(buf)


def _f(buf: bytes, at: int, n: int) -> Tuple[float, ...]:
    return struct.unpack_from(f"<{n}d", buf, at)


def _pack_f(values) -> bytes:
    return struct.pack(f"<{len(values)}d", *values)


@dataclass
class EffectorState:
    """One effector of a StateMsg: kind (PANEL_PAIR, REACTION_WHEEL, ...), flags, its states
    and outputs in the kind's order and units (proto/README.md, "Effector kinds")."""

    kind: int = 0
    flags: int = 0
    states: List[float] = field(default_factory=list)
    outputs: List[float] = field(default_factory=list)


@dataclass
class StateMsg:
    """Per-frame truth state (``flexdyn/<sc-id>/tlm/state``)."""

    header: Header = field(default_factory=Header)
    sigma_bn: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # MRP of B relative to N
    q_bn: Tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)  # scalar first
    omega_bn_b_rad_s: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [rad/s]
    omega_dot_bn_b_rad_s2: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [rad/s^2]
    r_bn_n_m: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m]
    v_bn_n_m_s: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m/s]
    nongrav_accel_bn_n_m_s2: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m/s^2]
    orb_energy_j: float = 0.0  # [J]
    rot_energy_j: float = 0.0  # [J]
    orb_ang_mom_n: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [kg m^2/s]
    rot_ang_mom_c_n: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [kg m^2/s]
    torque_b_nm: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # wrench_applied [N m]
    force_b_newton: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # wrench_applied [N]
    command_flags: int = 0
    effectors: List[EffectorState] = field(default_factory=list)

    def encode(self) -> bytes:
        out = bytearray(self.header.encode())
        for v in (
            self.sigma_bn, self.q_bn, self.omega_bn_b_rad_s, self.omega_dot_bn_b_rad_s2,
            self.r_bn_n_m, self.v_bn_n_m_s, self.nongrav_accel_bn_n_m_s2,
            (self.orb_energy_j, self.rot_energy_j), self.orb_ang_mom_n, self.rot_ang_mom_c_n,
            self.torque_b_nm, self.force_b_newton,
        ):
            out += _pack_f(v)
        out += struct.pack("<BQ", self.command_flags, len(self.effectors))
        for e in self.effectors:
            out += struct.pack("<HIQ", e.kind, e.flags, len(e.states)) + _pack_f(e.states)
            out += struct.pack("<Q", len(e.outputs)) + _pack_f(e.outputs)
        return bytes(out)

    @staticmethod
    def decode(buf: bytes) -> "StateMsg":
        _check_size_and_version(buf, STATE_FIXED_LEN)
        w = _Walker(buf, STATE_EFFECTOR_COUNT_OFFSET)
        n = w.count(MAX_EFFECTORS, "effector")
        for _ in range(n):
            w.skip(6)
            w.values("effector states")
            w.values("effector outputs")
        _check_total(w.at, buf)
        effectors = []
        at = STATE_FIXED_LEN
        for _ in range(n):
            kind, flags, ns = struct.unpack_from("<HIQ", buf, at)
            states = list(_f(buf, at + 14, ns))
            at += 14 + 8 * ns
            (no,) = struct.unpack_from("<Q", buf, at)
            outputs = list(_f(buf, at + 8, no))
            at += 8 + 8 * no
            effectors.append(EffectorState(kind, flags, states, outputs))
        return StateMsg(
            Header.unpack(buf), _f(buf, 30, 3), _f(buf, 54, 4), _f(buf, 86, 3), _f(buf, 110, 3),
            _f(buf, 134, 3), _f(buf, 158, 3), _f(buf, 182, 3), _f(buf, 206, 1)[0],
            _f(buf, 214, 1)[0], _f(buf, 222, 3), _f(buf, 246, 3), _f(buf, 270, 3),
            _f(buf, 294, 3), buf[318], effectors,
        )


@dataclass
class ImuMsg:
    """IMU sample (``flexdyn/<sc-id>/tlm/imu/<name>``), platform-frame components."""

    header: Header = field(default_factory=Header)
    omega_p_rad_s: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [rad/s]
    accel_p_m_s2: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m/s^2]
    dtheta_p_rad: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [rad]
    dv_p_m_s: Tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m/s]
    saturation_flags: int = 0

    def encode(self) -> bytes:
        return (
            self.header.encode()
            + _pack_f(self.omega_p_rad_s) + _pack_f(self.accel_p_m_s2)
            + _pack_f(self.dtheta_p_rad) + _pack_f(self.dv_p_m_s)
            + struct.pack("<B", self.saturation_flags)
        )

    @staticmethod
    def decode(buf: bytes) -> "ImuMsg":
        _check_size_and_version(buf, IMU_LEN)
        _check_total(IMU_LEN, buf)
        return ImuMsg(
            Header.unpack(buf), _f(buf, 30, 3), _f(buf, 54, 3), _f(buf, 78, 3), _f(buf, 102, 3),
            buf[126],
        )


@dataclass
class StarTrackerMsg:
    """Star-tracker measurement (``flexdyn/<sc-id>/tlm/st/<name>``): q_CN scalar first, held at
    the last valid value while ``valid`` is False."""

    header: Header = field(default_factory=Header)
    q_cn: Tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    valid: bool = False
    status_flags: int = 0

    def encode(self) -> bytes:
        return (
            self.header.encode() + _pack_f(self.q_cn)
            + struct.pack("<BB", 1 if self.valid else 0, self.status_flags)
        )

    @staticmethod
    def decode(buf: bytes) -> "StarTrackerMsg":
        _check_size_and_version(buf, STAR_TRACKER_LEN)
        _check_total(STAR_TRACKER_LEN, buf)
        if buf[62] > 1:
            raise DecodeError("Malformed", detail="valid is not a bool")
        return StarTrackerMsg(Header.unpack(buf), _f(buf, 30, 4), buf[62] == 1, buf[63])


@dataclass
class MagnetometerMsg:
    """Magnetometer sample (``flexdyn/<sc-id>/tlm/mag/<name>``): the field in the sensor frame S
    (T) and the saturated axes (``MAGNETOMETER_AXIS_*``)."""

    header: Header = field(default_factory=Header)
    b_s_t: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    saturation_flags: int = 0

    def encode(self) -> bytes:
        return self.header.encode() + _pack_f(self.b_s_t) + struct.pack("<B", self.saturation_flags)

    @staticmethod
    def decode(buf: bytes) -> "MagnetometerMsg":
        _check_size_and_version(buf, MAGNETOMETER_LEN)
        _check_total(MAGNETOMETER_LEN, buf)
        return MagnetometerMsg(Header.unpack(buf), _f(buf, 30, 3), buf[54])


@dataclass
class CssMsg:
    """Coarse-sun-sensor array sample (``flexdyn/<sc-id>/tlm/css/<name>``): ``detector_count``
    K and one reading per detector in the array's output unit; entries K.. of the 16 are 0."""

    header: Header = field(default_factory=Header)
    detector_count: int = 0
    readings: Tuple[float, ...] = (0.0,) * MAX_CSS_DETECTORS

    def encode(self) -> bytes:
        if len(self.readings) != MAX_CSS_DETECTORS:
            raise ValueError(f"readings has {len(self.readings)} entries, not {MAX_CSS_DETECTORS}")
        return (self.header.encode() + struct.pack("<B", self.detector_count)
                + _pack_f(self.readings))

    @staticmethod
    def decode(buf: bytes) -> "CssMsg":
        _check_size_and_version(buf, CSS_LEN)
        _check_total(CSS_LEN, buf)
        if buf[30] > MAX_CSS_DETECTORS:
            raise DecodeError("Malformed", detail=f"detector count {buf[30]} exceeds maximum "
                              f"{MAX_CSS_DETECTORS}")
        return CssMsg(Header.unpack(buf), buf[30], _f(buf, 31, MAX_CSS_DETECTORS))


@dataclass
class FssMsg:
    """Fine (two-axis) sun sensor sample (``flexdyn/<sc-id>/tlm/fss/<name>``): alpha =
    atan2(s1, s3), beta = atan2(s2, s3) (rad) of the Sun direction s in the sensor frame
    (boresight +3), and ``FSS_*`` flags (angles are 0 unless ``FSS_VALID``)."""

    header: Header = field(default_factory=Header)
    alpha_rad: float = 0.0
    beta_rad: float = 0.0
    flags: int = 0

    def encode(self) -> bytes:
        return (self.header.encode() + _pack_f((self.alpha_rad, self.beta_rad))
                + struct.pack("<B", self.flags))

    @staticmethod
    def decode(buf: bytes) -> "FssMsg":
        _check_size_and_version(buf, FSS_LEN)
        _check_total(FSS_LEN, buf)
        alpha, beta = _f(buf, 30, 2)
        return FssMsg(Header.unpack(buf), alpha, beta, buf[46])


@dataclass
class EffectorInput:
    """Inputs for one effector (index in StateMsg.effectors) in an Actuators command."""

    effector_index: int = 0
    values: List[float] = field(default_factory=list)


_TORQUE = ("kind.torque_b_nm[0]", "kind.torque_b_nm[1]", "kind.torque_b_nm[2]")
_FORCE = ("kind.force_b_newton[0]", "kind.force_b_newton[1]", "kind.force_b_newton[2]")


@dataclass
class CommandMsg:
    """Command from flight code (``flexdyn/<sc-id>/cmd/<sender_id>``): ``kind`` WRENCH (torque about
    B [N m] and force at B [N], B components), NO_COMMAND_KIND, or ACTUATORS (a wrench plus
    effector inputs, e.g. reaction-wheel motor torques)."""

    header: Header = field(default_factory=Header)
    sender_id: int = 0
    kind: int = NO_COMMAND_KIND
    torque_b_nm: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    force_b_newton: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    inputs: List[EffectorInput] = field(default_factory=list)

    def validate(self) -> None:
        """Rule 5: every number finite (raises DecodeError NonFinite naming the field)."""
        if self.kind == NO_COMMAND_KIND:
            return
        for name, v in zip(_TORQUE + _FORCE, tuple(self.torque_b_nm) + tuple(self.force_b_newton)):
            if not math.isfinite(v):
                raise DecodeError("NonFinite", field=name)
        if self.kind == ACTUATORS:
            for i in self.inputs:
                if not all(math.isfinite(v) for v in i.values):
                    raise DecodeError("NonFinite", field="kind.inputs[].values[]")

    def encode(self) -> bytes:
        out = self.header.encode() + struct.pack("<II", self.sender_id, self.kind)
        if self.kind == NO_COMMAND_KIND:
            return out
        out += _pack_f(self.torque_b_nm) + _pack_f(self.force_b_newton)
        if self.kind == WRENCH:
            return out
        if self.kind != ACTUATORS:
            raise ValueError(f"unknown command kind {self.kind}")
        out += struct.pack("<Q", len(self.inputs))
        for i in self.inputs:
            out += struct.pack("<IQ", i.effector_index, len(i.values)) + _pack_f(i.values)
        return out

    @staticmethod
    def decode(buf: bytes) -> "CommandMsg":
        _check_size_and_version(buf, COMMAND_NO_COMMAND_LEN)
        if len(buf) < COMMAND_KIND_OFFSET + 4:
            raise DecodeError("Length", needed=COMMAND_NO_COMMAND_LEN, actual=len(buf))
        (tag,) = struct.unpack_from("<I", buf, COMMAND_KIND_OFFSET)
        n = 0
        if tag == WRENCH:
            expected = COMMAND_WRENCH_LEN
        elif tag == NO_COMMAND_KIND:
            expected = COMMAND_NO_COMMAND_LEN
        elif tag == ACTUATORS:
            w = _Walker(buf, COMMAND_ACTUATORS_FIXED_LEN - 8)
            n = w.count(MAX_EFFECTORS, "effector input")
            for _ in range(n):
                w.skip(4)
                w.values("effector input values")
            expected = w.at
        else:
            raise DecodeError("Malformed", detail=f"unknown enum tag {tag} at offset 34")
        _check_total(expected, buf)
        (sender,) = struct.unpack_from("<I", buf, 30)
        m = CommandMsg(Header.unpack(buf), sender, tag)
        if tag != NO_COMMAND_KIND:
            m.torque_b_nm, m.force_b_newton = _f(buf, 38, 3), _f(buf, 62, 3)
        if tag == ACTUATORS:
            at = COMMAND_ACTUATORS_FIXED_LEN
            for _ in range(n):
                index, nv = struct.unpack_from("<IQ", buf, at)
                m.inputs.append(EffectorInput(index, list(_f(buf, at + 12, nv))))
                at += 12 + 8 * nv
        m.validate()
        return m


@dataclass
class StatusMsg:
    """Server health (``flexdyn/<sc-id>/status``). ``wall_time_unix_ns`` is the only
    non-deterministic field of the protocol."""

    header: Header = field(default_factory=Header)
    mode: int = MODE_REAL_TIME
    run_state: int = 0
    lateness_p50_ns: int = 0
    lateness_p99_ns: int = 0
    lateness_max_ns: int = 0
    overrun_count: int = 0
    frames_skipped: int = 0
    last_command_tick: int = NO_COMMAND
    command_age_ns: int = NO_COMMAND
    command_stale: bool = False
    stale_policy: int = STALE_POLICY_HOLD
    rejected_malformed: int = 0
    rejected_bad_version: int = 0
    rejected_non_finite: int = 0
    rejected_wrong_spacecraft: int = 0
    rejected_stale_tick: int = 0
    rejected_unknown_sender: int = 0
    rejected_bad_effector_input: int = 0
    rejected_wrong_identity: int = 0
    rejected_operator_refused: int = 0
    rejected_fault_refused: int = 0
    commands_dropped: int = 0
    wall_time_unix_ns: int = 0
    faults_active: int = 0
    faults_active_bits: Tuple[int, int, int, int] = (0, 0, 0, 0)

    _BODY: ClassVar[struct.Struct] = struct.Struct("<II7QBI17Q")

    def fault_active(self, index: int) -> bool:
        """Whether fault ``index`` is active (indices below ``MAX_STATUS_FAULTS``)."""
        return 0 <= index < MAX_STATUS_FAULTS and bool(
            self.faults_active_bits[index // 64] >> (index % 64) & 1)

    def encode(self) -> bytes:
        return self.header.encode() + self._BODY.pack(
            self.mode, self.run_state, self.lateness_p50_ns, self.lateness_p99_ns,
            self.lateness_max_ns, self.overrun_count, self.frames_skipped,
            self.last_command_tick, self.command_age_ns, 1 if self.command_stale else 0,
            self.stale_policy, self.rejected_malformed, self.rejected_bad_version,
            self.rejected_non_finite, self.rejected_wrong_spacecraft, self.rejected_stale_tick,
            self.rejected_unknown_sender, self.rejected_bad_effector_input,
            self.rejected_wrong_identity, self.rejected_operator_refused,
            self.rejected_fault_refused, self.commands_dropped, self.wall_time_unix_ns,
            self.faults_active, *self.faults_active_bits,
        )

    @staticmethod
    def decode(buf: bytes) -> "StatusMsg":
        _check_size_and_version(buf, STATUS_LEN)
        _check_total(STATUS_LEN, buf)
        f = StatusMsg._BODY.unpack_from(buf, HEADER_LEN)
        if f[0] > MODE_BATCH:
            raise DecodeError("Malformed", detail="mode tag")
        if f[1] > RUN_STATE_PAUSED:
            raise DecodeError("Malformed", detail="run_state tag")
        if f[9] > 1:
            raise DecodeError("Malformed", detail="command_stale is not a bool")
        if f[10] > STALE_POLICY_ZERO:
            raise DecodeError("Malformed", detail="stale_policy tag")
        return StatusMsg(Header.unpack(buf), *f[:9], f[9] == 1, *f[10:24], tuple(f[24:28]))


@dataclass
class TimeMsg:
    """The time service (``flexdyn/<sc-id>/tlm/time``, protocol 5): one per frame, before the
    frame's sensors and state. ``cuc_tai`` is 8 bytes, CCSDS order (big-endian); ``tone_met``
    and ``tone_tai`` are ``(seconds, subseconds in 2**-32 s)``. Without an ``[epoch]`` the
    ``TIME_EPOCH_VALID`` flag is clear and every calendar field is zero."""

    header: Header = field(default_factory=Header)
    run_state: int = 0
    mode: int = MODE_REAL_TIME
    flags: int = 0
    frame_ns: int = 0
    speed: float = 0.0
    tai_ns_1958: int = 0
    utc: Tuple[int, int, int, int, int, int, int] = (0, 0, 0, 0, 0, 0, 0)
    tai_minus_utc_s: int = 0
    gps_week: int = 0
    gps_ns_of_week: int = 0
    met_ns: int = 0
    cuc_tai: bytes = bytes(8)
    tone_met: Tuple[int, int] = (0, 0)
    tone_tai: Tuple[int, int] = (0, 0)

    _BODY: ClassVar[struct.Struct] = struct.Struct("<IIBQdQH5BIiIQQ8s4I")

    def encode(self) -> bytes:
        return self.header.encode() + self._BODY.pack(
            self.run_state, self.mode, self.flags, self.frame_ns, self.speed, self.tai_ns_1958,
            *self.utc, self.tai_minus_utc_s, self.gps_week, self.gps_ns_of_week, self.met_ns,
            bytes(self.cuc_tai), *self.tone_met, *self.tone_tai,
        )

    @staticmethod
    def decode(buf: bytes) -> "TimeMsg":
        _check_size_and_version(buf, TIME_LEN)
        _check_total(TIME_LEN, buf)
        f = TimeMsg._BODY.unpack_from(buf, HEADER_LEN)
        if f[0] > RUN_STATE_PAUSED:
            raise DecodeError("Malformed", detail="run_state tag")
        if f[1] > MODE_BATCH:
            raise DecodeError("Malformed", detail="mode tag")
        return TimeMsg(Header.unpack(buf), f[0], f[1], f[2], f[3], f[4], f[5], tuple(f[6:13]),
                       f[13], f[14], f[15], f[16], f[17], (f[18], f[19]), (f[20], f[21]))

    @property
    def paused(self) -> bool:
        return self.run_state == RUN_STATE_PAUSED

    @property
    def tone(self) -> bool:
        return bool(self.flags & TIME_TONE)


@dataclass
class OperatorMsg:
    """An operator's command (``flexdyn/<sc-id>/operator``, protocol 6): ``action`` is
    ``OPERATOR_PAUSE``, ``OPERATOR_RESUME`` or ``OPERATOR_RUN_TICKS`` (lockstep: step ``ticks``
    frames, then hold); ``ticks`` is 0 for the other actions."""

    header: Header = field(default_factory=Header)
    action: int = OPERATOR_PAUSE
    ticks: int = 0

    _BODY: ClassVar[struct.Struct] = struct.Struct("<IQ")

    def encode(self) -> bytes:
        return self.header.encode() + self._BODY.pack(self.action, self.ticks)

    @staticmethod
    def decode(buf: bytes) -> "OperatorMsg":
        _check_size_and_version(buf, OPERATOR_LEN)
        _check_total(OPERATOR_LEN, buf)
        action, ticks = OperatorMsg._BODY.unpack_from(buf, HEADER_LEN)
        if action > OPERATOR_RUN_TICKS:
            raise DecodeError("Malformed", detail="action tag")
        return OperatorMsg(Header.unpack(buf), action, ticks)


Vec3 = Tuple[float, float, float]


@dataclass
class SourceWrench:
    """One environment source's torque about B (N·m) and force at B (N), B components."""

    torque_b_nm: Vec3 = (0.0, 0.0, 0.0)
    force_b_newton: Vec3 = (0.0, 0.0, 0.0)


@dataclass
class EnvironmentMsg:
    """The environment at the spacecraft (``flexdyn/<sc-id>/tlm/env``, protocol 6), at
    ``[environment] telemetry_rate_hz``; every value refers to ``header.tick``. ``flags`` says
    which models are on (``ENVIRONMENT_*``), ``eclipse`` is ``ECLIPSE_SUNLIT``, ``_PENUMBRA`` or
    ``_UMBRA``. The four sources are each dynamic effector's own evaluation at that tick."""

    header: Header = field(default_factory=Header)
    tai_ns_1958: int = 0
    flags: int = 0
    eclipse: int = ECLIPSE_SUNLIT
    b_n_t: Vec3 = (0.0, 0.0, 0.0)
    b_b_t: Vec3 = (0.0, 0.0, 0.0)
    sun_n: Vec3 = (0.0, 0.0, 0.0)
    sun_b: Vec3 = (0.0, 0.0, 0.0)
    moon_n: Vec3 = (0.0, 0.0, 0.0)
    shadow_factor: float = 1.0
    density_kg_m3: float = 0.0
    gravity_gradient: SourceWrench = field(default_factory=SourceWrench)
    drag: SourceWrench = field(default_factory=SourceWrench)
    solar_pressure: SourceWrench = field(default_factory=SourceWrench)
    residual_dipole: SourceWrench = field(default_factory=SourceWrench)

    SOURCES: ClassVar[Tuple[str, ...]] = ("gravity_gradient", "drag", "solar_pressure",
                                          "residual_dipole")
    _BODY: ClassVar[struct.Struct] = struct.Struct("<QBB15d2d24d")

    def encode(self) -> bytes:
        wrenches = [v for s in self.SOURCES for w in (getattr(self, s),)
                    for v in (*w.torque_b_nm, *w.force_b_newton)]
        return self.header.encode() + self._BODY.pack(
            self.tai_ns_1958, self.flags, self.eclipse, *self.b_n_t, *self.b_b_t, *self.sun_n,
            *self.sun_b, *self.moon_n, self.shadow_factor, self.density_kg_m3, *wrenches)

    @staticmethod
    def decode(buf: bytes) -> "EnvironmentMsg":
        _check_size_and_version(buf, ENVIRONMENT_LEN)
        _check_total(ENVIRONMENT_LEN, buf)
        f = EnvironmentMsg._BODY.unpack_from(buf, HEADER_LEN)
        v = lambda i: tuple(f[i:i + 3])  # noqa: E731
        w = [SourceWrench(v(20 + 6 * k), v(23 + 6 * k)) for k in range(4)]
        return EnvironmentMsg(Header.unpack(buf), f[0], f[1], f[2], v(3), v(6), v(9), v(12),
                              v(15), f[18], f[19], *w)

    @property
    def eclipse_name(self) -> str:
        return ("sunlit", "penumbra", "umbra")[self.eclipse] if self.eclipse <= 2 else "?"


@dataclass
class GpsMsg:
    """A GPS receiver's solution (``flexdyn/<sc-id>/tlm/gps/<name>``, protocol 7), published
    at ``header.sim_time_ns`` and valid at ``valid_sim_time_ns`` (the receiver's latency
    earlier). ``flags``: ``GPS_FIX`` (else every number is 0), ``GPS_ECEF`` and ``GPS_INERTIAL``
    (which frames' fields are output; the others are 0). ECEF: position of B from the Earth's
    centre (m) and velocity relative to the Earth-fixed frame (m/s); N: inertial."""

    header: Header = field(default_factory=Header)
    valid_sim_time_ns: int = 0
    gps_week: int = 0
    gps_seconds_of_week: float = 0.0
    r_be_e_m: Vec3 = (0.0, 0.0, 0.0)
    v_be_e_m_s: Vec3 = (0.0, 0.0, 0.0)
    r_bn_n_m: Vec3 = (0.0, 0.0, 0.0)
    v_bn_n_m_s: Vec3 = (0.0, 0.0, 0.0)
    flags: int = 0

    _BODY: ClassVar[struct.Struct] = struct.Struct("<QId12dB")

    def encode(self) -> bytes:
        return self.header.encode() + self._BODY.pack(
            self.valid_sim_time_ns, self.gps_week, self.gps_seconds_of_week, *self.r_be_e_m,
            *self.v_be_e_m_s, *self.r_bn_n_m, *self.v_bn_n_m_s, self.flags)

    @staticmethod
    def decode(buf: bytes) -> "GpsMsg":
        _check_size_and_version(buf, GPS_LEN)
        _check_total(GPS_LEN, buf)
        f = GpsMsg._BODY.unpack_from(buf, HEADER_LEN)
        v = lambda i: tuple(f[i:i + 3])  # noqa: E731
        return GpsMsg(Header.unpack(buf), f[0], f[1], f[2], v(3), v(6), v(9), v(12), f[15])


def _target_bytes(target: str) -> bytes:
    b = target.encode("utf-8")
    if len(b) > FAULT_TARGET_LEN or b"\0" in b:
        raise ValueError(f"fault target {target!r}: at most {FAULT_TARGET_LEN} bytes, no NUL")
    return b + bytes(FAULT_TARGET_LEN - len(b))


def _target_str(b: bytes) -> str:
    return b.split(b"\0", 1)[0].decode("utf-8", errors="replace")


def _check_text_padded(b: bytes, field: str) -> None:
    """The text rule (README "Decoder rules", step 4): the text ends at its first NUL byte and
    every byte after it is NUL."""
    end = b.find(b"\0")
    if end >= 0 and b[end:].count(0) != len(b) - end:
        raise DecodeError("Malformed", detail=f"{field}: a byte other than NUL after its NUL")


@dataclass
class FaultEventMsg:
    """A fault's activation (``active``) or clearance (``flexdyn/<sc-id>/tlm/fault``, protocol
    8): ``fault_index`` (configured entry, or configured count + live order), ``source``
    (``FAULT_SOURCE_*``), ``mode`` (code in ``FAULT_MODES``), ``edge_ns`` (when the window's edge
    fell), ``axes`` (bit a: axis a + 1; 0 every axis), ``params`` and ``target`` (raw 128 bytes;
    ``target_str`` decodes them)."""

    header: Header = field(default_factory=Header)
    fault_index: int = 0
    source: int = FAULT_SOURCE_CONFIG
    mode: int = 0
    active: bool = False
    edge_ns: int = 0
    axes: int = 0
    params: Tuple[float, float] = (0.0, 0.0)
    target: bytes = bytes(FAULT_TARGET_LEN)

    _BODY: ClassVar[struct.Struct] = struct.Struct("<IIIBQI2d128s")

    @property
    def target_str(self) -> str:
        return _target_str(self.target)

    @property
    def mode_name(self) -> str:
        return FAULT_MODES[self.mode][0] if self.mode < len(FAULT_MODES) else f"mode {self.mode}"

    def encode(self) -> bytes:
        return self.header.encode() + self._BODY.pack(
            self.fault_index, self.source, self.mode, 1 if self.active else 0, self.edge_ns,
            self.axes, *self.params, bytes(self.target))

    @staticmethod
    def decode(buf: bytes) -> "FaultEventMsg":
        _check_size_and_version(buf, FAULT_EVENT_LEN)
        _check_total(FAULT_EVENT_LEN, buf)
        f = FaultEventMsg._BODY.unpack_from(buf, HEADER_LEN)
        if f[1] > FAULT_SOURCE_RANDOM:
            raise DecodeError("Malformed", detail="source tag")
        if f[3] > 1:
            raise DecodeError("Malformed", detail="active is not a bool")
        _check_text_padded(f[8], "target")
        return FaultEventMsg(Header.unpack(buf), f[0], f[1], f[2], f[3] == 1, f[4], f[5],
                             (f[6], f[7]), f[8])


@dataclass
class RelativeStateMsg:
    """A fleet deputy's state relative to its chief (``flexdyn/<deputy>/tlm/rel/<chief>``,
    protocol 9), every frame after the deputy's StateMsg. Both vehicles at their centres of
    mass; H is the chief's Hill frame (x radial, z along the orbit normal, y along-track):
    ``r_dc_h_m`` (m), ``v_dc_h_m_s`` (its rate seen in H, m/s), ``range_m``,
    ``range_rate_m_s`` (negative while closing). ``header.spacecraft_id`` is the deputy's."""

    header: Header = field(default_factory=Header)
    chief_spacecraft_id: int = 0
    deputy_spacecraft_id: int = 0
    r_dc_h_m: Vec3 = (0.0, 0.0, 0.0)
    v_dc_h_m_s: Vec3 = (0.0, 0.0, 0.0)
    range_m: float = 0.0
    range_rate_m_s: float = 0.0

    _BODY: ClassVar[struct.Struct] = struct.Struct("<II8d")

    def encode(self) -> bytes:
        return self.header.encode() + self._BODY.pack(
            self.chief_spacecraft_id, self.deputy_spacecraft_id, *self.r_dc_h_m,
            *self.v_dc_h_m_s, self.range_m, self.range_rate_m_s)

    @staticmethod
    def decode(buf: bytes) -> "RelativeStateMsg":
        _check_size_and_version(buf, RELATIVE_STATE_LEN)
        _check_total(RELATIVE_STATE_LEN, buf)
        f = RelativeStateMsg._BODY.unpack_from(buf, HEADER_LEN)
        return RelativeStateMsg(Header.unpack(buf), f[0], f[1], tuple(f[2:5]), tuple(f[5:8]),
                                f[8], f[9])


@dataclass
class FaultCommandMsg:
    """A live fault command (``flexdyn/<sc-id>/fault``, protocol 8): ``FAULT_INJECT`` the fault
    described (``target``, ``mode``, ``params``, ``axes``, ``duration_ns`` 0 = until cleared,
    ``seed``) at boundary ``at_tick`` (``AT_NEXT_TICK``: the next one), or ``FAULT_CLEAR`` fault
    ``fault_index`` from ``at_tick`` on."""

    header: Header = field(default_factory=Header)
    action: int = FAULT_INJECT
    at_tick: int = AT_NEXT_TICK
    fault_index: int = 0
    mode: int = 0
    params: Tuple[float, float] = (0.0, 0.0)
    axes: int = 0
    duration_ns: int = 0
    seed: int = 0
    target: bytes = bytes(FAULT_TARGET_LEN)

    _BODY: ClassVar[struct.Struct] = struct.Struct("<IQII2dIQQ128s")

    @property
    def target_str(self) -> str:
        return _target_str(self.target)

    def encode(self) -> bytes:
        return self.header.encode() + self._BODY.pack(
            self.action, self.at_tick, self.fault_index, self.mode, *self.params, self.axes,
            self.duration_ns, self.seed, bytes(self.target))

    @staticmethod
    def decode(buf: bytes) -> "FaultCommandMsg":
        _check_size_and_version(buf, FAULT_COMMAND_LEN)
        _check_total(FAULT_COMMAND_LEN, buf)
        f = FaultCommandMsg._BODY.unpack_from(buf, HEADER_LEN)
        if f[0] > FAULT_CLEAR:
            raise DecodeError("Malformed", detail="action tag")
        _check_text_padded(f[9], "target")
        for i in (0, 1):
            if not math.isfinite(f[4 + i]):
                raise DecodeError("NonFinite", field=f"params[{i}]")
        return FaultCommandMsg(Header.unpack(buf), f[0], f[1], f[2], f[3], (f[4], f[5]), f[6],
                               f[7], f[8], f[9])


def fault_command(spacecraft_id: int, target: str, mode: str, at_tick: int = AT_NEXT_TICK,
                  duration_ns: int = 0, axes=(), seed: int = 0, seq: int = 0, tick: int = 0,
                  **params: float) -> FaultCommandMsg:
    """An ``Inject`` FaultCommandMsg from a mode name and its parameters by name (as in
    ``[[faults]]``): ``fault_command(1, "imus.hub.gyro", "bias_step", at_tick=40, value=0.01,
    axes=(1, 3))``."""
    codes = [m[0] for m in FAULT_MODES]
    if mode not in codes:
        raise ValueError(f"unknown fault mode {mode!r} (expected one of {', '.join(codes)})")
    code = codes.index(mode)
    names = FAULT_MODES[code][1]
    if set(params) != set(names):
        raise ValueError(f"mode {mode!r} takes {', '.join(names) or 'no parameters'}, "
                         f"got {', '.join(params) or 'none'}")
    values = [float(params[n]) for n in names] + [0.0] * (2 - len(names))
    bits = 0
    for a in axes:
        bits |= 1 << (int(a) - 1)
    return FaultCommandMsg(Header(spacecraft_id, tick, 0, seq), FAULT_INJECT,
                           at_tick, 0, code, (values[0], values[1]), bits, duration_ns, seed,
                           _target_bytes(target))


def fault_clear(spacecraft_id: int, fault_index: int, at_tick: int = AT_NEXT_TICK, seq: int = 0,
                tick: int = 0) -> FaultCommandMsg:
    """A ``Clear`` FaultCommandMsg for fault ``fault_index``."""
    return FaultCommandMsg(Header(spacecraft_id, tick, 0, seq), FAULT_CLEAR,
                           at_tick, fault_index)


# --------------------------------------------------------------------------------------------
# Key expressions (proto/README.md, "Topics").

def _valid_id(s: str) -> bool:
    return 0 < len(s) <= 64 and all(c.isascii() and (c.isalnum() or c in "_-") for c in s)


def _key(sc: str, suffix: str, name: Optional[str] = None) -> str:
    if not _valid_id(sc):
        raise ValueError(f"invalid spacecraft id {sc!r}: 1-64 characters from [A-Za-z0-9_-]")
    if name is not None and not _valid_id(name):
        raise ValueError(f"invalid name {name!r}: 1-64 characters from [A-Za-z0-9_-]")
    return f"flexdyn/{sc}/{suffix}" + (f"/{name}" if name is not None else "")


def state_key(sc: str) -> str:
    return _key(sc, "tlm/state")


def environment_key(sc: str) -> str:
    """``flexdyn/<sc>/tlm/env``: the environment message (EnvironmentMsg)."""
    return _key(sc, "tlm/env")


def time_key(sc: str) -> str:
    """``flexdyn/<sc>/tlm/time``: the time service (TimeMsg)."""
    return _key(sc, "tlm/time")


def imu_key(sc: str, name: str) -> str:
    return _key(sc, "tlm/imu", name)


def star_tracker_key(sc: str, name: str) -> str:
    return _key(sc, "tlm/st", name)


def magnetometer_key(sc: str, name: str) -> str:
    return _key(sc, "tlm/mag", name)


def css_key(sc: str, name: str) -> str:
    return _key(sc, "tlm/css", name)


def fss_key(sc: str, name: str) -> str:
    return _key(sc, "tlm/fss", name)


def gps_key(sc: str, name: str) -> str:
    """``flexdyn/<sc>/tlm/gps/<name>``: a GPS receiver (GpsMsg, protocol 7)."""
    return _key(sc, "tlm/gps", name)


def command_key(sc: str, sender_id: int) -> str:
    """``flexdyn/<sc>/cmd/<sender_id>``: participant ``sender_id``'s command key (protocol 4:
    one key per sender, which the server's Zenoh access-control list can reserve for one
    authenticated subject)."""
    if not (isinstance(sender_id, int) and 0 <= sender_id <= 0xFFFFFFFF):
        raise ValueError(f"invalid sender_id {sender_id!r}: an integer 0..4294967295")
    return _key(sc, "cmd", str(sender_id))


def status_key(sc: str) -> str:
    return _key(sc, "status")


def operator_key(sc: str) -> str:
    """``flexdyn/<sc>/operator``: operator commands (OperatorMsg, protocol 6)."""
    return _key(sc, "operator")


def fault_key(sc: str) -> str:
    """``flexdyn/<sc>/fault``: live fault commands (FaultCommandMsg, protocol 8)."""
    return _key(sc, "fault")


def fault_event_key(sc: str) -> str:
    """``flexdyn/<sc>/tlm/fault``: fault activations and clearances (FaultEventMsg, protocol 8)."""
    return _key(sc, "tlm/fault")


def relative_state_key(deputy: str, chief: str) -> str:
    """``flexdyn/<deputy>/tlm/rel/<chief>``: a fleet deputy's state relative to its chief
    (RelativeStateMsg, protocol 9)."""
    return _key(deputy, "tlm/rel", chief)


def telemetry_key(sc: str) -> str:
    """``flexdyn/<sc>/tlm/**``: the state and every sensor topic. One subscriber on it sees a
    tick's samples in the order the server published them (proto/README.md, "Lockstep
    protocol")."""
    return _key(sc, "tlm/**")


def config_key(sc: str) -> str:
    """``flexdyn/<sc>/config``: the server's configuration queryable (a ``get`` returns UTF-8
    JSON, not a bincode message)."""
    return _key(sc, "config")


def participant_key(sc: str, sender_id: int) -> str:
    return _key(sc, "participant", str(sender_id))
