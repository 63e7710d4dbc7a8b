#!/usr/bin/env python3
"""A picture of a 2D run: the mesh coloured by a cell field (refinement
level by default) or by a point field, with the grains on top.

Reads the VTU pieces that immersed-grains writes (deal.II's zlib-compressed
binary XML), so no ParaView is needed:

    /usr/bin/python3 scripts/plot_scene.py output/falling_cloud_2d [--step N]
        [--field refinement_level|mpi_rank|fluid_fraction|pressure|speed]
        [--window x0,x1,y0,y1] [--out picture.png]

Without --step the last written state is drawn.
"""
import argparse
import base64
import glob
import os
import re
import struct
import sys
import zlib

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

TYPES = {"Float32": np.float32, "Float64": np.float64, "Int32": np.int32,
         "UInt8": np.uint8, "Int64": np.int64, "UInt32": np.uint32}


def decode(text, dtype):
    """One binary DataArray: a base64 header of UInt32 block sizes, then the
    base64 zlib blocks (VTK's compressed format), or raw base64 data."""
    text = text.strip()
    head = base64.b64decode(text[:8])
    n_blocks = struct.unpack("<I", head[:4])[0]
    header_len = 4 * (3 + n_blocks)
    header_b64 = 4 * ((header_len + 2) // 3)
    header = base64.b64decode(text[:header_b64])
    sizes = struct.unpack("<%dI" % (3 + n_blocks), header[:header_len])
    data = base64.b64decode(text[header_b64:])
    out, at = b"", 0
    for size in sizes[3:]:
        out += zlib.decompress(data[at:at + size])
        at += size
    return np.frombuffer(out, dtype=dtype)


def read_vtu(path):
    text = open(path).read()
    arrays = {}
    for m in re.finditer(r'<DataArray type="(\w+)" Name="(\w+)"'
                         r'(?: NumberOfComponents="(\d+)")? format="(\w+)"'
                         r'[^>]*>(.*?)</DataArray>', text, re.S):
        dtype, name, ncomp, fmt, body = m.groups()
        if fmt == "ascii":
            values = np.array(body.split(), dtype=TYPES[dtype])
        else:
            values = decode(body, TYPES[dtype])
        if ncomp:
            values = values.reshape(-1, int(ncomp))
        arrays.setdefault(name, values)
    # Points have no Name in deal.II's files.
    m = re.search(r'<Points>\s*<DataArray type="(\w+)" NumberOfComponents='
                  r'"3" format="(\w+)"[^>]*>(.*?)</DataArray>', text, re.S)
    if m is None:
        # A rank that holds no grains writes a piece without points, its
        # arrays empty and without a format.
        for m in re.finditer(r'<DataArray type="(\w+)" Name="(\w+)"'
                             r'(?: NumberOfComponents="(\d+)")?>', text):
            dtype, name, ncomp = m.groups()
            arrays.setdefault(name, np.zeros((0, int(ncomp)) if ncomp
                                             else 0, dtype=TYPES[dtype]))
        return np.zeros((0, 3)), arrays, []
    dtype, fmt, body = m.groups()
    points = (np.array(body.split(), dtype=float) if fmt == "ascii"
              else decode(body, TYPES[dtype])).reshape(-1, 3)
    cell_names = re.findall(r'Name="(\w+)"',
                            text[text.find("<CellData"):text.find("</CellData>")]
                            ) if "<CellData" in text else []
    return points, arrays, cell_names


def pvd_states(directory, series):
    """(time, the .vtu files of its pieces) of every state the list
    @p series (e.g. "particles.pvd") in a run's output directory holds;
    empty when there is none."""
    try:
        with open(os.path.join(directory, series)) as f:
            entries = re.findall(r'timestep="([^"]+)".*?file="([^"]+)"',
                                 f.read())
    except OSError:
        return []
    out = []
    for time, name in entries:
        base = os.path.join(directory, name)
        out.append((float(time), [base] if name.endswith(".vtu") else sorted(
            glob.glob(base.replace(".pvtu", ".*.vtu")))))
    return out


def particle_states(directory, caller, names=()):
    """(time, grain centres) of every state particles.pvd lists in a run's
    output directory, whatever the number of pieces; with @p names, (time,
    centres, {name: values}) with those particle fields (e.g. "radius").
    @p caller names the script in the message when there is none."""
    entries = pvd_states(directory, "particles.pvd")
    if not entries:
        sys.exit(caller + ": no particles.pvd in " + directory)
    out = []
    for time, files in entries:
        pieces_read = [read_vtu(f) for f in files]
        centres = np.concatenate([p[0] for p in pieces_read])
        if not names:
            out.append((time, centres))
            continue
        missing = [n for n in names if n not in pieces_read[0][1]]
        if missing:
            sys.exit("%s: no particle field %s in %s" %
                     (caller, ", ".join(missing), files[0]))
        out.append((time, centres,
                    {n: np.concatenate([p[1][n] for p in pieces_read])
                     for n in names}))
    return out


def run_parameters(directory, caller):
    """Each 'set' of the run's copy of its parameter file in @p directory,
    by its path ("Mesh/Upper corner"); @p caller names the script in the
    message when there is none."""
    files = glob.glob(os.path.join(directory, "*.prm"))
    if not files:
        sys.exit("%s: no copy of the parameter file (*.prm) in %s"
                 % (caller, directory))
    values, path = {}, []
    with open(files[0]) as f:
        for line in f:
            line = line.split("#")[0].strip()
            if line.startswith("subsection "):
                path.append(line[len("subsection "):].strip())
            elif line == "end" and path:
                path.pop()
            else:
                m = re.match(r"set\s+(.*?)\s*=\s*(.*)", line)
                if m:
                    values["/".join(path + [m.group(1)])] = m.group(2)
    return values


def pieces(directory, prefix, step):
    files = sorted(glob.glob(os.path.join(directory, prefix + "_*.vtu")))
    steps = sorted({int(re.search(prefix + r"_(\d+)\.", f).group(1))
                    for f in files})
    if not steps:
        sys.exit("plot_scene.py: no %s_*.vtu in %s" % (prefix, directory))
    chosen = steps[-1] if step is None else step
    if chosen not in steps:
        sys.exit("plot_scene.py: no written state %d in %s (have %s)"
                 % (chosen, directory, steps))
    return chosen, [f for f in files
                    if re.search(prefix + r"_%05d\." % chosen, f)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("directory")
    parser.add_argument("--step", type=int)
    parser.add_argument("--field", default="refinement_level")
    parser.add_argument("--window",
                        help="x0,x1,y0,y1: the part of the domain to draw")
    parser.add_argument("--out")
    args = parser.parse_args()

    step, field_files = pieces(args.directory, "fields", args.step)
    polygons, colours = [], []
    for path in field_files:
        points, arrays, cell_names = read_vtu(path)
        offsets = arrays["offsets"].astype(int)
        connectivity = arrays["connectivity"].astype(int)
        start = np.concatenate([[0], offsets[:-1]])
        if args.field == "speed":
            values = np.linalg.norm(arrays["velocity"], axis=1)
        else:
            values = arrays[args.field]
        on_cells = args.field in cell_names
        for c, (a, b) in enumerate(zip(start, offsets)):
            nodes = connectivity[a:b]
            polygons.append(points[nodes][:, :2])
            colours.append(values[c] if on_cells else values[nodes].mean())
    figure, axes = plt.subplots(figsize=(5, 7))
    collection = PolyCollection(polygons, array=np.array(colours),
                                cmap="viridis", edgecolors="k",
                                linewidths=0.15)
    axes.add_collection(collection)
    figure.colorbar(collection, ax=axes, label=args.field.replace("_", " "))

    try:
        _, particle_files = pieces(args.directory, "particles", step)
    except SystemExit:
        particle_files = []
    for path in particle_files:
        points, arrays, _ = read_vtu(path)
        if len(points):
            axes.scatter(points[:, 0], points[:, 1], s=1.5, c="w",
                         edgecolors="none")
    if args.window:
        x0, x1, y0, y1 = (float(v) for v in args.window.split(","))
    else:
        all_points = np.concatenate(polygons)
        x0, x1 = all_points[:, 0].min(), all_points[:, 0].max()
        y0, y1 = all_points[:, 1].min(), all_points[:, 1].max()
    axes.set_xlim(x0, x1)
    axes.set_ylim(y0, y1)
    axes.set_aspect("equal")
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.set_title("%s, output %d" % (os.path.basename(
        os.path.normpath(args.directory)), step))
    out = args.out or os.path.join(args.directory,
                                   "%s_%05d.png" % (args.field, step))
    figure.savefig(out, dpi=150, bbox_inches="tight")
    print(out)


if __name__ == "__main__":
    main()
