#!/usr/bin/env python3
"""The figures of docs/models/fuel-slosh.md.

- docs/figures/slosh_states.png: `flexdyn simulate` of scenarios/slosh.toml over 60 s, the
  spring-mass particle's rho and the pendulum's phi and theta;
- docs/figures/slosh_fill_level.png: the first mode of a 0.4 m radius cylindrical tank against
  its fill level, from `CylindricalTank::first_mode` (the example `slosh_fill_level`).

Run from the repository root, with the flexdyn binary built (`cargo build --release`):

    target/peers-venv/bin/python tools/peers/slosh_figures.py [--flexdyn target/release/flexdyn]

Needs matplotlib and numpy (both in the peers venv).
"""

import argparse
import io
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.dont_write_bytecode = True


def read_csv(text):
    return np.genfromtxt(io.StringIO(text), delimiter=",", names=True)


def states(flexdyn, out):
    with tempfile.NamedTemporaryFile(suffix=".csv") as f:
        subprocess.run(
            [flexdyn, "simulate", "--config", "scenarios/slosh.toml", "--duration-s", "60",
             "--log-every-s", "0.05", "-o", f.name],
            check=True, stdout=subprocess.DEVNULL)
        d = np.genfromtxt(f.name, delimiter=",", names=True)
    t = d["t_s"]
    fig, ax = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    ax[0].plot(t, d["slosh1_rho_m"] * 1e3)
    ax[0].set_ylabel("tank_px: rho [mm]")
    ax[1].plot(t, np.degrees(d["pendulum1_phi_rad"]), label="phi")
    ax[1].plot(t, np.degrees(d["pendulum1_theta_rad"]), label="theta")
    ax[1].set_ylabel("tank_mx [deg]")
    ax[1].set_xlabel("t [s]")
    ax[1].legend()
    fig.suptitle("scenarios/slosh.toml: spring-mass and pendulum slosh")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def fill_level(out):
    text = subprocess.run(
        ["cargo", "run", "-q", "--release", "-p", "flexdyn-dynamics", "--example",
         "slosh_fill_level"], check=True, capture_output=True, text=True).stdout
    d = read_csv(text)
    x = d["h_over_r"]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(x, d["slosh_fraction"], label="m1 / m_L")
    ax.plot(x, d["pendulum_length_over_r"], label="L1 / R")
    ax.plot(x, d["slosh_height_over_h"], label="h1 / h")
    ax.set_xlabel("fill level h / R")
    ax.set_ylim(0, 1.6)
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title("first lateral slosh mode of a flat-bottomed cylinder")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--flexdyn", default="target/release/flexdyn")
    args = ap.parse_args()
    states(args.flexdyn, "docs/figures/slosh_states.png")
    fill_level("docs/figures/slosh_fill_level.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
