"""Lockstep participation with complete ticks.

The server publishes, for each tick k, the sample of every sensor due at k (IMUs, star
trackers, magnetometers, sun sensors, GPS solutions), then the StateMsg of k (proto/README.md, "Lockstep protocol"). A controller that reads
sensors must answer tick k from exactly those samples; it is then as deterministic as the
server. :class:`LockstepParticipant` makes sure of it:

- it learns from the server's configuration queryable (``flexdyn/<sc>/config``) which sensors
  exist and at which ticks each one publishes (:class:`SensorSchedule`), instead of guessing;
- it sees the telemetry through the client's one ``flexdyn/<sc>/tlm/**`` subscriber, in the
  order it was published, and holds the StateMsg of tick k until every sample due at k is in;
- only then does it call your ``on_state(state)`` (after every ``subscribe_imu`` /
  ``subscribe_star_tracker`` callback of that tick has run) or ``on_tick(tick)`` (with the
  samples in a :class:`Tick`), and send the answer.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Tuple, Union

from . import proto
from .client import Client, Vec3
from .proto import (CommandMsg, CssMsg, FssMsg, ImuMsg, MagnetometerMsg, StarTrackerMsg, StateMsg,
                    StatusMsg)

log = logging.getLogger("flexdyn")

#: What ``on_state`` / ``on_tick`` returns: None (NoCommand), a (torque_b_nm, force_b_newton)
#: pair (Wrench), or a CommandMsg whose kind and body are sent (its header and sender are set
#: here).
Answer = Optional[Union[Tuple[Vec3, Vec3], CommandMsg]]

#: run_state values of a run's last StatusMsg: Finished, Failed, Stopped, and their words.
_ENDED = {3: "finished", 4: "failed", 5: "stopped"}

#: Once the end of the run is heard, :meth:`LockstepParticipant.wait` returns as soon as a slice
#: this long passes with no tick handed out (the frames still queued go first).
_END_SLICE_S = 0.02


#: The sensor kinds that publish at a rate: (configuration array, key kind, Tick attribute).
#: Each entry of the array publishes on the ticks that are multiples of round(frame_hz /
#: rate_hz), from tick 0, under ``flexdyn/<sc>/tlm/<kind>/<name>``.
PERIODIC_KINDS: Tuple[Tuple[str, str, str], ...] = (
    ("star_trackers", "st", "star_trackers"),
    ("magnetometers", "mag", "magnetometers"),
    ("coarse_sun_sensors", "css", "coarse_sun_sensors"),
    ("fine_sun_sensors", "fss", "fine_sun_sensors"),
)


def _periods(config: dict, array: str, frame_hz: float) -> Tuple[Tuple[str, int], ...]:
    out = []
    for i, entry in enumerate(config.get(array, [])):
        rate_hz = float(entry["rate_hz"])
        every = round(frame_hz / rate_hz) if rate_hz > 0 and math.isfinite(rate_hz) else 0
        if every < 1:
            raise ValueError(f"{array}[{i}].rate_hz = {rate_hz}: not the frame rate "
                             f"({frame_hz} Hz) divided by a whole number")
        out.append((str(entry["name"]), every))
    return tuple(out)


#: The configuration sections of the sensor kinds and their telemetry route prefixes.
_SENSOR_SECTIONS = {"imus": "imu", "star_trackers": "st", "magnetometers": "mag",
                    "coarse_sun_sensors": "css", "fine_sun_sensors": "fss",
                    "gps_receivers": "gps"}


@dataclass(frozen=True)
class SensorSchedule:
    """Which sensor samples the server publishes at each tick, read from its configuration:
    every ``[[imus]]`` entry each tick (route ``imu/<name>``), each ``[[star_trackers]]`` entry
    on the ticks that are multiples of its period, round(``simulation.frame_hz`` /
    ``rate_hz``) frames, from tick 0 (route ``st/<name>``), and the same for the other
    rate-driven kinds of :data:`PERIODIC_KINDS` (``mag/<name>``, ``css/<name>``,
    ``fss/<name>``); each ``[[gps_receivers]]`` entry on the ticks latency + n · period
    (route ``gps/<name>``; latency = ``latency_s`` · ``frame_hz`` frames, 0 when absent: each
    solution is published that long after the instant it is valid)."""

    imus: Tuple[str, ...]
    #: (name, period in frames)
    star_trackers: Tuple[Tuple[str, int], ...]
    #: (route, period in frames) of the magnetometers and sun sensors
    others: Tuple[Tuple[str, int], ...] = ()
    #: (route, period in frames, latency in frames) of the GPS receivers
    delayed: Tuple[Tuple[str, int, int], ...] = ()

    @classmethod
    def from_config(cls, config: dict) -> "SensorSchedule":
        """From a parsed configuration (see :meth:`flexdyn.VehicleInfo.config`)."""
        frame_hz = float(config["simulation"]["frame_hz"])
        others = tuple((f"{kind}/{name}", every)
                       for array, kind, _ in PERIODIC_KINDS[1:]
                       for name, every in _periods(config, array, frame_hz))
        delayed = []
        for (name, every), gps in zip(_periods(config, "gps_receivers", frame_hz),
                                      config.get("gps_receivers", [])):
            latency = float(gps.get("latency_s", 0.0)) * frame_hz
            if not (math.isfinite(latency) and latency >= 0
                    and abs(latency - round(latency)) < 1e-9):
                raise ValueError(f"gps_receivers `{name}`.latency_s = {gps.get('latency_s')}: "
                                 f"not a whole number of frames at {frame_hz} Hz")
            delayed.append((f"gps/{name}", every, round(latency)))
        return cls(tuple(str(imu["name"]) for imu in config.get("imus", [])),
                   _periods(config, "star_trackers", frame_hz), others, tuple(delayed))

    def _entries(self) -> List[Tuple[str, int, int]]:
        """(route, period in frames, latency in frames) of every scheduled sample, in
        publication order: an IMU each frame, the rate-driven kinds from tick 0."""
        return ([(f"imu/{n}", 1, 0) for n in self.imus]
                + [(f"st/{n}", every, 0) for n, every in self.star_trackers]
                + [(r, every, 0) for r, every in self.others]
                + list(self.delayed))

    def routes(self) -> Tuple[str, ...]:
        """The route of every sensor sample the schedule awaits at some tick, in the order of
        :meth:`due`."""
        return tuple(r for r, _, _ in self._entries())

    def due(self, tick: int) -> Tuple[str, ...]:
        """The routes of the samples published at `tick` (``imu/<name>``, ``st/<name>``,
        ``mag/<name>``, ...)."""
        return tuple(r for r, every, latency in self._entries()
                     if tick >= latency and (tick - latency) % every == 0)


@dataclass
class Tick:
    """One tick's telemetry: its StateMsg and the sensor samples due at it, by kind and name."""

    state: StateMsg
    imu: Dict[str, ImuMsg] = field(default_factory=dict)
    star_trackers: Dict[str, StarTrackerMsg] = field(default_factory=dict)
    magnetometers: Dict[str, MagnetometerMsg] = field(default_factory=dict)
    coarse_sun_sensors: Dict[str, CssMsg] = field(default_factory=dict)
    fine_sun_sensors: Dict[str, FssMsg] = field(default_factory=dict)
    #: GPS solutions published at this tick (a receiver with latency publishes on ticks of its
    #: own, see :class:`SensorSchedule`; each says when it was valid).
    gps: Dict[str, proto.GpsMsg] = field(default_factory=dict)
    #: Every sample of the tick by route (``<kind>/<name>``), also of kinds without a field
    #: above.
    samples: Dict[str, object] = field(default_factory=dict)
    #: Routes of due samples that never came (``imu/<name>``, ``st/<name>``, ...). Empty in
    #: lockstep unless a sample was lost; see ``sensor_timeout_s``.
    missing: Tuple[str, ...] = ()

    @property
    def tick(self) -> int:
        return self.state.header.tick


