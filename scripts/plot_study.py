#!/usr/bin/python3
"""The figures of a study, like the paper's, from what scripts/study wrote.

usage: scripts/plot_study.py STUDY_DIRECTORY

Reads STUDY_DIRECTORY/study.csv (one row per finished case) and each
case's profiles.txt, and writes to STUDY_DIRECTORY:
  mu_eff.png           mu_eff/mu_f against Phi (with the Eilers fit of the
                       paper, Phi_m = 0.58, B_E = 1.7, and its 2D
                       counterpart B_E = 1.7 x 2/2.5 for the intrinsic
                       viscosity 2 of discs), against Ca (Re = 3.75),
                       against Re (Ca = 0.3), against sqrt(Re Ca) at
                       Re/Ca = 50 (the table's diagonal);
  normal_stresses.png  N1 and N2 against Phi per Ca (Re = 3.75) and per Re
                       (Ca = 0.3);
  profiles.png         <phi>, u_rms, v_rms across the channel per Phi
                       (Re = 3.75, at the smallest and largest Ca);
  budget.png           the shear-stress budget across the channel per Phi
                       (Re = 3.75, smallest Ca) and its half-channel shares.
Only the cases present are drawn; error bars are the runs' blocked batch
means. Unsteady cases (steady = 0) are drawn hollow.
"""
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from statistics_table import read_table  # noqa: E402

root = sys.argv[1]
with open(os.path.join(root, "study.csv")) as f:
    rows = [{k: (float(v) if k != "case" else v) for k, v in r.items()} for r in csv.DictReader(f)]
if not rows:
    sys.exit(0)


