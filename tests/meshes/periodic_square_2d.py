#!/usr/bin/env python3
"""Writes periodic_square_2d.msh (Gmsh format 2.2 ASCII): the square
[0, 3.2e-3]^2 in 16 x 16 quadrilaterals whose inner nodes are moved off
the lattice by the smooth shift (dx, dy) = a sin(2 pi x / L) sin(2 pi y / L)
(1, -1), a = 0.3 h, so that no cell is a rectangle (the cells are general
quadrilaterals, their mapping bilinear). The boundary nodes stay on the
lattice: the sides are straight, and the nodes of opposite sides match
by a shift of L, as a mesh made with Gmsh's Periodic Curve does. Physical
curves: 1 the bottom (y = 0), 2 the right (x = L), 3 the top, 4 the left;
the cells physical surface 10. It also writes periodic_mismatch_2d.msh,
the same square with the inner nodes of its right side moved up by 0.3 h:
sides that do not match by a shift (a bad-input case).

    python3 periodic_square_2d.py  (in this folder)
"""
import math

n, L = 16, 3.2e-3
h = L / n
a = 0.3 * h


def node(i, j):
    return 1 + i + (n + 1) * j


def position(i, j, mismatch):
    x, y = i * h, j * h
    if mismatch and i == n and 0 < j < n:
        y += 0.3 * h
    if 0 < i < n and 0 < j < n:
        s = a * math.sin(2 * math.pi * x / L) * math.sin(2 * math.pi * y / L)
        x, y = x + s, y - s
    return x, y


def write(name, mismatch):
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes",
             str((n + 1) ** 2)]
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = position(i, j, mismatch)
            lines.append(f"{node(i, j)} {x!r} {y!r} 0")
    lines.append("$EndNodes")

    elements = []
    for i in range(n):
        elements.append((1, 1, [node(i, 0), node(i + 1, 0)]))
        elements.append((1, 3, [node(i + 1, n), node(i, n)]))
    for j in range(n):
        elements.append((1, 2, [node(n, j), node(n, j + 1)]))
        elements.append((1, 4, [node(0, j + 1), node(0, j)]))
    for j in range(n):
        for i in range(n):
            elements.append((3, 10, [node(i, j), node(i + 1, j),
                                     node(i + 1, j + 1), node(i, j + 1)]))
    lines += ["$Elements", str(len(elements))]
    for k, (kind, group, nodes) in enumerate(elements, start=1):
        lines.append(f"{k} {kind} 2 {group} {group} " +
                     " ".join(map(str, nodes)))
    lines.append("$EndElements")
    with open(name, "w") as f:
        f.write("\n".join(lines) + "\n")


write("periodic_square_2d.msh", False)
write("periodic_mismatch_2d.msh", True)
