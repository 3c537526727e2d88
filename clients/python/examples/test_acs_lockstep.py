"""A PD attitude controller in Python, closing the loop with flexdyn in lockstep: the test to
copy into your own CI. Run it with `pytest examples/test_acs_lockstep.py` (it finds the
`flexdyn` binary through $FLEXDYN_BIN or the workspace's target/release).

Control law (Schaub & Junkins, ch. 8): L = -K sigma_BN - P omega_BN, target sigma_RN = 0. The
reference spacecraft (about 1100-1800 kg m^2 about its centre of mass) with K = 100 N m and
P = 300 N m s settles within 8 I / P ~ 48 s (docs/guides/lockstep-ci.md); the test allows 60 s
and a threshold of 0.02 on |sigma|.
"""

import hashlib
import math
import threading

import flexdyn
from flexdyn.testing import flexdyn_server

K_NM, P_NMS = 100.0, 300.0
DURATION_S = 80.0


def pd(state: flexdyn.StateMsg):
    """The controller: a body torque from the state's attitude and rate (no force)."""
    torque = tuple(-K_NM * s - P_NMS * w for s, w in zip(state.sigma_bn, state.omega_bn_b_rad_s))
    return torque, (0.0, 0.0, 0.0)


def run_once():
    """One lockstep run; returns (sigma norms by tick, sha256 of the state stream, server run)."""
    sigmas, digest, done = {}, hashlib.sha256(), threading.Event()
    last_tick = int(DURATION_S * 100)

    def on_state(state):
        sigmas[state.header.tick] = math.sqrt(sum(s * s for s in state.sigma_bn))
        digest.update(state.encode())
        if state.header.tick == last_tick:
            done.set()
        return pd(state)

    # No `config`: the server's embedded default, the reference spacecraft of
    # scenarios/reference.toml, so this file runs wherever it is copied. Pass
    # `config="path/to/your.toml"` for your own vehicle.
    with flexdyn_server(mode="lockstep", participants=[1],
                        duration_s=DURATION_S) as server:
        with flexdyn.Client(server.endpoint) as client:
            with flexdyn.LockstepParticipant(client, sender_id=1, on_state=on_state):
                assert done.wait(120), "the run did not reach its last tick"
    assert server.returncode == 0, server.log
    return sigmas, digest.hexdigest(), server


def test_pd_controller_converges_and_is_bit_identical():
    sigmas, hash_a, _ = run_once()
    assert sorted(sigmas) == list(range(int(DURATION_S * 100) + 1)), "every tick, in order"
    assert max(sigmas.values()) > 0.02, "the attitude did move away first"
    late = [s for tick, s in sigmas.items() if tick >= 6000]
    assert max(late) < 0.02, f"not settled after 60 s: |sigma| up to {max(late)}"
    _, hash_b, _ = run_once()
    assert hash_a == hash_b, "two lockstep runs differ"
