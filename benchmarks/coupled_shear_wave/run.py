#!/usr/bin/python3
"""A shear wave shared by grains and fluid, against the exact solution of
the coupled equations (doc/validation.md, "A shear wave of grains and
fluid"; tests/coupled_shear_wave_2d.cc is its reduced form): 64 discs
(r = 50 um, 2500 kg/m^3) on a lattice 8 x 8 in a periodic box 3.2 mm wide,
a fluid of 50 kg/m^3 and 1e-4 Pa s (transient Stokes), Stokes' drag spread
with the Helmholtz filter (l = 0.4 mm), the discs started with
B0 sin(k y) along x, the fluid at rest. Prints, for each mesh and step,
B/B_exact - 1 at 0.02, 0.05 and 0.08 s and its largest magnitude over the
steps to 0.08 s (B from the grains' kinetic energy), and the wall time.

    benchmarks/coupled_shear_wave/run.py [CELLS:DT ...]

CELLS cells per side, DT the step in s; by default h = 200, 100 and 50 um
with steps of 250, 125 and 62.5 us, the finest pair left out (about 3.5
minutes on one core).
Environment: SHEAR_WAVE_LENGTH (the filter length, m; 4e-4 unless given).
IMMERSED_GRAINS_BUILD runs another build (benchmarks/scene_runner.py).
"""
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import scene_runner  # noqa: E402 (benchmarks/)

WORK = os.path.join(scene_runner.ROOT, "benchmarks", "results",
                    "coupled_shear_wave")
L, LATTICE, R = 3.2e-3, 8, 5e-5
RHO_P, RHO, MU, B0, END = 2500.0, 50.0, 1e-4, 1e-3, 0.08
LENGTH = float(os.environ.get("SHEAR_WAVE_LENGTH", "4e-4"))
K = 2 * math.pi / L
N = LATTICE * LATTICE
MASS = RHO_P * math.pi * R * R
GAMMA = 12 * MU  # Stokes' drag per unit depth, 6 mu (2 r) / r


def exact_amplitude(t):
    """B(t) of A' = -nu k^2 A - D a (a A - B), B' = G (a A - B), from
    A(0) = 0, B(0) = B0 (tests/coupled_shear_wave_2d.cc)."""
    phi = 1 - N * math.pi * R * R / (L * L)
    d = N / (L * L) * GAMMA / (phi * RHO)
    g = GAMMA / MASS
    a = 1 / (1 + (K * LENGTH) ** 2)
    m11, m22 = -MU / RHO * K * K - d * a * a, -g
    tr, det = m11 + m22, m11 * m22 - d * a * g * a
    root = math.sqrt(tr * tr - 4 * det)
    l1, l2 = (tr + root) / 2, (tr - root) / 2
    return B0 * ((m22 - l2) * math.exp(l1 * t)
                 + (l1 - m22) * math.exp(l2 * t)) / (l1 - l2)


def scene(cells, dt):
    s = L / LATTICE
    rows = [(i + 0.5) * s for i in range(LATTICE)]
    positions = "; ".join("%.17g, %.17g" % (x, y) for y in rows for x in rows)
    velocities = "; ".join("%.17g, 0" % (B0 * math.sin(K * y))
                           for y in rows for _ in rows)
    return f"""set Dimension = 2
set End time = {END}
set Time step = {dt}
subsection Mesh
  set Lower corner = 0, 0
  set Upper corner = {L}, {L}
  set Subdivisions = {cells}, {cells}
  set Initial refinement = 0
  set Boundary conditions = periodic, periodic, periodic, periodic
end
subsection Fluid
  set Density   = {RHO}
  set Viscosity = {MU}
  set Advection = false
end
subsection Grains
  set Enabled = true
  set Radius  = {R}
  set Density = {RHO_P}
  subsection Placement
    set Shape      = list
    set Positions  = {positions}
    set Velocities = {velocities}
  end
end
subsection Coupling
  set Drag law          = Stokes
  set Drag distribution = filtered
  set Smoothing length  = {LENGTH}
end
subsection Gravity
  set Vector = 0, 0
end
"""


def main():
    cases = sys.argv[1:] or ["16:2.5e-4", "16:1.25e-4", "16:6.25e-5",
                             "32:2.5e-4", "32:1.25e-4", "32:6.25e-5",
                             "64:2.5e-4", "64:1.25e-4"]
    print("exact B/B0 at 0.02, 0.05, 0.08 s: %.4f, %.4f, %.4f"
          % tuple(exact_amplitude(t) / B0 for t in (0.02, 0.05, 0.08)))
    print("| h (um) | dt (us) | error at 0.02 s | 0.05 s | 0.08 s "
          "| largest | wall (s) |")
    print("|---|---|---|---|---|---|---|")
    for case in cases:
        cells, dt = case.split(":")
        start = time.time()
        rows = scene_runner.run_scene(
            scene(int(cells), float(dt)),
            os.path.join(WORK, "h%s_dt%s" % (cells, dt)))
        wall = time.time() - start
        errors = {}
        for row in rows[1:]:
            t = float(row["time"])
            b = math.sqrt(4 * float(row["kinetic_energy"]) / (MASS * N))
            errors[t] = b / exact_amplitude(t) - 1

        def at(t):
            return errors[min(errors, key=lambda s: abs(s - t))]

        print("| %.0f | %g | %+.2f %% | %+.2f %% | %+.2f %% | %.2f %% "
              "| %.0f |" % (L / int(cells) * 1e6, float(dt) * 1e6,
                            100 * at(0.02), 100 * at(0.05), 100 * at(0.08),
                            100 * max(abs(e) for e in errors.values()), wall))


if __name__ == "__main__":
    main()
