#!/usr/bin/python3
"""Speed against accuracy on the 3D falling cloud, reduced
(doc/speed-accuracy.md): prm/falling_cloud_3d.prm with a smaller cloud
(radius SIZE instead of 0.5 mm, so about a fifth of the beads) run to
t = END under a set of strategies, each changing one choice of the scene,
against a reference run at the finest setting. Writes a table (markdown)
and a PNG of error against wall time with the Pareto front.

    benchmarks/speed_accuracy/cloud_3d.py [--end 0.1] [--size 3e-4]
        [--only NAME,...] [--out DIR] [--plot-only]

Error: the cloud's centroid at END against the reference's, as a
percentage of the distance the reference fell; and the cloud's horizontal
extent (radius of gyration across the fall) against the reference's, in
percent. END lies in the compact stage, long before the torus (doc/scenes/
falling_cloud_3d.md): the fall and the spreading are the figures a
strategy should keep. About 40 minutes on one core, most of it the
reference.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)
from run import STRATEGIES as CLOUD_2D_STRATEGIES, override, study  # noqa: E402
from scene_runner import ROOT  # noqa: E402

SCENE = os.path.join(ROOT, "prm", "falling_cloud_3d.prm")
WORK = os.path.join(ROOT, "benchmarks", "results", "speed_accuracy_cloud_3d")

# name: (what it changes, overrides). The default is the reduced scene;
# the resolution and solver strategies are those of the 2D cloud's study.
SHARED = ["courant_0.5", "courant_0.25", "courant_0.05", "grains_rule",
          "max_level_3", "max_level_5", "tolerance_1e-4", "tolerance_1e-8",
          "bdf1", "stokes", "smoothing_2e-4"]
STRATEGIES = {
    "reference": CLOUD_2D_STRATEGIES["reference"],
    "default": ("the scene as shipped (Courant 0.1, Max level 4, BDF2, "
                "extrapolated advection, filtered drag, tolerance 1e-6)", []),
    **{name: CLOUD_2D_STRATEGIES[name] for name in SHARED},
    "cell_drag": ("Coupling/Drag distribution cell, with the "
                  "self-disturbance correction (the code's 3D default; the "
                  "scene: filtered)",
                  [("Coupling", "Drag distribution", "cell")]),
}


def main():
    # --size: the cloud's radius (the scene's is 5e-4 m).
    study(STRATEGIES, SCENE, WORK, "speed_accuracy_cloud_3d.png",
          "3D falling cloud (reduced)", 0.1,
          options=[("--size", dict(type=float, default=3e-4))],
          scene_changes=lambda args: override("Grains/Placement", "Size",
                                              args.size))


if __name__ == "__main__":
    main()
