#!/usr/bin/python3
"""Cost per grain and memory per grain from a thousand to a million grains
(doc/performance.md, "A million grains").

Runs the settling suspension of benchmarks/step/suspension_3d_million.prm
(glass beads at solid fraction 0.1 in glycerine, periodic sideways, Stokes,
three fluid steps of 0.5 s) scaled to N grains: the cube's side is set so
that the fraction stays 0.1, the cells stay about 0.2 mm (16 radii, an even
number of them along each edge). Each run under /usr/bin/time; prints one row
per N:

- cells, DoFs, grain sub-steps per fluid step, the fastest grain (m/s),
  contact sweeps per sub-step;
- microseconds per grain and sub-step of the grains' phases: interaction
  force (drag and the fields at the grains), contacts (search, solve),
  gather + free velocities + move and sort;
- milliseconds per fluid step of the fluid's phases (assembly,
  preconditioner, solve, solid fraction);
- wall seconds per fluid step, the set-up (placement, first output), peak
  resident memory and the log's estimate.

    benchmarks/suspension/run.py [--ranks R] [--figure] [N ...]
        (default N = 1000 10000 100000; 1000000 takes about 3 minutes and
        3 GB on one core)

With --figure, draws doc/figures/suspension_3d_million.png from the last
state of the largest N's run: the grains in two vertical slabs, through
the middle of the cube and along a periodic face, coloured by their
vertical velocity.

Needs build/immersed-grains, python3-numpy and python3-matplotlib.
"""
import argparse
import csv
import math
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "benchmarks", "step", "suspension_3d_million.prm")
WORK = os.path.join(ROOT, "benchmarks", "results", "suspension")
RADIUS = 12.5e-6
FRACTION = 0.1
CELL = 2e-4


def scene(n):
    """The million-grain scene with N grains at the same fraction and
    about the same cell size."""
    side = (n * 4 / 3 * math.pi * RADIUS ** 3 / FRACTION) ** (1 / 3)
    cells = 2 * max(1, round(side / (2 * CELL)))
    text = open(SCENE).read()
    corner = ", ".join(["%.6g" % side] * 3)
    centre = ", ".join(["%.6g" % (side / 2)] * 3)
    subs = ", ".join(["%d" % (cells // 2)] * 3)
    for name, value in (("Upper corner", corner), ("Center", centre),
                        ("Size", corner), ("Subdivisions", subs),
                        ("Initial refinement", "1"), ("Count", str(n))):
        text, count = re.subn(r"(set %s\s*=).*" % name, r"\1 " + value, text)
        assert count == 1, name
    return text


def run(n, ranks):
    directory = os.path.join(WORK, "n%d_np%d" % (n, ranks))
    os.makedirs(directory, exist_ok=True)
    prm = os.path.join(directory, "scene.prm")
    with open(prm, "w") as f:
        f.write(scene(n))
        f.write("\nset Output directory = %s\n" % directory)
    command = ["/usr/bin/time", "-f", "peak %M KB",
               os.path.join(ROOT, "build", "immersed-grains"), prm]
    if ranks > 1:
        command[3:3] = ["mpirun", "-np", str(ranks)]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1",
               DEAL_II_NUM_THREADS="1", OMP_NUM_THREADS="1")
    result = subprocess.run(command, env=env, capture_output=True, text=True,
                            check=True)
    log = result.stdout + result.stderr
    # /usr/bin/time sees mpirun and the largest of its children: one rank.
    peak = float(re.findall(r"peak (\d+) KB", log)[-1]) / 1024
    estimate = float(re.search(r"peak memory about ([0-9.]+) GiB",
                               log).group(1)) * 1024
    with open(os.path.join(directory, "statistics.csv")) as f:
        stats = list(csv.DictReader(f))[1:]
    with open(os.path.join(directory, "timings.csv")) as f:
        timings = list(csv.DictReader(f))
    setup = sum(float(timings[0][k]) for k in ("setup", "output", "other",
                                                "solid_fraction"))
    steps = timings[1:]

    def per_step(*phases):
        return sum(float(r[p]) for r in steps for p in phases) / len(steps)

    substeps = sum(float(r["grain_substeps"]) for r in stats) / len(stats)
    grain_substeps = n * substeps
    return {
        "N": n,
        "cells": int(float(stats[-1]["cells"])),
        "dofs": int(float(stats[-1]["dofs"])),
        "substeps": substeps,
        "fastest": max(float(r["max_speed"]) for r in stats),
        "sweeps": sum(float(r["contact_iterations"]) for r in stats)
                  / (len(stats) * substeps),
        "force_us": 1e6 * per_step("interaction_force") / grain_substeps,
        "contacts_us": 1e6 * per_step("contacts") / grain_substeps,
        "move_us": 1e6 * per_step("grain_velocities", "sort") / grain_substeps,
        "fluid_ms": 1e3 * per_step("assembly", "preconditioner", "solve",
                                   "solid_fraction"),
        "step_s": per_step("total"),
        "setup_s": setup,
        "peak_MB": peak,
        "estimate_MB": estimate,
    }


def draw(n, ranks):
    """The two slabs of the figure, from the run of N grains."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    import plot_scene
    directory = os.path.join(WORK, "n%d_np%d" % (n, ranks))
    t, x, fields = plot_scene.particle_states(directory, "run.py",
                                              ["velocity"])[-1]
    vz = fields["velocity"].reshape(len(x), -1)[:, -1]
    side = (n * 4 / 3 * math.pi * RADIUS ** 3 / FRACTION) ** (1 / 3)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    for ax, (y, name) in zip(axes, [(side / 2, "y = L/2, through the middle"),
                                    (0.0, "y = 0, a periodic face")]):
        # Within 50 um of the plane, across the periodic face too.
        near = np.abs((x[:, 1] - y + side / 2) % side - side / 2) < 5e-5
        shown = ax.scatter(1e3 * x[near, 0], 1e3 * x[near, 2],
                           c=1e6 * vz[near], s=0.3, cmap="RdBu_r",
                           vmin=-60, vmax=60)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("z (mm)")
        ax.set_title("slab at " + name, fontsize=10)
    fig.colorbar(shown, ax=axes, label="vertical velocity (um/s)")
    fig.suptitle("%d beads at solid fraction %.1f, t = %.1f s, mean "
                 "vertical velocity %.1f um/s" % (n, FRACTION, t,
                                                  1e6 * vz.mean()))
    out = os.path.join(ROOT, "doc", "figures", "suspension_3d_million.png")
    fig.savefig(out, dpi=110)
    print("wrote " + out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--figure", action="store_true")
    parser.add_argument("counts", nargs="*", type=int,
                        default=[1000, 10000, 100000])
    args = parser.parse_args()
    columns = ["N", "cells", "dofs", "substeps", "fastest", "sweeps",
               "force_us", "contacts_us", "move_us", "fluid_ms", "step_s",
               "setup_s", "peak_MB", "estimate_MB"]
    print("| " + " | ".join(columns) + " |")
    print("|---" * len(columns) + "|")
    for n in args.counts:
        r = run(n, args.ranks)
        print("| " + " | ".join(("%d" % r[c]) if isinstance(r[c], int)
                                else ("%.3g" % r[c]) for c in columns) + " |",
              flush=True)
    print("(%d rank(s); us per grain and sub-step, ms and s per fluid step;"
          " peak: the largest rank's)" % args.ranks)
    if args.figure:
        draw(max(args.counts), args.ranks)


if __name__ == "__main__":
    main()
