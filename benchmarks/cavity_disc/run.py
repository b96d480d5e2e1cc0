#!/usr/bin/env python3
"""The elastic disc in the lid-driven cavity against Sugiyama et al. (2011):
the distance of the centroid path from the published path, against CPU time,
at 16, 32 and 64 cells per diameter (issue 13, item 5).

Usage (from the repository root, after a build in build/):

    python3 benchmarks/cavity_disc/run.py            # the three runs (about 1 h of CPU)
    python3 benchmarks/cavity_disc/run.py --replot   # table and chart from results.csv
    python3 benchmarks/cavity_disc/run.py --measure DIR  # the same from finished runs DIR/L3 ...

Each run is parameters/disc_cavity_2d.prm on 5 x 5 base cells of 0.2,
levels 3 (40 x 40, the flow) to L at the interface, L = 3, 4, 5 (h = 1/40,
1/80, 1/160: 16, 32, 64 cells per diameter), to t = 8, one rank, timed by
/usr/bin/time (user + system CPU seconds, peak resident memory). The
distance of every step's centroid from the digitized reference polyline
(../shared/reference/cavity_disc_path_sugiyama2011.csv, a few 1e-3
digitization error) is averaged to t = 6 and to t = 8 (scripts/path_distance.py).
Writes results.csv and doc/figures/cavity_path_cost.png.
"""

import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(REPO, "scripts"))
from benchmark_tools import plt, SUSPENSION, work_directory, write_csv  # noqa: E402

REFERENCE = os.path.normpath(os.path.join(REPO, "..", "shared", "reference",
                                          "cavity_disc_path_sugiyama2011.csv"))
LEVELS = [3, 4, 5]
# --levels 3,4 runs only those; --set 'Entry=value' (repeatable) is passed
# on to every run (for example 'Solid/Time integrator=SSP-RK2')
if "--levels" in sys.argv:
    LEVELS = [int(x) for x in sys.argv[sys.argv.index("--levels") + 1].split(",")]
EXTRA = []
for i, arg in enumerate(sys.argv):
    if arg == "--set":
        EXTRA += ["--set", sys.argv[i + 1]]


def distance(statistics, until):
    out = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "path_distance.py"),
                          statistics, REFERENCE, "--until", str(until)],
                         capture_output=True, text=True, check=True).stdout
    m = re.search(r"mean distance ([0-9.e-]+), max ([0-9.e-]+)", out)
    return float(m.group(1)), float(m.group(2))


def run(level, work):
    directory = os.path.join(work, "L%d" % level)
    log = directory + ".log"
    with open(log, "w") as f:
        subprocess.run(["/usr/bin/time", "-v", SUSPENSION,
                        os.path.join(REPO, "parameters", "disc_cavity_2d.prm"),
                        "--set", "Output/Directory=" + directory,
                        "--set", "Geometry/Subdivisions=5, 5", "--set", "Mesh/Global refinements=3",
                        "--set", "Mesh refinement/Minimum level=3",
                        "--set", "Mesh refinement/Maximum level=%d" % level,
                        "--set", "Output/Write vtu=false", "--set", "Output/Write phi cells=false"]
                       + EXTRA,
                       stdout=f, stderr=subprocess.STDOUT, check=True)
    return measure(level, directory, log)


def measure(level, directory, log):
    text = open(log).read()
    cpu = sum(float(re.search(k + r" \(seconds\): ([0-9.]+)", text).group(1))
              for k in ("User time", "System time"))
    memory = int(re.search(r"Maximum resident set size \(kbytes\): ([0-9]+)", text).group(1))
    mean6, max6 = distance(os.path.join(directory, "statistics.txt"), 6)
    mean8, max8 = distance(os.path.join(directory, "statistics.txt"), 8)
    return {"level": level, "cells_per_diameter": 0.4 * 40 * 2 ** (level - 3), "cpu_s": cpu,
            "peak_memory_MB": round(memory / 1024.), "mean_to_6": mean6, "max_to_6": max6,
            "mean_to_8": mean8, "max_to_8": max8}


def main():
    csv_path = os.path.join(HERE, "results.csv")
    if "--replot" in sys.argv:
        import csv
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open(csv_path))]
    elif "--measure" in sys.argv:
        work = sys.argv[sys.argv.index("--measure") + 1]
        rows = [measure(level, os.path.join(work, "L%d" % level), os.path.join(work, "L%d.log" % level))
                for level in LEVELS]
        write_csv(rows, csv_path)
    else:
        work = work_directory(HERE, False)
        os.makedirs(work, exist_ok=True)
        rows = [run(level, work) for level in LEVELS]
        if not EXTRA and LEVELS == [3, 4, 5]:
            write_csv(rows, csv_path)
    print("cells/diameter  CPU s   memory MB  mean to t=6  mean to t=8  max")
    for r in rows:
        print("%8.0f %10.0f %8.0f %12.4f %12.4f %8.4f" % (r["cells_per_diameter"], r["cpu_s"],
              r["peak_memory_MB"], r["mean_to_6"], r["mean_to_8"], r["max_to_8"]))
    fig, ax = plt.subplots(figsize=(6, 4))
    cpu = [r["cpu_s"] for r in rows]
    ax.plot(cpu, [r["mean_to_8"] for r in rows], "o-", label="mean distance to t = 8 (THINC)")
    ax.plot(cpu, [r["mean_to_6"] for r in rows], "s-", label="mean distance to t = 6 (THINC)")
    for r in rows:
        ax.annotate("%.0f cells/d" % r["cells_per_diameter"], (r["cpu_s"], r["mean_to_8"]),
                    textcoords="offset points", xytext=(4, 4), fontsize=8)
    # the DG transport alone (session 8), if its results are kept
    dg_path = os.path.join(HERE, "results_session8_dg.csv")
    if os.path.exists(dg_path):
        import csv
        dg = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open(dg_path))]
        ax.plot([r["cpu_s"] for r in dg], [r["mean_to_8"] for r in dg], "o:", color="grey",
                label="to t = 8, DG transport alone (session 8)")
    ax.axhline(0.004, color="grey", ls="--", lw=0.8, label="target at 32 cells/d (issue 13)")
    ax.set_xscale("log")
    ax.set_xlabel("CPU seconds (one rank)")
    ax.set_ylabel("distance from Sugiyama et al. 2011")
    ax.set_ylim(0, 0.008)
    ax.set_title("Elastic disc in the lid-driven cavity: centroid path")
    ax.legend(fontsize=8)
    fig.tight_layout()
    if not EXTRA and LEVELS == [3, 4, 5]:
        fig.savefig(os.path.join(REPO, "doc", "figures", "cavity_path_cost.png"), dpi=120)


if __name__ == "__main__":
    main()
