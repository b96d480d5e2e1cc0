#!/usr/bin/env python3
"""Adaptive against uniform meshes: error in D against wall time and cells.

Usage (from the repository root, after scripts/setup.sh or a build in build/):

    python3 benchmarks/adaptivity/run.py [--replot] [--quick]

Runs the disc in shear (disc_shear.prm: r = 0.2, Ca = 0.05, to t = 0.8) on
uniform meshes of levels 4, 5, 6 and on adaptive meshes (levels 2 to L, the
interface band on L) for L = 4 ... 7, against an adaptive reference at level
8; then one 3D pair, the sphere in shear (sphere_shear.prm) at level 4,
uniform and adaptive, to t = 0.2 (a cost comparison at equal finest cells). One MPI rank each, one run at a time. Writes
results.csv and work_precision.png next to this script and prints a table
with the wall-time ratio at equal error. --replot redraws from results.csv;
--quick runs levels 4 and 5 only and no 3D pair (the test-suite smoke run,
which writes into work/ instead).
"""

import csv
import math
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
WORK = os.path.join(HERE, "work")
QUICK = "--quick" in sys.argv
OUT = WORK if QUICK else HERE
sys.path.insert(0, os.path.join(REPO, "scripts"))
from benchmark_tools import plt, SUSPENSION, write_csv  # noqa: E402
from statistics_table import read_table as read_statistics  # noqa: E402

# (dim, kind, finest level); "reference" is adaptive
CASES = ([(2, "uniform", l) for l in (4, 5, 6)] + [(2, "adaptive", l) for l in (4, 5, 6, 7)]
         + [(2, "reference", 8)] + [(3, "uniform", 4), (3, "adaptive", 4)])
if QUICK:
    CASES = [(2, "uniform", 4), (2, "adaptive", 4), (2, "uniform", 5), (2, "adaptive", 5)]


def run(dim, kind, level):
    template = os.path.join(HERE, "disc_shear.prm" if dim == 2 else "sphere_shear.prm")
    name = "%dd_%s_%d" % (dim, kind, level)
    out = os.path.join(WORK, name)
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    adaptive = kind != "uniform"
    text = open(template).read()
    text = (text.replace("@GLOBAL@", str(min(3 if dim == 2 else 2, level) if adaptive else level))
            .replace("@ADAPTIVE@", "true" if adaptive else "false")
            .replace("@LEVEL@", str(level)).replace("@OUT@", out)
            .replace("@END@", "0.8" if dim == 2 else "0.2"))
    prm = os.path.join(out, "run.prm")
    open(prm, "w").write(text)
    start = time.perf_counter()
    result = subprocess.run([SUSPENSION, prm], capture_output=True, text=True)
    wall = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit("run %s failed:\n%s%s" % (name, result.stdout, result.stderr))
    stats = read_statistics(os.path.join(out, "statistics.txt"))
    d = stats["D"][-1]  # ten digits (the printed line has four)
    cells = sum(stats["cells"]) / len(stats["cells"])
    h = 2.0 / (2 * 2 ** level)
    print("  %-22s D = %.7f  cells (mean) %9.0f  wall %8.1f s" % (name, d, cells, wall), flush=True)
    return dict(dim=dim, kind=kind, level=level, cells_per_diameter=0.4 / h, D=d,
                mean_cells=cells, steps=len(stats["cells"]), wall_time=wall)


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k in r:
            if k != "kind":
                r[k] = float(r[k])
        r["dim"], r["level"] = int(r["dim"]), int(r["level"])
    return rows


def log_interpolate(x, xs, ys):
    """y at x on the broken line through (xs, ys), log-log; None outside."""
    pts = sorted(zip(xs, ys))
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if x0 <= x <= x1:
            s = (math.log(x) - math.log(x0)) / (math.log(x1) - math.log(x0))
            return math.exp(math.log(y0) + s * (math.log(y1) - math.log(y0)))
    return None


