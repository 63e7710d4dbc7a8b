#!/usr/bin/env python3
"""Figures of a falling-cloud run from its output directory (3D runs are
drawn from the side, x across and z up, and have no flow figure):

    /usr/bin/python3 scripts/plot_cloud.py OUTPUT_DIR [--out-prefix P]
        [--stages t1,t2,t3,t4,t5] [--flow t1,t2] [--half-width W]
        [--groups N] [--reference-velocity U]
    /usr/bin/python3 scripts/plot_cloud.py OUTPUT_DIR --clusters t1,t2,...
        [--link-distance L] [--core-neighbours N]

writes
  P_stages.png  the grains at five instants side by side, each framed on
                the cloud's centroid (by default the start, half the
                break-up time, the break-up, a third of the way from there
                to the end, and the end; without a break-up five instants
                evenly spaced); in 3D a second row shows only the grains
                in a vertical slab through the centroid (|y - y_c| below a
                fifth of the cloud's initial radius, --slab), where a torus
                shows as two blobs with a gap between them, and a third
                row the cloud from below, where a torus shows as a ring
                and its break-up as droplets along it;
  P_flow.png    at two instants: the pressure less its hydrostatic part
                (colour) and the streamlines of the fluid velocity, with the
                grains on top (by default the middle of the run and just
                after the break-up, or its end);
  P_series.png  from statistics.csv: the cloud's velocity, its extent per
                axis, the leaked grains and the number of clusters, the
                break-up time marked.

  P_groups.png  with --groups N (N clouds placed one after another): each
                cloud's fall velocity and the vertical distance between
                consecutive clouds' centroids; the stages colour each.
  P_front.png   2D: the maxima of the over-pressure ahead of the cloud
  P_front.csv   against time, across the fall (doc/output.md, "The front
                over-pressure"): one at the cloud's front while it is
                whole, two once it has split; the first time two are seen
                is printed.

P defaults to OUTPUT_DIR/cloud. Needs the Cloud analysis columns (on by
default for a ball of grains) and fields written at the chosen instants
(Output/Write fields every); each instant is taken as the nearest written
state. Reads the VTU files directly (scripts/plot_scene.py's reader).
"""
import argparse
import csv
import os
import re
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_scene import read_vtu  # noqa: E402


def read_statistics(directory):
    path = os.path.join(directory, "statistics.csv")
    if not os.path.exists(path):
        sys.exit("plot_cloud.py: no statistics.csv in %s" % directory)
    rows = list(csv.DictReader(open(path)))
    if not rows or "cloud_centroid_x" not in rows[0]:
        sys.exit("plot_cloud.py: %s has no cloud columns (Cloud analysis)"
                 % path)
    # In 3D the pictures are side views: x across, z (along gravity) up.
    global VERTICAL
    VERTICAL = "z" if "cloud_centroid_z" in rows[0] else "y"
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


VERTICAL = "y"  # the vertical axis's name, set by read_statistics()


def view(points):
    """The drawn coordinates: (x, y) in 2D, (x, z) in 3D."""
    return points[:, [0, 2 if VERTICAL == "z" else 1]]


def written_states(directory, prefix):
    """(time, [piece files]) per state in PREFIX.pvd."""
    pvd = os.path.join(directory, prefix + ".pvd")
    if not os.path.exists(pvd):
        sys.exit("plot_cloud.py: no %s" % pvd)
    states = []
    for t, name in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"',
                              open(pvd).read()):
        master = os.path.join(directory, name)
        if name.endswith(".pvtu"):
            pieces = [os.path.join(directory, p) for p in re.findall(
                r'Piece Source="([^"]+)"', open(master).read())]
        else:
            pieces = [master]
        states.append((float(t), pieces))
    if not states:
        sys.exit("plot_cloud.py: %s lists no states" % pvd)
    return states


def nearest(states, t):
    return min(states, key=lambda s: abs(s[0] - t))


