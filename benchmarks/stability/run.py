#!/usr/bin/env python3
"""Stability map: where each scheme breaks, against the theoretical limits.

Usage (from the repository root, after a build in build/):

    python3 benchmarks/stability/run.py            # the full map (wall time in README.md)
    python3 benchmarks/stability/run.py --replot   # table and charts from results.csv
    python3 benchmarks/stability/run.py --quick    # the test-suite smoke run (4 runs)

Sweeps the time step (shown as CFL number |u|max dt / h and as elastic
number dt sqrt(G / rho) / h), the capillary number Ca = mu shear / G and the
particle Reynolds number Re = rho shear r^2 / mu for the disc in shear
(disc_shear.prm, level 4: 6.4 cells per diameter, to t = 0.5), for each
scheme: elastic coupling explicit / semi-implicit, DG degree 1 / 2, phi
limiter on / off. Plus the elastic disc in the lid-driven cavity
(disc_cavity.prm) across the time step for both couplings.

Each run is classified by the solver's own checks:
  stable     the run finished and D is within 5 % of the scheme's converged
             value (its own run at the smallest time step of the sweep),
  inaccurate it finished but D is further off,
  failed     the solver stopped, and the check that caught it: B not SPD,
             phi out of bounds, NaN, solver divergence, step collapse.
Writes results.csv, one PNG per scheme (stability_<scheme>.png) and prints
the table and the largest stable time step of each scheme.
"""

import concurrent.futures
import csv
import math
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(REPO, "scripts"))
from benchmark_tools import plt, SUSPENSION, PARALLEL, work_directory, write_csv  # noqa: E402
from statistics_table import read_table as read_statistics  # noqa: E402

QUICK = "--quick" in sys.argv
WORK = work_directory(HERE, QUICK)
OUT = WORK if QUICK else HERE

RADIUS, SHEAR = 0.2, 1.0
TOLERANCE = 0.05  # stable-and-accurate: |D / D_converged - 1| <= 5 %

# time step as a multiple s of the cell size: CFL = s |u|max, En = s sqrt(G)
# SCHEMES: (coupling, DG degree, limiter, Ca values, Re values)
if QUICK:
    LEVEL, END = 4, 0.25
    STEPS = (0.05, 0.4)
    SCHEMES = [("explicit", 1, True, (0.01,), (0.1,)), ("semi-implicit", 1, True, (0.01,), (0.1,))]
    CAVITY = []
else:
    LEVEL, END = 4, 0.5
    STEPS = (0.05, 0.1, 0.2, 0.4, 0.8, 1.6)
    FULL, CORNERS = ((0.01, 0.1, 1.0), (0.1, 1.0, 10.0)), ((0.01, 1.0), (0.1, 10.0))
    # the full Ca x Re grid for the default DG degree 1 with the limiter,
    # the corners of it for the other six schemes
    SCHEMES = [(c, k, lim) + (FULL if (k, lim) == (1, True) else CORNERS)
               for c in ("explicit", "semi-implicit") for k in (1, 2) for lim in (True, False)]
    # the cavity: mu = 0.01 (lid Re = 100), G = 0.1 (the verification case)
    # and G = 10, both couplings, DG 1 with the limiter, to t = 0.5
    CAVITY = [(c, g) for c in ("explicit", "semi-implicit") for g in (0.1, 10.0)]

H_SHEAR = 2.0 / (2 * 2 ** LEVEL)
H_CAVITY = 1.0 / (4 * 2 ** 3)
CAVITY_STEPS = (0.05, 0.2, 0.8, 3.2)


def scheme_name(coupling, degree, limiter):
    return "%s_dg%d_%s" % (coupling, degree, "limiter" if limiter else "nolimiter")


def classify_failure(text):
    checks = [("too large for the transport", "velocity blow-up"),
              ("symmetric positive definite", "B not SPD"), ("phi left", "phi out of bounds"),
              ("not finite", "NaN"), ("diverged", "solver divergence"),
              ("collapsed", "step collapse")]
    for key, label in checks:
        if key in text:
            return label
    return "other"


def run(case):
    out = os.path.join(WORK, case["name"])
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    text = open(os.path.join(HERE, case["template"])).read()
    for key, value in (("@LEVEL@", case["level"]), ("@MU@", case["mu"]), ("@G@", case["G"]),
                       ("@DT@", case["dt"]), ("@END@", case["end"]),
                       ("@DEGREE@", case["degree"]),
                       ("@LIMITER@", "true" if case["limiter"] else "false"),
                       ("@COUPLING@", case["coupling"]), ("@OUT@", out)):
        text = text.replace(key, str(value))
    prm = os.path.join(out, "run.prm")
    open(prm, "w").write(text)
    start = time.perf_counter()
    try:
        result = subprocess.run([SUSPENSION, prm], capture_output=True, text=True, timeout=900)
        code, log = result.returncode, result.stdout + result.stderr
    except subprocess.TimeoutExpired:
        code, log = -1, "timeout"
    wall = time.perf_counter() - start
    row = dict(case)
    row.update(wall_time=wall, D=float("nan"), steps=0, failure="", returncode=code)
    stats_path = os.path.join(out, "statistics.txt")
    if code == 0 and os.path.exists(stats_path):
        stats = read_statistics(stats_path)
        row["D"] = stats["D"][-1]
        row["steps"] = len(stats["D"])
    else:
        row["failure"] = "timeout" if log == "timeout" else classify_failure(log)
        if os.path.exists(stats_path):
            try:
                row["steps"] = len(read_statistics(stats_path)["time"])
            except (KeyError, ValueError, IndexError):
                pass
    print("  %-50s %-18s D = %-10.6g wall %6.1f s" % (
        case["name"], row["failure"] or "finished", row["D"], wall), flush=True)
    return row


