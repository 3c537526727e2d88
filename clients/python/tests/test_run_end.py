"""The participant stops with the run (issue 36; issue 37 §4): against the real server, a
lockstep run of 300 ticks, `LockstepParticipant.wait()` without a timeout returns by itself
once the server's last StatusMsg (Finished) is in and every tick has been answered, and
`participant.ended` says ("finished", 300).

The time between the server process's exit and `wait()`'s return, and between the last tick's
callback and that return, are printed (pytest -s): figures, not pass/fail bounds; the bound
here is only "long before forever" (10 s)."""

import threading
import time
from pathlib import Path

import flexdyn
from flexdyn.testing import flexdyn_server

SCENARIO = Path(__file__).resolve().parents[3] / "scenarios" / "reference.toml"
LAST = 300
EXIT_BOUND_S = 10.0


def test_participant_wait_returns_when_the_server_ends_the_run():
    ticks = []
    result = {}

    def on_state(state):
        ticks.append(state.header.tick)
        result["last_tick_at"] = time.monotonic()
        return None

    with flexdyn_server(config=SCENARIO, mode="lockstep", participants=[1],
                        duration_s=LAST / 100) as server:
        with flexdyn.Client(server.endpoint) as client:
            with flexdyn.LockstepParticipant(client, 1, on_state) as participant:
                def loop():
                    final = participant.wait()  # no timeout: the end of run ends it
                    result["returned"] = time.monotonic()
                    result["final"] = final

                waiter = threading.Thread(target=loop, daemon=True)
                waiter.start()
                while server.process.poll() is None:
                    time.sleep(0.001)
                server_exit = time.monotonic()
                waiter.join(EXIT_BOUND_S)
                assert not waiter.is_alive(), \
                    f"wait() still blocked {EXIT_BOUND_S} s after the server ended"
                ended = participant.ended
                last = participant.last_tick
    assert server.returncode == 0, server.log
    assert ended == ("finished", LAST)
    assert flexdyn.proto.RUN_STATE_NAMES[result["final"].run_state] == "Finished"
    assert last == LAST and ticks == list(range(LAST + 1))
    latency_ms = (result["returned"] - server_exit) * 1e3
    after_last_ms = (result["returned"] - result["last_tick_at"]) * 1e3
    print(f"\nparticipant.wait() returned {latency_ms:+.1f} ms from the server process's exit "
          f"(negative: before it), {after_last_ms:.1f} ms after tick {LAST} reached the "
          f"callback; ended = {ended}")
