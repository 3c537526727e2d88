#!/usr/bin/env python3
"""Peer benchmark: one RK4 step (1 ms) of the flexdyn reference spacecraft in MuJoCo.

The spacecraft is the one of flexdyn's `benches/step.rs` (rigid hub + N dual-hinged rigid panel
pairs, torsional springs, no damping), written as an MJCF kinematic tree: a free-floating hub
body (freejoint) with, per pair, a panel-1 body hinged to the hub and a panel-2 body hinged to the
tip of panel 1. `integrator="RK4"`, `timestep=0.001`, zero gravity (free space: MuJoCo has no
point-mass central-body field, and the cost of a step is dominated by the tree anyway).

Time stepping runs on the C side through `mujoco.rollout.rollout` (single thread, many steps per
call). For each pair count the median wall-clock ns per step over the repetitions is printed as
one line on stdout:

    peer=mujoco pairs=<N> median_ns_per_step=<x>

and nothing else goes to stdout; sanity checks and diagnostics go to stderr. A failed sanity check
exits non-zero.
"""

import argparse
import math
import statistics
import sys
import time

import numpy as np

import mujoco
import mujoco.rollout

# --- The reference spacecraft (identical in flexdyn, Basilisk and here) -------------------------
HUB_MASS = 750.0  # kg
HUB_INERTIA = (900.0, 800.0, 600.0)  # kg m^2, principal, about the hub CoM, B axes
R_BCB_B = (0.0, 0.0, 1.0)  # m, hub CoM relative to point B
PANEL_MASS = 50.0  # kg (each panel)
PANEL_INERTIA = (50.0, 25.0, 25.0)  # kg m^2 about the panel CoM, S axes
PANEL_D = 0.75  # m, hinge to panel CoM along -s1
PANEL1_L = 1.5  # m, hinge 1 to hinge 2 along -s1
SPRING_K = 100.0  # N m / rad (both hinges)
OMEGA_BN_B = (0.05, -0.05, 0.05)  # rad/s
R_CN_N = (-4020338.69, 7490566.74, 5248299.04)  # m
V_CN_N = (-5199.77710904, -3436.68156331, 1041.57627160)  # m/s
STEP_S = 0.001


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


def fmt(v):
    return " ".join(repr(float(x)) for x in v)


def build_mjcf(n, with_checks=False):
    """MJCF of the spacecraft with n pairs. The hub body frame is B (origin at point B).

    Panel body frames are the hinge frames H1 (panel 1) and H2 = S1 at theta = 0 (panel 2), so
    the hinge axis is the body y axis (h2) and the CoM sits at -d along the body x axis (-s1). A
    positive hinge angle rotates the panel about +h2, as in Basilisk's dcm_S1H1 = M2(theta1).
    """
    panel_inertial = (f'<inertial pos="{-PANEL_D} 0 0" mass="{PANEL_MASS}" '
                      f'diaginertia="{fmt(PANEL_INERTIA)}"/>')
    spring = f'type="hinge" axis="0 1 0" stiffness="{SPRING_K}" springref="0" damping="0"'
    pairs = []
    for i, (r_h1b, dcm, _t1, _t2) in enumerate(pair_layout(n)):
        h1, h2, _h3 = dcm
        pairs.append(f"""
      <body name="pair{i}_panel1" pos="{fmt(r_h1b)}" xyaxes="{fmt(h1)} {fmt(h2)}">
        <joint name="pair{i}_theta1" {spring}/>
        {panel_inertial}
        <body name="pair{i}_panel2" pos="{-PANEL1_L} 0 0">
          <joint name="pair{i}_theta2" {spring}/>
          {panel_inertial}
        </body>
      </body>""")
    flags = '<flag energy="enable"/>' if with_checks else ""
    sensors = ('<sensor><subtreeangmom name="L_C" body="hub"/>'
               '<subtreelinvel name="v_C" body="hub"/></sensor>') if with_checks else ""
    return f"""
<mujoco model="flexdyn_peer_{n}_pairs">
  <compiler angle="radian"/>
  <option timestep="{STEP_S}" integrator="RK4" gravity="0 0 0">{flags}</option>
  <worldbody>
    <body name="hub">
      <freejoint name="hub"/>
      <inertial pos="{fmt(R_BCB_B)}" mass="{HUB_MASS}" diaginertia="{fmt(HUB_INERTIA)}"/>
      {''.join(pairs)}
    </body>
  </worldbody>
  {sensors}
</mujoco>
"""


def make(n, with_checks=False):
    """Model and data at the initial state: hinge angles set, the composite CoM at r_C/N moving
    at v_C/N, hub attitude identity (sigma_BN = 0), omega_BN_B as given, hinge rates zero."""
    model = mujoco.MjModel.from_xml_string(build_mjcf(n, with_checks))
    data = mujoco.MjData(model)
    for i, (_r, _dcm, t1, t2) in enumerate(pair_layout(n)):
        data.joint(f"pair{i}_theta1").qpos[0] = t1
        data.joint(f"pair{i}_theta2").qpos[0] = t2
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    r_cb = data.subtree_com[1].copy()  # composite CoM relative to B (hub at the origin, B = N)
    omega = np.array(OMEGA_BN_B)
    data.qpos[0:3] = np.array(R_CN_N) - r_cb
    data.qpos[3:7] = (1.0, 0.0, 0.0, 0.0)
    # Free joint: linear velocity of the body origin B in world axes, angular velocity in body
    # axes. Hinge rates are zero, so v_C = v_B + omega x r_C/B.
    data.qvel[0:3] = np.array(V_CN_N) - np.cross(omega, r_cb)
    data.qvel[3:6] = omega
    mujoco.mj_forward(model, data)
    return model, data


