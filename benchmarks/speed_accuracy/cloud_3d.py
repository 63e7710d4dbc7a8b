#!/usr/bin/python3
"""Speed against accuracy on the 3D falling cloud, reduced
(doc/speed-accuracy.md): prm/falling_cloud_3d.prm with a smaller cloud
(radius SIZE instead of 0.5 mm, so about a fifth of the beads) run to
t = END under a set of strategies, each changing one choice of the scene,
against a reference run at the finest setting. Writes a table (markdown)
and a PNG of error against wall time with the Pareto front.

    benchmarks/speed_accuracy/cloud_3d.py [--end 0.1] [--size 3e-4]
        [--only NAME,...] [--out DIR] [--plot-only]

Error: the cloud's centroid at END against the reference's, as a
percentage of the distance the reference fell; and the cloud's horizontal
extent (radius of gyration across the fall) against the reference's, in
percent. END lies in the compact stage, long before the torus (doc/scenes/
falling_cloud_3d.md): the fall and the spreading are the figures a
strategy should keep. About 40 minutes on one core, most of it the
reference.
"""
import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)
from pareto import plot_pareto  # noqa: E402
from run import override  # noqa: E402
from scene_runner import ROOT, read_csv, run_scene  # noqa: E402

SCENE = os.path.join(ROOT, "prm", "falling_cloud_3d.prm")
WORK = os.path.join(ROOT, "benchmarks", "results", "speed_accuracy_cloud_3d")

# name: (what it changes, overrides). The default is the reduced scene.
STRATEGIES = {
    "reference": ("Courant 0.025, Max level 5, tolerance 1e-8",
                  [("", "Courant number", 0.025),
                   ("Adaptivity", "Max level", 5),
                   ("Fluid/Linear solver", "Tolerance", 1e-8)]),
    "default": ("the scene as shipped (Courant 0.1, Max level 4, BDF2, "
                "extrapolated advection, filtered drag, tolerance 1e-6)", []),
    "courant_0.5": ("Courant number 0.5", [("", "Courant number", 0.5)]),
    "courant_0.25": ("Courant number 0.25", [("", "Courant number", 0.25)]),
    "courant_0.05": ("Courant number 0.05", [("", "Courant number", 0.05)]),
    "grains_rule": ("no grain sub-steps: the fluid step follows the grains "
                    "(r/8 per step)",
                    [("Coupling", "Grain sub-steps", "false")]),
    "max_level_3": ("Adaptivity/Max level 3", [("Adaptivity", "Max level", 3)]),
    "max_level_5": ("Adaptivity/Max level 5", [("Adaptivity", "Max level", 5)]),
    "tolerance_1e-4": ("Fluid/Linear solver/Tolerance 1e-4",
                       [("Fluid/Linear solver", "Tolerance", 1e-4)]),
    "tolerance_1e-8": ("Fluid/Linear solver/Tolerance 1e-8",
                       [("Fluid/Linear solver", "Tolerance", 1e-8)]),
    "bdf1": ("Fluid/Time scheme BDF1", [("Fluid", "Time scheme", "BDF1")]),
    "stokes": ("Fluid/Advection false (Stokes)",
               [("Fluid", "Advection", "false")]),
    "smoothing_2e-4": ("Coupling/Smoothing length 2e-4 m (the scene: 1e-4 m)",
                       [("Coupling", "Smoothing length", 2e-4)]),
    "cell_drag": ("Coupling/Drag distribution cell, with the "
                  "self-disturbance correction (the code's 3D default; the "
                  "scene: filtered)",
                  [("Coupling", "Drag distribution", "cell")]),
}


def run(name, end, size):
    description, changes = STRATEGIES[name]
    text = open(SCENE).read()
    text += override("", "End time", end)
    text += override("Output", "Write fields every", 0)
    text += override("Grains/Placement", "Size", size)
    for section, entry, value in changes:
        text += override(section, entry, value)
    directory = os.path.join(WORK, name)
    start = time.time()
    rows = run_scene(text, directory)
    wall = time.time() - start
    last = rows[-1]
    timings = read_csv(os.path.join(directory, "timings.csv"))
    setup = float(timings[0]["total"]) if timings else 0.0
    return dict(name=name, description=description, wall=wall,
                run=wall - setup, steps=len(rows) - 1,
                grains=int(float(last["particles"])),
                z0=float(rows[0]["cloud_centroid_z"]),
                x=float(last["cloud_centroid_x"]),
                y=float(last["cloud_centroid_y"]),
                z=float(last["cloud_centroid_z"]),
                width=float(last["cloud_extent_x"]),
                time=float(last["time"]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end", type=float, default=0.1)
    parser.add_argument("--size", type=float, default=3e-4)
    parser.add_argument("--only", default="")
    parser.add_argument("--out", default=WORK)
    parser.add_argument("--plot-only", action="store_true",
                        help="redraw the table and figure from results.json")
    args = parser.parse_args()
    names = args.only.split(",") if args.only else list(STRATEGIES)
    if "reference" not in names:
        names = ["reference"] + names
    os.makedirs(args.out, exist_ok=True)
    saved = os.path.join(args.out, "results.json")
    if args.plot_only:
        results = json.load(open(saved))
    else:
        results = []
        for name in names:
            results.append(run(name, args.end, args.size))
            print("ran %-16s %6.1f s" % (name, results[-1]["wall"]), flush=True)
            json.dump(results, open(saved, "w"), indent=1)
    reference = results[0]
    fallen = reference["z0"] - reference["z"]
    lines = ["| strategy | change | fluid steps | wall time after set-up s | "
             "centroid error, % of the fall | width error % |",
             "|---|---|---|---|---|---|"]
    for r in results:
        d = [r[k] - reference[k] for k in ("x", "y", "z")]
        r["error"] = 100 * sum(c * c for c in d) ** 0.5 / fallen
        r["width_error"] = 100 * (r["width"] / reference["width"] - 1)
        lines.append("| %s | %s | %d | %.1f | %s | %s |" % (
            r["name"], r["description"], r["steps"], r["run"],
            "—" if r is reference else "%.3f" % r["error"],
            "—" if r is reference else "%+.2f" % r["width_error"]))
    lines.append("")
    lines.append("Reference: %d beads; the cloud fell %.4f mm by t = %.3f s, "
                 "horizontal extent %.4f mm." % (
                     reference["grains"], 1e3 * fallen, reference["time"],
                     1e3 * reference["width"]))
    table = "\n".join(lines) + "\n"
    print(table)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table)
    plot_pareto(results, reference["run"],
                os.path.join(args.out, "speed_accuracy_cloud_3d.png"),
                "3D falling cloud (reduced) to t = %.2f s: error against cost"
                % reference["time"],
                "centroid error [% of the distance fallen]")


if __name__ == "__main__":
    main()
