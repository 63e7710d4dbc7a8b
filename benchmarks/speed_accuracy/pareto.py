"""Error against wall time with the Pareto front, for the speed-accuracy
drivers of this directory."""


def plot_pareto(results, reference_wall, path, title, ylabel):
    """@p results: dicts with name, run (wall seconds) and error (percent);
    the entry named "reference" is left out, the default (named so, or
    marked "default") is starred."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    points = [(r["run"], max(r["error"], 1e-4), r["name"],
               r["name"] == "default" or r.get("default", False))
              for r in results if r["name"] != "reference"]
    for wall, error, name, default in points:
        ax.plot(wall, error, "*" if default else "o",
                color="C3" if default else "C0",
                markersize=11 if default else 6)
        ax.annotate(name, (wall, error), fontsize=7,
                    xytext=(3, 3), textcoords="offset points")
    # Pareto front: no other point both faster and more accurate.
    front = sorted((p for p in points
                    if not any(q[0] <= p[0] and q[1] < p[1] or
                               q[0] < p[0] and q[1] <= p[1] for q in points)),
                   key=lambda p: p[0])
    ax.plot([p[0] for p in front], [p[1] for p in front], "-", color="C3",
            label="Pareto front")
    if reference_wall:
        ax.axvline(reference_wall, color="grey", ls=":",
                   label="reference run (%.0f s)" % reference_wall)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time after set-up [s], one core")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
