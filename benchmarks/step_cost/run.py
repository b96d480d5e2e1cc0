#!/usr/bin/env python3
"""The cost of a step, old code against new, side by side in one run
(issue 14).

Usage (from the repository root):

    python3 benchmarks/step_cost/run.py [--old REV] [--scenes a,b,...] [--replot]
                                        [--old-scenes-only]

Builds REV (default: 958feed, the end of session 10, before issue 14's
work) in a git worktree under work/old, copies build/suspension (the
working tree, not rebuilt here) to work/new, and runs each scene with both,
one after the other, never two at once. Prints per scene the wall time,
the TimerOutput sections that matter, the peak resident memory and the
ratios new/old, and writes results.csv and step_cost.png next to this
script. --replot redraws the chart and reprints the table from results.csv.
--old-scenes-only runs REV's scene files with the present binary instead of
building REV: the comparison of a scene's new settings where the code of
the old ones is unchanged.
"""

import argparse
import csv
import os
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
from benchmark_tools import plt, REPO  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
WORK = os.path.join(HERE, "work")
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMP_NUM_THREADS="1")

# name: (ranks, parameter file in parameters/, --set entries); every run
# writes no fields. Each code runs the scene file of its own tree: the scene
# as it was against the scene as it is (a scene may change its
# discretization, e.g. its DG degree, with the code; the results columns
# show what that does to the answer).
SCENES = {
    "main job (2D, 2 ranks)": (
        2, "suspension_channel_2d.prm", []),
    "3D reduced box, 6 steps (level 3, 2 ranks)": (
        2, "suspension_channel_3d_reduced.prm",
        ["Time stepping/Maximum number of steps=6", "Statistics/Enabled=false"]),
    "3D reduced box, 3 steps (level 4, 2 ranks)": (
        2, "suspension_channel_3d_reduced.prm",
        ["Mesh refinement/Maximum level=4", "Time stepping/Maximum number of steps=3",
         "Statistics/Enabled=false"]),
    # the memory target (<= 1 kB per velocity DoF): one rank, so that the
    # peak is that of one process holding the whole mesh
    "3D reduced box, 2 steps (level 4, 1 rank)": (
        1, "suspension_channel_3d_reduced.prm",
        ["Mesh refinement/Maximum level=4", "Time stepping/Maximum number of steps=2",
         "Statistics/Enabled=false"]),
    # per step and per unit of simulated time: a scene may take shorter steps
    # with fewer transport sub-steps each (session 33); one rank, so that it
    # runs beside a study on the other core
    "3D reduced box, 6 steps (level 4, 1 rank, per time unit)": (
        1, "suspension_channel_3d_reduced.prm",
        ["Mesh refinement/Maximum level=4", "Time stepping/Maximum number of steps=6",
         "Statistics/Enabled=false", "Output/Progress interval=1"]),
    "cavity disc to t = 1 (32 cells per diameter, 1 rank)": (
        1, "disc_cavity_2d.prm",
        ["Time stepping/End time=1", "Output/Write phi cells=false"]),
}
SECTIONS = ["solid transport", "fluid: momentum right-hand side", "fluid: momentum solve",
            "fluid: projection", "mesh adaptation", "setup (mesh, DoFs, matrices)"]


def sh(cmd, **kw):
    return subprocess.run(cmd, check=True, **kw)


def build_old(rev, build=True):
    """A worktree of `rev` with its own Release build (about 5 minutes);
    with build=False only the worktree (its scene files)."""
    tree = os.path.join(WORK, "old")
    exe = os.path.join(tree, "build", "suspension")
    if os.path.exists(exe if build else tree):
        have = subprocess.run(["git", "-C", tree, "rev-parse", "HEAD"], capture_output=True,
                              text=True).stdout.strip()
        want = subprocess.run(["git", "-C", REPO, "rev-parse", rev], capture_output=True,
                              text=True).stdout.strip()
        if have == want:
            return exe
    if os.path.exists(tree):
        sh(["git", "-C", REPO, "worktree", "remove", "--force", tree])
    sh(["git", "-C", REPO, "worktree", "add", "--detach", tree, rev])
    if not build:
        return exe
    sh(["cmake", "-S", tree, "-B", os.path.join(tree, "build"), "-DCMAKE_BUILD_TYPE=Release"],
       stdout=subprocess.DEVNULL)
    sh(["cmake", "--build", os.path.join(tree, "build"), "-j", str(os.cpu_count() or 1)],
       stdout=subprocess.DEVNULL)
    return exe


