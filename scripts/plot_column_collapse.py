#!/usr/bin/env python3
"""A granular column collapsing in a viscous liquid, loose and dense: the
run-out against time, the excess pore pressure under the column, and the
column and its deposit, for two runs whose statistics have the probe
`base` (Output/Probes) and whose particles were written at the release and
at the end. Prints a table of what it measured. The ready scenes
(doc/scenes/column_collapse_2d.md):

    build/immersed-grains prm/column_collapse_2d_loose.prm
    build/immersed-grains prm/column_collapse_2d_dense.prm
    /usr/bin/python3 scripts/plot_column_collapse.py output/column_collapse_2d_loose output/column_collapse_2d_dense

or their first 0.5 s, the runs of the test column_collapse_2d
(doc/validation.md, "Column collapse in a viscous liquid"):

    cd build && ctest -R column_collapse_2d && cd ..
    /usr/bin/python3 scripts/plot_column_collapse.py build/tests/column_collapse_2d.release/loose build/tests/column_collapse_2d.release/dense --out collapse.png

The run-out is (L - L0)/L0, L the largest x a grain's centre reaches
(statistics column grains_max_x), L0 its value at the release; the column
stands against the wall at x = 0. The excess pore pressure is the probe
`base` (statistics column probe_base_pressure, the pressure minus the
hydrostatic part) in units of the column's buoyant weight per area
W = (rho_p - rho) g (sum of the discs' areas) / L0; for a 3D slab,
periodic across its thickness T, W = (rho_p - rho) g (sum of the beads'
volumes) / (L0 T), T read from the box of the run's parameter file
(or --thickness). The packing inside the mass is measured on each written
state of the particles (bulk_packing: bins of two diameters inside the
mass, its edges, the wall and the floor left out). A collapse repeats only to within a spread: runs with
the time step 1-4 % off end at run-outs up to a fifth apart. `--repeat LOOSE
DENSE` (as often as wanted) adds such runs of the two scenes: their run-outs are drawn as thin lines,
and a second table gives each measure's mean and range over all the pairs.
The 3D slabs (doc/scenes/column_collapse_2d.md, "A 3D slab of beads"):

    build/immersed-grains prm/column_collapse_3d_slab_loose.prm
    build/immersed-grains prm/column_collapse_3d_slab_dense.prm
    /usr/bin/python3 scripts/plot_column_collapse.py output/column_collapse_3d_slab_loose output/column_collapse_3d_slab_dense --out column_collapse_3d_slab.png
"""
import argparse
import csv
import glob
import math
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_scene import particle_states, read_vtu, run_parameters  # noqa: E402

# The discs and liquid of Rondon et al. (2011), as in column_collapse_2d.
RHO_P, RHO, G = 2500.0, 1010.0, 9.81
# Before this the release shears the column's base and the excess pore
# pressure is negative under both packings (to 0.17 s under the loose
# column of column_collapse_2d): the mean excess is taken after it.
TRANSIENT = 0.2


def statistics(directory):
    path = os.path.join(directory, "statistics.csv")
    try:
        with open(path) as f:
            rows = list(csv.DictReader(f))
    except OSError:
        sys.exit("plot_column_collapse.py: cannot read " + path)
    for column in ("time", "grains_max_x", "grains_max_y",
                   "probe_base_pressure"):
        if not rows or column not in rows[0]:
            sys.exit("plot_column_collapse.py: no column %s in %s"
                     % (column, path))
    s = {k: np.array([float(r[k]) for r in rows]) for k in
         ("time", "dt", "grains_max_x", "grains_max_y",
          "probe_base_pressure")}
    s["dim"] = 3 if "grains_max_z" in rows[0] else 2
    return s


def grain_measure(directory, dim):
    """The discs' total area (2D) or the beads' total volume (3D), from the
    radii of the first written state."""
    first = sorted(glob.glob(os.path.join(directory, "particles_00000*.vtu")))
    if not first:
        sys.exit("plot_column_collapse.py: no particles_00000*.vtu in "
                 + directory)
    radii = np.concatenate([read_vtu(f)[1]["radius"] for f in first])
    if dim == 2:
        return float(np.sum(math.pi * radii ** 2))
    return float(np.sum(4.0 / 3.0 * math.pi * radii ** 3))


