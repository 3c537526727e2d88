"""How LockstepParticipant assembles a tick, without a server: samples are fed to it in chosen
orders through a stand-in client, and the answers it sends are recorded."""

import threading
import time

import flexdyn
from flexdyn import proto
from flexdyn.proto import Header, ImuMsg, StarTrackerMsg, StateMsg

CONFIG_TOML = """
[simulation]
step_s = 0.001
frame_hz = 100.0
[[imus]]
name = "hub"
[[imus]]
name = "bracket"
[[star_trackers]]
name = "st1"
rate_hz = 10.0
[[star_trackers]]
name = "st2"
rate_hz = 25.0
"""


class FakeClient:
    """What LockstepParticipant uses of a Client; telemetry is fed with `feed`."""

    sc_id, spacecraft_id = "sc1", 1

    def __init__(self):
        self._dispatch = threading.RLock()
        self._subscribers = []
        self.taps = []
        self.sent = []  # (tick, kind)
        self.declared = []  # keys, in the order declare_keys got them
        outer = self

        class Token:
            def undeclare(self):
                pass

        class Liveliness:
            def declare_token(self, key):
                assert key == "flexdyn/sc1/participant/1"
                return Token()

        class Session:
            def liveliness(self):
                return Liveliness()

        self.session = Session()
        self.status_callback = None

    def vehicle(self, timeout_s):
        return flexdyn.VehicleInfo("sc1", 1, CONFIG_TOML, "", None, None)

    def subscribe_status(self, callback):
        self.status_callback = callback

        class Sub:
            def undeclare(self):
                pass

        return Sub()

    def add_telemetry_tap(self, tap):
        self.taps.append(tap)

    def declare_keys(self, keys):
        self.declared.extend(keys)

    def remove_telemetry_tap(self, tap):
        self.taps.remove(tap)

    def feed(self, route, msg):
        with self._dispatch:
            for tap in self.taps:
                tap(route, msg)

    def send_no_command(self, sender_id, tick, sim_time_ns):
        self.sent.append((tick, "none"))

    def send_wrench(self, sender_id, tick, sim_time_ns, torque, force):
        self.sent.append((tick, "wrench"))


def header(tick):
    return Header(1, tick, tick * 10_000_000, tick)


def state(tick):
    return StateMsg(header(tick))


def imu(tick, rate_x=0.0):
    return ImuMsg(header(tick), (rate_x, 0.0, 0.0))


def st(tick):
    return StarTrackerMsg(header(tick), (1.0, 0.0, 0.0, 0.0), True)


def participant(client, seen, **kw):
    def on_tick(t):
        seen.append(t)
        return None

    return flexdyn.LockstepParticipant(client, 1, on_tick=on_tick, **kw)


def test_the_schedule_comes_from_the_configuration():
    s = flexdyn.SensorSchedule.from_config(flexdyn.VehicleInfo(
        "sc1", 1, CONFIG_TOML, "", None, None).config())
    assert s == flexdyn.SensorSchedule(("hub", "bracket"), (("st1", 10), ("st2", 4)))
    assert s.due(0) == ("imu/hub", "imu/bracket", "st/st1", "st/st2")
    assert s.due(4) == ("imu/hub", "imu/bracket", "st/st2")
    assert s.due(7) == ("imu/hub", "imu/bracket")
    assert s.due(20) == ("imu/hub", "imu/bracket", "st/st1", "st/st2")


def test_a_state_that_overtakes_its_samples_waits_for_them():
    c, seen = FakeClient(), []
    p = participant(c, seen)
    c.feed("state", state(0))
    c.feed("imu/hub", imu(0))
    c.feed("st/st1", st(0))
    c.feed("imu/bracket", imu(0))
    assert seen == [] and c.sent == [], "tick 0 answered without st/st2"
    c.feed("st/st2", st(0))
    assert [t.tick for t in seen] == [0] and c.sent == [(0, "none")]
    t = seen[0]
    assert set(t.imu) == {"hub", "bracket"} and set(t.star_trackers) == {"st1", "st2"}
    assert t.missing == ()
    # Tick 1: the IMUs only (no tracker is due); in publication order it goes at once.
    c.feed("imu/hub", imu(1, 0.5))
    c.feed("imu/bracket", imu(1))
    c.feed("state", state(1))
    assert [t.tick for t in seen] == [0, 1] and seen[1].imu["hub"].omega_p_rad_s[0] == 0.5
    p.close()


