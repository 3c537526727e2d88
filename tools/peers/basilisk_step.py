#!/usr/bin/env python3
"""Peer benchmark: one RK4 step (1 ms) of the flexdyn reference spacecraft in Basilisk.

The spacecraft is the one of flexdyn's `benches/step.rs`: a `spacecraft.Spacecraft` hub with one
`dualHingedRigidBodyStateEffector` per panel pair, the `svIntegratorRK4` integrator, a 1 ms task,
and a point-mass Earth (mu = 3.986004415e14) attached to the spacecraft's gravity field.

For each pair count the simulation is initialised, warmed up, and then `ExecuteSimulation` is
timed over repeated spans of sim time; the median wall-clock ns per step over the repetitions is
printed as one line on stdout:

    peer=basilisk pairs=<N> median_ns_per_step=<x>

and nothing else goes to stdout; sanity checks and diagnostics (including any non-finite state,
which the dual-hinged module is known to produce in some configurations) go to stderr.
"""

import argparse
import math
import statistics
import sys
import time

import numpy as np

from Basilisk.simulation import (dualHingedRigidBodyStateEffector, gravityEffector, spacecraft,
                                 svIntegrators)
from Basilisk.utilities import SimulationBaseClass, macros

# --- The reference spacecraft (identical in flexdyn, MuJoCo and here) ---------------------------
MU_EARTH = 3.986004415e14  # m^3/s^2
HUB_MASS = 750.0  # kg
HUB_INERTIA = (900.0, 800.0, 600.0)  # kg m^2, principal, about the hub CoM, B axes
R_BCB_B = (0.0, 0.0, 1.0)  # m, hub CoM relative to point B
PANEL_MASS = 50.0  # kg (each panel)
PANEL_INERTIA = (50.0, 25.0, 25.0)  # kg m^2 about the panel CoM, S axes
PANEL_D = 0.75  # m, hinge to panel CoM along -s1
PANEL1_L = 1.5  # m, hinge 1 to hinge 2 along -s1
SPRING_K = 100.0  # N m / rad (both hinges)
DAMPING_C = 0.0  # N m s / rad (both hinges)
OMEGA_BN_B = (0.05, -0.05, 0.05)  # rad/s
R_CN_N = (-4020338.69, 7490566.74, 5248299.04)  # m
V_CN_N = (-5199.77710904, -3436.68156331, 1041.57627160)  # m/s
STEP_NS = 1_000_000  # 1 ms


