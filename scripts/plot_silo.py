#!/usr/bin/env python3
"""Pictures of a 2D silo's discharge (prm/silo_discharge_2d.prm,
prm/silo_discharge_immersed_2d.prm): the grains at four instants, coloured
by speed, the number of grains that have left against time, and the
discharge rate against the grains still in the bin; with --compare, the
last two for a second run beside the first (the dry silo beside the
immersed one).

    /usr/bin/python3 scripts/plot_silo.py output/silo_discharge_2d [--out silo.png]
    /usr/bin/python3 scripts/plot_silo.py output/silo_discharge_immersed_2d \
        --compare output/silo_discharge_2d
"""
import argparse
import csv
import os
import re
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_scene import read_vtu  # noqa: E402


def read_rows(directory):
    with open(os.path.join(directory, "statistics.csv")) as f:
        return list(csv.DictReader(f))


def discharge_rate(t, removed, n0, interval=0.25):
    """The mean rate over successive intervals from the first removal,
    and the grains in the bin at each interval's middle."""
    start = t[np.argmax(removed > 0)]
    edges = np.arange(start, t[-1] + 1e-9, interval)
    counts = np.interp(edges, t, removed)
    rate = np.diff(counts) / interval
    left = n0 - 0.5 * (counts[1:] + counts[:-1])
    keep = rate > 0
    return left[keep], rate[keep]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("directory")
    parser.add_argument("--orifice", type=float, default=0.08,
                        help="the orifice's width D [m] (0.08 in the scene)")
    parser.add_argument("--compare",
                        help="a second run's output folder, drawn beside")
    parser.add_argument("--out")
    args = parser.parse_args()
    with open(os.path.join(args.directory, "particles.pvd")) as f:
        states = re.findall(r'timestep="([^"]+)".*?file="([^"]+)"', f.read())
    if not states:
        sys.exit("plot_silo.py: no particles.pvd in " + args.directory)
    chosen = [states[round(k * (len(states) - 1) / 3)] for k in range(4)]
    runs = [(args.directory, read_rows(args.directory))]
    if args.compare:
        runs.append((args.compare, read_rows(args.compare)))

    figure = plt.figure(figsize=(13.5, 4.2))
    for k, (time, name) in enumerate(chosen):
        axes = figure.add_subplot(1, 6, k + 1)
        base = os.path.join(args.directory, name.replace(".pvtu", ""))
        pieces = [base + ".%d.vtu" % p for p in range(64)
                  if os.path.exists(base + ".%d.vtu" % p)]
        for path in pieces:
            points, arrays, _ = read_vtu(path)
            if not len(points):
                continue
            d = 2 * arrays["radius"]
            speed = np.linalg.norm(arrays["velocity"], axis=1)
            axes.add_collection(EllipseCollection(
                d, d, np.zeros_like(d), units="xy", offsets=points[:, :2],
                transOffset=axes.transData, array=speed, cmap="viridis",
                clim=(0, 1)))
        axes.set_xlim(0, 0.4)
        axes.set_ylim(-0.02, 0.8)
        half = args.orifice / 2
        axes.plot([0, 0, 0.2 - half], [0.8, 0, 0], "k-", lw=1)
        axes.plot([0.2 + half, 0.4, 0.4], [0, 0, 0.8], "k-", lw=1)
        axes.set_aspect("equal")
        axes.set_title("t = %.2f s" % float(time), fontsize=9)
        axes.set_xticks([])
        axes.set_yticks([] if k else [0, 0.4, 0.8])
    removed_axes = figure.add_subplot(1, 6, 5)
    rate_axes = figure.add_subplot(1, 6, 6)
    for (directory, rows), style in zip(runs, ["k-", "C0--"]):
        label = os.path.basename(os.path.normpath(directory))
        t = np.array([float(r["time"]) for r in rows])
        removed = np.array([float(r["grains_removed"]) for r in rows])
        removed_axes.plot(t, removed, style, label=label)
        # The rate over each 0.25 s, against the grains left at its middle.
        left, rate = discharge_rate(t, removed, float(rows[0]["particles"]))
        rate_axes.plot(left, rate, style + "o", ms=3, label=label)
    removed_axes.set_xlabel("t [s]")
    removed_axes.set_ylabel("grains_removed")
    rate_axes.set_xlabel("grains in the bin")
    rate_axes.set_ylabel("rate [grains/s]")
    rate_axes.set_xlim(rate_axes.get_xlim()[::-1])
    rate_axes.set_ylim(bottom=0)
    if len(runs) > 1:
        rate_axes.legend(fontsize=7)
    figure.tight_layout()
    out = args.out or os.path.join(args.directory, "silo.png")
    figure.savefig(out, dpi=120)
    print(out)


if __name__ == "__main__":
    main()
