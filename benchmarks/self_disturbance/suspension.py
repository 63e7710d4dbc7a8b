#!/usr/bin/python3
"""Hindered settling of a random suspension: the seed's beads or discs
(r = 12.5 um, rho_p = 2400) in glycerine (rho = 1200, mu = 0.12) fill a box
periodic sideways and closed above and below, placed at random
(Placement/Shape = box, seed 3, centres a radius clear of the floor and
the lid); steady Stokes, steps of 0.5 s. Prints the grains' mean vertical
velocity over the seed's closure, v = eps^4.8 V_s / 0.96 in 3D and
eps^4.8 V_1 in 2D (V_1 = 4.1801e-6 m/s, the lone disc under the seed's
law; doc/theory.md, "Hindered settling"), at the end and, for runs of 6 s,
its mean and range over t = 3-6 s; in 3D without and with
Coupling/Self-disturbance correction (doc/validation.md).

    benchmarks/self_disturbance/suspension.py DIM DISTRIBUTION L H BOX PHI[,PHI...] [END]

DISTRIBUTION filtered or cell, L the filter length in radii (0 for the
cell spread without filter), H the cell size in radii, BOX the box in radii
(WxZ or WxWxZ), PHI the solid fractions, END the end time in s (3 unless
given). Examples (doc/validation.md):

    benchmarks/self_disturbance/suspension.py 3 cell 0 8 64x64x64 0.05,0.1,0.2
    benchmarks/self_disturbance/suspension.py 3 filtered 8 8 32x32x64 0.1
    benchmarks/self_disturbance/suspension.py 2 filtered 64 8 128x128 0.1 6

IMMERSED_GRAINS_BUILD runs another build (benchmarks/scene_runner.py).
A 3D run takes 5 s (6,260 grains on cells of 8 r, 3 s) to a few minutes.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import scene_runner  # noqa: E402 (benchmarks/)

WORK = os.path.join(scene_runner.ROOT, "benchmarks", "results",
                    "self_disturbance_suspension")
R = 12.5e-6
V_STOKES = 2 * (2400 - 1200) * 9.81 * R * R / (9 * 0.12)
V_DISC = 4.1801e-6


def run(dim, distribution, length, h, box, phi, correction, end):
    size = [w * R for w in box]
    volume = math.prod(size)
    grain = math.pi * R * R if dim == 2 else 4 / 3 * math.pi * R ** 3
    count = round(phi * volume / grain)
    phi = count * grain / volume
    subdivisions = [int(round(w / (2 * h))) for w in box]
    zeros = ", ".join(["0"] * dim)
    faces = ", ".join(["periodic"] * (2 * dim - 2) + ["wall", "wall"])
    centre = ", ".join(f"{s / 2}" for s in size)
    region = ", ".join(f"{s}" for s in size[:-1] + [size[-1] - 2 * R])
    gravity = ", ".join(["0"] * (dim - 1) + ["-9.81"])
    scene = f"""set Dimension = {dim}
set End time  = {end}
set Time step = 0.5
subsection Mesh
  set Lower corner = {zeros}
  set Upper corner = {", ".join(f"{s}" for s in size)}
  set Subdivisions = {", ".join(str(s) for s in subdivisions)}
  set Initial refinement = 1
  set Boundary conditions = {faces}
end
subsection Fluid
  set Density   = 1200
  set Viscosity = 0.12
  set Advection = false
  set Time derivative = false
end
subsection Grains
  set Enabled = true
  set Radius  = {R}
  set Density = 2400
  subsection Placement
    set Shape  = box
    set Center = {centre}
    set Size   = {region}
    set Count  = {count}
    set Random seed = 3
  end
end
subsection Coupling
  set Drag distribution = {distribution}
  set Smoothing length  = {length * R}
  set Self-disturbance correction = {correction}
end
subsection Gravity
  set Vector = {gravity}
end
"""
    name = (f"{dim}d_{distribution}_l{length:g}_h{h:g}_"
            f"{'x'.join(str(w) for w in box)}_{phi:.3f}_{correction}_{end:g}")
    rows = scene_runner.run_scene(scene, os.path.join(WORK, name))
    single = V_DISC if dim == 2 else V_STOKES / 0.96
    closure = -(1 - phi) ** 4.8 * single
    axis = "mean_velocity_" + "xyz"[dim - 1]
    late = [float(r[axis]) / closure for r in rows if float(r["time"]) >= 3]
    return count, phi, late


def main():
    if len(sys.argv) not in (7, 8) or sys.argv[2] not in ("filtered", "cell"):
        sys.exit(__doc__)
    dim, distribution = int(sys.argv[1]), sys.argv[2]
    length, h = float(sys.argv[3]), float(sys.argv[4])
    box = [int(w) for w in sys.argv[5].split("x")]
    end = float(sys.argv[7]) if len(sys.argv) == 8 else 3.0
    corrections = ["false"] if dim == 2 else ["false", "true"]
    print(f"{dim}D, {distribution}, l = {length:g} r, cells of {h:g} r, "
          f"box {sys.argv[5]} r, {end:g} s; v/closure at the end"
          + (", mean over t = 3-6 s (range)" if end >= 6 else ""))
    print("phi_s   grains   " + "   ".join(
        ("with the correction" if c == "true" else "without")
        for c in corrections))
    for phi in (float(p) for p in sys.argv[6].split(",")):
        cells = []
        for correction in corrections:
            count, phi_s, late = run(dim, distribution, length, h, box, phi,
                                     correction, end)
            cell = f"{late[-1]:.4f}"
            if end >= 6:
                cell += (f" {sum(late) / len(late):.4f} "
                         f"({min(late):.3f}-{max(late):.3f})")
            cells.append(cell)
        print(f"{phi_s:.3f}   {count:6d}   " + "   ".join(cells), flush=True)


if __name__ == "__main__":
    main()
