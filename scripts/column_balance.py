#!/usr/bin/env python3
"""The mixture's momentum balance of a column fed through its floor: a box
whose floor (the lower face along the last axis) is an inflow and whose
top is open, with gravity along that axis (prm/fluidized_bed_3d.prm,
prm/fluidized_bed_two_sizes_3d.prm). Once the flow is steady on average,
what the grains weigh in the liquid is carried by

  - the pressure drop from the floor to the top (without its hydrostatic
    part), as the mean over each face;
  - the floor's contact force on the grains resting on it;
  - the liquid's momentum lost between the floor, where it enters at U/phi,
    and the top, where it leaves at about U: the faces' integrals of
    rho phi u^2, floor minus top.

Each is printed per area and in units of the grains' buoyant weight per
area, W = (rho_p - rho) g V_s / A, with their sum, which the exact balance
makes 1. Face means are taken over the field output's states from --from
on (the run needs Output/Write fields every), the point drop
(statistics column pressure_drop) and the contact force
(boundary_contact_force_<id>_<axis>, Output/Boundary contact forces) as
the statistics' means over the same time, weighted by the step. The
densities and gravity are read from the run's copy of its parameter file.

    /usr/bin/python3 scripts/column_balance.py output/fluidized_bed_two_sizes_3d --from 3
"""
import argparse
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_scene import pvd_states, read_vtu, run_parameters  # noqa: E402


def fail(message):
    sys.exit("column_balance.py: " + message)


def states(directory, start):
    """(time, points, pressure, velocity, fluid fraction) of each field
    state written from @p start on."""
    entries = pvd_states(directory, "fields.pvd")
    if not entries:
        fail("no fields.pvd in %s (set Output/Write fields every)"
             % directory)
    for time, files in entries:
        if time < start - 1e-12:
            continue
        pieces = [read_vtu(f) for f in files]
        yield (time,
               np.concatenate([p[0] for p in pieces]),
               *(np.concatenate([p[1][k] for p in pieces])
                 for k in ("pressure", "velocity", "fluid_fraction")))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("directory")
    parser.add_argument("--from", dest="start", type=float, default=0.0,
                        help="average from this time on [s]")
    parser.add_argument("--floor-id", type=int, default=None,
                        help="the floor's boundary id in the contact-force "
                        "columns (default: 2 dim - 2, the box's lower face "
                        "along the last axis)")
    args = parser.parse_args()

    prm = run_parameters(args.directory, "column_balance.py")
    dim = int(prm.get("Dimension", "2"))
    axis = dim - 1
    rho = float(prm.get("Fluid/Density", "1000"))
    rho_p = float(prm.get("Grains/Density", "2500"))
    gravity = [float(v) for v in
               prm.get("Gravity/Vector", "0, 0, -9.81").split(",")]
    g = abs(gravity[axis])
    floor_id = 2 * dim - 2 if args.floor_id is None else args.floor_id

    face, flux, area, count = np.zeros(2), np.zeros(2), None, 0
    for time, points, p, u, phi in states(args.directory, args.start):
        low, high = points[:, axis].min(), points[:, axis].max()
        if area is None:
            across = [a for a in range(dim) if a != axis]
            area = np.prod([points[:, a].max() - points[:, a].min()
                            for a in across])
        for k, level in enumerate((low, high)):
            # The output's points on a face of a uniform mesh: their plain
            # mean is the face mean of a continuous Q1 or Q2 field.
            on = np.abs(points[:, axis] - level) <= 1e-9 * (high - low)
            face[k] += p[on].mean()
            flux[k] += (rho * phi[on] * u[on, axis] ** 2).mean()
        count += 1
    if count == 0:
        fail("no field state from %g s on in %s" % (args.start,
                                                    args.directory))
    face /= count
    flux /= count

    try:
        with open(os.path.join(args.directory, "statistics.csv")) as f:
            rows = list(csv.DictReader(f))
    except OSError:
        fail("cannot read statistics.csv in " + args.directory)
    late = [r for r in rows if float(r["time"]) >= args.start - 1e-12
            and float(r["dt"]) > 0]
    if not late:
        fail("no statistics row from %g s on" % args.start)
    dt = np.array([float(r["dt"]) for r in late])

    def mean(column):
        if column not in late[0]:
            return None
        return float(np.sum(dt * np.array([float(r[column]) for r in late]))
                     / np.sum(dt))

    weight = (rho_p - rho) * g * float(late[-1]["solid_volume"]) / area
    point_drop = mean("pressure_drop")
    contact = mean("boundary_contact_force_%d_%s" % (floor_id, "xyz"[axis]))
    # The grains press the floor along gravity: the weight it carries.
    if contact is not None:
        contact *= np.sign(gravity[axis]) / area
    # Stokes flow (Fluid/Advection = false) carries no momentum flux.
    stokes = prm.get("Fluid/Advection", "true").lower() == "false"
    momentum = None if stokes else flux[0] - flux[1]
    terms = [("pressure drop, face means", face[0] - face[1]),
             ("pressure drop between the two points", point_drop),
             ("floor's contact force per area", contact),
             ("momentum lost, floor minus top", momentum)]
    print("%d field states from %g s; W = %.4g Pa" % (count, args.start,
                                                      weight))
    print("| term | Pa | / W |")
    print("|---|---|---|")
    for name, value in terms:
        if value is None:
            print("| %s | (none) | |" % name)
        else:
            print("| %s | %.4g | %.4f |" % (name, value, value / weight))
    total = face[0] - face[1] + (contact or 0.0) + (momentum or 0.0)
    print("| sum: face drop + contacts + momentum | %.4g | %.4f |"
          % (total, total / weight))


if __name__ == "__main__":
    main()