#: The Tick attribute of each sensor key kind.
_TICK_FIELD = {"imu": "imu", "gps": "gps",
               **{kind: attr for _, kind, attr in PERIODIC_KINDS}}


class LockstepParticipant:
    """A lockstep participant that answers every tick from the tick's complete telemetry.

    On creation it asks the server's configuration queryable which sensors publish when
    (``config_timeout_s``), registers on the client's telemetry stream, and only then declares
    its liveliness token (so the server cannot publish tick 0 before it can be received).
    For every tick it calls exactly one of

    - ``on_state(state)``: after every sample due at that tick has been delivered to the
      client's ``subscribe_imu`` / ``subscribe_star_tracker`` callbacks, so state kept by
      those callbacks is that tick's;
    - ``on_tick(tick)``: with a :class:`Tick` holding the state and those samples,

    and sends what it returns, stamped with the state's tick. A sensor in a ``dropout`` fault
    publishes nothing: the fault events (``flexdyn/<sc>/tlm/fault``, after the state of their
    boundary) say so, and its samples are not waited for; the tick goes without them, listed in
    ``Tick.missing`` and counted in ``incomplete_ticks``. Any other due sample that has not come
    ``sensor_timeout_s`` after its state (lost; it cannot happen in lockstep) releases the tick
    the same way. In real time, where the server drops samples under load, a later
    tick's sample releases a waiting tick at once the same way.

    The end of the run: the server's last StatusMsg on ``flexdyn/<sc>/status`` (run_state
    Finished, Failed or Stopped; proto/README.md, "StatusMsg"), heard on a subscription the
    participant declares before its telemetry. :meth:`wait` blocks until it has come and every
    tick received before it has been handed to the callback, then returns it; :attr:`ended`
    says how the run ended (``None`` before, then e.g. ``("finished", 300)``). :meth:`close`
    stops (token first, so the server sees it leave) and raises the first error of the
    callback, if any.
    """

    def __init__(self, client: Client, sender_id: int,
                 on_state: Optional[Callable[[StateMsg], Answer]] = None, *,
                 on_tick: Optional[Callable[[Tick], Answer]] = None,
                 sensor_timeout_s: float = 5.0, config_timeout_s: float = 30.0) -> None:
        if (on_state is None) == (on_tick is None):
            raise TypeError("LockstepParticipant takes exactly one of on_state and on_tick")
        self.client = client
        self.sender_id = sender_id
        self.on_state = on_state
        self.on_tick = on_tick
        self.sensor_timeout_s = sensor_timeout_s
        self.answered = 0
        self.incomplete_ticks = 0
        self.errors: List[BaseException] = []
        self.vehicle = client.vehicle(timeout_s=config_timeout_s)
        if self.vehicle.spacecraft_id != client.spacecraft_id:
            raise ValueError(
                f"the server's spacecraft_id is {self.vehicle.spacecraft_id} and the Client's "
                f"{client.spacecraft_id}: its commands would be rejected (wrong spacecraft). "
                f"Pass spacecraft_id={self.vehicle.spacecraft_id} to flexdyn.Client")
        self.schedule = SensorSchedule.from_config(self.vehicle.config())
        # The tick being assembled: its state once it has come, and samples by tick.
        self._held: Optional[StateMsg] = None
        self._samples: Dict[int, Dict[str, object]] = {}
        # Dropout intervals from the fault events: [fault index, route, from ns, until ns|None].
        self._withheld: List[list] = []
        self._last_tick = -1  # the last tick handed to the callback
        self._timer: Optional[threading.Timer] = None
        self._final: Optional[StatusMsg] = None
        self._changed = threading.Condition()
        self._status_sub = client.subscribe_status(self._on_status)
        client.add_telemetry_tap(self._on_sample)
        # The keys it reads at every tick, declared (Client.declare_keys): the state, the time
        # service, the environment and fault events, and every scheduled sensor's.
        prefix = proto.telemetry_key(client.sc_id)[:-2]
        client.declare_keys(prefix + route for route in
                            ("time", "state", "env", "fault") + self.schedule.routes())
        self._token = client.session.liveliness().declare_token(
            proto.participant_key(client.sc_id, sender_id))

    # -- assembling ticks (on the client's telemetry thread, one sample at a time) ------------

    def _on_sample(self, route: str, msg) -> None:
        if route == "fault":
            # Not a sensor sample, but a dropout fault's edges say which samples the server
            # withholds: those are not waited for.
            self._note_fault(msg)
            if self._held is not None and not self._awaited():
                self._release()
            return
        if route in ("time", "env") or route.startswith("rel/"):
            # The time service, environment truth and a fleet deputy's relative state are not
            # sensor samples.
            return
        tick = msg.header.tick
        if tick <= self._last_tick:
            return  # a tick already answered (a sample that came after its timeout)
        if self._held is not None and tick > self._held.header.tick:
            self._release()  # the held tick's missing samples will not come any more
        if route == "state":
            for t in [t for t in self._samples if t < tick]:
                del self._samples[t]  # sensor samples of a state that never came (real time)
            self._held = msg
        else:
            self._samples.setdefault(tick, {})[route] = msg
        if self._held is not None:
            if self._awaited():
                self._arm_timer(self._held.header.tick)
            else:
                self._release()

    def _missing(self) -> Tuple[str, ...]:
        h = self._held
        have = self._samples.get(h.header.tick, {})
        return tuple(r for r in self.schedule.due(h.header.tick) if r not in have)

    def _note_fault(self, ev: proto.FaultEventMsg) -> None:
        """Notes a ``dropout`` fault's activation or clearance on a sensor (``imus.hub``)."""
        if ev.mode_name != "dropout":
            return
        parts = ev.target_str.split(".")
        prefix = _SENSOR_SECTIONS.get(parts[0])
        if prefix is None or len(parts) < 2:
            return
        if ev.active:
            self._withheld.append([ev.fault_index, f"{prefix}/{parts[1]}", ev.edge_ns, None])
            return
        for w in reversed(self._withheld):
            if w[0] == ev.fault_index and w[3] is None:
                w[3] = ev.edge_ns
                break

    def _awaited(self) -> Tuple[str, ...]:
        """The held tick's missing samples still to wait for: those no dropout withholds."""
        t = self._held.header.sim_time_ns

        def withheld(route: str) -> bool:
            return any(r == route and start <= t and (end is None or t < end)
                       for _, r, start, end in self._withheld)
        return tuple(r for r in self._missing() if not withheld(r))

    def _arm_timer(self, tick: int) -> None:
        if self._timer is None:
            self._timer = threading.Timer(self.sensor_timeout_s, self._on_timeout, (tick,))
            self._timer.daemon = True
            self._timer.start()

    def _on_timeout(self, tick: int) -> None:
        with self.client._dispatch:
            if self._held is not None and self._held.header.tick == tick:
                self._timer = None
                self._release()

    def _release(self) -> None:
        """Hands the held state and its samples to the callback and sends the answer."""
        state, self._held = self._held, None
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        h = state.header
        self._withheld = [w for w in self._withheld if w[3] is None or w[3] > h.sim_time_ns]
        samples = self._samples.pop(h.tick, {})
        missing = tuple(r for r in self.schedule.due(h.tick) if r not in samples)
        if missing:
            self.incomplete_ticks += 1
            if self.incomplete_ticks == 1 or self.incomplete_ticks % 100 == 0:
                log.warning("tick %d: no sample from %s; answering without it (%d incomplete "
                            "ticks so far)", h.tick, ", ".join(missing), self.incomplete_ticks)
        self._last_tick = h.tick
        try:
            if self.on_tick is not None:
                t = Tick(state, missing=missing, samples=dict(samples))
                for route, msg in samples.items():
                    kind, name = route.split("/", 1)
                    if kind in _TICK_FIELD:
                        getattr(t, _TICK_FIELD[kind])[name] = msg
                self._send(h, self.on_tick(t))
            else:
                self._send(h, self.on_state(state))
            self.answered += 1
        except BaseException as e:  # reported by wait() and close(); the server times out on us
            self.errors.append(e)
        with self._changed:
            self._changed.notify_all()

    def _send(self, h: proto.Header, a: Answer) -> None:
        if a is None:
            self.client.send_no_command(self.sender_id, h.tick, h.sim_time_ns)
        elif isinstance(a, CommandMsg):
            a.header = self.client._header(h.tick, h.sim_time_ns)
            a.sender_id = self.sender_id
            self.client.send(a)
        else:
            torque, force = a
            self.client.send_wrench(self.sender_id, h.tick, h.sim_time_ns, torque, force)

    # -- the end of the run ------------------------------------------------------------------

    def _on_status(self, status: StatusMsg) -> None:
        if status.run_state in _ENDED:
            with self._changed:
                if self._final is None:  # the first end heard
                    self._final = status
                self._changed.notify_all()

    @property
    def last_tick(self) -> int:
        """The last tick handed to the callback (-1 before the first)."""
        return self._last_tick

    @property
    def ended(self) -> Optional[Tuple[str, int]]:
        """How the run ended, once the server's last StatusMsg said so: ``("finished", tick)``,
        ``("failed", tick)`` or ``("stopped", tick)`` with the last tick the server stepped;
        ``None`` before. (:attr:`final_status` is the whole message.)"""
        final = self._final
        if final is None:
            return None
        return _ENDED[final.run_state], final.header.tick

    @property
    def final_status(self) -> Optional[StatusMsg]:
        """The server's last StatusMsg (Finished, Failed or Stopped), ``None`` before."""
        return self._final

    def wait(self, timeout_s: Optional[float] = None) -> StatusMsg:
        """Blocks until the run has ended and returns the server's last StatusMsg (run_state
        Finished, Failed or Stopped; :attr:`ended` says the same in words). Every tick received
        before it is handed to the callback first: `wait` returns once the tick of that status
        has been answered, or else (a run that ended before its tick was published, e.g.
        stopped before tick 0) as soon as 20 ms pass with no tick handed out after the status
        came; a tick still held for a sensor sample then goes out without it. Raises the
        callback's first error as soon as there is one, and ``TimeoutError`` after `timeout_s`
        without an end of run."""
        def done() -> bool:
            return bool(self.errors) or (self._final is not None
                                          and self._last_tick >= self._final.header.tick)

        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        with self._changed:
            while not done():
                if self._final is not None:
                    # The end was heard but not its tick: wait a slice for the ticks still
                    # queued, then (no callback running: it holds the client's dispatch lock)
                    # hand out a tick still held for a sample, or stop.
                    before = self._last_tick
                    if self._changed.wait_for(done, _END_SLICE_S) or self._last_tick != before:
                        continue
                    self._changed.release()
                    try:
                        with self.client._dispatch:
                            progressed = self._last_tick != before
                            if not progressed and self._held is not None:
                                self._release()  # as the sensor timeout would, but now
                                progressed = True
                    finally:
                        self._changed.acquire()
                    if progressed:
                        continue
                    break  # nothing queued, nothing held: the run is over
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    raise TimeoutError(
                        f"the run did not end within {timeout_s} s (last tick answered: "
                        f"{self._last_tick}; no final status yet)")
                self._changed.wait(left)
        if self.errors:
            raise self.errors[0]
        return self._final

    def close(self) -> None:
        """Undeclares the token, then stops listening; raises the first callback error."""
        self._token.undeclare()
        self.client.remove_telemetry_tap(self._on_sample)
        with self.client._dispatch:
            if self._timer is not None:
                self._timer.cancel()
                self._timer = None
        self._status_sub.undeclare()
        if self._status_sub in self.client._subscribers:
            self.client._subscribers.remove(self._status_sub)
        if self.errors:
            raise self.errors[0]

    def __enter__(self) -> "LockstepParticipant":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
