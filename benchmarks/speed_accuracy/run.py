#!/usr/bin/python3
"""Speed against accuracy on the README's main scene (doc/speed-accuracy.md):
the seed's 2D cloud (prm/falling_cloud_2d.prm) run to t = END under a set
of strategies, each changing one choice of the scene's defaults, against a
reference run at the finest setting. Writes a table (markdown) and a PNG
of error against wall time with the Pareto front.

    benchmarks/speed_accuracy/run.py [--end 0.3] [--only NAME,...] [--out DIR]

Error: the cloud's centroid at END against the reference's, as a
percentage of the distance the reference fell; and the cloud's horizontal
extent (radius of gyration) against the reference's, in percent. END is
before the break-up (0.32 s), whose time is chaotic to a few
milliseconds (tests/cloud_breakup_2d.prm): the compact cloud's fall and
its spreading are the figures a strategy should keep.
"""
import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from scene_runner import ROOT, read_csv, run_scene  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pareto import plot_pareto  # noqa: E402

SCENE = os.path.join(ROOT, "prm", "falling_cloud_2d.prm")
WORK = os.path.join(ROOT, "benchmarks", "results", "speed_accuracy")


def override(section, entry, value):
    """Parameter text that sets @p entry in @p section ('' for the top
    level, 'A/B' for nested subsections); later settings win."""
    if not section:
        return f"set {entry} = {value}\n"
    parts = section.split("/")
    text = "".join(f"subsection {p}\n" for p in parts)
    text += f"  set {entry} = {value}\n"
    text += "end\n" * len(parts)
    return text


# name: (what it changes, overrides). The default is the scene as shipped.
STRATEGIES = {
    "reference": ("Courant 0.025, Max level 5, tolerance 1e-8",
                  [("", "Courant number", 0.025),
                   ("Adaptivity", "Max level", 5),
                   ("Fluid/Linear solver", "Tolerance", 1e-8)]),
    "default": ("the scene as shipped (Courant 0.1, Max level 4, band of "
                "one layer looking 2 cells ahead, BDF2, extrapolated "
                "advection, tolerance 1e-6)", []),
    "band_2": ("Adaptivity/Band lookahead 0, Band width 2 (the band without "
               "lookahead)",
               [("Adaptivity", "Band lookahead", 0),
                ("Adaptivity", "Band width", 2)]),
    "lookahead_4": ("Adaptivity/Band lookahead 4",
                    [("Adaptivity", "Band lookahead", 4)]),
    "courant_0.5": ("Courant number 0.5", [("", "Courant number", 0.5)]),
    "courant_0.25": ("Courant number 0.25", [("", "Courant number", 0.25)]),
    "courant_0.05": ("Courant number 0.05", [("", "Courant number", 0.05)]),
    "grains_rule": ("no grain sub-steps: the fluid step follows the grains "
                    "(r/8 per step)",
                    [("Coupling", "Grain sub-steps", "false")]),
    "max_level_3": ("Adaptivity/Max level 3", [("Adaptivity", "Max level", 3)]),
    "max_level_5": ("Adaptivity/Max level 5", [("Adaptivity", "Max level", 5)]),
    "uniform_4": ("a uniform mesh at level 4 (no adaptivity)",
                  [("Adaptivity", "Enabled", "false"),
                   ("Mesh", "Initial refinement", 4)]),
    "tolerance_1e-4": ("Fluid/Linear solver/Tolerance 1e-4",
                       [("Fluid/Linear solver", "Tolerance", 1e-4)]),
    "tolerance_1e-8": ("Fluid/Linear solver/Tolerance 1e-8",
                       [("Fluid/Linear solver", "Tolerance", 1e-8)]),
    "bdf1": ("Fluid/Time scheme BDF1", [("Fluid", "Time scheme", "BDF1")]),
    "picard": ("Fluid/Linearization Picard (iterated to the nonlinear "
               "tolerance)", [("Fluid", "Linearization", "Picard")]),
    "stokes": ("Fluid/Advection false (Stokes)",
               [("Fluid", "Advection", "false")]),
    "smoothing_0": ("Coupling/Smoothing length 0 (the scene: 1e-4 m)",
                    [("Coupling", "Smoothing length", 0)]),
    "smoothing_2e-4": ("Coupling/Smoothing length 2e-4 m",
                       [("Coupling", "Smoothing length", 2e-4)]),
    "filtered": ("Coupling/Drag distribution filtered (l = 1e-4 m)",
                 [("Coupling", "Drag distribution", "filtered")]),
}