def pair_layout(n):
    """Per pair: (r_H1B_B, rows of dcm_H1B = (h1, h2, h3) in B, theta1, theta2) [m, rad].

    Two pairs: the reference wings. Any other count: a ring about b3 at radius 0.5 m, height 1 m,
    each wing pointing radially outward, with the small distinct deflections flexdyn's bench uses.
    """
    if n == 2:
        return [
            ((0.5, 0.0, 1.0), ((-1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
             math.radians(5.0), math.radians(-3.0)),
            ((-0.5, 0.0, 1.0), ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
             math.radians(-2.0), math.radians(4.0)),
        ]
    out = []
    for k in range(n):
        a = 2.0 * math.pi * k / n
        c, s = math.cos(a), math.sin(a)
        dcm = ((-c, -s, 0.0), (s, -c, 0.0), (0.0, 0.0, 1.0))
        out.append(((0.5 * c, 0.5 * s, 1.0), dcm,
                    0.05 * math.sin(1.0 + k), -0.04 * math.cos(2.0 + k)))
    return out


def diag3(v):
    return [[v[0], 0.0, 0.0], [0.0, v[1], 0.0], [0.0, 0.0, v[2]]]


def make_panel(i, r_h1b, dcm, theta1, theta2):
    """One dual-hinged pair. Basilisk's conventions match flexdyn's one to one: dcm_H1B rows are
    h1, h2, h3 in B; dcm_S1H1 = M2(theta1) so the hinge axis is h2; the panel CoM is at
    r_H1B - d1 s1 and hinge 2 at r_H1B - l1 s1; IPntS*_S* is about the panel CoM in S axes."""
    p = dualHingedRigidBodyStateEffector.DualHingedRigidBodyStateEffector()
    p.ModelTag = f"pair{i}"
    p.mass1 = PANEL_MASS
    p.IPntS1_S1 = diag3(PANEL_INERTIA)
    p.d1 = PANEL_D
    p.l1 = PANEL1_L
    p.k1 = SPRING_K
    p.c1 = DAMPING_C
    p.mass2 = PANEL_MASS
    p.IPntS2_S2 = diag3(PANEL_INERTIA)
    p.d2 = PANEL_D
    p.k2 = SPRING_K
    p.c2 = DAMPING_C
    p.thetaH2S1 = 0.0  # hinge 2 frame = S1 frame
    p.r_H1B_B = [[r_h1b[0]], [r_h1b[1]], [r_h1b[2]]]
    p.dcm_H1B = [list(row) for row in dcm]
    p.theta1Init = theta1
    p.theta1DotInit = 0.0
    p.theta2Init = theta2
    p.theta2DotInit = 0.0
    return p


class Sim:
    """The spacecraft with n pairs in a one-task Basilisk simulation, initialised at t = 0."""

    def __init__(self, n, gravity=True):
        self.sim = SimulationBaseClass.SimBaseClass()
        proc = self.sim.CreateNewProcess("dynProcess")
        proc.addTask(self.sim.CreateNewTask("dynTask", STEP_NS))

        sc = spacecraft.Spacecraft()
        sc.ModelTag = "flexdynPeer"
        sc.hub.mHub = HUB_MASS
        sc.hub.r_BcB_B = [[R_BCB_B[0]], [R_BCB_B[1]], [R_BCB_B[2]]]
        sc.hub.IHubPntBc_B = diag3(HUB_INERTIA)
        # r_CN_NInit / v_CN_NInit are the composite (hub + panels) centre of mass.
        sc.hub.r_CN_NInit = [[x] for x in R_CN_N]
        sc.hub.v_CN_NInit = [[x] for x in V_CN_N]
        sc.hub.sigma_BNInit = [[0.0], [0.0], [0.0]]
        sc.hub.omega_BN_BInit = [[x] for x in OMEGA_BN_B]

        self.panels = [make_panel(i, *lay) for i, lay in enumerate(pair_layout(n))]
        for p in self.panels:
            sc.addStateEffector(p)
        # Keep references alive: SWIG objects the C++ side points to.
        self.integrator = svIntegrators.svIntegratorRK4(sc)
        sc.setIntegrator(self.integrator)

        if gravity:
            earth = gravityEffector.GravBodyData()
            earth.planetName = "earth_planet_data"
            earth.mu = MU_EARTH
            earth.isCentralBody = True
            self.earth = earth
            sc.gravField.gravBodies = spacecraft.GravBodyVector([earth])

        # Only the spacecraft is a task model: the panels are integrated as its state effectors
        # (adding them to the task would only write their output messages each step).
        self.sim.AddModelToTask("dynTask", sc)
        self.sc = sc
        self.sim.InitializeSimulation()
        self.now_ns = 0

    def run_steps(self, steps):
        self.now_ns += steps * STEP_NS
        self.sim.ConfigureStopTime(self.now_ns)
        self.sim.ExecuteSimulation()

    def hinge_angles(self):
        out = []
        dm = self.sc.dynManager
        for p in self.panels:
            for name in (p.nameOfTheta1State, p.nameOfTheta2State):
                out.append(float(np.asarray(dm.getStateObject(name).getState()).ravel()[0]))
        return np.array(out)

    def hub_state(self):
        m = self.sc.scStateOutMsg.read()
        return np.concatenate([m.r_CN_N, m.v_CN_N, m.sigma_BN, m.omega_BN_B])

    def conserved(self):
        return (np.array(self.sc.totRotAngMomPntC_N).ravel(), float(self.sc.totRotEnergy),
                float(self.sc.totOrbEnergy))

    def finite(self):
        return bool(np.all(np.isfinite(self.hub_state())) and
                    np.all(np.isfinite(self.hinge_angles())))


def sanity(n, seconds, log):
    """Mass, initial CoM, panels oscillating, conservation; reports a non-finite blow-up."""
    s = Sim(n)
    ok = True
    mass = s.sc.scMassOutMsg.read().massSC
    expected = HUB_MASS + 2 * PANEL_MASS * n
    if abs(mass - expected) > 1e-9:
        log(f"  FAIL total mass {mass} != {expected}")
        ok = False
    s.run_steps(1)
    L0, Erot0, Eorb0 = s.conserved()
    th_hist = [s.hinge_angles()]
    th0 = th_hist[0]
    chunk = 100
    blown_at = None
    for k in range(int(seconds * 1000) // chunk):
        s.run_steps(chunk)
        th_hist.append(s.hinge_angles())
        if not s.finite():
            blown_at = (k + 1) * chunk * 1e-3
            break
    th = np.array(th_hist)
    if blown_at is not None:
        log(f"  pairs={n}: NON-FINITE state after ~{blown_at:.1f} s of sim time "
            f"(Basilisk dualHingedRigidBodyStateEffector blew up); timing still measured")
        return ok, False
    L1, Erot1, Eorb1 = s.conserved()
    swing = th.max(axis=0) - th.min(axis=0)
    oscillates = bool(np.all(swing > 0.5 * np.maximum(np.abs(th0), 1e-3)))
    dL = np.linalg.norm(L1 - L0) / np.linalg.norm(L0)
    dE = abs(Erot1 - Erot0) / abs(Erot0)
    dEo = abs(Eorb1 - Eorb0) / abs(Eorb0)
    log(f"  pairs={n}: mass={mass:.1f} kg, max|theta|={np.abs(th).max():.4f} rad, "
        f"swing(min)={swing.min():.4f} rad, {seconds:g} s drift: |dL|/|L|={dL:.2e} "
        f"|dErot|/Erot={dE:.2e} |dEorb|/Eorb={dEo:.2e}")
    if not oscillates:
        log("  FAIL panels do not oscillate")
        ok = False
    if dL > 1e-6 or dE > 1e-6 or dEo > 1e-6:
        log("  WARNING conservation drift above 1e-6 (module behaviour; timing unaffected)")
    return ok, True


def bench(n, reps, steps, log):
    s = Sim(n)
    s.run_steps(steps)  # warm-up
    per_step = []
    for _ in range(reps):
        t0 = time.perf_counter_ns()
        s.run_steps(steps)
        per_step.append((time.perf_counter_ns() - t0) / steps)
    finite = s.finite()
    med = statistics.median(per_step)
    log(f"  pairs={n}: median {med:.1f} ns/step (min {min(per_step):.1f}, "
        f"max {max(per_step):.1f}; {reps} reps x {steps} steps = {steps * 1e-3:g} s sim each)"
        + ("" if finite else f"; state NON-FINITE at t={s.now_ns * 1e-9:g} s"))
    return med, finite


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pairs", default="1,2,4,8,16",
                    help="comma-separated pair counts (default 1,2,4,8,16)")
    ap.add_argument("--reps", type=int, default=11, help="timed repetitions per count (>= 11)")
    ap.add_argument("--steps", type=int, default=10000,
                    help="RK4 steps (1 ms each) per timed ExecuteSimulation span")
    ap.add_argument("--max-seconds", type=float, default=3.0,
                    help="cap on wall time of one span: the span shrinks for large pair counts")
    ap.add_argument("--check-seconds", type=float, default=10.0,
                    help="sim time of the sanity run per count")
    ap.add_argument("--no-check", action="store_true", help="skip the sanity checks")
    args = ap.parse_args()

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    try:
        from Basilisk import __version__ as bsk_version
    except ImportError:
        bsk_version = "?"
    counts = [int(x) for x in args.pairs.split(",") if x.strip()]
    log(f"basilisk {bsk_version}: svIntegratorRK4, dt=1 ms, point-mass Earth gravity")
    nonfinite = []
    if not args.no_check:
        log("sanity checks:")
        ok_all = True
        for n in counts:
            ok, finite = sanity(n, args.check_seconds, log)
            ok_all &= ok
            if not finite:
                nonfinite.append(n)
        if not ok_all:
            log("sanity checks FAILED")
            return 1
    log("timing:")
    for n in counts:
        # Probe the cost to keep one span under --max-seconds of wall time.
        probe = Sim(n)
        t0 = time.perf_counter_ns()
        probe.run_steps(200)
        est = (time.perf_counter_ns() - t0) / 200
        del probe
        steps = max(1000, min(args.steps, int(args.max_seconds * 1e9 / est)))
        med, finite = bench(n, args.reps, steps, log)
        if not finite and n not in nonfinite:
            nonfinite.append(n)
        print(f"peer=basilisk pairs={n} median_ns_per_step={med:.1f}", flush=True)
    if nonfinite:
        log(f"NOTE: the Basilisk state went non-finite for pairs={nonfinite}; the timings are "
            f"of the module as distributed and still reported")
    return 0


if __name__ == "__main__":
    sys.exit(main())
