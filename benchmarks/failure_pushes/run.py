#!/usr/bin/env python3
"""Where methods fail: push one particle and a short 2D suspension.

Usage (from the repository root, after a build in build/):

    python3 benchmarks/failure_pushes/run.py            # all pushes (wall time in README.md)
    python3 benchmarks/failure_pushes/run.py --replot   # the table from results.csv

Pushes, each from a case that runs to one that does not (or to the end of
the range), with the default numerics (explicit elastic coupling, DG 1 with
the limiter, adaptive time step):
  single particle  the disc in shear (parameters/disc_shear_2d.prm, level 5)
                   to Ca = 0.3, 1, 3, 10, to t = 2;
  suspension       parameters/suspension_channel_2d.prm coarsened to level 6
                   (12.8 cells per diameter), to t = 0.3:
                   inertia Re_b = 250, 500, 1000, 2000 (Ca = 0.3),
                   deformation Ca = 0.3, 1, 3 (Re_b = 250),
                   packing Phi = 0.1, 0.2, 0.3.
Each row: finished or the solver's message, the smallest det B, the largest
eigenvalue of B, the closest particle gap (in cells), the mass drift.
"""

import concurrent.futures
import csv
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
WORK = os.environ.get("BENCHMARK_WORK", os.path.join(HERE, "work"))
SUSPENSION = os.environ.get("SUSPENSION", os.path.join(REPO, "build", "suspension"))
PARALLEL = int(os.environ.get("JOBS", os.cpu_count() or 1))

SHEAR = os.path.join(REPO, "parameters", "disc_shear_2d.prm")
CHANNEL = os.path.join(REPO, "parameters", "suspension_channel_2d.prm")
CHANNEL_COMMON = ["Mesh refinement/Maximum level=6", "Time stepping/End time=0.3",
                  "Statistics/Enabled=false", "Output/Write vtu=false",
                  "Output/Write phi cells=false", "Output/Timer summary=false"]


def cases():
    out = []
    for ca in (0.3, 1, 3, 10):
        # mu = 1, shear rate 1: G = 1 / Ca
        out.append(("particle", "Ca", ca, SHEAR, ["Solid/Shear modulus=%g" % (1.0 / ca),
                                                   "Time stepping/End time=2"]))
    for re in (250, 500, 1000, 2000):
        mu = 1.0 / re
        # Ca = mu (3/2) / G = 0.3
        out.append(("suspension", "Re_b", re, CHANNEL, CHANNEL_COMMON + [
            "Material/Viscosity=%g" % mu, "Solid/Shear modulus=%g" % (mu * 1.5 / 0.3)]))
    for ca in (1, 3):
        out.append(("suspension", "Ca", ca, CHANNEL, CHANNEL_COMMON + [
            "Solid/Shear modulus=%g" % (0.004 * 1.5 / ca)]))
    for phi in (0.2, 0.3):
        out.append(("suspension", "Phi", phi, CHANNEL, CHANNEL_COMMON + [
            "Solid/Seeding/Volume fraction=%g" % phi]))
    return out


def grab(pattern, text, default=""):
    m = re.search(pattern, text)
    return m.group(1) if m else default


def run(case):
    scene, knob, value, prm, sets = case
    name = "%s_%s%g" % (scene, knob, value)
    out = os.path.join(WORK, name)
    os.makedirs(out, exist_ok=True)
    command = [SUSPENSION, prm, "--set", "Output/Directory=" + out]
    for s in sets:
        command += ["--set", s]
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True)
    wall = time.perf_counter() - start
    log = result.stdout + result.stderr
    open(os.path.join(out, "log.txt"), "w").write(log)
    message = ""
    if result.returncode != 0:
        message = grab(r"error: (.*)", log, "exit code %d" % result.returncode)
    row = dict(scene=scene, knob=knob, value=value,
               outcome="finished" if result.returncode == 0 else "failed", message=message,
               min_det_B=grab(r"min det ([0-9.e+-]+)", log),
               closest_gap_cells=grab(r"closest gap between particles [0-9.e+-]+ \(([0-9.]+) dx\)", log),
               merged_free=grab(r"particles never merged and kept a gap >= dx: (\w+)", log),
               mass_drift=grab(r"relative drift ([0-9.e+-]+)", log),
               t_reached=(re.findall(r"t = ([0-9.e+-]+) / ", log) or [""])[-1],
               wall_time=round(wall, 1))
    print("  %-22s %-9s %s" % (name, row["outcome"], message[:150]), flush=True)
    return row


def main():
    os.makedirs(WORK, exist_ok=True)
    path = os.path.join(HERE, "results.csv")
    start = time.perf_counter()
    if "--replot" in sys.argv:
        with open(path) as f:
            rows = list(csv.DictReader(f))
    else:
        with concurrent.futures.ThreadPoolExecutor(PARALLEL) as pool:
            rows = list(pool.map(run, cases()))
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
    print("\n%-10s %-5s %6s %-9s %9s %10s %8s %7s %10s %7s  %s" % (
        "scene", "knob", "value", "outcome", "t reached", "min det B", "gap/dx", "merged",
        "drift", "wall", "message"))
    for r in rows:
        print("%-10s %-5s %6s %-9s %9s %10s %8s %7s %10s %7s  %s" % (
            r["scene"], r["knob"], r["value"], r["outcome"], r["t_reached"] or "-",
            r["min_det_B"] or "-",
            r["closest_gap_cells"] or "-", {"yes": "no", "no": "YES"}.get(r["merged_free"], "-"),
            r["mass_drift"] or "-", r["wall_time"], r["message"]))
    print("benchmark wall time %.0f s" % (time.perf_counter() - start))


if __name__ == "__main__":
    main()
