#!/usr/bin/python3
"""The extremes matrix (doc/stability.md): one small scene per cell, each
axis varied on its own around a base scene, in 2D and 3D. Every cell
reports whether the run finished without NaN, whether the grains' volume
and the momentum the phases exchange were conserved, its settling figure
against the analytical value, and its wall time.

    benchmarks/stability/run.py [--dims 2,3] [--axes dt,density,reynolds,cells,fraction] [--table FILE]

Scenes. A lone grain settling from rest in a closed box of 8 (3D) or 16
(2D) cells per side (more where cells are below 2 diameters, so that the
box stays 16 diameters wide), steady Stokes fluid, two-way coupled: its velocity
at the end against the seed's closure solved for the terminal velocity at
any Reynolds number, (rho_p - rho) V g = gamma(1, U) U (the Reynolds
axis with a transient Navier-Stokes fluid). 3D keeps the
default coupling (drag spread over the grain's cell); 2D uses the
filtered drag with a length half the box, as doc/theory.md recommends
for discs (a disc's own disturbance decays only logarithmically). The
fraction axis runs hindered settling instead: a suspension filling a box
closed above and below, periodic sideways (the hindered_settling_* tests'
scenes), against v = eps^4.8 times the lone grain's closure velocity
(doc/theory.md 3); the packed 2D bed is the hexagonal lattice at 0.84
with Closure porosity in 2D = sphere packing, against
phi^2 eps^2.8 V_1 (phi the area fraction, eps the sphere packing's).

Base: the seed's glass beads (r = 12.5 um, rho_p = 2400) in glycerine
(rho = 1200, mu = 0.12), cells of 8 diameters, dt = 1e-3 s (about 1400
relaxation times tau_p). End time 10 tau_p, or the time to fall 30
diameters if shorter, and at least 4 steps.

Tolerances (why, doc/stability.md): lone grain in 3D 20 % (the cell
spread's own disturbance, +5 to +17 % at 2-16 diameters, plus the box's
walls at 8 cells), in 2D 15 %; suspensions 5 % (3D, the tests' boxes) and
10 % (2D).
"""
import argparse
import math
import os
import re
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from scene_runner import ROOT, run_scene  # noqa: E402

WORK = os.path.join(ROOT, "benchmarks", "results", "stability")
G = 9.81


def volume(r, dim):
    return 4 / 3 * math.pi * r ** 3 if dim == 3 else math.pi * r * r


def area(r, dim):
    return math.pi * r * r if dim == 3 else 2 * r


def gamma(r, rho, mu, w, dim, eps=1.0):
    """The seed's closure (Dallavalle-Wen-Yu), as the code evaluates it."""
    root = 0.63 * math.sqrt(w) + 4.8 * math.sqrt(mu / (2 * r * rho * eps))
    return eps ** -1.8 * 0.5 * area(r, dim) * rho * root * root


def terminal(r, rho, rho_p, mu, dim, eps=1.0):
    """The closure's terminal speed (bisection), its Reynolds number and
    the relaxation time m / gamma there."""
    force = abs(rho_p - rho) * volume(r, dim) * G
    lo, hi = 0.0, 1e4
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if gamma(r, rho, mu, mid, dim, eps) * mid > force:
            hi = mid
        else:
            lo = mid
    w = lo
    m = rho_p * volume(r, dim)
    return w, 2 * r * rho * w * eps / mu, m / gamma(r, rho, mu, max(w, 1e-300), dim, eps)


