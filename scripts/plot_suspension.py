#!/usr/bin/python3
"""Four panels of the channel statistics of one run.

usage: scripts/plot_suspension.py OUTPUT_DIRECTORY [-o OUT.png]

Reads OUTPUT_DIRECTORY/profiles.txt and rheology.txt (written with
'Statistics/Enabled = true') and draws: <u> and <phi> against y/h, the
velocity fluctuations u_rms, v_rms (w_rms in 3D), the shear-stress budget
normalised by the wall value Pi h, and the bulk numbers (mu_eff/mu, N1,
N2 with their standard errors, the half-channel budget as bars).
Profiles are folded onto the lower half, -1 <= y/h <= 0 (y/h = -1 is the
wall). Default output: OUTPUT_DIRECTORY/suspension.png.
"""
import argparse
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

from statistics_table import read_table

p = argparse.ArgumentParser()
p.add_argument("directory")
p.add_argument("-o", "--output")
a = p.parse_args()

prof = read_table(os.path.join(a.directory, "profiles.txt"))
bulk = {k: v[0] for k, v in read_table(os.path.join(a.directory, "rheology.txt")).items()}
y = prof["y_over_h"]
# the wall value tau_w = Pi h: tau_linear = -Pi y, so Pi h = tau_linear / (-y/h)
wall = prof["tau_linear"][0] / -y[0]

fig, ax = plt.subplots(2, 2, figsize=(11, 8))

a0 = ax[0, 0]
a0.plot(y, prof["u"], "o-", color="C0", label=r"$\langle u\rangle$")
a0.set_xlabel("y/h")
a0.set_ylabel(r"$\langle u\rangle$", color="C0")
a0b = a0.twinx()
a0b.plot(y, prof["phi"], "s--", color="C3", label=r"$\langle\phi\rangle$")
a0b.set_ylabel(r"$\langle\phi\rangle$", color="C3")
a0b.set_ylim(bottom=0, top=max(0.1, 1.1 * max(prof["phi"])))
a0.set_title("mean velocity and solid fraction")

a1 = ax[0, 1]
for c in ("u_rms", "v_rms", "w_rms"):
    if c in prof:
        a1.plot(y, prof[c], "o-", label=c)
a1.set_xlabel("y/h")
a1.set_ylabel("rms velocity fluctuation")
a1.legend()
a1.set_title("velocity fluctuations")

a2 = ax[1, 0]
# (label, colour, line style, width): the total dashed over the parts, so
# that a part equal to the total (laminar flow: the viscous one) stays visible
styles = {"tau_viscous": ("viscous", "C0", "-", 3), "tau_reynolds": ("Reynolds", "C1", "-", 1.5),
          "tau_elastic": ("elastic", "C2", "-", 1.5), "tau_collision": ("collision", "C4", "-", 1.5),
          "tau_total": ("total", "k", "--", 1.5),
          "tau_linear": (r"$-\Pi y$ (exact total)", "0.5", ":", 2)}
for c, (label, color, ls, lw) in styles.items():
    a2.plot(y, [v / wall for v in prof[c]], ls=ls, lw=lw, color=color, label=label)
a2.set_xlabel("y/h")
a2.set_ylabel(r"shear stress / $\tau_w$")
a2.legend(fontsize=8)
a2.set_title(r"shear-stress budget ($\tau_w = \Pi h$ = %.4g)" % wall)

a3 = ax[1, 1]
names = ["viscous", "Reynolds", "elastic", "collision"]
fractions = [bulk["fraction_" + n] for n in names]
a3.bar(names, [100 * f for f in fractions], color=["C0", "C1", "C2", "C4"])
a3.set_ylabel("% of the half-channel mean total shear stress")
a3.set_ylim(min(0, 110 * min(fractions)), 110)
text = ("$\\mu_{eff}/\\mu$ = %.6f ± %.1e\n$N_1$ = %.3e ± %.1e\n$N_2$ = %.3e ± %.1e\n"
        "%d samples, t = %g to %g\ntotal linear to %.1e of $\\tau_w$"
        % (bulk["viscosity_ratio"], bulk["viscosity_ratio_error"], bulk["N1"], bulk["N1_error"],
           bulk["N2"], bulk["N2_error"], bulk["n_samples"], bulk["time_first"],
           bulk["time_last"], bulk["linear_deviation"]))
a3.text(0.97, 0.95, text, transform=a3.transAxes, ha="right", va="top", fontsize=9,
        bbox=dict(facecolor="white", alpha=0.8))
a3.set_title("bulk rheology and budget")

for panel in (a0, a1, a2):
    panel.set_xlim(-1, 0)
    panel.grid(alpha=0.3)
fig.tight_layout()
out = a.output or os.path.join(a.directory, "suspension.png")
fig.savefig(out, dpi=110)
print(out)