def shear_cases():
    cases = []
    for coupling, degree, limiter, ca_values, re_values in SCHEMES:
        for ca in ca_values:
            for re in re_values:
                mu = SHEAR * RADIUS ** 2 / re
                g = mu * SHEAR / ca
                for s in STEPS:
                    dt = s * H_SHEAR
                    cases.append(dict(
                        scene="shear", template="disc_shear.prm", level=LEVEL, end=END,
                        scheme=scheme_name(coupling, degree, limiter), coupling=coupling,
                        degree=degree, limiter=limiter, Ca=ca, Re=re, mu=mu, G=g, dt=dt,
                        cfl=dt * 1.0 / H_SHEAR, En=dt * math.sqrt(g) / H_SHEAR,
                        name="shear_%s_Ca%g_Re%g_s%g" % (scheme_name(coupling, degree, limiter),
                                                          ca, re, s)))
    return cases


def cavity_cases():
    cases = []
    for coupling, g in CAVITY:
        mu = 0.01
        for s in CAVITY_STEPS:
            dt = s * H_CAVITY
            cases.append(dict(
                scene="cavity", template="disc_cavity.prm", level=3, end=0.5,
                scheme=scheme_name(coupling, 1, True), coupling=coupling, degree=1,
                limiter=True, Ca=mu * 1.0 / g, Re=RADIUS * 1.0 / mu, mu=mu, G=g, dt=dt,
                cfl=dt * 1.0 / H_CAVITY, En=dt * math.sqrt(g) / H_CAVITY,
                name="cavity_%s_G%g_s%g" % (coupling, g, s)))
    return cases


def classify(rows):
    """Adds 'class': stable / inaccurate / failed, against each group's
    converged value (the smallest step of the same scheme and parameters)."""
    groups = {}
    for r in rows:
        groups.setdefault((r["scene"], r["scheme"], r["Ca"], r["Re"]), []).append(r)
    for group in groups.values():
        group.sort(key=lambda r: r["dt"])
        finished = [r for r in group if not r["failure"]]
        reference = finished[0]["D"] if finished and finished[0] is group[0] else None
        for r in group:
            r["D_converged"] = reference if reference is not None else float("nan")
            if r["failure"]:
                r["class"] = "failed"
            elif reference is None or not math.isfinite(r["D"]):
                r["class"] = "inaccurate"
            else:
                r["error"] = abs(r["D"] / reference - 1.0)
                r["class"] = "stable" if r["error"] <= TOLERANCE else "inaccurate"
    return rows


FIELDS = ["scene", "scheme", "coupling", "degree", "limiter", "Ca", "Re", "mu", "G", "dt", "cfl",
          "En", "class", "failure", "D", "D_converged", "steps", "wall_time"]


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k in ("Ca", "Re", "mu", "G", "dt", "cfl", "En", "D", "D_converged", "wall_time"):
            r[k] = float(r[k])
        r["degree"], r["steps"] = int(r["degree"]), int(r["steps"])
        r["limiter"] = r["limiter"] == "True"
    return rows