def lone_grain(dim, r=12.5e-6, rho=1200.0, rho_p=2400.0, mu=0.12,
               cell_diameters=8.0, dt_over_tau=None, dt=1e-3,
               navier_stokes=False, smoothing_diameters=0.0, cells=None,
               correction="auto"):
    """Parameter text, the analytical velocity (signed, along gravity's
    axis) and the number of fluid steps of a lone grain settling."""
    d = 2 * r
    # At least 16 diameters across, so that small cells do not make a box
    # the grain barely fits in.
    if cells is None:
        cells = max(8 if dim == 3 else 16, math.ceil(16 / cell_diameters))
    h = cell_diameters * d
    L = cells * h
    U, reynolds, tau = terminal(r, rho, rho_p, mu, dim)
    if dt_over_tau is not None:
        dt = dt_over_tau * tau
    # Ten relaxation times, but no farther than 30 diameters (the grain
    # starts 22 diameters above the box's centre).
    end = max(4 * dt, min(10 * tau, 30 * d / U))
    steps = max(4, round(end / dt))
    # Start high and off the axes: the grain falls (or rises) towards the
    # far wall through most of the box.
    sign = 1 if rho_p >= rho else -1
    start = [0.1 * h, 0.2 * h, 0.3 * h][:dim]
    start[-1] = sign * 0.35 * L
    lower = ", ".join([f"{-L / 2:.9g}"] * dim)
    upper = ", ".join([f"{L / 2:.9g}"] * dim)
    gravity = ", ".join(["0"] * (dim - 1) + [f"{-G}"])
    coupling = ("" if dim == 3 else
                f"  set Drag distribution = filtered\n"
                f"  set Smoothing length  = {L / 2:.9g}\n")
    if smoothing_diameters:
        coupling = (f"  set Drag distribution = filtered\n"
                    f"  set Smoothing length  = {smoothing_diameters * d:.9g}\n")
    text = f"""set Dimension = {dim}
set End time  = {steps * dt:.9g}
set Time step = {dt:.9g}
subsection Mesh
  set Lower corner = {lower}
  set Upper corner = {upper}
  set Subdivisions = {cells}
  set Initial refinement = 0
end
subsection Fluid
  set Density   = {rho}
  set Viscosity = {mu:.9g}
  set Advection = {str(navier_stokes).lower()}
  set Time derivative = {str(navier_stokes).lower()}
end
subsection Coupling
{coupling}  set Self-disturbance correction = {str(correction).lower()}
end
subsection Grains
  set Enabled = true
  set Radius  = {r}
  set Density = {rho_p}
  subsection Placement
    set Shape     = list
    set Positions = {", ".join(f"{x:.9g}" for x in start)}
  end
end
subsection Gravity
  set Vector = {gravity}
end
"""
    info = dict(tau=tau, dt_over_tau=dt / tau, reynolds=reynolds,
                cell_diameters=cell_diameters, density_ratio=rho_p / rho)
    return text, -sign * U, info


def steady_stokes(rho, mu):
    """The suspensions' fluid: steady Stokes, solved to 1e-10 (packed
    suspensions settle at 1e-8 of the free velocity over a step that the
    right-hand side holds, doc/stability.md)."""
    return f"""subsection Fluid
  set Density   = {rho}
  set Viscosity = {mu}
  set Advection = false
  set Time derivative = false
  subsection Linear solver
    set Tolerance = 1e-10
  end
end"""


def suspension(dim, fraction):
    """A hindered-settling scene at solid fraction @p fraction (the
    hindered_settling_* tests' boxes), its analytical velocity."""
    r, rho, rho_p, mu = 12.5e-6, 1200.0, 2400.0, 0.12
    U1, reynolds, tau = terminal(r, rho, rho_p, mu, dim)
    eps = 1 - fraction
    if dim == 3:
        size = (4e-4, 4e-4, 8e-4)
        fill = (4e-4, 4e-4, 7.75e-4)
        sub, ref, l = "2, 2, 4", 1, 1e-4
    else:
        size = (1.6e-3, 1.6e-3)
        fill = (1.6e-3, 1.575e-3)
        sub, ref, l = "4, 4", 2, 8e-4
    count = round(fraction * math.prod(size) / volume(r, dim))
    centre = ", ".join(f"{s / 2:.9g}" for s in size)
    walls = ", ".join(["periodic"] * (2 * dim - 2) + ["wall", "wall"])
    gravity = ", ".join(["0"] * (dim - 1) + [f"{-G}"])
    text = f"""set Dimension = {dim}
set End time  = 3
set Time step = 0.25
subsection Mesh
  set Lower corner = {", ".join(["0"] * dim)}
  set Upper corner = {", ".join(f"{s:.9g}" for s in size)}
  set Subdivisions = {sub}
  set Initial refinement = {ref}
  set Boundary conditions = {walls}
end
{steady_stokes(rho, mu)}
subsection Grains
  set Enabled = true
  set Radius  = {r}
  set Density = {rho_p}
  subsection Placement
    set Shape  = box
    set Center = {centre}
    set Size   = {", ".join(f"{s:.9g}" for s in fill)}
    set Count  = {count}
    set Random seed = 3
  end
end
subsection Coupling
  set Drag distribution = filtered
  set Smoothing length  = {l}
end
subsection Gravity
  set Vector = {gravity}
end
"""
    exact = count * volume(r, dim) / math.prod(size)
    v = -(1 - exact) ** 4.8 * U1
    return text, v, dict(tau=tau, dt_over_tau=0.25 / tau, reynolds=reynolds,
                         fraction=exact)


