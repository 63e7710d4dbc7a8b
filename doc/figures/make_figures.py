#!/usr/bin/env python3
"""Draws the figures of doc/theory.md and doc/validation.md.

    build/benchmarks/solid_fraction_profile > profile.csv
    doc/figures/make_figures.py profile.csv

needs python3-matplotlib (apt-get install python3-matplotlib). The
hindered-settling and fixed-bed values are the measured tables of
doc/validation.md (each row says how to reproduce it)."""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

here = os.path.dirname(os.path.abspath(__file__))


def solid_fraction(profile):
    with open(profile) as f:
        rows = list(csv.reader(f))
    names, data = rows[0][1:], [[float(v) for v in r] for r in rows[1:]]
    x = [r[0] for r in data]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), sharey=True)
    for panel, (ax, length, title) in enumerate(
        zip(axes, ["l=0.00", "l=0.04"],
            ["no smoothing (l = 0)", "Helmholtz filter, l = 0.04 = 4 r"])):
        for k, name in enumerate(names):
            if name.startswith(length):
                cells = name.split("cells=")[1]
                ax.plot(x, [r[k + 1] for r in data], lw=1,
                        label=f"{cells} cells across")
        ax.set_title(title)
        ax.set_xlabel("x (line y = 0.5)")
        ax.axhline(0.19, color="k", ls=":", lw=0.8)
    axes[0].set_ylabel("projected solid fraction φ_s")
    axes[1].legend(fontsize=8)
    fig.suptitle("600 discs of radius r = 0.01 at random in the unit square "
                 "(mean φ_s = 0.19, dotted)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(here, "solid_fraction_smoothing.png"), dpi=110)


def hindered_settling():
    phi = [0.05, 0.10, 0.20, 0.30]
    series = {
        "3D, l = 8 r, h = 8 r": [0.9999, 0.9997, 0.9980, 0.9973],
        "3D, l = 16 r, h = 8 r": [0.9995, 0.9993, 0.9990, 0.9991],
        "2D, l = 8 r, h = 8 r": [1.203, 1.182, 1.282, 1.409],
        "2D, l = 64 r = L/2, h = 8 r": [0.9963, 0.9997, 1.0008, 0.9929],
    }
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, values in series.items():
        ax.plot(phi, values, "o-", label=name)
    ax.axhspan(0.97, 1.03, color="0.9", label="±3 %")
    ax.set_xlabel("solid fraction φ_s")
    ax.set_ylabel("v / (ε^4.8 × single-grain velocity)")
    ax.set_ylim(0.9, 1.5)
    ax.set_title("Hindered settling against the seed's closure", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(here, "hindered_settling.png"), dpi=110)


def fixed_bed():
    h = [1.5, 0.75, 0.375]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(h, [0.06689, 0.06723, 0.06741], "o-",
            label="φ for the drag law filtered twice")
    ax.plot(h[:2], [0.0676, 0.0950], "s--",
            label="φ sampled at the grain (before)")
    ax.axhline(0.069353, color="k", ls=":", label="closure, mean φ = 0.845")
    ax.set_xscale("log")
    ax.invert_xaxis()
    ax.set_xlabel("cell size h [mm] (lattice spacing 1.5 mm, l = 1.5 mm)")
    ax.set_ylabel("pressure drop between the probes [Pa]")
    ax.set_title("Fixed bed: mesh study", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(here, "fixed_bed_mesh.png"), dpi=110)


if __name__ == "__main__":
    solid_fraction(sys.argv[1])
    hindered_settling()
    fixed_bed()
