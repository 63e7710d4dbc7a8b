#!/usr/bin/env python3
"""Batch settling of two sizes (prm/batch_settling_two_sizes_3d.prm): the
fronts against time beside the Masliyah / Lockett-Al-Habbooby balance and
Lockett & Bassoon's construction, the small beads' layer, and the
segregated bed. Prints the table of doc/scenes/batch_settling_two_sizes_3d.md.

    /usr/bin/python3 scripts/plot_batch_settling_sizes.py output/batch_settling_two_sizes_3d [--out sizes.png]

Heights come from the grains' centres and radii written at each state,
counted per size in horizontal slabs of 4 small radii:
  - the top of the suspension: the upper edge of the highest slab where
    the small beads fill half their initial fraction or more;
  - the top of the mixture: the same for the large beads;
  - the bed's surface: the lower edge of the lowest slab whose solid
    fraction lies below half-way between the initial one and the bed's.
The small beads' fraction in their own layer is the mean over the slabs
more than two slabs inside both of its edges, over the states where the
layer is at least six slabs thick and the top of the mixture below it
lies more than four filter lengths above the bed. The top of the large
beads is fitted over the same states.
"""
import argparse
import glob
import math
import os
import re
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_batch_settling import bed, fit_speed, top  # noqa: E402
from plot_scene import particle_states  # noqa: E402

# The scene's column, beads and fluid (prm/batch_settling_two_sizes_3d.prm).
WIDTH, HEIGHT = 4e-4, 3.2e-3
FILTER = 2e-4
RHO_P, RHO, MU, G = 2400.0, 1200.0, 0.12, 9.81
def stokes(a):
    """A lone bead's Stokes velocity."""
    return 2 / 9 * (RHO_P - RHO) * G * a ** 2 / MU


def slips(phis, radii, law):
    """Each size's slip w_k in a mixture at Re -> 0 (doc/theory.md section
    3): the pressure gradient carries the mixture's excess weight, so
    w_k = U_k/F_k with F_k the law's normalised drag. The seed's law
    (Dallavalle-Wen-Yu): F = e^-3.8 times 0.96, its lone-grain limit.
    Yin & Sundaresan: F_k = 1/e + (F_B - 1/e)(c y_k + (1 - c) y_k^2) with
    Beetstra's F_B = 10 s/e^2 + e^2 (1 + 1.5 sqrt(s)), s = 1 - e, and
    y_k = a_k/<a>, <a> the Sauter mean."""
    eps = 1 - sum(phis)
    if law == "Yin-Sundaresan":
        s = 1 - eps
        beetstra = 10 * s / eps ** 2 + eps ** 2 * (1 + 1.5 * math.sqrt(s))
        c = 1 - 2.66 * s + 9.096 * s ** 2 - 11.338 * s ** 3
        mean = sum(phis) / sum(p / a for p, a in zip(phis, radii)) \
            if sum(phis) > 0 else radii[0]
        return [stokes(a) / (1 / eps + (beetstra - 1 / eps) *
                             (c * a / mean + (1 - c) * (a / mean) ** 2))
                for a in radii]
    return [eps ** 3.8 * stokes(a) / 0.96 for a in radii]


def mixture_velocities(phis, radii, law):
    """Settling velocity (downwards) of each size in a mixture: its slip
    less the fluid's return flow sum phi_j w_j (Masliyah 1979)."""
    w = slips(phis, radii, law)
    back = sum(p * wk for p, wk in zip(phis, w))
    return [wk - back for wk in w]


def one_size(phi, a, law):
    """Settling velocity of one size alone at solid fraction phi."""
    return mixture_velocities([phi], [a], law)[0]


