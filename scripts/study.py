#!/usr/bin/python3
"""Run a study: the cases of a scene's 'Study' subsection, resumable.

usage: scripts/study STUDY.prm [--jobs N] [--max-cases K] [--exe PATH]
                               [--set 'Section/Entry=value']...

`suspension STUDY.prm --list-cases` names the cases (Re x Ca x Phi, or the
paper's table) and the entries that make each; every case runs the same
STUDY.prm with those entries set and writes to its own directory
(Study/Directory/<case>). Cases run N at a time (default: cores / 'Ranks
per case'), each on 'Ranks per case' MPI ranks.

Resumable: a case whose directory holds case_done.json is skipped; one
with a checkpoint/ continues from it (--resume); the others start afresh.
Ctrl-C or a time limit loses at most the work since each case's last
checkpoint ('Checkpoint/Interval minutes').

Extendable: a case that stopped at its End time before its statistics were
complete keeps the checkpoint the solver writes there; run the study again
with a later End time (--set 'Time stepping/End time=T') and such cases go
on from where they stopped (their CPU seconds carried over), while cases
whose statistics were complete are skipped.

While it runs, one line every 30 s: cases done, running (with their
times), and the ETA of the whole study from the simulated time per
second so far. At the end (and after every finished case) the study's
table Study/Directory/study.csv and its figures (scripts/plot_study.py).
--max-cases K stops after K cases have finished or failed in this
invocation (a test of resumption; a failed case is not replaced by the
next). --collect only writes the table and the figures from the cases
finished so far (for example while a part of the study runs
under --set 'Study/Volume fractions=...').
--save-state archives the unfinished cases (checkpoint, statistics, logs;
no field files) to study_state/<study directory>/<case>.tar.xz; a later
run on another machine restores such a case before running it, so a study
longer than a sitting can be committed part-way and carried on.
"""
import argparse
import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
from statistics_table import read_table  # noqa: E402

p = argparse.ArgumentParser()
p.add_argument("prm")
p.add_argument("--jobs", type=int, default=0)
p.add_argument("--max-cases", type=int, default=0)
p.add_argument("--exe", default=os.path.join(here, "..", "build", "suspension"))
p.add_argument("--set", action="append", default=[], dest="sets")
p.add_argument("--progress-seconds", type=float, default=30.)
p.add_argument("--save-state", action="store_true",
               help="archive every unfinished case that has a checkpoint (without its "
               "field files) to study_state/<study directory>/<case>.tar.xz, for a "
               "later sitting on another machine, and exit; stop the study first")
p.add_argument("--collect", action="store_true",
               help="write study.csv and the figures from the finished cases; run nothing")
a = p.parse_args()

overrides = []
for s in a.sets:
    overrides += ["--set", s]
listing = subprocess.run([a.exe, a.prm, "--list-cases"] + overrides,
                         capture_output=True, text=True)
if listing.returncode != 0:
    sys.exit(listing.stderr.strip() or "suspension --list-cases failed")
