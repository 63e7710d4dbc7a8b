#!/usr/bin/python3
"""Hindered settling with the drag spread over the cells (Drag distribution
= cell), the grains placed at random or on a lattice that puts the same
grains in every cell: prints v / closure (mean over t = 3-6 s, with the
range) for each. On the lattice every cell carries the same weight, the
pressure takes all of it, and no grain feels a flow; at random, each
cell's excess weight drives a flow that its grains feel
(doc/validation.md, "Dense suspensions: the cell spread's limit").

    benchmarks/self_disturbance/lattice_suspension.py [2|3]

2D: 512 discs, phi_s = 0.098, box 128 r x 128 r, cells of 8 r, without
the self-disturbance correction (its 2D default). 3D: 15,360 beads,
phi_s = 0.262 in a layer 60 r tall of a box 64 r x 64 r x 64 r, cells of
8 r, without and with the correction (its 3D default). Both periodic
sideways, closed above and below, steady Stokes, 12 steps of 0.5 s; the
seed's beads in glycerine. The last column: at the end, the grains more
than a cell from the floor and the lid. About 30 s.
"""
import glob
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import scene_runner  # noqa: E402 (benchmarks/)

sys.path.insert(0, os.path.join(scene_runner.ROOT, "scripts"))
from plot_scene import read_vtu  # noqa: E402

WORK = os.path.join(scene_runner.ROOT, "benchmarks", "results",
                    "lattice_suspension")
R = 12.5e-6


def lattice(dim):
    if dim == 2:
        h = 1e-4
        return [(h * (i + a), h * (j + b))
                for j in range(16) for i in range(16)
                for a, b in [(0.25, 0.35), (0.75, 0.85)]]
    # FCC, cubes of 50 um (two per cell edge), 15 layers from z = 25 um.
    a = 5e-5
    basis = [(0.25, 0.25, 0.25), (0.75, 0.75, 0.25),
             (0.75, 0.25, 0.75), (0.25, 0.75, 0.75)]
    return [(a * (i + b[0]), a * (j + b[1]), 2.5e-5 + a * (k + b[2]))
            for i in range(16) for j in range(16) for k in range(15)
            for b in basis]


def run(dim, placement, correction):
    points = lattice(dim)
    n = len(points)
    if dim == 2:
        box, cells, height = "1.6e-3, 1.6e-3", "4, 4", 1.6e-3
        faces = "periodic, periodic, wall, wall"
        refinement, gravity = 2, "0, -9.81"
        region = ("set Center = 8e-4, 8e-4", "set Size   = 1.6e-3, 1.6e-3")
    else:
        box, cells, height = "8e-4, 8e-4, 8e-4", "4, 4, 4", 7.5e-4
        faces = "periodic, periodic, periodic, periodic, wall, wall"
        refinement, gravity = 1, "0, 0, -9.81"
        region = ("set Center = 4e-4, 4e-4, 4e-4",
                  "set Size   = 8e-4, 8e-4, 7.5e-4")
    if placement == "lattice":
        positions = "; ".join(", ".join(f"{x:.6g}" for x in p)
                              for p in points)
        place = f"set Shape = list\n    set Positions = {positions}"
    else:
        place = (f"set Shape = box\n    {region[0]}\n    {region[1]}\n"
                 f"    set Count = {n}\n    set Random seed = 3")
    scene = f"""set Dimension = {dim}
set End time  = 6
set Time step = 0.5
subsection Mesh
  set Lower corner = {", ".join(["0"] * dim)}
  set Upper corner = {box}
  set Subdivisions = {cells}
  set Initial refinement = {refinement}
  set Boundary conditions = {faces}
end
subsection Fluid
  set Density   = 1200
  set Viscosity = 0.12
  set Advection = false
  set Time derivative = false
end
subsection Coupling
  set Drag distribution = cell
  set Self-disturbance correction = {correction}
end
subsection Grains
  set Enabled = true
  set Radius  = {R}
  set Density = 2400
  subsection Placement
    {place}
  end
end
subsection Gravity
  set Vector = {gravity}
end
"""
    directory = os.path.join(WORK, f"{dim}d_{placement}_{correction}")
    rows = scene_runner.run_scene(scene, directory)
    # The closure in the grains' layer: v = eps^4.8 times the law's own
    # single-grain velocity (doc/theory.md section 3).
    width = 1.6e-3 if dim == 2 else 8e-4
    volume = math.pi * R * R if dim == 2 else 4 / 3 * math.pi * R ** 3
    phi_s = n * volume / (width ** (dim - 1) * height)
    single = 4.1801e-6 if dim == 2 else 2 * 1200 * 9.81 * R * R / (9 * 0.12) / 0.96
    closure = -(1 - phi_s) ** 4.8 * single
    axis = "mean_velocity_" + ("y" if dim == 2 else "z")
    v = [float(r[axis]) / closure for r in rows if float(r["time"]) >= 3]
    # At the end, the grains more than a cell (8 r) from the floor and the
    # lid: in 3D the layer leaves its top and bottom cells partly filled.
    x, u = [], []
    for piece in glob.glob(os.path.join(directory, "particles_00012*.vtu")):
        centres, arrays, _ = read_vtu(piece)
        if len(centres):
            x.append(centres)
            u.append(arrays["velocity"])
    x, u = np.concatenate(x), np.concatenate(u)
    inner = (x[:, dim - 1] > 1e-4) & (x[:, dim - 1] < width - 1e-4)
    return phi_s, sum(v) / len(v), min(v), max(v), \
        u[inner, dim - 1].mean() / closure


def main():
    dims = [int(sys.argv[1])] if len(sys.argv) > 1 else [2, 3]
    print("dim  placement  correction  phi_s   v/closure (range)       "
          "a cell from the walls")
    for dim in dims:
        for correction in (["false"] if dim == 2 else ["false", "true"]):
            for placement in ["lattice", "random"]:
                phi_s, mean, low, high, inner = run(dim, placement,
                                                    correction)
                print(f"{dim}    {placement:9s}  {correction:10s}  {phi_s:.3f}   "
                      f"{mean:.3f} ({low:.3f}-{high:.3f})   {inner:.3f}",
                      flush=True)


if __name__ == "__main__":
    main()
