# Plots of `lvox sweep`: error against wall time and against medium evaluations, log-log,
# one curve per method, the Pareto front of each panel drawn as a dashed black line.
# Embedded in the lvox binary at build time (src/app/CMakeLists.txt) and run as
#   python3 plot_sweep.py SWEEP.csv OUT.png TITLE
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def pareto(points):
    """Points (cost, error, ...) not beaten in both cost and error, by increasing cost."""
    front, best = [], float("inf")
    for p in sorted(points, key=lambda q: (q[0], q[1])):
        if p[1] < best:
            front.append(p)
            best = p[1]
    return front


def main():
    csv_path, out_path, title = sys.argv[1], sys.argv[2], sys.argv[3]
    with open(csv_path, newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    curves = {}
    for r in rows:
        curves.setdefault(r["method"], []).append(r)
    panels = [("seconds", "wall time (s)"), ("medium_evals", "medium evaluations")]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    colours = plt.get_cmap("tab20")
    markers = "os^vD<>pP*hX"
    floor = 1e-4  # delta of identical images is 0; keep it on the log axis
    for ax, (key, label) in zip(axes, panels):
        everything = []
        for i, (method, rs) in enumerate(sorted(curves.items())):
            pts = sorted((max(float(r[key]), 1.0 if key == "medium_evals" else 1e-3),
                          max(float(r["delta_percent"]), floor)) for r in rs)
            everything += [(x, y, method) for x, y in pts]
            bold = method in ("auto", "mc")
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=markers[i % len(markers)],
                    color="black" if method == "auto" else colours(i % 20),
                    linewidth=2.2 if bold else 1.0, markersize=6 if bold else 4, label=method)
        front = pareto(everything)
        ax.plot([p[0] for p in front], [p[1] for p in front], "k--", linewidth=1, alpha=0.6,
                label="Pareto front")
        ax.scatter([p[0] for p in front], [p[1] for p in front], s=90, facecolors="none",
                   edgecolors="black", linewidths=1.2, zorder=5)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel("image delta vs reference (%)")
        ax.grid(True, which="both", alpha=0.25)
    axes[1].legend(fontsize=7, ncol=2, loc="upper right")
    fig.suptitle(title)
    fig.tight_layout()
    tmp = out_path + ".tmp.png"
    fig.savefig(tmp, dpi=80)
    os.replace(tmp, out_path)


if __name__ == "__main__":
    main()
