"""Live faults from Python (protocol 8) on a lab-network lockstep server
(`scenarios/zenoh/secure-server.json5`): the operator (`operator-client.json5`) holds the run at
tick K - 1 (``run_ticks``), injects a gyro bias step for tick K with ``Client.inject_fault`` and
resumes; the IMU sample of tick K, and of the four ticks after it, carry the bias (the healthy
run's value + the bias, sample by sample), and the FaultEventMsgs say activated at K and cleared
at K + 5. The flight code's user (`fsw`, no operator credentials) injects a much larger fault for
a later tick from its own client: it is never applied (the samples equal the healthy run's).

What is counted: a fault command the server receives and refuses (here the operator's, for an
IMU that does not exist) is counted in ``StatusMsg.rejected_fault_refused``. The non-operator's
put is dropped by Zenoh's access-control list at the server's interface, before flexdyn sees it,
so, like a command from the wrong subject (`test_secure.py`), it is not counted by flexdyn: the
counters show it never arrived."""

import threading
import time
from pathlib import Path

import flexdyn
from flexdyn import proto
from flexdyn.testing import flexdyn_server

WORKSPACE = Path(__file__).resolve().parents[3]
SCENARIO = WORKSPACE / "scenarios" / "wheels_star_tracker.toml"
ZENOH = WORKSPACE / "scenarios" / "zenoh"
DURATION_S = 0.4
LAST = 40
K = 12          # the operator's fault starts at tick K ...
LEN = 5         # ... for five frames
BIAS = 0.5      # [rad/s]
K_FSW = 25      # the impostor's tick
FRAME_NS = 10_000_000


def wait_for(cond, timeout_s, what):
    deadline = time.monotonic() + timeout_s
    while not cond():
        assert time.monotonic() < deadline, f"timed out: {what}"
        time.sleep(0.01)


def run(inject):
    secure = ["--zenoh-config", str(ZENOH / "secure-server.json5"),
              "--participant-subjects", "1=fsw"]
    gyro, events, statuses = {}, [], []
    done = threading.Event()
    with flexdyn_server(config=SCENARIO, mode="lockstep", participants=[1],
                        duration_s=DURATION_S, extra_args=secure) as server:
        with flexdyn.Client(server.endpoint,
                            zenoh_config=str(ZENOH / "operator-client.json5")) as op:
            op.subscribe_imu("hub", lambda m: gyro.__setitem__(m.header.tick, m.omega_p_rad_s))
            op.subscribe_fault_events(events.append)
            op.subscribe_status(statuses.append)
            wait_for(lambda: statuses, 30, "a status at the operator")
            if inject:
                op.run_ticks(K - 1)  # hold at K - 1: nothing is stepped past it meanwhile
                time.sleep(0.3)
            with flexdyn.Client(server.endpoint,
                                zenoh_config=str(ZENOH / "secure-client.json5")) as fsw:
                def on_state(state):
                    tick = state.header.tick
                    if inject and tick == K_FSW - 1:
                        # Put before this tick's answer, from the answering client: in time.
                        fsw.inject_fault("imus.hub.gyro", "bias_step", at_tick=K_FSW,
                                         value=100.0)
                    if tick == LAST:
                        done.set()
                    return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)

                with flexdyn.LockstepParticipant(fsw, 1, on_state):
                    if inject:
                        wait_for(lambda: statuses[-1].run_state == proto.RUN_STATE_PAUSED
                                 and statuses[-1].header.tick == K - 1, 30, "held at K - 1")
                        op.inject_fault("imus.hub.gyro", "bias_step", at_tick=K, value=BIAS,
                                        duration_s=LEN * FRAME_NS * 1e-9)
                        op.inject_fault("imus.nope.gyro", "bias_step", at_tick=K, value=BIAS)
                        wait_for(lambda: statuses[-1].rejected_fault_refused == 1, 10,
                                 "the bad target counted")
                        op.resume()
                    assert done.wait(60), "the run did not reach its last tick"
                    time.sleep(0.3)  # the final status
    assert server.returncode == 0, server.log
    return gyro, events, statuses[-1]


def test_a_live_fault_from_the_operator_lands_at_its_tick_and_no_one_elses_does():
    healthy, healthy_events, healthy_final = run(inject=False)
    faulty, events, final = run(inject=True)
    assert sorted(healthy) == sorted(faulty) == list(range(LAST + 1))
    for k in range(LAST + 1):
        if K <= k < K + LEN:
            assert faulty[k] == tuple(x + BIAS for x in healthy[k]), k
        else:
            assert faulty[k] == healthy[k], k  # before K, after it, and the impostor's tick on
    assert healthy_events == []
    assert [(e.header.tick, e.active, e.fault_index, e.source, e.mode_name, e.target_str,
             e.edge_ns, e.params) for e in events] == [
        (K, True, 0, proto.FAULT_SOURCE_LIVE, "bias_step", "imus.hub.gyro", K * FRAME_NS,
         (BIAS, 0.0)),
        (K + LEN, False, 0, proto.FAULT_SOURCE_LIVE, "bias_step", "imus.hub.gyro",
         (K + LEN) * FRAME_NS, (BIAS, 0.0)),
    ]
    assert final.run_state == 3 and final.faults_active == 0, final
    assert healthy_final.rejected_fault_refused == 0
    # The operator's bad target: refused and counted. The impostor's: never reached flexdyn.
    assert final.rejected_fault_refused == 1, final
    assert (final.rejected_malformed, final.rejected_wrong_spacecraft) == (0, 0)
