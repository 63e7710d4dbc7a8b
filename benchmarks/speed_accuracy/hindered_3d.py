#!/usr/bin/python3
"""Speed against accuracy on 3D hindered settling (doc/speed-accuracy.md):
the suspension of tests/hindered_settling_3d_020 (3129 beads, phi_s = 0.2,
box 32 r x 32 r x 64 r, periodic sideways) under mesh sizes, drag
distributions, filter lengths, the self-disturbance correction and the
outer tolerance, against the closure's v = eps^4.8 / 0.96 V_s. Writes a
table and a PNG of error against wall time with the Pareto front.

    benchmarks/speed_accuracy/hindered_3d.py [--out DIR] [--plot-only]

The analytical value assumes an unbounded suspension; the box is small
(32 r wide, periodic), which moves the corrected runs by a few percent
(doc/validation.md, "A grain's own disturbance").
"""
import argparse
import importlib.util
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)
from pareto import plot_pareto  # noqa: E402
from scene_runner import ROOT, read_csv, run_scene  # noqa: E402

spec = importlib.util.spec_from_file_location(
    "stability", os.path.join(os.path.dirname(HERE), "stability", "run.py"))
stability = importlib.util.module_from_spec(spec)
spec.loader.exec_module(stability)

WORK = os.path.join(ROOT, "benchmarks", "results", "speed_accuracy_hindered_3d")
R = 12.5e-6

# name: (what it changes, parameter text appended to the scene). The
# default is the test's scene: filtered drag, l = 8 r, cells of 8 r.
STRATEGIES = {
    "default": ("filtered drag, l = 8 r, cells of 8 r (the test's scene)", ""),
    "cells_16r": ("cells of 16 r", "subsection Mesh\n  set Initial refinement = 0\nend\n"),
    "cells_4r": ("cells of 4 r", "subsection Mesh\n  set Initial refinement = 2\nend\n"),
    "l_4r": ("filter length 4 r", "subsection Coupling\n  set Smoothing length = %g\nend\n" % (4 * R)),
    "l_16r": ("filter length 16 r", "subsection Coupling\n  set Smoothing length = %g\nend\n" % (16 * R)),
    "corrected": ("filtered, l = 8 r, with the self-disturbance correction",
                  "subsection Coupling\n  set Self-disturbance correction = true\nend\n"),
    "cell_spread": ("drag spread over the cell, no smoothing, no correction",
                    "subsection Coupling\n  set Drag distribution = cell\n  set Smoothing length = 0\n"
                    "  set Self-disturbance correction = false\nend\n"),
    "cell_spread_l": ("drag spread over the cell, solid fraction smoothed with l = 8 r, no correction",
                      "subsection Coupling\n  set Drag distribution = cell\n"
                      "  set Self-disturbance correction = false\nend\n"),
    "cell_corrected": ("drag spread over the cell, no smoothing, with the self-disturbance correction (the 3D default)",
                       "subsection Coupling\n  set Drag distribution = cell\n  set Smoothing length = 0\nend\n"),
    "tolerance_1e-6": ("outer tolerance 1e-6 (the default; the study runs 1e-10)",
                       "subsection Fluid\n  subsection Linear solver\n    set Tolerance = 1e-6\n  end\nend\n"),
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=WORK)
    parser.add_argument("--plot-only", action="store_true")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    saved = os.path.join(args.out, "results.json")
    text, exact, _ = stability.suspension(3, 0.2)
    if args.plot_only:
        results = json.load(open(saved))
    else:
        results = []
        for name, (description, change) in STRATEGIES.items():
            directory = os.path.join(args.out, name)
            start = time.time()
            rows = run_scene(text + change, directory)
            wall = time.time() - start
            setup = float(read_csv(os.path.join(directory, "timings.csv"))[0]["total"])
            v = float(rows[-1]["mean_velocity_z"])
            results.append(dict(name=name, description=description,
                                run=wall - setup, ratio=v / exact,
                                error=100 * abs(v / exact - 1)))
            print("ran %-16s %6.1f s  v/closure %.4f" % (name, wall, v / exact),
                  flush=True)
        json.dump(results, open(saved, "w"), indent=1)
    lines = ["| strategy | change | wall time after set-up s | v / closure |",
             "|---|---|---|---|"]
    for r in results:
        lines.append("| %s | %s | %.1f | %.4f |" % (r["name"], r["description"],
                                                    r["run"], r["ratio"]))
    table = "\n".join(lines) + "\n"
    print(table)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table)
    plot_pareto(results, 0, os.path.join(args.out, "speed_accuracy_hindered_3d.png"),
                "3D hindered settling, phi_s = 0.2: error against cost",
                "|v / closure - 1| [%]")


if __name__ == "__main__":
    main()
