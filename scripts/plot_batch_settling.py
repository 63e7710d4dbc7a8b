#!/usr/bin/env python3
"""Batch settling to a bed (prm/batch_settling_3d.prm): the height of the
suspension's top and of the bed against time, beside Kynch's construction
on the seed's closure and Richardson & Zaki's velocity, and the solid
fraction profiles. Prints the table of doc/scenes/batch_settling_3d.md.

    /usr/bin/python3 scripts/plot_batch_settling.py output/batch_settling_3d [--out batch.png]

Heights come from the grains' centres written at each state, counted in
horizontal slabs of 4 radii: the top is the upper edge of the highest slab
at half the initial solid fraction or more, the bed's surface the lower
edge of the lowest slab below half-way between the initial solid fraction
and the bed's packing. The bed's packing is the mean over the slabs of the
final bed, without the slab on the floor (the floor orders the first
layer) and the two at its surface.
"""
import argparse
import math
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_scene import particle_states  # noqa: E402

# The scene's column, beads and fluid (prm/batch_settling_3d.prm).
WIDTH, HEIGHT, RADIUS = 4e-4, 3.2e-3, 12.5e-6
RHO_P, RHO, MU, G = 2400.0, 1200.0, 0.12, 9.81
SLAB = 4 * RADIUS
# The seed's law at Re -> 0: a lone bead settles at V_s/0.96 and a
# suspension at fluid fraction e at e^4.8 of that (doc/theory.md section 3).
V_STOKES = 2 / 9 * (RHO_P - RHO) * G * RADIUS ** 2 / MU
V_LONE = V_STOKES / 0.96
EXPONENT = 4.8


def states(directory):
    """(time, z of every grain) of every written state of a run."""
    return [(t, x[:, 2]) for t, x in
            particle_states(directory, "plot_batch_settling.py")]


def profile(z):
    """Solid fraction in the slabs from the floor up."""
    slabs = int(round(HEIGHT / SLAB))
    counts = np.histogram(z, bins=slabs, range=(0, HEIGHT))[0]
    return counts * (4 / 3 * math.pi * RADIUS ** 3) / (WIDTH ** 2 * SLAB)


def top(fraction, phi0, slab=SLAB):
    """The upper edge of the highest slab at half of phi0 or more."""
    dense = np.nonzero(fraction >= 0.5 * phi0)[0]
    return (dense[-1] + 1) * slab if len(dense) else 0.0


def bed(fraction, phi0, phi_bed, slab=SLAB, height=HEIGHT):
    """The lower edge of the lowest slab below half-way between phi0 and
    the bed's packing."""
    loose = np.nonzero(fraction < 0.5 * (phi0 + phi_bed))[0]
    return loose[0] * slab if len(loose) else height


def flux(phi):
    """Kynch's flux: the solid volume crossing a section per area and
    time, downwards, under the closure (zero net volume flux)."""
    return phi * (1 - phi) ** EXPONENT * V_LONE


def kynch_bed_speed(phi0, phi_bed):
    """Rise speed of the bed in Kynch's construction: the slope of the
    lower convex hull of the flux between phi0 and the bed (where the flux
    is 0) at the bed's end. A direct shock when the chord lies under the
    flux curve; otherwise the hull's last segment."""
    phis = np.linspace(phi0, phi_bed, 4001)
    values = flux(phis)
    values[-1] = 0.0
    hull = []
    for i in range(len(phis)):
        while len(hull) >= 2:
            a, b = hull[-2], hull[-1]
            cross = (phis[b] - phis[a]) * (values[i] - values[a]) - (
                values[b] - values[a]) * (phis[i] - phis[a])
            if cross <= 0:
                hull.pop()
            else:
                break
        hull.append(i)
    before = hull[-2]
    return values[before] / (phi_bed - phis[before]), len(hull) == 2


