"""The flight code's own telemetry (protocol 10): a stream declared in the spacecraft
configuration's ``[[fsw_streams]]``, published as FswMsg on ``flexdyn/<sc>/fsw/<name>``.

The server checks each sample against the declaration, records it beside the truth, and
applies nothing from it to the physics (proto/README.md, "FswMsg";
docs/guides/fsw-telemetry.md). :meth:`flexdyn.Client.declare_fsw` reads the declaration from
the server's configuration, so flight code names its modes, events and values as the
configuration does, and a mistake is a ``ValueError`` here rather than a refusal counted there::

    acs = client.declare_fsw("acs")     # the stream of scenarios/acs_full.toml
    acs.publish(tick, sim_time_ns, mode="fine-pointing", events=["target-chosen"],
                estimate=q_bn, target=q_rn, rate_b_rad_s=(0.01, 0.0, -0.02),
                wheel_momentum_b_nms=(0.1, 0.0, -0.2), sun_visible=True)
"""

from __future__ import annotations

import math
import struct
import threading
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from . import proto
from .proto import FswMsg, Header

_TYPES = ("f64", "i64", "bool")


@dataclass(frozen=True)
class FswValue:
    """A declared value: its name, type (``f64``, ``i64`` or ``bool``), length (words) and unit,
    and its first word in FswMsg ``values``."""

    name: str
    type: str
    len: int
    unit: str
    offset: int


@dataclass(frozen=True)
class FswDeclaration:
    """A stream as the configuration declares it."""

    name: str
    modes: Tuple[str, ...]
    events: Tuple[Tuple[str, str], ...]  # (name, severity)
    values: Tuple[FswValue, ...]

    @property
    def words(self) -> int:
        """The value words of one sample (the sum of the lengths)."""
        return sum(v.len for v in self.values)

    @classmethod
    def from_config(cls, config: Mapping[str, Any], name: str) -> "FswDeclaration":
        """Stream `name` of a parsed configuration (the server validated the file); a
        ``KeyError`` naming the declared streams if there is none."""
        streams = config.get("fsw_streams", [])
        for s in streams:
            if s.get("name") == name:
                values, offset = [], 0
                for v in s.get("values", []):
                    n = int(v.get("len", 1))
                    values.append(FswValue(v["name"], v["type"], n, v.get("unit", ""), offset))
                    offset += n
                events = tuple((e["name"], e.get("severity", "info")) for e in s.get("events", []))
                return cls(name, tuple(s.get("modes", [])), events, tuple(values))
        declared = ", ".join(repr(s.get("name")) for s in streams) or "none"
        raise KeyError(f"the server's configuration declares no [[fsw_streams]] named {name!r} "
                       f"(declared: {declared})")

    def sample(self, header: Header, mode: Optional[str] = None, events: Sequence[str] = (),
               estimate: Optional[Sequence[float]] = None,
               target: Optional[Sequence[float]] = None,
               variance: Optional[Sequence[float]] = None, **values: Any) -> FswMsg:
        """The FswMsg of one sample; ``ValueError`` for anything the server would refuse: an
        undeclared mode, event or value, a value left out, a wrong length, a non-finite f64,
        an integer out of the i64 range, a covariance without an estimate."""
        flags, mode_index = 0, 0
        if mode is not None:
            if mode not in self.modes:
                raise ValueError(f"stream {self.name!r}: mode {mode!r} is not declared "
                                 f"(modes: {', '.join(self.modes) or 'none'})")
            flags |= proto.FSW_MODE
            mode_index = self.modes.index(mode)
        names = [e[0] for e in self.events]
        if len(events) > proto.MAX_FSW_EVENTS:
            raise ValueError(f"stream {self.name!r}: {len(events)} events in one sample, at most "
                             f"{proto.MAX_FSW_EVENTS}")
        indices = []
        for e in events:
            if e not in names:
                raise ValueError(f"stream {self.name!r}: event {e!r} is not declared "
                                 f"(events: {', '.join(names) or 'none'})")
            indices.append(names.index(e))

        def vec(v: Optional[Sequence[float]], n: int, what: str) -> Tuple[float, ...]:
            if v is None or any(isinstance(x, bool) or not isinstance(x, (int, float))
                                for x in v):
                raise ValueError(f"stream {self.name!r}: {what} must be {n} numbers, got {v!r}")
            t = tuple(float(x) for x in v)
            if len(t) != n or not all(math.isfinite(x) for x in t):
                raise ValueError(f"stream {self.name!r}: {what} must be {n} finite numbers, "
                                 f"got {v!r}")
            return t

        q_est = q_target = (1.0, 0.0, 0.0, 0.0)
        var = (0.0, 0.0, 0.0)
        if estimate is not None:
            flags |= proto.FSW_ESTIMATE
            q_est = vec(estimate, 4, "estimate (q_bn, scalar first)")
        if target is not None:
            flags |= proto.FSW_TARGET
            q_target = vec(target, 4, "target (q_rn, scalar first)")
        if variance is not None:
            if estimate is None:
                raise ValueError(f"stream {self.name!r}: a variance needs an estimate")
            flags |= proto.FSW_COVARIANCE
            var = vec(variance, 3, "variance (rad², about B)")
        words = self._words(values)
        return FswMsg(header, flags, mode_index, q_est, q_target, var, len(indices),
                      tuple(indices + [0] * (8 - len(indices))), words)

    def _words(self, values: Mapping[str, Any]) -> List[int]:
        declared = {v.name for v in self.values}
        unknown = sorted(set(values) - declared)
        if unknown:
            raise ValueError(f"stream {self.name!r}: {', '.join(map(repr, unknown))} not "
                             f"declared (values: {', '.join(sorted(declared)) or 'none'})")
        missing = [v.name for v in self.values if v.name not in values]
        if missing:
            raise ValueError(f"stream {self.name!r}: every declared value is in every sample; "
                             f"missing {', '.join(map(repr, missing))}")
        words: List[int] = []
        for v in self.values:
            x = values[v.name]
            items = list(x) if isinstance(x, (list, tuple)) else [x]
            if len(items) != v.len:
                raise ValueError(f"stream {self.name!r}: {v.name!r} has length {v.len}, got "
                                 f"{len(items)}")
            for k, item in enumerate(items):
                where = f"{v.name}[{k}]" if v.len > 1 else v.name
                words.append(_word(self.name, where, v.type, item))
        return words