def copy_new():
    """build/suspension and its library, so that a rebuild meanwhile does not
    change what is measured."""
    target = os.path.join(WORK, "new")
    os.makedirs(target, exist_ok=True)
    for name in os.listdir(os.path.join(REPO, "build")):
        if name == "suspension" or name.startswith("libsuspension"):
            shutil.copy2(os.path.join(REPO, "build", name), target)
    return os.path.join(target, "suspension")


def run(exe, tree, name, ranks, prm, sets, label):
    prm = os.path.join(tree, "parameters", prm)
    out = os.path.join(WORK, "runs", label + "_" + re.sub(r"[^a-z0-9]+", "_", name.lower()))
    os.makedirs(out, exist_ok=True)
    args = [exe, prm, "--set", "Output/Directory=" + os.path.join(out, "output"),
            "--set", "Output/Write vtu=false", "--set", "Output/Timer summary=true",
            "--set", "Output/Progress interval=0"]
    for s in sets:
        args += ["--set", s]
    cmd = (["mpirun", "-np", str(ranks)] if ranks > 1 else []) + args
    # the peak resident memory of the largest rank (GNU time: max over the
    # waited-for processes)
    start = time.perf_counter()
    with open(os.path.join(out, "log"), "w") as log:
        sh(["/usr/bin/time", "-f", "%M", "-o", os.path.join(out, "rss")] + cmd,
           stdout=log, stderr=subprocess.STDOUT, cwd=out,
           # the library next to the executable: the RUNPATH would load the
           # one in build/, which a rebuild meanwhile changes
           env=dict(MPI_ENV, LD_LIBRARY_PATH=os.path.dirname(exe)))
    wall = time.perf_counter() - start
    text = open(os.path.join(out, "log")).read()
    row = {"scene": name, "code": label, "ranks": ranks, "wall_s": round(wall, 2),
           "peak_MB": round(int(open(os.path.join(out, "rss")).read().split()[-1]) * 1.024e-3, 1)}
    m = re.search(r"(\d+) cells, (\d+) velocity", text)
    row["cells"], row["velocity_dofs"] = (int(m.group(1)), int(m.group(2))) if m else ("", "")
    m = re.search(r"Total wallclock time elapsed since start\s*\|\s*([0-9.e+]+)s", text)
    row["solver_s"] = float(m.group(1)) if m else ""
    # the steady step: solver time without the set-up, per step
    m = re.search(r"Maximum number of steps=(\d+)", " ".join(sets))
    row["s_per_step"] = (round((row["solver_s"] - float(re.search(
        r"\|\s*setup \(mesh, DoFs, matrices\)\s*\|\s*\d+\s*\|\s*([0-9.e+]+)s", text).group(1)))
        / int(m.group(1)), 3) if m and row["solver_s"] != "" else "")
    # simulated time reached (the last progress line, where the scene prints one)
    m = re.findall(r"step\s+\d+\s+t = ([0-9.e+-]+)", text)
    row["t_end"] = float(m[-1]) if m else ""
    row["s_per_time_unit"] = (round(row["s_per_step"] * int(re.search(
        r"Maximum number of steps=(\d+)", " ".join(sets)).group(1)) / row["t_end"], 1)
        if m and row["s_per_step"] != "" else "")
    m = re.search(r"Memory: peak resident .*?, ([0-9.]+) kB per velocity DoF", text)
    row["kB_per_velocity_dof"] = float(m.group(1)) if m else ""
    m = re.search(r"elastic energy where phi < 1/2: ([0-9.e+-]+) %", text)
    row["tail_energy_percent"] = m.group(1) if m else ""
    for section in SECTIONS:
        m = re.search(r"\|\s*" + re.escape(section) + r"\s*\|\s*(\d+)\s*\|\s*([0-9.e+]+)s", text)
        row[section] = float(m.group(2)) if m else 0.
    m = re.search(r"mu_eff/mu = ([-0-9.]+ \+- [0-9.]+), N1 = ([-0-9.]+ \+- [0-9.]+), N2 = ([-0-9.]+ \+- [0-9.]+)", text)
    row["mu_eff"], row["N1"], row["N2"] = m.groups() if m else ("", "", "")
    return row


