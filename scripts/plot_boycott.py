#!/usr/bin/env python3
"""The Boycott effect (prm/boycott_2d.prm): a suspension clarifying in a
vertical tank and in the same tank with its walls leaning, the height of
the suspension's top against time, and the Ponder-Nakamura-Kuroda
prediction for the leaning tank from the vertical tank's settling
velocity. Prints the table of doc/scenes/boycott_2d.md.

    /usr/bin/python3 scripts/plot_boycott.py output/boycott_2d_0 output/boycott_2d_30 [--angle 30] [--radius 25e-6] [--width 1.5e-3] [--out boycott.png]

The suspension's top at a written state is the highest height at which
the discs' area fraction, over horizontal strips of 0.25 mm, is at least
half the initial one (the tank's horizontal width is the same at every
height, so the strips of both tanks compare). The clear fluid is the area
of the squares, cut along the walls' lean and each holding about twelve
discs at the initial fraction, that hold less than half of it: the
fluid the theory counts, wherever it lies (under the top or under the
leaning wall); H minus its area over W is the level the top would have
if all of it had risen to the top.
"""
import argparse
import math
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_scene import particle_states  # noqa: E402

# The scene's tank and suspension (prm/meshes/boycott_2d.py defaults).
HEIGHT, STRIP = 6e-3, 0.25e-3
WIDTH, RADIUS = 1.5e-3, 25e-6  # --width, --radius


def states(directory):
    """(time, positions) of every written state of a run."""
    return particle_states(directory, "plot_boycott.py")


def top(points, fraction0):
    """The suspension's top: the highest strip at half the initial area
    fraction or more (its upper edge)."""
    strips = int(round(HEIGHT / STRIP))
    counts = np.histogram(points[:, 1], bins=strips, range=(0, HEIGHT))[0]
    fraction = counts * math.pi * RADIUS ** 2 / (WIDTH * STRIP)
    dense = np.nonzero(fraction >= 0.5 * fraction0)[0]
    return (dense[-1] + 1) * STRIP if len(dense) else 0.0


def clear_level(points, fraction0, lean):
    """H minus the clear fluid's area over W (see the module's text)."""
    side = math.sqrt(12 * math.pi * RADIUS ** 2 / fraction0)
    nx = max(1, int(round(WIDTH / side)))
    ny = max(1, int(round(HEIGHT / (WIDTH / nx))))
    counts = np.histogram2d(points[:, 0] - points[:, 1] * lean, points[:, 1],
                            bins=(nx, ny), range=((0, WIDTH), (0, HEIGHT)))[0]
    square = WIDTH / nx * HEIGHT / ny
    clear = (counts * math.pi * RADIUS ** 2 / square < 0.5 * fraction0).sum()
    return HEIGHT - clear * square / WIDTH


