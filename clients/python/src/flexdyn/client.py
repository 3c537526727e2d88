"""Zenoh transport the flexdyn way: a peer session with multicast scouting off, connected to
the given loopback endpoint(s), and typed helpers for the server's topics.

Every telemetry callback of a :class:`Client` (state, IMUs, star trackers) is fed by **one**
Zenoh subscriber on ``flexdyn/<sc>/tlm/**``, one sample at a time, in the order the server
published them (a tick's sensor samples, then its state). Separate Zenoh subscribers would each
be delivered on their own thread, and a StateMsg could then overtake the ImuMsg of its own tick
(proto/README.md, "Lockstep protocol").
"""

from __future__ import annotations

import json
import logging
import collections
import threading
import time
from dataclasses import dataclass
from typing import (TYPE_CHECKING, Any, Callable, Dict, Iterable, List, Optional, Sequence,
                    Tuple, Union)

import zenoh

from . import proto
if TYPE_CHECKING:  # the stream class, for annotations only (fsw imports nothing from here)
    from .fsw import FswStream
from .proto import (CommandMsg, CssMsg, EffectorInput, EnvironmentMsg, FssMsg, Header, ImuMsg,
                    MagnetometerMsg, OperatorMsg, StarTrackerMsg, StateMsg, StatusMsg, TimeMsg)

Vec3 = Tuple[float, float, float]

log = logging.getLogger("flexdyn")


def session_config(endpoints: Sequence[str], zenoh_config: Optional[str] = None) -> zenoh.Config:
    """Peer mode, connect to `endpoints`, listen nowhere, multicast scouting off.

    ``zenoh_config`` is a Zenoh JSON5 file to start from instead of the defaults, e.g. one with
    ``transport/auth/usrpwd`` credentials for a server on a lab network (see
    docs/guides/lab-network.md); the endpoints and the scouting rule still apply."""
    conf = zenoh.Config.from_file(zenoh_config) if zenoh_config else zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("connect/endpoints", json.dumps(list(endpoints)))
    conf.insert_json5("listen/endpoints", "[]")
    conf.insert_json5("scouting/multicast/enabled", "false")
    return conf


@dataclass(frozen=True)
class VehicleInfo:
    """The server's answer on ``flexdyn/<sc>/config`` (proto/README.md, "Topics"): what it runs.
    ``config_toml`` is the configuration file verbatim; ``server_settings`` the settings in
    effect as ``key=value`` pairs."""

    sc_id: str
    spacecraft_id: int
    config_toml: str
    server_settings: str
    flexdyn_version: Optional[str]
    git_commit: Optional[str]

    def config(self) -> Dict[str, Any]:
        """The configuration, parsed (``tomllib``; ``tomli`` before Python 3.11)."""
        try:
            import tomllib
        except ImportError:  # Python < 3.11
            import tomli as tomllib  # type: ignore[no-redef]
        return tomllib.loads(self.config_toml)


#: The decoder of each telemetry key kind: the part of the key after ``flexdyn/<sc>/tlm/``
#: is ``state``, ``time``, ``env`` or ``<kind>/<name>`` for a sensor (``imu``, ``st``, ``mag``,
#: ``css``, ``fss``; proto/README.md, "Keys").
_DECODERS = {"state": StateMsg.decode, "imu": ImuMsg.decode, "st": StarTrackerMsg.decode,
             "mag": MagnetometerMsg.decode, "css": CssMsg.decode, "fss": FssMsg.decode,
             "time": TimeMsg.decode, "env": EnvironmentMsg.decode}
_DECODERS["gps"] = proto.GpsMsg.decode  # protocol 7: tlm/gps/<name>
_DECODERS["fault"] = proto.FaultEventMsg.decode  # protocol 8: tlm/fault
_DECODERS["rel"] = proto.RelativeStateMsg.decode  # protocol 9: tlm/rel/<chief>


