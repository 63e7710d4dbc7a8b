#!/usr/bin/env python3
"""What physics a scene switches off saves, per step (doc/performance.md).

Runs Lethe's scene (benchmarks/boycott_small.prm) for 10 fluid steps as it
is (Navier-Stokes), with `Fluid/Advection = false` (Stokes) and without
grains, and prints the mean milliseconds per step of the assembly, the
solve and the whole step over steps 3-10 (the first two build the
preconditioner), with the assembly's microseconds per cell.

Usage (after scripts/setup.sh, about a minute):
    /usr/bin/python3 benchmarks/run_physics_off.py [--out DIR]
"""
import argparse
import os
import re

import scene_runner  # noqa: E402 (beside this script)

ROOT = scene_runner.ROOT


def variants(scene):
    scene = scene.replace("set End time  = 0.25", "set End time = 0.05")
    stokes = scene.replace("set Advection = true", "set Advection = false")
    # Without grains: no Grains and no Contacts section (an entry of either
    # with grains off is an input error).
    dry = re.sub(r"subsection Grains.*?\nend\n\nsubsection Contacts.*?\nend\n",
                 "", scene, flags=re.S)
    assert stokes != scene and dry != scene
    return {"navier-stokes": scene, "stokes": stokes, "no grains": dry}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=os.path.join(
        ROOT, "benchmarks", "results", "physics_off"))
    args = parser.parse_args()
    scene = open(os.path.join(ROOT, "benchmarks", "boycott_small.prm")).read()
    print("| variant | assembly ms | µs per cell | solve ms | step ms |")
    print("|---|---|---|---|---|")
    for name, text in variants(scene).items():
        directory = os.path.join(args.out, name.replace(" ", "_"))
        stats = scene_runner.run_scene(text, directory)
        rows = scene_runner.read_csv(
            os.path.join(directory, "timings.csv"))[3:]
        mean = {k: 1e3 * sum(float(r[k]) for r in rows) / len(rows)
                for k in ("assembly", "solve", "total")}
        cells = float(stats[-1]["cells"])
        print("| %s | %.0f | %.0f | %.0f | %.0f |" % (
            name, mean["assembly"], 1e3 * mean["assembly"] / cells,
            mean["solve"], mean["total"]))


if __name__ == "__main__":
    main()
