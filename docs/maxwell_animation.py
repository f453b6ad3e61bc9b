"""The gas relaxing onto the 2-D Maxwell–Boltzmann curve, as an animated GIF, from a
`ballpit run --trajectory` file read with ASE:

    ballpit run --scene assets/scenes/maxwell.ron --steps 60 --trajectory maxwell.xyz
    python3 docs/maxwell_animation.py maxwell.xyz docs/maxwell.gif

Each frame: the balls' speeds binned, against the mixture over the balls' masses of
f(v) = (m v / T) exp(-m v² / 2T) at the frame's temperature T (mean kinetic energy per ball),
as `ballpit run` reports it. Needs ase, numpy, matplotlib and pillow.
"""
import sys

import ase.io
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter

trajectory, out = sys.argv[1], sys.argv[2]
frames = ase.io.read(trajectory, index=":")
mass = frames[0].arrays["mass"]
speeds = [np.linalg.norm(f.arrays["velo"][:, :2], axis=1) for f in frames]
top = 800.0
bins = np.linspace(0.0, top, 41)
width = bins[1] - bins[0]
v = np.linspace(0.0, top, 300)

fig, ax = plt.subplots(figsize=(6, 3.6), dpi=80)


def draw(index):
    ax.clear()
    s = speeds[index]
    temperature = np.mean(0.5 * mass * s**2)
    expected = (mass[:, None] * v / temperature
                * np.exp(-mass[:, None] * v**2 / (2 * temperature))).sum(axis=0) * width
    ax.hist(s, bins=bins, color="#4c9be8", label="balls")
    ax.plot(v, expected, color="#e8714c", lw=2, label="Maxwell–Boltzmann, same temperature")
    ax.set_xlim(0, top)
    ax.set_ylim(0, len(s) * 0.2)
    ax.set_xlabel("speed, px/s")
    ax.set_ylabel("balls per bin")
    ax.set_title(f"{len(s)} balls, all at 300 px/s at t = 0;  t = {frames[index].info['Time']:.2f} s")
    ax.legend(loc="upper right")
    fig.tight_layout()


animation = FuncAnimation(fig, draw, frames=len(frames))
animation.save(out, writer=PillowWriter(fps=10))
print(f"{len(frames)} frames to {out}")
