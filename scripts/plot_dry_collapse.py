#!/usr/bin/env python3
"""A granular column collapsing dry: each run's column at the release and
its deposit at the end, and a table of the run-outs against the dry
experiments' band. The ready scene (doc/scenes/column_collapse_2d.md,
"The same column dry"):

    build/immersed-grains prm/column_collapse_2d_dry.prm
    /usr/bin/python3 scripts/plot_dry_collapse.py output/column_collapse_2d_dry --out column_collapse_2d_dry.png

Any number of runs, one panel each. The run-out is (L - L0)/L0, L the
front of the deposit: the x beyond which 1 % of the grains lie (so that a
lone grain rolling ahead does not count), L0 the largest x at the
release; both are grains' centres, the column against the wall at x = 0.
The aspect ratio a = H0/L0, H0 the largest y at the release. Dry columns
this short run out 1.2 a (Lube et al. 2005) to 1.8 a (Lajeunesse et al.
2005, glass beads).
"""
import argparse
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_scene import particle_states  # noqa: E402

# The linear fits of the dry experiments' run-outs, (L - L0)/L0 = k a.
LUBE, LAJEUNESSE = 1.2, 1.8


def front(x):
    """The x beyond which 1 % of the grains lie."""
    x = np.sort(x)
    return x[len(x) - 1 - len(x) // 100]


def measure(directory):
    states = particle_states(directory, "plot_dry_collapse.py")
    if len(states) < 2:
        sys.exit("plot_dry_collapse.py: %s has no state after the release"
                 % directory)
    (t0, first), (t1, last) = states[0], states[-1]
    L0, H0 = first[:, 0].max(), first[:, 1].max()
    return dict(name=os.path.basename(os.path.normpath(directory)),
                first=first, last=last, time=t1, L0=L0, H0=H0, a=H0 / L0,
                run_out=(front(last[:, 0]) - L0) / L0,
                height=last[:, 1].max() / H0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("runs", nargs="+", help="output directories")
    parser.add_argument("--out", default="column_collapse_2d_dry.png")
    args = parser.parse_args()
    runs = [measure(d) for d in args.runs]

    print("| run | a | t [s] | run-out (L - L0)/L0 | / a | H/H0 |")
    print("|---|---|---|---|---|---|")
    for r in runs:
        print("| %s | %.2f | %.2f | %.2f | %.2f | %.2f |"
              % (r["name"], r["a"], r["time"], r["run_out"],
                 r["run_out"] / r["a"], r["height"]))
    print("experiments: (L - L0)/L0 = %.1f a to %.1f a" % (LUBE, LAJEUNESSE))

    right = max(r["last"][:, 0].max() for r in runs) * 1e3
    top = max(r["H0"] for r in runs) * 1e3
    fig, axes = plt.subplots(len(runs), 1, sharex=True, squeeze=False,
                             figsize=(8, 0.4 + 1.3 * len(runs)))
    for ax, r in zip(axes[:, 0], runs):
        ax.scatter(r["first"][:, 0] * 1e3, r["first"][:, 1] * 1e3, s=1,
                   color="0.8", label="release")
        ax.scatter(r["last"][:, 0] * 1e3, r["last"][:, 1] * 1e3, s=1,
                   color="C0", label="t = %.2f s" % r["time"])
        # The band of the experiments' fronts.
        ax.axvspan((1 + LUBE * r["a"]) * r["L0"] * 1e3,
                   (1 + LAJEUNESSE * r["a"]) * r["L0"] * 1e3,
                   color="C2", alpha=0.2, label="experiments' front")
        ax.axvline(front(r["last"][:, 0]) * 1e3, color="C3", lw=0.8,
                   label="front (1 %)")
        ax.set_xlim(0, right * 1.02)
        ax.set_ylim(0, top * 1.05)
        ax.set_aspect("equal")
        ax.set_title("%s: run-out %.2f = %.2f a" %
                     (r["name"], r["run_out"], r["run_out"] / r["a"]),
                     fontsize=9)
        ax.set_ylabel("y [mm]")
    axes[0, 0].legend(fontsize=7, loc="upper right", markerscale=4)
    axes[-1, 0].set_xlabel("x [mm]")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print("wrote " + args.out)


if __name__ == "__main__":
    main()