def main():
    global RADIUS, WIDTH
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("vertical")
    parser.add_argument("leaning")
    parser.add_argument("--angle", type=float, default=30)
    parser.add_argument("--radius", type=float, default=RADIUS,
                        help="the discs' radius [m] (prm/meshes/boycott_2d.py)")
    parser.add_argument("--width", type=float, default=WIDTH,
                        help="the tank's horizontal width [m]")
    parser.add_argument("--out")
    args = parser.parse_args()
    RADIUS, WIDTH = args.radius, args.width
    runs = [states(args.vertical), states(args.leaning)]
    fraction0 = len(runs[0][0][1]) * math.pi * RADIUS ** 2 / (WIDTH * HEIGHT)
    curves = [(np.array([t for t, _ in run]),
               np.array([top(p, fraction0) for _, p in run])) for run in runs]
    tan = math.tan(math.radians(args.angle))
    clear = [np.array([clear_level(p, fraction0, lean) for _, p in run])
             for run, lean in zip(runs, (0.0, tan))]

    # The vertical tank's settling velocity v0: the slope of its top while
    # it is above half the tank (least squares).
    t0, h0 = curves[0]
    upper = h0 > 0.5 * HEIGHT
    v0 = -np.polyfit(t0[upper], h0[upper], 1)[0]
    # Ponder-Nakamura-Kuroda: clear fluid forms at v0 under the top and
    # under the downward-facing wall, dh/dt = -v0 (1 + h tan(angle)/W);
    # exactly h(t) = (H + W/tan) exp(-v0 tan t/W) - W/tan.
    t1, h1 = curves[1]
    grid = np.linspace(0, t1[-1], 200)
    pnk = (HEIGHT + WIDTH / tan) * np.exp(-v0 * tan * grid / WIDTH) \
        - WIDTH / tan
    # Time for the top to fall to half the tank, measured and predicted.
    half = 0.5 * HEIGHT

    def crossing(t, h):
        below = np.nonzero(h <= half)[0]
        if not len(below) or below[0] == 0:
            return float("nan")
        i = below[0]
        return t[i - 1] + (t[i] - t[i - 1]) * (h[i - 1] - half) / (
            h[i - 1] - h[i])

    t_pnk = WIDTH / (v0 * tan) * math.log((HEIGHT + WIDTH / tan) /
                                          (half + WIDTH / tan))
    t_half = crossing(t1, h1)
    t_clear = [crossing(t, c) for (t, _), c in zip(curves, clear)]

    figure = plt.figure(figsize=(10, 4.5))
    grid_spec = figure.add_gridspec(1, 4, width_ratios=[0.8, 1.4, 0.001, 2.2])
    snap = figure.add_subplot(grid_spec[0, 0:2])
    shown = t_pnk if math.isfinite(t_pnk) else 0.5 * t1[-1]
    for offset, run in ((0.0, runs[0]), (WIDTH * 1.6, runs[1])):
        points = min(run, key=lambda state: abs(state[0] - shown))[1]
        snap.add_collection(EllipseCollection(
            2 * RADIUS, 2 * RADIUS, 0, units="x", offsets=points[:, :2]
            + [offset, 0], transOffset=snap.transData, color="tab:brown"))
    for offset, lean in ((0.0, 0.0), (WIDTH * 1.6, tan)):
        xs = np.array([0, WIDTH, WIDTH + HEIGHT * lean, HEIGHT * lean, 0])
        ys = np.array([0, 0, HEIGHT, HEIGHT, 0])
        snap.plot(xs + offset, ys, "k-", lw=1)
    snap.set_aspect("equal")
    snap.set_xlim(-0.2e-3, WIDTH * 2.6 + HEIGHT * tan)
    snap.set_ylim(-0.2e-3, HEIGHT + 0.2e-3)
    snap.axis("off")
    snap.set_title("t = %.1f s" % shown, fontsize=9)
    plot = figure.add_subplot(grid_spec[0, 3])
    plot.plot(t0, h0 * 1e3, "o", ms=3, label="vertical tank")
    plot.plot(t0, (HEIGHT - v0 * t0) * 1e3, "k:", lw=1,
              label="v0 = %.1f µm/s" % (v0 * 1e6))
    plot.plot(t1, h1 * 1e3, "s", ms=3, label="walls at %g°" % args.angle)
    plot.plot(t1, clear[1] * 1e3, "x", ms=3, color="tab:orange",
              label="walls at %g°: clear fluid's level" % args.angle)
    plot.plot(grid, pnk * 1e3, "k-", lw=1,
              label="Ponder–Nakamura–Kuroda")
    plot.set_ylim(0, HEIGHT * 1.05e3)
    plot.set_xlabel("t [s]")
    plot.set_ylabel("top of the suspension [mm]")
    plot.legend(fontsize=8)
    figure.tight_layout()
    out = args.out or os.path.join(args.leaning, "boycott_2d.png")
    figure.savefig(out, dpi=110)

    print("| quantity | vertical | walls at %g° | Ponder–Nakamura–Kuroda |"
          % args.angle)
    print("|---|---|---|---|")
    print("| settling velocity of the top, first half [µm/s] | %.1f | | |"
          % (v0 * 1e6))
    early = t1 <= 0.25 * t_pnk
    rate = -np.polyfit(t1[early], h1[early], 1)[0] if early.sum() > 2 \
        else float("nan")
    print("| initial clarification rate / v0 | 1 | %.2f | %.2f |"
          % (rate / v0, 1 + HEIGHT * tan / WIDTH))
    print("| time for the top to reach half the tank [s] | %.1f | %.1f | %.1f |"
          % (0.5 * HEIGHT / v0, t_half, t_pnk))
    print("| time for the clear fluid to fill half the tank [s] | %.1f | %.1f "
          "| %.1f |" % (t_clear[0], t_clear[1], t_pnk))
    def theory(t):
        return (HEIGHT + WIDTH / tan) * math.exp(-v0 * tan * t / WIDTH) \
            - WIDTH / tan
    print("clear fluid of the leaning tank over the theory's at",
          ", ".join("%g s: %.2f" % (t, (HEIGHT - np.interp(t, t1, clear[1]))
                                    / (HEIGHT - theory(t)))
                    for t in (1, 2, 3, 5, 7)))
    print("figure:", out)


if __name__ == "__main__":
    main()
