"""The Python client against a lab-network server (`scenarios/zenoh/`): with the flight code's
credentials (`secure-client.json5`, user `fsw`) a LockstepParticipant commands the spacecraft;
with the operator's (`operator-client.json5`) a client receives the telemetry, but the
wrench it sends as sender 1 is dropped by the server's access-control list: never applied,
never even counted as a rejection."""

import threading
import time
from pathlib import Path

import flexdyn
from flexdyn.testing import flexdyn_server

WORKSPACE = Path(__file__).resolve().parents[3]
SCENARIO = WORKSPACE / "scenarios" / "reference.toml"
ZENOH = WORKSPACE / "scenarios" / "zenoh"
DURATION_S = 5.0
LAST = int(DURATION_S * 100)
FSW_TORQUE = (0.0, 0.0, 0.01)
IMPOSTOR_TORQUE = (5.0, -5.0, 5.0)


def wait_for(cond, timeout_s, what):
    deadline = time.monotonic() + timeout_s
    while not cond():
        assert time.monotonic() < deadline, f"timed out: {what}"
        time.sleep(0.01)


def test_only_the_flight_code_user_commands():
    secure = ["--zenoh-config", str(ZENOH / "secure-server.json5"),
              "--participant-subjects", "1=fsw"]
    applied, operator_ticks, statuses = [], [], []
    done = threading.Event()
    with flexdyn_server(config=SCENARIO, mode="lockstep", participants=[1],
                        duration_s=DURATION_S, extra_args=secure) as server:
        with flexdyn.Client(server.endpoint,
                            zenoh_config=str(ZENOH / "operator-client.json5")) as operator:
            def impostor(state):
                operator_ticks.append(state.header.tick)
                operator.send_wrench(1, state.header.tick, state.header.sim_time_ns,
                                     IMPOSTOR_TORQUE)

            operator.subscribe_state(impostor)
            operator.subscribe_status(statuses.append)
            wait_for(lambda: statuses, 30, "a status at the operator")

            with flexdyn.Client(server.endpoint,
                                zenoh_config=str(ZENOH / "secure-client.json5")) as fsw:
                def on_state(state):
                    applied.append(state.torque_b_nm)
                    if state.header.tick == LAST:
                        done.set()
                    return FSW_TORQUE, (0.0, 0.0, 0.0)

                with flexdyn.LockstepParticipant(fsw, 1, on_state):
                    assert done.wait(60), "the run did not reach its last tick"
                    time.sleep(0.3)  # the final status
    assert server.returncode == 0, server.log
    # Tick 0 precedes any command; every later frame held the flight code's torque only.
    assert applied[0] == (0.0, 0.0, 0.0)
    assert set(applied[1:]) == {FSW_TORQUE}, set(applied)
    # The operator saw the whole run, and its puts never reached flexdyn.
    assert len(operator_ticks) == LAST + 1
    final = statuses[-1]
    assert final.run_state == 3, final  # Finished
    assert (final.rejected_malformed, final.rejected_wrong_identity,
            final.rejected_unknown_sender, final.rejected_stale_tick) == (0, 0, 0, 0), final