def test_a_lost_sample_releases_its_tick_after_the_timeout():
    c, seen = FakeClient(), []
    p = participant(c, seen, sensor_timeout_s=0.2)
    c.feed("imu/hub", imu(3))
    c.feed("state", state(3))  # imu/bracket of tick 3 never comes
    assert seen == []
    time.sleep(0.6)
    assert [t.tick for t in seen] == [3] and seen[0].missing == ("imu/bracket",)
    assert p.incomplete_ticks == 1 and c.sent == [(3, "none")]
    c.feed("imu/bracket", imu(3))  # too late: ignored, nothing is answered twice
    assert c.sent == [(3, "none")]
    p.close()


def test_in_real_time_a_later_tick_releases_a_waiting_one_at_once():
    c, seen = FakeClient(), []
    p = participant(c, seen, sensor_timeout_s=60)
    c.feed("imu/hub", imu(5))
    c.feed("state", state(5))  # imu/bracket of tick 5 was dropped by the server
    c.feed("imu/hub", imu(6))
    assert [(t.tick, t.missing) for t in seen] == [(5, ("imu/bracket",))]
    c.feed("imu/bracket", imu(6))
    c.feed("state", state(6))
    assert [(t.tick, t.missing) for t in seen] == [(5, ("imu/bracket",)), (6, ())]
    p.close()


def feed_tick(c, tick):
    c.feed("imu/hub", imu(tick))
    c.feed("imu/bracket", imu(tick))
    if tick % 10 == 0:
        c.feed("st/st1", st(tick))
    if tick % 4 == 0:
        c.feed("st/st2", st(tick))
    c.feed("state", state(tick))


def test_wait_hands_out_the_queued_ticks_then_returns_the_final_status():
    # The end of the run is heard while ticks 0..2 are still on their way (issue 36): wait
    # returns only once the status's tick is answered, and says how the run ended.
    c, seen = FakeClient(), []
    p = participant(c, seen)
    assert p.ended is None and p.final_status is None
    final = proto.StatusMsg(header(2), proto.MODE_LOCKSTEP, 3)
    c.status_callback(final)

    def late_ticks():
        for tick in (0, 1, 2):
            time.sleep(0.005)
            feed_tick(c, tick)

    feeder = threading.Thread(target=late_ticks)
    feeder.start()
    assert p.wait(timeout_s=5) is final
    feeder.join()
    assert [t.tick for t in seen] == [0, 1, 2] and p.last_tick == 2
    assert p.ended == ("finished", 2)
    p.close()


def test_wait_returns_on_an_end_whose_tick_never_comes():
    # A run stopped before tick 0 (its last status names tick 0, no state was published): wait
    # returns by itself, without a timeout, and says so.
    c, seen = FakeClient(), []
    p = participant(c, seen)
    c.status_callback(proto.StatusMsg(header(0), proto.MODE_LOCKSTEP, 5))
    t0 = time.monotonic()
    assert p.wait().run_state == 5
    assert time.monotonic() - t0 < 1.0
    assert p.ended == ("stopped", 0) and seen == [] and p.last_tick == -1
    p.close()


def test_wait_hands_out_a_tick_held_for_a_sample_when_the_run_ends():
    # Tick 1's state is in, one of its IMU samples is not (lost); then the server fails at
    # tick 2. wait hands tick 1 out without the sample, then returns.
    c, seen = FakeClient(), []
    p = participant(c, seen)
    feed_tick(c, 0)
    c.feed("imu/hub", imu(1))
    c.feed("state", state(1))
    assert [t.tick for t in seen] == [0]
    c.status_callback(proto.StatusMsg(header(2), proto.MODE_LOCKSTEP, 4))
    assert p.wait(timeout_s=5).run_state == 4
    assert [(t.tick, t.missing) for t in seen] == [(0, ()), (1, ("imu/bracket",))]
    assert p.ended == ("failed", 2)
    p.close()


