#!/usr/bin/python3
"""Plot columns of one or more statistics.txt files against time.

usage: scripts/plot_statistics.py COLUMN[,COLUMN...] STATS [STATS...] -o OUT.png
       [--label NAME ...] [--hline VALUE:LABEL ...] [--x COLUMN] [--equal]

COLUMN names are those listed in the header of statistics.txt (e.g. D,
theta_deg, kinetic_energy, minus_dp_dx, y_c). Each STATS file gives one
line per column; --label names them in the legend, --hline draws reference
values (e.g. a theory). --x plots against another column than time (e.g.
--x x_c with y_c: a centroid path); --equal keeps the axes' aspect 1.
"""
import argparse

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from statistics_table import read_table as read


p = argparse.ArgumentParser()
p.add_argument("columns")
p.add_argument("files", nargs="+")
p.add_argument("-o", "--output", required=True)
p.add_argument("--label", action="append", default=[])
p.add_argument("--hline", action="append", default=[])
p.add_argument("--x", default="time")
p.add_argument("--equal", action="store_true")
a = p.parse_args()

fig, ax = plt.subplots(figsize=(7, 4))
for k, path in enumerate(a.files):
    data = read(path)
    for c in a.columns.split(","):
        label = (a.label[k] if k < len(a.label) else path) + ("" if "," not in a.columns else f" {c}")
        ax.plot(data[a.x], data[c], label=label)
for h in a.hline:
    value, _, label = h.partition(":")
    ax.axhline(float(value), color="k", ls="--", lw=1, label=label)
ax.set_xlabel(a.x)
if a.equal:
    ax.set_aspect("equal")
ax.set_ylabel(a.columns.replace(",", ", "))
ax.grid(alpha=0.3)
ax.legend()
fig.tight_layout()
fig.savefig(a.output, dpi=110)