def _word(stream: str, where: str, ty: str, x: Any) -> int:
    if ty == "f64":
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise ValueError(f"stream {stream!r}: {where} must be a number, got {x!r}")
        f = float(x)
        if not math.isfinite(f):
            raise ValueError(f"stream {stream!r}: {where} is {f}, not finite")
        return struct.unpack("<Q", struct.pack("<d", f))[0]
    if ty == "i64":
        if isinstance(x, bool) or not isinstance(x, int) or not -2**63 <= x < 2**63:
            raise ValueError(f"stream {stream!r}: {where} must be an integer in the i64 range, "
                             f"got {x!r}")
        return x & 0xFFFF_FFFF_FFFF_FFFF
    if ty == "bool":
        if x not in (True, False, 0, 1):
            raise ValueError(f"stream {stream!r}: {where} must be a bool, got {x!r}")
        return 1 if x else 0
    raise ValueError(f"stream {stream!r}: {where} has type {ty!r}, not one of {_TYPES}")


def value_of(value: FswValue, words: Sequence[int]) -> List[Any]:
    """The elements of `value` in a sample's ``values`` words, typed as declared."""
    out: List[Any] = []
    for w in words[value.offset:value.offset + value.len]:
        if value.type == "f64":
            out.append(struct.unpack("<d", struct.pack("<Q", w))[0])
        elif value.type == "i64":
            out.append(w - 2**64 if w >= 2**63 else w)
        else:
            out.append(bool(w))
    return out