def packed_lattice_2d():
    """The packed 2D suspension of coupled_packed_lattice_settling_2d, read
    as the sphere packing of the same gaps."""
    r, rho, rho_p, mu, phi_s = 12.5e-6, 1200.0, 2400.0, 0.12, 0.84
    a = 2 * r * math.sqrt((math.pi / (2 * math.sqrt(3))) / phi_s)
    dy = math.sqrt(3) / 2 * a
    k = m = 40
    gap = 1.04 * r
    W, H = k * a, (m - 1) * dy + 2 * gap
    positions = "; ".join(f"{(i + 0.25 + 0.5 * (j % 2)) * a:.9g},{gap + j * dy:.9g}"
                          for j in range(m) for i in range(k))
    text = f"""set Dimension = 2
set End time  = 2
set Time step = 0.25
subsection Mesh
  set Lower corner = 0, 0
  set Upper corner = {W:.9g}, {H:.9g}
  set Subdivisions = 10, 9
  set Initial refinement = 0
  set Boundary conditions = periodic, periodic, wall, wall
end
{steady_stokes(rho, mu)}
subsection Grains
  set Enabled = true
  set Radius  = {r}
  set Density = {rho_p}
  subsection Placement
    set Shape = list
    set Positions = {positions}
  end
end
subsection Coupling
  set Drag distribution = filtered
  set Smoothing length  = {W / 2:.6g}
  set Closure porosity in 2D = sphere packing
end
subsection Gravity
  set Vector = 0, {-G}
end
"""
    U1, reynolds, tau = terminal(r, rho, rho_p, mu, 2)
    phi = 1 - phi_s
    eps = 1 - 0.857382758104992 * phi_s ** 1.5
    # v = phi^2 (rho_p - rho) V g / gamma(eps) at Re -> 0, gamma ~ eps^-2.8.
    v = -phi ** 2 * eps ** 2.8 * U1
    return text, v, dict(tau=tau, dt_over_tau=0.25 / tau, reynolds=reynolds,
                         fraction=phi_s)


def cells_of(dim, axes):
    """(axis, label, scene text, analytical velocity, info, tolerance)."""
    lone_tolerance = 0.20 if dim == 3 else 0.15
    out = []
    if "dt" in axes:
        for x in [1e-1, 1e1, 1e3, 1e5, 1e8]:
            out.append(("dt/tau_p", f"{x:g}", *lone_grain(dim, dt_over_tau=x),
                        lone_tolerance))
    if "density" in axes:
        for ratio in [0.5, 1.001, 2.5, 1000]:
            out.append(("rho_p/rho", f"{ratio:g}",
                        *lone_grain(dim, rho_p=1200.0 * ratio), lone_tolerance))
    if "reynolds" in axes:
        # A 1 mm bead (rho_p = 2500) in a fluid of density 1000 whose
        # viscosity gives the Reynolds number at the closure's terminal
        # velocity; dt = tau_p; transient Navier-Stokes, as a scene at these
        # Reynolds numbers runs (with a Stokes fluid the grain's own
        # disturbance is not carried away: +27 % at Re_p = 100 in 3D).
        for target in [1e-7, 1e-3, 1, 100, 1000]:
            lo, hi = math.log(1e-8), math.log(1e6)
            for _ in range(100):
                mu = math.exp(0.5 * (lo + hi))
                if terminal(5e-4, 1000.0, 2500.0, mu, dim)[1] > target:
                    lo = math.log(mu)
                else:
                    hi = math.log(mu)
            tau = terminal(5e-4, 1000.0, 2500.0, mu, dim)[2]
            out.append(("Re_p", f"{target:g}",
                        *lone_grain(dim, r=5e-4, rho=1000.0, rho_p=2500.0,
                                    mu=mu, dt=tau, navier_stokes=True),
                        lone_tolerance))
    if "cells" in axes:
        # 3D cells of d/4 would need 64^3 cells for that box: not run.
        for c in ([0.5, 1, 4, 8, 32] if dim == 3 else [0.25, 1, 4, 8, 32]):
            out.append(("cell/d", f"{c:g}",
                        *lone_grain(dim, cell_diameters=c), lone_tolerance))
        if dim == 3:
            # What --check recommends below a diameter: a filter of a
            # diameter or two.
            out.append(("cell/d", "0.5 (filtered, l = 2 d)",
                        *lone_grain(dim, cell_diameters=0.5,
                                    smoothing_diameters=2), lone_tolerance))
    if "fraction" in axes:
        for f in ([0.05, 0.2, 0.3] if dim == 3 else [0.05, 0.2, 0.4]):
            out.append(("phi_s", f"{f:g}", *suspension(dim, f),
                        0.05 if dim == 3 else 0.10))
        if dim == 2:
            out.append(("phi_s", "0.84 (packed)", *packed_lattice_2d(), 0.10))
    return out