def report(rows):
    print("\n%-7s %-30s %6s %6s %8s %6s %7s %-10s %-18s %9s %6s %8s" % (
        "scene", "scheme", "Ca", "Re", "dt", "CFL", "En", "class", "failure", "D", "steps",
        "s/step"))
    for r in rows:
        per_step = r["wall_time"] / r["steps"] if r["steps"] else float("nan")
        print("%-7s %-30s %6g %6g %8.2e %6.2f %7.2f %-10s %-18s %9.5f %6d %8.4f" % (
            r["scene"], r["scheme"], r["Ca"], r["Re"], r["dt"], r["cfl"], r["En"], r["class"],
            r["failure"] or "-", r["D"], r["steps"], per_step))
    print("\nlargest stable step of each scheme (all Ca, Re of the sweep), as CFL and En:")
    summary = {}
    for r in rows:
        key = (r["scene"], r["scheme"])
        s = summary.setdefault(key, dict(max_cfl=0., max_en=0., first_fail=None, cost=[]))
        if r["steps"]:
            s["cost"].append(r["wall_time"] / r["steps"])
        if r["class"] == "stable":
            s["max_cfl"] = max(s["max_cfl"], r["cfl"])
            s["max_en"] = max(s["max_en"], r["En"])
        elif r["class"] == "failed":
            if s["first_fail"] is None or r["En"] < s["first_fail"]["En"]:
                s["first_fail"] = r
    for (scene, scheme), s in sorted(summary.items()):
        f = s["first_fail"]
        cost = sorted(s["cost"])[len(s["cost"]) // 2] if s["cost"] else float("nan")
        print("  %-7s %-30s stable to CFL %.2f, En %.2f; median %.4f s/step; first failure: %s" % (
            scene, scheme, s["max_cfl"], s["max_en"], cost,
            "none" if f is None else "%s at CFL %.2f, En %.2f (Ca %g, Re %g)" % (
                f["failure"], f["cfl"], f["En"], f["Ca"], f["Re"])))
    return summary


COLOURS = {"stable": "tab:green", "inaccurate": "tab:orange", "failed": "tab:red"}
MARKERS = {0.1: "v", 1.0: "o", 10.0: "^", 20.0: "s"}


def plot(rows, out_dir):
    paths = []
    for scheme in sorted({r["scheme"] for r in rows}):
        fig, ax = plt.subplots(figsize=(6.4, 5.0))
        sel = [r for r in rows if r["scheme"] == scheme]
        for r in sel:
            marker = MARKERS.get(r["Re"], "D") if r["scene"] == "shear" else "*"
            ax.loglog(r["cfl"], r["En"], marker, color=COLOURS[r["class"]], ms=7,
                      markeredgecolor="k", markeredgewidth=0.4)
        xs = [r["cfl"] for r in sel]
        ys = [r["En"] for r in sel]
        lo_x, hi_x = min(xs) / 1.5, max(xs) * 1.5
        lo_y, hi_y = min(ys) / 1.5, max(ys) * 1.5
        ax.axvline(1.0, color="k", ls="--", lw=1)
        ax.text(1.05, lo_y * 1.2, "CFL = 1\n(explicit convection)", fontsize=7)
        if scheme.startswith("explicit"):
            # c dt k_max <= 2 (the explicit wave step), k_max^2 = 60 / h^2 the
            # largest eigenvalue of M^-1 K for 1D P2 elements
            ax.axhline(1.0, color="k", ls=":", lw=1)
            ax.text(lo_x * 1.1, 1.1, "elastic wave crosses a cell (En = 1)", fontsize=7)
            ax.axhline(2 / math.sqrt(60), color="k", ls="-.", lw=1)
            ax.text(lo_x * 1.1, 2 / math.sqrt(60) * 0.8, "c dt k_max = 2 for Q2 (En = 0.26)",
                    fontsize=7)
        ax.set_xlim(lo_x, hi_x)
        ax.set_ylim(lo_y, hi_y)
        ax.set_xlabel("CFL number |u|max dt / h")
        ax.set_ylabel("elastic number dt sqrt(G/rho) / h")
        handles = [plt.Line2D([], [], marker="o", ls="", color=c, label=k) for k, c in COLOURS.items()]
        handles += [plt.Line2D([], [], marker=m, ls="", color="grey", label="shear, Re = %g" % re)
                    for re, m in MARKERS.items() if any(r["Re"] == re and r["scene"] == "shear"
                                                        for r in sel)]
        if any(r["scene"] == "cavity" for r in sel):
            handles.append(plt.Line2D([], [], marker="*", ls="", color="grey", label="cavity"))
        ax.legend(handles=handles, fontsize=7, loc="lower right")
        ax.set_title("%s (viscous term implicit: no viscous limit)" % scheme, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        path = os.path.join(out_dir, "stability_%s.png" % scheme)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    print("\nwrote", ", ".join(os.path.basename(p) for p in paths))


def main():
    os.makedirs(WORK, exist_ok=True)
    csv_path = os.path.join(OUT, "results.csv")
    start = time.perf_counter()
    if "--replot" in sys.argv:
        rows = read_csv(csv_path)
    else:
        cases = shear_cases() + cavity_cases()
        print("%d runs, %d at a time" % (len(cases), PARALLEL), flush=True)
        with concurrent.futures.ThreadPoolExecutor(PARALLEL) as pool:
            rows = list(pool.map(run, cases))
        classify(rows)
        write_csv(rows, csv_path, FIELDS)
    report(rows)
    plot(rows, OUT)
    print("benchmark wall time %.0f s" % (time.perf_counter() - start))
    if QUICK:
        # the smoke run's claim: at En = 1.6 sqrt(G) h-steps the explicit
        # coupling fails and the semi-implicit one does not
        by = {r["coupling"] + str(r["En"] > 1): r for r in rows}
        explicit_large, semi_large = by["explicitTrue"], by["semi-implicitTrue"]
        ok = explicit_large["class"] == "failed" and semi_large["class"] != "failed"
        print("explicit coupling fails at En = %.2f: %s; semi-implicit runs there: %s" % (
            explicit_large["En"], explicit_large["class"] == "failed", semi_large["class"] != "failed"))
        sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
