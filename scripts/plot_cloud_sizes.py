#!/usr/bin/python3
"""Clouds of one size and of many sizes side by side.

    /usr/bin/python3 scripts/plot_cloud_sizes.py OUT.png DIR [DIR ...]

For each run directory (a 2D cloud run: statistics.csv with the cloud
columns, particles.pvd) prints a row of the table in
doc/scenes/falling_cloud_2d.md, "A cloud of many sizes": grains, the
cloud's peak fall velocity, break-up time and fall before it, its
horizontal radius of gyration and fall velocity at the end, the leaked
grains at the end, and how the sizes sort along the fall at the end: the
mean radius of the lowest fifth of the grains over that of the highest
fifth (1 for one size). Draws OUT.png: one row per run, the grains at the
start, at the break-up (frames 3 mm wide on the cloud's centroid) and at
the end (6 mm), each dot's area in proportion to the grain's and its
colour the radius over the run's median.
"""
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_cloud import read_statistics, written_states, nearest  # noqa: E402
from plot_scene import read_vtu  # noqa: E402


def grains(pieces):
    """Centres (x, y) and radii of the grains of one written state."""
    xs, rs = [], []
    for path in pieces:
        x, arrays, _ = read_vtu(path)
        if len(x):
            xs.append(x[:, :2])
            rs.append(arrays["radius"])
    return np.concatenate(xs), np.concatenate(rs)


def sorting(x, r):
    """Mean radius of the lowest fifth over that of the highest fifth."""
    order = np.argsort(x[:, 1])
    fifth = max(1, len(order) // 5)
    return r[order[:fifth]].mean() / r[order[-fifth:]].mean()


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, directories = sys.argv[1], sys.argv[2:]
    figure, panels = plt.subplots(len(directories), 3, squeeze=False,
                                  figsize=(7.8, 2.8 * len(directories)))
    print("| run | grains | peak fall velocity | break-up | fall before "
          "break-up | horizontal radius of gyration at the end | fall "
          "velocity at the end | leaked at the end | lowest / highest "
          "fifth's mean radius |")
    print("|---|---|---|---|---|---|---|---|---|")
    for row, directory in enumerate(directories):
        stats = read_statistics(directory)
        t, vy = stats["time"], stats["cloud_velocity_y"]
        breakup = stats["breakup_time"][-1]
        cy = stats["cloud_centroid_y"]
        fall = (cy[0] - np.interp(breakup, t, cy)) if breakup > 0 else None
        states = written_states(directory, "particles")
        x_end, r_end = grains(states[-1][1])
        print("| %s | %d | %.1f mm/s | %s | %s | %.2f mm | %.1f mm/s | %d | "
              "%.2f |" % (
                  os.path.basename(os.path.normpath(directory)),
                  stats["particles"][0], -1e3 * vy.min(),
                  "%.3f s" % breakup if breakup > 0 else "none",
                  "%.2f mm" % (1e3 * fall) if fall is not None else "",
                  1e3 * stats["cloud_extent_x"][-1], -1e3 * vy[-1],
                  stats["leaked"][-1], sorting(x_end, r_end)))
        instants = [0.0, breakup if breakup > 0 else 0.5 * t[-1], t[-1]]
        for column, instant in enumerate(instants):
            time, pieces = nearest(states, instant)
            x, r = grains(pieces)
            median = np.median(r)
            centre = (np.interp(time, t, stats["cloud_centroid_x"]),
                      np.interp(time, t, cy))
            axes = panels[row][column]
            axes.scatter(x[:, 0], x[:, 1],
                         s=(1.5 if column < 2 else 0.6) * (r / median) ** 2,
                         c=r / median, cmap="viridis", vmin=0.5, vmax=2,
                         edgecolors="none")
            # The blobs spread over about 6 mm by the end.
            half = 1.5e-3 if column < 2 else 3e-3
            axes.set_xlim(centre[0] - half, centre[0] + half)
            axes.set_ylim(centre[1] - half, centre[1] + half)
            axes.set_aspect("equal")
            axes.set_xticks([])
            axes.set_yticks([])
            axes.set_title("t = %.3g s, %g mm wide" % (time, 2e3 * half),
                           fontsize=9)
        panels[row][0].set_ylabel(
            os.path.basename(os.path.normpath(directory)), fontsize=8)
    figure.tight_layout()
    figure.savefig(out, dpi=150)
    print(out)


if __name__ == "__main__":
    main()
