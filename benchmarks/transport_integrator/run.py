#!/usr/bin/env python3
"""SSP-RK3, SSP-RK2 and SSP-RK(3,2) for the DG 1 transport of phi (and B):
accuracy against cost, side by side in one run.

Usage (from the repository root, after a build in build/):

    python3 benchmarks/transport_integrator/run.py          # the table and chart
    python3 benchmarks/transport_integrator/run.py --replot # from the CSV

Scenes (the test suite's, so their references are documented there):
  zalesak  tests/solid_zalesak_01.prm: the slotted disc, one revolution on
           three meshes (L1 error of phi against the initial shape, and of
           the cell means against the exact cell fractions, finest mesh);
  disc     tests/solid_rotating_disc_01.prm: a disc in rigid rotation at
           16 cells per diameter (area(phi >= 1/2) against pi r^2, D);
  shear    tests/solid_disc_shear_01.prm: the elastic disc in shear at three
           capillary numbers (largest relative deviation of D at t = 0.8
           from doc/solid_theory.md, as the test prints it).
Each runs with 'Solid/Time integrator' = SSP-RK3, SSP-RK2 and SSP-RK(3,2), one MPI rank
each, as many at a time as cores (JOBS=n). Seconds are the runs' own
TimerOutput totals (wall time of one rank). Writes results.csv and transport_integrator.png.
"""
import concurrent.futures
import math
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(REPO, "scripts"))
from benchmark_tools import plt, SUSPENSION, PARALLEL, work_directory, write_csv  # noqa: E402

WORK = work_directory(HERE, False)
SCENES = {"zalesak": "solid_zalesak_01.prm", "disc": "solid_rotating_disc_01.prm",
          "shear": "solid_disc_shear_01.prm"}
INTEGRATORS = ["SSP-RK3", "SSP-RK2", "SSP-RK(3,2)"]
MARKERS = {"SSP-RK3": "o", "SSP-RK2": "s", "SSP-RK(3,2)": "^"}


def run(scene, integrator):
    out = os.path.join(WORK, f"{scene}_" + re.sub(r"[^A-Za-z0-9-]+", "", integrator))
    os.makedirs(out, exist_ok=True)
    cmd = [SUSPENSION, os.path.join(REPO, "tests", SCENES[scene]),
           "--set", f"Solid/Time integrator={integrator}", "--set", f"Output/Directory={out}",
           "--set", "Output/Write vtu=false"]
    start = time.time()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    text, _ = p.communicate()
    status = p.returncode
    wall = time.time() - start
    with open(os.path.join(out, "screen.txt"), "w") as f:
        f.write(text)
    return scene, integrator, text, wall, status


def cpu_of(text, wall):
    m = re.search(r"Total wallclock time elapsed since start\s*\|\s*([0-9.]+)s", text)
    return float(m.group(1)) if m else wall


def measures(scene, text):
    r = {}
    if scene == "zalesak":
        l1 = re.findall(r"phi L1 error ([0-9.e+-]+); of the cell means against the exact cell "
                        r"fractions ([0-9.e+-]+)", text)
        r["error"] = float(l1[-1][0])
        r["error_means"] = float(l1[-1][1])
    elif scene == "disc":
        area = re.findall(r"final: .*D = ([0-9.]+).*area\(phi >= 1/2\) ([0-9.]+)", text)
        D, a = float(area[-1][0]), float(area[-1][1])
        exact = math.pi * 0.125 ** 2
        r["D"] = D
        r["error"] = abs(a / exact - 1.)
    else:
        # the sweep's lines: D, ..., expected D, deviation; the largest deviation
        dev = re.findall(r"D = ([0-9.]+) .*expected D = ([0-9.]+)\s+deviation ([0-9.]+) %", text)
        r["D"] = " ".join(d for d, _, _ in dev)
        r["error"] = max(abs(float(d) / float(e) - 1.) for d, e, _ in dev)
    r["substeps"] = (re.findall(r"\(round-off bound, ([0-9]+) sub-steps", text) or ["?"])[-1]
    return r


def main():
    rows = []
    if "--replot" not in sys.argv:
        os.makedirs(WORK, exist_ok=True)
        jobs = [(s, i) for s in SCENES for i in INTEGRATORS]
        with concurrent.futures.ThreadPoolExecutor(PARALLEL) as pool:
            for scene, integrator, text, wall, status in pool.map(lambda a: run(*a), jobs):
                if status != 0:
                    sys.exit(f"{scene} {integrator} failed:\n{text[-2000:]}")
                row = {"scene": scene, "integrator": integrator,
                       "seconds": round(cpu_of(text, wall), 2)}
                row.update(measures(scene, text))
                rows.append(row)
        write_csv(rows, os.path.join(HERE, "results.csv"),
                  ["scene", "integrator", "seconds", "substeps", "error", "error_means", "D"])
    else:
        import csv
        with open(os.path.join(HERE, "results.csv")) as f:
            rows = list(csv.DictReader(f))
    print(f"{'scene':8s} {'integrator':10s} {'seconds':>8s} {'sub-steps':>9s} {'error':>10s} "
          f"{'means':>10s} {'D':>8s}")
    for r in rows:
        print(f"{r['scene']:8s} {r['integrator']:10s} {float(r['seconds']):8.2f} {str(r['substeps']):>9s} "
              f"{str(r.get('error', '')):>10s} {str(r.get('error_means', '')):>10s} {str(r.get('D', '')):>8s}")
    for s in SCENES:
        a = [r for r in rows if r["scene"] == s]
        rk3 = [r for r in a if r["integrator"] == "SSP-RK3"]
        for r in a:
            if rk3 and r is not rk3[0]:
                print(f"{s}: {r['integrator']} / SSP-RK3 time "
                      f"{float(r['seconds']) / float(rk3[0]['seconds']):.3f}")

    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for ax, s, key, label in zip(axes, SCENES, ["error", "error", "error"],
                                 ["phi L1 error (finest mesh)", "|area(phi >= 1/2) / (pi r^2) - 1|",
                                  "largest |D / D_theory - 1|, t = 0.8"]):
        for r in rows:
            if r["scene"] == s and r.get(key, "") != "":
                ax.plot(float(r["seconds"]), float(r[key]), MARKERS.get(r["integrator"], "x"),
                        label=r["integrator"], ms=8)
        ax.set_xlabel("wall seconds, one rank")
        ax.set_ylabel(label)
        ax.set_title(s)
        ax.legend()
    fig.suptitle("DG 1 transport: SSP-RK3, SSP-RK2 and SSP-RK(3,2)")
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "transport_integrator.png"), dpi=110)


main()