def test_wait_times_out_without_an_end_of_run():
    c, seen = FakeClient(), []
    p = participant(c, seen)
    feed_tick(c, 0)
    try:
        p.wait(timeout_s=0.1)
        raise AssertionError("wait returned without an end of run")
    except TimeoutError:
        pass
    assert p.ended is None
    p.close()


def test_an_error_in_the_callback_ends_wait_and_close():
    c = FakeClient()

    def on_state(s):
        raise RuntimeError("control law failed")

    p = flexdyn.LockstepParticipant(c, 1, on_state)
    for route in ("imu/hub", "imu/bracket", "st/st1", "st/st2"):
        c.feed(route, imu(0) if route.startswith("imu") else st(0))
    c.feed("state", state(0))
    for call in (lambda: p.wait(timeout_s=5), p.close):
        try:
            call()
            raise AssertionError("the error was not raised")
        except RuntimeError as e:
            assert str(e) == "control law failed"


ENV_SENSORS_TOML = """
[simulation]
step_s = 0.001
frame_hz = 100.0
[[imus]]
name = "hub"
[[magnetometers]]
name = "mag1"
rate_hz = 10.0
[[coarse_sun_sensors]]
name = "css"
rate_hz = 20.0
[[fine_sun_sensors]]
name = "fss"
rate_hz = 25.0
[[gps_receivers]]
name = "gps1"
rate_hz = 10.0
latency_s = 0.03
"""


def test_magnetometers_and_sun_sensors_are_scheduled_and_delivered_in_the_tick():
    # Periods: round(100 / 10) = 10, round(100 / 20) = 5, round(100 / 25) = 4 frames.
    s = flexdyn.SensorSchedule.from_config(flexdyn.VehicleInfo(
        "sc1", 1, ENV_SENSORS_TOML, "", None, None).config())
    assert s.others == (("mag/mag1", 10), ("css/css", 5), ("fss/fss", 4))
    # The GPS receiver: every 10 frames, published 0.03 s · 100 Hz = 3 frames late (3, 13, …).
    assert s.delayed == (("gps/gps1", 10, 3),)
    assert s.due(0) == ("imu/hub", "mag/mag1", "css/css", "fss/fss")
    assert s.due(3) == ("imu/hub", "gps/gps1")
    assert s.due(5) == ("imu/hub", "css/css")
    assert s.due(8) == ("imu/hub", "fss/fss")
    assert s.due(13) == ("imu/hub", "gps/gps1")
    assert s.due(10) == ("imu/hub", "mag/mag1", "css/css")
    # Every route due at some tick (the periods' least common multiple, 20, after the GPS's
    # 3 frames of latency covers them all), each once.
    due_somewhen = {r for tick in range(23) for r in s.due(tick)}
    assert sorted(s.routes()) == sorted(due_somewhen) and len(s.routes()) == 5

    c, seen = FakeClient(), []
    c.vehicle = lambda timeout_s: flexdyn.VehicleInfo("sc1", 1, ENV_SENSORS_TOML, "", None, None)
    p = participant(c, seen)
    c.feed("imu/hub", imu(0))
    c.feed("mag/mag1", flexdyn.MagnetometerMsg(header(0), (1e-5, 2e-5, 3e-5)))
    c.feed("css/css", flexdyn.CssMsg(header(0), 6, (0.5,) * proto.MAX_CSS_DETECTORS))
    c.feed("state", state(0))
    assert seen == [], "tick 0 answered without fss/fss"
    c.feed("fss/fss", flexdyn.FssMsg(header(0), 0.1, -0.2, 1))
    assert [t.tick for t in seen] == [0] and c.sent == [(0, "none")]
    t = seen[0]
    assert t.magnetometers["mag1"].b_s_t == (1e-5, 2e-5, 3e-5)
    assert t.coarse_sun_sensors["css"].detector_count == 6
    assert t.fine_sun_sensors["fss"].beta_rad == -0.2
    assert set(t.samples) == {"imu/hub", "mag/mag1", "css/css", "fss/fss"}
    assert t.missing == ()
    # Tick 1: the IMU only.
    c.feed("imu/hub", imu(1))
    c.feed("state", state(1))
    assert [t.tick for t in seen] == [0, 1] and seen[1].magnetometers == {}
    # Tick 3: the GPS solution valid at tick 0 is awaited.
    c.feed("imu/hub", imu(3))
    c.feed("state", state(3))
    assert [t.tick for t in seen] == [0, 1], "tick 3 answered without gps/gps1"
    c.feed("gps/gps1", flexdyn.GpsMsg(header(3), valid_sim_time_ns=0, flags=1))
    assert [t.tick for t in seen] == [0, 1, 3]
    assert seen[2].gps["gps1"].valid_sim_time_ns == 0 and seen[2].missing == ()
    p.close()