def evaluate(dim, axis, label, text, exact, info, tolerance):
    name = re.sub(r"[^A-Za-z0-9.+-]+", "_", f"{dim}d_{axis}_{label}").strip("_")
    directory = os.path.join(WORK, name)
    start = time.time()
    try:
        rows = run_scene(text, directory)
        failed = ""
    except Exception as error:  # a failed run is a result of the matrix
        rows, failed = [], str(error).splitlines()[0][:60]
    wall = time.time() - start
    if not rows:
        return dict(dim=dim, axis=axis, value=label, finite=False,
                    volume="-", exchange="-", ratio=float("nan"),
                    tolerance=tolerance, passed=False, wall=wall,
                    steps=0, note=failed or "no statistics", **info)
    last = rows[-1]
    component = "mean_velocity_" + ("z" if dim == 3 else "y")
    velocity = float(last[component])
    values = [float(v) for row in rows for k, v in row.items()
              if k not in ("cloud_breakup_time",) and v not in ("", None)]
    finite = all(math.isfinite(v) for v in values)
    volume_error = max(abs(float(row["solid_volume_error"])) for row in rows)
    # The books of the momentum the phases exchanged over the whole run:
    # round-off where every drag impulse reached the other phase (what the
    # sub-steps leave is repaid in the next fluid step).
    exchange = abs(float(last["momentum_exchange_drift"]))
    substeps = max(int(float(row["grain_substeps"])) for row in rows)
    ratio = velocity / exact
    passed = finite and volume_error < 1e-10 and abs(ratio - 1) <= tolerance
    return dict(dim=dim, axis=axis, value=label, finite=finite,
                volume=f"{volume_error:.0e}",
                exchange=(f"{exchange:.0e}" if substeps <= 1 else
                          f"{exchange:.0e} ({substeps} sub-steps)"),
                ratio=ratio, tolerance=tolerance, passed=passed, wall=wall,
                steps=len(rows) - 1, note=failed, **info)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dims", default="2,3")
    parser.add_argument("--axes", default="dt,density,reynolds,cells,fraction")
    parser.add_argument("--table", default=os.path.join(WORK, "table.md"))
    args = parser.parse_args()
    axes = args.axes.split(",")
    lines = ["| dim | axis | value | dt/tau_p | Re_p | finite | volume error | "
             "exchange drift | v / analytical | within | steps | wall s |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    os.makedirs(WORK, exist_ok=True)
    failures = 0
    for dim in [int(x) for x in args.dims.split(",")]:
        for cell in cells_of(dim, axes):
            result = evaluate(dim, *cell)
            failures += not result["passed"]
            line = ("| {dim}D | {axis} | {value} | {dt_over_tau:.2g} | "
                    "{reynolds:.2g} | {finite} | {volume} | {exchange} | "
                    "{ratio:.4f} | {mark} {tolerance:.0%} | {steps} | "
                    "{wall:.1f} |").format(
                        mark="yes" if result["passed"] else "**no**",
                        **result)
            if result["note"]:
                line += " " + result["note"]
            lines.append(line)
            print(line, flush=True)
    with open(args.table, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"{failures} cell(s) outside their tolerance; table in {args.table}")


if __name__ == "__main__":
    main()
