"""Reads a `ballpit run --trajectory` file with ASE and checks its last frame against the
`--dump` of the same run, bit for bit. CI runs it (after `pip install ase`):

    python3 tests/ase_check.py RUN.xyz DUMP.json FRAMES
"""
import json
import sys

import ase.io
import numpy as np

trajectory, dump, frames_expected = sys.argv[1], sys.argv[2], int(sys.argv[3])
frames = ase.io.read(trajectory, index=":")
assert len(frames) == frames_expected, f"{len(frames)} frames, expected {frames_expected}"
balls = json.load(open(dump))["balls"]
last = frames[-1]
expected = {
    "positions": np.array([[b["x"], b["y"], 0.0] for b in balls]),
    "velo": np.array([[b["vx"], b["vy"], 0.0] for b in balls]),
    "radius": np.array([b["r"] for b in balls]),
    "mass": np.array([b["m"] for b in balls]),
    "id": np.array([b["id"] for b in balls]),
}
for name, values in expected.items():
    assert np.array_equal(last.arrays[name], values), f"{name} differs from the dump"
assert np.all(last.cell.lengths()[:2] > 0), "the arena is the lattice"
print(f"ASE {ase.__version__} read {len(frames)} frames of {len(last)} balls; "
      "the last equals the dump")