def small_layer(phis, radii, law):
    """The small beads' fraction and velocity in the layer the large ones
    leave (Lockett & Bassoon 1979): across the top of the mixture, which
    falls with the large beads at v_1, the small beads' flux is continuous,
    phi' (v(phi') - v_1) = phi_0 (v_0 - v_1), v the small beads' velocity
    alone. The root on the branch of the initial fraction (bisection)."""
    v = mixture_velocities(phis, radii, law)
    target = phis[0] * (v[0] - v[1])

    def residual(p):
        return p * (one_size(p, radii[0], law) - v[1]) - target

    lo, hi = 1e-6, 0.3
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if residual(lo) * residual(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    return p, one_size(p, radii[0], law)


def drag_law(directory):
    """The drag law of the run: the copy of its scene file in its output
    directory names it (the seed's law when it does not)."""
    for name in glob.glob(os.path.join(directory, "*.prm")):
        for line in open(name):
            m = re.match(r"\s*set\s+Drag law\s*=\s*(\S+)", line)
            if m:
                return m.group(1)
    return "Dallavalle-Wen-Yu"


def profiles(z, r, radii, slab, height):
    """Solid fraction of each class in the slabs from the floor up."""
    slabs = int(round(height / slab))
    out = []
    for a in radii:
        mine = np.abs(r - a) < 1e-3 * a
        counts = np.histogram(z[mine], bins=slabs, range=(0, height))[0]
        out.append(counts * (4 / 3 * math.pi * a ** 3) / (WIDTH ** 2 * slab))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run")
    parser.add_argument("--out")
    parser.add_argument("--height", type=float, default=HEIGHT,
                        help="the column's height [m] (reduced runs)")
    args = parser.parse_args()
    height = args.height
    run = particle_states(args.run, "plot_batch_settling_sizes.py",
                          ("radius", "velocity"))
    r0 = run[0][2]["radius"]
    radii = sorted(set(np.round(r0, 12)))
    if len(radii) != 2:
        sys.exit("plot_batch_settling_sizes.py: %s has %d sizes, not two"
                 % (args.run, len(radii)))
    slab = 4 * radii[0]
    phis = [float(np.sum(np.abs(r0 - a) < 1e-3 * a)) * 4 / 3 * math.pi *
            a ** 3 / (WIDTH ** 2 * height) for a in radii]
    phi0 = sum(phis)
    times = np.array([s[0] for s in run])
    per_class = [profiles(x[:, 2], f["radius"], radii, slab, height)
                 for _, x, f in run]
    totals = [p[0] + p[1] for p in per_class]

    # The bed's packing: the final bed's slabs without the floor's and the
    # two at its surface.
    final = totals[-1]
    surface = top(final, phi0, slab)
    inside = np.arange(len(final))[1:max(2, int(round(surface / slab)) - 2)]
    phi_bed = float(final[inside].mean())

    tops = np.array([top(p[0], phis[0], slab) for p in per_class])
    mixtures = np.array([top(p[1], phis[1], slab) for p in per_class])
    beds = np.array([bed(t, phi0, phi_bed, slab, height) for t in totals])

    # Predictions.
    law = drag_law(args.run)
    v = mixture_velocities(phis, radii, law)
    phi_layer, v_layer = small_layer(phis, radii, law)
    bed_rise = (phis[0] * v[0] + phis[1] * v[1]) / (phi_bed - phi0)
    t_mixed = height / (v[1] + bed_rise)
    h_mixed = bed_rise * t_mixed
    bed_rise_small = phi_layer * v_layer / (phi_bed - phi_layer)
    t_meet = t_mixed + (height - v_layer * t_mixed - h_mixed) / (
        v_layer + bed_rise_small)
    # The lower bed takes each class at its flux through the rising front,
    # phi_k (v_k + s); its large share of the solid volume:
    fluxes = [p * (vk + bed_rise) for p, vk in zip(phis, v)]
    large_share_lower = fluxes[1] / sum(fluxes)

    # Measured speeds over the states where the fronts are clear of each
    # other and of the ends.
    clear_top = (tops < 0.95 * height) & (tops - mixtures > 4 * slab)
    clear_mix = (mixtures < 0.95 * height) & (mixtures - beds > 4 * slab) & (
        beds > 2 * slab)
    # The top of the mixture while the filter's tail from the bed does not
    # reach it (within 4 l the beads read part of the bed's fraction).
    clear_front = clear_mix & (mixtures - beds > 4 * FILTER)
    top_speed = fit_speed(times, tops, clear_top)
    mix_speed = fit_speed(times, mixtures, clear_front)
    bed_speed = -fit_speed(times, beds, clear_mix)
    layer = []
    for k, p in enumerate(per_class):
        lo = int(round(mixtures[k] / slab)) + 2
        hi = int(round(tops[k] / slab)) - 2
        if hi - lo >= 2 and tops[k] - mixtures[k] >= 6 * slab and \
                clear_front[k]:
            layer.append(p[0][lo:hi].mean())
    phi_layer_measured = float(np.mean(layer)) if layer else float("nan")
    # Each size's velocity inside the mixture and the small beads' in their
    # layer, over every state after the start: the grains more than two
    # filter lengths (FILTER, the scene's Smoothing length) from the zones'
    # edges, and four from the bed's surface (the filter's exponential tail
    # carries the bed's solid fraction that far).
    inside = [[], [], []]
    for k, (_, x, f) in enumerate(run):
        if k == 0:
            continue
        z, vz = x[:, 2], -f["velocity"][:, 2]
        small = np.abs(f["radius"] - radii[0]) < 1e-3 * radii[0]
        mixed = (z > beds[k] + 4 * FILTER) & (z < mixtures[k] - 2 * FILTER)
        alone = (z > mixtures[k] + 2 * FILTER) & (z > beds[k] + 4 * FILTER) \
            & (z < tops[k] - 2 * FILTER)
        for group, mask in enumerate((mixed & small, mixed & ~small,
                                      alone & small)):
            inside[group].extend(vz[mask])
    measured_v = [float(np.mean(g)) if g else float("nan") for g in inside]
    met = np.nonzero(tops - beds <= 2 * slab)[0]
    meet = times[met[0]] if len(met) else float("nan")

    # The final bed: the large beads' share of the solid in each slab.
    share = per_class[-1][1] / np.maximum(final, 1e-12)
    in_bed = np.arange(len(final))[1:int(round(surface / slab)) - 1]
    lower = in_bed[share[in_bed] > 0.5]
    upper = in_bed[share[in_bed] <= 0.5]
    large_share_measured = float(share[lower].mean()) if len(lower) else \
        float("nan")
    small_cap = (surface - (lower[-1] + 1) * slab) if len(lower) else \
        float("nan")
    small_cap_predicted = (height * phis[0] - (1 - large_share_lower) /
                           large_share_lower * height * phis[1]) / phi_bed

    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4.5))
    left.plot(times, tops * 1e3, "o", ms=3, label="top of the small beads")
    left.plot(times, mixtures * 1e3, "^", ms=3,
              label="top of the large beads")
    left.plot(times, beds * 1e3, "s", ms=3, label="surface of the bed")
    grid = np.linspace(0, times[-1], 400)
    h_final = phi0 * height / phi_bed
    bed_line = np.where(grid < t_mixed, bed_rise * grid,
                        h_mixed + bed_rise_small * (grid - t_mixed))
    bed_line = np.minimum(bed_line, h_final)
    left.plot(grid, np.maximum(height - v_layer * grid, bed_line) * 1e3,
              "k-", lw=1, label="Masliyah balance, Lockett & Bassoon")
    left.plot(grid, np.maximum(height - v[1] * grid, bed_line) * 1e3,
              "k-", lw=1)
    left.plot(grid, bed_line * 1e3, "k-", lw=1)
    left.set_xlabel("t [s]")
    left.set_ylabel("height [mm]")
    left.set_ylim(0, height * 1.05e3)
    left.legend(fontsize=8)
    centres = (np.arange(len(final)) + 0.5) * slab * 1e3
    picks = sorted({int(k) for k in np.linspace(0, len(run) - 1, 4)})
    for n, k in enumerate(picks):
        colour = "C%d" % n
        right.plot(per_class[k][0], centres, "-", color=colour, lw=1,
                   label="small, t = %.0f s" % times[k])
        right.plot(per_class[k][1], centres, "--", color=colour, lw=1,
                   label="large, t = %.0f s" % times[k])
    right.set_xlabel("solid fraction of each size (slabs of 4 a)")
    right.set_ylabel("height [mm]")
    right.set_xlim(0, 0.7)
    right.set_ylim(0, height * 1.05e3)
    right.legend(fontsize=7)
    figure.tight_layout()
    out = args.out or os.path.join(args.run, "batch_settling_sizes.png")
    figure.savefig(out, dpi=110)

    def um(x):
        return "%.3f" % (x * 1e6)

    print("drag law:", law)
    print("| quantity | simulated | prediction |")
    print("|---|---|---|")
    print("| initial solid fractions, small / large | %.4f / %.4f | |"
          % tuple(phis))
    print("| small beads in the mixture [µm/s] | %s | %s |"
          % (um(measured_v[0]), um(v[0])))
    print("| large beads in the mixture [µm/s] | %s | %s |"
          % (um(measured_v[1]), um(v[1])))
    print("| small beads in their layer [µm/s] | %s | %s |"
          % (um(measured_v[2]), um(v_layer)))
    print("| top of the small beads [µm/s] | %s | %s |"
          % (um(top_speed), um(v_layer)))
    print("| small beads' fraction in their layer | %.4f | %.4f |"
          % (phi_layer_measured, phi_layer))
    print("| top of the large beads [µm/s] | %s | %s |"
          % (um(mix_speed), um(v[1])))
    print("| rise of the bed under the mixture [µm/s] | %s | %s |"
          % (um(bed_speed), um(bed_rise)))
    print("| packing of the bed | %.3f | |" % phi_bed)
    print("| large beads reach the bed [s] | %s | %.0f |"
          % ("%.0f" % times[np.nonzero(mixtures - beds <= 2 * slab)[0][0]]
             if np.any(mixtures - beds <= 2 * slab) else "-", t_mixed))
    print("| fronts meet [s] | %.0f | %.0f |" % (meet, t_meet))
    print("| large beads' share of the lower bed | %.3f | %.3f |"
          % (large_share_measured, large_share_lower))
    print("| layer of small beads on the bed [mm] | %.3f | %.3f |"
          % (small_cap * 1e3, small_cap_predicted * 1e3))
    print("| final height of the bed [mm] | %.3f | %.3f |"
          % (surface * 1e3, h_final * 1e3))
    print("figure:", out)


if __name__ == "__main__":
    main()
