#!/usr/bin/python3
"""The column collapses of doc/scenes/column_collapse_2d.md compared with
Rondon, Pouliquen & Aussillous (2011): the loose and the dense column
(prm/column_collapse_2d_{loose,dense}.prm) run as pairs, with the rolling
friction, the time step or any other parameter changed, and the
run-outs at the end tabulated against the experiment's "the dense column
stops at about half the loose run-out".

    /usr/bin/python3 benchmarks/column_collapse/run.py [--rolling 0.2,0.3]
        [--steps 5e-3,4.8e-3] [--set Contacts/Friction=0.8]
        [--scene column_collapse_2d] [--loose-packing-set NAME=VALUE]
        [--jobs 2] [--ranks 1] [--analyse-only] [--figure collapse.png]

A collapse is chaotic: a time step 1-4 % off ends at run-outs up to a fifth
apart. Each rolling friction is therefore run once per time step in
--steps (default: the scene's 5 ms and five steps 1-4 % off it), and its
row gives the mean and the range over those pairs. Without --rolling the
scenes' own rolling friction is kept. The studies of the page:

    run.py                                              # the six pairs
    run.py --rolling 0                                  # without rolling friction
    run.py --rolling 0.05,0.1,0.5 --steps 5e-3          # the rolling table,
    run.py --rolling 0.3,100 --steps 4.9e-3,5e-3,5.1e-3 #   one and three pairs
    run.py --steps 2.45e-3,2.5e-3,2.55e-3               # how firm the half is
    run.py --steps 0.99e-3,1e-3,1.01e-3
    run.py --steps 1e-3 --set "Coupling/Resting threshold=0.01"
    run.py --rolling 0 --set Contacts/Friction=0.8 --steps 4.9e-3,5e-3,5.1e-3
    run.py --scene column_collapse_3d_slab --steps 5e-3 # the 3D slabs (an hour)
    run.py --scene column_collapse_3d_slab --steps 5e-3 \
        --loose-packing-set "Contacts/Rolling friction=0.15" # a looser slab

--loose-packing-set prepares the loose column anew: it runs
prm/packings/<scene>_loose.prm with the settings given (rolling friction
while the grains settle packs them looser) into
benchmarks/results/column_collapse/<scene>/packings/, and the loose
column starts from the grains that run leaves.

Each run writes into benchmarks/results/column_collapse/<scene>/<case>/
{loose,dense}; a run whose statistics reach the scene's end time is not
run again (--analyse-only runs nothing). The measures are those of
scripts/plot_column_collapse.py, which --figure calls with the first pair
and the others as repeats. A 2D pair takes about a minute on two cores.
"""
import argparse
import concurrent.futures
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.dirname(HERE))
from plot_column_collapse import measure  # noqa: E402
from scene_runner import (RunFailed, finished, ready_scene_text,  # noqa: E402
                          run_scene)

# The scene's step and five 1-4 % off it (doc/scenes/column_collapse_2d.md).
DEFAULT_STEPS = "5e-3,4.8e-3,4.9e-3,4.95e-3,5.05e-3,5.1e-3"
# Rondon et al. (2011): a dense column (packing 0.60) runs out about half
# as far as a loose one (0.55).
EXPERIMENT_RATIO = 0.5


def setting_text(setting):
    """'Section/Subsection/Name=value' as parameter text."""
    path, _, value = setting.partition("=")
    *sections, name = path.strip().split("/")
    if not value.strip() or not name:
        sys.exit("run.py: --set %s is not Section/Name=value" % setting)
    return "".join("subsection %s\n" % s for s in sections) + \
        "set %s = %s\n" % (name, value.strip()) + "end\n" * len(sections)


def scene_text(scene, kind, rolling, step, settings):
    """The ready scene's text with the packings' paths made absolute and
    the study's settings appended (a later 'set' overrides an earlier)."""
    text = ready_scene_text("%s_%s" % (scene, kind))
    text += "\nset Time step = %s\n" % step
    if rolling is not None:
        text += "subsection Contacts\n  set Rolling friction = %s\nend\n" \
            % rolling
    return text + "".join(setting_text(s) for s in settings)


