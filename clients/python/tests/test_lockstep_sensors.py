"""Lockstep flight code that reads sensors is deterministic: with the SDK's documented pattern
(``subscribe_imu`` / ``subscribe_star_tracker`` keeping the latest sample, and
``LockstepParticipant(on_state=...)`` using it), a controller on the star tracker and the gyro
commanding the reaction wheels of ``scenarios/wheels_star_tracker.toml`` gives the same state
stream run after run, also with every core of the machine busy; the same with ``on_tick``.

Before the SDK delivered a tick's samples ahead of its state (one ``tlm/**`` subscriber, the
state held until every due sample is in), 7-30 % of the ticks saw the previous tick's IMU sample
and two runs hashed differently. The hash is sensitive to exactly that: one tick that uses the
previous IMU sample on purpose changes it."""

import hashlib
import math
import os
import subprocess
import sys
import threading
from pathlib import Path

try:
    import tomllib
except ImportError:  # Python < 3.11
    import tomli as tomllib

import flexdyn
from flexdyn.testing import flexdyn_server

SCENARIO = Path(__file__).resolve().parents[3] / "scenarios" / "wheels_star_tracker.toml"
DURATION_S = 20.0
LAST = int(DURATION_S * 100)
# Gains small enough that the 0.2 N m wheel limit never clips the command (a clipped command
# would hide which sample it was computed from); each run checks that none reached it.
K_NM, P_NMS = 1.0, 5.0

# The flight code's own tables: the wheel axes, the tracker's mounting (from the scenario).
CONFIG = tomllib.loads(SCENARIO.read_text())
AXES = [w["spin_axis_b"] for w in CONFIG["reaction_wheels"]]
FIRST_WHEEL = len(CONFIG["panel_pairs"])
DCM_CB = CONFIG["star_trackers"][0]["dcm_cb"]
assert CONFIG["imus"][0]["dcm_pb"] == [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]


def mrp_from_quat(q):
    """sigma from a unit quaternion (scalar first), the set with |sigma| <= 1."""
    if q[0] < 0:
        q = [-x for x in q]
    return [x / (1.0 + q[0]) for x in q[1:]]


def quat_dcm(q):
    """[CN] of a quaternion (scalar first)."""
    b0, b1, b2, b3 = q
    return [[b0*b0 + b1*b1 - b2*b2 - b3*b3, 2*(b1*b2 + b0*b3), 2*(b1*b3 - b0*b2)],
            [2*(b1*b2 - b0*b3), b0*b0 - b1*b1 + b2*b2 - b3*b3, 2*(b2*b3 + b0*b1)],
            [2*(b1*b3 + b0*b2), 2*(b2*b3 - b0*b1), b0*b0 - b1*b1 - b2*b2 + b3*b3]]


def dcm_quat(c):
    """Quaternion (scalar first, b0 >= 0) of a DCM near the identity branch (Sheppard)."""
    b0 = 0.5 * math.sqrt(max(0.0, 1.0 + c[0][0] + c[1][1] + c[2][2]))
    return [b0, (c[1][2] - c[2][1]) / (4 * b0), (c[2][0] - c[0][2]) / (4 * b0),
            (c[0][1] - c[1][0]) / (4 * b0)]


class Controller:
    """Attitude from the star tracker ([BN] = [CB]^T [CN]), held between its 10 Hz updates,
    rate from the gyro; L = -K sigma - P omega; wheel torques u_j = -g_j . L / 2 (the pyramid's
    [G][G]^T is 2 I, so this is -[G]^+ L)."""

    def __init__(self):
        self.sigma_bn = None

    def answer(self, tick, imu, star_tracker):
        if star_tracker is not None and star_tracker.valid:
            c_cn = quat_dcm(star_tracker.q_cn)
            c_bn = [[sum(DCM_CB[k][i] * c_cn[k][j] for k in range(3)) for j in range(3)]
                    for i in range(3)]
            self.sigma_bn = mrp_from_quat(dcm_quat(c_bn))
        if self.sigma_bn is None or imu is None:
            return None  # no attitude or no rate yet: NoCommand
        w = imu.omega_p_rad_s
        torque = [-K_NM * self.sigma_bn[i] - P_NMS * w[i] for i in range(3)]
        u = [-0.5 * sum(a[i] * torque[i] for i in range(3)) for a in AXES]
        inputs = [flexdyn.EffectorInput(FIRST_WHEEL + j, [u[j]]) for j in range(len(AXES))]
        return flexdyn.CommandMsg(None, 0, flexdyn.proto.ACTUATORS, (0.0,) * 3, (0.0,) * 3,
                                  inputs)


