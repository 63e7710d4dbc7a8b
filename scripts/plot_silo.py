#!/usr/bin/env python3
"""Pictures of a 2D silo's discharge (prm/silo_discharge_2d.prm): the grains
at four instants, coloured by speed, and the number of grains that have
left against time.

    /usr/bin/python3 scripts/plot_silo.py output/silo_discharge_2d [--out silo.png]
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("directory")
    parser.add_argument("--orifice", type=float, default=0.08,
                        help="the orifice's width D [m] (0.08 in the scene)")
    parser.add_argument("--out")
    args = parser.parse_args()
    with open(os.path.join(args.directory, "particles.pvd")) as f:
        states = re.findall(r'timestep="([^"]+)".*?file="([^"]+)"', f.read())
    if not states:
        sys.exit("plot_silo.py: no particles.pvd in " + args.directory)
    chosen = [states[round(k * (len(states) - 1) / 3)] for k in range(4)]
    with open(os.path.join(args.directory, "statistics.csv")) as f:
        rows = list(csv.DictReader(f))

    figure = plt.figure(figsize=(11, 4.2))
    for k, (time, name) in enumerate(chosen):
        axes = figure.add_subplot(1, 5, k + 1)
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
    axes = figure.add_subplot(1, 5, 5)
    axes.plot([float(r["time"]) for r in rows],
              [float(r["grains_removed"]) for r in rows], "k-")
    axes.set_xlabel("t [s]")
    axes.set_ylabel("grains_removed")
    figure.tight_layout()
    out = args.out or os.path.join(args.directory, "silo.png")
    figure.savefig(out, dpi=120)
    print(out)


if __name__ == "__main__":
    main()
