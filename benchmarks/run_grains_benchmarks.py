#!/usr/bin/env python3
"""Grain-step benchmark through the executable (doc/benchmarks.md, section
"Grains").

A dense resting bed of N grains (r = 1 mm, glass density) on a square
(cubic) lattice of touching grains in a closed box under gravity, e = 0,
contact tolerance 1e-4, stepped 4 times at dt = 1e-4 s (the first step
starts without warm start and is included). Reports per run: contacts, Gauss-Seidel
sweeps per step, time per step per grain (whole grain step: gather, free
velocities, contacts, move and sort), contact updates per second in the
contact phase (active contacts x sweeps / time of "grains: contacts", which
also holds the neighbour search and solver setup: a lower bound), and the split of the step.

Usage: benchmarks/run_grains_benchmarks.py [BUILD_DIR] [N ...]
       (default: build, N = 1000 10000 100000, 2D and 3D)
Neighbour-search scaling alone: build/benchmarks/contact_throughput.
"""
import csv
import math
import os
import re
import subprocess
import sys
import tempfile

build = sys.argv[1] if len(sys.argv) > 1 else "build"
sizes = [int(n) for n in sys.argv[2:]] or [1000, 10000, 100000]
executable = os.path.join(build, "immersed-grains")
steps = 4
r = 1e-3


def scene(dim, n, directory):
    side = math.ceil(n ** (1 / dim))
    extent = [2 * r * side] * dim
    extent[-1] = 2 * r * math.ceil(n / side ** (dim - 1))
    upper = ", ".join("%.9g" % (e * 1.0) for e in extent)
    center = ", ".join("%.9g" % (e / 2) for e in extent)
    size = ", ".join("%.9g" % e for e in extent)
    gravity = "0, -9.81" if dim == 2 else "0, 0, -9.81"
    return f"""set Dimension = {dim}
set Output directory = {directory}
set End time = {steps * 1e-4 * (1 + 1e-9)}
set Time step = 1e-4
subsection Mesh
  set Lower corner = {"0, 0" if dim == 2 else "0, 0, 0"}
  set Upper corner = {upper}
  set Subdivisions = 4
  set Initial refinement = {3 if dim == 2 else 2}
end
subsection Fluid
  set Enabled = false
end
subsection Grains
  set Enabled = true
  set Radius = {r}
  set Density = 2500
  subsection Placement
    set Shape = lattice
    set Center = {center}
    set Size = {size}
    set Count = {n}
  end
end
subsection Contacts
  set Tolerance = 1e-4
end
subsection Gravity
  set Vector = {gravity}
end
subsection Output
  set Terminal output = quiet
  set Write fields every = 1000000
end
"""


def timer_sections(log):
    sections = {}
    for line in open(log):
        m = re.match(r"\|\s*([^|]+?)\s*\|\s*(\d+)\s*\|\s*([\d.e+-]+)s", line)
        if m:
            sections[m.group(1)] = float(m.group(3))
    return sections


print("| dim | N | contacts | sweeps/step | us/step/grain | contact updates/s "
      "| contacts % | gather+move+sort % |")
print("|---|---|---|---|---|---|---|---|")
for dim in (2, 3):
    for n in sizes:
        with tempfile.TemporaryDirectory() as tmp:
            prm = os.path.join(tmp, "bed.prm")
            out = os.path.join(tmp, "out")
            open(prm, "w").write(scene(dim, n, out))
            subprocess.run([executable, prm], check=True,
                           stdout=subprocess.DEVNULL)
            rows = list(csv.DictReader(open(os.path.join(out,
                                                         "statistics.csv"))))
            # All steps, the first (no warm start yet) included.
            timed = rows[1:]
            wall = float(rows[-1]["wall_time"]) - float(rows[0]["wall_time"])
            sweeps = sum(float(x["contact_iterations"]) for x in timed) / len(timed)
            contacts = sum(float(x["contacts"]) for x in timed) / len(timed)
            t = timer_sections(os.path.join(out, "log.txt"))
            contact_time = t.get("grains: contacts", 0)
            other = sum(t.get(k, 0) for k in ("grains: gather",
                                                "grains: move and sort",
                                                "grains: free velocities"))
            step_time = wall / len(timed)
            print("| %d | %d | %.3g | %.0f | %.3g | %.3g | %.0f | %.0f |" % (
                dim, n, contacts, sweeps, 1e6 * step_time / n,
                contacts * sweeps * len(timed) / max(contact_time, 1e-12),
                100 * contact_time / wall, 100 * other / wall))
            sys.stdout.flush()