def hinge_qpos_adr(model, n):
    return [model.jnt_qposadr[model.joint(f"pair{i}_theta{j}").id]
            for i in range(n) for j in (1, 2)]


def sanity(n, log):
    """Mass, CoM placement, springs making panels oscillate, conservation over 5 s of RK4."""
    model, data = make(n, with_checks=True)
    total = model.body_subtreemass[1]
    expected = HUB_MASS + 2 * PANEL_MASS * n
    ok = True
    if abs(total - expected) > 1e-9:
        log(f"  FAIL total mass {total} != {expected}")
        ok = False
    com_err = np.linalg.norm(data.subtree_com[1] - np.array(R_CN_N))
    vc0 = data.sensor("v_C").data.copy()
    L0 = data.sensor("L_C").data.copy()
    E0 = data.energy.sum()
    adr = hinge_qpos_adr(model, n)
    th0 = data.qpos[adr].copy()
    nstep = 5000
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    init = np.empty(nstate)
    mujoco.mj_getState(model, data, init, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    state, sens = mujoco.rollout.rollout(model, data, init[None, :], nstep=nstep)
    # Full-physics state layout starts with time, then qpos.
    qpos_hist = state[0, :, 1:1 + model.nq]
    th = qpos_hist[:, adr]
    finite = bool(np.all(np.isfinite(state)))
    # Oscillation: every hinge angle changes sign relative to its spring's rest angle, or at
    # least swings by a good fraction of its initial amplitude (coupled modes).
    swing = th.max(axis=0) - th.min(axis=0)
    oscillates = bool(np.all(swing > 0.5 * np.maximum(np.abs(th0), 1e-3)))
    # Conservation: angular momentum about the CoM and total energy.
    mujoco.mj_setState(model, data, state[0, -1], mujoco.mjtState.mjSTATE_FULLPHYSICS)
    mujoco.mj_forward(model, data)
    L1 = data.sensor("L_C").data.copy()
    E1 = data.energy.sum()
    vc1 = data.sensor("v_C").data.copy()
    dL = np.linalg.norm(L1 - L0) / np.linalg.norm(L0)
    dE = abs(E1 - E0) / abs(E0)
    dv = np.linalg.norm(vc1 - vc0)
    log(f"  pairs={n}: nq={model.nq} nv={model.nv} mass={total:.1f} kg "
        f"|r_C - r_C/N|={com_err:.2e} m, swing(min)={swing.min():.4f} rad, "
        f"5 s drift: |dL|/|L|={dL:.2e} |dE|/E={dE:.2e} |dv_C|={dv:.2e} m/s")
    if not finite:
        log("  FAIL non-finite state")
        ok = False
    if not oscillates:
        log("  FAIL panels do not oscillate")
        ok = False
    if com_err > 1e-6 or dL > 1e-6 or dE > 1e-6 or dv > 1e-6:
        log("  FAIL initial CoM placement or conservation")
        ok = False
    return ok


def bench(n, reps, steps, log, make=make, label="pairs"):
    """Median ns per RK4 step of the model `make(n)` builds (`mujoco_chain.py` passes its own)."""
    model, data = make(n)
    nstate = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    init = np.empty((1, nstate))
    mujoco.mj_getState(model, data, init[0], mujoco.mjtState.mjSTATE_FULLPHYSICS)
    state = np.empty((1, steps, nstate))
    sens = np.empty((1, steps, model.nsensordata))
    roll = mujoco.rollout.Rollout(nthread=0)  # rollouts run on the calling thread
    # Warm-up (page in the output buffers, caches), then continue the trajectory rep after rep.
    roll.rollout(model, data, init, nstep=steps, state=state, sensordata=sens)
    init[0] = state[0, -1]
    per_step = []
    for _ in range(reps):
        t0 = time.perf_counter_ns()
        roll.rollout(model, data, init, nstep=steps, state=state, sensordata=sens)
        dt = time.perf_counter_ns() - t0
        per_step.append(dt / steps)
        init[0] = state[0, -1]
    roll.close()
    if not np.all(np.isfinite(state)):
        log(f"  WARNING {label}={n}: non-finite state during timing")
    med = statistics.median(per_step)
    log(f"  {label}={n}: median {med:.1f} ns/step (min {min(per_step):.1f}, "
        f"max {max(per_step):.1f}; {reps} reps x {steps} steps)")
    return med


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pairs", default="1,2,4,8,16",
                    help="comma-separated pair counts (default 1,2,4,8,16)")
    ap.add_argument("--reps", type=int, default=15, help="timed repetitions per count (>= 11)")
    ap.add_argument("--steps", type=int, default=20000, help="RK4 steps per rollout call")
    ap.add_argument("--no-check", action="store_true", help="skip the sanity checks")
    ap.add_argument("--print-mjcf", type=int, metavar="N",
                    help="print the MJCF for N pairs to stdout and exit")
    args = ap.parse_args()

    if args.print_mjcf is not None:
        print(build_mjcf(args.print_mjcf))
        return 0

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    counts = [int(x) for x in args.pairs.split(",") if x.strip()]
    log(f"mujoco {mujoco.__version__}: RK4, dt={STEP_S} s, zero gravity (free space), "
        f"single-thread mujoco.rollout")
    if not args.no_check:
        log("sanity checks:")
        if not all([sanity(n, log) for n in counts]):
            log("sanity checks FAILED")
            return 1
    log("timing:")
    for n in counts:
        med = bench(n, args.reps, args.steps, log)
        print(f"peer=mujoco pairs={n} median_ns_per_step={med:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
