#!/usr/bin/env python3
"""Peer benchmark: one RK4 step (1 ms) of the reference hub with an N-link panel chain in MuJoCo.

The spacecraft is the one of flexdyn's `benches/chain.rs`: the reference hub of
`mujoco_step.py` with one chain of N unequal panels, exactly `flexdyn_dynamics::reference::
unequal_chain(N, 0.0)`: hinge 1 at (0.5, 0, 1) m with [H1 B] = diag(-1, -1, 1); panel k
(0-based) of mass 40 - 3k kg, inertia (30 - 2k, 15 - k, 16 - k) kg m^2, length 1.5 - 0.05k m,
d = 0.45 l + 0.02k m, stiffness 100 + 15k N m/rad, no damping, theta = 0.06 sin(1 + k) rad,
theta_dot = 0.02 cos(2 + k) rad/s. As an MJCF tree: a free hub body with a chain of N hinged
bodies, each a child of the previous one at its hinge, all hinges about the body y axis;
`integrator="RK4"`, `timestep=0.001`, zero gravity. Timed as `mujoco_step.py` times its pairs
(single-thread `mujoco.rollout`, median over repetitions); prints one line per count:

    peer=mujoco links=<N> median_ns_per_step=<x>

and nothing else on stdout. A failed sanity check (mass, non-finite state, a conservation drift
over 5 s above 1e-6) exits 1 before timing.
"""

import argparse
import math
import os
import sys

import numpy as np

import mujoco
import mujoco.rollout

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mujoco_step  # noqa: E402
from mujoco_step import (HUB_INERTIA, HUB_MASS, OMEGA_BN_B, R_BCB_B, R_CN_N, STEP_S,  # noqa: E402
                         V_CN_N, fmt)

R_H1B_B = (0.5, 0.0, 1.0)
DCM_H1B = ((-1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0))


def panel(k):
    """(mass, inertia, d, l, k_spring, theta, theta_dot) of panel k, as `unequal_chain`."""
    l = 1.5 - 0.05 * k
    return (40.0 - 3.0 * k, (30.0 - 2.0 * k, 15.0 - k, 16.0 - k), 0.45 * l + 0.02 * k, l,
            100.0 + 15.0 * k, 0.06 * math.sin(1.0 + k), 0.02 * math.cos(2.0 + k))


def build_mjcf(n, with_checks=False):
    """The hub frame is B; body k's frame is hinge frame H_k at theta = 0, so its hinge axis is
    the body y axis and its CoM is at -d_k along the body x axis; body k + 1 sits at -l_k."""
    inner = ""
    for k in reversed(range(n)):
        m, inertia, d, l, ks, _th, _thd = panel(k)
        pos = fmt(R_H1B_B) if k == 0 else f"{-panel(k - 1)[3]} 0 0"
        axes = f' xyaxes="{fmt(DCM_H1B[0])} {fmt(DCM_H1B[1])}"' if k == 0 else ""
        inner = f"""
      <body name="panel{k}" pos="{pos}"{axes}>
        <joint name="theta{k}" type="hinge" axis="0 1 0" stiffness="{ks}" springref="0" damping="0"/>
        <inertial pos="{-d} 0 0" mass="{m}" diaginertia="{fmt(inertia)}"/>{inner}
      </body>"""
    flags = '<flag energy="enable"/>' if with_checks else ""
    sensors = ('<sensor><subtreeangmom name="L_C" body="hub"/></sensor>') if with_checks else ""
    return f"""
<mujoco model="flexdyn_peer_chain_{n}">
  <compiler angle="radian"/>
  <option timestep="{STEP_S}" integrator="RK4" gravity="0 0 0">{flags}</option>
  <worldbody>
    <body name="hub">
      <freejoint name="hub"/>
      <inertial pos="{fmt(R_BCB_B)}" mass="{HUB_MASS}" diaginertia="{fmt(HUB_INERTIA)}"/>{inner}
    </body>
  </worldbody>
  {sensors}
</mujoco>
"""


def make(n, with_checks=False):
    model = mujoco.MjModel.from_xml_string(build_mjcf(n, with_checks))
    data = mujoco.MjData(model)
    for k in range(n):
        _m, _i, _d, _l, _ks, th, thd = panel(k)
        data.joint(f"theta{k}").qpos[0] = th
        data.joint(f"theta{k}").qvel[0] = thd
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    r_cb = data.subtree_com[1].copy()
    data.qpos[0:3] = np.array(R_CN_N) - r_cb
    data.qpos[3:7] = (1.0, 0.0, 0.0, 0.0)
    data.qvel[0:3] = np.array(V_CN_N) - np.cross(np.array(OMEGA_BN_B), r_cb)
    data.qvel[3:6] = OMEGA_BN_B
    mujoco.mj_forward(model, data)
    return model, data


def sanity(n, log):
    model, data = make(n, with_checks=True)
    expected = HUB_MASS + sum(panel(k)[0] for k in range(n))
    L0, E0 = data.sensor("L_C").data.copy(), data.energy.sum()
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    init = np.empty(nstate)
    mujoco.mj_getState(model, data, init, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    state, _ = mujoco.rollout.rollout(model, data, init[None, :], nstep=5000)
    mujoco.mj_setState(model, data, state[0, -1], mujoco.mjtState.mjSTATE_FULLPHYSICS)
    mujoco.mj_forward(model, data)
    dL = np.linalg.norm(data.sensor("L_C").data - L0) / np.linalg.norm(L0)
    dE = abs(data.energy.sum() - E0) / abs(E0)
    total = model.body_subtreemass[1]
    log(f"  links={n}: nv={model.nv} mass={total:.1f} kg, 5 s drift |dL|/|L|={dL:.2e} "
        f"|dE|/E={dE:.2e}")
    return (abs(total - expected) < 1e-9 and bool(np.all(np.isfinite(state)))
            and dL < 1e-6 and dE < 1e-6)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--links", default="10", help="comma-separated link counts (default 10)")
    ap.add_argument("--reps", type=int, default=11, help="timed repetitions per count")
    ap.add_argument("--steps", type=int, default=20000, help="RK4 steps per rollout call")
    ap.add_argument("--print-mjcf", type=int, metavar="N", help="print the MJCF for N links")
    args = ap.parse_args()
    if args.print_mjcf is not None:
        print(build_mjcf(args.print_mjcf))
        return 0

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    counts = [int(x) for x in args.links.split(",") if x.strip()]
    log(f"mujoco {mujoco.__version__}: chain, RK4, dt={STEP_S} s, zero gravity, one thread")
    if not all([sanity(n, log) for n in counts]):
        log("sanity checks FAILED")
        return 1
    for n in counts:
        med = mujoco_step.bench(n, args.reps, args.steps, log, make=make, label="links")
        print(f"peer=mujoco links={n} median_ns_per_step={med:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
