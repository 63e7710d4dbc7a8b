#!/usr/bin/python3
"""The underwater avalanches of doc/scenes/avalanche_2d.md on several
slopes: the loose and the dense layer (prm/avalanche_2d_{loose,dense}.prm)
with gravity tilted by each angle, optionally with a rolling friction, and
the table of how each layer moves, dilates and fails, to set beside
Pailha, Nicolas & Pouliquen (2008): a loose layer avalanches at once, a
dense one creeps while it dilates and fails later the gentler the slope.

    /usr/bin/python3 benchmarks/avalanche/run.py [--slopes 22,25,28]
        [--rolling 0.2] [--dense-end 20] [--jobs 2] [--analyse-only]

The studies of the page:

    run.py --slopes 22,25,28 --dense-end 20             # the slope
    run.py --slopes 25,28,31,34 --rolling 0.2           # with rolling friction

Each run writes into benchmarks/results/avalanche/<case>/{loose,dense}; a
run whose statistics reach its end time is not run again (--analyse-only
runs nothing). The layers run for the scenes' end times (3 s loose, 15 s
dense; --dense-end for the dense one). The measures are scripts/plot_avalanche.py's,
which also draws each slope's figure into its case folder. A slope's pair
takes 5 to 10 minutes on two cores.
"""
import argparse
import concurrent.futures
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.dirname(HERE))
from plot_avalanche import analyse  # noqa: E402
from scene_runner import (RunFailed, finished, ready_scene_text,  # noqa: E402
                          run_scene)

G = 9.81


def scene_text(kind, angle, rolling, end):
    """The ready scene's text with the packings' paths made absolute and
    the study's settings appended (a later 'set' overrides an earlier)."""
    text = ready_scene_text("avalanche_2d_%s" % kind)
    theta = math.radians(angle)
    text += "\nsubsection Gravity\n  set Vector = %.6g, %.6g\nend\n" % (
        G * math.sin(theta), -G * math.cos(theta))
    if rolling is not None:
        text += "subsection Contacts\n  set Rolling friction = %s\nend\n" \
            % rolling
    if end is not None and kind == "dense":
        text += "set End time = %s\n" % end
    return text


def cell(value, form, scale=1.0):
    return "—" if math.isnan(value) else form % (value * scale)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--slopes", default="22,25,28",
                        help="angles in degrees, comma separated")
    parser.add_argument("--rolling", help="Contacts/Rolling friction "
                        "(default: the scenes' 0)")
    parser.add_argument("--dense-end", help="end time of the dense layer "
                        "[s] (default: the scene's 15 s)")
    parser.add_argument("--jobs", type=int, default=2,
                        help="runs side by side")
    parser.add_argument("--analyse-only", action="store_true",
                        help="run nothing, tabulate the runs there are")
    args = parser.parse_args()
    slopes = [float(a) for a in args.slopes.split(",")]
    results = os.path.join(ROOT, "benchmarks", "results", "avalanche")

    def folder(angle):
        name = "slope_%g" % angle
        if args.rolling is not None:
            name += "_rolling_%s" % args.rolling
        if args.dense_end is not None:
            name += "_dense_end_%s" % args.dense_end
        return os.path.join(results, name)

    cases = [(angle, kind, os.path.join(folder(angle), kind),
              scene_text(kind, angle, args.rolling, args.dense_end))
             for angle in slopes for kind in ("loose", "dense")]
    todo = [c for c in cases if not finished(c[2], c[3])]
    if todo and not args.analyse_only:
        print("%d runs, %d side by side" % (len(todo), args.jobs),
              flush=True)
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            runs = [pool.submit(run_scene, c[3], c[2]) for c in todo]
            for c, run in zip(todo, runs):
                run.result()
                print("  done: %s" % os.path.relpath(c[2], ROOT), flush=True)

    print("\n| slope | loose: velocity over 0.1–2 s, 2–3 s [mm/s] | loose: "
          "mean excess [W] | dense: velocity over 0.1–2 s [mm/s] | dense: "
          "creep [mm/s] | dense: fails at [s] | packing at failure | dense: "
          "packing at the end |")
    print("|---|---|---|---|---|---|---|---|")
    for angle in slopes:
        loose, dense = (os.path.join(folder(angle), k)
                        for k in ("loose", "dense"))
        texts = {c[2]: c[3] for c in cases}
        if not (finished(loose, texts[loose]) and
                finished(dense, texts[dense])):
            print("| %g° | not complete | | | | | | |" % angle)
            continue
        lo, de = analyse(loose, "loose"), analyse(dense, "dense")
        print("| %g° | %s, %s | %s | %s | %s | %s | %s | %.3f (%.0f s) |" % (
            angle, cell(lo["velocity_early"], "%.1f", 1e3),
            cell(lo["velocity_late"], "%.1f", 1e3),
            cell(lo["excess_flowing"], "%+.3f"),
            cell(de["velocity_early"], "%.2f", 1e3),
            cell(de["creep"], "%.3f", 1e3), cell(de["t_fail"], "%.2f"),
            cell(de["packing_fail"], "%.3f"), de["packing_end"],
            de["t_end"]))
        subprocess.run([sys.executable,
                        os.path.join(ROOT, "scripts", "plot_avalanche.py"),
                        loose, dense, "--out",
                        os.path.join(folder(angle), "avalanche_2d.png")],
                       check=True, stdout=subprocess.DEVNULL)
    print("\nEach slope's figure: benchmarks/results/avalanche/<case>/"
          "avalanche_2d.png")


if __name__ == "__main__":
    try:
        main()
    except RunFailed as error:
        sys.exit("run.py: %s" % error)
