"""The time service from Python: ``Client.wait_tick()`` returns each tick's TimeMsg in order,
``now()`` the last one, and a real-time server at ``--speed 2`` advances simulation time at
twice the wall clock."""

import time
from pathlib import Path

import pytest

import flexdyn
from flexdyn import proto
from flexdyn.testing import flexdyn_server

SCENARIO = Path(__file__).resolve().parents[3] / "scenarios" / "reference.toml"


def test_wait_tick_follows_the_server_at_speed_2():
    with flexdyn_server(config=SCENARIO, mode="realtime", participants=[1], duration_s=3.0,
                        extra_args=["--speed", "2"]) as server:
        with flexdyn.Client(server.endpoint) as client:
            assert client.now() is None or client.now().header.tick >= 0
            first = client.wait_tick(timeout_s=30.0)
            t0 = time.monotonic()
            seen = [first]
            while seen[-1].header.tick < first.header.tick + 100:
                seen.append(client.wait_tick(timeout_s=5.0))
            wall_s = time.monotonic() - t0
            assert client.now().header.tick >= seen[-1].header.tick
    ticks = [m.header.tick for m in seen]
    # Every tick once, in order (the reference scenario's frame is 10 ms: 100 frames = 1 s).
    assert ticks == list(range(ticks[0], ticks[0] + len(ticks)))
    sim_s = (seen[-1].header.sim_time_ns - first.header.sim_time_ns) * 1e-9
    assert sim_s == pytest.approx(1.0)
    # 1 s of simulation at --speed 2 takes 0.5 s of wall time (Python's wake-ups add a little).
    assert 0.4 < wall_s < 0.7, wall_s
    for m in seen:
        assert m.speed == 2.0 and m.frame_ns == 10_000_000 and m.met_ns == m.header.sim_time_ns
        assert m.run_state == proto.RUN_STATE_RUNNING
        assert not m.flags & proto.TIME_EPOCH_VALID  # the reference scenario has no [epoch]
    # The tone on every whole simulated second.
    assert [m.header.tick for m in seen if m.tone] == [k for k in ticks if k % 100 == 0]

