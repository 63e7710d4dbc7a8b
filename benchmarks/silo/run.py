#!/usr/bin/python3
"""Discharge of the 2D silo of prm/silo_discharge_2d.prm through orifices of
D = 6 to 14 mean grain diameters, and Beverloo's law fitted to the rates;
with --immersed the silo in water of prm/silo_discharge_immersed_2d.prm.

    /usr/bin/python3 benchmarks/silo/run.py [--immersed] [--ranks N]
        [--widths 0.04,0.06] [--jobs 2] [--cell 0.005]

Each width gets its own mesh (prm/meshes/silo_2d.py) and run (output in
benchmarks/results/silo[_immersed]/D<width>/), from the same settled fill
(prm/packings/silo_2d.txt). The discharge rate is the slope of
grains_removed against time while between 10 % and 50 % of the grains have
left (the bed still deep above the orifice). Beverloo's law in 2D,
W = C rho_b sqrt(g) (D - k d)^(3/2) (per unit depth), is fitted as a line
of W^(2/3) against D, which gives k; the exponent fitted freely shows how
well 3/2 describes the rates; immersed, C is stated for the grains'
buoyant weight, g' = g (1 - rho_f/rho_s), so that it equals the dry C
where the law holds with g' for g. Writes results.csv and beverloo.png
there.
"""
import argparse
import concurrent.futures
import csv
import math
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(
    __file__))))
d_mean, rho_s, rho_f, g = 0.01, 2500.0, 1000.0, 9.81
# Mean area of a disc of radius uniform in [4, 6] mm: pi (r^2 mean).
area = math.pi * (0.005 ** 2 + 0.002 ** 2 / 12)


def run(out, width, ranks, immersed, cell):
    folder = os.path.join(out, "D%g" % width)
    os.makedirs(folder, exist_ok=True)
    mesh = os.path.join(folder, "silo.msh")
    with open(mesh, "w") as f:
        # Cells of 1 cm (--cell), so that every width is a centred whole
        # number of them.
        subprocess.run([sys.executable,
                        os.path.join(ROOT, "prm", "meshes", "silo_2d.py")]
                       + (["--open-top"] if immersed else [])
                       + [str(width), "0.4", "0.8", str(cell)], stdout=f,
                       check=True)
    scene = "silo_discharge_immersed_2d" if immersed else "silo_discharge_2d"
    with open(os.path.join(ROOT, "prm", scene + ".prm")) as f:
        text = f.read()
    for name in ["meshes/silo_2d.msh", "meshes/silo_immersed_2d.msh"]:
        text = text.replace("set File                = " + name,
                            "set File                = silo.msh")
    text = text.replace("packings/silo_2d.txt", os.path.join(
        ROOT, "prm", "packings", "silo_2d.txt"))
    text = text.replace("set Write fields every = 25",
                        "set Write fields every = 0")
    text += "set Output directory = %s\n" % os.path.join(folder, "output")
    prm = os.path.join(folder, "silo.prm")
    with open(prm, "w") as f:
        f.write(text)
    command = [os.path.join(ROOT, "build", "immersed-grains"), prm]
    if ranks > 1:
        command = ["mpirun", "-np", str(ranks), "--oversubscribe"] + command
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    subprocess.run(command, check=True, env=env, stdout=subprocess.DEVNULL)
    with open(os.path.join(folder, "output", "statistics.csv")) as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["time"]) for r in rows])
    removed = np.array([float(r["grains_removed"]) for r in rows])
    n0 = float(rows[0]["particles"])
    window = (removed >= 0.1 * n0) & (removed <= 0.5 * n0)
    if window.sum() < 10:
        return n0, float("nan"), float(rows[-1]["wall_time"])
    rate = np.polyfit(t[window], removed[window], 1)[0]
    return n0, rate, float(rows[-1]["wall_time"])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--immersed", action="store_true",
                        help="the silo in water")
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=1,
                        help="runs at once")
    parser.add_argument("--widths", default="0.06,0.08,0.1,0.12,0.14")
    parser.add_argument("--cell", type=float, default=0.01,
                        help="the cells' size [m]: the widths and the bin "
                        "must be whole numbers of it (results in a folder "
                        "named with it unless 0.01)")
    args = parser.parse_args()
    out = os.path.join(ROOT, "benchmarks", "results",
                       ("silo_immersed" if args.immersed else "silo")
                       + ("" if args.cell == 0.01 else "_cell%g" % args.cell))
    # The weight that drives the grains: buoyant in water.
    g_drive = g * (1 - rho_f / rho_s) if args.immersed else g
    widths = [float(w) for w in args.widths.split(",")]
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        runs = list(pool.map(
            lambda w: run(out, w, args.ranks, args.immersed, args.cell),
            widths))
    results = []
    for w, (n0, rate, wall) in zip(widths, runs):
        mass_rate = rate * area * rho_s  # kg/(m s)
        results.append((w, n0, rate, mass_rate, wall))
        print("D = %.2f m (%.0f d): %.0f grains, %.1f grains/s, "
              "W = %.3f kg/(m s), %.0f s" % (w, w / d_mean, n0, rate,
                                              mass_rate, wall), flush=True)
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "results.csv"), "w") as f:
        f.write("D,grains,rate_grains_per_s,W_kg_per_m_s,wall_time\n")
        for row in results:
            f.write(",".join("%.6g" % x for row_x in [row] for x in row_x)
                    + "\n")
    if len(results) < 3:
        return  # too few widths for Beverloo's law
    D = np.array([r[0] for r in results])
    W = np.array([r[3] for r in results])
    ok = np.isfinite(W)
    slope, intercept = np.polyfit(D[ok], W[ok] ** (2 / 3), 1)
    k = -intercept / slope / d_mean
    c_rho = slope ** 1.5 / math.sqrt(g_drive)  # C rho_b
    # The exponent free: W = a (D - k d)^n with k from the 3/2 fit.
    n = np.polyfit(np.log(D[ok] - k * d_mean), np.log(W[ok]), 1)[0]
    print("Beverloo, exponent 3/2, g = %.2f m/s^2: k = %.2f, "
          "C rho_b = %.0f kg/m^3, C = %.3f with rho_b = %.0f (packing 0.8); "
          "free exponent %.2f"
          % (g_drive, k, c_rho, c_rho / (0.8 * rho_s), 0.8 * rho_s, n))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 4))
        ax.plot(D[ok] / d_mean, W[ok] ** (2 / 3), "o", label="runs")
        x = np.linspace(k, D.max() / d_mean * 1.05, 50)
        ax.plot(x, slope * x * d_mean + intercept, "-",
                label="Beverloo, k = %.2f" % k)
        ax.set_xlabel("D / d")
        ax.set_ylabel("W$^{2/3}$  [(kg/(m s))$^{2/3}$]")
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(out, "beverloo.png"), dpi=120)
    except ImportError:
        pass


if __name__ == "__main__":
    main()
