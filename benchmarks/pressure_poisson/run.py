#!/usr/bin/env python3
"""The projection's pressure Poisson problem: assembled Q1 matrix with
BoomerAMG (the solver's choice) against matrix-free geometric multigrid,
side by side in one run (issue 14, item 1).

Usage (from the repository root):

    python3 benchmarks/pressure_poisson/run.py [--replot]

Configures and builds pressure_poisson.cc (a stand-alone deal.II program,
not part of the solver's build) under work/, runs it on the main job's kind
of 2D channel mesh at three finest levels and on the reduced 3D box at two,
each with periodic faces (the solver's channel) and with walls all round,
one rank, and prints per case the set-up (per mesh change), the solve (per
step), the iterations and the resident memory the set-up adds. Writes
results.csv and pressure_poisson.png next to this script.
"""

import argparse
import csv
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
from benchmark_tools import plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
WORK = os.path.join(HERE, "work")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMP_NUM_THREADS="1")
# (dimension, finest level of the program's coarse mesh): 2D level 5 is the
# main job's level 7 (its 6 x 2 mesh refined twice globally is level 2)
CASES = [(2, 5), (2, 6), (2, 7), (3, 3), (3, 4)]
FIELDS = ["dim", "level", "faces", "pressure DoFs", "method", "set-up s", "solve s",
          "iterations", "converged", "heap MB", "max difference"]


def build():
    os.makedirs(WORK, exist_ok=True)
    subprocess.run(["cmake", HERE, "-DCMAKE_BUILD_TYPE=Release"], cwd=WORK, check=True,
                   stdout=subprocess.DEVNULL)
    subprocess.run(["make"], cwd=WORK, check=True, stdout=subprocess.DEVNULL)
    return os.path.join(WORK, "pressure_poisson")


def number(pattern, text):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else float("nan")


def run(exe, dim, level, faces):
    env = dict(ENV)
    env.pop("PRESSURE_POISSON_WALLS", None)
    if faces == "walls":
        env["PRESSURE_POISSON_WALLS"] = "1"
    out = subprocess.run([exe, str(dim), str(level), "2"], env=env, capture_output=True,
                         text=True, check=True).stdout
    dofs = int(number(r"(\d+) pressure DoFs", out))
    difference = number(r"max \|p_amg - p_gmg\| \(both mean-free\): (\S+)", out)
    def multigrid(name):
        return {"set-up s": number(name + r".*set-up (\S+) s", out),
                "solve s": number(name + r".*solve (\S+) s", out),
                "iterations": int(number(name + r".*?(\d+)(?: \(not converged\))? iterations",
                                         out)),
                "converged": not re.search(name + r".*not converged", out),
                "heap MB": number(name + r".*heap growth (\S+) MB", out)}
    local, global_ = multigrid("gmg local"), multigrid("gmg global")
    amg = {"set-up s": number(r"amg: assembly (\S+) s", out)
           + number(r"AMG set-up (\S+) s", out),
           "solve s": number(r"amg:.*solve (\S+) s", out),
           "iterations": int(number(r"amg:.*?(\d+) iterations", out)),
           "converged": True,
           "heap MB": number(r"amg:.*heap growth (\S+) MB", out)}
    rows = []
    for method, r in (("BoomerAMG, assembled", amg), ("GMG local smoothing, matrix-free", local),
                      ("GMG global coarsening, matrix-free", global_)):
        rows.append(dict(r, **{"dim": dim, "level": level, "faces": faces,
                               "pressure DoFs": dofs, "method": method,
                               "max difference": difference}))
    return rows


def table(rows):
    print("| dim | faces | pressure DoFs | method | set-up s | solve s | iterations |"
          " heap MB | solve / AMG's |")
    print("|---|---|---|---|---|---|---|---|---|")
    for i in range(0, len(rows), 3):
        amg = rows[i]
        for r in rows[i:i + 3]:
            ratio = (f"{float(r['solve s']) / float(amg['solve s']):.2f}"
                     if r is not amg else "")
            print(f"| {r['dim']} | {r['faces']} | {r['pressure DoFs']} | {r['method']} |"
                  f" {float(r['set-up s']):.3f} | {float(r['solve s']):.3f} |"
                  f" {r['iterations']}{'' if str(r['converged']) == 'True' else ' (cap)'} |"
                  f" {float(r['heap MB']):.1f} | {ratio} |")


def chart(rows):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, dim in zip(axes, (2, 3)):
        for method, marker in (("BoomerAMG, assembled", "o"),
                               ("GMG local smoothing, matrix-free", "s"),
                               ("GMG global coarsening, matrix-free", "^")):
            for faces, style in (("periodic", "-"), ("walls", "--")):
                sel = [r for r in rows if int(r["dim"]) == dim and r["method"] == method
                       and r["faces"] == faces]
                if not sel:
                    continue
                x = [int(r["pressure DoFs"]) for r in sel]
                y = [float(r["solve s"]) for r in sel]
                ax.loglog(x, y, style, marker=marker, label=f"{method}, {faces}")
                for r, xi, yi in zip(sel, x, y):
                    ax.annotate(str(r["iterations"]), (xi, yi), textcoords="offset points",
                                xytext=(4, 4), fontsize=7)
        ax.set_xlabel("pressure DoFs (Q1)")
        ax.set_ylabel("one solve to 1e-8, s (one rank)")
        ax.set_title(f"{dim}D (labels: CG iterations)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "pressure_poisson.png"), dpi=120)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--replot", action="store_true")
    args = p.parse_args()
    path = os.path.join(HERE, "results.csv")
    if args.replot:
        with open(path) as f:
            rows = list(csv.DictReader(f))
    else:
        exe = build()
        rows = []
        for dim, level in CASES:
            for faces in ("periodic", "walls"):
                rows += run(exe, dim, level, faces)
                print(f"  {dim}D level {level} {faces}: done", flush=True)
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=FIELDS)
            w.writeheader()
            w.writerows(rows)
    table(rows)
    chart(rows)


if __name__ == "__main__":
    main()
