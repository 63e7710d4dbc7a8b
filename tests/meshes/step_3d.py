#!/usr/bin/env python3
"""Writes step_3d.msh (Gmsh format 2.2 ASCII): the cube [0, 2]^3 without the
block [1, 2] x [1, 2] x [0, 1], in hexahedra of edge 0.5. The block's faces
are physical surface 2, the cube's faces physical surface 1, the cells
physical volume 10. The block has convex edges (x = 1 or y = 1 at z = 1,
and x = y = 1 for z < 1) and a convex vertex at (1, 1, 1).

    python3 step_3d.py  (in this folder)
"""
n, h = 4, 0.5


def inside_block(i, j, k):
    """Whether cell (i, j, k) lies in the removed block."""
    return i >= 2 and j >= 2 and k < 2


def node(i, j, k):
    return 1 + i + (n + 1) * (j + (n + 1) * k)


cells = [(i, j, k) for k in range(n) for j in range(n) for i in range(n)
         if not inside_block(i, j, k)]
present = set(cells)

# Gmsh's hexahedron: the bottom face counter-clockwise, then the top one.
corners = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
           (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
# Each face of a cell: the neighbour's offset and the face's corners (in
# order round the face).
faces = {(-1, 0, 0): [(0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)],
         (1, 0, 0): [(1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 1, 0)],
         (0, -1, 0): [(0, 0, 0), (0, 0, 1), (1, 0, 1), (1, 0, 0)],
         (0, 1, 0): [(0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)],
         (0, 0, -1): [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
         (0, 0, 1): [(0, 0, 1), (0, 1, 1), (1, 1, 1), (1, 0, 1)]}

elements = []
for (i, j, k) in cells:
    for offset, quad in faces.items():
        m = (i + offset[0], j + offset[1], k + offset[2])
        if m in present:
            continue
        on_cube = not all(0 <= c < n for c in m)
        tag = 1 if on_cube else 2
        elements.append((3, tag, [node(i + a, j + b, k + c)
                                  for (a, b, c) in quad]))
for (i, j, k) in cells:
    elements.append((5, 10, [node(i + a, j + b, k + c)
                             for (a, b, c) in corners]))

with open("step_3d.msh", "w") as f:
    f.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n")
    f.write(f"{(n + 1) ** 3}\n")
    for k in range(n + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                f.write(f"{node(i, j, k)} {i * h:g} {j * h:g} {k * h:g}\n")
    f.write(f"$EndNodes\n$Elements\n{len(elements)}\n")
    for number, (kind, tag, nodes) in enumerate(elements, 1):
        f.write(f"{number} {kind} 2 {tag} {tag} "
                + " ".join(map(str, nodes)) + "\n")
    f.write("$EndElements\n")