def documented_pattern_run(stale_imu_at=None):
    """The pattern of the SDK's README: sensor callbacks keep the latest sample; on_state uses
    them. `stale_imu_at`: at that tick, use the previous IMU sample (the hash's sensitivity)."""
    latest, previous_imu = {}, {}
    digest, done, ctrl = hashlib.sha256(), threading.Event(), Controller()
    max_u = [0.0]

    def keep_imu(m):
        if "imu" in latest:
            previous_imu["imu"] = latest["imu"]
        latest["imu"] = m

    def on_state(state):
        digest.update(state.encode())
        for e in state.effectors[FIRST_WHEEL:]:
            max_u[0] = max(max_u[0], abs(e.outputs[0]))
        k = state.header.tick
        if k == LAST:
            done.set()
        imu = previous_imu.get("imu") if k == stale_imu_at else latest.get("imu")
        st = latest.get("st")
        return ctrl.answer(k, imu, st if st is not None and st.header.tick == k else None)

    with flexdyn_server(config=SCENARIO, mode="lockstep", participants=[1],
                        duration_s=DURATION_S) as server:
        with flexdyn.Client(server.endpoint) as client:
            client.subscribe_imu("hub", keep_imu)
            client.subscribe_star_tracker("st1", lambda m: latest.__setitem__("st", m))
            with flexdyn.LockstepParticipant(client, 1, on_state):
                assert done.wait(120), "the run did not reach its last tick"
    assert server.returncode == 0, server.log
    assert 0.01 < max_u[0] < 0.2, f"wheel torques up to {max_u[0]} N m: clipped or absent"
    return digest.hexdigest()


def on_tick_run():
    """The same controller with on_tick: the samples come with the state."""
    digest, ctrl = hashlib.sha256(), Controller()
    incomplete = []

    def on_tick(t):
        digest.update(t.state.encode())
        if t.missing:
            incomplete.append(t.tick)
        return ctrl.answer(t.tick, t.imu["hub"], t.star_trackers.get("st1"))

    with flexdyn_server(config=SCENARIO, mode="lockstep", participants=[1],
                        duration_s=DURATION_S) as server:
        with flexdyn.Client(server.endpoint) as client:
            with flexdyn.LockstepParticipant(client, 1, on_tick=on_tick) as participant:
                final = participant.wait(timeout_s=120)
                assert participant.schedule == flexdyn.SensorSchedule(("hub",), (("st1", 10),))
    assert server.returncode == 0, server.log
    assert flexdyn.proto.RUN_STATE_NAMES[final.run_state] == "Finished"
    assert final.header.tick == LAST and participant.last_tick == LAST
    assert incomplete == []
    return digest.hexdigest()


class CpuLoad:
    """One busy-looping process per core, for the duration of a `with` block."""

    def __enter__(self):
        self.procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"])
                      for _ in range(os.cpu_count() or 2)]
        return self

    def __exit__(self, *exc):
        for p in self.procs:
            p.kill()
            p.wait()


def test_sensor_closed_runs_are_bit_identical_also_under_load():
    a = documented_pattern_run()
    assert documented_pattern_run() == a, "two identical runs differ"
    with CpuLoad():
        assert documented_pattern_run() == a, "a run with every core busy differs"
        assert documented_pattern_run() == a, "a second run with every core busy differs"
    # The hash sees which IMU sample a tick used.
    assert documented_pattern_run(stale_imu_at=LAST // 2) != a


def test_on_tick_gets_each_tick_complete_and_matches_on_state():
    b = on_tick_run()
    with CpuLoad():
        assert on_tick_run() == b, "an on_tick run with every core busy differs"
    assert b == documented_pattern_run(), "on_tick and on_state with callbacks differ"
