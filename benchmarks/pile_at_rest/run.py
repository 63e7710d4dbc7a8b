#!/usr/bin/python3
"""The 3000-disc frictionless pile of pile_2d_3000.prm beside this script, run to
t = 4 s with the default contact solver (Gauss-Seidel with its subspace
correction), with plain Gauss-Seidel (Subspace correction every = 0) and
with apgd,
all at the default tolerances: prints the rows of the table in
doc/contacts.md, "Coming to rest" (kinetic energy against its peak after
settling, share of steps below 1e-8 of the peak, sweeps per step) and
draws doc/figures/pile_at_rest.png (the energy against time, and the bed
at t = 4 s coloured by speed).

    benchmarks/pile_at_rest/run.py [END_TIME]

About 5 min on the 2-core machine (the three runs at once: the default
252 s, plain Gauss-Seidel 229 s, apgd 200 s).
Needs build/immersed-grains, python3-numpy and python3-matplotlib.
"""
import csv
import os
import statistics
import subprocess
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PatchCollection  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import plot_scene  # noqa: E402  (its VTU reader)

EXECUTABLE = os.path.join(ROOT, "build", "immersed-grains")
WORK = os.path.join(ROOT, "benchmarks", "results", "pile_at_rest")
FIGURE = os.path.join(ROOT, "doc", "figures", "pile_at_rest.png")
SETTLED = 1.0  # [s]: the table's statistics are taken from here on


# label: (Contacts/Solver, further lines of subsection Contacts)
SOLVERS = {
    "gauss-seidel": ("gauss-seidel", []),
    "gauss-seidel-plain": ("gauss-seidel",
                           ["  set Subspace correction every = 0"]),
    "apgd": ("apgd", []),
}


def scene(label, end_time):
    solver, extra = SOLVERS[label]
    text = open(os.path.join(ROOT, "benchmarks", "pile_at_rest",
                             "pile_2d_3000.prm")).read()
    out = os.path.join(WORK, label)
    lines = []
    for line in text.splitlines():
        if line.startswith("set Output directory"):
            line = f"set Output directory = {out}"
        elif line.startswith("set End time"):
            line = f"set End time = {end_time}"
        elif line.strip().startswith("set Terminal output"):
            line = "  set Terminal output = quiet"
        elif line.strip().startswith("set Test"):
            continue
        lines.append(line)
    lines += ["subsection Contacts", f"  set Solver = {solver}", *extra, "end",
              "subsection Output", f"  set Write fields every = {int(round(end_time * 1000))}",
              "end"]
    os.makedirs(WORK, exist_ok=True)
    path = os.path.join(WORK, label + ".prm")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path, out


def summary(out):
    rows = list(csv.DictReader(open(os.path.join(out, "statistics.csv"))))
    peak = max(float(r["kinetic_energy"]) for r in rows)
    late = [r for r in rows if float(r["time"]) >= SETTLED]
    ratio = [float(r["kinetic_energy"]) / peak for r in late]
    return rows, peak, {
        "median": statistics.median(ratio),
        "below": sum(k < 1e-8 for k in ratio) / len(ratio),
        "max": max(ratio),
        "sweeps": sum(int(r["contact_iterations"]) for r in late) / len(late),
        "capped": sum(r["contact_converged"] == "0" for r in late) / len(late),
        "overlap": max(float(r["max_overlap"]) for r in late),
        "packing": float(late[-1]["packing_fraction"]),
        "wall": float(rows[-1]["wall_time"]),
    }


def main():
    end_time = float(sys.argv[1]) if len(sys.argv) > 1 else 4.0
    runs = {label: scene(label, end_time) for label in SOLVERS}
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    jobs = [subprocess.Popen([EXECUTABLE, path], env=env,
                             stdout=subprocess.DEVNULL)
            for path, _ in runs.values()]
    if any(job.wait() != 0 for job in jobs):
        sys.exit("pile_at_rest: a run failed")

    fig, (energy, bed) = plt.subplots(
        1, 2, figsize=(13, 3.8), gridspec_kw={"width_ratios": [1, 1.5]})
    print(f"from t = {SETTLED} s to {end_time} s:")
    print("| solver | KE/peak, median | steps with KE/peak < 1e-8 | "
          "largest KE/peak | sweeps per step | steps at the cap | "
          "largest overlap [m] | packing fraction | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for solver, (_, out) in runs.items():
        rows, peak, s = summary(out)
        print(f"| {solver} | {s['median']:.2g} | {100 * s['below']:.2f} % | "
              f"{s['max']:.3g} | {s['sweeps']:.0f} | {100 * s['capped']:.0f} % | "
              f"{s['overlap']:.2g} | {s['packing']:.4f} | {s['wall']:.0f} |")
        energy.semilogy([float(r["time"]) for r in rows],
                        [max(float(r["kinetic_energy"]) / peak, 1e-12)
                         for r in rows], lw=0.7, label=solver)
    energy.axhline(1e-8, color="k", ls=":", lw=0.8)
    energy.set_xlabel("t [s]")
    energy.set_ylabel("kinetic energy / peak")
    energy.set_title("3000 frictionless discs, default tolerances")
    energy.legend(fontsize=8)

    out = runs["gauss-seidel"][1]
    step = int(round(end_time * 1000))
    points, arrays, _ = plot_scene.read_vtu(
        os.path.join(out, f"particles_{step:05d}.0.vtu"))
    speed = np.linalg.norm(arrays["velocity"], axis=1)
    discs = PatchCollection([Circle((x, y), r) for (x, y, _), r
                             in zip(points, arrays["radius"])], cmap="viridis")
    discs.set_array(np.log10(speed + 1e-9))
    bed.add_collection(discs)
    bed.set_xlim(0, 0.2)
    bed.set_ylim(0, 0.065)
    bed.set_aspect("equal")
    bed.set_title(f"gauss-seidel, t = {end_time:g} s")
    fig.colorbar(discs, ax=bed, label="log10 speed [m/s]")
    fig.savefig(FIGURE, dpi=110, bbox_inches="tight")
    print("wrote", os.path.relpath(FIGURE, ROOT))


if __name__ == "__main__":
    main()
