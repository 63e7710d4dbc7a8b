#!/usr/bin/env python3
"""A fluidized bed of two sizes (prm/fluidized_bed_two_sizes_3d.prm): each
size's centroid against time and each size's solid fraction against height
beside complete segregation into two layers, each expanded as a bed of its
own size alone by Richardson-Zaki with the Garside-Al-Dibouni exponent (the
serial model of Epstein, LeClair & Pruden 1981); the pressure drop against
the buoyant weight. Prints the table of
doc/scenes/fluidized_bed_two_sizes_3d.md.

    /usr/bin/python3 scripts/plot_fluidized_bed_sizes.py output/fluidized_bed_two_sizes_3d [--from 3] [--out sizes.png]

Centroids are the statistics' class<k>_centroid_z; the pressure drop is
pressure_drop (floor to top, without the hydrostatic part); the
superficial velocity is the flow rate through the floor over the
cross-section (boundary_flux_4 / A). Means are over time from --from
seconds to the end, weighted by the step. The profiles cut each grain's
volume by horizontal slabs one small diameter thick, averaged over the
particle states written from --from on.
"""
import argparse
import csv
import math
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_fluidized_bed import (  # noqa: E402
    G, RHO_F, RHO_P, richardson_zaki_exponent, terminal_velocity)
from plot_scene import particle_states  # noqa: E402

# The scene's column (prm/fluidized_bed_two_sizes_3d.prm); its beads and
# water are the one-size bed's.
WIDTH, HEIGHT = 0.01, 0.04
NAMES = ("small", "large")


def voidage(u, d):
    """Richardson-Zaki, U / v_t = eps^n, with Garside & Al-Dibouni's n:
    (eps, v_t, n) for beads of diameter d."""
    v_t = terminal_velocity(d)
    n = richardson_zaki_exponent(v_t, d)
    return (u / v_t) ** (1 / n), v_t, n


