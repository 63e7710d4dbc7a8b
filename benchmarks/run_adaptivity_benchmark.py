#!/usr/bin/env python3
"""Adaptive against uniform mesh with the same finest cell (doc/adaptivity.md).

Runs each scene of benchmarks/adaptivity/ twice: as written (Adaptivity on)
and on the uniform mesh of its Max level (Adaptivity off, Initial
refinement = Max level). Prints cells, DoFs, fluid steps and wall time of
both, and the largest difference of the centroid's vertical position
between them over the run, as a share of the distance the cloud fell;
writes a PNG of both trajectories (and of the difference) beside the runs.

Usage (after scripts/setup.sh):
    /usr/bin/python3 benchmarks/run_adaptivity_benchmark.py
        [--scenes cloud_2d_adaptive cloud_3d_adaptive] [--ranks N]
        [--out DIR]
"""
import argparse
import os
import re

import scene_runner  # noqa: E402 (beside this script)

ROOT = scene_runner.ROOT


def run(prm_text, directory, ranks):
    rows = scene_runner.run_scene(prm_text, directory, ranks)
    # The vertical axis: y in 2D, z in 3D.
    vertical = "centroid_z" if re.search(r"set Dimension\s*=\s*3",
                                         prm_text) else "centroid_y"
    return {"time": [float(r["time"]) for r in rows],
            "y": [float(r[vertical]) for r in rows],
            "cells": [int(float(r["cells"])) for r in rows],
            "dofs": [int(float(r["dofs"])) for r in rows],
            "particles": int(float(rows[-1]["particles"])),
            "steps": len(rows) - 1,
            "wall": float(rows[-1]["wall_time"])}


def interpolate(t, times, values):
    for k in range(1, len(times)):
        if times[k] >= t:
            w = (t - times[k - 1]) / (times[k] - times[k - 1])
            return (1 - w) * values[k - 1] + w * values[k]
    return values[-1]


def uniform_version(text):
    max_level = re.search(r"set Max level\s*=\s*(\d+)", text).group(1)
    text = re.sub(r"(set Initial refinement\s*=\s*)\d+", r"\g<1>" + max_level,
                  text)
    return re.sub(r"(subsection Adaptivity.*?set Enabled\s*=\s*)true",
                  r"\g<1>false", text, flags=re.S)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", nargs="+", default=["cloud_2d_adaptive"])
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--out", default=os.path.join(ROOT, "output",
                                                      "adaptivity"))
    args = parser.parse_args()
    print("| scene | mesh | cells | DoFs | fluid steps | wall s | "
          "centroid difference, % of fall |")
    print("|---|---|---|---|---|---|---|")
    for scene in args.scenes:
        text = open(os.path.join(ROOT, "benchmarks", "adaptivity",
                                 scene + ".prm")).read()
        adaptive = run(text, os.path.join(args.out, scene), args.ranks)
        uniform = run(uniform_version(text),
                      os.path.join(args.out, scene + "_uniform"), args.ranks)
        fall = uniform["y"][0] - uniform["y"][-1]
        difference = max(abs(y - interpolate(t, uniform["time"],
                                              uniform["y"]))
                         for t, y in zip(adaptive["time"], adaptive["y"]))
        print("| %s | uniform | %d | %d | %d | %.1f | reference (fall %.3g mm)"
              " |" % (scene, uniform["cells"][-1], uniform["dofs"][-1],
                      uniform["steps"], uniform["wall"], 1e3 * fall))
        print("| %s | adaptive | %d-%d | %d-%d | %d | %.1f (%.1fx less) | "
              "%.2f |" % (scene, min(adaptive["cells"]),
                          max(adaptive["cells"]), min(adaptive["dofs"]),
                          max(adaptive["dofs"]), adaptive["steps"],
                          adaptive["wall"], uniform["wall"] / adaptive["wall"],
                          100 * difference / fall))
        assert adaptive["particles"] == uniform["particles"], "grains lost"
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            continue
        figure, axes = plt.subplots(figsize=(5, 3.5))
        axes.plot(uniform["time"], [1e3 * y for y in uniform["y"]],
                  label="uniform, %d cells" % uniform["cells"][-1])
        axes.plot(adaptive["time"], [1e3 * y for y in adaptive["y"]], "--",
                  label="adaptive, %d-%d cells" % (min(adaptive["cells"]),
                                                   max(adaptive["cells"])))
        axes.set_xlabel("t [s]")
        axes.set_ylabel("centroid height [mm]")
        axes.legend()
        picture = os.path.join(args.out, scene + "_trajectory.png")
        figure.savefig(picture, dpi=150, bbox_inches="tight")
        print("(%s)" % picture)


if __name__ == "__main__":
    main()