def report(rows):
    two = [r for r in rows if r["dim"] == 2]
    ref = [r for r in two if r["kind"] == "reference"]
    d_ref = ref[0]["D"] if ref else max(two, key=lambda r: r["level"])["D"]
    print("\n2D disc in shear, Ca = 0.05; reference D = %.5f (%s)" %
          (d_ref, "adaptive level 8" if ref else "finest run"))
    print("  %-9s %5s %9s %9s %10s %10s %9s" % ("mesh", "level", "cells/d", "D", "rel. error",
                                                "mean cells", "wall [s]"))
    series = {}
    for r in two:
        if r["kind"] == "reference":
            continue
        r["error"] = abs(r["D"] - d_ref) / d_ref
        series.setdefault(r["kind"], []).append(r)
        print("  %-9s %5d %9.1f %9.7f %10.2e %10.0f %9.1f" % (r["kind"], r["level"],
              r["cells_per_diameter"], r["D"], r["error"], r["mean_cells"], r["wall_time"]))
    print("\n  at equal error (uniform wall time interpolated log-log at the adaptive error):")
    uni = series.get("uniform", [])
    for a in series.get("adaptive", []):
        t_u = log_interpolate(a["error"], [u["error"] for u in uni], [u["wall_time"] for u in uni]) \
            if a["error"] > 0 else None
        same = [u for u in uni if u["level"] == a["level"]]
        line = "  adaptive level %d: error %.2e" % (a["level"], a["error"])
        if t_u:
            line += ", uniform needs %.1f s vs %.1f s: ratio %.1f" % (t_u, a["wall_time"], t_u / a["wall_time"])
        if same:
            line += "; same level: cells %.1fx fewer, wall time %.1fx less, |D_a/D_u - 1| = %.2e" % (
                same[0]["mean_cells"] / a["mean_cells"], same[0]["wall_time"] / a["wall_time"],
                abs(a["D"] / same[0]["D"] - 1))
        print(line)
    three = [r for r in rows if r["dim"] == 3]
    if len(three) == 2:
        u, a = sorted(three, key=lambda r: r["kind"] != "uniform")
        print("\n3D sphere in shear, level %d (%.1f cells per diameter):" % (u["level"], u["cells_per_diameter"]))
        print("  uniform  D = %.7f, %.0f cells, %.1f s" % (u["D"], u["mean_cells"], u["wall_time"]))
        print("  adaptive D = %.7f, %.0f cells, %.1f s" % (a["D"], a["mean_cells"], a["wall_time"]))
        print("  cells %.1fx fewer, wall time %.1fx less, |D_a/D_u - 1| = %.2e" % (
            u["mean_cells"] / a["mean_cells"], u["wall_time"] / a["wall_time"], abs(a["D"] / u["D"] - 1)))
    return series


def plot(series, path):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    style = {"uniform": ("o-", "C0"), "adaptive": ("s-", "C1")}
    for kind, rs in series.items():
        rs = [r for r in rs if r["error"] > 0]
        m, c = style[kind]
        for ax, key in zip(axes, ("wall_time", "mean_cells")):
            ax.loglog([r[key] for r in rs], [r["error"] for r in rs], m, color=c, label=kind)
            for r in rs:
                ax.annotate("L%d" % r["level"], (r[key], r["error"]), textcoords="offset points",
                            xytext=(4, 4), fontsize=8)
    axes[0].set_xlabel("wall time [s] (1 rank)")
    axes[1].set_xlabel("mean number of cells")
    for ax in axes:
        ax.set_ylabel("relative error in D")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle("Disc in shear (Ca = 0.05): uniform vs interface-adaptive meshes")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print("\nwrote", path)


def main():
    os.makedirs(WORK, exist_ok=True)
    csv_path = os.path.join(OUT, "results.csv")
    start = time.perf_counter()
    if "--replot" in sys.argv:
        rows = read_csv(csv_path)
        # D with all its digits from the runs' statistics, where still there
        for r in rows:
            path = os.path.join(WORK, "%dd_%s_%d" % (r["dim"], r["kind"], r["level"]),
                                "statistics.txt")
            if os.path.exists(path):
                r["D"] = read_statistics(path)["D"][-1]
        write_csv(rows, csv_path)
    else:
        rows = [run(*case) for case in CASES]
        write_csv(rows, csv_path)
    series = report(rows)
    plot(series, os.path.join(OUT, "work_precision.png"))
    print("benchmark wall time %.0f s" % (time.perf_counter() - start))


if __name__ == "__main__":
    main()
