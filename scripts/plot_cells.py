#!/usr/bin/python3
"""Draw phi and the (adaptive) mesh of a 2D run from phi_cells_NNNNN.txt.

usage: scripts/plot_cells.py CELLS.txt [CELLS.txt ...] -o OUT.png [--no-mesh]
       [--title TEXT] [--path STATS:XCOL:YCOL]

One panel per file: each cell filled with its mean phi (white 0 .. dark 1)
and outlined, so the refined band at the interface is visible. --path adds
a trajectory from a statistics.txt (e.g. the centroid x_c, y_c).
Written with 'Output/Write phi cells = true' at every output.
"""
import argparse

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.collections import PolyCollection

from statistics_table import read_table as read_statistics


def read_cells(path):
    time, rows = None, []
    with open(path) as f:
        for line in f:
            if line.startswith("# time"):
                time = float(line.split()[2])
            elif not line.startswith("#") and line.strip():
                rows.append([float(v) for v in line.split()])
    return time, rows


p = argparse.ArgumentParser()
p.add_argument("files", nargs="+")
p.add_argument("-o", "--output", required=True)
p.add_argument("--no-mesh", action="store_true")
p.add_argument("--title", default="")
p.add_argument("--path", default="")
a = p.parse_args()

n = len(a.files)
fig, axes = plt.subplots(1, n, figsize=(4.2 * n + 0.8, 4.4), squeeze=False)
for ax, path in zip(axes[0], a.files):
    time, rows = read_cells(path)
    if rows and len(rows[0]) != 6:
        raise SystemExit(f"{path}: not a 2D cell table")
    polys = [[(r[0], r[1]), (r[2], r[1]), (r[2], r[3]), (r[0], r[3])] for r in rows]
    coll = PolyCollection(polys, array=[r[5] for r in rows], cmap="Greys", clim=(0, 1),
                          edgecolors="0.6" if not a.no_mesh else "face", linewidths=0.15)
    ax.add_collection(coll)
    ax.set_xlim(min(r[0] for r in rows), max(r[2] for r in rows))
    ax.set_ylim(min(r[1] for r in rows), max(r[3] for r in rows))
    ax.set_aspect("equal")
    ax.set_title(f"t = {time:g}, {len(rows)} cells")
    if a.path:
        stats, xcol, ycol = a.path.split(":")
        s = read_statistics(stats)
        ax.plot(s[xcol], s[ycol], "C3-", lw=1)
fig.colorbar(coll, ax=axes[0].tolist(), label="cell mean of phi", shrink=0.8)
if a.title:
    fig.suptitle(a.title)
fig.savefig(a.output, dpi=130)