def box_thickness(directory):
    """The z extent of the box in the run's copy of its parameter file."""
    prm = run_parameters(directory, "plot_column_collapse.py")
    try:
        lower, upper = ([float(v) for v in prm["Mesh/%s corner" % k].split(",")]
                        for k in ("Lower", "Upper"))
        return upper[2] - lower[2]
    except (KeyError, IndexError, ValueError):
        sys.exit("plot_column_collapse.py: no 3D box corners in the "
                 "parameter file in %s; give --thickness" % directory)


def bulk_packing(centres, radii, dim, thickness):
    """The packing inside the mass: the x-y plane cut into square bins of
    two mean diameters, the grains' area (3D: volume over the slab's
    thickness) in the bins that hold grains and whose neighbours to the
    left, to the right and above hold grains too, over those bins' area.
    The bins along the wall (x = 0) and the floor are left out (grains
    layer against a wall), and so are the edges of the mass."""
    size = 4.0 * float(np.mean(radii))
    amount = (math.pi * radii ** 2 if dim == 2 else
              4.0 / 3.0 * math.pi * radii ** 3 / thickness)
    ix = np.floor(centres[:, 0] / size).astype(int)
    iy = np.floor(centres[:, 1] / size).astype(int)
    grid = np.zeros((ix.max() + 2, iy.max() + 2))
    np.add.at(grid, (ix, iy), amount)
    held = grid > 0
    inside = np.zeros_like(held)
    inside[1:-1, 1:-1] = (held[1:-1, 1:-1] & held[:-2, 1:-1] & held[2:, 1:-1]
                          & held[1:-1, 2:])
    return float(grid[inside].sum() / (inside.sum() * size * size)) \
        if inside.any() else float("nan")


