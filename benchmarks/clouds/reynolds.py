#!/usr/bin/python3
"""The 3D falling cloud at three cloud Reynolds numbers
(doc/scenes/falling_cloud_3d.md, "Inertia: the cloud at three Reynolds
numbers"): prm/falling_cloud_3d.prm as shipped (Re_c 0.4, run to 5 s) and in
two lighter liquids (Re_c 1 to 2.3 s; Re_c 3 in a box 60 mm tall to 2 s),
everything else unchanged. Prints the table's rows: the peak cloud velocity
and its Reynolds number, the fall after which the axis is empty, and the
ring radius after 10, 14, 20, 30 and 40 cloud radii of fall.

    benchmarks/clouds/reynolds.py [--only re0.4,re1,re3] [--jobs 2]
        [--out DIR] [--analyse-only] [--states]

The runs write a checkpoint every 200 steps, so a run that is stopped goes
on from there when started again. Run side by side on the 2-core machine
(three at once) they took 78, 60 and 81 minutes; with two jobs, the
default, count on about two hours.

The ring radius is the median distance of the beads from the vertical
through their centroid, read from the written states (every 50 steps) and
interpolated in the fall; the axis is empty from the first written state
after which fewer than 10 beads lie within R/5 of that vertical. --states also prints, per written state, the fall, the
beads near the axis, the ring radius and the ring's roundness: the beads
between 0.6 and 1.4 ring radii counted in 24 sectors of 15 degrees around
the vertical (the largest count over the smallest) and the spread of the
sectors' mean heights.
"""
import argparse
import concurrent.futures
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from scene_runner import ROOT, read_csv, run_scene  # noqa: E402

sys.path.insert(0, os.path.join(ROOT, "scripts"))
import plot_cloud  # noqa: E402

SCENE = os.path.join(ROOT, "prm", "falling_cloud_3d.prm")
WORK = os.path.join(ROOT, "benchmarks", "results", "cloud_reynolds")
R = 5e-4  # the scene's cloud radius
FALLS = (10, 14, 20, 30, 40)

# name: (end time, liquid density, viscosity, tall box)
RUNS = {
    "re0.4": (5.0, 1154.0, 0.0108, False),
    "re1": (2.3, 1126.0, 0.006, False),
    "re3": (2.0, 1110.0, 0.0027, True),
}


def scene_text(end, density, viscosity, tall):
    with open(SCENE) as f:
        text = f.read()
    changes = [(r"(?m)^set End time .*$", "set End time = %g" % end),
               (r"= 1154\b", "= %g" % density),
               (r"= 0\.0108\b", "= %g" % viscosity)]
    if tall:
        # 60 mm tall, the cloud again 8 R under the top: room to fall.
        changes += [(r"= 16e-3, 16e-3, 40e-3", "= 16e-3, 16e-3, 60e-3"),
                    (r"= 8, 8, 20\b", "= 8, 8, 30"),
                    (r"= 8e-3, 8e-3, 36e-3", "= 8e-3, 8e-3, 56e-3")]
    for pattern, replacement in changes:
        text, count = re.subn(pattern, replacement, text)
        assert count == 1, "the scene changed: %s" % pattern
    return text + "\nsubsection Checkpoint\n  set Every steps = 200\nend\n"


def roundness(x, c, r):
    """The ring's beads per 15-degree sector, largest over smallest, and the
    spread of the sectors' mean heights [m]."""
    ring = np.abs(r / np.median(r) - 1) < 0.4
    sector = (np.degrees(np.arctan2(x[ring, 1] - c[1], x[ring, 0] - c[0]))
              % 360 // 15).astype(int)
    counts = np.bincount(sector, minlength=24)
    heights = [x[ring, 2][sector == k].mean() for k in range(24)
               if counts[k] > 0]
    return counts.max() / max(counts.min(), 1), max(heights) - min(heights)


def analyse(directory, density, viscosity, print_states=False):
    states = []
    z0 = None
    for t, pieces in plot_cloud.written_states(directory, "particles"):
        x = plot_cloud.grains_at(pieces, full=True)
        c = x.mean(axis=0)
        z0 = c[2] if z0 is None else z0
        r = np.hypot(x[:, 0] - c[0], x[:, 1] - c[1])
        states.append((t, (z0 - c[2]) / R, int(np.sum(r < R / 5)),
                       np.median(r) / R))
        if print_states:
            factor, spread = roundness(x, c, r)
            print("%s %.3f s: fall %.1f R, %d beads near the axis, ring "
                  "%.2f R, sectors %.2f, heights %.3f mm" % (
                      os.path.basename(directory), t, states[-1][1],
                      states[-1][2], states[-1][3], factor, 1e3 * spread))
    falls = np.array([s[1] for s in states])
    rings = np.array([s[3] for s in states])
    ring = " / ".join("%.2f" % np.interp(f, falls, rings)
                      if f <= falls[-1] else "–" for f in FALLS)
    empty = next((s for i, s in enumerate(states)
                  if all(later[2] < 10 for later in states[i:])), None)
    rows = read_csv(os.path.join(directory, "statistics.csv"))
    peak = max(rows, key=lambda row: -float(row["cloud_velocity_z"]))
    u = -float(peak["cloud_velocity_z"])
    last = rows[-1]
    return ("| %g, %g | %.1f mm/s at %.2f s, **%.2f** | %s | %s R | to %.2f s "
            "(%.0f R), %d steps, %.0f s, %d–%d cells |" % (
                density, viscosity, 1e3 * u, float(peak["time"]),
                density * u * R / viscosity,
                "%.1f R (%.2f s)" % (empty[1], empty[0]) if empty else "–",
                ring, float(last["time"]), falls[-1], int(last["step"]),
                float(last["wall_time"]),
                min(int(row["cells"]) for row in rows),
                max(int(row["cells"]) for row in rows)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--only", default=",".join(RUNS))
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--out", default=WORK)
    parser.add_argument("--analyse-only", action="store_true")
    parser.add_argument("--states", action="store_true",
                        help="print every written state's ring figures")
    args = parser.parse_args()
    names = args.only.split(",")
    for name in names:
        if name not in RUNS:
            sys.exit("reynolds.py: --only: no run '%s' (%s)"
                     % (name, ", ".join(RUNS)))
    if not args.analyse_only:
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            for done in [pool.submit(run_scene, scene_text(*RUNS[name]),
                                     os.path.join(args.out, name))
                         for name in names]:
                done.result()
    rows = [analyse(os.path.join(args.out, name), *RUNS[name][1:3],
                    print_states=args.states) for name in names]
    print("| liquid: ρ (kg/m³), μ (Pa·s) | peak cloud velocity, its Re_c "
          "| axis empty after | ring radius after %s R of fall | run |"
          % " / ".join(map(str, FALLS)))
    print("|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