def sphere_volume_below(h, r):
    """The volume of a sphere of radius r below the plane at height h
    above its centre."""
    h = np.clip(h, -r, r)
    return math.pi * (r * r * h - h ** 3 / 3 + 2 * r ** 3 / 3)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("directory")
    parser.add_argument("--from", dest="start", type=float, default=3.0)
    parser.add_argument("--out")
    args = parser.parse_args()
    path = os.path.join(args.directory, "statistics.csv")
    if not os.path.exists(path):
        sys.exit("plot_fluidized_bed_sizes.py: no statistics.csv in "
                 + args.directory)
    with open(path) as f:
        rows = list(csv.DictReader(f))
    keys = ("time", "dt", "pressure_drop", "boundary_flux_4",
            "class0_centroid_z", "class1_centroid_z", "class0_particles",
            "class1_particles")
    missing = [k for k in keys if k not in rows[0]]
    if missing:
        sys.exit("plot_fluidized_bed_sizes.py: no column %s in %s"
                 % (", ".join(missing), path))
    col = {k: np.array([float(r[k]) for r in rows[1:]]) for k in keys}
    t, dt = col["time"], col["dt"]
    late = t >= args.start
    if not late.any():
        sys.exit("plot_fluidized_bed_sizes.py: the run ends before --from %g s"
                 % args.start)
    area = WIDTH * WIDTH
    u = np.average(-col["boundary_flux_4"][late], weights=dt[late]) / area

    # The beads' radii from the particle states (class 0 the smaller).
    states = particle_states(args.directory, "plot_fluidized_bed_sizes.py",
                             ("radius",))
    radii = np.unique(np.round(states[-1][2]["radius"], 12))
    if len(radii) != 2:
        sys.exit("plot_fluidized_bed_sizes.py: %d sizes in %s, not 2"
                 % (len(radii), args.directory))
    counts = [col["class%d_particles" % k][-1] for k in (0, 1)]
    volumes = [n * 4 / 3 * math.pi * r ** 3 for n, r in zip(counts, radii)]
    weight = sum(volumes) * (RHO_P - RHO_F) * G / area

    # Complete segregation, the large beads' layer below: each layer as
    # thick as a bed of its size alone at the voidage Richardson-Zaki
    # gives it at this U.
    eps = [voidage(u, 2 * r) for r in radii]
    thick = [v / (area * (1 - e[0])) for v, e in zip(volumes, eps)]
    layer = {1: (0.0, thick[1]), 0: (thick[1], thick[1] + thick[0])}
    predicted = {k: 0.5 * sum(layer[k]) for k in (0, 1)}

    mean = {k: np.average(col["class%d_centroid_z" % k][late],
                          weights=dt[late]) for k in (0, 1)}
    spread = {k: (col["class%d_centroid_z" % k][late].min(),
                  col["class%d_centroid_z" % k][late].max()) for k in (0, 1)}
    dp = col["pressure_drop"][late]
    dp_mean = np.average(dp, weights=dt[late])

    # Solid fraction per size in slabs of one small diameter, each bead's
    # volume cut by the slabs' planes, averaged over the states from
    # --from on.
    slab = 2 * radii[0]
    edges = np.arange(0, HEIGHT + slab / 2, slab)
    profile = np.zeros((2, len(edges) - 1))
    used = 0
    for time, centres, fields in states:
        if time < args.start:
            continue
        r = fields["radius"]
        for k in (0, 1):
            mine = np.isclose(r, radii[k])
            profile[k] += np.diff(sphere_volume_below(
                edges[:, None] - centres[mine, -1][None, :],
                r[mine][None, :]).sum(axis=1))
        used += 1
    if used == 0:
        sys.exit("plot_fluidized_bed_sizes.py: no particle state after %g s"
                 % args.start)
    profile /= used * area * slab

    figure, (left, middle, right) = plt.subplots(
        1, 3, figsize=(13, 4.2), gridspec_kw={"width_ratios": [3, 2, 3]})
    colours = ("tab:blue", "tab:red")
    for k in (0, 1):
        left.plot(t, col["class%d_centroid_z" % k] * 1e3, color=colours[k],
                  lw=1, label="%s beads (d = %g mm)"
                  % (NAMES[k], 2e3 * radii[k]))
        left.axhline(predicted[k] * 1e3, color=colours[k], ls="--", lw=1)
    left.plot([], [], "k--", lw=1, label="complete segregation, "
              "Richardson–Zaki per size")
    left.axvspan(args.start, t[-1], color="0.92", zorder=0)
    left.set_xlabel("time [s]")
    left.set_ylabel("centroid height [mm]")
    left.legend(fontsize=8, loc="center right")
    for k in (0, 1):
        middle.stairs(profile[k], edges * 1e3, orientation="horizontal",
                      color=colours[k], label=NAMES[k])
        lo, hi = layer[k]
        middle.plot([1 - eps[k][0]] * 2, [lo * 1e3, hi * 1e3],
                    color=colours[k], ls="--", lw=1.5)
    middle.set_ylim(0, 0.6 * HEIGHT * 1e3)
    middle.set_xlabel("solid fraction of each size")
    middle.set_ylabel("height [mm]")
    middle.plot([], [], "k--", lw=1.5, label="Richardson–Zaki layers")
    middle.legend(fontsize=8)
    right.plot(t, col["pressure_drop"] / weight, lw=0.6, color="0.3")
    right.axhline(1, color="k", lw=1, label="buoyant weight")
    right.axvspan(args.start, t[-1], color="0.92", zorder=0)
    right.set_ylim(0, 1.5)
    right.set_xlabel("time [s]")
    right.set_ylabel("pressure drop / buoyant weight per area")
    right.legend(fontsize=8, loc="lower right")
    figure.tight_layout()
    out = args.out or os.path.join(args.directory,
                                   "fluidized_bed_two_sizes_3d.png")
    figure.savefig(out, dpi=110)

    print("U = %.1f mm/s over %.1f-%.1f s" % (u * 1e3, args.start, t[-1]))
    print("| quantity | this run (mean; range) | reference |")
    print("|---|---|---|")
    for k in (1, 0):
        print("| %s beads' centroid [mm] | %.2f; %.2f–%.2f | %.2f (layer "
              "%.2f–%.2f mm, ε = %.3f: v_t = %.0f mm/s, n = %.2f) |"
              % (NAMES[k], mean[k] * 1e3, spread[k][0] * 1e3,
                 spread[k][1] * 1e3, predicted[k] * 1e3, layer[k][0] * 1e3,
                 layer[k][1] * 1e3, eps[k][0], eps[k][1] * 1e3, eps[k][2]))
    # Each layer's solid fraction inside it: slabs whose centres lie a
    # large radius clear of the floor and the top, a large diameter clear
    # of the interface (where the two sizes mix).
    centre = 0.5 * (edges[:-1] + edges[1:])
    for k in (1, 0):
        lo = layer[k][0] + (radii[1] if k == 1 else 2 * radii[1])
        hi = layer[k][1] - radii[1]
        inside = (centre >= lo) & (centre <= hi)
        print("| %s beads' solid fraction, %g–%g mm | %.3f | %.3f |"
              % (NAMES[k], edges[:-1][inside][0] * 1e3,
                 edges[1:][inside][-1] * 1e3, profile[k][inside].mean(),
                 1 - eps[k][0]))
    print("| pressure drop [Pa] | %.1f; %.1f–%.1f | %.1f (buoyant weight) |"
          % (dp_mean, dp.min(), dp.max(), weight))
    print("figure:", out)


if __name__ == "__main__":
    main()