def measure(directory, thickness=None):
    s = statistics(directory)
    L0, H0 = s["grains_max_x"][0], s["grains_max_y"][0]
    per_area = L0
    if s["dim"] == 3:
        thickness = thickness if thickness else box_thickness(directory)
        per_area *= thickness
    W = (RHO_P - RHO) * G * grain_measure(directory, s["dim"]) / per_area
    run_out = (s["grains_max_x"] - L0) / L0
    excess = s["probe_base_pressure"] / W
    final = run_out[-1]
    # When the front first reaches 90 % of its final run-out.
    t90 = s["time"][np.argmax(run_out >= 0.9 * final)]
    # While the column flows: from the release's transient to t90 (from
    # the transient on where the front is that far before it).
    late = (s["time"] > TRANSIENT + 1e-9) & (s["time"] <= t90 + 1e-9)
    if not late.any():
        late = s["time"] > TRANSIENT + 1e-9
    states = particle_states(directory, "plot_column_collapse.py",
                             ("radius",))
    packing = np.array([bulk_packing(c, f["radius"], s["dim"], thickness)
                        for _, c, f in states])
    return dict(
        s=s, L0=L0, H0=H0, W=W, run_out=run_out, excess=excess,
        final=final, t90=t90,
        height=s["grains_max_y"][-1] / H0,
        mean_excess=float(np.sum(excess[late] * s["dt"][late])
                          / np.sum(s["dt"][late])),
        lowest=float(excess.min()), highest=float(excess.max()),
        states=[(t, c) for t, c, _ in states],
        packing_time=np.array([t for t, _, _ in states]), packing=packing,
        packing_start=packing[0], packing_lowest=float(np.nanmin(packing)),
        packing_end=packing[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("loose")
    parser.add_argument("dense")
    parser.add_argument("--out", default="column_collapse_2d.png")
    parser.add_argument("--thickness", type=float,
                        help="a 3D slab's thickness [m] (default: the z "
                        "extent of the box in the run's parameter file)")
    parser.add_argument("--repeat", nargs=2, action="append", default=[],
                        metavar=("LOOSE", "DENSE"),
                        help="another run of each scene, made to part from "
                        "the first (repeatable)")
    args = parser.parse_args()
    runs = {"loose": measure(args.loose, args.thickness),
            "dense": measure(args.dense, args.thickness)}
    repeats = [{"loose": measure(loose, args.thickness),
                "dense": measure(dense, args.thickness)}
               for loose, dense in args.repeat]
    colours = {"loose": "tab:orange", "dense": "tab:blue"}

    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5))
    ax_run, ax_p = axes[0]
    right = max(r["states"][-1][1][:, 0].max() for r in runs.values())
    top = max(r["states"][0][1][:, 1].max() for r in runs.values())
    for (name, r), ax_dep in zip(runs.items(), axes[1]):
        t = r["s"]["time"]
        ax_run.plot(t, r["run_out"], color=colours[name], label=name)
        for k, pair in enumerate(repeats):
            ax_run.plot(pair[name]["s"]["time"], pair[name]["run_out"],
                        color=colours[name], lw=0.6, alpha=0.6,
                        label=name + ", repeated" if k == 0 else None)
        ax_p.plot(t, r["excess"], color=colours[name], lw=0.8, label=name)
        for k, (time, points) in enumerate((r["states"][0],
                                            r["states"][-1])):
            ax_dep.plot(points[:, 0] * 1e3, points[:, 1] * 1e3,
                        ".", ms=1.5, color="0.7" if k == 0 else colours[name],
                        label="t = %.2f s" % time)
        ax_dep.set_xlim(0, 1.05e3 * right)
        ax_dep.set_ylim(0, 1.05e3 * top)
        ax_dep.set_aspect("equal")
        ax_dep.set_title(name + ": the column and the deposit")
        ax_dep.set_xlabel("x [mm]")
        ax_dep.set_ylabel("y [mm]")
        ax_dep.legend(markerscale=8, fontsize=8, loc="upper right")
    ax_run.set_xlabel("t [s]")
    ax_run.set_ylabel("run-out (L - L0)/L0")
    ax_run.legend()
    ax_p.axhline(0, color="k", lw=0.5)
    ax_p.axvline(TRANSIENT, color="gray", ls=":", lw=0.8)
    ax_p.set_xlabel("t [s]")
    ax_p.set_ylabel("excess pore pressure at the base / W")
    ax_p.legend()
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)

    print("| | loose | dense |")
    print("|---|---|---|")
    rows = [
        ("column width L0, height H0 [mm]",
         lambda r: "%.2f, %.2f" % (r["L0"] * 1e3, r["H0"] * 1e3)),
        ("buoyant weight per area W [Pa]", lambda r: "%.0f" % r["W"]),
        ("final run-out (L - L0)/L0", lambda r: "%.2f" % r["final"]),
        ("time to 90 % of it [s]", lambda r: "%.2f" % r["t90"]),
        ("final height / H0", lambda r: "%.2f" % r["height"]),
        ("mean excess pore pressure from %.1f s to t90 / W" % TRANSIENT,
         lambda r: "%+.3f" % r["mean_excess"]),
        ("lowest, highest excess / W",
         lambda r: "%+.2f, %+.2f" % (r["lowest"], r["highest"])),
        ("packing inside the mass: at the release, lowest, at the end",
         lambda r: "%.3f, %.3f, %.3f" % (r["packing_start"],
                                         r["packing_lowest"],
                                         r["packing_end"])),
    ]
    for label, f in rows:
        print("| %s | %s | %s |" % (label, f(runs["loose"]),
                                     f(runs["dense"])))
    print("dense/loose final run-out: %.2f"
          % (runs["dense"]["final"] / runs["loose"]["final"]))
    if repeats:
        pairs = [runs] + repeats
        print()
        print("Over the %d pairs, mean (lowest - highest):" % len(pairs))
        print("| | loose | dense |")
        print("|---|---|---|")

        def spread(values, form):
            return "%s (%s - %s)" % (form % np.mean(values),
                                     form % min(values), form % max(values))

        for label, key, form in (
                ("final run-out (L - L0)/L0", "final", "%.2f"),
                ("time to 90 % of it [s]", "t90", "%.2f"),
                ("final height / H0", "height", "%.2f"),
                ("mean excess pore pressure from %.1f s to t90 / W"
                 % TRANSIENT, "mean_excess", "%+.3f")):
            print("| %s | %s | %s |" % (
                label, spread([p["loose"][key] for p in pairs], form),
                spread([p["dense"][key] for p in pairs], form)))
        print("dense/loose final run-out: %s" % spread(
            [p["dense"]["final"] / p["loose"]["final"] for p in pairs],
            "%.2f"))
    print("wrote " + args.out)


if __name__ == "__main__":
    main()
