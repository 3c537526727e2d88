#!/usr/bin/env python3
"""Reference numbers for flexdyn's linear spring-mass-damper slosh effector, from Basilisk.

Runs the case of Basilisk's own unit test of the module,
`src/simulation/dynamics/LinearSpringMassDamper/_UnitTest/test_linearSpringMassDamper.py`
(Basilisk 2.12.1): a 750 kg hub with three slosh particles, RK4 at 1 ms for 2.5 s, in its
`NoGravity` and `Damping` cases, and prints the final hub state and particle states as the Rust
constants that `crates/dynamics/tests/slosh.rs` (`validate_slosh_linear_vs_basilisk`) embeds.

    target/peers-venv/bin/python tools/peers/basilisk_slosh.py

Conventions (identical in both tools, so no mapping is applied): Basilisk's `r_PB_B`, `pHat_B`,
`rhoInit`, `rhoDotInit`, `massInit`, `k`, `c` are flexdyn's `r_pb_b_m`, `p_hat_b`, `rho_m`,
`rho_dot_m_s`, `mass_kg`, `k_n_m`, `c_n_s_m`; the hub's `r_CN_NInit`/`v_CN_NInit` are the
system centre of mass's initial state (flexdyn's `InitialTranslation::CenterOfMass`); the output
`r_BN_N`, `v_BN_N`, `sigma_BN`, `omega_BN_B` are flexdyn's `r_bn_n`, `v_bn_n`, `sigma_bn`,
`omega_bn_b`. Basilisk carries each particle's mass as an integrated state with zero derivative;
it stays constant, as flexdyn's parameter does. The unit test's initial velocity
`[[0.1], [0.-5], [0.3]]` evaluates to (0.1, -5.0, 0.3) in Python and is kept as such.
"""

import sys

import numpy as np

sys.dont_write_bytecode = True

from Basilisk.simulation import linearSpringMassDamper, spacecraft  # noqa: E402
from Basilisk.utilities import SimulationBaseClass, macros  # noqa: E402

STOP_S = 2.5
STEP_S = 0.001

PARTICLES = [
    # (k, c undamped, c damped, r_PB_B, pHat_B (times sqrt(3)/3), rho0, mass)
    (100.0, 15.0, [0.1, 0.0, -0.1], [1, 1, 1], 0.05, 10.0),
    (100.0, 17.0, [0.0, 0.0, 0.1], [1, -1, -1], -0.025, 20.0),
    (100.0, 11.0, [-0.1, 0.0, 0.1], [-1, -1, 1], -0.015, 15.0),
]


def run(damped):
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("proc")
    proc.addTask(sim.CreateNewTask("task", macros.sec2nano(STEP_S)))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "spacecraftBody"
    particles = []
    s = np.sqrt(3) / 3
    for k, c, r, p, rho0, m in PARTICLES:
        e = linearSpringMassDamper.LinearSpringMassDamper()
        e.k = k
        e.c = c if damped else 0.0
        e.r_PB_B = [[r[0]], [r[1]], [r[2]]]
        e.pHat_B = [[s * p[0]], [s * p[1]], [s * p[2]]]
        e.rhoInit = rho0
        e.rhoDotInit = 0.0
        e.massInit = m
        sc.addStateEffector(e)
        particles.append(e)
    sim.AddModelToTask("task", sc)
    sc.hub.mHub = 750
    sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    sc.hub.IHubPntBc_B = [[900.0, 0.0, 0.0], [0.0, 800.0, 0.0], [0.0, 0.0, 600.0]]
    sc.hub.r_CN_NInit = [[0.5], [0.4], [-0.7]]
    sc.hub.v_CN_NInit = [[0.1], [-5.0], [0.3]]
    sc.hub.sigma_BNInit = [[0.0], [0.0], [0.0]]
    sc.hub.omega_BN_BInit = [[0.1], [-0.1], [0.1]]
    log = sc.scStateOutMsg.recorder()
    sim.AddModelToTask("task", log)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(STOP_S))
    sim.ExecuteSimulation()
    rho = []
    for e in particles:
        r = sc.dynManager.getStateObject(e.nameOfRhoState).getState()[0][0]
        rd = sc.dynManager.getStateObject(e.nameOfRhoDotState).getState()[0][0]
        rho += [r, rd]
    return {
        "r_bn_n": log.r_BN_N[-1],
        "v_bn_n": log.v_BN_N[-1],
        "sigma_bn": log.sigma_BN[-1],
        "omega_bn_b": log.omega_BN_B[-1],
        "rho": rho,
        "t_s": log.times()[-1] * 1e-9,
    }


def rust(name, v):
    body = ", ".join(repr(float(x)) for x in v)
    return f"const {name}: [f64; {len(v)}] = [{body}];"


def main():
    import Basilisk

    print(f"// Basilisk {getattr(Basilisk, '__version__', '?')}, "
          f"tools/peers/basilisk_slosh.py, t = {STOP_S} s, step {STEP_S} s")
    for case, damped in (("UNDAMPED", False), ("DAMPED", True)):
        out = run(damped)
        assert abs(out["t_s"] - STOP_S) < 1e-12, out["t_s"]
        for key in ("r_bn_n", "v_bn_n", "sigma_bn", "omega_bn_b", "rho"):
            print(rust(f"{case}_{key.upper()}", out[key]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