def fault(index, mode, target, active, tick, edge_tick):
    code = [m[0] for m in proto.FAULT_MODES].index(mode)
    return proto.FaultEventMsg(header(tick), fault_index=index, mode=code, active=active,
                               edge_ns=edge_tick * 10_000_000,
                               target=proto._target_bytes(target))


def test_a_dropout_fault_event_stops_the_wait_for_the_samples_it_withholds():
    # Ticks 1, 3, 7, 9: only the IMUs are due (st1 every 10 ticks, st2 every 4).
    c, seen = FakeClient(), []
    p = participant(c, seen, sensor_timeout_s=3600)
    c.feed("imu/hub", imu(3))
    c.feed("state", state(3))  # imu/bracket of tick 3 is withheld from tick 3 on
    c.feed("fault", fault(0, "bias_step", "imus.hub.gyro", True, 3, 3))
    assert seen == [], "a bias withholds nothing"
    c.feed("fault", fault(1, "dropout", "imus.nowhere", True, 3, 3))
    assert seen == [], "not a sensor of the schedule"
    c.feed("fault", fault(2, "dropout", "imus.bracket", True, 3, 3))
    assert [(t.tick, t.missing) for t in seen] == [(3, ("imu/bracket",))]
    c.feed("imu/hub", imu(7))
    c.feed("state", state(7))  # released with its state
    assert [(t.tick, t.missing) for t in seen][1:] == [(7, ("imu/bracket",))]
    # Cleared at tick 9 (its event after the state of 9): tick 9's sample is there again.
    c.feed("imu/hub", imu(9))
    c.feed("imu/bracket", imu(9))
    c.feed("state", state(9))
    c.feed("fault", fault(2, "dropout", "imus.bracket", False, 9, 9))
    assert [(t.tick, t.missing) for t in seen][2:] == [(9, ())]
    c.feed("imu/hub", imu(11))
    c.feed("state", state(11))
    assert len(seen) == 3, "no dropout any more: imu/bracket of tick 11 is waited for"
    assert p.incomplete_ticks == 2 and [s[0] for s in c.sent] == [3, 7, 9]
    p.close()


def test_a_participant_declares_the_keys_it_reads_at_every_tick():
    # Declared keys are routed by a route Zenoh computed once (Client.declare_keys); the
    # participant's are the state, the time service, the environment and fault events, and
    # every sensor sample of its schedule, under the spacecraft's telemetry prefix.
    c, seen = FakeClient(), []
    c.vehicle = lambda timeout_s: flexdyn.VehicleInfo("sc1", 1, ENV_SENSORS_TOML, "", None, None)
    p = participant(c, seen)
    expected = ["flexdyn/sc1/tlm/" + r for r in ("time", "state", "env", "fault", "imu/hub",
                                                 "mag/mag1", "css/css", "fss/fss", "gps/gps1")]
    assert c.declared == expected
    assert proto.state_key("sc1") in c.declared and proto.gps_key("sc1", "gps1") in c.declared
    p.close()