class Subscription:
    """A callback registered on a :class:`Client`; ``undeclare()`` removes it."""

    def __init__(self, client: "Client", route: str, callback: Callable) -> None:
        self._client, self._route, self._callback = client, route, callback

    def undeclare(self) -> None:
        self._client._telemetry_remove(self._route, self._callback)


class Client:
    """A Zenoh session to one flexdyn server and spacecraft.

    ``endpoint`` is the server's ``--listen`` endpoint (e.g. ``tcp/127.0.0.1:7447``), or a list
    of them; ``sc_id`` the string spacecraft id of the keys; ``spacecraft_id`` the numeric id
    written into command headers (the server's ``spacecraft_id`` setting, 1 by default).
    """

    def __init__(self, endpoint: Union[str, Iterable[str]], sc_id: str = "sc1",
                 spacecraft_id: int = 1, zenoh_config: Optional[str] = None) -> None:
        endpoints = [endpoint] if isinstance(endpoint, str) else list(endpoint)
        self.sc_id = sc_id
        self.spacecraft_id = spacecraft_id
        self._tlm_prefix = proto.telemetry_key(sc_id)[:-2]  # "flexdyn/<sc>/tlm/"
        self.session = zenoh.open(session_config(endpoints, zenoh_config))
        # One publisher per sender id, on flexdyn/<sc>/cmd/<sender_id>, declared on first use.
        self._command_pubs: dict = {}
        self._subscribers: List[object] = []
        self._seq = 0
        self._lock = threading.Lock()
        # Publishing happens on Zenoh callback threads (a participant's answers) as well as the
        # caller's; this lock keeps a put and close() from overlapping.
        self._pub_lock = threading.Lock()
        self._closed = False
        # Keys declared to the session (`Session.declare_keyexpr`), by key, for the Client's
        # life: the command keys and the telemetry keys read at every tick (`declare_keys`).
        self._declared: Dict[str, object] = {}
        # Telemetry: one subscriber on flexdyn/<sc>/tlm/**, declared on first use; the callbacks
        # by route ("state", "imu/<name>", "st/<name>"), then the taps (every decoded sample).
        # `_dispatch` is held while a sample is delivered, so callbacks never overlap.
        self._dispatch = threading.RLock()
        self._routes: Dict[str, List[Callable]] = {}
        self._taps: List[Callable[[str, object], None]] = []
        self._telemetry_sub: Optional[object] = None
        # The time service (now / wait_tick): the last TimeMsg and its condition, on first use.
        self._time_cond: Optional[threading.Condition] = None
        self._now: Optional[TimeMsg] = None
        # The last 1024 TimeMsgs (10 s at 100 Hz), oldest first, shared by every waiter, and
        # per thread the tick wait_tick handed it last.
        self._ticks: collections.deque = collections.deque(maxlen=1024)
        self._waited = threading.local()
        #: Undecodable telemetry samples received (a sample that is not the message its key says).
        self.undecodable = 0
        #: Exceptions raised by telemetry callbacks (logged on the ``flexdyn`` logger; the other
        #: callbacks of the same sample still run).
        self.callback_errors: List[BaseException] = []

    # -- declared keys ---------------------------------------------------------------------

    def _declared_key(self, key: str):
        with self._lock:
            declared = self._declared.get(key)
            if declared is None:
                declared = self._declared[key] = self.session.declare_keyexpr(key)
            return declared

    def declare_keys(self, keys: Iterable[str]) -> None:
        """Declares each of `keys` to the session (``Session.declare_keyexpr``), once, for as
        long as the Client lives. Zenoh then routes a declared key's samples by a route it
        computed once, instead of matching each sample against the subscriptions (the
        telemetry subscriber's ``tlm/**`` is a wildcard): for the keys received or sent at every
        tick. The route subscriptions, the command publishers and :class:`LockstepParticipant`
        declare theirs (docs/guides/flight-code.md)."""
        for key in keys:
            self._declared_key(key)

    # -- subscriptions ---------------------------------------------------------------------

    def _on_telemetry(self, sample) -> None:
        key = str(sample.key_expr)
        if not key.startswith(self._tlm_prefix):
            return
        route = key[len(self._tlm_prefix):]
        decode = _DECODERS.get(route.split("/", 1)[0])
        if decode is None:
            return
        with self._dispatch:
            callbacks = list(self._routes.get(route, ()))
            taps = list(self._taps)
            if not callbacks and not taps:
                return
            try:
                msg = decode(sample.payload.to_bytes())
            except proto.DecodeError:
                self.undecodable += 1
                return
            calls = [(c, (msg,)) for c in callbacks] + [(t, (route, msg)) for t in taps]
            for fn, args in calls:
                try:
                    fn(*args)
                except BaseException as e:  # one callback's failure does not starve the others
                    if len(self.callback_errors) < 100:
                        self.callback_errors.append(e)
                    log.exception("a flexdyn telemetry callback on %s raised", key)

    def _telemetry_subscriber(self) -> None:
        """Declares the one ``tlm/**`` subscriber (once)."""
        with self._dispatch:
            if self._telemetry_sub is None:
                self._telemetry_sub = self.session.declare_subscriber(
                    proto.telemetry_key(self.sc_id), self._on_telemetry)

    def _telemetry_add(self, route: str, callback: Callable) -> Subscription:
        self._declared_key(self._tlm_prefix + route)
        with self._dispatch:
            self._routes.setdefault(route, []).append(callback)
        self._telemetry_subscriber()
        return Subscription(self, route, callback)

    def _telemetry_remove(self, route: str, callback: Callable) -> None:
        with self._dispatch:
            callbacks = self._routes.get(route, [])
            if callback in callbacks:
                callbacks.remove(callback)

    def add_telemetry_tap(self, tap: Callable[[str, object], None]) -> None:
        """Calls ``tap(route, msg)`` with every telemetry sample, after the callbacks of its
        route: ``route`` is ``"state"``, ``"imu/<name>"`` or ``"st/<name>"``, ``msg`` the decoded
        message. (The lockstep participant's view of the stream.)"""
        with self._dispatch:
            self._taps.append(tap)
        self._telemetry_subscriber()

    def remove_telemetry_tap(self, tap: Callable[[str, object], None]) -> None:
        """Removes a tap added by :meth:`add_telemetry_tap`."""
        with self._dispatch:
            if tap in self._taps:
                self._taps.remove(tap)

    def subscribe_state(self, callback: Callable[[StateMsg], None]) -> Subscription:
        """Calls `callback` with every StateMsg (on a Zenoh thread; after the sensor samples
        the server published before it)."""
        return self._telemetry_add("state", callback)

    def subscribe_imu(self, name: str, callback: Callable[[ImuMsg], None]) -> Subscription:
        """Calls `callback` with every sample of the IMU `name` (before the StateMsg of its
        tick)."""
        return self._telemetry_add(proto.imu_key(self.sc_id, name)[len(self._tlm_prefix):],
                                   callback)

    def subscribe_star_tracker(self, name: str,
                               callback: Callable[[StarTrackerMsg], None]) -> Subscription:
        """Calls `callback` with every measurement of the star tracker `name` (before the
        StateMsg of its tick)."""
        key = proto.star_tracker_key(self.sc_id, name)
        return self._telemetry_add(key[len(self._tlm_prefix):], callback)

    def subscribe_magnetometer(self, name: str,
                               callback: Callable[[MagnetometerMsg], None]) -> Subscription:
        """Calls `callback` with every sample of the magnetometer `name` (before the StateMsg
        of its tick)."""
        key = proto.magnetometer_key(self.sc_id, name)
        return self._telemetry_add(key[len(self._tlm_prefix):], callback)

    def subscribe_coarse_sun_sensor(self, name: str,
                                    callback: Callable[[CssMsg], None]) -> Subscription:
        """Calls `callback` with every sample of the coarse-sun-sensor array `name` (before
        the StateMsg of its tick)."""
        key = proto.css_key(self.sc_id, name)
        return self._telemetry_add(key[len(self._tlm_prefix):], callback)

    def subscribe_fine_sun_sensor(self, name: str,
                                  callback: Callable[[FssMsg], None]) -> Subscription:
        """Calls `callback` with every sample of the fine sun sensor `name` (before the
        StateMsg of its tick)."""
        key = proto.fss_key(self.sc_id, name)
        return self._telemetry_add(key[len(self._tlm_prefix):], callback)

    def subscribe_time(self, callback: Callable[[TimeMsg], None]) -> Subscription:
        """Calls `callback` with every TimeMsg, the time service (``flexdyn/<sc>/tlm/time``,
        one per frame, before the frame's sensors and state)."""
        return self._telemetry_add("time", callback)

    def subscribe_environment(self, callback: Callable[[EnvironmentMsg], None]) -> Subscription:
        """Calls `callback` with every EnvironmentMsg (``flexdyn/<sc>/tlm/env``, truth at the
        configured ``[environment] telemetry_rate_hz``)."""
        return self._telemetry_add("env", callback)

    def subscribe_gps(self, name: str, callback: Callable[[proto.GpsMsg], None]) -> Subscription:
        """Calls `callback` with every solution of the GPS receiver `name`
        (``flexdyn/<sc>/tlm/gps/<name>``, published its latency after the instant it is valid)."""
        key = proto.gps_key(self.sc_id, name)
        return self._telemetry_add(key[len(self._tlm_prefix):], callback)

    def subscribe_fault_events(self, callback: Callable[[proto.FaultEventMsg], None]
                               ) -> Subscription:
        """Calls `callback` with every FaultEventMsg (``flexdyn/<sc>/tlm/fault``): a fault's
        activation or clearance, at the frame boundary where it takes effect (protocol 8)."""
        return self._telemetry_add("fault", callback)

    def subscribe_relative_state(self, chief: str,
                                 callback: Callable[[proto.RelativeStateMsg], None]
                                 ) -> Subscription:
        """Calls `callback` with every RelativeStateMsg of this vehicle (a fleet deputy)
        relative to vehicle `chief` (``flexdyn/<sc>/tlm/rel/<chief>``, every frame after the
        StateMsg; protocol 9)."""
        key = proto.relative_state_key(self.sc_id, chief)
        return self._telemetry_add(key[len(self._tlm_prefix):], callback)

    def _clock(self) -> threading.Condition:
        # Under _dispatch (not _lock: a callback that sends holds _dispatch, then takes _lock).
        with self._dispatch:
            if self._time_cond is None:
                self._time_cond = threading.Condition()
                self.subscribe_time(self._on_time)
            return self._time_cond

    def _on_time(self, msg: TimeMsg) -> None:
        cond = self._time_cond
        with cond:
            self._now = msg
            self._ticks.append(msg)
            cond.notify_all()

    def now(self) -> Optional[TimeMsg]:
        """The last TimeMsg received (``None`` before the first): the simulation's time, the
        one clock flight code should follow (it stops while the run is paused and runs at the
        server's ``--speed``). The first call subscribes."""
        self._clock()
        return self._now

    def _tick_after(self, last: int) -> Optional[TimeMsg]:
        """The held TimeMsg after tick `last` (under the clock's condition): the next one, the
        oldest held if `last` is older than all of them, or the first of a new run when the
        ticks went back (a server restarted on the same keys); ``None`` if none yet."""
        ticks = self._ticks
        n = len(ticks)
        if n == 0:
            return None
        if ticks[-1].header.tick < last:
            j = n - 1
            while j > 0 and ticks[j - 1].header.tick < ticks[j].header.tick:
                j -= 1
            return ticks[j]
        i = n - 1  # from the newest: a waiter that keeps up looks at one or two
        while i >= 0 and ticks[i].header.tick > last:
            i -= 1
        return ticks[i + 1] if i + 1 < n else None

    def wait_tick(self, timeout_s: float = 10.0) -> TimeMsg:
        """Blocks until the next TimeMsg and returns it; ``TimeoutError`` after ``timeout_s`` s of
        wall time without one (the server is gone, or the run is paused). A thread's first call
        returns the first tick newer than :meth:`now` at the call; each later call returns the
        tick after the one it returned last to that thread, in order and without a gap, even
        when the thread woke late (the client holds the last 1024 ticks; a thread further
        behind resumes at the oldest held). Each thread has its own position, so two rate
        groups on two threads each see every tick; a server restarted on the same keys
        (ticks going back) starts them again at its first tick held. A rate-group driver calls
        it in a loop: one call per frame, ``msg.flags & proto.TIME_TONE`` on the 1 Hz tone."""
        cond = self._clock()
        waited = self._waited
        with cond:
            last = getattr(waited, "tick", None)
            if last is None:
                last = self._now.header.tick if self._now is not None else -1
            if not cond.wait_for(lambda: self._tick_after(last) is not None, timeout_s):
                raise TimeoutError(f"no tick after {last} within {timeout_s} s")
            msg = self._tick_after(last)
            waited.tick = msg.header.tick
            return msg

    def subscribe_status(self, callback: Callable[[StatusMsg], None]) -> object:
        """Calls `callback` with every StatusMsg (its own subscriber: status is not telemetry
        of a tick)."""
        def on_sample(sample) -> None:
            try:
                msg = StatusMsg.decode(sample.payload.to_bytes())
            except proto.DecodeError:
                return
            callback(msg)

        sub = self.session.declare_subscriber(proto.status_key(self.sc_id), on_sample)
        self._subscribers.append(sub)
        return sub

    # -- the configuration queryable --------------------------------------------------------

    def vehicle(self, timeout_s: float = 30.0) -> VehicleInfo:
        """Asks the server's ``flexdyn/<sc>/config`` queryable what it runs, retrying until it
        answers (it is declared a moment after the server starts listening) or `timeout_s`
        passes (then ``TimeoutError``)."""
        key = proto.config_key(self.sc_id)
        deadline = time.monotonic() + timeout_s
        while True:
            left = deadline - time.monotonic()
            for reply in self.session.get(key, timeout=max(0.1, min(left, 2.0))):
                if reply.ok is None:
                    continue
                try:
                    d = json.loads(reply.ok.payload.to_bytes().decode("utf-8"))
                    return VehicleInfo(d["sc_id"], int(d["spacecraft_id"]), d["config_toml"],
                                       d["server_settings"], d.get("flexdyn_version"),
                                       d.get("git_commit"))
                except (ValueError, KeyError, TypeError) as e:
                    raise ValueError(f"{key}: the reply is not a flexdyn vehicle description "
                                     f"({e})") from e
            if time.monotonic() >= deadline:
                raise TimeoutError(f"no answer on {key} within {timeout_s} s: is a flexdyn "
                                   f"server running with sc_id {self.sc_id!r} at this endpoint?")
            time.sleep(0.05)

    # -- commands ----------------------------------------------------------------------------

    def _header(self, tick: int, sim_time_ns: int) -> Header:
        with self._lock:
            seq = self._seq
            self._seq += 1
        return Header(self.spacecraft_id, tick, sim_time_ns, seq)

    def send(self, cmd: CommandMsg) -> None:
        """Publishes `cmd` as it is (checked finite first)."""
        cmd.validate()
        payload = cmd.encode()
        with self._pub_lock:
            if self._closed:
                raise RuntimeError("flexdyn.Client is closed")
            pub = self._command_pubs.get(cmd.sender_id)
            if pub is None:
                # Blocking: a lockstep answer must never be dropped (Zenoh's default for a
                # put is to drop a sample that finds the link's queue full for 1 ms, and the
                # server then waits for an answer that will not come). Express: sent at once,
                # not held for a batch (and it takes along a flight-code telemetry sample
                # published before it, which is batched), as the Rust participant's.
                pub = self.session.declare_publisher(
                    self._declared_key(proto.command_key(self.sc_id, cmd.sender_id)),
                    congestion_control=zenoh.CongestionControl.BLOCK, express=True)
                self._command_pubs[cmd.sender_id] = pub
            pub.put(payload)

    def send_wrench(self, sender_id: int, tick: int, sim_time_ns: int, torque_b_nm: Vec3,
                    force_b_newton: Vec3 = (0.0, 0.0, 0.0)) -> None:
        """A Wrench command for `tick`: torque about B [N m] and force at B [N], B components."""
        self.send(CommandMsg(self._header(tick, sim_time_ns), sender_id, proto.WRENCH,
                             tuple(torque_b_nm), tuple(force_b_newton)))

    def send_no_command(self, sender_id: int, tick: int, sim_time_ns: int) -> None:
        """A NoCommand for `tick` (a lockstep answer that changes nothing)."""
        self.send(CommandMsg(self._header(tick, sim_time_ns), sender_id, proto.NO_COMMAND_KIND))

    def send_actuators(self, sender_id: int, tick: int, sim_time_ns: int,
                       inputs: Sequence[EffectorInput], torque_b_nm: Vec3 = (0.0, 0.0, 0.0),
                       force_b_newton: Vec3 = (0.0, 0.0, 0.0)) -> None:
        """An Actuators command: a wrench and effector inputs (e.g. wheel torques [N m])."""
        self.send(CommandMsg(self._header(tick, sim_time_ns), sender_id, proto.ACTUATORS,
                             tuple(torque_b_nm), tuple(force_b_newton), list(inputs)))

    # -- operator control (protocol 6) -------------------------------------------------------

    def operator(self, action: int, ticks: int = 0) -> None:
        """Publishes an OperatorMsg on ``flexdyn/<sc>/operator``: ``proto.OPERATOR_PAUSE``,
        ``OPERATOR_RESUME``, ``OPERATOR_RUN_TICKS`` or (protocol 12) ``OPERATOR_CHECKPOINT``
        (proto/README.md, "OperatorMsg"). The server applies it or counts it in
        ``StatusMsg.rejected_operator_refused``; on a lab network only the operator's subject may
        put there."""
        if action not in (proto.OPERATOR_PAUSE, proto.OPERATOR_RESUME, proto.OPERATOR_RUN_TICKS,
                          proto.OPERATOR_CHECKPOINT):
            raise ValueError(f"unknown operator action {action!r}")
        if not (isinstance(ticks, int) and 0 <= ticks < 2**64):
            raise ValueError(f"ticks must be an integer 0..2**64-1, not {ticks!r}")
        now = self._now
        tick = now.header.tick if now is not None else 0
        msg = OperatorMsg(self._header(tick, 0), action, ticks)
        with self._pub_lock:
            if self._closed:
                raise RuntimeError("flexdyn.Client is closed")
            self.session.put(proto.operator_key(self.sc_id), msg.encode())

    def pause(self) -> None:
        """Holds the run: real time at the next frame (its TimeMsg says paused, then nothing
        until :meth:`resume`); lockstep at the tick after the one published."""
        self.operator(proto.OPERATOR_PAUSE)

    def resume(self) -> None:
        """Releases a hold (real time: the schedule restarts from now, no catch-up burst)."""
        self.operator(proto.OPERATOR_RESUME)

    def run_ticks(self, n: int) -> None:
        """Lockstep: steps `n` (>= 1) more ticks from the tick published or held, then holds."""
        if n < 1:
            raise ValueError("run_ticks needs n >= 1")
        self.operator(proto.OPERATOR_RUN_TICKS, n)

    # -- the flight code's own telemetry (protocol 10) ---------------------------------------

    def declare_fsw(self, name: str, timeout_s: float = 30.0) -> "FswStream":
        """The telemetry stream `name` of the configuration's ``[[fsw_streams]]``, read from the
        server (:meth:`vehicle`), bound to a publisher on ``flexdyn/<sc>/fsw/<name>``: publish
        its samples with ``FswStream.publish(tick, sim_time_ns, mode=..., events=[...],
        estimate=q_bn, target=q_rn, <value>=...)``. ``KeyError`` naming the declared streams
        if the configuration has no such stream. The server records the samples beside the
        truth, counts refused ones in ``StatusMsg.rejected_fsw_refused``, and applies nothing
        from them to the physics."""
        from .fsw import FswDeclaration, FswStream
        vehicle = self.vehicle(timeout_s)
        declaration = FswDeclaration.from_config(vehicle.config(), name)
        with self._pub_lock:
            if self._closed:
                raise RuntimeError("flexdyn.Client is closed")
            return FswStream(self, declaration, vehicle.spacecraft_id)

    # -- live faults (protocol 8) -------------------------------------------------------------

    def send_fault(self, msg: proto.FaultCommandMsg) -> None:
        """Publishes a FaultCommandMsg on ``flexdyn/<sc>/fault`` as it is. The server applies it
        at ``at_tick`` or counts it in ``StatusMsg.rejected_fault_refused`` (with the reason in
        its log); on a lab network only the operator's subject may put there."""
        payload = msg.encode()
        with self._pub_lock:
            if self._closed:
                raise RuntimeError("flexdyn.Client is closed")
            self.session.put(proto.fault_key(self.sc_id), payload)

    def inject_fault(self, target: str, mode: str, at_tick: int = proto.AT_NEXT_TICK,
                     duration_s: float = 0.0, axes: Sequence[int] = (), seed: int = 0,
                     **params: float) -> None:
        """Injects a live fault, written as a ``[[faults]]`` entry: ``inject_fault(
        "imus.hub.gyro", "bias_step", at_tick=40, value=0.01, axes=(3,), duration_s=0.5)``.
        It takes effect at boundary `at_tick` (default: the next one): the sensor samples of
        that tick carry it. In lockstep, call it before answering tick ``at_tick - 1`` (from
        this client, so it reaches the server before the answer). ``duration_s`` 0: until
        cleared (:meth:`clear_fault`). Its FaultEventMsg (:meth:`subscribe_fault_events`) gives
        its ``fault_index``."""
        duration_ns = round(duration_s * 1e9)
        if duration_ns < 0:
            raise ValueError("duration_s must be >= 0")
        now = self._now
        header = self._header(now.header.tick if now is not None else 0, 0)
        msg = proto.fault_command(self.spacecraft_id, target, mode, at_tick, duration_ns, axes,
                                  seed, header.seq, header.tick, **params)
        self.send_fault(msg)

    def clear_fault(self, fault_index: int, at_tick: int = proto.AT_NEXT_TICK) -> None:
        """Clears fault `fault_index` (configured or live) from boundary `at_tick` on."""
        now = self._now
        header = self._header(now.header.tick if now is not None else 0, 0)
        self.send_fault(proto.fault_clear(self.spacecraft_id, fault_index, at_tick, header.seq,
                                          header.tick))

    def close(self) -> None:
        """Undeclares everything and closes the session."""
        with self._dispatch:
            self._routes.clear()
            self._taps.clear()
            tlm, self._telemetry_sub = self._telemetry_sub, None
        if tlm is not None:
            tlm.undeclare()
        for s in self._subscribers:
            s.undeclare()
        self._subscribers.clear()
        with self._pub_lock:
            if self._closed:
                return
            self._closed = True
            for pub in self._command_pubs.values():
                pub.undeclare()
            self._command_pubs.clear()
        with self._lock:
            for declared in self._declared.values():
                self.session.undeclare(declared)
            self._declared.clear()
        self.session.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
