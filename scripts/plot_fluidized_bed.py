#!/usr/bin/env python3
"""The fluidization curve and the bed's expansion of a fluidized bed
(prm/fluidized_bed_3d.prm), against Ergun's law, the buoyant weight and
Richardson-Zaki with the Garside-Al-Dibouni exponent. Prints the table of
doc/scenes/fluidized_bed_3d.md.

    /usr/bin/python3 scripts/plot_fluidized_bed.py output/fluidized_bed_3d [--out bed.png]

The superficial velocity is the measured flow rate through the floor over
the cross-section (boundary_flux_4 / A); the pressure drop is
pressure_drop (floor to top), averaged over bins of U on the way up and
on the way down; the bed's voidage is 1 - packing_fraction.
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

# The scene's material (prm/fluidized_bed_3d.prm).
D, RHO_P, RHO_F, MU, G = 1e-3, 2500.0, 1000.0, 1e-3, 9.81


def terminal_velocity(d=D):
    """A lone sphere's settling velocity with Dallavalle's drag,
    C_D = (0.63 + 4.8 / sqrt(Re))^2 (bisection on the force balance)."""
    lo, hi = 1e-6, 10.0
    for _ in range(200):
        v = 0.5 * (lo + hi)
        re = RHO_F * v * d / MU
        cd = (0.63 + 4.8 / math.sqrt(re)) ** 2
        if 0.75 * cd * RHO_F * v * v / d > (RHO_P - RHO_F) * G:
            hi = v
        else:
            lo = v
    return v


def richardson_zaki_exponent(v_t, d=D):
    """Garside & Al-Dibouni's n = (5.1 + 0.27 Re_t^0.9) / (1 + 0.1 Re_t^0.9)
    at a lone grain's settling Reynolds number."""
    k = 0.1 * (RHO_F * v_t * d / MU) ** 0.9
    return (5.1 + 2.7 * k) / (1 + k)


def ergun_gradient(u, eps):
    """Ergun's pressure gradient through a packed bed [Pa/m]."""
    return (150 * MU * u * (1 - eps) ** 2 / (eps ** 3 * D ** 2)
            + 1.75 * RHO_F * u * u * (1 - eps) / (eps ** 3 * D))


