#!/usr/bin/env python3
"""Writes outlet_2d.msh (Gmsh format 2.2 ASCII): the unit square in 10 x 10
quadrilaterals, its floor open between x = 0.4 and 0.6 (physical line 2),
the rest of its boundary physical line 1, the cells physical surface 10.

    python3 outlet_2d.py  (in this folder)
"""
n = 10


def node(i, j):
    return 1 + i + (n + 1) * j


elements = []
for i in range(n):  # floor, then top
    elements.append((1, 2 if 4 <= i < 6 else 1, [node(i, 0), node(i + 1, 0)]))
    elements.append((1, 1, [node(i, n), node(i + 1, n)]))
for j in range(n):  # sides
    elements.append((1, 1, [node(0, j), node(0, j + 1)]))
    elements.append((1, 1, [node(n, j), node(n, j + 1)]))
for j in range(n):
    for i in range(n):
        elements.append((3, 10, [node(i, j), node(i + 1, j),
                                 node(i + 1, j + 1), node(i, j + 1)]))

with open("outlet_2d.msh", "w") as f:
    f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n")
    f.write(f"{(n + 1) ** 2}\n")
    for j in range(n + 1):
        for i in range(n + 1):
            f.write(f"{node(i, j)} {i / n:g} {j / n:g} 0\n")
    f.write(f"$EndNodes\n$Elements\n{len(elements)}\n")
    for number, (kind, tag, nodes) in enumerate(elements, 1):
        f.write(f"{number} {kind} 2 {tag} {tag} "
                + " ".join(map(str, nodes)) + "\n")
    f.write("$EndElements\n")
