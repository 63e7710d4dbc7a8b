"""A structured 2D mesh of nx x ny quadrilaterals in Gmsh's format 2.2
ASCII, for the scripts of this folder: the cells physical surface 10, the
boundary lines physical line 1 except the floor's segments that
floor_tag(i) gives another tag and the top's, top_tag."""


def write(out, nx, ny, point, floor_tag=lambda i: 1, top_tag=1):
    """point(i, j) gives the (x, y) of the node in column i, row j."""
    def node(i, j):
        return 1 + i + (nx + 1) * j

    elements = []
    for i in range(nx):
        elements.append((1, floor_tag(i), [node(i, 0), node(i + 1, 0)]))
        elements.append((1, top_tag, [node(i, ny), node(i + 1, ny)]))
    for j in range(ny):
        elements.append((1, 1, [node(0, j), node(0, j + 1)]))
        elements.append((1, 1, [node(nx, j), node(nx, j + 1)]))
    for j in range(ny):
        for i in range(nx):
            elements.append((3, 10, [node(i, j), node(i + 1, j),
                                     node(i + 1, j + 1), node(i, j + 1)]))
    out.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n")
    out.write(f"{(nx + 1) * (ny + 1)}\n")
    for j in range(ny + 1):
        for i in range(nx + 1):
            x, y = point(i, j)
            out.write(f"{node(i, j)} {x:.10g} {y:.10g} 0\n")
    out.write(f"$EndNodes\n$Elements\n{len(elements)}\n")
    for number, (kind, tag, nodes) in enumerate(elements, 1):
        out.write(f"{number} {kind} 2 {tag} {tag} "
                  + " ".join(map(str, nodes)) + "\n")
    out.write("$EndElements\n")