def grains_at(pieces, with_ids=False, full=False):
    """The grains' drawn coordinates (all three with @p full)."""
    points, ids = [], []
    for path in pieces:
        x, arrays, _ = read_vtu(path)
        if len(x):
            points.append(x if full else view(x))
            ids.append(arrays["id"].astype(np.int64))
    x = np.concatenate(points) if points else np.zeros((0, 3 if full else 2))
    if with_ids:
        return x, (np.concatenate(ids) if ids else np.zeros(0, np.int64))
    return x


def group_of(ids, n_grains, groups):
    """Clouds placed one after another (Grains/Placement/Center with
    several centres) have consecutive ids: group k holds the k-th share."""
    return np.minimum(ids * groups // max(n_grains, 1), groups - 1)


def fields_at(pieces):
    xs, ps, vs = [], [], []
    for path in pieces:
        points, arrays, _ = read_vtu(path)
        xs.append(points[:, :2])
        ps.append(arrays["pressure"])
        vs.append(arrays["velocity"][:, :2])
    x, p, v = np.concatenate(xs), np.concatenate(ps), np.concatenate(vs)
    # deal.II writes each cell's nodes apart: merge coincident points.
    key = np.round(x / (1e-9 * np.ptp(x, axis=0).max()))
    _, unique = np.unique(key, axis=0, return_index=True)
    return x[unique], p[unique], v[unique]


def centroid_at(stats, t):
    return (np.interp(t, stats["time"], stats["cloud_centroid_x"]),
            np.interp(t, stats["time"], stats["cloud_centroid_" + VERTICAL]))


def frame(axes, centre, half_width):
    axes.set_xlim(centre[0] - half_width, centre[0] + half_width)
    axes.set_ylim(centre[1] - half_width, centre[1] + half_width)
    axes.set_aspect("equal")
    axes.set_xticks([])
    axes.set_yticks([])


def plot_stages(directory, stats, times, half_width, out, groups, slab=0.0):
    particles = written_states(directory, "particles")
    n_grains = int(stats["particles"][0])
    rows = 3 if VERTICAL == "z" else 1
    figure, panels = plt.subplots(rows, len(times), squeeze=False,
                                  figsize=(2.6 * len(times), 3.0 * rows))
    for column, t in enumerate(times):
        t_state, pieces = nearest(particles, t)
        x, ids = grains_at(pieces, with_ids=True, full=rows == 3)
        centre = centroid_at(stats, t_state)
        colour = np.array(["k", "tab:red", "tab:blue", "tab:green"])[
            group_of(ids, n_grains, groups) % 4]
        for row in range(rows):
            axes = panels[row][column]
            shown = np.ones(len(x), dtype=bool)
            framed_on = centre
            if rows == 3:
                y_c = np.interp(t_state, stats["time"],
                                stats["cloud_centroid_y"])
            if rows == 3 and row == 1:
                shown = np.abs(x[:, 1] - y_c) < slab
            if rows == 3 and row == 2:
                # From below, as the experiments photograph a torus.
                drawn = x[:, :2]
                framed_on = (centre[0], y_c)
            else:
                drawn = view(x[shown]) if rows == 3 else x
            axes.scatter(drawn[:, 0], drawn[:, 1],
                         s=1.2 if VERTICAL == "y" or row == 1 else 0.3,
                         c=colour[shown], edgecolors="none",
                         alpha=1 if VERTICAL == "y" or row == 1 else 0.4)
            frame(axes, framed_on, half_width)
            if row == 0:
                axes.set_title("t = %.3g s" % t_state, fontsize=10)
    panels[0][0].set_ylabel("%.2g mm frames on the centroid"
                            % (2e3 * half_width), fontsize=8)
    if rows == 3:
        panels[1][0].set_ylabel("slab |y - y_c| < %.2g mm" % (1e3 * slab),
                                fontsize=8)
        panels[2][0].set_ylabel("from below (x, y)", fontsize=8)
    figure.tight_layout()
    figure.savefig(out, dpi=150)
    plt.close(figure)
    print(out)


def plot_flow(directory, stats, times, half_width, out):
    fields = written_states(directory, "fields")
    particles = written_states(directory, "particles")
    figure, panels = plt.subplots(1, len(times),
                                  figsize=(4.6 * len(times), 4.2))
    for axes, t in zip(np.atleast_1d(panels), times):
        t_state, pieces = nearest(fields, t)
        x, p, v = fields_at(pieces)
        excess = excess_pressure(x, p)
        centre = centroid_at(stats, t_state)
        triangulation = mtri.Triangulation(x[:, 0], x[:, 1])
        n = 120
        gx = np.linspace(centre[0] - half_width, centre[0] + half_width, n)
        gy = np.linspace(centre[1] - half_width, centre[1] + half_width, n)
        X, Y = np.meshgrid(gx, gy)
        grid = [mtri.LinearTriInterpolator(triangulation, f)(X, Y)
                for f in (excess, v[:, 0], v[:, 1])]
        limit = np.nanmax(np.abs(grid[0]))
        image = axes.pcolormesh(X, Y, grid[0], cmap="RdBu_r",
                                vmin=-limit, vmax=limit, shading="auto")
        figure.colorbar(image, ax=axes, label="pressure - hydrostatic [Pa]",
                        shrink=0.8)
        axes.streamplot(gx, gy, np.ma.filled(grid[1], 0.),
                        np.ma.filled(grid[2], 0.), color="0.25",
                        density=1.2, linewidth=0.6, arrowsize=0.6)
        g = grains_at(nearest(particles, t_state)[1])
        axes.scatter(g[:, 0], g[:, 1], s=0.8, c="k", edgecolors="none")
        frame(axes, centre, half_width)
        axes.set_title("t = %.3g s" % t_state, fontsize=10)
    figure.tight_layout()
    figure.savefig(out, dpi=150)
    plt.close(figure)
    print(out)


def plot_series(stats, out, reference=None):
    t = stats["time"]
    breakup = stats["breakup_time"][-1]
    figure, panels = plt.subplots(2, 2, figsize=(9, 6), sharex=True)
    panels[0, 0].plot(t, -stats["cloud_velocity_" + VERTICAL] * 1e3)
    if reference:
        panels[0, 0].axhline(reference * 1e3, color="0.4", ls=":",
                             label="reference %.4g mm/s" % (reference * 1e3))
        panels[0, 0].legend(fontsize=8)
    panels[0, 0].set_ylabel("cloud fall velocity [mm/s]")
    panels[0, 1].plot(t, stats["cloud_extent_x"] * 1e3, label="horizontal")
    panels[0, 1].plot(t, stats["cloud_extent_" + VERTICAL] * 1e3,
                      label="vertical")
    panels[0, 1].set_ylabel("radius of gyration [mm]")
    panels[0, 1].legend(fontsize=8)
    panels[1, 0].plot(t, stats["leaked"], label="outside the largest cluster")
    panels[1, 0].plot(t, stats["particles"] - stats["cloud_grains"],
                      label="in the loose tail")
    panels[1, 0].set_ylabel("grains")
    panels[1, 0].legend(fontsize=8)
    panels[1, 1].step(t, stats["clusters"], where="post")
    panels[1, 1].set_ylabel("clusters")
    for axes in panels.flat:
        if breakup >= 0:
            axes.axvline(breakup, color="r", lw=0.8, ls="--")
        axes.grid(alpha=0.3)
    for axes in panels[1]:
        axes.set_xlabel("t [s]")
    title = "break-up at t = %.3g s" % breakup if breakup >= 0 else \
        "no break-up"
    figure.suptitle(title, fontsize=10)
    figure.tight_layout()
    figure.savefig(out, dpi=150)
    plt.close(figure)
    print(out)


def plot_groups(directory, stats, groups, out):
    """Each placed cloud's centroid height and fall velocity, and the
    vertical distance between consecutive clouds, from the particle
    files (every written state)."""
    particles = written_states(directory, "particles")
    n_grains = int(stats["particles"][0])
    times, heights = [], []
    for t, pieces in particles:
        x, ids = grains_at(pieces, with_ids=True)
        g = group_of(ids, n_grains, groups)
        times.append(t)
        heights.append([x[g == k, 1].mean() for k in range(groups)])
    times, heights = np.array(times), np.array(heights)
    figure, panels = plt.subplots(1, 2, figsize=(9, 3.4))
    colours = ["k", "tab:red", "tab:blue", "tab:green"]
    for k in range(groups):
        velocity = -np.gradient(heights[:, k], times)
        panels[0].plot(times, velocity * 1e3, color=colours[k % 4],
                       label="cloud %d" % (k + 1))
    panels[0].set_ylabel("fall velocity of each cloud's grains [mm/s]")
    panels[0].legend(fontsize=8)
    for k in range(groups - 1):
        panels[1].plot(times, (heights[:, k + 1] - heights[:, k]) * 1e3,
                       color=colours[(k + 1) % 4],
                       label="cloud %d above cloud %d" % (k + 2, k + 1))
    panels[1].axhline(0, color="0.5", lw=0.8)
    panels[1].set_ylabel("vertical distance between centroids [mm]")
    panels[1].legend(fontsize=8)
    for axes in panels:
        axes.set_xlabel("t [s]")
        axes.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(out, dpi=150)
    plt.close(figure)
    print(out)


def excess_pressure(x, p):
    """The pressure less its hydrostatic part: the least-squares plane
    through the whole domain (the mixture's mean weight)."""
    basis = np.column_stack([np.ones(len(x)), x[:, 0], x[:, 1]])
    return p - basis @ np.linalg.lstsq(basis, p, rcond=None)[0]


def smoothed(grid, sigma):
    """Gaussian smoothing of a 2D array, sigma in grid spacings; the
    kernel is renormalised at the edges, so that a constant stays one."""
    k = np.arange(-int(3 * sigma), int(3 * sigma) + 1)
    w = np.exp(-0.5 * (k / sigma) ** 2)

    def along(a, axis):
        return np.apply_along_axis(lambda r: np.convolve(r, w, "same"),
                                   axis, a)
    ones = np.ones_like(grid)
    return along(along(grid, 1), 0) / along(along(ones, 1), 0)


def front_maxima(directory, stats, radius, out):
    """Per written state: the maxima of the excess pressure, smoothed
    over half the cloud's radius, along the row where it peaks within two
    radii ahead of the cloud (below its centroid), those above half of
    the row's range; x relative to the centroid, in cloud radii.
    Smoothing over R/2: at cells of R/4 the pressure is grainy at the cell
    scale, and unsmoothed rows flicker between one and two maxima (R/4
    to R/2 smoothing give the same split within 0.1 s on the main scene,
    doc/scenes/falling_cloud_2d.md)."""
    fields = written_states(directory, "fields")
    spacing = radius / 20
    n = 121  # +-3 R
    rows = []
    for t, pieces in fields:
        x, p, _ = fields_at(pieces)
        excess = excess_pressure(x, p)
        cx, cy = centroid_at(stats, t)
        gx = cx + spacing * (np.arange(n) - n // 2)
        gy = cy + spacing * (np.arange(n) - n // 2)
        X, Y = np.meshgrid(gx, gy)
        grid = mtri.LinearTriInterpolator(
            mtri.Triangulation(x[:, 0], x[:, 1]), excess)(X, Y)
        inside = ~np.ma.getmaskarray(grid)
        field = smoothed(np.ma.filled(grid, 0.0), 10.0)
        front = inside & (Y < cy) & (Y > cy - 2 * radius)
        if not front.any():
            continue
        i = np.unravel_index(np.argmax(np.where(front, field, -np.inf)),
                             field.shape)[0]
        row, ok = field[i], inside[i]
        valid = row[ok]
        threshold = valid.min() + 0.5 * (valid.max() - valid.min())
        maxima = [(gx[j] - cx) / radius for j in range(1, n - 1)
                  if ok[j - 1] and ok[j] and ok[j + 1] and
                  row[j] > row[j - 1] and row[j] >= row[j + 1] and
                  row[j] > threshold]
        rows.append((t, maxima))
    with open(out + ".csv", "w") as f:
        f.write("time,maxima,positions_over_R\n")
        for t, maxima in rows:
            f.write("%.6g,%d,%s\n" % (t, len(maxima),
                                      " ".join("%.3f" % m for m in maxima)))
    figure, axes = plt.subplots(figsize=(6, 3.4))
    for t, maxima in rows:
        axes.plot([t] * len(maxima), maxima, "k.", ms=3)
    breakup = stats["breakup_time"][-1]
    if breakup >= 0:
        axes.axvline(breakup, color="r", lw=0.8, ls="--",
                     label="break-up (clusters)")
        axes.legend(fontsize=8)
    axes.set_xlabel("t [s]")
    axes.set_ylabel("front over-pressure maxima, (x - x_c) / R")
    axes.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(out + ".png", dpi=150)
    plt.close(figure)
    split = next((t for t, maxima in rows if len(maxima) >= 2), None)
    print(out + ".png")
    print(out + ".csv")
    print("front over-pressure: " +
          ("two maxima first at t = %.3g s (written states)" % split
           if split is not None else "one maximum throughout"))


def clusters_of(x, diameter, link, core):
    """The cloud analysis's clusters (doc/theory.md): grains closer than
    @p link diameters are linked; a grain with at least @p core linked
    neighbours is a core grain; clusters grow from core grains, and other
    grains join the cluster of a core grain they are linked to. Returns a
    label per grain, -1 for grains in no cluster."""
    cut = link * diameter
    keys = np.floor(x / cut).astype(np.int64)
    buckets = {}
    for i, key in enumerate(map(tuple, keys)):
        buckets.setdefault(key, []).append(i)
    offsets = np.array(np.meshgrid(*[[-1, 0, 1]] * x.shape[1])).reshape(
        x.shape[1], -1).T
    neighbours = [None] * len(x)
    for key, members in buckets.items():
        near = np.array([j for o in offsets
                         for j in buckets.get(tuple(np.add(key, o)), [])])
        for i in members:
            close = np.sum((x[near] - x[i]) ** 2, axis=1) < cut * cut
            neighbours[i] = near[close & (near != i)]
    is_core = np.array([len(n) >= core for n in neighbours])
    label = -np.ones(len(x), dtype=int)
    count = 0
    for start in np.flatnonzero(is_core):
        if label[start] >= 0:
            continue
        label[start] = count
        stack = [start]
        while stack:
            for j in neighbours[stack.pop()]:
                if label[j] < 0:
                    label[j] = count
                    if is_core[j]:
                        stack.append(j)
        count += 1
    return label


def print_clusters(directory, times, link, core):
    """A table of the clusters at the written states nearest to @p times:
    their sizes, largest first, and in 3D the azimuthal sectors (15
    degrees, from +x towards +y around the vertical through the grains'
    centroid) that each of the three largest occupies."""
    states = written_states(directory, "particles")
    print("t [s] | grains | clusters of >= 20 % | next largest | in none")
    sectors = []
    for t in times:
        time, pieces = nearest(states, t)
        read = [read_vtu(p) for p in pieces]
        x = np.concatenate([r[0] for r in read])
        radius = np.concatenate([r[1]["radius"] for r in read])
        # Links in diameters of the grain of mean volume, as the run's
        # own cloud analysis measures them.
        dim = 3 if VERTICAL == "z" else 2
        diameter = 2 * np.mean(radius ** dim) ** (1 / dim)
        label = clusters_of(x[:, :dim], diameter, link, core)
        sizes = np.bincount(label[label >= 0])
        order = np.argsort(-sizes)
        large = [int(sizes[k]) for k in order if sizes[k] >= 0.2 * len(x)]
        rest = [int(sizes[k]) for k in order[len(large):len(large) + 5]]
        print("%.3f | %d | %s | %s | %d" % (time, len(x), large, rest,
                                            int(np.sum(label < 0))))
        if VERTICAL == "z":
            c = x.mean(axis=0)
            angle = np.degrees(np.arctan2(x[:, 1] - c[1], x[:, 0] - c[0]))
            for k in order[:3]:
                counts = np.histogram(angle[label == k] % 360, bins=24,
                                      range=(0, 360))[0]
                sectors.append("%.3f  %5d: %s" % (
                    time, sizes[k], " ".join("%d" % n for n in counts)))
    if sectors:
        print("beads per 15-degree sector (0-15, 15-30, ...), three largest "
              "clusters:")
        print("\n".join(sectors))


def times_option(text, count, name):
    """The comma-separated times of option @p name: @p count of them, or
    any number if @p count is None."""
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        sys.exit("plot_cloud.py: %s takes times in seconds, comma "
                 "separated, not '%s'" % (name, text))
    if count is not None and len(values) != count:
        sys.exit("plot_cloud.py: %s needs %d times" % (name, count))
    return values


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("directory")
    parser.add_argument("--out-prefix")
    parser.add_argument("--stages", help="five times, comma separated")
    parser.add_argument("--flow", help="two times, comma separated")
    parser.add_argument("--groups", type=int, default=1,
                        help="clouds placed one after another (several "
                        "Grains/Placement/Center): colour each and write "
                        "P_groups.png with their heights and velocities")
    parser.add_argument("--reference-velocity", type=float,
                        help="a velocity [m/s] to draw beside the cloud's "
                        "(e.g. the Hadamard-Rybczynski estimate)")
    parser.add_argument("--slab", type=float,
                        help="3D: half the thickness of the slab through "
                        "the centroid drawn in the second row [m] (default: "
                        "a fifth of the cloud's initial radius)")
    parser.add_argument("--half-width", type=float,
                        help="half the side of each frame [m] (default: "
                        "six times the cloud's initial radius of gyration)")
    parser.add_argument("--clusters", help="times, comma separated: print "
                        "the clusters at the written states nearest to them "
                        "(sizes; in 3D the sectors around the axis each "
                        "occupies) instead of drawing")
    parser.add_argument("--link-distance", type=float, default=3,
                        help="with --clusters: Cloud analysis/Link distance "
                        "[diameters]")
    parser.add_argument("--core-neighbours", type=int, default=4,
                        help="with --clusters: Cloud analysis/Core "
                        "neighbours")
    args = parser.parse_args()

    stats = read_statistics(args.directory)
    if args.clusters:
        times = times_option(args.clusters, None, "--clusters")
        print_clusters(args.directory, times, args.link_distance,
                       args.core_neighbours)
        return
    prefix = args.out_prefix or os.path.join(args.directory, "cloud")
    end = stats["time"][-1]
    breakup = stats["breakup_time"][-1]
    half_width = args.half_width or 6 * max(stats["cloud_extent_x"][0],
                                            stats["cloud_extent_" + VERTICAL][0])
    default_stages = [0, breakup / 2, breakup, breakup + (end - breakup) / 3,
                      end] if breakup > 0 else list(np.linspace(0, end, 5))
    stages = times_option(args.stages, 5, "--stages") or default_stages
    flow = times_option(args.flow, 2, "--flow") or \
        [0.5 * (breakup if breakup > 0 else end),
         min(end, 1.2 * breakup) if breakup > 0 else end]
    # A uniform ball's radius of gyration per axis is R / sqrt(5).
    slab = args.slab or 0.2 * np.sqrt(5) * stats["cloud_extent_x"][0]
    plot_stages(args.directory, stats, stages, half_width,
                prefix + "_stages.png", args.groups, slab)
    if VERTICAL == "y":
        plot_flow(args.directory, stats, flow, half_width,
                  prefix + "_flow.png")
        # A uniform disc's radius of gyration per axis is half its radius.
        front_maxima(args.directory, stats, 2 * stats["cloud_extent_x"][0],
                     prefix + "_front")
    else:
        print("(no flow figure in 3D: open fields.pvd in ParaView)")
    plot_series(stats, prefix + "_series.png", args.reference_velocity)
    if args.groups > 1:
        plot_groups(args.directory, stats, args.groups, prefix + "_groups.png")


if __name__ == "__main__":
    main()
