#!/usr/bin/python3
"""Speed against accuracy for a lone bead in 3D (doc/speed-accuracy.md):
the seed's bead settling in a closed box 64 diameters wide, steady Stokes,
on cells of 16, 8, 4 and 2 diameters, with the drag spread over the cell
(the default), the same with the self-disturbance correction, and the
filtered drag with l = 4 diameters (8 radii). Error: the terminal velocity
against the seed's closure. Writes a table and a PNG of error against
wall time with the Pareto front.

    benchmarks/speed_accuracy/lone_grain_3d.py [--out DIR] [--plot-only]

The box's walls slow the bead by several percent: the corrected runs
read 0.95-0.96 at every cell size (doc/validation.md, "A grain's own
disturbance", has the same in a box half as wide), and the uncorrected
runs' excess over that is their own disturbance.
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

WORK = os.path.join(ROOT, "benchmarks", "results", "speed_accuracy_lone_grain_3d")
BOX_DIAMETERS = 64


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=WORK)
    parser.add_argument("--plot-only", action="store_true")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    saved = os.path.join(args.out, "results.json")
    if args.plot_only:
        results = json.load(open(saved))
    else:
        results = []
        for h in [16, 8, 4, 2]:
            for kind, options in [("cell", {"correction": False}),
                                  ("cell+correction", {"correction": True}),
                                  ("filtered", {"smoothing_diameters": 4})]:
                name = f"{kind}_{h}d"
                text, exact, _ = stability.lone_grain(
                    3, cell_diameters=h, cells=BOX_DIAMETERS // h, **options)
                directory = os.path.join(args.out, name)
                start = time.time()
                rows = run_scene(text, directory)
                wall = time.time() - start
                setup = float(read_csv(os.path.join(directory, "timings.csv"))[0]["total"])
                v = float(rows[-1]["mean_velocity_z"])
                results.append(dict(name=name, run=wall - setup, ratio=v / exact,
                                    error=100 * abs(v / exact - 1),
                                    default=(kind == "cell" and h == 8)))
                print("ran %-22s %6.1f s  v/closure %.4f" % (name, wall, v / exact),
                      flush=True)
        json.dump(results, open(saved, "w"), indent=1)
    lines = ["| distribution, cell | wall time after set-up s | v / closure |",
             "|---|---|---|"]
    for r in results:
        lines.append("| %s | %.1f | %.4f |" % (r["name"], r["run"], r["ratio"]))
    table = "\n".join(lines) + "\n"
    print(table)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table)
    plot_pareto(results, 0, os.path.join(args.out, "speed_accuracy_lone_grain_3d.png"),
                "3D lone bead, box of 64 diameters: error against cost",
                "|v / closure - 1| [%]")


if __name__ == "__main__":
    main()
