#!/usr/bin/env python3
"""Writes a flat-bottomed 2D silo as a Gmsh mesh (format 2.2 ASCII): the box
[0, W] x [0, H] in square cells of edge h, its floor open over the centred
orifice of width D (physical line 2), walls elsewhere (physical line 1),
the cells physical surface 10. With --open-top the top is physical line 3
(a silo standing in a tank of liquid, open to it above).

    python3 silo_2d.py [--open-top] D [W H h] > silo_2d.msh

D must be a whole number of cells, of the same parity as W/h so that the
orifice is centred (defaults: W = 0.4, H = 0.8, h = 0.02 m).
"""
import os
import sys

arguments = sys.argv[1:]
open_top = "--open-top" in arguments
if open_top:
    arguments.remove("--open-top")
D = float(arguments[0])
W, H, h = (float(x) for x in arguments[1:4]) if len(arguments) > 3 else \
    (0.4, 0.8, 0.02)
nx, ny, nd = round(W / h), round(H / h), round(D / h)
if abs(nd * h - D) > 1e-9 * W or (nx - nd) % 2:
    sys.exit("silo_2d.py: D = %g is not a centred whole number of cells" % D)
first_open = (nx - nd) // 2


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import structured_2d  # noqa: E402

structured_2d.write(
    sys.stdout, nx, ny, lambda i, j: (i * h, j * h),
    lambda i: 2 if first_open <= i < first_open + nd else 1,
    3 if open_top else 1)
