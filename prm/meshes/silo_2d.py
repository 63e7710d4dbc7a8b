#!/usr/bin/env python3
"""Writes a flat-bottomed 2D silo as a Gmsh mesh (format 2.2 ASCII): the box
[0, W] x [0, H] in square cells of edge h, its floor open over the centred
orifice of width D (physical line 2), walls elsewhere (physical line 1),
the cells physical surface 10.

    python3 silo_2d.py D [W H h] > silo_2d.msh

D must be a whole number of cells, of the same parity as W/h so that the
orifice is centred (defaults: W = 0.4, H = 0.8, h = 0.02 m).
"""
import sys

D = float(sys.argv[1])
W, H, h = (float(x) for x in sys.argv[2:5]) if len(sys.argv) > 4 else \
    (0.4, 0.8, 0.02)
nx, ny, nd = round(W / h), round(H / h), round(D / h)
if abs(nd * h - D) > 1e-9 * W or (nx - nd) % 2:
    sys.exit("silo_2d.py: D = %g is not a centred whole number of cells" % D)
first_open = (nx - nd) // 2


def node(i, j):
    return 1 + i + (nx + 1) * j


elements = []
for i in range(nx):
    is_open = first_open <= i < first_open + nd
    elements.append((1, 2 if is_open else 1, [node(i, 0), node(i + 1, 0)]))
    elements.append((1, 1, [node(i, ny), node(i + 1, ny)]))
for j in range(ny):
    elements.append((1, 1, [node(0, j), node(0, j + 1)]))
    elements.append((1, 1, [node(nx, j), node(nx, j + 1)]))
for j in range(ny):
    for i in range(nx):
        elements.append((3, 10, [node(i, j), node(i + 1, j),
                                 node(i + 1, j + 1), node(i, j + 1)]))

out = sys.stdout
out.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n")
out.write(f"{(nx + 1) * (ny + 1)}\n")
for j in range(ny + 1):
    for i in range(nx + 1):
        out.write(f"{node(i, j)} {i * h:.10g} {j * h:.10g} 0\n")
out.write(f"$EndNodes\n$Elements\n{len(elements)}\n")
for number, (kind, tag, nodes) in enumerate(elements, 1):
    out.write(f"{number} {kind} 2 {tag} {tag} " + " ".join(map(str, nodes))
              + "\n")
out.write("$EndElements\n")
