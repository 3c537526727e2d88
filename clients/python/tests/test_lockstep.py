"""A real lockstep run of the server binary with a LockstepParticipant: every tick is answered,
the server ends with exit 0, the status says Finished, and pausing the server (SIGSTOP for 1 s,
then SIGCONT) mid-run changes nothing in the state stream."""

import hashlib
import os
import signal
import threading
import time
from pathlib import Path

import flexdyn
from flexdyn.testing import flexdyn_server

SCENARIO = Path(__file__).resolve().parents[3] / "scenarios" / "reference.toml"
DURATION_S = 30.0
LAST = int(DURATION_S * 100)


def run(pause_at=None):
    digest, done, reached = hashlib.sha256(), threading.Event(), threading.Event()
    ticks, statuses = [], []

    def on_state(state):
        ticks.append(state.header.tick)
        digest.update(state.encode())
        if pause_at is not None and state.header.tick == pause_at:
            reached.set()
        if state.header.tick == LAST:
            done.set()
        # A small torque so the commands matter to the stream.
        return (0.0, 0.0, 0.01 * (state.header.tick % 7)), (0.0, 0.0, 0.0)

    with flexdyn_server(config=SCENARIO, mode="lockstep", participants=[1],
                        duration_s=DURATION_S) as server:
        with flexdyn.Client(server.endpoint) as client:
            client.subscribe_status(statuses.append)
            with flexdyn.LockstepParticipant(client, 1, on_state) as participant:
                if pause_at is not None:
                    assert reached.wait(60)
                    os.kill(server.process.pid, signal.SIGSTOP)
                    frozen = len(ticks)
                    time.sleep(1.0)
                    assert len(ticks) <= frozen + 1, "states arrived from a stopped server"
                    os.kill(server.process.pid, signal.SIGCONT)
                assert done.wait(120), "the run did not reach its last tick"
                time.sleep(0.3)  # the final status
            assert participant.answered == LAST + 1
    assert server.returncode == 0, server.log
    assert ticks == list(range(LAST + 1))
    assert statuses and flexdyn.proto.RUN_STATE_NAMES[statuses[-1].run_state] == "Finished"
    return digest.hexdigest()


def test_lockstep_run_is_invariant_to_a_paused_server():
    a = run()
    b = run(pause_at=1000)
    assert a == b, "pausing the server changed the state stream"
