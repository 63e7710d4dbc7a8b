#!/usr/bin/env python3
"""Cost of one coupled time step, phase by phase (doc/performance.md).

Runs the scenes in benchmarks/step/ with the built executable, reads each
run's timings.csv and statistics.csv, and prints wall milliseconds per fluid
step for every phase, the assembly's microseconds per cell, and the outer
solver iterations. With --compare FILE it flags every phase that is more
than 20 % (and 2 ms) slower than the figures in FILE (written earlier with
--save FILE), so that a change that slows a phase shows at once.

Scenes: cloud_2d, cloud_3d (the default), suspension_3d_million (10^6
grains, about 3 minutes and 3 GB; doc/performance.md, "A million
grains").

Usage (after scripts/setup.sh):
    benchmarks/run_step_benchmarks.py [--scenes cloud_2d cloud_3d]
        [--ranks N] [--save FILE] [--compare FILE] [--out DIR]
"""
import argparse
import json
import os
import sys

import scene_runner  # noqa: E402 (beside this script)

ROOT = scene_runner.ROOT
PHASES = ["assembly", "preconditioner", "solve", "solid_fraction",
          "interaction_force", "grain_velocities", "contacts", "sort",
          "statistics", "output", "other"]


def run_scene(name, ranks, out):
    scene = os.path.join(ROOT, "benchmarks", "step", name + ".prm")
    directory = os.path.join(out, name)
    stats = scene_runner.run_scene(open(scene).read(), directory, ranks)[1:]
    timings = scene_runner.read_csv(os.path.join(directory, "timings.csv"))[1:]
    steps = len(timings)
    result = {"steps": steps,
              "cells": int(float(stats[-1]["cells"])),
              "dofs": int(float(stats[-1]["dofs"])),
              "grains": int(float(stats[-1]["particles"])),
              "iterations": sum(float(r["fluid_iterations"])
                                for r in stats) / steps}
    for phase in PHASES + ["total"]:
        result[phase] = 1e3 * sum(float(r[phase]) for r in timings) / steps
    result["assembly_us_per_cell"] = 1e3 * result["assembly"] / result["cells"]
    result["total_us_per_dof"] = 1e3 * result["total"] / max(result["dofs"], 1)
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", nargs="+", default=["cloud_2d", "cloud_3d"])
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--out", default=os.path.join(ROOT, "benchmarks",
                                                      "results", "step"))
    parser.add_argument("--save")
    parser.add_argument("--compare")
    args = parser.parse_args()

    results = {name: run_scene(name, args.ranks, args.out)
               for name in args.scenes}
    columns = ["cells", "dofs", "grains", "iterations", "total"] + PHASES + [
        "assembly_us_per_cell", "total_us_per_dof"]
    print("| scene | " + " | ".join(columns) + " |")
    print("|---" * (len(columns) + 1) + "|")
    for name, r in results.items():
        print("| %s | " % name + " | ".join(
            ("%d" % r[c]) if isinstance(r[c], int) else ("%.3g" % r[c])
            for c in columns) + " |")
    print("(ms per fluid step unless named otherwise; %d rank(s))" % args.ranks)

    if args.save:
        with open(args.save, "w") as f:
            json.dump(results, f, indent=1, sort_keys=True)
    if args.compare:
        baseline = json.load(open(args.compare))
        slower = []
        for name, r in results.items():
            for phase in PHASES + ["total"]:
                before = baseline.get(name, {}).get(phase)
                if before is not None and r[phase] > 1.2 * before + 2:
                    slower.append("%s %s: %.1f ms, was %.1f ms"
                                  % (name, phase, r[phase], before))
        for line in slower:
            print("slower: " + line)
        if slower:
            sys.exit(1)


if __name__ == "__main__":
    main()
