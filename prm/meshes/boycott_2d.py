#!/usr/bin/env python3
"""Writes a 2D settling tank whose side walls lean at an angle from the
vertical (prm/boycott_2d.prm): a parallelogram of horizontal width W and
height H, floor and top horizontal, as a Gmsh mesh (format 2.2 ASCII) of
nx x ny cells, every side a wall (physical line 1), the cells physical
surface 10; and, beside it, a suspension filling it: discs of radius r at
area fraction phi placed at random without overlap (random sequential
addition, a fixed seed), one 'x y' per line.

    python3 boycott_2d.py ANGLE [W H nx ny r phi]

writes boycott_2d_<ANGLE>.msh and boycott_2d_<ANGLE>_grains.txt next to
this script (defaults: W = 1.5e-3, H = 6e-3 m, 12 x 48 cells, r = 25e-6 m,
phi = 0.1). ANGLE in degrees; 0 is a vertical tank.
"""
import math
import os
import random
import sys

angle = float(sys.argv[1])
W, H = (float(x) for x in sys.argv[2:4]) if len(sys.argv) > 3 else \
    (1.5e-3, 6e-3)
nx, ny = (int(x) for x in sys.argv[4:6]) if len(sys.argv) > 5 else (12, 48)
r, phi = (float(x) for x in sys.argv[6:8]) if len(sys.argv) > 7 else \
    (25e-6, 0.1)
if not 0 <= angle < 80:
    sys.exit("boycott_2d.py: the angle must lie in [0, 80) degrees")
shift = math.tan(math.radians(angle))  # x offset per unit height
base = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                    "boycott_2d_%g" % angle)


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import structured_2d  # noqa: E402

with open(base + ".msh", "w") as out:
    structured_2d.write(out, nx, ny, lambda i, j: (
        i * W / nx + j * H / ny * shift, j * H / ny))

# The suspension: centres at least 1.01 r from the walls (measured across
# the leaning walls) and 2.02 r apart, on a bucket grid of 2.02 r.
target = round(phi * W * H / (math.pi * r * r))
gap = 2.02 * r
cos = math.cos(math.radians(angle))
rng = random.Random(1)
buckets = {}
placed = []
attempts = 0
while len(placed) < target:
    attempts += 1
    if attempts > 1000 * target:
        sys.exit("boycott_2d.py: phi = %g is too dense for random addition"
                 % phi)
    y = rng.uniform(1.01 * r, H - 1.01 * r)
    margin = 1.01 * r / cos
    x = y * shift + rng.uniform(margin, W - margin)
    key = (math.floor(x / gap), math.floor(y / gap))
    if any((x - a) ** 2 + (y - b) ** 2 < gap * gap
           for dx in (-1, 0, 1) for dy in (-1, 0, 1)
           for a, b in buckets.get((key[0] + dx, key[1] + dy), [])):
        continue
    buckets.setdefault(key, []).append((x, y))
    placed.append((x, y))
with open(base + "_grains.txt", "w") as out:
    out.write("# %d discs of radius %g at area fraction %g, made by "
              "boycott_2d.py %g\n" % (len(placed), r, phi, angle))
    for x, y in placed:
        out.write("%.9g %.9g\n" % (x, y))
