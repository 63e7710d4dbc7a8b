#!/usr/bin/python3
"""A lone seed bead (or disc) settling two-way coupled in a closed box of
CELLS cells per side, cells of H grain diameters, steady Stokes fluid:
prints the terminal velocity over the closure's, U = V_s/0.96 (3D) or the
disc's V_1 (2D), with and without Coupling/Self-disturbance correction.

    benchmarks/self_disturbance/lone_grain.py DIM DISTRIBUTION L/D CELLS H[,H...]

DISTRIBUTION cell or filtered, L/D the filter length in diameters (0 for
cell). Example (doc/validation.md, "A grain's own disturbance"):

    benchmarks/self_disturbance/lone_grain.py 3 cell 0 16 16,8,4,2
"""
import csv
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXECUTABLE = os.path.join(ROOT, "build", "immersed-grains")
WORK = os.path.join(ROOT, "benchmarks", "results", "self_disturbance")


def run(dim, cell_diameters, distribution, filter_diameters, cells, correction):
    r = 12.5e-6
    d = 2 * r
    h = cell_diameters * d
    L = cells * h
    closure = 3.5482e-6 if dim == 3 else 4.1801e-6
    name = f"{dim}d_{distribution}_{filter_diameters:g}_{cells}_{cell_diameters:g}_{correction}"
    out = os.path.join(WORK, name)
    corner = ", ".join([f"{-L / 2}"] * dim)
    upper = ", ".join([f"{L / 2}"] * dim)
    # Off the cell's centre and off the box's axes.
    position = ", ".join([f"{0.1 * h}", f"{0.2 * h}", f"{0.3 * h}"][:dim])
    gravity = ", ".join(["0"] * (dim - 1) + ["-9.81"])
    smoothing = f"set Smoothing length = {filter_diameters * d}" if filter_diameters else ""
    scene = f"""set Output directory = {out}
set Dimension = {dim}
set End time  = 3.47
set Time step = 0.694
subsection Mesh
  set Lower corner = {corner}
  set Upper corner = {upper}
  set Subdivisions = {cells}
  set Initial refinement = 0
end
subsection Fluid
  set Density   = 1200
  set Viscosity = 0.12
  set Advection = false
  set Time derivative = false
end
subsection Coupling
  set Drag distribution = {distribution}
  set Self-disturbance correction = {correction}
  {smoothing}
end
subsection Grains
  set Enabled = true
  set Radius  = {r}
  set Density = 2400
  subsection Placement
    set Shape     = list
    set Positions = {position}
  end
end
subsection Gravity
  set Vector = {gravity}
end
subsection Output
  set Terminal output = quiet
end
"""
    os.makedirs(WORK, exist_ok=True)
    with open(out + ".prm", "w") as f:
        f.write(scene)
    subprocess.run([EXECUTABLE, out + ".prm"], check=True)
    rows = list(csv.DictReader(open(os.path.join(out, "statistics.csv"))))
    return -float(rows[-1]["mean_velocity_" + ("z" if dim == 3 else "y")]) / closure


def main():
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    dim, distribution = int(sys.argv[1]), sys.argv[2]
    filter_diameters, cells = float(sys.argv[3]), int(sys.argv[4])
    print("cell/d  U/closure without  with correction")
    for h in [float(x) for x in sys.argv[5].split(",")]:
        print("%6g  %8.4f  %8.4f" % (h,
              run(dim, h, distribution, filter_diameters, cells, "false"),
              run(dim, h, distribution, filter_diameters, cells, "true")), flush=True)


if __name__ == "__main__":
    main()
