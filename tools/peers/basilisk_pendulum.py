#!/usr/bin/env python3
"""Reference numbers for flexdyn's spherical slosh pendulum, from Basilisk.

Runs the case of Basilisk's own unit test of the module,
`src/simulation/dynamics/sphericalPendulum/_UnitTest/test_sphericalPendulum.py` (Basilisk
2.12.1): a 1500 kg hub tumbling at (1, 0.5, 0.1) rad/s in a 6700 km orbit with two pendulums,
for 10 s, in its test case 2 (undamped, RK4 at 1 ms) and test case 4 (isotropic damping
D = 10 N s/m), also at 1 ms: the unit test runs case 4 at 10 ms, where the two tools' different
angle charts for pendulum 2 (below) give RK4 truncation errors that differ by 1.5e-9 at 10 s. Prints the initial centre-of-mass state, the final hub state and
each pendulum mass's final position and velocity relative to B (B components), as the Rust
constants that `crates/dynamics/tests/slosh.rs` (`validate_slosh_pendulum_vs_basilisk`)
embeds.

    target/peers-venv/bin/python tools/peers/basilisk_pendulum.py

Convention mapping (flexdyn <- Basilisk):
- pivot `r_pb_b_m` <- `d`; rod `l_m` <- `pendulumRadius`; `mass_kg` <- `massInit`;
- hang axis `hang_axis_b` <- `pHat_01`. flexdyn builds p2, p3 from the hang axis (module docs):
  for pendulum 1 (pHat_01 = (1, 0, 1)/sqrt 2) that gives Basilisk's pHat_02 = y, pHat_03 =
  (-1, 0, 1)/sqrt 2 exactly, so its angles are Basilisk's; for pendulum 2 (Basilisk's P0 = B)
  it gives (x, z, -y), so its initial rates are mapped through the rod's velocity at rest,
  l (phiDot y - thetaDot z) = l (phiDot' z + thetaDot' y): phiDot' = -thetaDot, thetaDot' =
  phiDot. The angles then differ, so the comparison is on the masses' positions and velocities;
- damping: Basilisk's force -D r' with D = d [1] is flexdyn's Rayleigh damping with
  `c_nm_s_rad` = d l^2 (the generalized forces -d l^2 cos^2(theta) phiDot, -d l^2 thetaDot);
- gravity: Basilisk's Earth (mu = 3.986004415e14) at the system centre of mass, flexdyn's
  `GravityModel::PointMass` (the same uniform field at C).
"""

import sys

import numpy as np

sys.dont_write_bytecode = True

from Basilisk.simulation import spacecraft, sphericalPendulum  # noqa: E402
from Basilisk.utilities import SimulationBaseClass, macros, orbitalMotion  # noqa: E402
from Basilisk.utilities import simIncludeGravBody  # noqa: E402


