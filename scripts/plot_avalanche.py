#!/usr/bin/env python3
"""An underwater avalanche on an inclined plane, loose and dense
(prm/avalanche_2d_loose.prm, prm/avalanche_2d_dense.prm): the layer's
velocity along the slope, its packing and the excess pore pressure under it
against time, the two side by side. Prints the table of
doc/scenes/avalanche_2d.md.

    /usr/bin/python3 scripts/plot_avalanche.py output/avalanche_2d_loose output/avalanche_2d_dense [--out avalanche.png]

From each run's statistics.csv: the layer's velocity is the mean velocity
along the slope of the grains that move (the fixed base excluded); its
packing is the initial bulk packing scaled by the height of the moving
grains' centroid above the base, which grows as the layer dilates; the
excess pore pressure is the probe under the layer, in units of the
layer's buoyant weight per area normal to the slope,
W = (rho_p - rho) g cos(theta) phi H, theta the slope of the run's
gravity vector. The layer fails when its velocity,
averaged over the last 0.1 s, first exceeds 1 mm/s (about ten times the
dense layer's creep, a tenth of the loose layer's flow), from 0.2 s on
(the release jolts both layers for a step or two); its creep is the
median velocity from the start to then.
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
from plot_scene import run_parameters  # noqa: E402

# The scenes' discs, liquid and slope (prm/avalanche_2d_*.prm); a run's
# own slope is read from its gravity vector.
RHO_P, RHO, G, THETA = 2500.0, 1010.0, 9.81, math.radians(25)
LENGTH, BASE = 9e-3, 1.5e-4
# Bulk packing and height of each prepared layer
# (prm/packings/avalanche_2d_*.prm).
PREPARED = {"loose": (0.755, 4.77e-3), "dense": (0.821, 4.38e-3)}
FAILURE_SPEED = 1e-3
SMOOTHING = 0.1


def read(directory):
    with open(os.path.join(directory, "statistics.csv")) as f:
        rows = list(csv.DictReader(f))
    column = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    n, fixed = column["particles"], column["fixed_particles"]
    moving = n - fixed
    # The moving grains' mean velocity and centroid, from all grains' and
    # the fixed ones' (at rest, their centroid fixed_centroid_y).
    column["layer_velocity"] = column["mean_velocity_x"] * n / moving
    column["layer_centroid"] = (column["centroid_y"] * n - column[
        "fixed_centroid_y"] * fixed) / moving
    return column


def slope(directory):
    """The slope from the run's gravity vector (g sin theta, -g cos theta);
    the scenes' 25 degrees where the run's parameters do not say."""
    try:
        gx, gy = (float(v) for v in
                  run_parameters(directory, "plot_avalanche.py")[
                      "Gravity/Vector"].split(","))
        return math.atan2(gx, -gy)
    except (KeyError, ValueError):
        return THETA


def analyse(directory, kind):
    """The layer's velocity, packing and excess pore pressure against time,
    and what the table prints, for one run of the @p kind of layer."""
    c = read(directory)
    phi0, height = PREPARED[kind]
    weight = (RHO_P - RHO) * G * math.cos(slope(directory)) * phi0 * height
    t = c["time"]
    lift = c["layer_centroid"] - BASE
    packing = phi0 * lift[0] / lift
    excess = c["probe_base_pressure"] / weight
    # The release jolts both layers for a step or two: the failure is
    # read on the velocity averaged over the last SMOOTHING seconds,
    # once that window has left the jolt behind.
    window = max(1, int(round(SMOOTHING / (t[2] - t[1]))))
    smooth = np.convolve(c["layer_velocity"], np.ones(window) / window,
                         mode="full")[:len(t)]
    failed = np.nonzero((smooth > FAILURE_SPEED) &
                        (t >= 2 * SMOOTHING - 1e-9))[0]
    t_fail = t[failed[0]] if len(failed) else float("nan")
    # A layer that fails within the first window has no creep.
    before = (t > 0) & (t < t_fail) if len(failed) and \
        t_fail > 2 * SMOOTHING + 1e-9 else np.zeros_like(t, bool)
    after = t >= t_fail if len(failed) else np.zeros_like(t, bool)

    def mean(values, mask):
        return float(np.mean(values[mask])) if mask.sum() else \
            float("nan")

    def over(start, end):
        """The layer's mean velocity from @p start to @p end [s]."""
        return mean(c["layer_velocity"], (t > start + 1e-9) &
                    (t <= end + 1e-9)) if t[-1] >= end - 1e-9 \
            else float("nan")
    return dict(
        kind=kind, phi0=phi0, time=t, velocity=c["layer_velocity"],
        packing=packing, excess=excess, t_fail=t_fail,
        creep=float(np.median(c["layer_velocity"][before]))
        if before.sum() else float("nan"),
        excess_before=mean(excess, before),
        packing_fail=packing[failed[0]] if len(failed) else float("nan"),
        velocity_after=mean(c["layer_velocity"], after),
        excess_after=mean(excess, after),
        excess_flowing=mean(excess, t > SMOOTHING + 1e-9),
        packing_end=packing[-1], t_end=t[-1],
        velocity_early=over(SMOOTHING, 2.0), velocity_late=over(2.0, 3.0))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("loose")
    parser.add_argument("dense")
    parser.add_argument("--out")
    args = parser.parse_args()

    figure, axes = plt.subplots(1, 3, figsize=(13, 4))
    rows = []
    for kind, directory in (("loose", args.loose), ("dense", args.dense)):
        r = analyse(directory, kind)
        rows.append(r)
        t = r["time"]
        axes[0].semilogy(t, np.maximum(r["velocity"], 1e-6), lw=1,
                         label=kind)
        axes[1].plot(t, r["packing"], lw=1, label=kind)
        axes[2].plot(t, r["excess"], lw=0.6, label=kind)
    axes[0].axhline(FAILURE_SPEED, color="k", lw=0.5, ls=":")
    axes[0].set_ylabel("velocity along the slope [m/s]")
    axes[1].set_ylabel("bulk packing of the layer")
    axes[2].set_ylabel("excess pore pressure at the base [W]")
    axes[2].axhline(0, color="k", lw=0.5)
    for a in axes:
        a.set_xlabel("t [s]")
        a.legend(fontsize=8)
    figure.tight_layout()
    out = args.out or os.path.join(args.dense, "avalanche_2d.png")
    figure.savefig(out, dpi=110)

    def cell(value, form):
        return "—" if math.isnan(value) else form % value

    print("| layer | initial packing | fails at [s] | creep before "
          "[mm/s] | excess before [W] | packing at failure | velocity "
          "after [mm/s] | excess after [W] | packing at the end |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %.3f | %s | %s | %s | %s | %s | %s | %.3f (%.0f s) |"
              % (r["kind"], r["phi0"], cell(r["t_fail"], "%.2f"),
                 cell(r["creep"] * 1e3, "%.3f"),
                 cell(r["excess_before"], "%+.3f"),
                 cell(r["packing_fail"], "%.3f"),
                 cell(r["velocity_after"] * 1e3, "%.2f"),
                 cell(r["excess_after"], "%+.3f"), r["packing_end"],
                 r["t_end"]))
    print("figure:", out)


if __name__ == "__main__":
    main()