def run(strategies, name, scene_text, work):
    """Runs strategy @p name on @p scene_text (the scene with its end time
    and output set) into WORK/name; returns its cost and the cloud's last
    centroid (the last axis vertical) and horizontal extent."""
    description, changes = strategies[name]
    text = scene_text
    for section, entry, value in changes:
        text += override(section, entry, value)
    directory = os.path.join(work, name)
    start = time.time()
    rows = run_scene(text, directory)
    wall = time.time() - start
    last = rows[-1]
    axes = [a for a in "xyz" if "cloud_centroid_" + a in last]
    timings = read_csv(os.path.join(directory, "timings.csv"))
    setup = float(timings[0]["total"]) if timings else 0.0
    return dict(name=name, description=description, wall=wall,
                run=wall - setup, steps=len(rows) - 1,
                grains=int(float(last["particles"])),
                start=[float(rows[0]["cloud_centroid_" + a]) for a in axes],
                centroid=[float(last["cloud_centroid_" + a]) for a in axes],
                width=float(last["cloud_extent_x"]),
                time=float(last["time"]))


def study(strategies, scene, work, figure, title, default_end, options=(),
          scene_changes=None):
    """The command line of a cloud study: runs the strategies (or redraws
    from results.json), writes the table and the Pareto figure. The error
    is the centroid's distance from the reference's in percent of the
    reference's vertical fall. @p options: more (flag, add_argument
    keywords); @p scene_changes(args): parameter text they add to the
    scene."""
    parser = argparse.ArgumentParser(description=title)
    parser.add_argument("--end", type=float, default=default_end)
    parser.add_argument("--only", default="")
    parser.add_argument("--out", default=work)
    parser.add_argument("--plot-only", action="store_true",
                        help="redraw the table and figure from results.json")
    for flag, keywords in options:
        parser.add_argument(flag, **keywords)
    args = parser.parse_args()
    names = args.only.split(",") if args.only else list(strategies)
    if "reference" not in names:
        names = ["reference"] + names
    os.makedirs(args.out, exist_ok=True)
    saved = os.path.join(args.out, "results.json")
    if args.plot_only:
        results = json.load(open(saved))
        for r in results:  # results files without centroid fields: the 2D layout
            if "centroid" not in r:
                r.update(start=[r["x"], r["y0"]], centroid=[r["x"], r["y"]],
                         grains=321)
    else:
        text = open(scene).read()
        text += override("", "End time", args.end)
        text += override("Output", "Write fields every", 0)
        if scene_changes:
            text += scene_changes(args)
        results = []
        for name in names:
            results.append(run(strategies, name, text, args.out))
            print("ran %-16s %6.1f s" % (name, results[-1]["wall"]), flush=True)
            json.dump(results, open(saved, "w"), indent=1)
    reference = results[0]
    fallen = reference["start"][-1] - reference["centroid"][-1]
    lines = ["| strategy | change | fluid steps | wall time after set-up s | "
             "centroid error, % of the fall | width error % |",
             "|---|---|---|---|---|---|"]
    for r in results:
        d = [a - b for a, b in zip(r["centroid"], reference["centroid"])]
        r["error"] = 100 * sum(c * c for c in d) ** 0.5 / fallen
        r["width_error"] = 100 * (r["width"] / reference["width"] - 1)
        lines.append("| %s | %s | %d | %.1f | %s | %s |" % (
            r["name"], r["description"], r["steps"], r["run"],
            "—" if r is reference else "%.3f" % r["error"],
            "—" if r is reference else "%+.2f" % r["width_error"]))
    lines.append("")
    lines.append("Reference: %d grains; the cloud fell %.4f mm by t = %.3f s, "
                 "horizontal extent %.4f mm." % (
                     reference["grains"], 1e3 * fallen, reference["time"],
                     1e3 * reference["width"]))
    table = "\n".join(lines) + "\n"
    print(table)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table)
    plot_pareto(results, reference["run"], os.path.join(args.out, figure),
                "%s to t = %.2f s: error against cost" % (title,
                                                          reference["time"]),
                "centroid error [% of the distance fallen]")


def main():
    study(STRATEGIES, SCENE, WORK, "speed_accuracy_cloud_2d.png",
          "2D falling cloud", 0.3)


if __name__ == "__main__":
    main()