study = json.loads(listing.stdout)
cases, root = study["cases"], study["directory"]
ranks = study["ranks_per_case"]
end_time = float(study["end_time"])
cores = os.cpu_count() or 1
jobs = a.jobs if a.jobs > 0 else max(1, cores // ranks)
os.makedirs(root, exist_ok=True)


def directory(case):
    return case["set"]["Output/Directory"]


# Unfinished cases carried between machines (--save-state): the case
# directory without its field files, restored before the case runs.
state_root = os.path.join(here, "..", "study_state", os.path.basename(os.path.normpath(root)))


def state_archive(case):
    return os.path.join(state_root, case["name"] + ".tar.xz")


def save_state():
    os.makedirs(state_root, exist_ok=True)
    for case in cases:
        d = directory(case)
        if os.path.isdir(os.path.join(d, "checkpoint")) and \
                not os.path.isfile(os.path.join(d, "case_done.json")):
            subprocess.run(["tar", "-cJf", state_archive(case), "--exclude=*.vtu",
                            "--exclude=*.pvtu", "--exclude=*.pvd", "-C",
                            os.path.dirname(os.path.normpath(d)),
                            os.path.basename(os.path.normpath(d))], check=True)
            print(f"  saved {case['name']} at t = {simulated_time(case):g} -> "
                  f"{os.path.relpath(state_archive(case))}", flush=True)


def restore_state(case):
    """A case not yet started here continues from an archived state."""
    d = directory(case)
    if os.path.isfile(state_archive(case)) and not os.path.isdir(os.path.join(d, "checkpoint")) \
            and not os.path.isfile(os.path.join(d, "case_done.json")):
        subprocess.run(["tar", "-xJf", state_archive(case), "-C",
                        os.path.dirname(os.path.normpath(d))], check=True)
        print(f"  restored {case['name']} from {os.path.relpath(state_archive(case))}",
              flush=True)


def done(case):
    """Finished, and not to be extended: a case that stopped at an End time
    below the study's present one keeps its checkpoint and goes on."""
    if not os.path.isfile(os.path.join(directory(case), "case_done.json")):
        return False
    return not extendable(case)


def extendable(case):
    has_checkpoint = os.path.isdir(os.path.join(directory(case), "checkpoint"))
    return has_checkpoint and end_of(case) < end_time * (1. - 1e-9)


def simulated_time(case):
    """The last time in the case's statistics.txt (0 if none yet)."""
    if done(case):
        return end_of(case)
    path = os.path.join(directory(case), "statistics.txt")
    try:
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            f.seek(max(0, f.tell() - 4096))
            lines = [l for l in f.read().decode(errors="replace").splitlines()
                     if l.strip() and not l.startswith("#")]
        return float(lines[-1].split()[1]) if lines else 0.
    except (OSError, ValueError, IndexError):
        return 0.


def end_of(case):
    path = os.path.join(directory(case), "case_done.json")
    try:
        with open(path) as f:
            return float(json.load(f)["time"])
    except (OSError, ValueError, KeyError):
        return end_time


def command(case):
    cmd = [a.exe, a.prm] + overrides
    for entry, value in case["set"].items():
        cmd += ["--set", f"{entry}={value}"]
    if os.path.isdir(os.path.join(directory(case), "checkpoint")):
        cmd.append("--resume")
    if ranks > 1:
        cmd = ["mpirun", "-np", str(ranks)] + cmd
    return cmd


def finish(case, seconds):
    """case_done.json: when it ended, what it cost (CPU seconds per rank x
    ranks), whether it was steady."""
    d = directory(case)
    cpu = seconds * ranks
    previous = os.path.join(d, "cpu_seconds_before.txt")
    if os.path.isfile(previous):
        with open(previous) as f:
            cpu += float(f.read() or 0)
    line = ""
    path = os.path.join(d, "stationarity.txt")
    if os.path.isfile(path):
        with open(path) as f:
            line = f.read().strip()
    record = {"name": case["name"], "time": simulated_time(case), "cpu_seconds": cpu,
              "ranks": ranks, "stationarity": line}
    with open(os.path.join(d, "case_done.json"), "w") as f:
        json.dump(record, f, indent=1)
    # a case that stopped at its End time keeps its last checkpoint (the
    # solver writes one there): a later End time extends it; one whose
    # statistics were complete before that has no use for it
    if record["time"] < end_time * (1. - 1e-9) and \
            os.path.isdir(os.path.join(d, "checkpoint")):
        shutil.rmtree(os.path.join(d, "checkpoint"))
    for name in ["cpu_seconds_before.txt"]:
        if os.path.isfile(os.path.join(d, name)):
            os.remove(os.path.join(d, name))


def extend(case):
    """A finished case goes on from its last checkpoint to the present End
    time: what it cost so far is carried over, its record is removed until
    it finishes again (an interruption then resumes it as any case)."""
    d = directory(case)
    with open(os.path.join(d, "case_done.json")) as f:
        record = json.load(f)
    with open(os.path.join(d, "cpu_seconds_before.txt"), "w") as f:
        f.write(str(record["cpu_seconds"]))
    os.remove(os.path.join(d, "case_done.json"))
    print(f"  extend {case['name']} from t = {record['time']:g} to {end_time:g}", flush=True)


def spent_before(case, seconds):
    """An interrupted case keeps what it cost (added when it finishes)."""
    path = os.path.join(directory(case), "cpu_seconds_before.txt")
    before = 0.
    if os.path.isfile(path):
        with open(path) as f:
            before = float(f.read() or 0)
    os.makedirs(directory(case), exist_ok=True)
    with open(path, "w") as f:
        f.write(str(before + seconds * ranks))


def collect():
    """study.csv: one row per finished case; then the figures."""
    rows = []
    for case in cases:
        if not done(case):
            continue
        d = directory(case)
        try:
            bulk = {k: v[0] for k, v in read_table(os.path.join(d, "rheology.txt")).items()}
        except OSError:
            continue
        with open(os.path.join(d, "case_done.json")) as f:
            record = json.load(f)
        row = {"case": case["name"], "Re": case["Re"], "Ca": case["Ca"], "Phi": case["Phi"]}
        for k in ["viscosity_ratio", "viscosity_ratio_error", "N1", "N1_error", "N2",
                  "N2_error", "fraction_viscous", "fraction_Reynolds", "fraction_elastic",
                  "fraction_collision", "linear_deviation", "steady", "errors_converged", "time_first",
                  "time_last", "n_samples"]:
            row[k] = bulk.get(k, "")
        row["cpu_seconds"] = round(record["cpu_seconds"], 1)
        rows.append(row)
    if not rows:
        return
    with open(os.path.join(root, "study.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    subprocess.run([sys.executable, os.path.join(here, "plot_study.py"), root],
                   check=False)


def hms(seconds):
    seconds = int(max(0, seconds))
    return f"{seconds // 3600}h{seconds % 3600 // 60:02d}m{seconds % 60:02d}s"




def terminated(signum, frame):
    raise KeyboardInterrupt  # a batch system's time limit: stop as Ctrl-C does


signal.signal(signal.SIGTERM, terminated)
if a.save_state:
    save_state()
    sys.exit(0)
if a.collect:
    collect()
    print(f"study: {sum(done(c) for c in cases)}/{len(cases)} cases done in {root} (collected)",
          flush=True)
    sys.exit(0)
pending = [c for c in cases if not done(c)]
print(f"study {a.prm}: {len(cases)} cases, {len(cases) - len(pending)} done, "
      f"{len(pending)} to run, {jobs} at a time on {ranks} rank(s) each -> {root}",
      flush=True)
running = {}  # name -> (case, process, start)
start = time.time()
simulated_at_start = sum(simulated_time(c) for c in cases)
finished_now, failed = 0, []
last_report = 0.
try:
    while pending or running:
        while (pending and len(running) < jobs and
               (a.max_cases == 0 or finished_now + len(failed) + len(running) < a.max_cases)):
            case = pending.pop(0)
            restore_state(case)
            if os.path.isfile(os.path.join(directory(case), "case_done.json")):
                extend(case)
            os.makedirs(directory(case), exist_ok=True)
            log = open(os.path.join(directory(case), "run.log"), "a")
            cmd = command(case)
            print(f"  start {case['name']}" + (" (resumed)" if "--resume" in cmd else ""),
                  flush=True)
            running[case["name"]] = (case, subprocess.Popen(cmd, stdout=log,
                                                            stderr=subprocess.STDOUT),
                                     time.time())
        if not running:
            break
        for name in list(running):
            case, proc, t0 = running[name]
            # wait4: the exit status and the CPU time the case used (user +
            # system, its MPI ranks included), not its wall time
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid == 0:
                continue
            proc.returncode = os.waitstatus_to_exitcode(status)
            cpu = (usage.ru_utime + usage.ru_stime) / ranks
            del running[name]
            if proc.returncode == 0:
                finish(case, cpu)
                finished_now += 1
                with open(os.path.join(directory(case), "case_done.json")) as f:
                    line = json.load(f)["stationarity"]
                print(f"  done  {name}: {line}", flush=True)
                collect()
            else:
                spent_before(case, cpu)
                failed.append(name)
                with open(os.path.join(directory(case), "run.log")) as f:
                    last = [l for l in f.read().splitlines() if l.strip()][-1:]
                print(f"  FAILED {name} (exit {proc.returncode}): {' '.join(last)}",
                      flush=True)
        now = time.time()
        if now - last_report >= a.progress_seconds and running:
            last_report = now
            total = end_time * len(cases)
            simulated = sum(simulated_time(c) for c in cases)
            rate = (simulated - simulated_at_start) / max(now - start, 1e-9)
            eta = (total - simulated) / rate if rate > 0 else float("inf")
            states = ", ".join(f"{n} t={simulated_time(c):.2f}"
                               for n, (c, _, _) in running.items())
            print(f"  study: {sum(done(c) for c in cases)}/{len(cases)} done, running {states};"
                  f" ETA {hms(eta) if eta != float('inf') else '?'} (at most: cases may "
                  f"end before End time = {end_time:g})", flush=True)
        time.sleep(1.)
except KeyboardInterrupt:
    for name, (case, proc, t0) in running.items():
        proc.terminate()
        _, _, usage = os.wait4(proc.pid, 0)
        proc.returncode = -15
        spent_before(case, (usage.ru_utime + usage.ru_stime) / ranks)
    print("study interrupted: run the same command again to resume", flush=True)
    sys.exit(130)

collect()
left = sum(not done(c) for c in cases)
print(f"study: {len(cases) - left}/{len(cases)} cases done in {root}"
      + (f"; failed: {', '.join(failed)}" if failed else "")
      + (f"; {left} left: run the same command again" if left else ""), flush=True)
sys.exit(1 if failed else 0)