def settings_name(settings):
    return "".join("_" + re.sub(r"[^A-Za-z0-9.=-]", "-", setting)
                   for setting in settings)


def case_name(rolling, step, settings, packing_settings=()):
    name = "rolling_%s_dt_%s" % ("scene" if rolling is None else rolling,
                                 step) + settings_name(settings)
    if packing_settings:
        name += "_loose-packing" + settings_name(packing_settings)
    return name


def loose_packing_directory(results, settings):
    return os.path.join(results, "packings", "loose" + settings_name(settings))


def prepare_loose_packing(scene, settings, results, ranks):
    """Runs the loose packing's preparation with @p settings (once) and
    returns the grain file it leaves."""
    text = ready_scene_text(os.path.join("packings", scene + "_loose")) + \
        "".join(setting_text(s) for s in settings)
    directory = loose_packing_directory(results, settings)
    if not finished(directory, text):
        print("preparing the loose packing: %s"
              % os.path.relpath(directory, ROOT), flush=True)
        run_scene(text, directory, ranks)
    return os.path.join(directory, "grains.txt")


def spread(values, form):
    """Mean (lowest–highest); signed figures' range as 'a to b'."""
    if len(values) == 1:
        return form % values[0]
    dash = " to " if "+" in form else "–"
    return "%s (%s%s%s)" % (form % np.mean(values), form % min(values), dash,
                            form % max(values))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rolling", help="rolling frictions, comma "
                        "separated (default: the scenes' own)")
    parser.add_argument("--steps", default=DEFAULT_STEPS,
                        help="time steps, comma separated (default: %s)"
                        % DEFAULT_STEPS)
    parser.add_argument("--set", action="append", default=[],
                        metavar="SECTION/NAME=VALUE",
                        help="any other parameter (repeatable)")
    parser.add_argument("--scene", default="column_collapse_2d",
                        help="prm/<scene>_{loose,dense}.prm")
    parser.add_argument("--loose-packing-set", action="append", default=[],
                        metavar="SECTION/NAME=VALUE",
                        help="prepare the loose column anew, with this "
                        "parameter of its packing's preparation changed "
                        "(repeatable)")
    parser.add_argument("--jobs", type=int, default=2,
                        help="runs side by side")
    parser.add_argument("--ranks", type=int, default=1,
                        help="MPI ranks per run")
    parser.add_argument("--analyse-only", action="store_true",
                        help="run nothing, tabulate the runs there are")
    parser.add_argument("--figure", help="the run-outs, pressures and "
                        "deposits of all pairs (scripts/"
                        "plot_column_collapse.py)")
    args = parser.parse_args()
    rollings = [None] if args.rolling is None else \
        [r.strip() for r in args.rolling.split(",")]
    steps = [s.strip() for s in args.steps.split(",")]
    results = os.path.join(ROOT, "benchmarks", "results", "column_collapse",
                           args.scene)

    loose_settings = []
    if args.loose_packing_set:
        if args.analyse_only:
            grains = os.path.join(
                loose_packing_directory(results, args.loose_packing_set),
                "grains.txt")
        else:
            grains = prepare_loose_packing(args.scene, args.loose_packing_set,
                                           results, args.ranks)
        loose_settings = ["Grains/Placement/File=" + grains]

    def folder_of(rolling, step):
        return os.path.join(results, case_name(rolling, step, args.set,
                                               args.loose_packing_set))

    cases = []
    for rolling in rollings:
        for step in steps:
            folder = folder_of(rolling, step)
            for kind in ("loose", "dense"):
                text = scene_text(args.scene, kind, rolling, step,
                                  args.set + (loose_settings
                                              if kind == "loose" else []))
                cases.append((rolling, step, kind,
                              os.path.join(folder, kind), text))

    todo = [c for c in cases if not finished(c[3], c[4])]
    if todo and not args.analyse_only:
        print("%d runs, %d side by side" % (len(todo), args.jobs),
              flush=True)
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            runs = [pool.submit(run_scene, c[4], c[3], args.ranks)
                    for c in todo]
            for c, run in zip(todo, runs):
                run.result()
                print("  done: %s" % os.path.relpath(c[3], ROOT), flush=True)

    measured = {}
    for rolling, step, kind, directory, text in cases:
        if finished(directory, text):
            measured[(rolling, step, kind)] = measure(directory)
        else:
            print("not complete, left out: %s"
                  % os.path.relpath(directory, ROOT))

    def pairs_of(rolling):
        return [(s, measured[(rolling, s, "loose")],
                 measured[(rolling, s, "dense")]) for s in steps
                if (rolling, s, "loose") in measured and
                (rolling, s, "dense") in measured]

    def label(rolling):
        return "the scenes'" if rolling is None else rolling

    print("\nEach pair: run-out (L - L0)/L0 at the end, time to 90 % of it, "
          "mean excess pore pressure from 0.2 s to then:")
    print("| rolling friction | time step | loose | dense | dense / loose | "
          "t90 loose, dense [s] | excess loose, dense [W] |")
    print("|---|---|---|---|---|---|---|")
    for rolling in rollings:
        for step, lo, de in pairs_of(rolling):
            print("| %s | %s | %.2f | %.2f | %.2f | %.2f, %.2f | %+.3f, "
                  "%+.3f |" % (label(rolling), step, lo["final"],
                               de["final"], de["final"] / lo["final"],
                               lo["t90"], de["t90"], lo["mean_excess"],
                               de["mean_excess"]))

    print("\nMean (range) over the pairs:")
    print("| rolling friction | pairs | loose | dense | dense / loose |")
    print("|---|---|---|---|---|")
    for rolling in rollings:
        pairs = [(lo, de) for _, lo, de in pairs_of(rolling)]
        if not pairs:
            continue
        print("| %s | %d | %s | %s | **%s** |" % (
            label(rolling), len(pairs),
            spread([lo["final"] for lo, _ in pairs], "%.2f"),
            spread([de["final"] for _, de in pairs], "%.2f"),
            spread([de["final"] / lo["final"] for lo, de in pairs], "%.2f")))
        if len(rollings) == 1:
            print("\n| | loose | dense |\n|---|---|---|")
            for name, key, form in (
                    ("time to 90 % of the run-out [s]", "t90", "%.2f"),
                    ("final height / initial height", "height", "%.2f"),
                    ("mean excess pore pressure from 0.2 s to that time "
                     "[W]", "mean_excess", "%+.3f"),
                    ("lowest excess [W]", "lowest", "%+.2f"),
                    ("highest excess [W]", "highest", "%+.2f"),
                    ("packing inside the mass at the release",
                     "packing_start", "%.3f"),
                    ("lowest packing inside the mass", "packing_lowest",
                     "%.3f"),
                    ("packing inside the mass at the end", "packing_end",
                     "%.3f")):
                print("| %s | %s | %s |" % (
                    name, spread([lo[key] for lo, _ in pairs], form),
                    spread([de[key] for _, de in pairs], form)))
    print("\nRondon et al. (2011): the dense column stops at about %.1f of "
          "the loose run-out." % EXPERIMENT_RATIO)

    if args.figure:
        folders = [(os.path.join(folder_of(r, s), "loose"),
                    os.path.join(folder_of(r, s), "dense"))
                   for r in rollings for s in steps
                   if (r, s, "loose") in measured and
                   (r, s, "dense") in measured]
        if folders:
            command = [sys.executable,
                       os.path.join(ROOT, "scripts",
                                    "plot_column_collapse.py"),
                       folders[0][0], folders[0][1], "--out", args.figure]
            for loose, dense in folders[1:]:
                command += ["--repeat", loose, dense]
            subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
            print("wrote " + args.figure)


if __name__ == "__main__":
    try:
        main()
    except RunFailed as error:
        sys.exit("run.py: %s" % error)