def run(step_s, damping):
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("proc")
    proc.addTask(sim.CreateNewTask("task", macros.sec2nano(step_s)))
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "spacecraftBody"
    sim.AddModelToTask("task", sc)
    dmat = [[damping, 0.0, 0.0], [0.0, damping, 0.0], [0.0, 0.0, damping]]
    s2 = np.sqrt(2) / 2
    # (pendulumRadius, massInit, phiDotInit, thetaDotInit, P0 frame or None for B)
    specs = [
        (0.3, 20.0, 0.01, 0.05, ([s2, 0, s2], [0, 1, 0], [-s2, 0, s2])),
        (0.4, 40.0, 0.1, 0.5, None),
    ]
    pendulums = []
    for radius, mass, phi_dot, theta_dot, frame in specs:
        p = sphericalPendulum.SphericalPendulum()
        p.pendulumRadius = radius
        p.d = [[0.1], [0.1], [0.1]]
        p.D = dmat
        p.phiDotInit = phi_dot
        p.thetaDotInit = theta_dot
        p.massInit = mass
        if frame is not None:
            p.pHat_01, p.pHat_02, p.pHat_03 = ([[c] for c in v] for v in frame)
        pendulums.append(p)
    sc.hub.mHub = 1500
    sc.hub.r_BcB_B = [[1.0], [0.5], [0.1]]
    sc.hub.IHubPntBc_B = [[900.0, 0.0, 0.0], [0.0, 800.0, 0.0], [0.0, 0.0, 600.0]]
    sc.hub.sigma_BNInit = [[0.0], [0.0], [0.0]]
    sc.hub.omega_BN_BInit = [[1.0], [0.5], [0.1]]
    for p in pendulums:
        sc.addStateEffector(p)
    grav = simIncludeGravBody.gravBodyFactory()
    earth = grav.createEarth()
    earth.isCentralBody = True
    sc.gravField.gravBodies = spacecraft.GravBodyVector(list(grav.gravBodies.values()))
    oe = orbitalMotion.ClassicElements()
    oe.a = 6700.0 * 1000
    oe.e = 0.01
    oe.omega = 100.0 * macros.D2R
    oe.Omega = 100.0 * macros.D2R
    oe.i = 30.0 * macros.D2R
    oe.f = 0.0
    r_n, v_n = orbitalMotion.elem2rv(earth.mu, oe)
    sc.hub.r_CN_NInit = r_n
    sc.hub.v_CN_NInit = v_n
    log = sc.scStateOutMsg.recorder()
    sim.AddModelToTask("task", log)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(10.0))
    sim.ExecuteSimulation()
    masses = []
    for p in pendulums:
        get = lambda n: sc.dynManager.getStateObject(n).getState()[0][0]  # noqa: E731
        phi, theta = get(p.nameOfPhiState), get(p.nameOfThetaState)
        phid, thetad = get(p.nameOfPhiDotState), get(p.nameOfThetaDotState)
        frame = np.column_stack([np.array(p.pHat_01).ravel(), np.array(p.pHat_02).ravel(),
                                 np.array(p.pHat_03).ravel()])
        sp, cp, st, ct = np.sin(phi), np.cos(phi), np.sin(theta), np.cos(theta)
        l = p.pendulumRadius
        r = np.array(p.d).ravel() + frame @ (l * np.array([cp * ct, sp * ct, -st]))
        v = frame @ (l * np.array([-phid * sp * ct - thetad * cp * st,
                                   phid * cp * ct - thetad * sp * st, -thetad * ct]))
        masses += [r, v]
    return {
        "mu": earth.mu,
        "r_cn_n_0": np.array(r_n).ravel(),
        "v_cn_n_0": np.array(v_n).ravel(),
        "r_bn_n": log.r_BN_N[-1],
        "v_bn_n": log.v_BN_N[-1],
        "sigma_bn": log.sigma_BN[-1],
        "omega_bn_b": log.omega_BN_B[-1],
        "r_pc1b_b": masses[0],
        "r_prime_pc1b_b": masses[1],
        "r_pc2b_b": masses[2],
        "r_prime_pc2b_b": masses[3],
        "t_s": log.times()[-1] * 1e-9,
    }


def rust(name, v):
    v = np.atleast_1d(v)
    body = ", ".join(repr(float(x)) for x in v)
    return f"pub const {name}: [f64; {len(v)}] = [{body}];"


def main():
    import Basilisk

    print(f"// Basilisk {getattr(Basilisk, '__version__', '?')}, tools/peers/basilisk_pendulum.py, "
          f"t = 10 s")
    for case, step, damping in (("UNDAMPED", 0.001, 0.0), ("DAMPED", 0.001, 10.0)):
        out = run(step, damping)
        assert abs(out["t_s"] - 10.0) < 1e-9, out["t_s"]
        if case == "UNDAMPED":
            print(rust("MU", out["mu"]))
            print(rust("R_CN_N_0", out["r_cn_n_0"]))
            print(rust("V_CN_N_0", out["v_cn_n_0"]))
        for key in ("r_bn_n", "v_bn_n", "sigma_bn", "omega_bn_b", "r_pc1b_b", "r_prime_pc1b_b",
                    "r_pc2b_b", "r_prime_pc2b_b"):
            print(rust(f"{case}_{key.upper()}", out[key]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