def fit_speed(t, h, mask):
    return -np.polyfit(t[mask], h[mask], 1)[0] if mask.sum() > 2 \
        else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run")
    parser.add_argument("--out")
    args = parser.parse_args()
    run = states(args.run)
    n = len(run[0][1])
    phi0 = n * 4 / 3 * math.pi * RADIUS ** 3 / (WIDTH ** 2 * HEIGHT)
    times = np.array([t for t, _ in run])
    profiles = [profile(z) for _, z in run]

    final = profiles[-1]
    surface = top(final, phi0)
    inside = np.arange(len(final))[1:max(2, int(round(surface / SLAB)) - 2)]
    phi_bed = float(final[inside].mean())
    tops = np.array([top(p, phi0) for p in profiles])
    beds = np.array([bed(p, phi0, phi_bed) for p in profiles])

    # Speeds over the time both fronts are clear of each other and of the
    # ends: the top below 0.95 H, the two more than 0.25 H apart.
    clear = (tops < 0.95 * HEIGHT) & (tops - beds > 0.25 * HEIGHT) & (
        beds > 2 * SLAB)
    top_speed = fit_speed(times, tops, clear)
    bed_speed = -fit_speed(times, beds, clear)

    eps0 = 1 - phi0
    v_closure = eps0 ** EXPONENT * V_LONE
    v_rz = eps0 ** 4.65 * V_LONE
    v_gad = eps0 ** 5.1 * V_LONE
    kynch, direct = kynch_bed_speed(phi0, phi_bed)
    meet_kynch = HEIGHT / (v_closure + kynch)
    h_final = phi0 * HEIGHT / phi_bed
    met = np.nonzero(tops - beds <= 2 * SLAB)[0]
    meet = times[met[0]] if len(met) else float("nan")

    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4.5))
    left.plot(times, tops * 1e3, "o", ms=3, label="top of the suspension")
    left.plot(times, beds * 1e3, "s", ms=3, label="surface of the bed")
    grid = np.linspace(0, times[-1], 200)
    kynch_top = np.maximum(HEIGHT - v_closure * grid, h_final)
    kynch_bed = np.minimum(kynch * grid, h_final)
    left.plot(grid, kynch_top * 1e3, "k-", lw=1,
              label="Kynch, closure's flux")
    left.plot(grid, kynch_bed * 1e3, "k-", lw=1)
    left.plot(grid, np.maximum(HEIGHT - v_rz * grid, h_final) * 1e3, "k:",
              lw=1, label="Richardson–Zaki, n = 4.65")
    left.set_xlabel("t [s]")
    left.set_ylabel("height [mm]")
    left.set_ylim(0, HEIGHT * 1.05e3)
    left.legend(fontsize=8)
    centres = (np.arange(len(final)) + 0.5) * SLAB * 1e3
    picks = sorted({int(k) for k in np.linspace(0, len(run) - 1, 6)})
    for k in picks:
        right.plot(profiles[k], centres, lw=1, label="t = %.0f s" % times[k])
    right.set_xlabel("solid fraction (slabs of 4 r)")
    right.set_ylabel("height [mm]")
    right.set_xlim(0, 0.75)
    right.set_ylim(0, HEIGHT * 1.05e3)
    right.legend(fontsize=8)
    figure.tight_layout()
    out = args.out or os.path.join(args.run, "batch_settling_3d.png")
    figure.savefig(out, dpi=110)

    print("| quantity | simulated | prediction | source |")
    print("|---|---|---|---|")
    print("| initial solid fraction φ0 | %.4f | | |" % phi0)
    print("| top of the suspension [µm/s] | %.3f | %.3f | closure, "
          "ε^4.8 V_s/0.96 |" % (top_speed * 1e6, v_closure * 1e6))
    print("| | | %.3f | Richardson & Zaki, n = 4.65 |" % (v_rz * 1e6))
    print("| | | %.3f | Garside & Al-Dibouni at low Re, n = 5.1 |"
          % (v_gad * 1e6))
    print("| packing of the bed | %.3f | 0.64 | random close packing |"
          % phi_bed)
    print("| rise of the bed [µm/s] | %.3f | %.3f | Kynch (%s) with "
          "the measured packing |" % (bed_speed * 1e6, kynch * 1e6,
                                      "a direct shock" if direct else
                                      "the hull's last chord"))
    print("| fronts meet [s] | %.0f | %.0f | Kynch |" % (meet, meet_kynch))
    print("| final height of the bed [mm] | %.3f | %.3f | φ0 H / packing |"
          % (surface * 1e3, h_final * 1e3))
    print("figure:", out)


if __name__ == "__main__":
    main()
