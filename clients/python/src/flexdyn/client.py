"""Zenoh transport the flexdyn way: a peer session with multicast scouting off, connected to
the given loopback endpoint(s), and typed helpers for the server's topics."""

from __future__ import annotations

import json
import threading
from typing import Callable, Iterable, List, Optional, Sequence, Tuple, Union

import zenoh

from . import proto
from .proto import CommandMsg, EffectorInput, Header, ImuMsg, StarTrackerMsg, StateMsg, StatusMsg

Vec3 = Tuple[float, float, float]


def session_config(endpoints: Sequence[str], zenoh_config: Optional[str] = None) -> zenoh.Config:
    """Peer mode, connect to `endpoints`, listen nowhere, multicast scouting off.

    ``zenoh_config`` is a Zenoh JSON5 file to start from instead of the defaults, e.g. one with
    ``transport/auth/usrpwd`` credentials for a server on a lab network (see the README's
    "Running on a lab network"); the endpoints and the scouting rule still apply."""
    conf = zenoh.Config.from_file(zenoh_config) if zenoh_config else zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("connect/endpoints", json.dumps(list(endpoints)))
    conf.insert_json5("listen/endpoints", "[]")
    conf.insert_json5("scouting/multicast/enabled", "false")
    return conf


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

    # -- subscriptions ---------------------------------------------------------------------

    def _subscribe(self, key: str, decode, callback) -> object:
        def on_sample(sample) -> None:
            try:
                msg = decode(sample.payload.to_bytes())
            except proto.DecodeError:
                return
            callback(msg)

        sub = self.session.declare_subscriber(key, on_sample)
        self._subscribers.append(sub)
        return sub

    def subscribe_state(self, callback: Callable[[StateMsg], None]) -> object:
        """Calls `callback` with every StateMsg (on a Zenoh thread)."""
        return self._subscribe(proto.state_key(self.sc_id), StateMsg.decode, callback)

    def subscribe_imu(self, name: str, callback: Callable[[ImuMsg], None]) -> object:
        """Calls `callback` with every sample of the IMU `name`."""
        return self._subscribe(proto.imu_key(self.sc_id, name), ImuMsg.decode, callback)

    def subscribe_star_tracker(self, name: str,
                               callback: Callable[[StarTrackerMsg], None]) -> object:
        """Calls `callback` with every measurement of the star tracker `name`."""
        return self._subscribe(proto.star_tracker_key(self.sc_id, name), StarTrackerMsg.decode,
                               callback)

    def subscribe_status(self, callback: Callable[[StatusMsg], None]) -> object:
        """Calls `callback` with every StatusMsg."""
        return self._subscribe(proto.status_key(self.sc_id), StatusMsg.decode, callback)

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
                pub = self.session.declare_publisher(proto.command_key(self.sc_id, cmd.sender_id))
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

    def close(self) -> None:
        """Undeclares everything and closes the session."""
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
        self.session.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


#: What an `on_state` callback returns: None (NoCommand), a (torque_b_nm, force_b_newton) pair
#: (Wrench), or a CommandMsg whose kind and body are sent (its header and sender are set here).
Answer = Optional[Union[Tuple[Vec3, Vec3], CommandMsg]]


class LockstepParticipant:
    """A lockstep participant: subscribes to the state first, then declares its liveliness token
    (so the server cannot publish tick 0 before it can be received), and answers every state with
    what `on_state(state)` returns, stamped with the state's tick. `close()` stops it cleanly
    (token first, so the server sees it leave)."""

    def __init__(self, client: Client, sender_id: int,
                 on_state: Callable[[StateMsg], Answer]) -> None:
        self.client = client
        self.sender_id = sender_id
        self.on_state = on_state
        self.answered = 0
        self.errors: List[BaseException] = []
        self._sub = client.subscribe_state(self._answer)
        self._token = client.session.liveliness().declare_token(
            proto.participant_key(client.sc_id, sender_id))

    def _answer(self, state: StateMsg) -> None:
        h = state.header
        try:
            a = self.on_state(state)
            if a is None:
                self.client.send_no_command(self.sender_id, h.tick, h.sim_time_ns)
            elif isinstance(a, CommandMsg):
                a.header = self.client._header(h.tick, h.sim_time_ns)
                a.sender_id = self.sender_id
                self.client.send(a)
            else:
                torque, force = a
                self.client.send_wrench(self.sender_id, h.tick, h.sim_time_ns, torque, force)
            self.answered += 1
        except BaseException as e:  # reported by close(); the server then times out on us
            self.errors.append(e)

    def close(self) -> None:
        """Undeclares the token, then the subscriber; raises the first callback error, if any."""
        self._token.undeclare()
        self._sub.undeclare()
        if self._sub in self.client._subscribers:
            self.client._subscribers.remove(self._sub)
        if self.errors:
            raise self.errors[0]

    def __enter__(self) -> "LockstepParticipant":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
