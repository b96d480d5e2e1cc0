#!/usr/bin/python3
"""Plot D against the capillary number from the sweep table a run prints.

usage: scripts/plot_sweep.py RUN_OUTPUT.txt [RUN_OUTPUT.txt ...] -o OUT.png
       --ca "1/x" [--theory "Ca/sqrt(1+4*Ca**2)"] [--label NAME ...]

RUN_OUTPUT is what `suspension FILE.prm` printed for a parameter sweep
(Verification/Sweep entry), e.g. tests/solid_disc_shear_01.output; its
lines "VALUE  D = ...  inclination = ... deg" are read. --ca maps the swept
value x to Ca (a Python expression of x); --theory draws a curve of Ca.
"""
import argparse
import math
import re

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

p = argparse.ArgumentParser()
p.add_argument("files", nargs="+")
p.add_argument("-o", "--output", required=True)
p.add_argument("--ca", default="x")
p.add_argument("--theory", default="")
p.add_argument("--label", action="append", default=[])
a = p.parse_args()

line = re.compile(r"^\s+(\S+)\s+D = ([0-9.eE+-]+)\s+inclination = ([0-9.eE+-]+) deg")
fig, (ax_d, ax_t) = plt.subplots(1, 2, figsize=(10, 4))
all_ca = []
for k, path in enumerate(a.files):
    points = []
    for text in open(path):
        m = line.match(text)
        if m:
            x = float(m.group(1))
            points.append((eval(a.ca, {"x": x, "math": math}), float(m.group(2)), float(m.group(3))))
    points.sort()
    all_ca += [c for c, _, _ in points]
    label = a.label[k] if k < len(a.label) else path
    ax_d.plot([c for c, _, _ in points], [d for _, d, _ in points], "o-", label=label)
    ax_t.plot([c for c, _, _ in points], [t for _, _, t in points], "o-", label=label)
if a.theory and all_ca:
    lo, hi = 0., 1.1 * max(all_ca)
    ca = [lo + (hi - lo) * i / 100 for i in range(101)]
    env = {"math": math, "sqrt": math.sqrt, "atan": math.atan}
    ax_d.plot(ca, [eval(a.theory, dict(env, Ca=c)) for c in ca], "k--", lw=1, label="theory " + a.theory)
    ax_t.plot(ca[1:], [0.5 * math.degrees(math.atan(1 / (2 * c))) for c in ca[1:]], "k--", lw=1,
              label="theory ½ arctan(1/(2Ca))")
ax_d.set_xlabel("Ca")
ax_d.set_ylabel("Taylor deformation D")
ax_t.set_xlabel("Ca")
ax_t.set_ylabel("inclination [deg]")
for ax in (ax_d, ax_t):
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(a.output, dpi=110)
