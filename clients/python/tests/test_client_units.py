"""Client logic without a server: wait_tick's positions over the held ticks, and a telemetry
stream's tick order and identity (stub session and publisher)."""

import collections
import threading

import pytest

import flexdyn
from flexdyn import proto
from flexdyn.fsw import FswDeclaration, FswStream
from flexdyn.proto import Header, TimeMsg


def held(*ticks):
    stub = type("Stub", (), {})()
    stub._ticks = collections.deque((TimeMsg(Header(1, t, t * 10_000_000, t)) for t in ticks),
                                    maxlen=1024)
    return lambda last: (lambda m: None if m is None else m.header.tick)(
        flexdyn.Client._tick_after(stub, last))


def test_tick_after_hands_out_the_next_held_tick():
    after = held(5, 6, 7, 8)
    assert after(-1) == 5      # older than everything held: the oldest
    assert after(5) == 6 and after(7) == 8
    assert after(8) is None    # nothing newer yet
    assert held()(3) is None


def test_a_server_restarted_on_the_same_keys_starts_again_at_its_first_tick():
    after = held(40, 41, 42, 0, 1, 2)
    assert after(42) == 0      # the ticks went back: the new run's first held tick
    assert after(0) == 1       # then on through the new run
    assert after(45) == 0


class _Publisher:
    def __init__(self):
        self.sent = []

    def put(self, payload):
        self.sent.append(payload)


class _Session:
    def __init__(self):
        self.publisher = _Publisher()

    def declare_publisher(self, key, **_):
        return self.publisher


class _Client:
    sc_id = "sc1"
    spacecraft_id = 1
    _closed = False

    def __init__(self):
        self.session = _Session()
        self._pub_lock = threading.Lock()


def test_a_stream_refuses_a_tick_not_after_its_last_and_stamps_the_served_id():
    config = {"fsw_streams": [{"name": "acs", "modes": ["a"],
                               "values": [{"name": "x", "type": "f64"}]}]}
    client = _Client()
    stream = FswStream(client, FswDeclaration.from_config(config, "acs"), spacecraft_id=7)
    m = stream.publish(3, 30, mode="a", x=1.0)
    assert m.header.spacecraft_id == 7 and m.header.seq == 0
    for tick in (3, 2):
        with pytest.raises(ValueError, match="not after tick 3"):
            stream.publish(tick, tick * 10, mode="a", x=1.0)
    # A refused sample spends no sequence number and sends nothing.
    with pytest.raises(ValueError):
        stream.publish(4, 40, mode="b", x=1.0)
    m = stream.publish(4, 40, mode="a", x=2.0)
    assert m.header.seq == 1
    assert len(client.session.publisher.sent) == 2
    assert proto.FswMsg.decode(client.session.publisher.sent[1]).header.tick == 4