def table(rows):
    by = {(r["scene"], r["code"]): r for r in rows}
    print(f"{'scene':52s} {'':5s} {'wall s':>8s} {'solver s':>9s} {'transport':>9s} "
          f"{'peak MB':>8s} {'s/step':>7s} {'kB/vDoF':>7s} {'s/t':>8s}")
    num = lambda r, k: float(r[k]) if r.get(k) not in (None, "") else float("nan")
    for scene in dict.fromkeys(r["scene"] for r in rows):
        for code in ("old", "new"):
            r = by.get((scene, code))
            if r:
                print(f"{scene:52s} {code:5s} {float(r['wall_s']):8.1f} {float(r['solver_s'] or 0):9.1f} "
                      f"{float(r['solid transport']):9.1f} {float(r['peak_MB']):8.0f}"
                      f" {num(r, 's_per_step'):7.2f} {num(r, 'kB_per_velocity_dof'):7.2f}"
                      f" {num(r, 's_per_time_unit'):8.1f}"
                      + (f"  mu_eff {r['mu_eff']}, N1 {r['N1']}, N2 {r['N2']}" if r.get("mu_eff") else ""))
        if (scene, "old") in by and (scene, "new") in by:
            o, n = by[(scene, "old")], by[(scene, "new")]
            ratio = lambda k: num(n, k) / num(o, k) if num(o, k) > 0 else float("nan")
            print(f"{'':52s} {'ratio':5s} {ratio('wall_s'):8.2f} {ratio('solver_s'):9.2f} "
                  f"{ratio('solid transport'):9.2f} {ratio('peak_MB'):8.2f} "
                  f"{ratio('s_per_step'):7.2f} {ratio('kB_per_velocity_dof'):7.2f} "
                  f"{ratio('s_per_time_unit'):8.2f}")


def chart(rows, png="step_cost.png"):
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    by = {(r["scene"], r["code"]): r for r in rows}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, key, title in ((axes[0], "solver_s", "solver wall time (s)"),
                           (axes[1], "peak_MB", "peak resident memory (MB)")):
        for i, code in enumerate(("old", "new")):
            values = [float(by[(s, code)][key] or 0) if (s, code) in by else 0 for s in scenes]
            ax.barh([j + 0.4 * i for j in range(len(scenes))], values, height=0.4,
                    label=code, color=("0.6", "C0")[i])
        ax.set_yticks([j + 0.2 for j in range(len(scenes))])
        ax.set_yticklabels([s.replace(" (", "\n(") for s in scenes], fontsize=8)
        ax.set_title(title)
        ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, png), dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", default="958feed")
    parser.add_argument("--scenes", default="")
    parser.add_argument("--replot", action="store_true")
    parser.add_argument("--old-scenes-only", action="store_true",
                        help="run REV's scene files with the present binary (no build): for a "
                             "change of a scene's settings whose code path REV already had")
    parser.add_argument("--csv", default="results.csv",
                        help="the table's file in benchmarks/step_cost/ (a subset of the scenes "
                             "can keep its own)")
    a = parser.parse_args()
    csv_path = os.path.join(HERE, a.csv)
    if a.replot:
        rows = list(csv.DictReader(open(csv_path)))
    else:
        os.makedirs(WORK, exist_ok=True)
        new = copy_new()
        old = build_old(a.old, build=not a.old_scenes_only)
        exes = {"old": new if a.old_scenes_only else old, "new": new}
        trees = {"old": os.path.join(WORK, "old"), "new": REPO}
        chosen = [s for s in SCENES if not a.scenes or any(k in s for k in a.scenes.split(","))]
        rows = []
        for name in chosen:
            ranks, prm, sets = SCENES[name]
            for label in ("old", "new"):
                rows.append(run(exes[label], trees[label], name, ranks, prm, sets, label))
                print(f"  {name} [{label}]: {rows[-1]['wall_s']} s", flush=True)
        fields = list(rows[0].keys())
        with open(csv_path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            w.writerows(rows)
    table(rows)
    chart(rows, "step_cost.png" if a.csv == "results.csv" else os.path.splitext(a.csv)[0] + ".png")


if __name__ == "__main__":
    main()
