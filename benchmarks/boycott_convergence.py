#!/usr/bin/env python3
"""Mesh, time-step and seed study of Lethe's sedimentation scene
(benchmarks/boycott_small.prm, doc/performance.md "Against Lethe").

The scene's figure is the grains' mean vertical velocity at t = 0.25 s.
Each row runs the scene with `Mesh/Subdivisions`, `Time step` and the
placement's `Random seed` changed and prints that velocity, the wall time
of the run (its last `wall_time`), the fluid steps and the mean FGMRES
iterations per step. The seeds show how far the figure moves with the
grains' random placement alone, the yardstick for the mesh and step
differences.

Usage (after scripts/setup.sh):
    benchmarks/boycott_convergence.py [--cells 4,5,7,10] [--steps 0.005]
        [--seeds 1] [--ranks N] [--filter L] [--out DIR]
--cells lists the subdivisions across (the height gets five times as many);
the box is 20 grain diameters across, so 5 cells are cells of 4 diameters.
--filter L runs the drag filtered over L metres (Drag distribution =
filtered) instead of the scene's cell spread.
"""
import argparse
import os
import re

import scene_runner  # noqa: E402 (beside this script)

ROOT = scene_runner.ROOT
SCENE = os.path.join(ROOT, "benchmarks", "boycott_small.prm")
DIAMETERS_ACROSS = 20  # 0.04 m across, grains of 2 mm


def scene_text(cells, step, seed, filter_length=0):
    text = open(SCENE).read()
    if filter_length > 0:
        text += ("subsection Coupling\n  set Drag distribution = filtered\n"
                 "  set Smoothing length = %g\nend\n" % filter_length)
    text = re.sub(r"(?m)^(\s*set Subdivisions\s*=).*$",
                  r"\g<1> %d, %d, %d" % (cells, 5 * cells, cells), text)
    text = re.sub(r"(?m)^(set Time step\s*=).*$", r"\g<1> %g" % step, text)
    text = re.sub(r"(?m)^(\s*set Random seed\s*=).*$",
                  r"\g<1> %d" % seed, text)
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cells", default="5,10",
                        help="subdivisions across, comma separated")
    parser.add_argument("--steps", default="0.005",
                        help="time steps [s], comma separated")
    parser.add_argument("--seeds", default="1",
                        help="placement seeds, comma separated")
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--filter", type=float, default=0,
                        help="the filtered drag over this length [m] "
                        "instead of the cell spread")
    parser.add_argument("--out", default=os.path.join(
        ROOT, "benchmarks", "results", "boycott_convergence"))
    args = parser.parse_args()

    print("| cells across (cell / d) | time step | seed | mean v_y at "
          "0.25 s (cm/s) | fluid steps | FGMRES per step | wall (s) |")
    print("|---|---|---|---|---|---|---|")
    for cells in [int(c) for c in args.cells.split(",")]:
        for step in [float(s) for s in args.steps.split(",")]:
            for seed in [int(s) for s in args.seeds.split(",")]:
                directory = os.path.join(
                    args.out, "c%d_dt%g_s%d%s" % (
                        cells, step, seed,
                        "_l%g" % args.filter if args.filter else ""))
                rows = scene_runner.run_scene(
                    scene_text(cells, step, seed, args.filter), directory,
                    args.ranks)
                last = rows[-1]
                steps = len(rows) - 1
                iterations = sum(float(r["fluid_iterations"])
                                 for r in rows[1:]) / max(steps, 1)
                print("| %d (%.2g) | %g ms | %d | %.4f | %d | %.1f | %.1f |" % (
                    cells, DIAMETERS_ACROSS / cells, step * 1e3, seed,
                    100 * float(last["mean_velocity_y"]), steps, iterations,
                    float(last["wall_time"])), flush=True)


if __name__ == "__main__":
    main()
