"""Operator control from Python (protocol 6): ``Client.pause()`` holds a real-time run (the
held tick's TimeMsg says paused, then no tick comes), ``resume()`` continues with the next tick,
and in lockstep ``run_ticks(n)`` holds exactly n ticks later."""

import threading
import time
from pathlib import Path

import pytest

import flexdyn
from flexdyn import proto
from flexdyn.testing import flexdyn_server

SCENARIO = Path(__file__).resolve().parents[3] / "scenarios" / "reference.toml"


def test_pause_holds_a_real_time_run_and_resume_continues_with_the_next_tick():
    with flexdyn_server(config=SCENARIO, mode="realtime", participants=[1],
                        duration_s=30.0) as server:
        with flexdyn.Client(server.endpoint) as client:
            statuses = []
            client.subscribe_status(statuses.append)
            first = client.wait_tick(timeout_s=30.0).header.tick
            client.pause()
            deadline = time.monotonic() + 5.0
            while not (client.now() and client.now().paused):
                assert time.monotonic() < deadline, "no paused tick"
                time.sleep(0.005)
            held = client.now().header.tick
            # wait_tick hands out every tick up to the hold, in order, then nothing more.
            drained = []
            with pytest.raises(TimeoutError):
                while True:
                    drained.append(client.wait_tick(timeout_s=0.5).header.tick)
            assert drained == list(range(first + 1, held + 1))
            assert client.now().header.tick == held
            time.sleep(0.2)
            assert statuses[-1].run_state == proto.RUN_STATE_PAUSED
            assert statuses[-1].header.tick == held
            client.resume()
            after = client.wait_tick(timeout_s=5.0)
            assert after.header.tick == held + 1 and not after.paused
            # A second resume has nothing to release: refused and counted.
            client.resume()
            time.sleep(0.3)
            assert statuses[-1].rejected_operator_refused == 1


def test_run_ticks_holds_a_lockstep_run_exactly_n_ticks_later():
    ticks = []
    reached = threading.Event()

    def on_state(state):
        ticks.append(state.header.tick)
        if state.header.tick == 7:
            reached.set()
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)

    with flexdyn_server(config=SCENARIO, mode="lockstep", participants=[1],
                        duration_s=0.2) as server:
        with flexdyn.Client(server.endpoint) as client:
            client.vehicle()  # the server is up: its operator subscriber too
            client.run_ticks(7)
            time.sleep(0.3)
            with flexdyn.LockstepParticipant(client, 1, on_state):
                assert reached.wait(30)
                time.sleep(1.0)
                assert ticks == list(range(8)), "stepped past the hold"
                client.run_ticks(2)
                deadline = time.monotonic() + 10
                while ticks[-1] != 9:
                    assert time.monotonic() < deadline
                    time.sleep(0.01)
                time.sleep(0.5)
                assert ticks[-1] == 9
                client.resume()
                deadline = time.monotonic() + 30
                while ticks[-1] != 20:
                    assert time.monotonic() < deadline, ticks[-5:]
                    time.sleep(0.01)
    assert ticks == list(range(21))
    assert server.returncode == 0, server.log