class FswStream:
    """A declared stream bound to its publisher (from :meth:`flexdyn.Client.declare_fsw`)."""

    def __init__(self, client: Any, declaration: FswDeclaration,
                 spacecraft_id: Optional[int] = None) -> None:
        self.declaration = declaration
        self._client = client
        # The vehicle's numeric id as its server serves it (the client's own by default).
        self.spacecraft_id = client.spacecraft_id if spacecraft_id is None else spacecraft_id
        # The last tick published: a stream carries at most one sample per tick, in order.
        self._last_tick: Optional[int] = None
        self._key = proto.fsw_key(client.sc_id, declaration.name)
        # Blocking, so this end never drops a sample (the client's command publishers block
        # too). Not express: an express sample takes a batch of the link's queue of its own,
        # and while the commands used Zenoh's default "drop" a lockstep answer put right after
        # it was sometimes dropped on a loaded machine (0.5 s lockstep runs, a sample per tick,
        # two CPU hogs on 2 cores: 9 runs in 600 stalled with express, none in 700 without).
        # Same priority, same session: the sample reaches the server before the answer.
        import zenoh
        self._publisher = client.session.declare_publisher(
            self._key, congestion_control=zenoh.CongestionControl.BLOCK)
        self._seq = 0
        self._lock = threading.Lock()

    @property
    def key(self) -> str:
        """``flexdyn/<sc>/fsw/<name>``."""
        return self._key

    def publish(self, tick: int, sim_time_ns: int, mode: Optional[str] = None,
                events: Sequence[str] = (), estimate: Optional[Sequence[float]] = None,
                target: Optional[Sequence[float]] = None,
                variance: Optional[Sequence[float]] = None, **values: Any) -> FswMsg:
        """Publishes one sample for `tick` (the tick this flight code answers, at its
        `sim_time_ns`); returns the message sent. Every declared value is given by name:
        ``wheel_momentum_b_nms=(0.1, 0.0, -0.2)``. In lockstep, publish before answering the
        tick, from this client, so the server has it before it steps on. ``ValueError`` (and
        nothing sent) for a tick not after the last one published: the server records at most
        one sample per tick per stream."""
        with self._lock:
            if self._last_tick is not None and tick <= self._last_tick:
                raise ValueError(f"stream {self.declaration.name!r}: tick {tick} is not after "
                                 f"tick {self._last_tick}, the last one published (at most one "
                                 f"sample per tick, in order)")
            header = Header(self.spacecraft_id, tick, sim_time_ns, self._seq)
            msg = self.declaration.sample(header, mode, events, estimate, target, variance,
                                          **values)
            payload = msg.encode()
            with self._client._pub_lock:
                if self._client._closed:
                    raise RuntimeError("flexdyn.Client is closed")
                self._publisher.put(payload)
            self._seq += 1
            self._last_tick = tick
        return msg

    def undeclare(self) -> None:
        """Undeclares the publisher."""
        self._publisher.undeclare()


def decode_sample(declaration: FswDeclaration, msg: FswMsg) -> Dict[str, Any]:
    """A sample as names: ``{"tick", "mode", "events", "estimate", "target", "variance",
    <value name>: [elements]}`` (``None`` for what the sample does not set)."""
    out: Dict[str, Any] = {"tick": msg.header.tick}
    out["mode"] = (declaration.modes[msg.mode] if msg.flags & proto.FSW_MODE
                   and msg.mode < len(declaration.modes) else None)
    out["events"] = [declaration.events[i][0] for i in msg.events[:msg.event_count]
                     if i < len(declaration.events)]
    out["estimate"] = msg.q_est_bn if msg.flags & proto.FSW_ESTIMATE else None
    out["target"] = msg.q_target_rn if msg.flags & proto.FSW_TARGET else None
    out["variance"] = msg.att_var_b_rad2 if msg.flags & proto.FSW_COVARIANCE else None
    for v in declaration.values:
        out[v.name] = value_of(v, msg.values)
    return out
