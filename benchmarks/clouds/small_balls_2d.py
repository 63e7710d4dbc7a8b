#!/usr/bin/python3
"""Small 2D balls of discs: which drag distribution suits them
(doc/validation.md, "Small 2D balls").

The main scene, made from prm/falling_cloud_2d.prm (glass discs of
r = 12.5 um in a water-glycerol mixture, solid fraction 0.2, a 16 x 30 mm
box, adaptive cells down to 0.125 mm = 5 disc diameters), with balls of
N = 10, 30, 100
and 321 discs (radius r sqrt(5 N)), and a lone disc, each run to
t = 0.1 s with

  - cell:      the cell spread, what Drag distribution = auto gives a ball;
  - cell, L5:  the same on cells half as wide (Adaptivity/Max level 5);
  - filtered:  the filter half the box wide, what auto gives separate
               discs (a lone disc within 0.5 % of the closure);
  - filtered, 4 d: a filter of 4 disc diameters (0.1 mm).

A disc's own disturbance in 2D decays only logarithmically: with the cell
spread a lone disc settles several times too fast, and every disc of a
ball carries that excess, Delta = v_lone(cell) - v_lone(filtered). A
cloud's collective velocity grows with N, so the share Delta / v_ball of
the cell spread's answer that is the discs' own disturbance falls with N;
the cells half as wide show it too (the own disturbance grows as the cells
shrink, the collective flow does not). The filter half the box wide, in
turn, spreads each drag over the box and takes the cloud's collective flow
away. Prints one row per ball: its velocity at 0.1 s with each
distribution and the own-disturbance share.

    benchmarks/clouds/small_balls_2d.py [--out DIR] [--end 0.1]

About two minutes on one core.
"""
import argparse
import math
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                ".."))
import scene_runner  # noqa: E402

R_DISC = 12.5e-6
BALLS = [10, 30, 100, 321]
SCENE = os.path.join(scene_runner.ROOT, "prm", "falling_cloud_2d.prm")


def placement(n):
    if n == 1:
        return ("    set Shape     = list\n"
                "    set Positions = 8e-3, 25e-3\n")
    return ("    set Shape          = ball\n"
            "    set Center         = 8e-3, 25e-3\n"
            f"    set Size           = {R_DISC * math.sqrt(5 * n):.6e}\n"
            "    set Solid fraction = 0.2\n"
            "    set Random seed    = 1\n")


def scene(n, distribution, length, level, end):
    """The main scene with the ball of @p n discs (a lone disc for 1)."""
    text = open(SCENE).read()
    changes = [(r"set End time  = 1\n", f"set End time  = {end}\n"),
               (r"set Max level = 4\n", f"set Max level = {level}\n"),
               (r"    set Shape          = ball\n(    set .*\n){4}",
                placement(n)),
               (r"set Smoothing length = 1e-4\n",
                f"set Smoothing length = {length}\n"
                f"  set Drag distribution = {distribution}\n"),
               (r"set Write fields every = 20\n",
                "set Write fields every = 0\n")]
    for pattern, replacement in changes:
        text, count = re.subn(pattern, lambda _: replacement, text)
        assert count == 1, "the scene changed: %s" % pattern
    return text


def velocity(n, distribution, level, out, end, length=None):
    if length is None:
        length = 8e-3 if distribution == "filtered" else 1e-4
    name = f"n{n}_{distribution}_{length:g}_L{level}"
    rows = scene_runner.run_scene(scene(n, distribution, length, level, end),
                                  os.path.join(out, name))
    last = rows[-1]
    column = "cloud_velocity_y" if n > 1 else "mean_velocity_y"
    return -float(last[column]), int(float(last["particles"]))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", default=os.path.join(
        scene_runner.ROOT, "benchmarks", "results", "small_balls_2d"))
    parser.add_argument("--end", type=float, default=0.1)
    args = parser.parse_args()
    lone_cell, _ = velocity(1, "cell", 4, args.out, args.end)
    lone_cell5, _ = velocity(1, "cell", 5, args.out, args.end)
    lone, _ = velocity(1, "filtered", 4, args.out, args.end)
    lone_short, _ = velocity(1, "filtered", 4, args.out, args.end, 1e-4)
    delta, delta5 = lone_cell - lone, lone_cell5 - lone
    print(f"lone disc: filtered {lone * 1e3:.4f} mm/s, cell "
          f"{lone_cell * 1e3:.4f} ({lone_cell / lone:.2f} times), "
          f"cell L5 {lone_cell5 * 1e3:.4f} ({lone_cell5 / lone:.2f} times), "
          f"filtered 4 d {lone_short * 1e3:.4f} ({lone_short / lone:.2f} "
          "times)")
    print("| discs | ball radius / r | cell, mm/s | cell L5, mm/s | "
          "filtered, mm/s | filtered 4 d, mm/s | own disturbance in cell: "
          "Delta / v | L5 / L4 |")
    print("|---|---|---|---|---|---|---|---|")
    for n in BALLS:
        cell, placed = velocity(n, "cell", 4, args.out, args.end)
        cell5, _ = velocity(n, "cell", 5, args.out, args.end)
        filtered, _ = velocity(n, "filtered", 4, args.out, args.end)
        short, _ = velocity(n, "filtered", 4, args.out, args.end, 1e-4)
        print(f"| {placed} | {math.sqrt(5 * n):.1f} | {cell * 1e3:.3f} | "
              f"{cell5 * 1e3:.3f} | {filtered * 1e3:.3f} | "
              f"{short * 1e3:.3f} | "
              f"{delta / cell * 100:.1f} % | {cell5 / cell:.3f} |")
    print(f"(t = {args.end} s; Delta = {delta * 1e3:.4f} mm/s on cells of "
          f"5 d, {delta5 * 1e3:.4f} on cells of 2.5 d)")


if __name__ == "__main__":
    main()