def binned(u, values, weights, edges):
    centres, means = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        inside = (u >= a) & (u < b)
        if weights[inside].sum() > 0:
            centres.append(0.5 * (a + b))
            means.append(np.average(values[inside], weights=weights[inside]))
    return np.array(centres), np.array(means)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("directory")
    parser.add_argument("--out")
    args = parser.parse_args()
    path = os.path.join(args.directory, "statistics.csv")
    if not os.path.exists(path):
        sys.exit("plot_fluidized_bed.py: no statistics.csv in " + args.directory)
    with open(path) as f:
        rows = list(csv.DictReader(f))
    col = {k: np.array([float(r[k]) for r in rows[1:]])
           for k in ("time", "dt", "pressure_drop", "boundary_flux_4",
                     "packing_fraction", "particles", "grains_max_z")}
    area = 0.01 * 0.01
    n = col["particles"][-1]
    weight = n * (RHO_P - RHO_F) * math.pi / 6 * D ** 3 * G / area
    u = -col["boundary_flux_4"] / area
    t, dt = col["time"], col["dt"]
    turn = t[np.argmax(u)]
    up, down = (t > 0.5) & (t <= turn), t > turn
    edges = np.linspace(0, u.max() * 1.0001, 25)
    u_up, dp_up = binned(u[up], col["pressure_drop"][up], dt[up], edges)
    u_dn, dp_dn = binned(u[down], col["pressure_drop"][down], dt[down], edges)
    _, eps_up = binned(u[up], 1 - col["packing_fraction"][up], dt[up], edges)
    _, eps_dn = binned(u[down], 1 - col["packing_fraction"][down], dt[down],
                       edges)

    # The packed bed as poured (before the flow starts), and Ergun's
    # minimum fluidization for it: the U where its pressure drop is the
    # buoyant weight.
    eps0 = 1 - col["packing_fraction"][t <= 0.5][-1]
    height0 = n * math.pi / 6 * D ** 3 / (area * (1 - eps0))
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if ergun_gradient(mid, eps0) * height0 > weight:
            hi = mid
        else:
            lo = mid
    u_mf_ergun = lo
    archimedes = RHO_F * (RHO_P - RHO_F) * G * D ** 3 / MU ** 2
    u_mf_wen_yu = (math.sqrt(33.7 ** 2 + 0.0408 * archimedes) - 33.7) * MU / (
        RHO_F * D)
    # Measured minimum fluidization: where a straight line through the
    # packed part of the rising branch (below 70 % of the weight) reaches
    # the weight.
    packed = dp_up < 0.7 * weight
    slope = np.sum(u_up[packed] * dp_up[packed]) / np.sum(u_up[packed] ** 2)
    u_mf = weight / slope
    v_t = terminal_velocity()
    n_rz = richardson_zaki_exponent(v_t)

    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4.2))
    left.plot(u_up * 1e3, dp_up / weight, "o-", ms=4, label="rising U")
    left.plot(u_dn * 1e3, dp_dn / weight, "s-", ms=4, mfc="none",
              label="falling U")
    grid = np.linspace(0, u.max(), 100)
    left.plot(grid * 1e3, np.minimum(ergun_gradient(grid, eps0) * height0,
                                     1e9) / weight, "k--", lw=1,
              label="Ergun, bed as poured (ε = %.3f)" % eps0)
    left.axhline(1, color="k", lw=1, label="buoyant weight")
    left.axvline(u_mf_wen_yu * 1e3, color="0.6", ls=":",
                 label="Wen–Yu U_mf")
    left.set_ylim(0, 1.4)
    left.set_xlabel("superficial velocity U [mm/s]")
    left.set_ylabel("pressure drop / buoyant weight per area")
    left.legend(fontsize=8, loc="lower right")
    fluid = dp_up > 0.95 * weight
    right.plot(u_up[fluid] * 1e3, eps_up[fluid], "o", ms=4, label="rising U")
    fluid_dn = dp_dn > 0.95 * weight
    right.plot(u_dn[fluid_dn] * 1e3, eps_dn[fluid_dn], "s", ms=4, mfc="none",
               label="falling U")
    grid = np.linspace(u_mf * 0.8, u.max(), 100)
    right.plot(grid * 1e3, (grid / v_t) ** (1 / n_rz), "k-", lw=1,
               label="Richardson–Zaki, n = %.2f, v_t = %.0f mm/s"
               % (n_rz, v_t * 1e3))
    right.set_xlabel("superficial velocity U [mm/s]")
    right.set_ylabel("bed voidage ε = 1 − packing_fraction")
    right.legend(fontsize=8, loc="lower right")
    figure.tight_layout()
    out = args.out or os.path.join(args.directory, "fluidized_bed_3d.png")
    figure.savefig(out, dpi=110)

    print("| quantity | this run | reference |")
    print("|---|---|---|")
    print("| minimum fluidization U_mf [mm/s] | %.1f | %.1f (Ergun, ε = %.3f);"
          " %.1f (Wen–Yu) |" % (u_mf * 1e3, u_mf_ergun * 1e3, eps0,
                                u_mf_wen_yu * 1e3))
    plateau = np.concatenate([dp_up[u_up > 1.5 * u_mf],
                              dp_dn[u_dn > 1.5 * u_mf]])
    print("| pressure drop above 1.5 U_mf / buoyant weight | %.3f ± %.3f |"
          " 1 |" % (plateau.mean() / weight, plateau.std() / weight))
    for target in (0.02, 0.03, 0.04):
        measured = ["%.3f" % e[np.argmin(abs(x - target))]
                    for x, e in ((u_up, eps_up), (u_dn, eps_dn)) if len(x)]
        print("| voidage at U = %d mm/s (rising, falling) | %s |"
              " %.3f (Richardson–Zaki) |"
              % (target * 1e3, ", ".join(measured),
                 (target / v_t) ** (1 / n_rz)))
    print("figure:", out)


if __name__ == "__main__":
    main()