def legend(ax):
    """A panel whose cases are not (yet) in the study stays empty, without one."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7)


def eilers(phi, b, phi_m=0.58):
    return (1 + b * phi / (1 - phi / phi_m)) ** 2


def series(key, fixed):
    """{value of `key`: rows sorted by Phi} among rows matching `fixed`."""
    out = defaultdict(list)
    for r in rows:
        if all(abs(r[k] - v) < 1e-9 for k, v in fixed.items()):
            out[r[key]].append(r)
    return {k: sorted(v, key=lambda r: r["Phi"]) for k, v in sorted(out.items())}


def errorbar(ax, x, rs, q, label, color):
    y = [r[q] for r in rs]
    e = [r[q + "_error"] for r in rs]
    steady = [r["steady"] > 0.5 for r in rs]
    ax.errorbar(x, y, yerr=e, color=color, label=label, marker="none", capsize=3)
    ax.scatter([a for a, s in zip(x, steady) if s], [b for b, s in zip(y, steady) if s],
               color=color, zorder=3)
    ax.scatter([a for a, s in zip(x, steady) if not s], [b for b, s in zip(y, steady) if not s],
               facecolors="none", edgecolors=color, zorder=3)


fig, ax = plt.subplots(2, 2, figsize=(11, 8.5))
a = ax[0, 0]
pairs = defaultdict(list)
for r in rows:
    pairs[(r["Re"], r["Ca"])].append(r)
for i, ((re, ca), rs) in enumerate(sorted(pairs.items())):
    rs.sort(key=lambda r: r["Phi"])
    errorbar(a, [r["Phi"] for r in rs], rs, "viscosity_ratio", f"Re {re:g}, Ca {ca:g}", f"C{i}")
phis = [0.001 * i for i in range(0, 161)]
a.plot(phis, [eilers(p, 1.7) for p in phis], "k-", label="Eilers, $\\Phi_m$ 0.58, $B_E$ 1.7 (paper, 3D)")
a.plot(phis, [eilers(p, 1.7 * 2 / 2.5) for p in phis], "k--", label="Eilers 2D: $B_E$ 1.36")
a.plot(phis, [1 + 2 * p for p in phis], "k:", label="dilute discs 1 + 2$\\Phi$")
a.set_xlabel("$\\Phi$")
a.set_ylabel("$\\mu_{eff}/\\mu_f$")
legend(a)

a = ax[0, 1]
for i, (phi, rs) in enumerate(series("Phi", {"Re": 3.75}).items()):
    rs.sort(key=lambda r: r["Ca"])
    errorbar(a, [r["Ca"] for r in rs], rs, "viscosity_ratio", f"$\\Phi$ {phi:g}", f"C{i}")
a.set_xscale("log")
a.set_xlabel("Ca (Re = 3.75)")
a.set_ylabel("$\\mu_{eff}/\\mu_f$")
legend(a)

a = ax[1, 0]
for i, (phi, rs) in enumerate(series("Phi", {"Ca": 0.3}).items()):
    rs.sort(key=lambda r: r["Re"])
    errorbar(a, [r["Re"] for r in rs], rs, "viscosity_ratio", f"$\\Phi$ {phi:g}", f"C{i}")
a.set_xlabel("Re (Ca = 0.3)")
a.set_ylabel("$\\mu_{eff}/\\mu_f$")
legend(a)

a = ax[1, 1]
diagonal = [r for r in rows if abs(r["Re"] / r["Ca"] - 50) < 1e-6]
by_phi = defaultdict(list)
for r in diagonal:
    by_phi[r["Phi"]].append(r)
for i, (phi, rs) in enumerate(sorted(by_phi.items())):
    rs.sort(key=lambda r: r["Re"])
    errorbar(a, [math.sqrt(r["Re"] * r["Ca"]) for r in rs], rs, "viscosity_ratio",
             f"$\\Phi$ {phi:g}", f"C{i}")
a.set_xlabel("$\\sqrt{Re\\,Ca}$ at Re/Ca = 50")
a.set_ylabel("$\\mu_{eff}/\\mu_f$")
legend(a)
fig.tight_layout()
fig.savefig(os.path.join(root, "mu_eff.png"), dpi=110)
plt.close(fig)

fig, ax = plt.subplots(2, 2, figsize=(11, 8))
for col, q in enumerate(["N1", "N2"]):
    for i, (ca, rs) in enumerate(series("Ca", {"Re": 3.75}).items()):
        errorbar(ax[0, col], [r["Phi"] for r in rs], rs, q, f"Ca {ca:g}", f"C{i}")
    for i, (re, rs) in enumerate(series("Re", {"Ca": 0.3}).items()):
        errorbar(ax[1, col], [r["Phi"] for r in rs], rs, q, f"Re {re:g}", f"C{i}")
    for row, what in enumerate(["Re = 3.75", "Ca = 0.3"]):
        ax[row, col].axhline(0, color="0.6", lw=0.8)
        ax[row, col].set_xlabel(f"$\\Phi$ ({what})")
        ax[row, col].set_ylabel(f"${q[0]}_{q[1]}$ / ($\\rho V_b^2$)")
        legend(ax[row, col])
fig.tight_layout()
fig.savefig(os.path.join(root, "normal_stresses.png"), dpi=110)
plt.close(fig)


def profiles(r):
    try:
        return read_table(os.path.join(root, r["case"], "profiles.txt"))
    except OSError:
        return None


# the profiles at Re = 3.75 (the paper's), or at the first Re of the study
re_ref = 3.75 if any(abs(r["Re"] - 3.75) < 1e-9 for r in rows) else rows[0]["Re"]
re_rows = [r for r in rows if abs(r["Re"] - re_ref) < 1e-9]
cas = sorted({r["Ca"] for r in re_rows})
if cas:
    fig, ax = plt.subplots(2, 3, figsize=(14, 8))
    for row, ca in enumerate([cas[0], cas[-1]]):
        for i, r in enumerate(sorted([r for r in re_rows if r["Ca"] == ca], key=lambda r: r["Phi"])):
            p = profiles(r)
            if p is None:
                continue
            for col, q in enumerate(["phi", "u_rms", "v_rms"]):
                ax[row, col].plot(p["y_over_h"], p[q], color=f"C{i}", label=f"$\\Phi$ {r['Phi']:g}")
                ax[row, col].set_xlabel(f"y/h (Re {re_ref:g}, Ca {ca:g}; wall at -1)")
                ax[row, col].set_ylabel({"phi": "$\\langle\\phi\\rangle$", "u_rms": "$u_{rms}/V_b$",
                                         "v_rms": "$v_{rms}/V_b$"}[q])
                legend(ax[row, col])
    fig.tight_layout()
    fig.savefig(os.path.join(root, "profiles.png"), dpi=110)
    plt.close(fig)

    chosen = sorted([r for r in re_rows if r["Ca"] == cas[0]], key=lambda r: r["Phi"])
    if chosen:
        fig, ax = plt.subplots(1, len(chosen) + 1, figsize=(4 * (len(chosen) + 1), 4))
        for i, r in enumerate(chosen):
            p = profiles(r)
            if p is None:
                continue
            wall = p["tau_linear"][0] / -p["y_over_h"][0]
            for q, c in [("viscous", "0.7"), ("Reynolds", "0.35"), ("elastic", "k"),
                         ("collision", "C3"), ("total", "C0")]:
                ax[i].plot(p["y_over_h"], [v / wall for v in p["tau_" + q.lower()]], color=c,
                       label=q)
            ax[i].plot(p["y_over_h"], [v / wall for v in p["tau_linear"]], "C0:", label="exact total")
            ax[i].set_title(f"Re {re_ref:g}, Ca {cas[0]:g}, $\\Phi$ {r['Phi']:g}", fontsize=9)
            ax[i].set_xlabel("y/h")
            ax[i].set_ylabel("$\\tau / (\\Pi h)$")
            legend(ax[i])
        b = ax[-1]
        bottom = [0.] * len(chosen)
        for q, c in [("viscous", "0.8"), ("Reynolds", "0.4"), ("elastic", "k"), ("collision", "C3")]:
            v = [100 * r["fraction_" + q] for r in chosen]
            b.bar([str(r["Phi"]) for r in chosen], v, bottom=bottom, color=c, label=q)
            bottom = [x + y for x, y in zip(bottom, v)]
        b.set_xlabel("$\\Phi$")
        b.set_ylabel("share of the half-channel shear stress (%)")
        legend(b)
        fig.tight_layout()
        fig.savefig(os.path.join(root, "budget.png"), dpi=110)
        plt.close(fig)
print(f"figures: {root}/mu_eff.png, normal_stresses.png, profiles.png, budget.png")
